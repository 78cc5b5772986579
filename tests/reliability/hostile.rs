//! The hostile-input catalogue (docs/RELIABILITY.md): every case runs the binary in a scratch
//! directory and checks its exit code, its message, that it neither panicked nor hung, and that
//! no input or earlier output changed (`common::hostile`).

use crate::common;

use common::hostile::{Case, check, check_all, setup};

/// The harness itself must be able to fail: a wrong exit code, a missing message fragment and
/// an unexpected file are each reported.
#[test]
fn the_harness_catches_wrong_exit_codes_messages_and_stray_files() {
    let ok = Case {
        name: "a small render",
        setup: setup::cornell_box,
        args: &["cornell_box.obj", "--size", "8", "8", "-q", "-o", "x.png"],
        stdin: None,
        exit: 0,
        stderr: &[],
        outputs: &["x.png"],
    };
    check(&ok).unwrap();
    let wrong_exit = Case { exit: 1, ..ok };
    assert!(
        check(&wrong_exit)
            .unwrap_err()
            .contains("exit Some(0), expected 1")
    );
    let wrong_message = Case {
        stderr: &["no such words"],
        ..ok
    };
    assert!(check(&wrong_message).unwrap_err().contains("stderr lacks"));
    let stray_output = Case { outputs: &[], ..ok };
    assert!(check(&stray_output).unwrap_err().contains("x.png appeared"));
}

#[test]
fn scene_errors() {
    check_all(&[
        Case {
            name: "missing scene",
            setup: setup::nothing,
            args: &["nothing.obj", "-q"],
            stdin: None,
            exit: 1,
            stderr: &["nothing.obj"],
            outputs: &[],
        },
        Case {
            name: "a word where a number belongs",
            setup: |d| setup::file(d, "bad.obj", b"v 0 0 zero\n"),
            args: &["bad.obj", "-q"],
            stdin: None,
            exit: 1,
            stderr: &["bad.obj:1"],
            outputs: &[],
        },
    ]);
}
