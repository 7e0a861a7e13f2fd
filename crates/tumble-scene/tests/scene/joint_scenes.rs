//! The joint scenes and the `joints` key: what each built-in joint scene must show, and how
//! joints read from a scene file.

// Casts between Real and f64 are no-ops in the default build but needed in the f32 one.
#![allow(clippy::unnecessary_cast)]

use tumble::prelude::*;
use tumble_scene::{load, load_str};

/// Steps a loaded scene for its whole duration, returning the largest joint gap seen.
fn run_scene(name: &str) -> (tumble_scene::Scene, Real) {
    let mut scene = load(name).unwrap();
    let steps = (scene.duration / scene.dt).round() as usize;
    let mut worst: Real = 0.0;
    for _ in 0..steps {
        scene.world.step(scene.dt).unwrap();
        worst = worst.max(joint_gap(&scene.world));
    }
    (scene, worst)
}

/// The largest distance between the two anchors of any unbroken joint that holds them
/// together (distance joints keep them apart, see `rope_lengths`).
fn joint_gap(w: &World) -> Real {
    w.joints()
        .filter(|(_, j)| !j.is_broken() && !matches!(j.kind(), JointKind::Distance { .. }))
        .map(|(_, j)| anchor_distance(w, j))
        .fold(0.0, Real::max)
}

/// How far apart a joint's two anchors are now.
fn anchor_distance(w: &World, j: &tumble::Joint) -> Real {
    let d = j.def();
    let a = w.body(d.body).unwrap().pose().transform_point(d.anchor);
    let b = match d.other {
        Some(o) => w.body(o).unwrap().pose().transform_point(d.other_anchor),
        None => d.other_anchor,
    };
    (a - b).length()
}

fn body<'a>(w: &'a World, name: &str) -> &'a Body {
    w.body(w.find_body(name).unwrap()).unwrap()
}

#[test]
fn the_door_opens_under_its_motor_until_its_limit() {
    // 1 rad/s for 3 s would turn it 3 rad; the limit stops it at π/2 (within 0.01 rad).
    let (scene, gap) = run_scene("door");
    let door = body(&scene.world, "door");
    let (axis, angle) = door.orientation().to_axis_angle();
    assert!(axis.y > 0.99, "turned about {axis}");
    let quarter = std::f64::consts::FRAC_PI_2 as Real;
    assert!((angle - quarter).abs() < 0.01, "door at {angle} rad");
    assert!(gap < 1e-3, "hinge gap {gap}");
}

#[test]
fn the_cradle_passes_the_swing_to_the_last_ball() {
    // Ball 0 falls through 0.6 rad and strikes the row. A quarter period of the 0.8 m
    // strings later, ball 4 has swung out while ball 0 hangs nearly still: ball 4 must
    // reach 80 % of ball 0's release height, and ball 0 must rise less than a tenth of it.
    let mut scene = load("cradle").unwrap();
    let w = &mut scene.world;
    let rest = body(w, "ball4").center_of_mass().y;
    let lift = body(w, "ball0").center_of_mass().y - rest;
    let dt = scene.dt;
    let (mut high4, mut high0): (Real, Real) = (0.0, 0.0);
    // First strike after a quarter period (~0.45 s); the last ball's apex a quarter later.
    for i in 0..(1.0 / dt) as usize {
        w.step(dt).unwrap();
        if i as Real * dt > 0.5 {
            high4 = high4.max(body(w, "ball4").center_of_mass().y - rest);
            high0 = high0.max(body(w, "ball0").center_of_mass().y - rest);
        }
    }
    assert!(high4 > 0.8 * lift, "last ball rose {high4} of {lift}");
    assert!(high0 < 0.1 * lift, "first ball rose {high0} of {lift}");
    // The strings (rods: no min or max) keep their length to a millimetre.
    for length in rope_lengths(w) {
        assert!(
            (length - 0.8544).abs() < 1e-3,
            "a string is {length} m long"
        );
    }
}

/// Distance between the anchors of every distance joint.
fn rope_lengths(w: &World) -> Vec<Real> {
    w.joints()
        .filter(|(_, j)| matches!(j.kind(), JointKind::Distance { .. }))
        .map(|(_, j)| anchor_distance(w, j))
        .collect()
}

#[test]
fn the_rope_bridge_holds_its_crates_above_the_ground() {
    // The bridge is longer than its span (1 cm of slack per rope), so it sags and, with
    // nothing but its joints to damp it, still sways at the end; the crates ride on it.
    let (scene, _) = run_scene("rope_bridge");
    let w = &scene.world;
    for k in 0..3 {
        let c = body(w, &format!("crate{k}")).position();
        assert!(c.y > 1.0 && c.x.abs() < 4.0, "crate{k} fell off, to {c}");
    }
    // Ropes hold their 6 cm maximum to within a centimetre under the crates' weight.
    for length in rope_lengths(w) {
        assert!(length < 0.06 + 0.01, "a rope stretched to {length} m");
    }
}

#[test]
fn the_ragdoll_falls_down_the_stairs_in_one_piece() {
    let (scene, gap) = run_scene("ragdoll");
    let w = &scene.world;
    for (_, b) in w.bodies() {
        assert!(b.position().is_finite() && b.linear_velocity().is_finite());
    }
    let pelvis = body(w, "pelvis").position();
    assert!(
        pelvis.x > 1.0,
        "the ragdoll stayed on the top step: {pelvis}"
    );
    // Limbs whipped by impacts stretch their joints for a moment; at the end, at rest:
    assert!(
        joint_gap(w) < 0.01,
        "a joint is {} m apart at rest",
        joint_gap(w)
    );
    assert!(gap < 0.1, "a joint opened {gap} m during the fall");
}

/// The ragdoll kicked: every body's velocity nudged by up to `kick` m/s on each axis
/// (a fixed pseudo-random sequence per `seed`), as a batch of randomised copies does.
fn kicked_ragdoll(seed: u64, kick: Real) -> tumble_scene::Scene {
    let mut scene = load("ragdoll").unwrap();
    let mut s = seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1;
    let mut unit = move || {
        s = s
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((s >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0) as Real
    };
    let ids: Vec<BodyId> = scene.world.bodies().map(|(id, _)| id).collect();
    for id in ids {
        let b = scene.world.body(id).unwrap();
        if b.kind() == BodyKind::Dynamic {
            let v = b.linear_velocity() + Vec3::new(unit(), unit(), unit()) * kick;
            scene.world.set_linear_velocity(id, v).unwrap();
        }
    }
    scene
}

#[test]
fn the_ragdoll_kicked_a_little_never_blows_up() {
    // Its forearms, thin capsules, roll under the torso at up to ~100 rad/s and turn
    // 1.5 rad a step: with the world inertia kept from the step's start the joints' rows
    // overshot, and 8 runs of 30 kicked by 1 cm/s reached 10,000 m/s within a second.
    // A fall of 3.75 m gives 8.6 m/s; a whipped limb may go faster for a moment, so the
    // bound is 25 m/s (reached: 18) and 1,500 rad/s (a forearm rolling at 25 m/s on its
    // 4 cm radius spins at 600).
    for kick in [0.01, 0.3] {
        for seed in 1..=10 {
            let mut scene = kicked_ragdoll(seed, kick);
            let steps = (scene.duration / scene.dt).round() as usize;
            let (mut fastest, mut spin): (Real, Real) = (0.0, 0.0);
            for i in 0..steps {
                if let Err(e) = scene.world.step(scene.dt) {
                    panic!("kick {kick}, seed {seed}: step {i} failed: {e}");
                }
                for (_, b) in scene.world.bodies() {
                    fastest = fastest.max(b.linear_velocity().length());
                    spin = spin.max(b.angular_velocity().length());
                }
            }
            assert!(
                fastest < 25.0 && spin < 1500.0,
                "kick {kick}, seed {seed}: a body reached {fastest} m/s, {spin} rad/s"
            );
        }
    }
}

#[test]
fn joints_read_from_a_scene_with_defaults_and_named_errors() {
    let scene = r#"{
        "bodies": [
            {"name": "a", "shape": {"type": "sphere", "radius": 0.1}, "position": [0, 1, 0]},
            {"name": "b", "shape": {"type": "sphere", "radius": 0.1}, "position": [1, 1, 0]}
        ],
        "joints": [
            {"type": "hinge", "name": "h", "body": "a", "anchor": [0.5, 0, 0], "other": "b",
             "axis": [0, 0, 1], "limits": [-1, 1], "motor": {"speed": 1, "max_torque": 2},
             "break_force": 100},
            {"type": "distance", "body": "b", "other": null, "other_anchor": [1, 2, 0],
             "max": 1.5}
        ]
    }"#;
    let s = load_str(scene).unwrap();
    let w = &s.world;
    let h = w.joint(w.find_joint("h").unwrap()).unwrap();
    // other_anchor and other_axis left out: the body's, seen from the other body.
    assert!((h.def().other_anchor - Vec3::new(-0.5, 0.0, 0.0)).length() < 1e-9);
    assert!((h.def().other_axis - Vec3::Z).length() < 1e-9);
    assert!(matches!(h.kind(), JointKind::Hinge { motor: Some(m), .. } if m.max_force == 2.0));
    assert_eq!(w.joints().count(), 2);
    for (bad, message) in [
        (r#"{"type": "hinge", "body": "a", "limits": [1, -1]}"#, "joints[0].limits: lower must be <= upper"),
        (r#"{"type": "hinge", "body": "zz"}"#, "joints[0].body: no body named 'zz'"),
        (r#"{"type": "rope", "body": "a"}"#, "joints[0].type: unknown joint type 'rope' (expected one of: ball, hinge, slider, fixed, distance)"),
        (r#"{"type": "slider", "body": "a", "motor": {"speed": 1, "max_force": -1}}"#, "joints[0].motor.max_force: must be >= 0"),
        (r#"{"type": "ball", "body": "a", "limits": [0, 1]}"#, "joints[0].limits: unknown key"),
        // Joint rows are labelled by index when unnamed, as bodies are: the same rules.
        (r#"{"type": "ball", "body": "a", "name": "3"}"#, "joints[0].name: must not be a plain number (unnamed joints are labelled by their index)"),
        (r#"{"type": "ball", "body": "a", "name": ""}"#, "joints[0].name: must not be empty"),
        (r#"{"type": "ball", "body": "a", "name": "a\nb"}"#, "joints[0].name: must not contain control characters"),
    ] {
        let json = format!(
            r#"{{"bodies": [{{"name": "a", "shape": {{"type": "sphere", "radius": 0.1}}}}],
                 "joints": [{bad}]}}"#
        );
        let err = load_str(&json).expect_err("accepted a bad joint").to_string();
        assert!(err.starts_with(message), "{err}\n  expected {message}");
    }
}

#[test]
fn each_joint_type_takes_exactly_its_described_keys_and_the_docs_list_them() {
    // The reader's keys come from the engine's description of each kind: every option of
    // a kind is accepted (a wrong value is refused by the engine, not as an unknown key),
    // and the documentation's "Keys of each type" table names each of them.
    let doc = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../docs/scene-format.md");
    let doc = std::fs::read_to_string(doc).unwrap();
    let table = doc.split("Keys of each type:").nth(1).unwrap();
    let table = table.split("\n\n").nth(1).unwrap();
    for spec in &tumble::joint::JOINT_KINDS {
        // The kind's rows: its own, then the continuation rows under it.
        let own = format!("| `{}`", spec.name);
        let rows: String = table
            .lines()
            .skip_while(|l| !l.starts_with(&own))
            .enumerate()
            .take_while(|(i, l)| *i == 0 || l.starts_with("|            |"))
            .map(|(_, l)| l)
            .collect();
        assert!(!rows.is_empty(), "{} is not documented", spec.name);
        for key in spec.keys() {
            assert!(
                rows.contains(&format!("`{key}`")),
                "{}: {key} undocumented",
                spec.name
            );
            let json = format!(
                r#"{{"bodies": [{{"name": "a", "shape": {{"type": "sphere", "radius": 0.1}}}}],
                     "joints": [{{"type": "{}", "body": "a", "{key}": "x"}}]}}"#,
                spec.name
            );
            let err = load_str(&json).expect_err("accepted a string").to_string();
            assert!(err.starts_with(&format!("joints[0].{key}")), "{err}");
            assert!(!err.contains("unknown key"), "{err}");
        }
    }
}

#[test]
fn a_servo_is_read_and_checked_by_its_field_names() {
    let scene = |servo: &str| {
        format!(
            r#"{{"bodies": [{{"name": "arm", "shape": {{"type": "sphere", "radius": 0.1}}}}],
                 "joints": [{{"type": "hinge", "body": "arm", "axis": [0, 0, 1], "servo": {servo}}}]}}"#
        )
    };
    let s = load_str(&scene(
        r#"{"target": 0.3, "stiffness": 500, "damping": 20, "max_torque": 50}"#,
    ))
    .unwrap();
    let (_, j) = s.world.joints().next().unwrap();
    let expect = tumble::Servo {
        target: 0.3,
        stiffness: 500.0,
        damping: 20.0,
        max_force: 50.0,
    };
    assert!(matches!(j.kind(), JointKind::Hinge { servo: Some(s), .. } if *s == expect));
    for (servo, message) in [
        (
            r#"{"target": 0.3, "stiffness": -1, "max_torque": 5}"#,
            "joints[0].servo.stiffness: must be >= 0",
        ),
        (
            r#"{"target": 0.3, "stiffness": 1, "max_force": 5}"#,
            "joints[0].servo.max_force: unknown key",
        ),
        (
            r#"{"stiffness": 1, "max_torque": 5}"#,
            "joints[0].servo.target: missing required key",
        ),
    ] {
        let err = load_str(&scene(servo)).unwrap_err().to_string();
        assert!(err.starts_with(message), "{err}");
    }
}
