//! The start-up check that the CPU has every x86 feature the binary was compiled with
//! (`raywave::output::cpu`), end to end: the real binary run on an emulated CPU with AVX2 and
//! without AVX-512, which is what a binary built on an AVX-512 node meets on an older one.
//! Before the check it died there of SIGILL, with no message. Two emulators, each a CPU of its
//! own: valgrind (the host's CPUID less what valgrind cannot run, AVX-512 first) and QEMU's
//! user mode as a Haswell, whose CPUID is another CPU's altogether.
//!
//! An emulator is the honest test: it runs the very instructions the build contains, so had the
//! check itself (compiled with AVX-512 like the rest) used one, it would die of SIGILL too. A
//! hidden environment variable that made the binary pretend a feature was absent would test the
//! message but not that; the message's wording is the unit tests' in `src/output/cpu.rs`.

use crate::common;

use common::bin::{raywave, stderr, stdout};
use common::skip::skip_or_fail;
use raywave::output::cpu::FEATURES;
use std::path::PathBuf;
use std::process::{Command, Output};

/// `name` on PATH.
fn on_path(name: &str) -> Option<PathBuf> {
    let path = std::env::var_os("PATH")?;
    std::env::split_paths(&path)
        .map(|dir| dir.join(name))
        .find(|p| p.is_file())
}

/// Checks a run of `raywave info` on an emulated CPU without AVX-512 whose own lines in
/// standard error start with `noise`; returns the features the refusal names (empty when the
/// build needs nothing beyond that CPU's).
fn refused_or_ran(out: &Output, noise: &str) -> Vec<String> {
    let err: String = stderr(out)
        .lines()
        .filter(|l| !l.starts_with(noise))
        .map(|l| format!("{l}\n"))
        .collect();
    assert!(
        !err.contains("signal") && out.status.code().is_some_and(|c| c < 128),
        "the binary died on a CPU without AVX-512 instead of refusing it ({:?}):\n{err}",
        out.status
    );
    if out.status.code() == Some(0) {
        // Built for the emulated CPU or an older one: it runs there. (A constant per build, and
        // checked only when the binary ran: an AVX-512 build must refuse, not run.)
        #[allow(clippy::assertions_on_constants)]
        {
            assert!(!cfg!(target_feature = "avx512f"), "{err}");
        }
        assert!(
            stdout(out).contains("this CPU has every one"),
            "{}",
            stdout(out)
        );
        return Vec::new();
    }
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(stdout(out).is_empty(), "{}", stdout(out));
    assert!(
        err.starts_with("error: this raywave was compiled for CPU features that this CPU"),
        "{err}"
    );
    // Both emulators show the host's /proc/cpuinfo, so the model named is the host's.
    let model = raywave::output::machine::cpu_model();
    assert!(
        err.contains(&format!("this CPU ({model}) lacks: ")),
        "{err}"
    );
    assert!(err.contains("or build it on this machine"), "{err}");
    let lacks: Vec<String> = err
        .lines()
        .next()
        .and_then(|l| l.split_once("lacks: "))
        .map(|(_, list)| list.split(", ").map(str::to_string).collect())
        .unwrap_or_default();
    // Every AVX-512 feature the build has is missing, and is named.
    for f in FEATURES.iter().filter(|f| f.compiled) {
        if f.name.starts_with("avx512") {
            assert!(lacks.iter().any(|l| l == f.name), "{}: {err}", f.name);
        }
    }
    if cfg!(target_feature = "avx512f") {
        assert!(err.contains("lacks: avx512f, "), "{err}");
        assert!(
            err.contains("RUSTFLAGS=\"-C target-cpu=x86-64-v3\" cargo build --release"),
            "{err}"
        );
    }
    lacks
}

#[test]
fn a_build_the_cpu_cannot_run_exits_2_under_valgrind_naming_the_features_the_cpu_and_the_fix() {
    let Some(valgrind) = on_path("valgrind") else {
        return skip_or_fail("valgrind is missing (.ci/run installs it)");
    };
    let out = Command::new(valgrind)
        .args(["--tool=none", "-q", crate::common::bin::exe(), "info"])
        .output()
        .expect("run valgrind");
    let lacks = refused_or_ran(&out, "==");
    // Valgrind runs AVX2, FMA and BMI: an x86-64-v3 feature is never what it lacks.
    for f in FEATURES.iter().filter(|f| (1..=3).contains(&f.level)) {
        assert!(!lacks.iter().any(|l| l == f.name), "{}: {lacks:?}", f.name);
    }
}

#[test]
fn a_build_the_cpu_cannot_run_exits_2_under_qemu_as_haswell() {
    let Some(qemu) = on_path("qemu-x86_64") else {
        return skip_or_fail("qemu-x86_64 is missing (.ci/run installs qemu-user)");
    };
    let out = Command::new(qemu)
        .args(["-cpu", "Haswell", crate::common::bin::exe(), "info"])
        .output()
        .expect("run qemu-x86_64");
    // QEMU warns about the Haswell features its emulator leaves out.
    let lacks = refused_or_ran(&out, "qemu-x86_64: warning:");
    // Another CPU's CPUID read through the same table: what Haswell has is not missing.
    let haswell = [
        "sse3",
        "ssse3",
        "sse4.1",
        "sse4.2",
        "popcnt",
        "cmpxchg16b",
        "avx",
        "avx2",
        "fma",
        "f16c",
        "bmi1",
        "bmi2",
        "lzcnt",
        "movbe",
        "xsave",
        "xsaveopt",
        "aes",
        "pclmulqdq",
        "rdrand",
    ];
    for name in haswell {
        assert!(
            !lacks.iter().any(|l| l == name),
            "{name} is on Haswell: {lacks:?}"
        );
    }
}

#[test]
fn info_lists_the_features_the_build_needs_beside_the_cpu() {
    let dir = tempfile::tempdir().unwrap();
    let out = raywave(dir.path(), &["info"]);
    assert!(out.status.success(), "{}", stderr(&out));
    let info = stdout(&out);
    let line = |head: &str| {
        info.lines()
            .find(|l| l.starts_with(head))
            .unwrap_or_else(|| panic!("no `{head}` line in:\n{info}"))
            .to_string()
    };
    let model = raywave::output::machine::cpu_model();
    assert_eq!(line("cpu "), format!("cpu     {model}"));
    let needs = line("needs ");
    let compiled: Vec<&str> = FEATURES
        .iter()
        .filter(|f| f.compiled)
        .map(|f| f.name)
        .collect();
    // The test runs here, so the CPU has every feature the build needs.
    assert!(
        needs.ends_with(&format!(
            "({} x86 features; this CPU has every one)",
            compiled.len()
        )),
        "{needs}"
    );
    let listed: Vec<&str> = needs["needs ".len()..]
        .split(" (")
        .next()
        .unwrap()
        .split_whitespace()
        .collect();
    assert_eq!(listed, compiled, "{needs}");
    // A feature is needed or unused, never both.
    let unused = line("unused ");
    for name in &compiled {
        assert!(
            !unused.split_whitespace().any(|w| w == *name),
            "{name}: {unused}"
        );
    }
}
