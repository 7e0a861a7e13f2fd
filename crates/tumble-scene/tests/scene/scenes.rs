//! Scenes that load: every documented key, the defaults, and the built-in scenes.

use tumble::{
    BodyKind, Force, Integrator, MassProperties, Mat3, Quat, Real, Shape, SpringEnd, Vec3,
};
use tumble_scene::{builtin, builtin_names, load_str, Scene};

/// Relative tolerance for values computed in `Real`.
const TOL: Real = if std::mem::size_of::<tumble::Real>() == 4 {
    1e-5
} else {
    1e-12
};

fn close(a: Real, b: Real) -> bool {
    (a - b).abs() <= TOL * (1.0 + a.abs().max(b.abs()))
}

fn close3(a: Vec3, b: Vec3) -> bool {
    close(a.x, b.x) && close(a.y, b.y) && close(a.z, b.z)
}

fn load(json: &str) -> Scene {
    match load_str(json) {
        Ok(scene) => scene,
        Err(e) => panic!("{e}"),
    }
}

/// The example of the task brief and docs/scene-format.md, key for key.
const EXAMPLE: &str = r#"{
  "name": "example", "description": "every key",
  "gravity": [0, -9.8, 0], "dt": 0.01, "duration": 1.0, "integrator": "symplectic_euler",
  "bodies": [
    {"name": "ball", "kind": "dynamic", "shape": {"type": "sphere", "radius": 0.1},
     "mass": 1.0, "position": [0, 5, 0], "orientation": [0, 0, 0, 1],
     "velocity": [0, 0, 0], "angular_velocity": [0, 0, 0], "planar": false}
  ],
  "forces": [
    {"type": "spring", "body": "ball", "anchor": [0, 0, 0], "world_point": [0, 6, 0],
     "stiffness": 100.0, "rest_length": 0.5, "damping": 0.0},
    {"type": "drag", "body": "ball", "linear": 0.1, "quadratic": 0.0},
    {"type": "force", "body": "ball", "force": [1, 0, 0], "point": [0, 0, 0], "torque": [0, 0, 0]}
  ]
}"#;

#[test]
fn the_documented_example_loads_key_for_key() {
    let scene = load(EXAMPLE);
    assert_eq!(scene.name.as_deref(), Some("example"));
    assert_eq!(scene.description.as_deref(), Some("every key"));
    assert_eq!((scene.dt, scene.duration), (0.01, 1.0));
    let world = &scene.world;
    assert_eq!(world.gravity(), Vec3::new(0.0, -9.8, 0.0));
    assert_eq!(world.integrator(), Integrator::SymplecticEuler);
    assert_eq!(scene.body_names, ["ball"]);
    let id = world.find_body("ball").unwrap();
    let ball = world.body(id).unwrap();
    assert_eq!(ball.kind(), BodyKind::Dynamic);
    assert_eq!(ball.shape(), &Shape::sphere(0.1));
    assert_eq!(ball.mass(), 1.0);
    assert_eq!(ball.position(), Vec3::new(0.0, 5.0, 0.0));
    assert_eq!(ball.orientation(), Quat::IDENTITY);
    assert!(!ball.is_planar());
    let forces: Vec<Force> = world.forces().map(|(_, f)| *f).collect();
    let [Force::Spring(s), Force::Drag(d), Force::Applied(a)] = forces.as_slice() else {
        panic!("{forces:?}");
    };
    assert_eq!(
        (s.body, s.anchor, s.other),
        (id, Vec3::ZERO, SpringEnd::World(Vec3::new(0.0, 6.0, 0.0)))
    );
    assert_eq!((s.stiffness, s.rest_length, s.damping), (100.0, 0.5, 0.0));
    assert_eq!((d.body, d.linear, d.quadratic), (id, 0.1, 0.0));
    assert_eq!(
        (a.body, a.force, a.point, a.torque),
        (id, Vec3::X, Some(Vec3::ZERO), Vec3::ZERO)
    );
}

#[test]
fn damping_and_gravity_scale_are_read() {
    let scene = load(
        r#"{"bodies": [{"shape": {"type": "sphere", "radius": 0.1},
            "linear_damping": 0.5, "angular_damping": 2, "gravity_scale": -0.25}]}"#,
    );
    let (_, body) = scene.world.bodies().next().unwrap();
    assert_eq!(body.linear_damping(), 0.5);
    assert_eq!(body.angular_damping(), 2.0);
    assert_eq!(body.gravity_scale(), -0.25);
}

#[test]
fn omitted_keys_take_their_defaults() {
    let scene = load(r#"{"bodies": [{"shape": {"type": "sphere", "radius": 0.1}}]}"#);
    assert_eq!((scene.dt, scene.duration), (0.01, 1.0));
    assert_eq!(scene.world.gravity(), Vec3::new(0.0, -9.8, 0.0));
    assert_eq!(scene.world.integrator(), Integrator::SymplecticEuler);
    assert_eq!(scene.body_names, ["0"]);
    let (_, body) = scene.world.bodies().next().unwrap();
    assert_eq!(body.kind(), BodyKind::Dynamic);
    assert_eq!(body.position(), Vec3::ZERO);
    assert_eq!(body.linear_velocity(), Vec3::ZERO);
    let damping = (body.linear_damping(), body.angular_damping());
    assert_eq!((damping, body.gravity_scale()), ((0.0, 0.0), 1.0));
    // Water: 1000 kg/m³ over the ball's volume.
    let volume = 4.0 / 3.0 * tumble::math::PI * 0.1 * 0.1 * 0.1;
    assert!(close(body.mass(), 1000.0 * volume));
    let empty = load("{}");
    assert_eq!(empty.world.body_count(), 0);
    assert!(empty.body_names.is_empty());
}

#[test]
fn unnamed_bodies_are_labelled_by_index() {
    let scene = load(
        r#"{"bodies": [{"shape": {"type": "sphere", "radius": 1}},
                       {"name": "b", "shape": {"type": "sphere", "radius": 1}},
                       {"shape": {"type": "sphere", "radius": 1}}]}"#,
    );
    assert_eq!(scene.body_names, ["0", "b", "2"]);
}

#[test]
fn every_shape_type_loads() {
    let scene = load(
        r#"{"bodies": [
        {"shape": {"type": "box", "half_extents": [0.5, 0.25, 0.1]}},
        {"shape": {"type": "capsule", "radius": 0.1, "half_height": 0.5}},
        {"shape": {"type": "cylinder", "radius": 0.1, "half_height": 0.5}}]}"#,
    );
    let shapes: Vec<Shape> = scene
        .world
        .bodies()
        .map(|(_, b)| b.shape().clone())
        .collect();
    assert_eq!(
        shapes,
        [
            Shape::cuboid(Vec3::new(0.5, 0.25, 0.1)),
            Shape::capsule(0.1, 0.5),
            Shape::cylinder(0.1, 0.5)
        ]
    );
}

#[test]
fn a_compound_weighs_the_sum_of_its_children() {
    let scene = load(
        r#"{"bodies": [{"density": 500, "shape": {"type": "compound", "children": [
            {"shape": {"type": "sphere", "radius": 0.2}, "position": [1, 0, 0]},
            {"shape": {"type": "box", "half_extents": [0.1, 0.2, 0.3]},
             "orientation": [0, 0, 0.7071067811865476, 0.7071067811865476]},
            {"shape": {"type": "cylinder", "radius": 0.1, "half_height": 0.4}}]}}]}"#,
    );
    let (_, body) = scene.world.bodies().next().unwrap();
    let parts = [
        MassProperties::sphere(500.0, 0.2).mass,
        MassProperties::cuboid(500.0, Vec3::new(0.1, 0.2, 0.3)).mass,
        MassProperties::cylinder(500.0, 0.1, 0.4).mass,
    ];
    assert!(close(body.mass(), parts.iter().sum()));
    let Shape::Compound(children) = body.shape() else {
        panic!()
    };
    assert_eq!(children[0].position, Vec3::X);
    assert_eq!(children[1].position, Vec3::ZERO);
    assert_eq!(children[2].orientation, Quat::IDENTITY);
}

#[test]
fn inertia_accepts_principal_moments_or_a_matrix_and_centre_of_mass_is_kept() {
    let body = |inertia: &str| {
        let scene = load(&format!(
            r#"{{"bodies": [{{"shape": {{"type": "sphere", "radius": 1}}, "mass": 2,
                "center_of_mass": [0.1, 0, 0], "inertia": {inertia}}}]}}"#
        ));
        let (_, b) = scene.world.bodies().next().unwrap();
        (b.inertia_local(), b.local_center_of_mass())
    };
    let (principal, com) = body("[1, 2, 2.5]");
    assert_eq!(principal, Mat3::from_diagonal(Vec3::new(1.0, 2.0, 2.5)));
    assert_eq!(com, Vec3::new(0.1, 0.0, 0.0));
    let (tensor, _) = body("[[2, 0.1, 0], [0.1, 2, 0], [0, 0, 3]]");
    assert_eq!(tensor.x_axis, Vec3::new(2.0, 0.1, 0.0));
    assert_eq!(tensor.z_axis, Vec3::new(0.0, 0.0, 3.0));
}

#[test]
fn orientations_are_normalised_and_kinds_and_planar_read() {
    let scene = load(
        r#"{"bodies": [{"kind": "kinematic", "planar": true, "orientation": [0, 0, 2, 2],
            "velocity": [1, 2, 3], "angular_velocity": [4, 5, 6],
            "shape": {"type": "sphere", "radius": 1}},
            {"kind": "static", "shape": {"type": "sphere", "radius": 1}}]}"#,
    );
    let bodies: Vec<_> = scene.world.bodies().map(|(_, b)| b).collect();
    assert_eq!(bodies[0].kind(), BodyKind::Kinematic);
    assert!(bodies[0].is_planar());
    let q = bodies[0].orientation();
    let h = (0.5 as Real).sqrt();
    assert!(close(q.z, h) && close(q.w, h));
    // Planar bodies keep only in-plane motion.
    assert!(close3(
        bodies[0].linear_velocity(),
        Vec3::new(1.0, 2.0, 0.0)
    ));
    assert!(close3(
        bodies[0].angular_velocity(),
        Vec3::new(0.0, 0.0, 6.0)
    ));
    assert_eq!(bodies[1].kind(), BodyKind::Static);
}

#[test]
fn a_spring_between_two_bodies_refers_to_both() {
    let scene = load(builtin("double_spring").unwrap());
    let w = &scene.world;
    let (ceiling, upper, lower) = (
        w.find_body("ceiling").unwrap(),
        w.find_body("upper").unwrap(),
        w.find_body("lower").unwrap(),
    );
    let springs: Vec<_> = w
        .forces()
        .filter_map(|(_, f)| match f {
            Force::Spring(s) => Some(*s),
            _ => None,
        })
        .collect();
    assert_eq!(springs.len(), 2);
    assert_eq!(springs[0].body, upper);
    assert_eq!(
        springs[0].other,
        SpringEnd::Body {
            body: ceiling,
            anchor: Vec3::new(0.0, -0.05, 0.0)
        }
    );
    assert_eq!(springs[1].body, lower);
    assert_eq!(
        springs[1].other,
        SpringEnd::Body {
            body: upper,
            anchor: Vec3::ZERO
        }
    );
    assert_eq!(
        (
            springs[1].stiffness,
            springs[1].rest_length,
            springs[1].damping
        ),
        (200.0, 0.8, 0.0)
    );
}

#[test]
fn the_spring_scene_has_its_spring() {
    let scene = load(builtin("spring").unwrap());
    let ball = scene.world.find_body("ball").unwrap();
    let forces: Vec<Force> = scene.world.forces().map(|(_, f)| *f).collect();
    let [Force::Spring(s)] = forces.as_slice() else {
        panic!("{forces:?}")
    };
    assert_eq!(s.body, ball);
    assert_eq!(s.other, SpringEnd::World(Vec3::new(0.0, 5.0, 0.0)));
    assert_eq!((s.stiffness, s.rest_length), (100.0, 1.0));
}

#[test]
fn every_builtin_loads_and_runs_a_few_steps() {
    assert_eq!(builtin_names()[0], "free_fall");
    for name in builtin_names() {
        let mut scene = tumble_scene::load(name).unwrap_or_else(|e| panic!("{name}: {e}"));
        assert_eq!(scene.name.as_deref(), Some(name));
        assert!(scene.description.is_some(), "{name} has no description");
        let plan = scene.plan().unwrap();
        for k in 1..=plan.steps.min(10) {
            scene.world.step(plan.step_dt(k)).unwrap();
        }
        for (_, b) in scene.world.bodies() {
            assert!(b.position().is_finite(), "{name}");
        }
    }
}

#[test]
fn the_seed_scene_is_the_seed() {
    let scene = load(builtin("free_fall").unwrap());
    let ball = scene
        .world
        .body(scene.world.find_body("ball").unwrap())
        .unwrap();
    assert_eq!((ball.mass(), ball.shape()), (1.0, &Shape::sphere(0.1)));
    assert_eq!(ball.position(), Vec3::new(0.0, 5.0, 0.0));
    assert_eq!((scene.dt, scene.duration), (0.01, 1.0));
    assert_eq!(scene.world.gravity(), Vec3::new(0.0, -9.8, 0.0));
    assert_eq!(scene.plan().unwrap().steps, 100);
    let dz = load(builtin("dzhanibekov").unwrap());
    assert_eq!(dz.plan().unwrap().steps, 4800);
}

/// The built-ins are compiled from `scenes/*.json`; every file there must be one of them,
/// byte for byte, so the directory and the binary cannot drift apart.
#[test]
fn every_scene_file_is_a_builtin() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes");
    let mut files = Vec::new();
    for entry in std::fs::read_dir(&dir).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().is_some_and(|e| e == "json") {
            let stem = path.file_stem().unwrap().to_string_lossy().into_owned();
            let text = std::fs::read_to_string(&path).unwrap();
            assert_eq!(
                builtin(&stem),
                Some(text.as_str()),
                "{stem} is not a builtin"
            );
            let from_file = tumble_scene::load_file(&path).unwrap();
            assert_eq!(from_file.world.state_hash(), load(&text).world.state_hash());
            files.push(stem);
        }
    }
    files.sort();
    let mut names = builtin_names();
    names.sort();
    assert_eq!(files, names);
}

/// The example at the top of docs/scene-format.md must stay a valid scene.
#[test]
fn the_documentation_example_loads() {
    let doc = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../docs/scene-format.md");
    let text = std::fs::read_to_string(doc).unwrap();
    let start = text.find("```json\n").unwrap() + "```json\n".len();
    let end = start + text[start..].find("```").unwrap();
    let scene = load(&text[start..end]);
    assert_eq!(scene.body_names, ["ball"]);
    assert_eq!(scene.world.forces().count(), 3);
}

#[test]
fn rolling_resistance_and_torsional_friction_load_and_default_to_zero() {
    let scene = load(
        r#"{"bodies": [
        {"shape": {"type": "sphere", "radius": 0.1},
         "rolling_resistance": 0.05, "torsional_friction": 0.002},
        {"shape": {"type": "sphere", "radius": 0.1}}]}"#,
    );
    let bodies: Vec<_> = scene.world.bodies().map(|(_, b)| b).collect();
    assert_eq!(
        (
            bodies[0].rolling_resistance(),
            bodies[0].torsional_friction()
        ),
        (0.05, 0.002)
    );
    assert_eq!(
        (
            bodies[1].rolling_resistance(),
            bodies[1].torsional_friction()
        ),
        (0.0, 0.0)
    );
}

#[test]
fn every_body_key_is_in_the_documented_table() {
    // The reader lists its keys when refusing an unknown one; the Bodies table of
    // docs/scene-format.md must have a row for each.
    let err = load_str(r#"{"bodies": [{"shape": {"type": "sphere", "radius": 1}, "x": 1}]}"#)
        .expect_err("an unknown key");
    let keys = err.reason.split("expected one of: ").nth(1).unwrap();
    let keys = keys.trim_end_matches(')').split(", ");
    let doc = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../docs/scene-format.md");
    let doc = std::fs::read_to_string(doc).unwrap();
    let table = doc.split("## Bodies").nth(1).unwrap();
    let table = table.split("\n\n").nth(1).unwrap();
    for key in keys {
        assert!(
            table.lines().any(|l| l.starts_with(&format!("| `{key}`"))),
            "{key} has no row in the Bodies table"
        );
    }
}
