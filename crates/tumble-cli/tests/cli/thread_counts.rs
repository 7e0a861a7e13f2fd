//! Issue 16: the benchmark scenes (the 385-cube pyramid, the rain of 2,000 balls and boxes
//! into a walled box, the 30 × 30 joint grid) and the built-in ragdoll write the same
//! trajectory, byte for byte, on 1, 2, 3 and 8 threads and in every lane mode of the
//! contact passes (`TUMBLE_LANES`: AVX-512 lanes, AVX2 lanes, portable lanes, one manifold at
//! a time; AVX-512 falls back to AVX2 on a CPU without it).
//!
//! Each run is a whole `tumble run` process at the stages' real thresholds, so the splits a
//! user's run takes are the ones checked (tests/threads.rs in the core crate forces every
//! split on small scenes). The CSV holds every body's position and orientation each step,
//! printed so that they read back exactly.

use serde_json::{json, Value};
use std::path::{Path, PathBuf};
use std::process::Command;

/// A scratch folder of this test binary's own.
fn scratch() -> PathBuf {
    let dir = std::env::temp_dir().join(format!("tumble-thread-counts-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn cube(name: String, half: f64, at: [f64; 3], dynamic: bool) -> Value {
    let mut b = json!({"name": name, "shape": {"type": "box", "half_extents": [half, half, half]},
                       "position": at, "friction": 0.5});
    if !dynamic {
        b["kind"] = json!("static");
    }
    b
}

/// The bench's settings: dt 1/60 s, 4 substeps, sleeping off.
fn scene(name: &str, duration: f64, bodies: Vec<Value>, joints: Vec<Value>) -> Value {
    json!({"name": name, "gravity": [0, -9.81, 0], "dt": 1.0 / 60.0, "duration": duration,
           "sleep": false, "bodies": bodies, "joints": joints})
}

/// The bench's pyramid: 10 layers of unit cubes, 385 bodies.
fn pyramid() -> Value {
    let mut bodies = vec![json!({"name": "ground", "kind": "static",
                                 "shape": {"type": "plane", "normal": [0, 1, 0]}})];
    for k in 0..10 {
        let n = 10 - k;
        let first = -0.5 * (n as f64 - 1.0);
        for i in 0..n {
            for j in 0..n {
                let at = [first + i as f64, 0.5 + k as f64, first + j as f64];
                bodies.push(cube(format!("c{k}_{i}_{j}"), 0.5, at, true));
            }
        }
    }
    scene("pyramid", 1.0, bodies, vec![])
}

/// The bench's rain, in its shape: 1,000 balls and 1,000 cubes of 0.25 m in a 10 × 10 × 20
/// grid, jittered, above a floor walled 10 m × 10 m.
fn rain() -> Value {
    let mut bodies = vec![cube("floor".into(), 20.0, [0.0, -20.0, 0.0], false)];
    for (x, z, hx, hz) in [
        (5.25, 0.0, 0.25, 5.5),
        (-5.25, 0.0, 0.25, 5.5),
        (0.0, 5.25, 5.5, 0.25),
        (0.0, -5.25, 5.5, 0.25),
    ] {
        bodies.push(json!({"name": format!("wall{x}{z}"), "kind": "static",
                           "shape": {"type": "box", "half_extents": [hx, 1.5, hz]},
                           "position": [x, 1.5, z]}));
    }
    let mut seed: u64 = 7;
    let mut jitter = || {
        seed = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((seed >> 33) as f64 / (1u64 << 31) as f64 - 0.5) * 0.2
    };
    for i in 0..2000 {
        let (x, z, y) = (i % 10, (i / 10) % 10, i / 100);
        let at = [
            x as f64 - 4.5 + jitter(),
            4.0 + 0.7 * y as f64,
            z as f64 - 4.5 + jitter(),
        ];
        bodies.push(if i % 2 == 0 {
            json!({"name": format!("b{i}"), "shape": {"type": "sphere", "radius": 0.25},
                   "position": at, "friction": 0.5})
        } else {
            cube(format!("b{i}"), 0.25, at, true)
        });
    }
    scene("rain", 1.5, bodies, vec![])
}

/// The bench's joint grid: 30 × 30 balls 1 m apart joined to their +x and +z neighbours
/// by ball joints, hanging from nine fixed balls of the first row.
fn joint_grid() -> Value {
    let n = 30;
    let name = |r: usize, c: usize| format!("n{r}_{c}");
    let fixed = |r: usize, c: usize| r == 0 && (c % 4 == 0 || c == n - 1);
    let mut bodies = Vec::new();
    for r in 0..n {
        for c in 0..n {
            let mut b = json!({"name": name(r, c), "shape": {"type": "sphere", "radius": 0.4},
                               "position": [c as f64 - 14.5, 0.0, r as f64]});
            if fixed(r, c) {
                b["kind"] = json!("static");
            }
            bodies.push(b);
        }
    }
    let mut joints = Vec::new();
    for r in 0..n {
        for c in 0..n {
            for (r2, c2, d) in [(r, c + 1, [0.5, 0.0, 0.0]), (r + 1, c, [0.0, 0.0, 0.5])] {
                if r2 < n && c2 < n && !(fixed(r, c) && fixed(r2, c2)) {
                    joints.push(json!({"type": "ball", "body": name(r, c), "anchor": d,
                                       "other": name(r2, c2),
                                       "other_anchor": [-d[0], -d[1], -d[2]]}));
                }
            }
        }
    }
    scene("joints", 1.0, bodies, joints)
}

/// The trajectory CSV of `scene` on `threads` threads in lane mode `lanes`.
fn trajectory(scene: &Path, threads: usize, lanes: &str, dir: &Path) -> Vec<u8> {
    let out = dir.join(format!("{}-{threads}-{lanes}.csv", scene.display()).replace('/', "_"));
    let status = Command::new(env!("CARGO_BIN_EXE_tumble"))
        .args([
            "run",
            scene.to_str().unwrap(),
            "--quiet",
            "--threads",
            &threads.to_string(),
        ])
        .arg("--out")
        .arg(&out)
        .env("TUMBLE_LANES", lanes)
        .status()
        .unwrap();
    assert!(
        status.success(),
        "{} on {threads} threads, {lanes}",
        scene.display()
    );
    let bytes = std::fs::read(&out).unwrap();
    std::fs::remove_file(&out).unwrap();
    bytes
}

#[test]
fn benchmark_scenes_write_the_same_bytes_on_every_thread_count_and_lane_mode() {
    let dir = scratch();
    let mut scenes = vec![PathBuf::from("ragdoll")];
    for (name, s) in [
        ("pyramid", pyramid()),
        ("rain", rain()),
        ("joints", joint_grid()),
    ] {
        let path = dir.join(format!("{name}.json"));
        std::fs::write(&path, serde_json::to_string(&s).unwrap()).unwrap();
        scenes.push(path);
    }
    for scene in &scenes {
        let reference = trajectory(scene, 1, "avx2", &dir);
        assert!(
            reference.len() > 10_000,
            "{}: a short trajectory",
            scene.display()
        );
        let runs = [
            (1, "avx512"),
            (2, "avx512"),
            (3, "avx2"),
            (8, "avx2"),
            (1, "portable"),
            (8, "portable"),
            (1, "scalar"),
            (3, "scalar"),
        ];
        for (threads, lanes) in runs {
            let other = trajectory(scene, threads, lanes, &dir);
            assert!(
                other == reference,
                "{}: {threads} threads in lane mode {lanes} differ from 1 thread, avx2",
                scene.display()
            );
        }
    }
    std::fs::remove_dir_all(&dir).unwrap();
}
