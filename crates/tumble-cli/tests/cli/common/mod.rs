//! What the tests of the `tumble` binary share: running it, and reading what it said.
#![allow(dead_code)] // each test file uses its own part

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// Runs `tumble` with `args`.
pub fn tumble(args: &[&str]) -> Output {
    match Command::new(env!("CARGO_BIN_EXE_tumble"))
        .args(args)
        .output()
    {
        Ok(out) => out,
        Err(e) => panic!("cannot start tumble: {e}"),
    }
}

pub fn stdout(out: &Output) -> String {
    String::from_utf8_lossy(&out.stdout).into_owned()
}

pub fn stderr(out: &Output) -> String {
    String::from_utf8_lossy(&out.stderr).into_owned()
}

/// Runs `tumble`, requires exit status `code` and exactly one line on stderr, and returns
/// that line.
pub fn one_line(code: i32, args: &[&str]) -> String {
    let out = tumble(args);
    let err = stderr(&out);
    assert_eq!(out.status.code(), Some(code), "tumble {args:?}: {err}");
    assert_eq!(
        err.lines().count(),
        1,
        "tumble {args:?}: not one line: {err:?}"
    );
    assert!(err.ends_with('\n'), "{err:?}");
    err.trim_end().to_string()
}

/// [`one_line`] for bad input: exit status 2.
pub fn refused(args: &[&str]) -> String {
    one_line(2, args)
}

/// Runs `tumble` and requires success.
pub fn ok(args: &[&str]) -> String {
    let out = tumble(args);
    assert!(out.status.success(), "tumble {args:?}: {}", stderr(&out));
    stdout(&out)
}

/// A fresh directory for one test's files.
pub fn scratch(test: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("tumble-{}-{test}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

pub fn path(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// The names in `dir`, sorted.
pub fn names(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    names
}
