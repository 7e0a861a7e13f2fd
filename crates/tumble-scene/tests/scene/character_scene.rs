//! The scene format's `character`: a character controller walked along a path of
//! velocities, shown by a kinematic body that collides with nothing; the built-in
//! `character_course` walked through, and the errors of the section.

// Casts between Real and f64 are no-ops in the default build but needed in the f32 one.
#![allow(clippy::unnecessary_cast)]

use tumble::{BodyKind, Real, Vec3};
use tumble_scene::{load, load_str};

const SKIN: Real = 0.02;
/// The walker's centre height standing on the floor: radius + half height + skin.
const STANDING: Real = 0.3 + 0.6 + SKIN;

/// The course walked step by step: the character's position, whether it is on the
/// ground, and the crate's position, after every step, with the time.
fn walk_the_course() -> Vec<(Real, Vec3, bool, Vec3, Real)> {
    let mut scene = load("character_course").unwrap();
    let plan = scene.plan().unwrap();
    let crate_id = scene.world.find_body("crate").unwrap();
    let mut out = Vec::new();
    for k in 1..=plan.steps {
        scene.step(plan.step_dt(k)).unwrap();
        let walker = scene.character.as_ref().unwrap();
        let c = &walker.controller;
        let pushed: Real = c.pushes().iter().map(|p| p.impulse.length()).sum();
        let crate_at = scene.world.body(crate_id).unwrap().position();
        out.push((
            plan.time_after(k),
            c.position(),
            c.on_ground(),
            crate_at,
            pushed,
        ));
        // The body that shows it is where the controller is, after the step.
        let shown = scene.world.body(walker.body).unwrap().position();
        assert!(
            (shown - c.position()).length() < 1e-9,
            "{shown} vs {}",
            c.position()
        );
    }
    out
}

/// The built-in course, in its legs (times from the path and the geometry, at 2 m/s):
/// up the 20° ramp to the plateau (its top 0.8 m up: the centre 1.72 m, to half a skin),
/// down the stairs to the floor (on the ground every step of the way), along the wall
/// (z grows), refused by the 60° slope (never above the floor by more than a skin
/// while walking into it, stopped at its foot: z within a skin of 3.815 m, where the
/// capsule's lower sphere is a skin from the slope), then the crate pushed back along −x
/// by more than 3 m with pushes of at most 400 N·dt. The character's body follows it to
/// 1e-9 m (checked every step).
#[test]
fn the_character_course_is_walked() {
    let run = walk_the_course();
    let dt = 1.0 / 60.0;
    let at = |t: Real| run.iter().find(|r| r.0 >= t - 1e-9).unwrap();
    // Up the ramp onto the plateau.
    let top = at(3.0).1;
    assert!((top.y - (0.8 + STANDING)).abs() <= 0.5 * SKIN, "{top}");
    // Down the stairs: on the ground every step from the plateau to the floor.
    for r in run.iter().filter(|r| r.0 > 2.0 && r.0 < 5.0) {
        assert!(r.2, "in the air at t = {}: {}", r.0, r.1);
    }
    let floor = at(5.0).1;
    assert!(
        (floor.y - STANDING).abs() <= 0.5 * SKIN && floor.x > 8.0,
        "{floor}"
    );
    // Along the wall at 45°: z grows while it walks +x.
    assert!(at(7.5).1.z > 1.0, "{}", at(7.5).1);
    // Into the 60° slope: never climbs it.
    for r in run.iter().filter(|r| r.0 > 7.5 && r.0 < 10.0) {
        assert!(r.1.y - STANDING <= SKIN, "t = {}: {}", r.0, r.1);
    }
    let foot = at(10.0).1;
    assert!((foot.z - 3.815).abs() <= SKIN, "{foot}");
    // The crate pushed back, by bounded pushes.
    let (start, end) = (at(10.0).3, run.last().unwrap().3);
    assert!(start.x - end.x > 3.0, "{start} -> {end}");
    for r in &run {
        assert!(r.4 <= 400.0 * dt * (1.0 + 1e-6), "t = {}: {}", r.0, r.4);
    }
    assert!(run.iter().any(|r| r.4 > 0.0));
}

/// A minimal character scene: a floor and the `character` object given.
fn with_character(character: &str) -> String {
    format!(
        r#"{{"bodies": [{{"name": "floor", "kind": "static",
                         "shape": {{"type": "plane", "normal": [0, 1, 0], "offset": 0}}}}],
             "character": {character}}}"#
    )
}

fn error(json: &str) -> String {
    match load_str(json) {
        Ok(_) => panic!("accepted {json}"),
        Err(e) => e.to_string(),
    }
}

/// The defaults: a body named `character`, kinematic, a capsule of the engine's default
/// size, colliding with nothing; no path (it stands, on the ground); its label and
/// colour are the scene's last.
#[test]
fn a_character_gets_a_body_that_collides_with_nothing() {
    let mut scene = load_str(&with_character(
        r##"{"position": [0, 0.92, 0], "color": "#102030"}"##,
    ))
    .unwrap();
    assert_eq!(scene.body_names, ["floor", "character"]);
    assert_eq!(scene.body_colors[1], Some([0x10, 0x20, 0x30]));
    let walker = scene.character.clone().unwrap();
    let body = scene.world.body(walker.body).unwrap();
    assert_eq!(body.kind(), BodyKind::Kinematic);
    assert_eq!(body.collision_filter(), (0, 0));
    assert_eq!(body.shape(), &walker.controller.shape());
    assert!(walker.controller.on_ground());
    for _ in 0..10 {
        scene.step(0.01).unwrap();
    }
    let c = &scene.character.as_ref().unwrap().controller;
    assert_eq!(c.position(), Vec3::new(0.0, 0.92, 0.0));
}

/// Each leg's velocity holds until its `until`, then the next; after the last the
/// character stands. On a floor, with no gravity to fight, it walks exactly v·t (to
/// 1e-9 m; 1e-5 in f32, 150 sums of numbers near 1 good to 6e-8 each).
#[test]
fn the_path_is_followed_leg_by_leg() {
    let json = with_character(
        r#"{"position": [0, 0.92, 0], "path": [
              {"until": 0.5, "velocity": [1, 0, 0]},
              {"until": 1.0, "velocity": [0, 0, -2]}]}"#,
    );
    let mut scene = load_str(&json).unwrap();
    for _ in 0..150 {
        scene.step(0.01).unwrap();
    }
    let p = scene.character.as_ref().unwrap().controller.position();
    let expected = Vec3::new(0.5, 0.92, -1.0);
    let f32 = std::mem::size_of::<Real>() == 4;
    assert!(
        (p - expected).length() < if f32 { 1e-5 } else { 1e-9 },
        "{p}"
    );
    let walker = scene.character.as_ref().unwrap();
    assert_eq!(walker.velocity_at(0.25), Vec3::new(1.0, 0.0, 0.0));
    assert_eq!(walker.velocity_at(0.5), Vec3::new(0.0, 0.0, -2.0));
    assert_eq!(walker.velocity_at(1.0), Vec3::ZERO);
}

#[test]
fn bad_character_fields_are_refused_with_their_path() {
    let cases = [
        (r#"{"radius": 0}"#, "character.radius: must be > 0"),
        (r#"{"radius": -1}"#, "character.radius: must be > 0"),
        (
            r#"{"half_height": -0.5}"#,
            "character.half_height: must be >= 0",
        ),
        (
            r#"{"max_slope": 1.6}"#,
            "character.max_slope: must be >= 0 and below π/2 rad (90°), got 1.6",
        ),
        (
            r#"{"up": [0, 0, 0]}"#,
            "character.up: must be a non-zero vector",
        ),
        (
            r#"{"skin": 0.5}"#,
            "character.skin: must be less than radius (0.3 m)",
        ),
        (
            r#"{"step_height": -1}"#,
            "character.step_height: must be >= 0",
        ),
        (
            r#"{"snap_distance": -1}"#,
            "character.snap_distance: must be >= 0",
        ),
        (
            r#"{"max_push_force": -1}"#,
            "character.max_push_force: must be >= 0",
        ),
        (
            r#"{"radius": "big"}"#,
            "character.radius: expected a number",
        ),
        (
            r#"{"position": [0, 1]}"#,
            "character.position: expected an array of 3 numbers [x, y, z]",
        ),
        (
            r#"{"collision_mask": -1}"#,
            "character.collision_mask: must be a whole number >= 0",
        ),
        (
            r#"{"color": "blue"}"#,
            "character.color: expected \"#rrggbb\", got 'blue'",
        ),
        (
            r#"{"name": "floor"}"#,
            "character.name: a body named 'floor' already exists",
        ),
        (
            r#"{"name": "7"}"#,
            "character.name: must not be a plain number (unnamed bodies are labelled by \
             their index)",
        ),
        (
            r#"{"radiuss": 1}"#,
            "character.radiuss: unknown key (expected one of: name, position, radius, \
             half_height, up, max_slope, step_height, skin, snap_distance, max_push_force, \
             collision_mask, color, path, fall, velocity, ground)",
        ),
        (r#"{"path": {}}"#, "character.path: expected an array"),
        (
            r#"{"path": [{"until": 1}]}"#,
            "character.path[0].velocity: missing required key",
        ),
        (
            r#"{"path": [{"until": 0, "velocity": [1, 0, 0]}]}"#,
            "character.path[0].until: must be after 0",
        ),
        (
            r#"{"path": [{"until": 2, "velocity": [1, 0, 0]}, {"until": 2, "velocity": [0, 0, 0]}]}"#,
            "character.path[1].until: must be after the previous leg's until (2 s)",
        ),
        (
            r#"{"path": [{"until": 1, "velocity": [1e5, 0, 0]}]}"#,
            "character.path[0].velocity: must be no faster than max_speed (10000 m/s)",
        ),
        (
            r#"{"path": [{"until": 1, "speed": 1}]}"#,
            "character.path[0].speed: unknown key (expected one of: until, velocity)",
        ),
    ];
    for (character, message) in cases {
        assert_eq!(error(&with_character(character)), message, "{character}");
    }
    assert_eq!(
        error(r#"{"character": []}"#),
        "character: expected an object"
    );
}
