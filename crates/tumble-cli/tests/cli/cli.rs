//! The `tumble` binary end to end: output formats, exit codes, determinism.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use tumble::{Integrator, Real};

/// Tolerance on simulated values; f32 builds carry about 7 digits.
const TOL: f64 = if std::mem::size_of::<tumble::Real>() == 4 {
    1e-4
} else {
    1e-9
};

fn tumble(args: &[&str]) -> Output {
    match Command::new(env!("CARGO_BIN_EXE_tumble"))
        .args(args)
        .output()
    {
        Ok(out) => out,
        Err(e) => panic!("cannot start tumble: {e}"),
    }
}

fn stdout(out: &Output) -> String {
    String::from_utf8_lossy(&out.stdout).into_owned()
}

fn stderr(out: &Output) -> String {
    String::from_utf8_lossy(&out.stderr).into_owned()
}

/// Runs `tumble` and requires success.
fn ok(args: &[&str]) -> String {
    let out = tumble(args);
    assert!(out.status.success(), "tumble {args:?}: {}", stderr(&out));
    stdout(&out)
}

/// Runs `tumble`, requires exit status 2 and one line on stderr, and returns that line.
fn refused(args: &[&str]) -> String {
    let out = tumble(args);
    assert_eq!(
        out.status.code(),
        Some(2),
        "tumble {args:?}: {}",
        stderr(&out)
    );
    let err = stderr(&out);
    assert_eq!(err.lines().count(), 1, "not one line: {err:?}");
    assert!(err.ends_with('\n'));
    err.trim_end().to_string()
}

/// A fresh directory for one test's files.
fn scratch(test: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("tumble-cli-{}-{test}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn path(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// The rows of a CSV file below its header, split into fields.
fn rows(file: &Path) -> (String, Vec<Vec<String>>) {
    let text = std::fs::read_to_string(file).unwrap();
    let mut lines = text.lines();
    let header = lines.next().unwrap().to_string();
    let rows = lines
        .map(|l| l.split(',').map(str::to_string).collect())
        .collect();
    (header, rows)
}

fn num(field: &str) -> f64 {
    field
        .parse()
        .unwrap_or_else(|_| panic!("not a number: {field}"))
}

#[test]
fn bare_tumble_is_tumble_run() {
    assert_eq!(ok(&[]), ok(&["run"]));
}

#[test]
fn no_scene_prints_the_seed_table() {
    let text = ok(&["run"]);
    let row = |t: &str| -> Vec<f64> {
        let line = text
            .lines()
            .find(|l| l.split_whitespace().next() == Some(t))
            .unwrap_or_else(|| panic!("no row for t = {t} in\n{text}"));
        line.split_whitespace().map(num).collect()
    };
    let rows = text
        .lines()
        .filter(|l| l.trim_start().starts_with(|c: char| c.is_ascii_digit()));
    assert_eq!(rows.count(), 11, "{text}");
    assert_eq!(row("0.000"), [0.0, 5.0, 5.0, 0.0]);
    // Symplectic Euler: v_n = -g h n, y_n = 5 - g h² n(n+1)/2; at n = 100, 0.051 m.
    let n = 100.0;
    let discrete = 5.0 - 9.8 * 0.01 * 0.01 * n * (n + 1.0) / 2.0;
    let last = row("1.000");
    assert!((last[1] - discrete).abs() < TOL, "{last:?} vs {discrete}");
    assert!((last[2] - 0.1).abs() < TOL);
    assert!((last[3] - (discrete - 0.1)).abs() < 1e-3);
    let summary = text.lines().last().unwrap();
    assert!(
        summary.starts_with("after 100 steps (t = 1 s): height "),
        "{summary}"
    );
    assert!((summary_height(&text) - discrete).abs() < 1e-5);
}

/// The height in the seed table's last line, `after N steps (t = T s): height H m, ...`.
fn summary_height(text: &str) -> f64 {
    let summary = text.lines().last().unwrap_or_default();
    let height = summary
        .split("height ")
        .nth(1)
        .and_then(|s| s.split(' ').next());
    num(height.unwrap_or_else(|| panic!("no height in {summary}")))
}

#[test]
fn options_override_the_scene() {
    // RK4 integrates constant gravity exactly: the error column is round-off.
    let text = ok(&["run", "--integrator", "rk4", "--dt", "0.05"]);
    assert!(text
        .lines()
        .last()
        .unwrap()
        .starts_with("after 20 steps (t = 1 s): "));
    assert!((summary_height(&text) - 0.1).abs() < TOL, "{text}");
    assert!(text.contains("(rk4, dt = 0.05 s)"), "{text}");
    let quiet = ok(&["run", "spring", "--quiet", "--steps", "3"]);
    assert_eq!(quiet, "");
}

#[test]
fn trajectory_csv_has_the_header_the_rows_and_the_initial_state() {
    let dir = scratch("trajectory");
    let out = dir.join("traj.csv");
    ok(&[
        "run",
        "double_spring",
        "--out",
        path(&out),
        "--every",
        "100",
        "--quiet",
    ]);
    let (header, rows) = rows(&out);
    assert_eq!(header, "time,body,x,y,z,qx,qy,qz,qw,vx,vy,vz,wx,wy,wz");
    // 5 s at dt 0.005: 1000 steps, recorded at 0, 100, ..., 1000; three bodies each.
    assert_eq!(rows.len(), 11 * 3);
    let labels: Vec<&str> = rows[..3].iter().map(|r| r[1].as_str()).collect();
    assert_eq!(labels, ["ceiling", "upper", "lower"]);
    let initial: Vec<Vec<f64>> = rows[..3]
        .iter()
        .map(|r| r.iter().skip(2).map(|f| num(f)).collect())
        .collect();
    let at_rest =
        |x: f64, y: f64| vec![x, y, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0];
    assert_eq!(
        initial,
        [at_rest(0.0, 5.0), at_rest(0.0, 4.0), at_rest(0.5, 3.0)]
    );
    assert!(rows[..3].iter().all(|r| r[0] == "0"));
    assert!(rows[30..].iter().all(|r| num(&r[0]) == 5.0));
    // The static ceiling never moves.
    assert_eq!(rows[30][2..9], rows[0][2..9]);
    std::fs::remove_dir_all(dir).unwrap();
}

#[test]
fn every_keeps_the_first_and_last_steps() {
    let dir = scratch("every");
    let out = dir.join("traj.csv");
    // 500 steps recorded every 7th: 0, 7, ..., 497 (72 rows) and the last, 500.
    ok(&["run", "spring", "--out", path(&out), "--every", "7", "-q"]);
    let (_, rows) = rows(&out);
    assert_eq!(rows.len(), 500 / 7 + 2);
    let times: Vec<f64> = rows.iter().map(|r| num(&r[0])).collect();
    assert_eq!(times[0], 0.0);
    assert!((times[1] - 0.07).abs() < 1e-6);
    assert_eq!(*times.last().unwrap(), 5.0);
    // When the last step is a multiple of K it is not written twice.
    ok(&["run", "spring", "--out", path(&out), "--every", "100", "-q"]);
    assert_eq!(rows_of(&out), 6);
    ok(&["run", "spring", "--out", path(&out), "--steps", "4", "-q"]);
    assert_eq!(rows_of(&out), 5);
    std::fs::remove_dir_all(dir).unwrap();
}

fn rows_of(file: &Path) -> usize {
    rows(file).1.len()
}

#[test]
fn a_fractional_duration_ends_exactly_on_time() {
    let dir = scratch("fraction");
    let out = dir.join("traj.csv");
    ok(&[
        "run",
        "free_fall",
        "--duration",
        "0.055",
        "--out",
        path(&out),
        "-q",
    ]);
    let (_, rows) = rows(&out);
    let times: Vec<f64> = rows.iter().map(|r| num(&r[0])).collect();
    assert_eq!(times.len(), 7);
    assert!((times[5] - 0.05).abs() < 1e-6);
    assert!((times[6] - 0.055).abs() < 1e-6, "{times:?}");
    std::fs::remove_dir_all(dir).unwrap();
}

#[test]
fn diagnostics_csv_has_its_header_and_a_row_per_recorded_step() {
    let dir = scratch("diagnostics");
    let diag = dir.join("diag.csv");
    let text = ok(&[
        "run",
        "spring",
        "--diagnostics",
        path(&diag),
        "--every",
        "50",
    ]);
    let (header, rows) = rows(&diag);
    assert_eq!(header, "time,kinetic,potential,total,px,py,pz,lx,ly,lz");
    assert_eq!(rows.len(), 11);
    // At rest at first: all the energy is potential, gravity plus the stretched spring.
    let first: Vec<f64> = rows[0].iter().map(|f| num(f)).collect();
    let potential = 1.0 * 9.8 * 3.5 + 0.5 * 100.0 * 0.5 * 0.5;
    assert!((first[2] - potential).abs() < TOL * 50.0, "{first:?}");
    assert_eq!(first[1], 0.0);
    assert!(
        text.contains(&format!("wrote '{}' (11 rows)", path(&diag))),
        "{text}"
    );
    std::fs::remove_dir_all(dir).unwrap();
}

#[test]
fn two_runs_write_identical_bytes() {
    let dir = scratch("determinism");
    let run = |tag: &str| {
        let (t, d) = (
            dir.join(format!("t{tag}.csv")),
            dir.join(format!("d{tag}.csv")),
        );
        ok(&[
            "run",
            "dumbbell",
            "--out",
            path(&t),
            "--diagnostics",
            path(&d),
            "-q",
        ]);
        (std::fs::read(t).unwrap(), std::fs::read(d).unwrap())
    };
    let (a, b) = (run("a"), run("b"));
    assert!(a == b, "two runs of the same scene differ");
    std::fs::remove_dir_all(dir).unwrap();
}

#[test]
fn a_bad_scene_file_is_one_line_naming_the_field() {
    let dir = scratch("bad-scene");
    let file = dir.join("bad.json");
    let bodies = r#"{"bodies": [{"shape": {"type": "sphere", "radius": 1}},
        {"shape": {"type": "sphere", "radius": 1}}, {"shape": {"type": "sphere", "radius": 1}},
        {"shape": {"type": "sphere", "radius": 0}}]}"#;
    std::fs::write(&file, bodies).unwrap();
    assert_eq!(
        refused(&["run", path(&file)]),
        "bodies[3].shape.radius: must be > 0"
    );
    // Issue 17's body keys are refused the same way.
    for (key, value, rule) in [
        ("linear_damping", "-1", "must be >= 0"),
        ("angular_damping", "-0.5", "must be >= 0"),
        ("gravity_scale", "1e7", "must be at most 1e6 in magnitude"),
    ] {
        let one = format!(
            r#"{{"bodies": [{{"shape": {{"type": "sphere", "radius": 1}}, "{key}": {value}}}]}}"#
        );
        std::fs::write(&file, one).unwrap();
        assert_eq!(
            refused(&["run", path(&file)]),
            format!("bodies[0].{key}: {rule}")
        );
    }
    std::fs::write(&file, "{\"bodies\": [,]}").unwrap();
    assert_eq!(
        refused(&["run", path(&file)]),
        "scene: invalid JSON at line 1 column 13: expected value"
    );
    // Nothing is written when the scene is refused.
    let out = dir.join("traj.csv");
    refused(&["run", path(&file), "--out", path(&out)]);
    assert!(!out.exists());
    std::fs::remove_dir_all(dir).unwrap();
}

#[test]
fn bad_options_are_one_line_and_exit_2() {
    assert_eq!(refused(&["run", "--dt", "0"]), "dt: must be > 0");
    assert_eq!(
        refused(&["run", "spring", "--dt", "-0.1"]),
        "dt: must be > 0"
    );
    assert_eq!(
        refused(&["run", "--every", "0"]),
        "every: must be a whole number >= 1, got '0'"
    );
    assert_eq!(
        refused(&["run", "--duration", "-1"]),
        "duration: must be >= 0"
    );
    assert_eq!(
        refused(&["run", "--integrator", "rk5"]),
        format!(
            "integrator: unknown integrator 'rk5' (expected one of: {})",
            Integrator::names()
        )
    );
    assert!(refused(&["run", "no_such_scene"]).starts_with("scene: 'no_such_scene' is neither"));
    let line = refused(&["run", "--out", "/no/such/dir/traj.csv"]);
    assert!(
        line.starts_with("out: cannot create '/no/such/dir/traj.csv': "),
        "{line}"
    );
    // What clap refuses is one line too (tests/messages.rs has the rest).
    assert_eq!(
        refused(&["run", "--dt", "fast"]),
        "dt: expected a number, got 'fast'"
    );
    assert_eq!(
        refused(&["run", "--duration", "1", "--steps", "3"]),
        "duration: cannot be given together with --steps"
    );
    assert!(refused(&["fly"]).starts_with("command: unknown command 'fly'"));
}

#[test]
fn every_subcommand_has_help() {
    let top = ok(&["--help"]);
    for sub in ["run", "analyze", "scenes"] {
        assert!(top.contains(sub), "{top}");
        let help = ok(&[sub, "--help"]);
        assert!(
            help.starts_with(|c: char| c.is_uppercase()),
            "{sub}: {help}"
        );
    }
    let run = ok(&["run", "--help"]);
    for option in [
        "--duration",
        "--steps",
        "--dt",
        "--integrator",
        "--out",
        "--diagnostics",
    ] {
        assert!(run.contains(option), "{option} missing from\n{run}");
    }
    assert!(run.contains("--every") && run.contains("--quiet") && run.contains("(s)"));
    // The names spelt out in the help must be the real ones.
    for integrator in Integrator::ALL {
        assert!(run.contains(integrator.name()), "{}", integrator.name());
    }
    for scene in tumble_scene::builtin_names() {
        assert!(run.contains(scene), "{scene} missing from run --help");
    }
}

#[test]
fn scenes_lists_the_builtins_and_every_builtin_runs() {
    let list = ok(&["scenes"]);
    for scene in tumble_scene::builtin_names() {
        assert!(list.lines().any(|l| l.starts_with(scene)), "{scene}");
        let text = ok(&["run", scene, "--steps", "20"]);
        assert!(text.contains("20 steps of dt"), "{text}");
        assert!(!text.contains("NaN") && !text.contains("inf"), "{text}");
    }
}

#[test]
fn analyze_tabulates_every_integrator_with_its_observed_order() {
    let table = ok(&["analyze"]);
    for integrator in Integrator::ALL {
        let row = table
            .lines()
            .find(|l| l.split_whitespace().next() == Some(integrator.name()))
            .unwrap_or_else(|| panic!("no row for {}: {table}", integrator.name()));
        let cells: Vec<&str> = row.split_whitespace().collect();
        let theory: f64 = cells[1].parse().unwrap();
        let observed: f64 = cells[2].parse().unwrap();
        assert_eq!(theory, integrator.order() as f64);
        assert!((observed - theory).abs() < 0.2, "{row}");
    }
}

#[test]
fn the_summary_names_final_positions_and_energy() {
    let text = ok(&["run", "planar_spinner"]);
    assert!(text.contains("scene 'planar_spinner': 1 body, 1 force element, symplectic_euler"));
    assert!(
        text.contains("200 steps of dt = 0.01 s, final time 2 s"),
        "{text}"
    );
    assert!(text.contains("  spinner "), "{text}");
    let energy = text
        .lines()
        .find(|l| l.starts_with("total energy (J): start 0."))
        .unwrap();
    // ½ I ω² with ω = τ t / I: (0.5·2)² / (2 I) = 4.41 J for I = 0.11333 kg·m²; symplectic
    // Euler's first-order error shifts it by O(dt).
    let end: Real = energy
        .split("end ")
        .nth(1)
        .unwrap()
        .split(',')
        .next()
        .unwrap()
        .parse()
        .unwrap();
    let exact = 1.0 / (2.0 * 2.0 / 3.0 * (0.16 + 0.01));
    assert!((end - exact).abs() < 0.05 * exact, "{end} vs {exact}");
}

#[test]
fn options_can_rescue_a_scene_too_long_to_run() {
    let dir = scratch("long");
    let file = dir.join("long.json");
    std::fs::write(&file, r#"{"duration": 1e9, "dt": 0.01}"#).unwrap();
    assert!(refused(&["run", path(&file)]).starts_with("duration: needs more than"));
    assert!(ok(&["run", path(&file), "--steps", "2"]).contains("2 steps of dt = 0.01 s"));
    std::fs::remove_dir_all(dir).unwrap();
}

#[test]
fn contacts_lists_every_manifold_point_of_the_initial_state() {
    let text = ok(&["contacts", "resting"]);
    let mut lines = text.lines();
    assert_eq!(
        lines.next(),
        Some("body_a,body_b,x,y,z,nx,ny,nz,separation")
    );
    let rows: Vec<Vec<&str>> = lines.map(|l| l.split(',').collect()).collect();
    let count = |a: &str, b: &str| rows.iter().filter(|r| r[0] == a && r[1] == b).count();
    // Box faces give four points, a ball one, a capsule lying down two.
    assert_eq!(count("ground", "crate"), 4, "{text}");
    assert_eq!(count("crate", "cube"), 4, "{text}");
    assert_eq!(count("ground", "ball"), 1, "{text}");
    assert_eq!(count("ground", "pill"), 2, "{text}");
    assert_eq!(rows.len(), 11, "{text}");
    for r in &rows {
        let n: Vec<f64> = r[5..8].iter().map(|x| num(x)).collect();
        // Everything rests on something below it: the normals point up, from A to B.
        assert!((n[1] - 1.0).abs() < TOL, "{r:?}");
        assert!(num(r[8]).abs() < TOL, "{r:?}");
    }
    assert_eq!(refused(&["contacts", "no_such_scene"]).lines().count(), 1);
}

#[test]
fn runs_with_contacts_write_identical_bytes() {
    let dir = scratch("contacts_determinism");
    let run = |k: usize| {
        let (out, contacts) = (
            dir.join(format!("out{k}.csv")),
            dir.join(format!("contacts{k}.csv")),
        );
        ok(&[
            "run",
            "resting",
            "--out",
            path(&out),
            "--contacts",
            path(&contacts),
            "--quiet",
        ]);
        (
            std::fs::read(out).unwrap(),
            std::fs::read(contacts).unwrap(),
        )
    };
    let (first, second) = (run(1), run(2));
    assert!(first.1.len() > 1000, "hardly any contacts were written");
    assert_eq!(first, second);
}

#[test]
fn joint_reactions_are_written_and_carry_the_load() {
    // The door (0.9 × 2 × 0.04 m of wood at 600 kg/m³: 43.2 kg) hangs on its hinge, which
    // must carry its weight: the force on the frame is m·g down, and the torque about the
    // hinge is m·g times the 0.45 m from the hinge to the door's centre.
    let dir = scratch("joints_csv");
    let file = dir.join("joints.csv");
    ok(&["run", "door", "--joints", path(&file), "--quiet"]);
    let text = std::fs::read_to_string(file).unwrap();
    let mut lines = text.lines();
    assert_eq!(
        lines.next(),
        Some(
            "time,joint,body,other,fx,fy,fz,tx,ty,tz,broken,position,velocity,\
             position_x,position_y,position_z,velocity_x,velocity_y,velocity_z"
        )
    );
    let fields: Vec<String> = lines.last().unwrap().split(',').map(String::from).collect();
    // A hinge: its angle and rate in position and velocity, the vector columns empty.
    assert_eq!(fields.len(), 19);
    assert!(fields[13..].iter().all(|f| f.is_empty()), "{fields:?}");
    let last: Vec<f64> = fields[4..13].iter().map(|x| x.parse().unwrap()).collect();
    let weight = 0.9 * 2.0 * 0.04 * 600.0 * 9.8;
    assert!((last[1] + weight).abs() < 1e-3 * weight, "fy {}", last[1]);
    let torque = (last[3] * last[3] + last[4] * last[4] + last[5] * last[5]).sqrt();
    assert!(
        (torque - 0.45 * weight).abs() < 1e-2 * weight,
        "torque {torque}"
    );
    assert_eq!(last[6], 0.0, "the hinge broke");
    // The motor (1 rad/s) has opened it onto its 90° limit, where it rests.
    assert!(
        (last[7] - std::f64::consts::FRAC_PI_2).abs() < 0.01,
        "angle {}",
        last[7]
    );
    assert!(last[8].abs() < 0.05, "rate {}", last[8]);
}

#[test]
fn slider_and_ball_coordinates_are_written_in_their_columns() {
    // No gravity: a box on a slider along x set moving at 0.5 m/s, and a ball spinning at
    // 2 rad/s about z on a ball joint at its centre (no torque: ω stays). At time t the
    // slider's offset is 0.5 t (its anchors coincide at creation) in `position`, its rate
    // 0.5 in `velocity`, the vector columns empty; the ball's rotation vector is (0, 0, 2t)
    // in `position_x..z` (t = 1 s: under π), its relative ω (0, 0, 2) in `velocity_x..z`,
    // the scalar columns empty. To 1e-9 (free motion, integrated exactly up to rounding).
    let dir = scratch("coordinates_csv");
    let scene = dir.join("coordinates.json");
    std::fs::write(
        &scene,
        r#"{"gravity": [0, 0, 0], "dt": 0.01, "duration": 1.0, "bodies": [
            {"name": "carriage", "position": [0, 1, 0], "velocity": [0.5, 0, 0],
             "shape": {"type": "box", "half_extents": [0.2, 0.1, 0.1]}},
            {"name": "globe", "position": [3, 1, 0], "angular_velocity": [0, 0, 2],
             "shape": {"type": "sphere", "radius": 0.3}}
        ], "joints": [
            {"type": "slider", "name": "rail", "body": "carriage", "axis": [1, 0, 0]},
            {"type": "ball", "name": "pivot", "body": "globe"}
        ]}"#,
    )
    .unwrap();
    let file = dir.join("joints.csv");
    ok(&["run", path(&scene), "--joints", path(&file), "--quiet"]);
    let text = std::fs::read_to_string(file).unwrap();
    let mut seen = 0;
    for line in text.lines().skip(1) {
        let f: Vec<&str> = line.split(',').collect();
        let t: f64 = f[0].parse().unwrap();
        let num = |k: usize| f[k].parse::<f64>().unwrap();
        let close = |k: usize, x: f64| (num(k) - x).abs() < 1e-9;
        match f[1] {
            "rail" => {
                assert!(close(11, 0.5 * t) && close(12, 0.5), "{line}");
                assert!(f[13..].iter().all(|c| c.is_empty()), "{line}");
            }
            "pivot" => {
                assert!(f[11].is_empty() && f[12].is_empty(), "{line}");
                let expected = [0.0, 0.0, 2.0 * t, 0.0, 0.0, 2.0];
                for (k, x) in (13..19).zip(expected) {
                    assert!(close(k, x), "column {k}: {line}");
                }
            }
            other => panic!("unknown joint {other}"),
        }
        seen += 1;
    }
    assert!(seen >= 4, "{seen} rows");
}

#[test]
fn sensor_events_are_written_at_every_step() {
    // A ball of radius 0.1 dropped from y = 5 through a sensor slab y in [1, 2]: it enters
    // when its bottom reaches 2, at t = √(2·2.9/g), and leaves when its top passes 1, at
    // t = √(2·4.1/g); each event lies within a step (dt = 0.01 s) of those times, and both
    // are written though --every records only the first and last steps.
    let dir = scratch("sensors_csv");
    let scene = dir.join("gate.json");
    std::fs::write(
        &scene,
        r#"{"dt": 0.01, "duration": 1.5, "bodies": [
            {"name": "gate", "kind": "static", "sensor": true, "position": [0, 1.5, 0],
             "shape": {"type": "box", "half_extents": [2, 0.5, 2]}},
            {"name": "ball", "position": [0, 5, 0], "shape": {"type": "sphere", "radius": 0.1}}
        ]}"#,
    )
    .unwrap();
    let file = dir.join("sensors.csv");
    let run = |file: &Path| {
        ok(&[
            "run",
            path(&scene),
            "--sensors",
            path(file),
            "--every",
            "1000",
            "--quiet",
        ])
    };
    run(&file);
    let (header, rows) = rows(&file);
    assert_eq!(header, "time,sensor,body,began");
    assert_eq!(rows.len(), 2, "{rows:?}");
    for (row, (drop, began)) in rows.iter().zip([(2.9, "1"), (4.1, "0")]) {
        let t = (2.0 * drop / 9.8_f64).sqrt();
        assert!((num(&row[0]) - t).abs() <= 0.01, "{row:?} vs {t}");
        assert_eq!(row[1..], ["gate", "ball", began]);
    }
    let again = dir.join("again.csv");
    run(&again);
    assert_eq!(
        std::fs::read(&file).unwrap(),
        std::fs::read(&again).unwrap()
    );
    let line = refused(&["run", path(&scene), "--sensors", path(&dir)]);
    assert!(line.starts_with("sensors: '") && line.ends_with("is a folder; name a file"));
    std::fs::remove_dir_all(dir).unwrap();
}

/// `tumble run character_course` walks its character: the walker's rows of the trajectory
/// start where the scene puts it and, 5 s in (at 2 m/s, up the ramp, over the plateau and
/// down the stairs), are past the stairs (x > 8 m) and back on the floor, its centre
/// 0.92 m up (radius + half height + skin, to half a skin); the scene's other bodies stay
/// where they are. A scene file with a bad character is refused in one line.
#[test]
fn the_character_course_walks_its_character() {
    let dir = scratch("character");
    let out = dir.join("walk.csv");
    ok(&[
        "run",
        "character_course",
        "--steps",
        "300",
        "--out",
        path(&out),
        "-q",
    ]);
    let (_, rows) = rows(&out);
    let walker: Vec<&Vec<String>> = rows.iter().filter(|r| r[1] == "walker").collect();
    assert_eq!(walker.len(), 301);
    let (first, last) = (walker[0], walker[300]);
    assert_eq!((num(&first[2]), num(&first[3])), (0.0, 0.92));
    assert!(num(&last[2]) > 8.0, "{last:?}");
    assert!((num(&last[3]) - 0.92).abs() <= 0.01, "{last:?}");
    let ramp: Vec<&Vec<String>> = rows.iter().filter(|r| r[1] == "ramp").collect();
    assert_eq!(ramp.first().unwrap()[2..5], ramp.last().unwrap()[2..5]);
    let bad = dir.join("bad.json");
    std::fs::write(&bad, r#"{"character": {"radius": 0}}"#).unwrap();
    assert_eq!(
        refused(&["run", path(&bad)]),
        "character.radius: must be > 0"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn joint_trees_choose_the_solver_of_joint_trees() {
    // A double pendulum of free hinges hung from the world is a tree: reduced, it moves
    // otherwise than in the soft step (exact joints, another scheme), as the scene key
    // makes it; an unknown way is refused in one line.
    let dir = scratch("joint_trees");
    let scene = |key: &str| {
        let file = dir.join(format!("pendulum{key}.json"));
        let text = format!(
            r#"{{"gravity": [0, -9.81, 0], "dt": 0.01, "sleep": false{key},
            "bodies": [
              {{"name": "a", "shape": {{"type": "box", "half_extents": [0.5, 0.05, 0.05]}},
                "mass": 1.0, "position": [0.5, 0, 0]}},
              {{"name": "b", "shape": {{"type": "box", "half_extents": [0.5, 0.05, 0.05]}},
                "mass": 2.0, "position": [1.5, 0, 0]}}],
            "joints": [
              {{"type": "hinge", "body": "a", "anchor": [-0.5, 0, 0], "axis": [0, 0, 1]}},
              {{"type": "hinge", "body": "b", "other": "a", "anchor": [-0.5, 0, 0],
                "axis": [0, 0, 1]}}]}}"#
        );
        std::fs::write(&file, text).unwrap();
        file
    };
    let plain = scene("");
    let keyed = scene(r#", "joint_trees": "reduced""#);
    let run = |file: &Path, extra: &[&str]| {
        let mut args = vec!["run", path(file), "--steps", "60"];
        args.extend_from_slice(extra);
        ok(&args)
    };
    let (soft, tree) = (run(&plain, &[]), run(&plain, &["--joint-trees", "reduced"]));
    assert_ne!(soft, tree);
    assert_eq!(tree, run(&keyed, &[]));
    assert_eq!(soft, run(&keyed, &["--joint-trees", "maximal"]));
    assert_eq!(
        refused(&["run", "--joint-trees", "featherstone"]),
        "joint_trees: unknown way 'featherstone' (expected one of: maximal, reduced)"
    );
}
