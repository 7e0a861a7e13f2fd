//! `tumble sweep`: the table's layout and order, its numbers against closed forms, failed
//! runs kept with their parameters, and every refusal one line with exit status 2.

use crate::common;

use crate::common::{one_line, stdout, tumble};

/// Rounding of simulated values: f32 builds carry about 7 digits (5 m at 1e-6 relative,
/// summed over 40 steps), f64 about 16.
const TOL: f64 = if std::mem::size_of::<tumble::Real>() == 4 {
    1e-4
} else {
    1e-12
};

fn table(args: &[&str]) -> Vec<Vec<String>> {
    let out = tumble(args);
    assert_eq!(out.status.code(), Some(0), "{}", common::stderr(&out));
    stdout(&out).lines().map(cells).collect()
}

/// A CSV line's cells (quoted cells may hold commas; no quotes inside them here).
fn cells(line: &str) -> Vec<String> {
    let (mut out, mut cell, mut quoted) = (Vec::new(), String::new(), false);
    for ch in line.chars() {
        match ch {
            '"' => quoted = !quoted,
            ',' if !quoted => out.push(std::mem::take(&mut cell)),
            _ => cell.push(ch),
        }
    }
    out.push(cell);
    out
}

#[test]
fn free_fall_grid_against_symplectic_euler() {
    // Symplectic Euler from rest takes y_n = y0 - g h² n (n + 1) / 2 exactly (up to
    // rounding, TOL): each row must be its own (g, h), in the grid's order.
    let rows = table(&[
        "sweep",
        "free_fall",
        "--set",
        "gravity=[0,-9.8,0],[0,-2,0]",
        "--set",
        "dt=0.01,0.02",
        "--metric",
        "ball.y",
        "--metric",
        "ball.vy",
        "--metric",
        "time",
        "--duration",
        "0.4",
        "--quiet",
    ]);
    assert_eq!(
        rows[0],
        ["gravity", "dt", "ball.y", "ball.vy", "time", "error"]
    );
    assert_eq!(rows.len(), 5);
    let cases = [(9.8, 0.01), (9.8, 0.02), (2.0, 0.01), (2.0, 0.02)];
    for (row, (g, h)) in rows[1..].iter().zip(cases) {
        let n = (0.4f64 / h).round();
        let y: f64 = row[2].parse().unwrap();
        let vy: f64 = row[3].parse().unwrap();
        assert!(
            (y - (5.0 - g * h * h * n * (n + 1.0) / 2.0)).abs() < TOL,
            "{row:?}"
        );
        assert!((vy + g * h * n).abs() < TOL, "{row:?}");
        assert!((row[4].parse::<f64>().unwrap() - 0.4).abs() < TOL);
        assert_eq!(row[5], "");
    }
}

#[test]
fn bounce_heights_follow_restitution() {
    // A ball dropped from 1 m (its bottom) onto the ground rises after the bounce to
    // about e² m at t = 0.4518 (1 + e) s. Measured there, within 0.06 m (the contact's
    // slop, soft contact and the step's discretisation), where the other restitution
    // would be 0.39 m off. max_y is the start, 1.1 m: the ball never rises above it.
    let scene = r#"{"dt": 0.002, "bodies": [
        {"kind": "static", "shape": {"type": "plane", "normal": [0, 1, 0]}},
        {"name": "ball", "shape": {"type": "sphere", "radius": 0.1}, "mass": 1,
         "position": [0, 1.1, 0], "restitution": 0.5}]}"#;
    let dir = std::env::temp_dir().join(format!("tumble-sweep-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("bounce.json");
    std::fs::write(&path, scene).unwrap();
    // Falls 1 m in 0.4518 s, then rises for e·0.4518 s: at 0.4518 (1 + e) s it is at its apex.
    for e in [0.5, 0.8] {
        let t = 0.4518 * (1.0 + e);
        let rows = table(&[
            "sweep",
            path.to_str().unwrap(),
            "--set",
            &format!("bodies[ball].restitution={e}"),
            "--metric",
            "ball.y",
            "--metric",
            "ball.max_y",
            "--duration",
            &t.to_string(),
            "--quiet",
        ]);
        let apex: f64 = rows[1][1].parse::<f64>().unwrap() - 0.1;
        assert!((apex - e * e).abs() < 0.06, "e = {e}: apex {apex}");
        assert_eq!(rows[1][2], "1.1");
    }
    // The table cannot overwrite the scene it reads.
    let scene = path.to_str().unwrap();
    let line = one_line(
        2,
        &[
            "sweep", scene, "--set", "dt=0.01", "--metric", "time", "--out", scene,
        ],
    );
    assert!(
        line.starts_with("out: '") && line.ends_with("is the scene being read; name another file"),
        "{line}"
    );
    // --out writes the same table as standard output.
    let table = dir.join("table.csv");
    let args = [
        "sweep",
        scene,
        "--set",
        "dt=0.01,0.02",
        "--metric",
        "ball.y",
        "--quiet",
    ];
    let printed = stdout(&tumble(&args));
    let out = tumble(&[&args[..], &["--out", table.to_str().unwrap()]].concat());
    assert_eq!(out.status.code(), Some(0));
    assert_eq!(std::fs::read_to_string(&table).unwrap(), printed);
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn failed_runs_keep_their_parameters() {
    let rows = table(&[
        "sweep",
        "free_fall",
        "--set",
        "bodies[0].shape.radius=0.2,-1,0.3",
        "--metric",
        "ball.y",
        "--quiet",
    ]);
    assert_eq!(rows[2], ["-1", "", "bodies[0].shape.radius: must be > 0"]);
    assert_eq!(rows[1][2], "");
    assert_eq!(rows[3][2], "");
}

#[test]
fn refusals_are_one_line() {
    let cases: [(&[&str], &str); 5] = [
        (
            &["--set", "bodies[bal].mass=1", "--metric", "time"],
            "bodies[bal]: no body named 'bal'",
        ),
        (
            &["--set", "bodies[2].mass=1", "--metric", "time"],
            "bodies[2]: index out of range (bodies has 1 entry)",
        ),
        (
            &["--set", "dt.x=1", "--metric", "time"],
            "dt: not an object, cannot take .x",
        ),
        (
            &["--set", "=1", "--metric", "time"],
            "set: expected PATH=V1,V2,..., got '=1'",
        ),
        (
            &["--set", "dt=1", "--metric", "ball.z", "--duration=-1"],
            "duration: must be a finite number >= 0, got -1",
        ),
    ];
    for (args, want) in cases {
        let mut all = vec!["sweep", "free_fall"];
        all.extend_from_slice(args);
        assert_eq!(one_line(2, &all), want);
    }
    let line = one_line(
        2,
        &["sweep", "free_fall", "--set", "dt=1", "--metric", "ball.h"],
    );
    assert!(
        line.starts_with("metric: unknown metric 'ball.h'"),
        "{line}"
    );
}
