//! Issue 18: `tumble run SCENE --save-state FILE.json` writes the world at the end of the
//! run, and `tumble run FILE.json` continues it bit-identically: its CSV rows (trajectory,
//! diagnostics, contacts, joints) are the rows the run that never stopped writes from the
//! saved step on, byte for byte, times included (the clock goes on from the saved time).

use crate::common::{ok, path, scratch};
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
    check_cut(scene, extra, ("1", "1"));
}

/// (cut + rest) s straight against `cut` s, --save-state, and `rest` s of the saved file.
fn check_cut(scene: &str, extra: &[&str], (cut, rest): (&str, &str)) {
    let dir = scratch(&format!("save-{scene}-{}-{cut}", extra.join("")));
    let state = dir.join("state.json");
    fn with<'a>(more: &[&'a str], extra: &[&'a str]) -> Vec<&'a str> {
        [more, extra].concat()
    }
    let total = (cut.parse::<f64>().unwrap() + rest.parse::<f64>().unwrap()).to_string();
    run_to(
        &dir,
        "straight",
        &with(&[scene, "--duration", &total], extra),
    );
    run_to(
        &dir,
        "first",
        &with(
            &[scene, "--duration", cut, "--save-state", path(&state)],
            extra,
        ),
    );
    run_to(&dir, "second", &[path(&state), "--duration", rest]);
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
        check(scene, &[]);
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
fn a_character_continues_from_anywhere_on_its_course() {
    // The character's position, fall, last velocity and ground are saved with its path:
    // cut on the ramp, in the air off the stairs' top and on the flat before the crate,
    // the saved course goes on byte for byte (the character's body is in every file).
    for (cut, rest) in [("2.5", "1"), ("4.3", "0.7"), ("8.05", "1.5")] {
        check_cut("character_course", &[], (cut, rest));
    }
    // Cut mid-fall (dropped from 3 m, 0.3 s into its 0.78 s fall): the saved fall speed
    // and the lack of ground carry it on; found afresh they would restart the fall.
    let dir = scratch("save-character-falling");
    let scene = dir.join("drop.json");
    std::fs::write(
        &scene,
        r#"{"dt": 0.01, "bodies": [{"name": "floor", "kind": "static",
              "shape": {"type": "plane", "normal": [0, 1, 0]}}],
            "character": {"name": "walker", "position": [0, 3.9, 0],
              "path": [{"until": 5, "velocity": [1, 0, 0]}]}}"#,
    )
    .unwrap();
    check_cut(path(&scene), &[], ("0.3", "1"));
}
