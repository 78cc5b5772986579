//! The hostile-input catalogue for sharded studies: special files and directories where a part
//! or a study file belongs, study files too large, binary or of another format, outputs that
//! are files, and flags that do not go together. Each case checks its exit code, a message, no
//! panic, no hang and that nothing changed but the files it names (`common::hostile`). What a
//! damaged or foreign part does to a merge is in `tests/commands/variance_shards.rs`.

use crate::common;

use common::hostile::{case, check_all, setup, setup_streams};
use std::path::Path;

/// The smallest study as one shard, `parts/variance-shard-0-of-1.part`.
fn one_part(dir: &Path) {
    let r = common::hostile::run(
        dir,
        &[
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
            "--no-cache",
            "--shard",
            "0/1",
            "--out",
            "parts",
            "-q",
        ],
        None,
        common::hostile::TIMEOUT,
    );
    assert_eq!(r.code, Some(0), "{}", r.stderr);
}

#[test]
fn special_files_and_odd_outputs_in_a_sharded_study_are_refused() {
    check_all(&[
        case(
            "a FIFO as a part",
            |d| setup::fifo(d, "p.part"),
            &["variance", "merge", "p.part", "--out", "rep"],
            1,
            &["p.part: expected a part file"],
            &[],
        ),
        case(
            "a directory named like a part, given as a file",
            |d| {
                std::fs::create_dir(d.join("d.part")).unwrap();
                std::fs::write(d.join("d.part/x.txt"), "x").unwrap();
            },
            &["variance", "merge", "d.part", "--out", "rep"],
            1,
            &[
                "d.part: expected variance shard parts (variance-shard-I-of-N.part) in this directory, found none",
            ],
            &[],
        ),
        case(
            "a sparse 64 MiB file as a part",
            |d| setup_streams::sparse(d, "big.part", 64 << 20),
            &["variance", "merge", "big.part", "--out", "rep"],
            1,
            &["big.part: not a raywave part"],
            &[],
        ),
        case(
            "a merge into a file",
            |d| {
                one_part(d);
                setup::file(d, "report", b"keep me");
            },
            &["variance", "merge", "parts", "--out", "report"],
            1,
            &["cannot create the output directory report"],
            &["parts", "parts/variance-shard-0-of-1.part"],
        ),
        case(
            "a FIFO as the study file",
            |d| setup::fifo(d, "s.toml"),
            &["variance", "--study", "s.toml", "--out", "rep"],
            1,
            &["s.toml: expected a study file (TOML), found a directory or device"],
            &[],
        ),
        case(
            "a study file of 2 MiB",
            |d| setup_streams::sparse(d, "s.toml", 2 << 20),
            &["variance", "--study", "s.toml", "--out", "rep"],
            1,
            &["s.toml: 2097152 bytes, expected a study file (TOML) of at most 1 MiB"],
            &[],
        ),
        case(
            "a scene file given as the study file",
            setup::cornell_box,
            &["variance", "--study", "cornell_box.obj", "--out", "rep"],
            1,
            &["cornell_box.obj:"],
            &[],
        ),
        case(
            "a study file that is not UTF-8",
            |d| setup::file(d, "s.toml", b"seeds = 4\n\xff\xfe\n"),
            &["variance", "--study", "s.toml", "--out", "rep"],
            1,
            &["s.toml"],
            &[],
        ),
        case(
            "a shard whose --out is a file",
            |d| setup::file(d, "parts", b"keep me"),
            &[
                "variance", "--size", "4", "4", "--shard", "0/2", "--out", "parts", "-q",
            ],
            1,
            &["parts"],
            &[],
        ),
        case(
            "--shard with --clean-cache",
            setup::nothing,
            &["variance", "--clean-cache", "--shard", "0/2"],
            2,
            &["'--clean-cache' cannot be used with '--shard"],
            &[],
        ),
        case(
            "--study with a scene",
            setup::cornell_box,
            &["variance", "cornell_box.obj", "--study", "s.toml"],
            2,
            &["cannot be used with"],
            &[],
        ),
    ]);
}
