//! `tumble run model.xml`: an MJCF model runs like a scene; a bad one is one line, exit 2.

use std::path::PathBuf;
use std::process::{Command, Output};

fn tumble(args: &[&str]) -> Output {
    match Command::new(env!("CARGO_BIN_EXE_tumble"))
        .args(args)
        .output()
    {
        Ok(out) => out,
        Err(e) => panic!("cannot start tumble: {e}"),
    }
}

fn model(name: &str) -> String {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../tumble-scene/tests/mjcf")
        .join(name)
        .display()
        .to_string()
}

#[test]
fn an_mjcf_model_runs_with_its_bodies_named() {
    let dir = std::env::temp_dir().join(format!("tumble-cli-mjcf-run-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let csv = dir.join("cartpole.csv");
    let out = tumble(&[
        "run",
        &model("cartpole.xml"),
        "--steps",
        "20",
        "--quiet",
        "--out",
        csv.to_str().unwrap(),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = std::fs::read_to_string(&csv).unwrap();
    // A row per body per recorded step, labelled with the file's body names; the file's
    // timestep (1 ms) is the run's dt.
    let last = text.lines().last().unwrap();
    let t: f64 = last.split(',').next().unwrap().parse().unwrap();
    assert!((t - 0.02).abs() < 1e-6, "{last}");
    for name in ["cart", "pole"] {
        assert!(
            text.lines().any(|l| l.split(',').nth(1) == Some(name)),
            "{text}"
        );
    }
}

#[test]
fn a_bad_mjcf_model_is_one_line_and_exit_2() {
    let dir = std::env::temp_dir().join(format!("tumble-cli-mjcf-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("bad.xml");
    std::fs::write(
        &path,
        "<mujoco>\n<worldbody>\n<geom size=\"0\"/>\n</worldbody>\n</mujoco>",
    )
    .unwrap();
    let out = tumble(&["run", path.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(
        err.starts_with("bad.xml:3: <geom>: size: must be > 0"),
        "{err}"
    );
}
