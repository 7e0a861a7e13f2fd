//! Issue 18: `tumble run SCENE --save-state FILE.json` writes the world at the end of the
//! run, and `tumble run FILE.json` continues it bit-identically: its CSV rows (trajectory,
//! diagnostics, contacts, joints) are the rows the run that never stopped writes from the
//! saved step on, byte for byte, times included (the clock goes on from the saved time).

use crate::common::{ok, path, refused, scratch};
use std::path::Path;

const FILES: [&str; 4] = ["out", "diagnostics", "contacts", "joints"];

/// Runs `tumble run` with `args`, writing every CSV file into `dir` named `tag.KIND.csv`.
fn run_to(dir: &Path, tag: &str, args: &[&str]) {
    let names: Vec<String> = FILES
        .iter()
        .map(|f| path(&dir.join(format!("{tag}.{f}.csv"))).to_string())
        .collect();
    let mut all: Vec<&str> = vec!["run", "--quiet"];
    all.extend_from_slice(args);
    for (flag, name) in FILES.iter().zip(&names) {
        all.push(match *flag {
            "out" => "--out",
            "diagnostics" => "--diagnostics",
            "contacts" => "--contacts",
            _ => "--joints",
        });
        all.push(name);
    }
    ok(&all);
}

fn rows(dir: &Path, tag: &str, kind: &str) -> Vec<String> {
    let text = std::fs::read_to_string(dir.join(format!("{tag}.{kind}.csv"))).unwrap();
    text.lines().skip(1).map(str::to_string).collect()
}

/// 2 s straight against 1 s, --save-state, and 1 s of the saved file.
fn check(scene: &str, extra: &[&str]) {
    let dir = scratch(&format!("save-{scene}-{}", extra.join("")));
    let state = dir.join("state.json");
    fn with<'a>(more: &[&'a str], extra: &[&'a str]) -> Vec<&'a str> {
        [more, extra].concat()
    }
    run_to(&dir, "straight", &with(&[scene, "--duration", "2"], extra));
    run_to(
        &dir,
        "first",
        &with(
            &[scene, "--duration", "1", "--save-state", path(&state)],
            extra,
        ),
    );
    run_to(&dir, "second", &[path(&state), "--duration", "1"]);
    for kind in FILES {
        let (straight, second) = (rows(&dir, "straight", kind), rows(&dir, "second", kind));
        let first = rows(&dir, "first", kind);
        if kind == "out" || kind == "diagnostics" {
            // One step's rows are in both the first and the second half.
            assert!(!second.is_empty() && !first.is_empty(), "{scene} {kind}");
        }
        assert!(
            straight.ends_with(&second),
            "{scene} {extra:?} {kind}: the continued rows differ from the straight run's"
        );
        assert!(
            straight.len() <= first.len() + second.len(),
            "{scene} {kind}"
        );
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn every_builtin_scene_continues_from_its_saved_state_byte_for_byte() {
    for scene in tumble_scene::builtin_names() {
        if scene != "character_course" {
            check(scene, &[]);
        }
    }
}

#[test]
fn every_integrator_continues_from_its_saved_state_byte_for_byte() {
    for integrator in tumble::Integrator::ALL {
        check("rope_bridge", &["--integrator", integrator.name()]);
    }
}

#[test]
fn the_saved_clock_goes_on() {
    let dir = scratch("save-clock");
    let state = dir.join("s.json");
    ok(&[
        "run",
        "spring",
        "--quiet",
        "--duration",
        "0.5",
        "--save-state",
        path(&state),
    ]);
    let out = dir.join("t.csv");
    ok(&[
        "run",
        path(&state),
        "--quiet",
        "--steps",
        "2",
        "--out",
        path(&out),
    ]);
    let text = std::fs::read_to_string(&out).unwrap();
    let times: Vec<&str> = text
        .lines()
        .skip(1)
        .map(|l| l.split(',').next().unwrap())
        .collect();
    assert_eq!(times, ["0.5", "0.51", "0.52"]);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_character_scene_is_not_saved() {
    let dir = scratch("save-character");
    let state = dir.join("s.json");
    assert_eq!(
        refused(&["run", "character_course", "--save-state", path(&state)]),
        "save-state: a scene with a character cannot be saved yet (its path and fall are not \
         world state)"
    );
    assert!(!state.exists());
    let _ = std::fs::remove_dir_all(&dir);
}
