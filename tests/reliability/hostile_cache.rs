//! The hostile-input catalogue for the converged-reference cache of `raywave variance`:
//! corrupt, foreign or special files where an entry belongs, `--no-cache`, `--clean-cache`, the
//! size bound, and the command's usage errors (exit 2). Each case checks its exit code, a
//! message, no panic, no hang and that nothing changed but the files it names
//! (`common::hostile`). Bench records and verdicts are in `tests/reliability/hostile_records.rs`.

use crate::common;

use common::hostile::{Case, TIMEOUT, check_all, run, setup};
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

/// The smallest study: 4×4, one budget, one sampler, two seeds, one reference sample.
const VARIANCE: &[&str] = &[
    "variance",
    "--size",
    "4",
    "4",
    "--budgets",
    "1",
    "--seeds",
    "2",
    "--samplers",
    "random",
    "--reference-samples",
    "1",
    "--mask-samples",
    "1",
    "--heatmap-n",
    "1",
    "--out",
    "rep",
    "-q",
];

/// The study's report files, rewritten by every run.
const REPORT: &[&str] = &[
    "rep",
    "rep/table.txt",
    "rep/results.csv",
    "rep/seeds.csv",
    "rep/perceived.csv",
    "rep/spectra.csv",
    "rep/results.json",
    "rep/mse.png",
    "rep/contact_sheet.png",
    "rep/heat_random_N1.png",
    "rep/spectrum_N1.png",
];

/// `VARIANCE` followed by `extra`, for a case's arguments.
fn variance(extra: &[&'static str]) -> &'static [&'static str] {
    Box::leak([VARIANCE, extra].concat().into_boxed_slice())
}

/// The cache entry's path relative to the scratch directory: the key depends on the scene,
/// the settings and this build's executable, not on the directory, so one run finds it.
fn entry() -> &'static str {
    static NAME: OnceLock<&'static str> = OnceLock::new();
    NAME.get_or_init(|| {
        let dir = tempfile::tempdir().unwrap();
        populate(dir.path());
        let name = entry_in(dir.path());
        let rel = name.strip_prefix(dir.path()).unwrap().to_string_lossy();
        Box::leak(rel.into_owned().into_boxed_str())
    })
}

/// `names` plus the report files, as a case's outputs.
fn outputs(names: &[&'static str]) -> &'static [&'static str] {
    Box::leak([REPORT, names].concat().into_boxed_slice())
}

/// Runs the smallest study in `dir`, which caches its reference.
fn populate(dir: &Path) {
    let r = run(dir, VARIANCE, None, TIMEOUT);
    assert_eq!(r.code, Some(0), "{}", r.stderr);
}

/// The one cache entry under `dir`.
fn entry_in(dir: &Path) -> PathBuf {
    let mut found: Vec<PathBuf> = std::fs::read_dir(dir.join(".raywave-cache"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "rwref"))
        .collect();
    assert_eq!(found.len(), 1, "{found:?}");
    found.pop().unwrap()
}

/// A cached study whose entry `edit` then changes in place.
fn doctored_entry(dir: &Path, edit: fn(&mut Vec<u8>)) {
    populate(dir);
    let path = entry_in(dir);
    let mut bytes = std::fs::read(&path).unwrap();
    edit(&mut bytes);
    std::fs::write(path, bytes).unwrap();
}

/// A cached study whose entry is replaced by what `make` puts at its path.
fn replaced_entry(dir: &Path, make: fn(&Path)) {
    populate(dir);
    let path = entry_in(dir);
    std::fs::remove_file(&path).unwrap();
    make(&path);
}

/// FNV-1a, as the cache's checksum.
fn fnv(bytes: &[u8]) -> u64 {
    bytes.iter().fold(0xcbf2_9ce4_8422_2325, |h, &b| {
        (h ^ u64::from(b)).wrapping_mul(0x0000_0100_0000_01b3)
    })
}

/// A case that runs the smallest study and must warn about the entry, render again and exit 0.
fn rerender(name: &'static str, setup: fn(&Path), why: &'static str) -> Case {
    let fragments: &'static [&'static str] =
        Box::leak(vec!["warning: ignoring the cache entry", why].into_boxed_slice());
    Case {
        name,
        setup,
        args: VARIANCE,
        stdin: None,
        exit: 0,
        stderr: fragments,
        outputs: outputs(&[entry()]),
    }
}

#[test]
fn corrupt_cache_entries_are_reported_and_rendered_again() {
    check_all(&[
        rerender(
            "a truncated entry",
            |d| doctored_entry(d, |b| b.truncate(50)),
            "50 bytes, expected",
        ),
        rerender(
            "a zero-length entry",
            |d| doctored_entry(d, |b| b.clear()),
            "0 bytes, shorter than the 36-byte header",
        ),
        rerender(
            "an entry with the wrong magic",
            |d| doctored_entry(d, |b| b[..8].copy_from_slice(b"PF\n4 4\n-")),
            "wrong magic",
        ),
        rerender(
            "an entry of another format version",
            |d| doctored_entry(d, |b| b[8..12].copy_from_slice(&99u32.to_le_bytes())),
            "cache format 99, expected 1",
        ),
        rerender(
            "an entry with other dimensions",
            |d| doctored_entry(d, |b| b[12..16].copy_from_slice(&5u32.to_le_bytes())),
            "5×4 pixels, expected 4×4",
        ),
        rerender(
            "an entry whose pixels were altered",
            |d| doctored_entry(d, |b| b[40] ^= 0x40),
            "checksum mismatch",
        ),
        rerender(
            "an entry full of NaN with a matching checksum",
            |d| {
                doctored_entry(d, |b| {
                    for v in b[36..].chunks_exact_mut(4) {
                        v.copy_from_slice(&f32::NAN.to_le_bytes());
                    }
                    let sum = fnv(&b[36..]);
                    b[28..36].copy_from_slice(&sum.to_le_bytes());
                })
            },
            "96 values are not finite",
        ),
        rerender(
            "an entry that is a FIFO (must not hang)",
            |d| replaced_entry(d, |p| setup::fifo(p.parent().unwrap(), &name_of(p))),
            "expected a regular file",
        ),
        rerender(
            "an entry that is a symlink to /dev/zero (must not read forever)",
            |d| replaced_entry(d, |p| std::os::unix::fs::symlink("/dev/zero", p).unwrap()),
            "expected a regular file",
        ),
        Case {
            // Cannot be read nor replaced: warned twice, left alone, and the study still runs.
            outputs: outputs(&[]),
            stderr: &["expected a regular file", "cannot cache the reference in"],
            ..rerender(
                "a directory where the entry belongs",
                |d| replaced_entry(d, |p| std::fs::create_dir(p).unwrap()),
                "",
            )
        },
        Case {
            // The earlier layout's PFM with a zero width once panicked in the PFM reader; it is
            // no entry of this layout and is left alone.
            name: "a zero-width PFM of the earlier layout in the cache",
            setup: |d| {
                std::fs::create_dir(d.join(".raywave-cache")).unwrap();
                setup::file(
                    d,
                    ".raywave-cache/reference-0000000000000000-0.pfm",
                    b"PF\n0 4\n-1.0\n",
                );
            },
            args: VARIANCE,
            stdin: None,
            exit: 0,
            stderr: &["raise --reference-samples"],
            outputs: outputs(&[entry()]),
        },
    ]);
}

fn name_of(p: &Path) -> String {
    p.file_name().unwrap().to_string_lossy().into_owned()
}

#[test]
fn the_cache_can_be_bypassed_and_cleaned() {
    check_all(&[
        Case {
            name: "a valid entry is used and not rewritten",
            setup: populate,
            args: VARIANCE,
            stdin: None,
            exit: 0,
            stderr: &["raise --reference-samples"],
            outputs: REPORT,
        },
        Case {
            name: "--no-cache neither reads nor writes a corrupt entry",
            setup: |d| doctored_entry(d, |b| b.truncate(50)),
            args: variance(&["--no-cache"]),
            stdin: None,
            exit: 0,
            stderr: &["raise --reference-samples"],
            outputs: REPORT,
        },
        Case {
            name: "--clean-cache removes entries of both layouts and nothing else",
            setup: |d| {
                populate(d);
                setup::file(d, ".raywave-cache/notes.txt", b"mine");
                setup::file(d, ".raywave-cache/reference-00-0.pfm", b"PF\n0 4\n-1.0\n");
            },
            args: &["variance", "--clean-cache"],
            stdin: None,
            exit: 0,
            stderr: &[],
            outputs: Box::leak(
                vec![entry(), ".raywave-cache/reference-00-0.pfm"].into_boxed_slice(),
            ),
        },
        Case {
            name: "--clean-cache on a file",
            setup: |d| setup::file(d, "f.txt", b"not a cache"),
            args: &["variance", "--clean-cache", "--cache", "f.txt"],
            stdin: None,
            exit: 1,
            stderr: &["f.txt: expected a directory"],
            outputs: &[],
        },
        Case {
            name: "--no-cache with --clean-cache",
            setup: populate,
            args: &["variance", "--no-cache", "--clean-cache"],
            stdin: None,
            exit: 2,
            stderr: &["'--no-cache' cannot be used with '--clean-cache'"],
            outputs: &[],
        },
        Case {
            name: "--no-cache with --cache",
            setup: setup::nothing,
            args: &["variance", "--no-cache", "--cache", "c"],
            stdin: None,
            exit: 2,
            stderr: &["cannot be used with"],
            outputs: &[],
        },
        Case {
            name: "--clean-cache with a scene",
            setup: setup::cornell_box,
            args: &["variance", "--clean-cache", "cornell_box.obj"],
            stdin: None,
            exit: 2,
            stderr: &["cannot be used with"],
            outputs: &[],
        },
        Case {
            name: "--cache-limit 0",
            setup: setup::nothing,
            args: &["variance", "--cache-limit", "0"],
            stdin: None,
            exit: 2,
            stderr: &["--cache-limit"],
            outputs: &[],
        },
        Case {
            name: "a cache limit below one entry: the study runs, nothing is cached",
            setup: setup::nothing,
            args: &[
                "variance",
                "--size",
                "300",
                "300",
                "--budgets",
                "1",
                "--seeds",
                "2",
                "--samplers",
                "random",
                "--reference-samples",
                "1",
                "--mask-samples",
                "1",
                "--heatmap-n",
                "1",
                "--out",
                "rep",
                "-q",
                "--cache-limit",
                "1",
            ],
            stdin: None,
            exit: 0,
            stderr: &["would take 2.1 MiB, above the cache limit of 1 MiB: not cached"],
            outputs: outputs(&[".raywave-cache"]),
        },
    ]);
}

#[test]
fn variance_option_conflicts_are_usage_errors() {
    check_all(&[
        Case {
            name: "--seeds and --size that need too much memory",
            setup: setup::nothing,
            args: &["variance", "--seeds", "1024", "--size", "4096", "4096"],
            stdin: None,
            exit: 2,
            stderr: &["would hold", "GiB"],
            outputs: &[],
        },
        // A --heatmap-n that is not a budget is not an error: the nearest budget is drawn
        // (tests/sampling/variance_report.rs).
    ]);
}
