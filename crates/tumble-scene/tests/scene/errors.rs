//! Every refusal is one line naming its field; these pin the exact wording.

use tumble_scene::load_str;

/// The error line for `json`, which must be refused.
fn error(json: &str) -> String {
    match load_str(json) {
        Ok(scene) => panic!("accepted {json}: {scene:?}"),
        Err(e) => {
            let line = e.to_string();
            assert!(!line.contains('\n'), "multi-line error: {line}");
            assert_eq!(line, format!("{}: {}", e.field, e.reason));
            line
        }
    }
}

/// A scene with one body whose fields are `body` (JSON object members).
fn one_body(body: &str) -> String {
    format!(r#"{{"bodies": [{{"shape": {{"type": "sphere", "radius": 0.1}}, {body}}}]}}"#)
}

/// A body named ball, and the `forces` array given.
fn with_forces(forces: &str) -> String {
    format!(
        r#"{{"bodies": [{{"name": "ball", "shape": {{"type": "sphere", "radius": 0.1}}}},
                        {{"name": "cup", "shape": {{"type": "box", "half_extents": [1, 1, 1]}}}}],
             "forces": {forces}}}"#
    )
}

#[test]
fn misspelt_keys_are_refused_with_the_allowed_ones() {
    assert_eq!(
        error(r#"{"bodies": [{"shape": {"type": "sphere", "radiuss": 0.1}}]}"#),
        "bodies[0].shape.radiuss: unknown key (expected one of: type, radius)"
    );
    assert_eq!(
        error(r#"{"gravityy": [0, 0, 0]}"#),
        "gravityy: unknown key (expected one of: name, description, gravity, dt, duration, \
         integrator, bodies, forces, joints, solver, substeps, iterations, contact_hertz, \
         contact_damping_ratio, joint_hertz, joint_damping_ratio, joint_trees, length_unit, sleep, max_speed, \
         max_angular_speed, max_contacts, max_contacts_per_body, max_push_speed, character, state, models, \
         exclude)"
    );
    assert_eq!(
        error(&one_body(r#""velocty": [1, 0, 0]"#)),
        "bodies[0].velocty: unknown key (expected one of: name, kind, shape, mass, density, \
         inertia, center_of_mass, position, orientation, velocity, angular_velocity, planar, \
         collision_group, collision_mask, collision_owner, friction, restitution, rolling_resistance, \
         torsional_friction, bullet, color, linear_damping, angular_damping, gravity_scale, \
         sensor, one_way)"
    );
    assert_eq!(
        error(&with_forces(
            r#"[{"type": "drag", "body": "ball", "lineer": 1}]"#
        )),
        "forces[0].lineer: unknown key (expected one of: type, body, linear, quadratic)"
    );
    let child = r#"{"bodies": [{"shape": {"type": "compound", "children": [
        {"shape": {"type": "sphere", "radius": 1}, "rotation": [0, 0, 0, 1]}]}}]}"#;
    assert_eq!(
        error(child),
        "bodies[0].shape.children[0].rotation: unknown key (expected one of: shape, position, \
         orientation)"
    );
}

#[test]
fn unknown_names_list_the_known_ones() {
    assert_eq!(
        error(r#"{"bodies": [{"shape": {"type": "cone", "radius": 0.1}}]}"#),
        "bodies[0].shape.type: unknown shape type 'cone' (expected one of: sphere, box, capsule, \
         cylinder, convex_hull, compound, plane, trimesh, heightfield)"
    );
    assert_eq!(
        error(r#"{"integrator": "rk5"}"#),
        "integrator: unknown integrator 'rk5' (expected one of: explicit_euler, symplectic_euler, \
         implicit_euler, midpoint, rk4, verlet, velocity_verlet)"
    );
    assert_eq!(
        error(&one_body(r#""kind": "floating""#)),
        "bodies[0].kind: unknown kind 'floating' (expected one of: static, kinematic, dynamic)"
    );
    assert_eq!(
        error(&with_forces(
            r#"[{"type": "drag", "body": "ball"}, {"type": "drag", "body": "bal"}]"#
        )),
        "forces[1].body: no body named 'bal'"
    );
    assert_eq!(
        error(&with_forces(r#"[{"type": "magnet", "body": "ball"}]"#)),
        "forces[0].type: unknown force type 'magnet' (expected one of: spring, drag, force)"
    );
}

#[test]
fn engine_rules_come_back_with_the_scene_path() {
    let bodies = r#"{"bodies": [
        {"shape": {"type": "sphere", "radius": 1}},
        {"shape": {"type": "sphere", "radius": 1}},
        {"shape": {"type": "sphere", "radius": 1}},
        {"shape": {"type": "sphere", "radius": -0.1}}]}"#;
    assert_eq!(error(bodies), "bodies[3].shape.radius: must be > 0");
    assert_eq!(
        error(&one_body(r#""orientation": [0, 0, 0, 0]"#)),
        "bodies[0].orientation: must be a non-zero quaternion [x, y, z, w]"
    );
    assert_eq!(
        error(&one_body(r#""mass": 0"#)),
        "bodies[0].mass: must be > 0"
    );
    assert_eq!(
        error(&one_body(r#""density": -5"#)),
        "bodies[0].density: must be > 0"
    );
    assert_eq!(
        error(&one_body(r#""inertia": [1, 1, 5]"#)),
        "bodies[0].inertia: violates the triangle inequality: no principal moment may exceed \
         the sum of the other two"
    );
    assert_eq!(
        error(r#"{"bodies": [{"shape": {"type": "box", "half_extents": [1, 0, 1]}}]}"#),
        "bodies[0].shape.half_extents: every component must be > 0"
    );
    assert_eq!(
        error(r#"{"bodies": [{"shape": {"type": "compound", "children": []}}]}"#),
        "bodies[0].shape.children: must not be empty"
    );
    assert_eq!(
        error(&with_forces(
            r#"[{"type": "spring", "body": "ball", "world_point": [0, 0, 0], "stiffness": -1}]"#
        )),
        "forces[0].stiffness: must be >= 0"
    );
}

#[test]
fn a_degenerate_hull_is_reported_under_its_shape() {
    let flat = r#"{"bodies": [{"shape": {"type": "convex_hull",
        "points": [[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0]]}}]}"#;
    let line = error(flat);
    assert!(line.starts_with("bodies[0].shape.points: "), "{line}");
    assert_eq!(
        error(r#"{"bodies": [{"shape": {"type": "convex_hull", "points": [[0, 0]]}}]}"#),
        "bodies[0].shape.points[0]: expected an array of 3 numbers [x, y, z]"
    );
}

#[test]
fn mass_and_density_together_are_refused() {
    assert_eq!(
        error(&one_body(r#""mass": 1, "density": 1000"#)),
        "bodies[0].density: cannot be given together with mass (give one of mass, density)"
    );
}

#[test]
fn numbers_must_be_finite_and_of_the_right_type() {
    assert_eq!(
        error(&one_body(r#""mass": 1e400"#)),
        "bodies[0].mass: must be a finite number"
    );
    assert_eq!(
        error(&one_body(r#""position": [0, -1e400, 0]"#)),
        "bodies[0].position[1]: must be a finite number"
    );
    assert_eq!(
        error(&one_body(r#""mass": "1""#)),
        "bodies[0].mass: expected a number"
    );
    assert_eq!(
        error(&one_body(r#""mass": null"#)),
        "bodies[0].mass: expected a number"
    );
    assert_eq!(
        error(&one_body(r#""planar": 1"#)),
        "bodies[0].planar: expected true or false"
    );
    assert_eq!(
        error(&one_body(r#""name": 7"#)),
        "bodies[0].name: expected a string"
    );
    assert_eq!(
        error(&one_body(r#""position": [0, 1]"#)),
        "bodies[0].position: expected an array of 3 numbers [x, y, z]"
    );
    assert_eq!(
        error(&one_body(r#""orientation": [0, 0, 1]"#)),
        "bodies[0].orientation: expected an array of 4 numbers [x, y, z, w]"
    );
    assert_eq!(error(r#"{"bodies": {}}"#), "bodies: expected an array");
    assert_eq!(error(r#"{"bodies": [3]}"#), "bodies[0]: expected an object");
    assert_eq!(error("[]"), "scene: expected an object");
    assert_eq!(
        error(&one_body(r#""inertia": [[1, 0, 0], [0, 1, 0]]"#)),
        "bodies[0].inertia: expected a 3x3 matrix [[..], [..], [..]] (or 3 principal moments)"
    );
    assert_eq!(
        error(&one_body(r#""inertia": [[1, 0, 0], [0, 1, 0], [0, 0]]"#)),
        "bodies[0].inertia[2]: expected an array of 3 numbers (a matrix row)"
    );
}

#[test]
fn run_settings_are_checked() {
    assert_eq!(error(r#"{"dt": 0}"#), "dt: must be > 0");
    assert_eq!(error(r#"{"dt": -0.01}"#), "dt: must be > 0");
    assert_eq!(error(r#"{"duration": -1}"#), "duration: must be >= 0");
    assert_eq!(
        error(r#"{"gravity": [0, "down", 0]}"#),
        "gravity[1]: expected a number"
    );
    assert_eq!(error(r#"{"name": 3}"#), "name: expected a string");
}

#[test]
fn malformed_json_names_the_position() {
    assert_eq!(
        error("{\n  \"dt\": 0.01,\n    ,\n}"),
        "scene: invalid JSON at line 3 column 5: key must be a string"
    );
    assert_eq!(
        error(""),
        "scene: invalid JSON at line 1 column 0: EOF while parsing a value"
    );
}

#[test]
fn names_must_be_unique_and_not_numbers() {
    let twice = r#"{"bodies": [
        {"name": "ball", "shape": {"type": "sphere", "radius": 1}},
        {"name": "ball", "shape": {"type": "sphere", "radius": 1}}]}"#;
    assert_eq!(
        error(twice),
        "bodies[1].name: a body named 'ball' already exists"
    );
    assert_eq!(
        error(&one_body(r#""name": "12""#)),
        "bodies[0].name: must not be a plain number (unnamed bodies are labelled by their index)"
    );
    assert_eq!(
        error(&one_body(r#""name": """#)),
        "bodies[0].name: must not be empty"
    );
}

#[test]
fn a_spring_needs_exactly_one_far_end() {
    let both = r#"[{"type": "spring", "body": "ball", "world_point": [0, 1, 0], "other": "cup",
                    "stiffness": 1}]"#;
    assert_eq!(
        error(&with_forces(both)),
        "forces[0].other: cannot be given together with world_point (give exactly one of \
         world_point, other)"
    );
    let neither = r#"[{"type": "spring", "body": "ball", "stiffness": 1}]"#;
    assert_eq!(
        error(&with_forces(neither)),
        "forces[0]: a spring needs world_point or other (give exactly one)"
    );
    let stray = r#"[{"type": "spring", "body": "ball", "world_point": [0, 1, 0],
                     "other_anchor": [0, 0, 0], "stiffness": 1}]"#;
    assert_eq!(
        error(&with_forces(stray)),
        "forces[0].other_anchor: only allowed together with other"
    );
    let itself = r#"[{"type": "spring", "body": "ball", "other": "ball", "stiffness": 1}]"#;
    assert_eq!(
        error(&with_forces(itself)),
        "forces[0].other: must be a different body from body"
    );
    let unknown = r#"[{"type": "spring", "body": "ball", "other": "cap", "stiffness": 1}]"#;
    assert_eq!(
        error(&with_forces(unknown)),
        "forces[0].other: no body named 'cap'"
    );
    let loose = r#"[{"type": "spring", "body": "ball", "world_point": [0, 1, 0]}]"#;
    assert_eq!(
        error(&with_forces(loose)),
        "forces[0].stiffness: missing required key"
    );
}

#[test]
fn missing_required_keys_are_named() {
    assert_eq!(
        error(r#"{"bodies": [{}]}"#),
        "bodies[0].shape: missing required key"
    );
    assert_eq!(
        error(r#"{"bodies": [{"shape": {"radius": 1}}]}"#),
        "bodies[0].shape.type: missing required key"
    );
    assert_eq!(
        error(r#"{"bodies": [{"shape": {"type": "capsule", "radius": 1}}]}"#),
        "bodies[0].shape.half_height: missing required key"
    );
    assert_eq!(
        error(&with_forces(r#"[{"type": "drag"}]"#)),
        "forces[0].body: missing required key"
    );
}

#[test]
fn colours_must_be_hex_triplets() {
    for bad in [r#""red""#, r##""#ff00""##, r##""#gg0000""##, "[1, 0, 0]"] {
        let e = error(&one_body(&format!(r#""color": {bad}"#)));
        assert!(e.starts_with("bodies[0].color: expected "), "{bad}: {e}");
    }
    let scene = tumble_scene::load_str(
        r##"{"bodies": [{"color": "#FF8000", "shape": {"type": "sphere", "radius": 1}},
                         {"shape": {"type": "sphere", "radius": 1}}]}"##,
    )
    .unwrap();
    assert_eq!(scene.body_colors, [Some([255, 128, 0]), None]);
}

#[test]
fn files_that_cannot_be_read_are_reported() {
    let e = tumble_scene::load_file("/no/such/scene.json").unwrap_err();
    assert_eq!(e.field, "scene");
    assert!(
        e.reason.starts_with("cannot read '/no/such/scene.json': "),
        "{e}"
    );
    let e = tumble_scene::load("no_such_scene").unwrap_err();
    assert_eq!(
        e.to_string(),
        "scene: 'no_such_scene' is neither a built-in scene (free_fall, spring, double_spring, \
         dzhanibekov, planar_spinner, dumbbell, resting, door, cradle, rope_bridge, ragdoll, pyramid, pendulum_chain, character_course) nor an existing file"
    );
}

#[test]
fn user_text_cannot_break_the_line() {
    assert_eq!(
        error(r#"{"du\nration": 1}"#),
        "du\\nration: unknown key (expected one of: name, description, gravity, dt, duration, \
         integrator, bodies, forces, joints, solver, substeps, iterations, contact_hertz, \
         contact_damping_ratio, joint_hertz, joint_damping_ratio, joint_trees, length_unit, sleep, max_speed, \
         max_angular_speed, max_contacts, max_contacts_per_body, max_push_speed, character, state, models, \
         exclude)"
    );
    assert_eq!(error(r#"{"integrator": "rk\n4"}"#).lines().count(), 1);
    assert_eq!(
        error(&one_body(r#""name": "a\tb""#)),
        "bodies[0].name: must not contain control characters"
    );
}

#[test]
fn mass_properties_that_underflow_are_refused() {
    let tiny = if std::mem::size_of::<tumble::Real>() == 4 {
        "1e-20"
    } else {
        "1e-120"
    };
    let line = error(&format!(
        r#"{{"bodies": [{{"shape": {{"type": "sphere", "radius": {tiny}}}}}]}}"#
    ));
    assert!(
        line.starts_with("bodies[0].shape: mass and inertia come out at 0 kg"),
        "{line}"
    );
    // A density just inside the float range, times the ball's volume, overflows.
    let dense = if std::mem::size_of::<tumble::Real>() == 4 {
        "1e38"
    } else {
        "1e308"
    };
    let heavy = error(&one_body(&format!(r#""density": {dense}"#)));
    assert_eq!(
        heavy,
        "bodies[0].density: must be at most 1e15 in magnitude"
    );
}

#[test]
fn solver_passes_state_one_rule_for_every_bad_count() {
    // -1 used to be told ">= 0" and 0 ">= 1": one rule, whatever the bad value.
    for key in ["substeps", "iterations"] {
        for bad in ["-1", "0", "1.5", "10001", "2000000", "\"4\""] {
            assert_eq!(
                error(&format!(r#"{{"{key}": {bad}}}"#)),
                format!("{key}: must be a whole number from 1 to 10000")
            );
        }
        assert!(load_str(&format!(r#"{{"{key}": 10000}}"#)).is_ok());
    }
}

#[test]
fn body_coefficients_are_checked_with_their_paths() {
    for key in [
        "rolling_resistance",
        "torsional_friction",
        "linear_damping",
        "angular_damping",
    ] {
        assert_eq!(
            error(&one_body(&format!(r#""{key}": -0.1"#))),
            format!("bodies[0].{key}: must be >= 0")
        );
        assert_eq!(
            error(&one_body(&format!(r#""{key}": 1e20"#))),
            format!("bodies[0].{key}: must be at most 1e15 in magnitude")
        );
        assert_eq!(
            error(&one_body(&format!(r#""{key}": 1e400"#))),
            format!("bodies[0].{key}: must be a finite number")
        );
        assert_eq!(
            error(&one_body(&format!(r#""{key}": "0.1""#))),
            format!("bodies[0].{key}: expected a number")
        );
        // The second body's, to show the index.
        let two = format!(
            r#"{{"bodies": [{{"shape": {{"type": "sphere", "radius": 0.1}}}},
                            {{"shape": {{"type": "sphere", "radius": 0.1}}, "{key}": -1}}]}}"#
        );
        assert_eq!(error(&two), format!("bodies[1].{key}: must be >= 0"));
    }
}

#[test]
fn gravity_scale_is_checked_with_its_path() {
    assert_eq!(
        error(&one_body(r#""gravity_scale": 2e6"#)),
        "bodies[0].gravity_scale: must be at most 1e6 in magnitude"
    );
    assert_eq!(
        error(&one_body(r#""gravity_scale": "1""#)),
        "bodies[0].gravity_scale: expected a number"
    );
    assert!(load_str(&one_body(r#""gravity_scale": -0.5"#)).is_ok());
}

#[test]
fn the_push_out_speed_is_read_and_checked() {
    for (value, rule) in [("0", "must be > 0"), ("-3", "must be > 0")] {
        let scene = format!(r#"{{"max_push_speed": {value}}}"#);
        assert_eq!(error(&scene), format!("max_push_speed: {rule}"));
    }
    assert_eq!(
        error(r#"{"max_push_speed": "fast"}"#),
        "max_push_speed: expected a number"
    );
    let scene = tumble_scene::load_str(r#"{"max_push_speed": 0.5}"#).unwrap();
    assert_eq!(scene.world.max_push_speed(), 0.5);
    // The default follows the length unit, as Box2D's does.
    let scene = tumble_scene::load_str(r#"{"length_unit": 0.01}"#).unwrap();
    assert!((scene.world.max_push_speed() - 0.03).abs() < 1e-6);
}

#[test]
fn sensor_and_one_way_are_checked_with_their_paths() {
    assert_eq!(
        error(&one_body(r#""one_way": [0, 0, 0]"#)),
        "bodies[0].one_way: must be a non-zero vector"
    );
    assert_eq!(
        error(&one_body(r#""one_way": [0, 1]"#)),
        "bodies[0].one_way: expected an array of 3 numbers [x, y, z]"
    );
    assert_eq!(
        error(&one_body(r#""one_way": [0, 1e400, 0]"#)),
        "bodies[0].one_way[1]: must be a finite number"
    );
    assert_eq!(
        error(&one_body(r#""sensor": 1"#)),
        "bodies[0].sensor: expected true or false"
    );
    let scene = load_str(&one_body(r#""sensor": true, "one_way": [0, 2, 0]"#)).unwrap();
    let (_, body) = scene.world.bodies().next().unwrap();
    assert!(body.is_sensor());
    assert_eq!(body.one_way(), Some(tumble::Vec3::Y));
}

#[test]
fn bad_exclusions_are_refused_by_entry() {
    let scene = |exclude: &str| {
        with_forces("[]").replace("\"forces\": []", &format!("\"exclude\": {exclude}"))
    };
    assert_eq!(
        error(&scene(r#"[["ball", "cup", "ball"]]"#)),
        "exclude[0]: must be a pair of bodies, got 3 items"
    );
    assert_eq!(
        error(&scene(r#"[["ball", "cup"], ["ball", "mug"]]"#)),
        "exclude[1][1]: no body named 'mug'"
    );
    assert_eq!(
        error(&scene(r#"[[0, 2]]"#)),
        "exclude[0][1]: no body at index 2 (there are 2)"
    );
    assert_eq!(
        error(&scene(r#"[["cup", 1]]"#)),
        "exclude[0]: a body cannot be excluded from itself"
    );
}

#[test]
fn a_bad_saved_character_state_is_refused_by_field() {
    let scene = |state: &str| {
        format!(
            r#"{{"bodies": [{{"name": "floor", "kind": "static",
                   "shape": {{"type": "plane", "normal": [0, 1, 0]}}}}],
                 "character": {{"position": [0, 0.92, 0], {state}}}}}"#
        )
    };
    assert_eq!(
        error(&scene(
            r#""ground": {"body": "roof", "normal": [0, 1, 0], "point": [0, 0, 0]}"#
        )),
        "character.ground.body: no body named 'roof'"
    );
    assert_eq!(
        error(&scene(
            r#""ground": {"body": "floor", "normal": [0, 2, 0], "point": [0, 0, 0]}"#
        )),
        "character.ground.normal: must be a unit vector"
    );
    assert_eq!(
        error(&scene(
            r#""ground": {"body": "floor", "normal": [0, 1, 0]}"#
        )),
        "character.ground.point: missing required key"
    );
    assert_eq!(
        error(&scene(r#""fall": [0, "down", 0]"#)),
        "character.fall[1]: expected a number"
    );
}
