//! SIGINT and SIGTERM at any phase (while rendering, while writing the output) leave no
//! temporary file behind, keep the old output as it was, and exit 130 or 143.

use std::path::Path;
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

const OLD: &[u8] = b"the old output";

/// Starts a render of `size`² into out.png and out.exr (both holding [`OLD`]); `slow` adds 64
/// soft-shadow samples and 5 bounces, so the render outlasts any delay the tests use.
fn start(dir: &Path, size: &str, slow: bool) -> Child {
    std::fs::write(dir.join("out.png"), OLD).unwrap();
    std::fs::write(dir.join("out.exr"), OLD).unwrap();
    Command::new(crate::common::bin::exe())
        .args(["render", "--size", size, size, "-q"])
        .args(if slow {
            [
                "--shadows",
                "soft",
                "--shadow-samples",
                "64",
                "--bounces",
                "5",
            ]
        } else {
            [
                "--shadows",
                "off",
                "--shadow-samples",
                "1",
                "--bounces",
                "0",
            ]
        })
        .args(["--threads", "2", "-o", "out.png", "--hdr", "out.exr"])
        .current_dir(dir)
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap()
}

fn temporaries(dir: &Path) -> Vec<String> {
    std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.starts_with(".raywave-"))
        .collect()
}

/// Waits until the child catches `sig` (its handler is installed: `SigCgt` in
/// /proc/PID/status), so that a delay counts from then and not from a start that a loaded
/// machine may stretch past it (a signal before the handler kills the process outright).
fn wait_until_caught(child: &Child, sig: i32) {
    let start = Instant::now();
    let status = format!("/proc/{}/status", child.id());
    loop {
        let caught = std::fs::read_to_string(&status)
            .ok()
            .and_then(|s| {
                s.lines()
                    .find_map(|l| l.strip_prefix("SigCgt:"))
                    .and_then(|m| u64::from_str_radix(m.trim(), 16).ok())
            })
            .is_some_and(|mask| mask & (1 << (sig - 1)) != 0);
        if caught {
            return;
        }
        assert!(
            start.elapsed() < Duration::from_secs(20),
            "the child never installed its handler for signal {sig}"
        );
        std::thread::sleep(Duration::from_millis(1));
    }
}

fn signal(child: &Child, sig: i32) {
    // SAFETY: kill with a pid we spawned and a valid signal number.
    assert_eq!(unsafe { libc::kill(child.id() as i32, sig) }, 0);
}

/// Waits for the child; the exit code it ended with.
fn finish(mut child: Child) -> (Option<i32>, String) {
    let start = Instant::now();
    loop {
        if let Some(status) = child.try_wait().unwrap() {
            let mut err = String::new();
            use std::io::Read;
            child
                .stderr
                .take()
                .unwrap()
                .read_to_string(&mut err)
                .unwrap();
            return (status.code(), err);
        }
        assert!(
            start.elapsed() < Duration::from_secs(30),
            "hung after the signal"
        );
        std::thread::sleep(Duration::from_millis(5));
    }
}

/// After a signal: the right code, the old outputs intact, nothing else in the directory.
fn check_interrupted(dir: &Path, code: Option<i32>, stderr: &str, expected: i32) {
    assert_eq!(code, Some(expected), "{stderr}");
    assert!(stderr.contains("stopped by SIG"), "{stderr}");
    assert!(
        temporaries(dir).is_empty(),
        "left behind: {:?}",
        temporaries(dir)
    );
    assert!(
        std::fs::read(dir.join("out.exr")).unwrap() == OLD,
        "out.exr changed"
    );
}

#[test]
fn a_signal_while_rendering_exits_cleanly_and_keeps_the_old_outputs() {
    for (sig, code) in [(libc::SIGINT, 130), (libc::SIGTERM, 143)] {
        for delay_ms in [50, 300] {
            let dir = tempfile::tempdir().unwrap();
            let child = start(dir.path(), "2048", true);
            wait_until_caught(&child, sig);
            std::thread::sleep(Duration::from_millis(delay_ms));
            signal(&child, sig);
            let (got, err) = finish(child);
            check_interrupted(dir.path(), got, &err, code);
            let png = std::fs::read(dir.path().join("out.png")).unwrap();
            assert!(png == OLD, "out.png changed");
        }
    }
}

#[test]
fn a_signal_while_writing_removes_the_temporary_file() {
    for (sig, code) in [(libc::SIGINT, 130), (libc::SIGTERM, 143)] {
        let dir = tempfile::tempdir().unwrap();
        let child = start(dir.path(), "2048", false);
        // The signal goes the moment a temporary file appears: mid-write.
        let start = Instant::now();
        while temporaries(dir.path()).is_empty() {
            assert!(
                start.elapsed() < Duration::from_secs(20),
                "no write phase seen"
            );
            std::thread::sleep(Duration::from_micros(200));
        }
        signal(&child, sig);
        let (got, err) = finish(child);
        // The PNG may have been finished and renamed before the signal was handled; the EXR,
        // written after it, cannot have been.
        check_interrupted(dir.path(), got, &err, code);
        let png = std::fs::read(dir.path().join("out.png")).unwrap();
        assert!(
            png == OLD || png.starts_with(b"\x89PNG"),
            "out.png is neither old nor whole"
        );
    }
}
