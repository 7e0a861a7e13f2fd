//! Snapshots (issue 18) on every built-in scene and every integrator: 2 s straight equals
//! 1 s, snapshot, restore into a fresh world, 1 s — bit for bit.
//!
//! The oracle is twofold: the state hash (every body's state bits) after every step of
//! the second second, and the snapshot bytes at the end, which hold everything else a
//! world keeps (contacts with warm starts and anchors, broad-phase trees, sleep timers,
//! islands, joint impulses, integrator memory). Equal bytes mean equal worlds.

use tumble::{Integrator, World};
use tumble_scene::{builtin_names, load, Scene};

/// Steps `scene` `n` times by its own `dt`, recording the state hash after each step; a
/// failed step (an explicit integrator may blow a stiff scene up: that is the method, not
/// the snapshot) is recorded by its message and ends the run.
fn run(scene: &mut Scene, n: usize, out: &mut Vec<String>) {
    for _ in 0..n {
        match scene.step(scene.dt) {
            Ok(()) => out.push(format!("{:016x}", scene.world.state_hash())),
            Err(e) => {
                out.push(e.to_string());
                return;
            }
        }
    }
}

fn scene(name: &str, integrator: Integrator) -> Scene {
    let mut s = load(name).unwrap();
    s.world.set_integrator(integrator);
    s
}

/// Runs `name` 2 s straight and 1 s + snapshot + restore into a fresh world + 1 s, and
/// compares the second seconds step by step and the worlds at the end.
fn check_scene(name: &str, integrator: Integrator) {
    let mut straight = scene(name, integrator);
    let half = (1.0 / straight.dt).round() as usize;
    let mut before = Vec::new();
    run(&mut straight, half, &mut before);
    let bytes = straight.world.snapshot();
    let walker = straight.character.clone();
    let mut first = Vec::new();
    run(&mut straight, half, &mut first);

    let mut resumed = scene(name, integrator);
    resumed.world = World::from_snapshot(&bytes).unwrap();
    // The character's walker is the scene's, not the world's: carried over as is.
    resumed.character = walker;
    assert_eq!(
        resumed.world.snapshot(),
        bytes,
        "{name}: restore is not exact"
    );
    let mut second = Vec::new();
    run(&mut resumed, half, &mut second);
    assert_eq!(first, second, "{name} with {integrator:?}: runs differ");
    assert_eq!(
        straight.world.snapshot(),
        resumed.world.snapshot(),
        "{name} with {integrator:?}: worlds differ after 1 s more"
    );
    assert_eq!(straight.world.time(), resumed.world.time());
}

#[test]
fn every_builtin_scene_continues_bit_identically_with_every_integrator() {
    let names = builtin_names();
    assert!(names.len() >= 14, "the scenes are all there");
    for name in names {
        for integrator in Integrator::ALL {
            check_scene(name, integrator);
        }
    }
}

#[test]
fn a_snapshot_restored_into_the_world_it_came_from_rewinds_it() {
    // Rollback: the pyramid 0.5 s on, then back to the snapshot and on again, twice.
    let mut s = load("pyramid").unwrap();
    run(&mut s, 50, &mut Vec::new());
    let bytes = s.world.snapshot();
    let mut once = Vec::new();
    run(&mut s, 30, &mut once);
    s.world.restore(&bytes).unwrap();
    let mut again = Vec::new();
    run(&mut s, 30, &mut again);
    assert_eq!(once, again);
    assert_eq!(s.world.step_count(), 80);
}

/// Saves `scene` with its state after 1 s, loads the text back, and checks that 1 s more
/// of each is the same run.
fn check_saved(name: &str, integrator: Integrator) {
    let mut straight = scene(name, integrator);
    let half = (1.0 / straight.dt).round() as usize;
    run(&mut straight, half, &mut Vec::new());
    let text = tumble_scene::save_scene(&straight);
    let mut loaded = tumble_scene::load_str(&text).unwrap();
    assert_eq!(loaded.world.snapshot(), straight.world.snapshot(), "{name}");
    assert_eq!(loaded.body_names, straight.body_names, "{name}");
    assert_eq!(
        (loaded.dt, loaded.duration),
        (straight.dt, straight.duration)
    );
    // The character is saved too: where it is, its fall, its ground, its path.
    let kept = |s: &Scene| {
        s.character.as_ref().map(|w| {
            let c = &w.controller;
            (
                c.position(),
                c.ground(),
                c.velocity(),
                w.fall,
                w.path.clone(),
            )
        })
    };
    assert_eq!(kept(&loaded), kept(&straight), "{name}");
    let (mut first, mut second) = (Vec::new(), Vec::new());
    run(&mut straight, half, &mut first);
    run(&mut loaded, half, &mut second);
    assert_eq!(first, second, "{name} with {integrator:?}");
    assert_eq!(straight.world.snapshot(), loaded.world.snapshot(), "{name}");
}

#[test]
fn a_saved_scene_with_its_state_runs_on_bit_identically() {
    for name in builtin_names() {
        check_saved(name, load(name).unwrap().world.integrator());
    }
    for integrator in Integrator::ALL {
        check_saved("ragdoll", integrator);
    }
}

#[test]
fn a_saved_scene_without_state_is_the_same_scene_at_the_saved_poses() {
    // Without `state` the file is a fresh scene: every key reads back to the same bits
    // (shapes, materials, mass, inertia, settings, velocities), and positions to within
    // the rounding of body origin -> centre of mass -> body origin (a few ulps).
    let mut s = load("ragdoll").unwrap();
    run(&mut s, 30, &mut Vec::new());
    let options = tumble_scene::SaveOptions {
        state: false,
        dt: s.dt,
        duration: s.duration,
        ..Default::default()
    };
    let text = tumble_scene::save_with(&s.world, &options);
    assert!(!text.contains("\"state\""));
    let loaded = load_str_ok(&text);
    let (a, b) = (&s.world, &loaded.world);
    assert_eq!(a.body_count(), b.body_count());
    assert_eq!(a.joints().count(), b.joints().count());
    assert_eq!(a.forces().count(), b.forces().count());
    assert_eq!(a.solver_settings(), b.solver_settings());
    assert_eq!(a.integrator(), b.integrator());
    assert_eq!(a.length_unit(), b.length_unit());
    for (&ia, &ib) in a.body_ids().iter().zip(b.body_ids()) {
        let (x, y) = (a.body(ia).unwrap(), b.body(ib).unwrap());
        assert_eq!(x.shape(), y.shape());
        assert_eq!(x.name(), y.name());
        assert_eq!(x.mass().to_bits(), y.mass().to_bits());
        assert_eq!(x.inertia_local(), y.inertia_local());
        assert_eq!(x.linear_velocity(), y.linear_velocity());
        assert_eq!(x.friction(), y.friction());
        // Two roundings of a sum of |x| + |q·c| (centre offsets under 1 m here): 8 ulps.
        let eps = 8.0 * tumble::Real::EPSILON;
        let tol = eps * (1.0 + x.position().length());
        assert!((x.position() - y.position()).length() <= tol);
        assert!(x.orientation().dot(y.orientation()) >= 1.0 - eps);
    }
    for ((_, x), (_, y)) in a.joints().zip(b.joints()) {
        assert_eq!(x.def(), y.def());
    }
}

fn load_str_ok(text: &str) -> Scene {
    tumble_scene::load_str(text).unwrap()
}

#[test]
fn a_bad_state_section_names_the_field() {
    let s = load("spring").unwrap();
    let text = tumble_scene::save_scene(&s);
    let start = text.find("\"state\": \"").unwrap() + 10;
    let end = start + text[start..].find('"').unwrap();
    let with = |state: &str| format!("{}{state}{}", &text[..start], &text[end..]);
    let err = |t: String| tumble_scene::load_str(&t).unwrap_err().to_string();
    assert_eq!(
        err(with("zz")),
        "state: expected hex digits, not 'z' at character 0"
    );
    assert_eq!(
        err(with("abc")),
        "state: expected an even number of hex digits, got 3"
    );
    assert_eq!(err(with("00")), "state: snapshot: truncated at byte 1");
    let cut = &text[start..end - 2];
    let n = cut.len() / 2;
    assert_eq!(
        err(with(cut)),
        format!("state: snapshot: truncated at byte {n}")
    );
}

#[test]
fn forces_and_joints_may_name_a_body_by_its_index() {
    let text = r#"{"bodies": [
        {"shape": {"type": "sphere", "radius": 0.1}, "position": [0, 1, 0]},
        {"shape": {"type": "sphere", "radius": 0.1}, "position": [1, 1, 0]}],
      "forces": [{"type": "spring", "body": 0, "other": 1, "stiffness": 10}],
      "joints": [{"type": "distance", "body": 1}]}"#;
    let s = load_str_ok(text);
    assert_eq!(s.world.forces().count(), 1);
    let bad = text.replace("\"other\": 1", "\"other\": 2");
    assert_eq!(
        tumble_scene::load_str(&bad).unwrap_err().to_string(),
        "forces[0].other: no body at index 2 (there are 2)"
    );
}

/// Excluded pairs (`exclude`, by name or index) are saved with the scene, with and
/// without its state: the loaded world keeps the same pairs apart and runs on as the
/// original, bit for bit (a small ball falls through a big unnamed one onto the floor).
#[test]
fn excluded_pairs_are_saved_and_loaded() {
    let text = r#"{"dt": 0.01, "bodies": [
        {"name": "floor", "kind": "static", "shape": {"type": "plane", "normal": [0, 1, 0]}},
        {"shape": {"type": "sphere", "radius": 0.5}, "position": [0, 0.5, 0]},
        {"name": "ball", "shape": {"type": "sphere", "radius": 0.1}, "position": [0, 2, 0]}],
      "exclude": [["ball", 1]]}"#;
    let mut original = load_str_ok(text);
    for _ in 0..30 {
        original.world.step(0.01).unwrap();
    }
    for state in [true, false] {
        let options = tumble_scene::SaveOptions {
            state,
            ..Default::default()
        };
        let saved = tumble_scene::save_with(&original.world, &options);
        assert!(saved.contains("\"exclude\": [[1, \"ball\"]]"), "{saved}");
        let mut loaded = load_str_ok(&saved).world;
        assert_eq!(
            loaded.excluded_contacts(),
            original.world.excluded_contacts()
        );
        let mut twin = World::from_snapshot(&original.world.snapshot()).unwrap();
        for _ in 0..120 {
            loaded.step(0.01).unwrap();
            twin.step(0.01).unwrap();
        }
        let ball = loaded.find_body("ball").unwrap();
        let y = loaded.body(ball).unwrap().position().y;
        assert!((y - 0.1).abs() < 5e-3, "state {state}: the ball at {y}");
        if state {
            assert_eq!(loaded.state_hash(), twin.state_hash());
        }
    }
}
