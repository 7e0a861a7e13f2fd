//! Output files are never lost: paths are checked before the run, files are written as
//! NAME.partial and renamed into place when complete, a failed command truncates nothing,
//! and special files are written in place with their errors reported.

use std::path::Path;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use crate::common::{names, ok, path, refused, scratch, stdout, tumble};

/// A file that a good earlier run wrote, which a failing command must leave alone.
const GOOD: &str = "time,body,x\n0,ball,1\n";

fn read(file: &Path) -> String {
    std::fs::read_to_string(file).unwrap_or_else(|e| panic!("{}: {e}", file.display()))
}

#[test]
fn a_bad_second_path_truncates_nothing() {
    let dir = scratch("bad-second");
    let out = dir.join("traj.csv");
    std::fs::write(&out, GOOD).unwrap();
    let bad = dir.join("no/such/dir/diag.csv");
    let line = refused(&[
        "run",
        "spring",
        "--out",
        path(&out),
        "--diagnostics",
        path(&bad),
    ]);
    assert!(line.starts_with("diagnostics: cannot create '"), "{line}");
    assert!(line.ends_with("does not exist"), "{line}");
    assert_eq!(read(&out), GOOD);
    // A folder where a file should be, and a path through a file, alike.
    let line = refused(&["run", "spring", "--out", path(&out), "--joints", path(&dir)]);
    assert!(line.starts_with("joints: '") && line.ends_with("is a folder; name a file"));
    let through = out.join("x.csv");
    let line = refused(&[
        "run",
        "spring",
        "--out",
        path(&out),
        "--contacts",
        path(&through),
    ]);
    assert!(line.starts_with("contacts: cannot create '") && line.ends_with("is not a folder"));
    assert_eq!(read(&out), GOOD);
    assert_eq!(names(&dir), ["traj.csv"]);
    std::fs::remove_dir_all(dir).unwrap();
}

#[test]
fn a_full_device_is_reported_and_nothing_else_is_touched() {
    let dir = scratch("full");
    let out = dir.join("traj.csv");
    std::fs::write(&out, GOOD).unwrap();
    let line = refused(&[
        "run",
        "spring",
        "--out",
        path(&out),
        "--diagnostics",
        "/dev/full",
    ]);
    assert!(
        line.starts_with("diagnostics: cannot write '/dev/full': "),
        "{line}"
    );
    assert!(line.contains("No space left on device"), "{line}");
    assert_eq!(read(&out), GOOD);
    assert_eq!(names(&dir), ["traj.csv"], "a partial file was left");
    // Any option, any command: the device is flushed before the run.
    let line = refused(&[
        "run",
        "pyramid",
        "--steps",
        "50",
        "--out",
        "/dev/full",
        "-q",
    ]);
    assert!(
        line.starts_with("out: cannot write '/dev/full': No space left"),
        "{line}"
    );
    let line = refused(&["render", "free_fall", "--out", "/dev/full"]);
    assert!(
        line.starts_with("out: '/dev/full' is not a folder"),
        "{line}"
    );
    assert!(!line.contains("File exists"), "{line}");
    let line = refused(&["export-html", "free_fall", "--out", "/dev/full"]);
    assert!(line.contains("No space left on device"), "{line}");
    std::fs::remove_dir_all(dir).unwrap();
}

#[test]
fn a_link_to_a_full_device_is_written_in_place() {
    let dir = scratch("link-full");
    let gif = dir.join("a.gif");
    std::os::unix::fs::symlink("/dev/full", &gif).unwrap();
    let line = refused(&[
        "render",
        "free_fall",
        "--out",
        path(&gif),
        "--duration",
        "0.2",
    ]);
    assert!(line.starts_with("out: cannot write '"), "{line}");
    assert!(line.contains("No space left on device"), "{line}");
    assert_eq!(names(&dir), ["a.gif"]);
    std::fs::remove_dir_all(dir).unwrap();
}

#[test]
fn special_files_are_written_directly() {
    let out = tumble(&[
        "run",
        "spring",
        "--steps",
        "3",
        "--out",
        "/dev/stdout",
        "-q",
    ]);
    assert!(out.status.success());
    let text = stdout(&out);
    assert!(text.starts_with("time,body,x,y,z,"), "{text}");
    assert_eq!(text.lines().count(), 5, "{text}");
    // The null device may take several outputs: nothing written to it is kept.
    ok(&[
        "run",
        "spring",
        "--out",
        "/dev/null",
        "--diagnostics",
        "/dev/null",
        "-q",
    ]);
}

#[test]
fn an_output_may_not_be_the_scene_nor_another_output() {
    let dir = scratch("same");
    let scene = dir.join("scene.json");
    let text = r#"{"bodies": [{"name": "ball", "shape": {"type": "sphere", "radius": 0.1}}]}"#;
    std::fs::write(&scene, text).unwrap();
    let roundabout = dir.join("sub/../scene.json");
    std::fs::create_dir(dir.join("sub")).unwrap();
    let link = dir.join("link.json");
    std::os::unix::fs::symlink(&scene, &link).unwrap();
    for out in [&scene, &roundabout, &link] {
        let line = refused(&["run", path(&scene), "--out", path(out)]);
        assert!(
            line.ends_with("is the scene being read; name another file"),
            "{line}"
        );
        let line = refused(&["export-html", path(&scene), "--out", path(out)]);
        assert!(line.starts_with("out: "), "{line}");
    }
    let line = refused(&["run", path(&link), "--diagnostics", path(&scene)]);
    assert!(line.starts_with("diagnostics: "), "{line}");
    assert_eq!(read(&scene), text);
    let a = dir.join("a.csv");
    let line = refused(&[
        "run",
        "spring",
        "--out",
        path(&a),
        "--joints",
        &format!("{}/./a.csv", path(&dir)),
    ]);
    assert!(
        line.starts_with("joints: '") && line.ends_with("is also --out; name a different file")
    );
    assert!(!a.exists());
    std::fs::remove_dir_all(dir).unwrap();
}

#[test]
fn a_finished_run_leaves_no_partial_files() {
    let dir = scratch("finished");
    let (out, png, html) = (dir.join("t.csv"), dir.join("p.png"), dir.join("p.html"));
    std::fs::write(&out, GOOD).unwrap();
    ok(&[
        "run",
        "spring",
        "--steps",
        "5",
        "--out",
        path(&out),
        "--diagnostics",
        path(&dir.join("d.csv")),
        "-q",
    ]);
    assert_eq!(read(&out).lines().count(), 7);
    ok(&[
        "render",
        "free_fall",
        "--out",
        path(&png),
        "--duration",
        "0",
        "-q",
    ]);
    ok(&[
        "export-html",
        "free_fall",
        "--out",
        path(&html),
        "--duration",
        "0.1",
        "-q",
    ]);
    ok(&[
        "render",
        "free_fall",
        "--out",
        path(&dir.join("frames")),
        "--duration",
        "0.1",
        "-q",
    ]);
    assert_eq!(names(&dir), ["d.csv", "frames", "p.html", "p.png", "t.csv"]);
    assert_eq!(names(&dir.join("frames")).len(), 4);
    std::fs::remove_dir_all(dir).unwrap();
}

#[test]
fn a_killed_run_leaves_only_its_partial_file() {
    let dir = scratch("killed");
    let out = dir.join("traj.csv");
    std::fs::write(&out, GOOD).unwrap();
    let partial = dir.join("traj.csv.partial");
    let mut child = Command::new(env!("CARGO_BIN_EXE_tumble"))
        .args([
            "run",
            "pyramid",
            "--duration",
            "100000",
            "--out",
            path(&out),
            "-q",
        ])
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .expect("tumble starts");
    let start = Instant::now();
    // Killed once rows have reached the disk, mid-run.
    while std::fs::metadata(&partial).map_or(true, |m| m.len() < 100_000) {
        assert!(start.elapsed() < Duration::from_secs(60), "no rows written");
        std::thread::sleep(Duration::from_millis(20));
    }
    child.kill().unwrap();
    child.wait().unwrap();
    assert_eq!(
        read(&out),
        GOOD,
        "the target was written before the run ended"
    );
    assert!(partial.exists());
    // The next run replaces the leftover and puts its own file in place.
    ok(&["run", "spring", "--steps", "2", "--out", path(&out), "-q"]);
    assert_eq!(names(&dir), ["traj.csv"]);
    std::fs::remove_dir_all(dir).unwrap();
}

#[test]
fn frames_replace_a_folders_frames_only_when_complete() {
    let dir = scratch("frames");
    let frames = dir.join("frames");
    std::fs::create_dir(&frames).unwrap();
    std::fs::write(frames.join("frame_00000.png"), "old").unwrap();
    std::fs::write(frames.join("notes.txt"), "mine").unwrap();
    // Refused before the run: the old frame stays.
    refused(&["render", "free_fall", "--out", path(&frames), "--fps", "0"]);
    assert_eq!(read(&frames.join("frame_00000.png")), "old");
    ok(&[
        "render",
        "free_fall",
        "--out",
        path(&frames),
        "--duration",
        "0.1",
        "-q",
    ]);
    let got = names(&frames);
    assert_eq!(
        got,
        [
            "frame_00000.png",
            "frame_00001.png",
            "frame_00002.png",
            "frame_00003.png",
            "notes.txt"
        ]
    );
    assert!(std::fs::read(frames.join("frame_00000.png"))
        .unwrap()
        .starts_with(b"\x89PNG"));
    std::fs::remove_dir_all(dir).unwrap();
}

#[test]
fn a_closed_standard_output_stops_the_table_not_the_files() {
    // `tumble run --out traj.csv | head -1`: the seed table meets a closed pipe.
    let dir = scratch("closed");
    let out = dir.join("traj.csv");
    let mut child = Command::new(env!("CARGO_BIN_EXE_tumble"))
        .args(["run", "--out", path(&out)])
        .stdout(Stdio::piped())
        .spawn()
        .expect("tumble starts");
    drop(child.stdout.take());
    assert!(child.wait().unwrap().success());
    // The seed's 100 steps, all recorded, and the header.
    assert_eq!(read(&out).lines().count(), 102);
    assert_eq!(names(&dir), ["traj.csv"]);
    std::fs::remove_dir_all(dir).unwrap();
}
