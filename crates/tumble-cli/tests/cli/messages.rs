//! Every refusal of the command line is one line naming the option, exit status 2; help
//! and version are clap's own, exit status 0; numbers in what is printed stay short.

use crate::common::{ok, path, refused, scratch, stderr, stdout, tumble};

#[test]
fn what_clap_refuses_is_one_line_naming_the_option() {
    let cases: [(&[&str], &str); 14] = [
        (
            &["run", "--steps", "-1"],
            "steps: must be a whole number from 0 to 1000000000, got '-1'",
        ),
        (
            &["run", "--steps", "1.5"],
            "steps: must be a whole number from 0 to 1000000000, got '1.5'",
        ),
        (&["run", "--steps"], "steps: needs a value"),
        (&["run", "--out"], "out: needs a value"),
        (
            &["run", "--dt", "fast"],
            "dt: expected a number, got 'fast'",
        ),
        (
            &["run", "--fly"],
            "--fly: unknown option of 'tumble run' (see 'tumble run --help')",
        ),
        (
            &["run", "--quiett"],
            "--quiett: unknown option of 'tumble run' (did you mean --quiet?)",
        ),
        (
            &["run", "spring", "extra"],
            "extra: unexpected argument of 'tumble run' (see 'tumble run --help')",
        ),
        (&["run", "--quiet=yes"], "quiet: takes no value"),
        (
            &["render", "free_fall"],
            "out: required; see 'tumble render --help'",
        ),
        (
            &["render", "free_fall", "--out", "a.gif", "--width", "-4"],
            "width: must be a whole number from 16 to 8192, got '-4'",
        ),
        (
            &["plot", "d.csv", "--out", "a.png", "--height", "tall"],
            "height: must be a whole number from 100 to 8192, got 'tall'",
        ),
        (
            &["view", "free_fall", "--port", "70000"],
            "port: must be a whole number from 0 to 65535, got '70000'",
        ),
        (
            &["export-html", "free_fall", "--out", "a.html", "--fps", "x"],
            "fps: expected a number, got 'x'",
        ),
    ];
    for (args, line) in cases {
        assert_eq!(refused(args), line, "tumble {args:?}");
    }
    let line = refused(&["fly"]);
    assert!(
        line.starts_with("command: unknown command 'fly' (expected one of: run, analyze,"),
        "{line}"
    );
    let line = refused(&["render"]);
    assert_eq!(line, "out, scene: required; see 'tumble render --help'");
}

#[test]
fn substeps_and_iterations_state_one_rule_for_every_bad_count() {
    let rule = "must be a whole number from 1 to 10000";
    for option in ["substeps", "iterations"] {
        for bad in ["-1", "0", "1.5", "10001", "2000000"] {
            assert_eq!(
                refused(&["run", "--steps", "1", &format!("--{option}"), bad]),
                format!("{option}: {rule}, got '{bad}'")
            );
        }
    }
    // The scene's keys of the same names say the same.
    let dir = scratch("passes");
    let file = dir.join("s.json");
    for bad in ["-1", "0", "1.5"] {
        std::fs::write(&file, format!(r#"{{"substeps": {bad}}}"#)).unwrap();
        assert_eq!(refused(&["run", path(&file)]), format!("substeps: {rule}"));
    }
    std::fs::remove_dir_all(dir).unwrap();
}

#[test]
fn help_and_version_are_unchanged() {
    for args in [
        &["--help"][..],
        &["run", "--help"],
        &["-h"],
        &["render", "--help"],
    ] {
        let out = tumble(args);
        assert_eq!(out.status.code(), Some(0), "{args:?}");
        assert!(stdout(&out).lines().count() > 5, "{args:?}");
        assert!(stderr(&out).is_empty());
    }
    let version = ok(&["--version"]);
    assert_eq!(version, format!("tumble {}\n", env!("CARGO_PKG_VERSION")));
    let help = ok(&["--help"]);
    assert!(help.contains("Exit status: 0 on success"), "{help}");
    assert!(help.contains(".partial"), "{help}");
}

#[test]
fn numbers_are_printed_short() {
    // Rust's `{}` writes 1e-300 with 300 zeros and `{:.6}` of 1e30 with 31 digits.
    for args in [
        &["run", "free_fall", "--dt", "1e-300", "--steps", "2"][..],
        &["run", "--dt", "1e-300", "--steps", "2"],
        &["run", "spring", "--dt", "1e30", "--steps", "1"],
        &["run", "--dt", "1e30", "--steps", "1"],
    ] {
        let out = tumble(args);
        let text = stdout(&out) + &stderr(&out);
        for line in text.lines() {
            assert!(line.len() < 120, "tumble {args:?}: {line}");
        }
    }
}

#[test]
fn threads_are_a_count_from_one_and_do_not_change_a_run() {
    let rule = "must be a whole number from 1 to 256";
    for command in ["run", "render", "export-html"] {
        for bad in ["0", "-2", "1.5", "300"] {
            let line = refused(&[command, "--threads", bad]);
            assert_eq!(line, format!("threads: {rule}, got '{bad}'"), "{command}");
        }
    }
    let dir = scratch("threads");
    let mut files = Vec::new();
    for threads in ["1", "2", "3"] {
        let file = dir.join(format!("{threads}.csv"));
        let args = [
            "run",
            "--quiet",
            "--steps",
            "60",
            "--threads",
            threads,
            "--out",
        ];
        ok(&[&args[..], &[path(&file)]].concat());
        files.push(std::fs::read_to_string(&file).unwrap());
    }
    assert!(files[0].lines().count() > 60);
    assert_eq!(files[1], files[0]);
    assert_eq!(files[2], files[0]);
    std::fs::remove_dir_all(dir).unwrap();
}
