//! MJCF import (`tumble_scene::mjcf`) on models written for these tests
//! (`tests/mjcf/*.xml`, and small files written at run time): masses, centres of mass and
//! inertia tensors against closed forms, frames, default classes, joints and their
//! coordinates, a passive double pendulum's energy and a pendulum's small-angle period,
//! collision filters, and one error line per kind of bad file.

// Casts between Real and f64 are no-ops in the default build but needed in the f32 one.
#![allow(clippy::unnecessary_cast)]

use std::path::PathBuf;

use tumble::{JointCoordinate, Mat3, Quat, Real, Vec3, World, WorldDef};
use tumble_scene::mjcf::{self, ImportedMjcf, MjcfOptions};

const PI: Real = std::f64::consts::PI as Real;
/// Relative tolerance of quantities computed in closed form twice (import and test) in
/// different orders: a few hundred ulps of `Real`.
const EXACT: Real = 500.0 * Real::EPSILON;

fn model(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/mjcf")
        .join(name)
}

fn z_up() -> World {
    World::new(&WorldDef {
        gravity: Vec3::new(0.0, 0.0, -9.81),
        ..WorldDef::default()
    })
}

fn load(name: &str) -> (World, ImportedMjcf) {
    load_at(model(name))
}

/// The file at `path` loaded into a fresh z-up world with the default options.
fn load_at(path: PathBuf) -> (World, ImportedMjcf) {
    let mut world = z_up();
    let m = mjcf::load(path, &mut world, &MjcfOptions::default()).unwrap();
    (world, m)
}

/// Writes `text` to a fresh file called `name` in this test run's temporary folder.
fn write(name: &str, text: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("tumble-mjcf-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join(name);
    std::fs::create_dir_all(path.parent().unwrap()).unwrap();
    std::fs::write(&path, text).unwrap();
    path
}

fn close(a: Real, b: Real, rel: Real) -> bool {
    (a - b).abs() <= rel * a.abs().max(b.abs()).max(1e-30)
}

fn mat_close(a: Mat3, b: Mat3, rel: Real) -> bool {
    let scale = b
        .to_cols_array()
        .iter()
        .fold(0.0 as Real, |m, x| m.max(x.abs()));
    a.to_cols_array()
        .iter()
        .zip(b.to_cols_array())
        .all(|(x, y)| (x - y).abs() <= rel * scale)
}

/// A capsule along x of radius r and shaft length l, density ρ: its mass and its tensor
/// about its centre (axial m_c r²/2 + m_s 2r²/5; transverse m_c (r²/4 + h²/3) +
/// m_s (2r²/5 + h² + 3hr/4), h = l/2: the shaft plus two hemispheres shifted).
fn capsule_x(rho: Real, r: Real, l: Real) -> (Real, Mat3) {
    let h = l / 2.0;
    let mc = rho * PI * r * r * l;
    let ms = rho * 4.0 / 3.0 * PI * r * r * r;
    let axial = mc * r * r / 2.0 + ms * 0.4 * r * r;
    let side = mc * (r * r / 4.0 + h * h / 3.0) + ms * (0.4 * r * r + h * h + 0.75 * h * r);
    (mc + ms, Mat3::from_diagonal(Vec3::new(axial, side, side)))
}

#[test]
fn capsule_links_have_the_closed_form_mass_centre_and_inertia() {
    let (world, m) = load("double_pendulum.xml");
    for (name, r, l, origin) in [
        ("upper", 0.05, 0.5, Vec3::new(0.0, 0.0, 2.0)),
        ("lower", 0.04, 0.4, Vec3::new(0.5, 0.0, 2.0)),
    ] {
        let body = world.body(m.body(name).unwrap()).unwrap();
        let (mass, inertia) = capsule_x(1000.0, r, l);
        assert!(
            close(body.mass(), mass, EXACT),
            "{name}: {} vs {mass}",
            body.mass()
        );
        assert!((body.local_center_of_mass() - Vec3::new(l / 2.0, 0.0, 0.0)).length() < EXACT);
        assert!(
            mat_close(body.inertia_local(), inertia, EXACT),
            "{name}: {} vs {inertia}",
            body.inertia_local()
        );
        assert!((body.position() - origin).length() < EXACT);
    }
    assert_eq!(
        world.body_count(),
        2,
        "no static body: the world has no geoms"
    );
    let names: Vec<&str> = m.joints.iter().map(|j| j.name.as_str()).collect();
    assert_eq!(names, ["shoulder", "elbow"]);
    assert_eq!(world.integrator(), tumble::Integrator::Rk4);
    assert_eq!(m.timestep, 0.001);
    assert!(m.warnings.is_empty(), "{:?}", m.warnings);
}

#[test]
fn every_orientation_form_gives_the_same_turn() {
    let (world, m) = load("frames.xml");
    // 120° about (1, 1, 1)/√3: x → y, y → z, z → x.
    let expected = Quat::from_axis_angle(Vec3::ONE.normalize(), 2.0 * PI / 3.0);
    for name in ["by_quat", "by_axisangle", "by_xyaxes", "by_euler"] {
        let q = world.body(m.body(name).unwrap()).unwrap().orientation();
        assert!(
            q.dot(expected).abs() > 1.0 - 1e2 * Real::EPSILON,
            "{name}: {q} vs {expected}"
        );
    }
    // zaxis fixes only where z goes (the shortest turn there).
    let q = world
        .body(m.body("by_zaxis").unwrap())
        .unwrap()
        .orientation();
    assert!((q * Vec3::Z - Vec3::X).length() < 1e-6);
    let free = m.joints.iter().filter(|j| j.kind == "free").count();
    assert_eq!(free, 5);
}

#[test]
fn default_classes_inherit_and_childclass_passes_down() {
    let (world, m) = load("defaults.xml");
    let mass = |n: &str| world.body(m.body(n).unwrap()).unwrap().mass();
    let sphere = 4.0 / 3.0 * PI * 0.001;
    assert!(close(mass("plain"), 500.0 * sphere, EXACT));
    assert!(close(mass("classed"), 1000.0 * sphere, EXACT));
    // "big" inherits heavy's density and adds a box of 0.2 × 0.4 × 0.6 m.
    assert!(close(mass("nested"), 1000.0 * 0.048, EXACT));
    // "welded" (no joint) joins "parent": its box (own size, the class's density) is
    // added, 1 m along x, and both names map to the one body.
    assert_eq!(m.body("welded"), m.body("parent"));
    let parent = world.body(m.body("parent").unwrap()).unwrap();
    let (m1, m2) = (48.0, 8.0);
    assert!(close(parent.mass(), m1 + m2, EXACT));
    let com = Vec3::new(m2 / (m1 + m2), 0.0, 0.0);
    assert!((parent.local_center_of_mass() - com).length() < EXACT);
    // The tensor about the joint centre: both boxes' own plus the parallel-axis terms.
    let own = |m: Real, h: Vec3| {
        Vec3::new(
            h.y * h.y + h.z * h.z,
            h.x * h.x + h.z * h.z,
            h.x * h.x + h.y * h.y,
        ) * (m / 3.0)
    };
    let d1 = com.x;
    let d2 = 1.0 - com.x;
    let i = own(m1, Vec3::new(0.1, 0.2, 0.3))
        + own(m2, Vec3::splat(0.1))
        + Vec3::new(0.0, 1.0, 1.0) * (m1 * d1 * d1 + m2 * d2 * d2);
    assert!(mat_close(
        parent.inertia_local(),
        Mat3::from_diagonal(i),
        EXACT
    ));
    assert_eq!(world.body_count(), 4);
}

#[test]
fn inertial_elements_set_mass_centre_and_full_tensor() {
    let (world, m) = load("inertial.xml");
    let diag = world.body(m.body("diag").unwrap()).unwrap();
    assert_eq!(diag.mass(), 2.0);
    assert!((diag.local_center_of_mass() - Vec3::new(0.1, 0.2, 0.3)).length() < EXACT);
    // diaginertia in a frame turned 90° about z: x and y moments swap.
    let expected = Mat3::from_diagonal(Vec3::new(0.2, 0.1, 0.25));
    assert!(
        mat_close(diag.inertia_local(), expected, 1e-6),
        "{}",
        diag.inertia_local()
    );
    let full = world.body(m.body("full").unwrap()).unwrap();
    let expected = Mat3::from_cols(
        Vec3::new(0.3, 0.01, 0.02),
        Vec3::new(0.01, 0.4, 0.03),
        Vec3::new(0.02, 0.03, 0.5),
    );
    assert!(mat_close(full.inertia_local(), expected, EXACT));
    assert_eq!(full.mass(), 3.0);
}

#[test]
fn cartpole_joints_keep_the_files_names_limits_and_coordinates() {
    let (mut world, m) = load("cartpole.xml");
    // The floor is a static plane; cart and pole are dynamic.
    assert_eq!(world.body_count(), 3);
    let cart = world.body(m.body("cart").unwrap()).unwrap();
    assert_eq!(cart.mass(), 1.5);
    let pole = world.body(m.body("pole").unwrap()).unwrap();
    assert!(close(pole.mass(), 0.2, EXACT));
    // euler="0 20 0" (degrees): the pole leans 20° about y.
    let lean = pole.orientation() * Vec3::Z;
    let t = (20.0 as Real).to_radians();
    assert!((lean - Vec3::new(t.sin(), 0.0, t.cos())).length() < 1e-6);
    let slider = m.joint("slider").unwrap();
    assert_eq!(slider.kind, "slide");
    let hinge = m.joint("hinge").unwrap();
    let j = world.joint(hinge.id.unwrap()).unwrap();
    match j.def().kind {
        tumble::JointKind::Hinge { limits, .. } => {
            let [lo, hi] = limits.unwrap();
            assert!(close(lo, -PI / 2.0, EXACT) && close(hi, PI / 2.0, EXACT));
        }
        k => panic!("{k:?}"),
    }
    // Coordinates are zero at the file's placement, and follow MuJoCo's signs: the
    // cart moved +0.3 along x reads +0.3; the pole turned +0.1 about y reads +0.1.
    let s = world
        .joint_position(slider.id.unwrap())
        .unwrap()
        .scalar()
        .unwrap();
    assert!(s.abs() < 1e-9);
    world
        .set_joint_position(slider.id.unwrap(), JointCoordinate::Scalar(0.3))
        .unwrap();
    let x = world.body(m.body("cart").unwrap()).unwrap().position().x;
    assert!((x - 0.3).abs() < 1e-6, "{x}");
    world
        .set_joint_position(hinge.id.unwrap(), JointCoordinate::Scalar(0.1))
        .unwrap();
    let lean = world.body(m.body("pole").unwrap()).unwrap().orientation() * Vec3::Z;
    let t2 = t + 0.1;
    assert!(
        (lean - Vec3::new(t2.sin(), 0.0, t2.cos())).length() < 1e-5,
        "{lean}"
    );
    let a = &m.actuators[0];
    assert_eq!(
        (a.name.as_str(), a.kind.as_str(), a.joint.as_str()),
        ("push", "motor", "slider")
    );
    assert_eq!((a.gain, a.ctrl_range), (10.0, Some([-1.0, 1.0])));
}

/// The cart-pole released from its 20° lean: no force acts along x, so the system's
/// centre of mass keeps its x (to the solver's tolerance), while the pole falls.
#[test]
fn cartpole_keeps_its_centre_of_mass_over_the_rail() {
    let (mut world, m) = load("cartpole.xml");
    let ids = [m.body("cart").unwrap(), m.body("pole").unwrap()];
    let com_x = |w: &World| {
        let (mut mx, mut mm) = (0.0, 0.0);
        for id in ids {
            let b = w.body(id).unwrap();
            mx += b.mass() * b.center_of_mass().x;
            mm += b.mass();
        }
        mx / mm
    };
    let x0 = com_x(&world);
    let hinge = m.joint("hinge").unwrap().id.unwrap();
    for _ in 0..300 {
        world.step(0.001).unwrap();
    }
    let angle = world.joint_position(hinge).unwrap().scalar().unwrap();
    assert!(angle > 0.05, "the pole falls the way it leans: {angle}");
    // 1 mm of drift over 0.3 s while the pole's centre moves ~3 cm sideways.
    eprintln!(
        "cart-pole: centre of mass x moved {} m, pole at {angle} rad",
        com_x(&world) - x0
    );
    assert!(
        (com_x(&world) - x0).abs() < 1e-3,
        "{} vs {x0}",
        com_x(&world)
    );
}

/// A passive double pendulum released from horizontal: total energy stays within 0.1% of
/// its swing (m g L) over 2 s at dt = 1 ms (measured 3e-6 of it in f64 with RK4 from the
/// file's `<option>`; the rest is room for f32).
#[test]
fn double_pendulum_conserves_energy() {
    let (mut world, m) = load("double_pendulum.xml");
    let e0 = world.diagnostics().total;
    let bodies = ["upper", "lower"].map(|n| world.body(m.body(n).unwrap()).unwrap().mass());
    let scale = (bodies[0] + bodies[1]) * 9.81 * 0.9;
    let mut worst: Real = 0.0;
    for _ in 0..2000 {
        world.step(0.001).unwrap();
        worst = worst.max((world.diagnostics().total - e0).abs());
    }
    eprintln!("double pendulum: worst energy change {worst} J of m g L = {scale} J");
    assert!(worst < 1e-3 * scale, "energy moved {worst} J of {scale}");
    let elbow = m.joint("elbow").unwrap().id.unwrap();
    let q = world.joint_position(elbow).unwrap().scalar().unwrap();
    assert!(q.abs() > 0.01, "the elbow bends: {q}");
}

/// A capsule pendulum (length l, radius r, hanging from its end) started at a small
/// angle: its period is 2π √(I_pivot / (m g d)) (d = l/2), lengthened by θ₀²/16.
#[test]
fn pendulum_small_angle_period() {
    for (l, r, dt) in [(0.5, 0.02, 0.0005), (1.2, 0.05, 0.001)] {
        let text = format!(
            r#"<mujoco><compiler angle="radian"/><worldbody>
            <body name="link" pos="0 0 3"><joint name="pivot" axis="0 1 0"/>
            <geom type="capsule" fromto="0 0 0 0 0 -{l}" size="{r}"/></body>
            </worldbody></mujoco>"#
        );
        let mut world = z_up();
        let m = mjcf::load(
            write("period.xml", &text),
            &mut world,
            &MjcfOptions::default(),
        )
        .unwrap();
        let id = m.joint("pivot").unwrap().id.unwrap();
        let theta0 = 0.05;
        world
            .set_joint_position(id, JointCoordinate::Scalar(theta0))
            .unwrap();
        let b = world.body(m.body("link").unwrap()).unwrap();
        let d = l / 2.0;
        let (mass, i) = capsule_x(1000.0, r, l);
        let pivot = i.y_axis.y + mass * d * d;
        let period = 2.0 * PI * (pivot / (mass * 9.81 * d)).sqrt() * (1.0 + theta0 * theta0 / 16.0);
        assert!(close(b.mass(), mass, EXACT));
        // Time of the second downward zero crossing after the first: one full period.
        let (mut prev, mut k, mut crossings) = (theta0, 0u32, Vec::new());
        while crossings.len() < 3 && k < 20_000 {
            world.step(dt).unwrap();
            k += 1;
            // The step count times dt, not a running sum, which rounds in f32.
            let t = k as Real * dt;
            let q = world.joint_position(id).unwrap().scalar().unwrap();
            if prev > 0.0 && q <= 0.0 {
                crossings.push(t - dt * q / (q - prev));
            }
            prev = q;
        }
        let measured = crossings[2] - crossings[1];
        eprintln!("pendulum l {l}: period {measured} s, closed form {period} s");
        // Measured within 1e-8 of it (f64); 1e-4 leaves room for f32's rounding over
        // thousands of steps, and still fails on a wrong mass, inertia or pivot.
        assert!(
            close(measured, period, 1e-4),
            "l {l}: {measured} vs {period}"
        );
    }
}

/// contype/conaffinity: for every pair of bodies, Tumble's group/mask rule gives
/// MuJoCo's answer, including the one-way case a (1, 0) geom meets a (1, 1) floor.
#[test]
fn collision_filters_follow_mujocos_rule() {
    let pairs = [(1, 1), (1, 0), (2, 1), (0, 2), (4, 4), (1, 0)];
    let mut text = String::from("<mujoco><worldbody>\n");
    for (i, (ct, ca)) in pairs.iter().enumerate() {
        text += &format!(
            "<body name=\"b{i}\" pos=\"{i} 0 0\"><freejoint/><geom size=\"0.1\" contype=\"{ct}\" conaffinity=\"{ca}\"/></body>\n"
        );
    }
    text += "</worldbody></mujoco>";
    let mut world = z_up();
    let m = mjcf::load(
        write("filters.xml", &text),
        &mut world,
        &MjcfOptions::default(),
    )
    .unwrap();
    for (i, a) in pairs.iter().enumerate() {
        for (j, b) in pairs.iter().enumerate() {
            let mujoco = a.0 & b.1 != 0 || b.0 & a.1 != 0;
            let fa = world
                .body(m.body(&format!("b{i}")).unwrap())
                .unwrap()
                .collision_filter();
            let fb = world
                .body(m.body(&format!("b{j}")).unwrap())
                .unwrap()
                .collision_filter();
            let tumble = fa.0 & fb.1 != 0 && fb.0 & fa.1 != 0;
            assert_eq!(mujoco, tumble, "{a:?} with {b:?}");
        }
    }
}

/// Parent and child never collide, even when extra joints chain them through light
/// bodies; the chain gives each joint its coordinate.
#[test]
fn several_joints_in_one_body_chain_and_keep_their_coordinates() {
    let text = r#"<mujoco><compiler angle="radian"/><worldbody>
      <body name="base" pos="0 0 1"><freejoint/><geom type="box" size="0.2 0.2 0.2"/>
        <body name="tip" pos="0 0 0">
          <joint name="tx" type="slide" axis="1 0 0"/>
          <joint name="tz" type="slide" axis="0 0 1"/>
          <joint name="ry" type="hinge" axis="0 1 0"/>
          <geom type="sphere" size="0.1"/>
        </body>
      </body></worldbody></mujoco>"#;
    let (mut world, m) = load_at(write("chain.xml", text));
    // base, tip and two light bodies between them.
    assert_eq!(world.body_count(), 4);
    assert!(m
        .warnings
        .iter()
        .any(|w| w.message.contains("several joints")));
    let tz = m.joint("tz").unwrap().id.unwrap();
    world
        .set_joint_position(tz, JointCoordinate::Scalar(0.25))
        .unwrap();
    let tip = world.body(m.body("tip").unwrap()).unwrap().position();
    assert!((tip - Vec3::new(0.0, 0.0, 1.25)).length() < 1e-6, "{tip}");
    for _ in 0..100 {
        world.step(0.002).unwrap();
    }
    // The sphere sits inside the box: had they collided they would have been pushed apart.
    for name in ["tx", "tz", "ry"] {
        let q = world
            .joint_position(m.joint(name).unwrap().id.unwrap())
            .unwrap()
            .scalar()
            .unwrap();
        let expect = if name == "tz" { 0.25 } else { 0.0 };
        assert!((q - expect).abs() < 1e-3, "{name}: {q}");
    }
}

/// Gymnasium's pusher.xml: a goal marker of 4e-10 kg on two slide joints. Its light
/// intermediate body, a thousandth of that, would be below the engine's least mass; it is
/// kept at the least instead, and the model loads as MuJoCo loads it.
#[test]
fn a_light_intermediate_body_of_a_tiny_body_is_kept_at_the_engines_least_mass() {
    let text = r#"<mujoco><worldbody>
      <body name="goal" pos="0.45 -0.05 -0.3230">
        <joint name="goal_slidex" type="slide" axis="1 0 0" limited="true" range="-10.3213 10.3"/>
        <joint name="goal_slidey" type="slide" axis="0 1 0" limited="true" range="-10.3213 10.3"/>
        <geom type="cylinder" size=".08 .001 .1" density="0.00001" contype="0" conaffinity="0"/>
      </body></worldbody></mujoco>"#;
    let mut world = z_up();
    let m = mjcf::load(write("tiny.xml", text), &mut world, &MjcfOptions::default()).unwrap();
    let goal = world.body(m.body("goal").unwrap()).unwrap();
    let expect = PI * 0.08 * 0.08 * 0.002 * 1e-5;
    assert!(close(goal.mass(), expect, 1e-6), "{}", goal.mass());
    let least = world
        .bodies()
        .map(|(_, b)| b.mass())
        .filter(|m| *m > 0.0)
        .fold(Real::INFINITY, Real::min);
    assert_eq!(least, tumble::limits::MIN_MASS);
    for _ in 0..10 {
        world.step(0.002).unwrap();
    }
}

/// `<frame>` places what it holds: a box 1 m up a frame turned 90° about z, in a body.
#[test]
fn frames_place_their_geoms_and_bodies() {
    let text = r#"<mujoco><compiler angle="degree"/><worldbody>
      <body name="b" pos="0 0 1"><freejoint/>
        <geom type="sphere" size="0.1" mass="1"/>
        <frame pos="1 0 0" euler="0 0 90">
          <geom type="box" pos="1 0 0" size="0.1 0.1 0.1" mass="3"/>
          <body name="c" pos="0 1 0"><joint axis="1 0 0"/><geom size="0.1"/></body>
        </frame>
      </body></worldbody></mujoco>"#;
    let mut world = z_up();
    let m = mjcf::load(
        write("frame.xml", text),
        &mut world,
        &MjcfOptions::default(),
    )
    .unwrap();
    let b = world.body(m.body("b").unwrap()).unwrap();
    // The box sits at (1, 1, 0) in b's frame: the centre of mass is 3/4 of the way there.
    let com = Vec3::new(0.75, 0.75, 0.0);
    assert!(
        (b.local_center_of_mass() - com).length() < 1e-5,
        "{}",
        b.local_center_of_mass()
    );
    let c = world.body(m.body("c").unwrap()).unwrap();
    // (0, 1, 0) in the turned frame is (−1, 0, 0): c's origin is at (0, 0, 1) in the world.
    assert!(
        (c.position() - Vec3::new(0.0, 0.0, 1.0)).length() < 1e-5,
        "{}",
        c.position()
    );
    assert!(m.warnings.is_empty(), "{:?}", m.warnings);
}

#[test]
fn includes_and_their_defaults_are_read() {
    let (world, m) = load("with_include.xml");
    let mass = world.body(m.body("ball").unwrap()).unwrap().mass();
    assert!(close(mass, 2000.0 * 4.0 / 3.0 * PI * 0.001, EXACT));
}

#[test]
fn unsupported_parts_are_warned_once_with_their_line() {
    let text = "<mujoco>\n<worldbody>\n<body name=\"a\"><joint frictionloss=\"0.1\"/>\n<geom size=\"0.1\"/>\n<geom type=\"hfield\" hfield=\"m\"/>\n<geom type=\"hfield\" hfield=\"n\"/>\n</body>\n</worldbody>\n<tendon/>\n</mujoco>";
    let mut world = z_up();
    let m = mjcf::load(write("warn.xml", text), &mut world, &MjcfOptions::default()).unwrap();
    let lines: Vec<String> = m.warnings.iter().map(|w| w.to_string()).collect();
    assert!(
        lines.contains(&"warn.xml:5: <geom>: hfield geoms: not yet read (skipped)".to_string()),
        "{lines:?}"
    );
    assert!(
        lines
            .iter()
            .any(|l| l.starts_with("warn.xml:3: <joint>: joint frictionloss")),
        "{lines:?}"
    );
    assert!(
        lines.contains(&"warn.xml:9: <tendon>: <tendon>: not read".to_string()),
        "{lines:?}"
    );
    assert_eq!(lines.len(), 3, "{lines:?}");
}

#[test]
fn armature_is_read_from_hinges_slides_and_defaults_and_warned_on_balls() {
    let text = "<mujoco>\n<default><joint armature=\"0.25\"/></default>\n<worldbody>\n<body name=\"a\"><joint name=\"h\" type=\"hinge\"/><geom size=\"0.1\"/>\n<body name=\"b\" pos=\"0 0 -1\"><joint name=\"s\" type=\"slide\" armature=\"2\"/><geom size=\"0.1\"/>\n<body name=\"c\" pos=\"0 0 -1\"><joint name=\"ball\" type=\"ball\"/><geom size=\"0.1\"/>\n</body></body></body>\n</worldbody>\n</mujoco>";
    let (world, m) = load_at(write("armature.xml", text));
    let armature = |name: &str| {
        let id = m.joint(name).unwrap().id.unwrap();
        world.joint(id).unwrap().def().armature
    };
    assert_eq!(
        (armature("h"), armature("s"), armature("ball")),
        (0.25, 2.0, 0.0)
    );
    let lines: Vec<String> = m.warnings.iter().map(|w| w.to_string()).collect();
    assert_eq!(
        lines,
        ["armature.xml:6: <joint name=\"ball\">: ball joint armature: not applied"],
    );
}

/// Every kind of bad file: one line, `file:line: <element>: what`, and the world as it
/// was (one body of its own before and after).
#[test]
fn bad_files_give_one_line_naming_file_line_and_element() {
    let cases: [(&str, &str, &str); 12] = [
        ("malformed.xml", "<mujoco>\n<worldbody>\n</mujoco>", "malformed.xml:3: malformed XML"),
        ("units.xml", "<mujoco>\n<compiler angle=\"grad\"/>\n</mujoco>",
         "units.xml:2: <compiler>: angle: unknown unit 'grad' (expected degree or radian)"),
        ("inertia.xml", "<mujoco><worldbody>\n<body name=\"b\"><joint/>\n<inertial mass=\"1\" diaginertia=\"1 1 3\"/></body></worldbody></mujoco>",
         "inertia.xml:3: <inertial>: diaginertia: impossible inertia"),
        ("size.xml", "<mujoco><worldbody>\n<geom name=\"g\" size=\"-0.1\"/></worldbody></mujoco>",
         "size.xml:2: <geom name=\"g\">: size: must be > 0, got -0.1"),
        ("massless.xml", "<mujoco><worldbody>\n<body name=\"b\"><joint/><geom size=\"0.1\" mass=\"0\"/></body></worldbody></mujoco>",
         "massless.xml:2: <body name=\"b\">: mass and inertia of a moving body must be > 0"),
        ("joint.xml", "<mujoco><worldbody><body>\n<joint type=\"weld\"/><geom size=\"1\"/></body></worldbody></mujoco>",
         "joint.xml:2: <joint>: type: unknown joint type 'weld'"),
        ("class.xml", "<mujoco><worldbody>\n<geom class=\"nope\" size=\"1\"/></worldbody></mujoco>",
         "class.xml:2: <geom>: class: no <default class=\"nope\">"),
        ("quat.xml", "<mujoco><worldbody>\n<body quat=\"0 0 0 0\"><joint/><geom size=\"1\"/></body></worldbody></mujoco>",
         "quat.xml:2: <body>: quat: must not be zero"),
        ("number.xml", "<mujoco><worldbody>\n<geom size=\"abc\"/></worldbody></mujoco>",
         "number.xml:2: <geom>: size: 'abc' is not a number"),
        ("plane.xml", "<mujoco><worldbody><body><joint/>\n<geom type=\"plane\" size=\"1 1 1\"/></body></worldbody></mujoco>",
         "plane.xml:2: <geom>: type: a plane must be part of the world body"),
        ("actuator.xml", "<mujoco><worldbody/><actuator>\n<motor joint=\"ghost\"/></actuator></mujoco>",
         "actuator.xml:2: <motor>: joint: no joint 'ghost'"),
        ("root.xml", "<robot>\n</robot>", "root.xml:1: <robot>: the root element must be <mujoco>"),
    ];
    for (name, text, expected) in cases {
        let mut world = z_up();
        world
            .create_body(&tumble::BodyDef::default(), tumble::Shape::sphere(1.0))
            .unwrap();
        let err = mjcf::load(write(name, text), &mut world, &MjcfOptions::default()).unwrap_err();
        let line = err.to_string();
        assert!(line.starts_with(expected), "{name}: {line}");
        assert!(!line.contains('\n'), "{line}");
        assert_eq!(world.body_count(), 1, "{name}");
    }
}

#[test]
fn missing_files_are_named() {
    let mut world = z_up();
    let err = mjcf::load(
        model("no_such_model.xml"),
        &mut world,
        &MjcfOptions::default(),
    )
    .unwrap_err()
    .to_string();
    assert!(err.starts_with("no_such_model.xml: cannot read"), "{err}");
    let err = mjcf::load(
        model("bad_include_main.xml"),
        &mut world,
        &MjcfOptions::default(),
    )
    .unwrap_err()
    .to_string();
    assert!(
        err.starts_with("bad_include_main.xml:2: <include>: file: cannot read"),
        "{err}"
    );
    assert!(err.contains("missing_part.xml"), "{err}");
}

/// A failure found only when the world creates the bodies (two bodies of one name)
/// removes what had been created.
#[test]
fn a_failure_while_creating_leaves_the_world_as_it_was() {
    let text = r#"<mujoco><worldbody>
      <body name="twin"><joint/><geom size="0.1"/></body>
      <body name="twin"><joint/><geom size="0.1"/></body>
    </worldbody></mujoco>"#;
    let mut world = z_up();
    let err = mjcf::load(
        write("twins.xml", text),
        &mut world,
        &MjcfOptions::default(),
    )
    .unwrap_err()
    .to_string();
    assert!(
        err.starts_with("twins.xml:3: <body name=\"twin\">"),
        "{err}"
    );
    assert_eq!(world.body_count(), 0);
    assert_eq!(world.joints().count(), 0);
}

#[test]
fn a_scene_runs_from_an_mjcf_path() {
    let path = model("cartpole.xml");
    let mut scene = tumble_scene::load(path.to_str().unwrap()).unwrap();
    assert_eq!(scene.dt, 0.001);
    assert_eq!(scene.world.gravity(), Vec3::new(0.0, 0.0, -9.81));
    assert_eq!(scene.body_names.len(), scene.world.body_count());
    assert!(scene.body_names.contains(&"pole".to_string()));
    let plan = scene.plan().unwrap();
    for k in 1..=plan.steps.min(100) {
        scene.step(plan.step_dt(k)).unwrap();
    }
}

/// A pendulum link about a vertical hinge (gravity does no work on it) with one actuator
/// of each kind: the motor's torque gives α = τ / I_pivot exactly; the position servo
/// settles at its control; the velocity actuator drives to its control speed.
#[test]
fn actuator_controls_drive_their_joints() {
    let text = r#"<mujoco><compiler angle="radian"/><option gravity="0 0 -9.81"/>
      <worldbody>
        <body name="arm" pos="0 0 1"><joint name="j" axis="0 0 1"/>
          <geom type="box" pos="0.25 0 0" size="0.25 0.05 0.05" mass="2"/></body>
        <body name="arm2" pos="0 3 1"><joint name="k" axis="0 0 1"/>
          <geom type="box" pos="0.25 0 0" size="0.25 0.05 0.05" mass="2"/></body>
        <body name="arm3" pos="0 6 1"><joint name="v" axis="0 0 1"/>
          <geom type="box" pos="0.25 0 0" size="0.25 0.05 0.05" mass="2"/></body>
      </worldbody>
      <actuator>
        <motor name="twist" joint="j" gear="4" ctrlrange="-1 1"/>
        <position name="hold" joint="k" kp="20" kv="3"/>
        <velocity name="spin" joint="v" kv="5"/>
      </actuator></mujoco>"#;
    let mut world = z_up();
    let mut m = mjcf::load(
        write("actuators.xml", text),
        &mut world,
        &MjcfOptions::default(),
    )
    .unwrap();
    // Control 2 is clamped to the range's 1: a torque of 4 N·m.
    m.set_control(&mut world, "twist", 2.0).unwrap();
    m.set_control(&mut world, "hold", 0.4).unwrap();
    m.set_control(&mut world, "spin", 1.5).unwrap();
    assert_eq!(m.actuators[0].control, 1.0);
    let (mass, h) = (2.0, Vec3::new(0.25, 0.05, 0.05));
    let pivot = mass / 3.0 * (h.x * h.x + h.y * h.y) + mass * h.x * h.x;
    let dt = 0.001;
    for _ in 0..500 {
        world.step(dt).unwrap();
    }
    let rate = |w: &World, n: &str| {
        let id = m.joint(n).unwrap().id.unwrap();
        w.joint_velocity(id).unwrap().scalar().unwrap()
    };
    let expected = 4.0 / pivot * 0.5;
    // The motor's impulse is its bound every substep; the hinge's soft locking rows,
    // holding the spinning arm's centripetal load, take a little (measured 8e-6).
    assert!(
        close(rate(&world, "j"), expected, 1e-4),
        "{} vs {expected}",
        rate(&world, "j")
    );
    for _ in 0..9500 {
        world.step(dt).unwrap();
    }
    let at = |w: &World, n: &str| {
        let id = m.joint(n).unwrap().id.unwrap();
        w.joint_position(id).unwrap().scalar().unwrap()
    };
    // Ten seconds: the servo (k = 20, c = 3 against I = 0.17) has long settled; the
    // spinning one reached kv·ctrl / kv = 1.5 rad/s (time constant I / kv = 0.03 s).
    assert!((at(&world, "k") - 0.4).abs() < 1e-3, "{}", at(&world, "k"));
    assert!(
        (rate(&world, "v") - 1.5).abs() < 1e-3,
        "{}",
        rate(&world, "v")
    );
    let err = m
        .set_control(&mut world, "nope", 1.0)
        .unwrap_err()
        .to_string();
    assert_eq!(err, "actuator 'nope': no such actuator");
}

/// A ball joint's coordinate is a rotation vector in the parent's frame: MuJoCo's qpos
/// quaternion Q (in the child's placement frame q0) is the vector q0 · log(Q).
#[test]
fn ball_coordinates_map_to_mujocos_quaternion() {
    let text = r#"<mujoco><compiler angle="degree"/><worldbody>
      <body name="ball" pos="0 0 1" axisangle="0 0 1 90"><joint name="b" type="ball"/>
        <geom type="capsule" fromto="0 0 0 0.5 0 0" size="0.05"/></body>
      </worldbody></mujoco>"#;
    let mut world = z_up();
    let m = mjcf::load(write("ball.xml", text), &mut world, &MjcfOptions::default()).unwrap();
    let q0 = Quat::from_axis_angle(Vec3::Z, PI / 2.0);
    // MuJoCo's qpos: 0.3 rad about the child's own x axis.
    let local = Vec3::new(0.3, 0.0, 0.0);
    let id = m.joint("b").unwrap().id.unwrap();
    world
        .set_joint_position(id, JointCoordinate::Vector(q0 * local))
        .unwrap();
    let q = world.body(m.body("ball").unwrap()).unwrap().orientation();
    let mujoco = q0 * Quat::from_axis_angle(Vec3::X, 0.3);
    assert!(q.dot(mujoco).abs() > 1.0 - 1e-6, "{q} vs {mujoco}");
    // And the anchor stays put: the body turned about its origin.
    let p = world.body(m.body("ball").unwrap()).unwrap().position();
    assert!((p - Vec3::new(0.0, 0.0, 1.0)).length() < 1e-6, "{p}");
}

/// A box of sides `s` with its low corner at `lo`, as OBJ text (quads, split by the reader).
fn box_obj(lo: Vec3, s: Vec3) -> String {
    let mut text = String::from("# box\n");
    for i in 0..8 {
        let c = |bit: u32, k: usize| lo[k] + s[k] * ((i >> bit) & 1) as Real;
        text += &format!("v {} {} {}\n", c(0, 0), c(1, 1), c(2, 2));
    }
    for q in [
        "1 3 4 2", "5 6 8 7", "1 2 6 5", "3 7 8 4", "1 5 7 3", "2 4 8 6",
    ] {
        text += &format!("f {q}\n");
    }
    text
}

/// The right tetrahedron O, aX, bY, cZ as binary STL (outward triangles).
fn tetra_stl(a: f32, b: f32, c: f32) -> Vec<u8> {
    let p = [[0.0, 0.0, 0.0], [a, 0.0, 0.0], [0.0, b, 0.0], [0.0, 0.0, c]];
    let tris = [[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]];
    let mut out = vec![b' '; 80];
    out.extend_from_slice(&4u32.to_le_bytes());
    for t in tris {
        out.extend_from_slice(&[0u8; 12]);
        for v in t {
            for x in p[v] {
                out.extend_from_slice(&(x as f32).to_le_bytes());
            }
        }
        out.extend_from_slice(&[0u8; 2]);
    }
    out
}

/// Tolerance of mesh mass properties: rounding of sums over the mesh's triangles.
const MESH: Real = if std::mem::size_of::<Real>() == 4 {
    3e-5
} else {
    1e-9
};

/// Mesh geoms: a scaled, offset box (OBJ, found through `meshdir`) placed with a turn,
/// and a right tetrahedron (binary STL, given a mass): volume, centre and inertia in
/// closed form; the compound's child sits at the mesh's centre (MuJoCo's `geom_pos`).
#[test]
fn mesh_geoms_have_the_closed_form_mass_centre_and_inertia() {
    let (lo, s, scale) = (
        Vec3::new(1.0, 2.0, 3.0),
        Vec3::new(0.4, 0.2, 0.1),
        Vec3::new(1.0, 2.0, 3.0),
    );
    let dir = write("meshes/box.obj", &box_obj(lo, s))
        .parent()
        .unwrap()
        .to_path_buf();
    std::fs::write(dir.join("tetra.stl"), tetra_stl(0.3, 0.5, 0.7)).unwrap();
    let text = r#"<mujoco><compiler meshdir="meshes" angle="radian"/>
      <asset><mesh file="box.obj" scale="1 2 3"/><mesh name="t" file="tetra.stl"/></asset>
      <worldbody>
        <body name="box" pos="0 0 2"><freejoint/>
          <geom type="mesh" mesh="box" pos="0.1 0.2 0.3" axisangle="0 0 1 0.5" density="800"/></body>
        <body name="tetra" pos="3 0 2"><freejoint/><geom type="mesh" mesh="t" mass="2"/></body>
      </worldbody></mujoco>"#;
    let mut world = z_up();
    let m = mjcf::load(write("mesh.xml", text), &mut world, &MjcfOptions::default()).unwrap();
    assert!(m.warnings.is_empty(), "{:?}", m.warnings);
    let b = world.body(m.body("box").unwrap()).unwrap();
    let sides = s * scale;
    let mass = 800.0 * sides.x * sides.y * sides.z;
    let turn = Quat::from_axis_angle(Vec3::Z, 0.5);
    let centre = Vec3::new(0.1, 0.2, 0.3) + turn * ((lo + 0.5 * s) * scale);
    // Exact to rounding of the sums: in f32 the box's vertices, 9 m out, carry 1e-6 m of
    // rounding against its 0.3 m sides (mass measured 2.4e-6 off).
    assert!(close(b.mass(), mass, MESH), "{} vs {mass}", b.mass());
    assert!(
        (b.local_center_of_mass() - centre).length() < MESH,
        "{}",
        b.local_center_of_mass()
    );
    let sq = sides * sides;
    let own = Vec3::new(sq.y + sq.z, sq.x + sq.z, sq.x + sq.y) * (mass / 12.0);
    let r = Mat3::from_quat(turn);
    let expected = r * Mat3::from_diagonal(own) * r.transpose();
    assert!(
        mat_close(b.inertia_local(), expected, MESH),
        "{}",
        b.inertia_local()
    );
    let tumble::Shape::Compound(children) = b.shape() else {
        panic!("a compound: {:?}", b.shape().kind_name());
    };
    assert!((children[0].position - centre).length() < MESH);
    assert_eq!(children[0].shape.kind_name(), "convex_hull");
    // The tetrahedron: V = abc/6, centre (a, b, c)/4, covariance about the centre
    // C_ii = m a_i² · 3/80, C_ij = −m a_i a_j / 80; inertia tr(C) 1 − C.
    let t = world.body(m.body("tetra").unwrap()).unwrap();
    let e = Vec3::new(0.3, 0.5, 0.7);
    assert!(close(t.mass(), 2.0, 1e-12));
    // The STL holds f32 vertices: 1e-7 relative.
    assert!((t.local_center_of_mass() - e / 4.0).length() < MESH.max(1e-7));
    let c = Mat3::from_cols(e * e.x, e * e.y, e * e.z) * (-2.0 / 80.0)
        + Mat3::from_diagonal(e * e) * (2.0 * 4.0 / 80.0);
    let trace = c.x_axis.x + c.y_axis.y + c.z_axis.z;
    let expected = Mat3::from_diagonal(Vec3::splat(trace)) - c;
    assert!(
        mat_close(t.inertia_local(), expected, MESH.max(1e-6)),
        "{} vs {expected}",
        t.inertia_local()
    );
}

/// An L-shaped prism (three unit cubes): MuJoCo's three inertia modes. Exact and legacy
/// (star-shaped about its faces' centroid) give the true volume 3 and centre (5/6, 5/6,
/// 1/2); convex gives its hull's, volume 3.5.
#[test]
fn mesh_inertia_modes_read_a_non_convex_mesh_as_mujoco_does() {
    let poly = [
        (0.0, 0.0),
        (2.0, 0.0),
        (2.0, 1.0),
        (1.0, 1.0),
        (1.0, 2.0),
        (0.0, 2.0),
    ];
    let mut verts = String::new();
    for z in [0.0, 1.0] {
        for (x, y) in poly {
            verts += &format!("{x} {y} {z} ");
        }
    }
    let mut faces = String::new();
    for k in 1..5 {
        faces += &format!("0 {} {} 6 {} {} ", k + 1, k, 6 + k, 7 + k);
    }
    for k in 0..6 {
        let (a, b) = (k, (k + 1) % 6);
        faces += &format!("{a} {b} {} {a} {} {} ", 6 + b, 6 + b, 6 + a);
    }
    for (mode, volume, centre) in [
        ("legacy", 3.0, Vec3::new(5.0 / 6.0, 5.0 / 6.0, 0.5)),
        ("exact", 3.0, Vec3::new(5.0 / 6.0, 5.0 / 6.0, 0.5)),
        // The hull: the L plus the triangle (1,1) (2,1) (1,2) of area 1/2, height 1.
        (
            "convex",
            3.5,
            (Vec3::new(2.5, 2.5, 1.5) + Vec3::new(4.0 / 3.0, 4.0 / 3.0, 0.5) * 0.5) / 3.5,
        ),
    ] {
        let text = format!(
            r#"<mujoco><asset><mesh name="l" vertex="{verts}" face="{faces}" inertia="{mode}"/></asset>
            <worldbody><body name="l"><freejoint/><geom type="mesh" mesh="l" density="1"/></body></worldbody></mujoco>"#
        );
        let mut world = z_up();
        let m = mjcf::load(write("l.xml", &text), &mut world, &MjcfOptions::default()).unwrap();
        let b = world.body(m.body("l").unwrap()).unwrap();
        assert!(close(b.mass(), volume, EXACT), "{mode}: {}", b.mass());
        let c = b.local_center_of_mass();
        assert!((c - centre).length() < 1e-6, "{mode}: {c}");
    }
}

/// A mesh welded to the world keeps its triangles (a static mesh body of its own); a
/// ball dropped on the box's top face comes to rest on it.
#[test]
fn a_static_mesh_keeps_its_triangles_and_holds_a_ball() {
    let dir = write("static/box.obj", &box_obj(Vec3::splat(-0.5), Vec3::ONE))
        .parent()
        .unwrap()
        .to_path_buf();
    let text = r#"<mujoco><asset><mesh file="box.obj"/></asset><worldbody>
      <geom type="mesh" mesh="box" pos="0 0 0.5"/>
      <body name="ball" pos="0.1 0.1 1.5"><freejoint/><geom size="0.1"/></body>
      </worldbody></mujoco>"#;
    let path = dir.join("on_mesh.xml");
    std::fs::write(&path, text).unwrap();
    let mut world = z_up();
    let m = mjcf::load(&path, &mut world, &MjcfOptions::default()).unwrap();
    let kinds: Vec<&str> = world
        .body_ids()
        .iter()
        .map(|id| world.body(*id).unwrap().shape().kind_name())
        .collect();
    assert!(kinds.contains(&"trimesh"), "{kinds:?}");
    for _ in 0..600 {
        world.step(1.0 / 240.0).unwrap();
    }
    let z = world.body(m.body("ball").unwrap()).unwrap().position().z;
    // At rest on the top face (z = 1) within the contact slop (a few mm).
    assert!((z - 1.1).abs() < 5e-3, "{z}");
}

#[test]
fn bad_meshes_give_one_line_naming_the_element() {
    let flat = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nf 1 2 3\nf 2 4 3\n";
    write("badmesh/flat.obj", flat);
    let cases = [
        ("<geom type=\"mesh\" mesh=\"ghost\"/>", "<asset/>", "<geom>: mesh: no mesh asset 'ghost'"),
        ("<geom type=\"mesh\" mesh=\"gone\"/>", "<asset>\n<mesh file=\"gone.stl\"/></asset>",
         "<mesh>: file: "),
        ("<geom type=\"mesh\" mesh=\"flat\"/>", "<asset>\n<mesh file=\"flat.obj\"/></asset>",
         "<mesh>: mesh has no volume"),
        ("<geom type=\"mesh\" mesh=\"in\"/>",
         "<asset>\n<mesh name=\"in\" inertia=\"exact\" vertex=\"0 0 0 1 0 0 0 1 0 0 0 1\" face=\"0 1 2 0 3 1 0 2 3 1 3 2\"/></asset>",
         "<mesh name=\"in\">: mesh volume is negative"),
    ];
    for (geom, asset, expected) in cases {
        let text = format!(
            "<mujoco>{asset}<worldbody><body><freejoint/>\n{geom}</body></worldbody></mujoco>"
        );
        let path = write("badmesh/bad.xml", &text);
        let mut world = z_up();
        let err = mjcf::load(&path, &mut world, &MjcfOptions::default())
            .unwrap_err()
            .to_string();
        assert!(
            err.starts_with("bad.xml:") && err.contains(expected),
            "{err}"
        );
        assert!(!err.contains('\n'), "{err}");
        assert_eq!(world.body_count(), 0);
    }
}

/// MJCF files in a scene's `models`: placed and prefixed, their bodies and joints named
/// as in the file for the scene's joints; the scene's gravity stays (the file's
/// `<option>` is not read).
#[test]
fn a_scene_places_mjcf_models_whose_bodies_its_joints_can_name() {
    let file = model("cartpole.xml");
    let file = file.to_str().unwrap();
    let scene = format!(
        r#"{{"gravity": [0, 0, -5],
      "bodies": [{{"name": "ball", "shape": {{"type": "sphere", "radius": 0.1}}, "mass": 1,
                  "position": [0, 0, 3]}}],
      "models": [
        {{"file": "{file}"}},
        {{"file": "{file}", "prefix": "b_", "position": [3, 0, 0], "orientation": [0, 0, 1, 0]}}],
      "joints": [{{"type": "fixed", "body": "ball", "other": "b_cart"}}]}}"#
    );
    let path = write("mjcf_scene.json", &scene);
    let s = tumble_scene::load(path.to_str().unwrap()).unwrap();
    for name in ["ball", "cart", "pole", "b_cart", "b_pole"] {
        assert!(
            s.body_names.iter().any(|n| n == name),
            "{name}: {:?}",
            s.body_names
        );
    }
    assert_eq!(s.body_names.len(), s.world.body_count());
    assert_eq!(s.body_colors.len(), s.world.body_count());
    let w = &s.world;
    assert_eq!(w.gravity(), Vec3::new(0.0, 0.0, -5.0));
    // The pole's centre: 0.3 m up its axis, tilted 20° about y, then the model turned
    // half a turn about z and moved 3 m along x.
    let a = (20.0 as Real).to_radians();
    let expected = Vec3::new(3.0 - 0.3 * a.sin(), 0.0, 1.0 + 0.3 * a.cos());
    let pole = w.body(w.find_body("b_pole").unwrap()).unwrap();
    assert!(
        (pole.center_of_mass() - expected).length() < 1e-6,
        "{}",
        pole.center_of_mass()
    );
    assert!(w.find_joint("b_hinge").is_some() && w.find_joint("hinge").is_some());
    assert_eq!(w.joints().count(), 5);

    let bad = |models: &str| {
        let path = write("bad_models.json", &format!(r#"{{"models": [{models}]}}"#));
        tumble_scene::load(path.to_str().unwrap())
            .unwrap_err()
            .to_string()
    };
    assert_eq!(
        bad(&format!(r#"{{"file": "{file}", "fixed_base": true}}"#)),
        "models[0].fixed_base: not used for MJCF models (the file says which bodies move)"
    );
    let missing = bad(r#"{"file": "gone.xml"}"#);
    assert!(
        missing.starts_with("models[0]: gone.xml: cannot read"),
        "{missing}"
    );
}

/// `<contact><exclude>` between two free boxes stacked over a floor: the upper one falls
/// through the lower one onto the floor (its centre 0.1 m up, to 5 mm), in each of two
/// copies of the model loaded into one world (the second copy's exclusion used to replace
/// the first's, which was a contact filter), and a world holding them is copied by a
/// Batch bit for bit.
#[test]
fn excluded_pairs_hold_in_every_copy_of_a_model_and_the_world_can_be_batched() {
    let path = write(
        "exclude.xml",
        r#"<mujoco><worldbody>
             <geom type="plane" size="5 5 0.1"/>
             <body name="upper" pos="0 0 1"><freejoint/><geom type="box" size="0.1 0.1 0.1"/></body>
             <body name="lower" pos="0 0 0.2"><freejoint/><geom type="box" size="0.2 0.2 0.2"/></body>
           </worldbody>
           <contact><exclude body1="upper" body2="lower"/></contact></mujoco>"#,
    );
    let mut world = z_up();
    for (prefix, x) in [("a/", 0.0), ("b/", 2.0)] {
        let options = MjcfOptions {
            position: Vec3::new(x, 0.0, 0.0),
            prefix: prefix.to_string(),
            ..MjcfOptions::default()
        };
        mjcf::load(&path, &mut world, &options).unwrap();
    }
    assert_eq!(world.excluded_contacts().len(), 2);
    let mut batch = tumble::Batch::new(&world, 2, Some(1)).unwrap();
    let dt = 1.0 / 100.0;
    for _ in 0..150 {
        world.step(dt).unwrap();
    }
    batch.step(dt, 150).unwrap();
    for prefix in ["a/", "b/"] {
        let upper = world.find_body(&format!("{prefix}upper")).unwrap();
        let z = world.body(upper).unwrap().position().z;
        assert!((z - 0.1).abs() < 5e-3, "{prefix}upper at z = {z}");
    }
    assert_eq!(batch.world(0).unwrap().state_hash(), world.state_hash());
}

#[test]
fn options_bodies_and_actuators_with_nothing_to_map_to_are_warned() {
    let text = "<mujoco>\n<option cone=\"elliptic\" impratio=\"10\"/>\n<worldbody>\n\
                <body name=\"target\" mocap=\"true\"><geom size=\"0.1\"/></body>\n\
                <body name=\"arm\" gravcomp=\"1\"><joint name=\"j\"/><geom size=\"0.1\"/></body>\n\
                <body name=\"idle\" gravcomp=\"0\"><joint/><geom size=\"0.1\"/></body>\n\
                </worldbody>\n<actuator><position joint=\"j\" kp=\"5\" dampratio=\"1\"/></actuator>\n\
                </mujoco>";
    let mut world = z_up();
    let m = mjcf::load(
        write("unmapped.xml", text),
        &mut world,
        &MjcfOptions::default(),
    )
    .unwrap();
    let lines: Vec<String> = m.warnings.iter().map(|w| w.to_string()).collect();
    for expected in [
        "unmapped.xml:2: <option>: option cone: not read",
        "unmapped.xml:2: <option>: option impratio: not read",
        "unmapped.xml:4: <body name=\"target\">: body mocap: not read (the body stays where it is)",
        "unmapped.xml:5: <body name=\"arm\">: body gravcomp: not read",
        "unmapped.xml:8: <position>: position actuator dampratio: not read",
    ] {
        assert!(
            lines.contains(&expected.to_string()),
            "{expected}: {lines:?}"
        );
    }
    assert_eq!(lines.len(), 5, "{lines:?}");
}

/// `<option integrator>` maps to the nearest Tumble integrator; `<compiler settotalmass>`
/// scales every moving body to the total, keeping their ratios; an ellipsoid has its exact
/// mass and inertia (m = ρ 4/3 π abc, I_x = m (b² + c²)/5, ...); a slide's `ref` and
/// `springref` put its spring's rest at springref − ref in Tumble's coordinate (zero at
/// the file's placement), where the damped slide settles (to 1e-3 m: 10 s of a decay
/// e^(−ζωt) with ζω ≈ 0.78/s from 0.3 m).
#[test]
fn integrator_total_mass_ellipsoids_and_spring_references_are_read() {
    let text = |integrator: &str| {
        format!(
            r#"<mujoco><compiler settotalmass="6"/>
             <option integrator="{integrator}" gravity="0 0 0"/>
             <worldbody>
               <body name="egg" pos="0 0 1">
                 <joint name="s" type="slide" axis="1 0 0" ref="0.2" springref="0.5"
                        stiffness="40" damping="8"/>
                 <geom type="ellipsoid" size="0.1 0.2 0.3"/></body>
               <body name="ball" pos="2 0 1"><freejoint/><geom type="sphere" size="0.1"/></body>
             </worldbody></mujoco>"#
        )
    };
    for (name, expected) in [
        ("RK4", tumble::Integrator::Rk4),
        ("implicitfast", tumble::Integrator::ImplicitEuler),
        ("Euler", tumble::Integrator::SymplecticEuler),
    ] {
        let (world, _) = load_at(write(&format!("options_{name}.xml"), &text(name)));
        assert_eq!(world.integrator(), expected, "{name}");
    }
    let (mut world, m) = load_at(write("options_RK4.xml", &text("RK4")));
    let egg = world.body(m.body("egg").unwrap()).unwrap();
    let ball = world.body(m.body("ball").unwrap()).unwrap();
    // Volumes 0.1·0.2·0.3 and 0.1³ (times 4/3 π): the egg is six balls.
    assert!(close(egg.mass() + ball.mass(), 6.0, EXACT));
    assert!(close(egg.mass(), 6.0 * ball.mass(), EXACT));
    let me = egg.mass();
    let expected = Mat3::from_diagonal(Vec3::new(
        me * (0.04 + 0.09) / 5.0,
        me * (0.01 + 0.09) / 5.0,
        me * (0.01 + 0.04) / 5.0,
    ));
    assert!(
        mat_close(egg.inertia_local(), expected, 1e-6),
        "{}",
        egg.inertia_local()
    );
    let s = m.joint("s").unwrap();
    assert_eq!(s.reference, 0.2);
    assert!(close(s.spring.1, 0.3, EXACT) && s.spring.0 == 40.0 && s.spring.2 == 8.0);
    let id = s.id.unwrap();
    // Awake throughout: its last centimetres of swing are slower than the sleep speed.
    world.set_sleep_enabled(false);
    for _ in 0..5000 {
        world.step(0.002).unwrap();
    }
    let q = world.joint_position(id).unwrap().scalar().unwrap();
    assert!((q - 0.3).abs() < 1e-3, "settled at {q}");
}
