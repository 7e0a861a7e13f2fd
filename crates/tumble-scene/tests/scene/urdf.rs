//! URDF models written for these tests, loaded and checked against closed forms: mass
//! properties exactly, a double pendulum's energy and normal-mode periods, a cart-pole's
//! momentum and period, meshes from OBJ and binary STL, joint coordinates in the file's
//! convention, and every bad file refused with one line naming file, line and element,
//! leaving the world as it was.

use std::path::{Path, PathBuf};

use tumble::{
    BodyId, JointCoordinate, JointId, JointKind, Mat3, Real, Shape, Vec3, World, WorldDef,
};
use tumble_scene::urdf::{self, Imported, UrdfOptions};

const G: Real = 9.81;
const F32: bool = std::mem::size_of::<Real>() == 4;
/// Mass properties go through a few products and sums: exact to rounding.
const EXACT: Real = if F32 { 2e-5 } else { 1e-12 };

/// A fresh folder for one test's files.
fn dir(test: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("tumble-urdf-{}-{test}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn write(dir: &Path, name: &str, text: &str) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p
}

fn z_up() -> World {
    World::new(&WorldDef {
        gravity: Vec3::new(0.0, 0.0, -G),
        // Small swings would fall asleep; these tests watch them.
        sleep: false,
        ..WorldDef::default()
    })
}

fn load(path: &Path, world: &mut World, fixed_base: bool) -> Imported {
    let opts = UrdfOptions {
        fixed_base,
        ..UrdfOptions::default()
    };
    match urdf::load(path, world, &opts) {
        Ok(m) => m,
        Err(e) => panic!("{e}"),
    }
}

/// A rod of `mass` (kg) and `length` (m) hanging from its link's origin along −z, 5 cm
/// square: the box's inertia about its centre.
fn rod(name: &str, mass: Real, length: Real) -> String {
    let w = 0.05;
    let long = mass * (length * length + w * w) / 12.0;
    let thin = mass * (2.0 * w * w) / 12.0;
    format!(
        r#"<link name="{name}">
    <inertial><origin xyz="0 0 {c}"/><mass value="{mass}"/>
      <inertia ixx="{long}" iyy="{long}" izz="{thin}" ixy="0" ixz="0" iyz="0"/></inertial>
    <visual><geometry><box size="{w} {w} {length}"/></geometry></visual>
    <collision><origin xyz="0 0 {c}"/><geometry><box size="{w} {w} {length}"/></geometry></collision>
  </link>"#,
        c = -0.5 * length
    )
}

fn double_pendulum(m1: Real, l1: Real, m2: Real, l2: Real) -> String {
    format!(
        r#"<?xml version="1.0"?>
<robot name="double_pendulum">
  <link name="base"/>
  {upper}
  {lower}
  <joint name="shoulder" type="continuous">
    <parent link="base"/><child link="upper"/><axis xyz="0 1 0"/>
  </joint>
  <joint name="elbow" type="revolute">
    <parent link="upper"/><child link="lower"/>
    <origin xyz="0 0 {l1n}" rpy="0 0 0"/><axis xyz="0 1 0"/>
    <limit lower="-3" upper="3" effort="10" velocity="10"/>
  </joint>
</robot>
"#,
        upper = rod("upper", m1, l1),
        lower = rod("lower", m2, l2),
        l1n = -l1
    )
}

fn total_energy(w: &World, ids: &[BodyId]) -> Real {
    ids.iter()
        .map(|&id| {
            let b = w.body(id).unwrap();
            b.kinetic_energy() + b.mass() * G * b.center_of_mass().z
        })
        .sum()
}

fn angle(w: &World, j: JointId) -> Real {
    w.joint_position(j).unwrap().scalar().unwrap()
}

#[test]
fn a_double_pendulum_loads_with_the_files_names_masses_and_inertias() {
    let d = dir("names");
    let path = write(&d, "double.urdf", &double_pendulum(1.0, 1.0, 2.0, 0.8));
    let mut w = z_up();
    let m = load(&path, &mut w, true);
    assert_eq!(m.name, "double_pendulum");
    let names: Vec<&str> = m.bodies.iter().map(|(n, _)| n.as_str()).collect();
    assert_eq!(names, ["base", "upper", "lower"]);
    let joints: Vec<&str> = m.joints.iter().map(|(n, _)| n.as_str()).collect();
    assert_eq!(joints, ["shoulder", "elbow"]);
    assert!(m.warnings.is_empty());
    let lower = w.body(m.body("lower").unwrap()).unwrap();
    assert_eq!(lower.name(), Some("lower"));
    assert!((lower.mass() - 2.0).abs() < EXACT);
    // The elbow is 1 m below the origin, the rod's centre 0.4 m below that.
    assert!((lower.center_of_mass() - Vec3::new(0.0, 0.0, -1.4)).length() < EXACT);
    let long = 2.0 * (0.64 + 0.0025) / 12.0;
    let expect = Mat3::from_diagonal(Vec3::new(long, long, 2.0 * 0.005 / 12.0));
    assert!((lower.inertia_local() - expect)
        .abs()
        .to_cols_array()
        .iter()
        .all(|x| *x < EXACT));
    let elbow = w.joint(m.joint("elbow").unwrap()).unwrap();
    match elbow.kind() {
        JointKind::Hinge {
            limits,
            motor,
            servo,
            ..
        } => {
            assert_eq!(*limits, Some([-3.0, 3.0]));
            assert!(motor.is_none() && servo.is_none());
        }
        other => panic!("elbow became {other:?}"),
    }
    assert!(matches!(
        w.joint(m.joint("shoulder").unwrap()).unwrap().kind(),
        JointKind::Hinge { limits: None, .. }
    ));
    assert_eq!(
        w.body(m.body("base").unwrap()).unwrap().kind(),
        tumble::BodyKind::Static
    );
}

#[test]
fn joint_positions_follow_the_files_convention() {
    // URDF: the child turns by +q about the axis (right hand) relative to the parent. A
    // turn of +θ about +y takes the upper rod's centre (0, 0, −0.5) to
    // (−0.5 sin θ, 0, −0.5 cos θ); the elbow's turn adds to it for the lower rod.
    let d = dir("coords");
    let path = write(&d, "double.urdf", &double_pendulum(1.0, 1.0, 1.0, 1.0));
    let mut w = z_up();
    let m = load(&path, &mut w, true);
    let (shoulder, elbow) = (m.joint("shoulder").unwrap(), m.joint("elbow").unwrap());
    assert!(angle(&w, shoulder).abs() < EXACT && angle(&w, elbow).abs() < EXACT);
    let (a, b) = (0.3 as Real, -0.7 as Real);
    w.set_joint_position(shoulder, JointCoordinate::Scalar(a))
        .unwrap();
    w.set_joint_position(elbow, JointCoordinate::Scalar(b))
        .unwrap();
    assert!((angle(&w, shoulder) - a).abs() < 1e-6);
    assert!((angle(&w, elbow) - b).abs() < 1e-6);
    let upper = w.body(m.body("upper").unwrap()).unwrap().center_of_mass();
    let expect = Vec3::new(-0.5 * a.sin(), 0.0, -0.5 * a.cos());
    assert!((upper - expect).length() < 1e-6, "{upper} vs {expect}");
    let lower = w.body(m.body("lower").unwrap()).unwrap().center_of_mass();
    let elbow_at = Vec3::new(-a.sin(), 0.0, -a.cos());
    let expect = elbow_at + Vec3::new(-0.5 * (a + b).sin(), 0.0, -0.5 * (a + b).cos());
    assert!((lower - expect).length() < 1e-6, "{lower} vs {expect}");
}

#[test]
fn a_passive_double_pendulum_keeps_its_energy() {
    // Chaotic at these angles, so only the energy is checked, against the pendulum's
    // energy scale (the centres' weights times their arms). What moves it is symplectic
    // Euler's bounded O(h) oscillation plus the soft joints' stretch: measured 3.5e-5 to
    // 8e-5 of the scale over 5 s; 1e-3 allowed (the engine's own double-pendulum test
    // allows 2e-2). A drift, or a mass or inertia read wrong, would pass it within
    // seconds. Sizes, masses and steps vary.
    for (m1, l1, m2, l2, hz) in [
        (1.0, 1.0, 1.0, 1.0, 240.0),
        (0.5, 0.6, 2.0, 0.9, 480.0),
        (3.0, 1.5, 0.4, 0.5, 240.0),
    ] {
        let d = dir(&format!("energy{hz}{m1}"));
        let path = write(&d, "double.urdf", &double_pendulum(m1, l1, m2, l2));
        let mut w = z_up();
        let m = load(&path, &mut w, true);
        let ids = [m.body("upper").unwrap(), m.body("lower").unwrap()];
        w.set_joint_position(m.joint("shoulder").unwrap(), JointCoordinate::Scalar(1.2))
            .unwrap();
        w.set_joint_position(m.joint("elbow").unwrap(), JointCoordinate::Scalar(-0.8))
            .unwrap();
        let e0 = total_energy(&w, &ids);
        let scale = G * (m1 * 0.5 * l1 + m2 * (l1 + 0.5 * l2));
        let mut worst: Real = 0.0;
        for _ in 0..(5.0 * hz) as usize {
            w.step(1.0 / hz).unwrap();
            worst = worst.max((total_energy(&w, &ids) - e0).abs());
        }
        assert!(
            worst < 1e-3 * scale,
            "m {m1},{m2} l {l1},{l2} at {hz} Hz: energy moved {worst} J of {scale} J"
        );
    }
}

/// The double pendulum's small-oscillation modes, in absolute angles (θ₁, θ₂):
/// M θ̈ + K θ = 0 with M = [[I₁ + m₁c₁² + m₂l₁², m₂l₁c₂], [m₂l₁c₂, I₂ + m₂c₂²]],
/// K = diag((m₁c₁ + m₂l₁) g, m₂c₂ g), c the centres' distances from their hinges and I
/// the rods' moments about their centres. det(K − λM) = 0 is a quadratic in λ = ω²;
/// each root's mode has θ₂/θ₁ = (K₁₁ − λM₁₁)/(λM₁₂). Returns (ω, θ₂/θ₁) per mode.
fn modes(m1: Real, l1: Real, m2: Real, l2: Real) -> [(Real, Real); 2] {
    let w2 = 0.0025;
    let (i1, i2) = (m1 * (l1 * l1 + w2) / 12.0, m2 * (l2 * l2 + w2) / 12.0);
    let (c1, c2) = (0.5 * l1, 0.5 * l2);
    let (a, b, c) = (
        i1 + m1 * c1 * c1 + m2 * l1 * l1,
        m2 * l1 * c2,
        i2 + m2 * c2 * c2,
    );
    let (k1, k2) = ((m1 * c1 + m2 * l1) * G, m2 * c2 * G);
    let det = a * c - b * b;
    let mid = a * k2 + c * k1;
    let root = (mid * mid - 4.0 * det * k1 * k2).sqrt();
    [(mid - root) / (2.0 * det), (mid + root) / (2.0 * det)]
        .map(|lambda| (lambda.sqrt(), (k1 - lambda * a) / (lambda * b)))
}

/// Upward zero crossings of the shoulder angle over `seconds`, interpolated.
fn crossings(w: &mut World, j: JointId, dt: Real, seconds: Real) -> Vec<Real> {
    let mut out = Vec::new();
    let mut last = angle(w, j);
    for i in 0..(seconds / dt) as usize {
        w.step(dt).unwrap();
        let q = angle(w, j);
        if last < 0.0 && q >= 0.0 {
            out.push((i as Real + last / (last - q)) * dt);
        }
        last = q;
    }
    out
}

#[test]
fn a_double_pendulum_started_in_a_normal_mode_swings_with_its_closed_form_period() {
    // Released at 0.01 rad in one mode's shape it stays in that mode; the amplitude's
    // own lengthening of the period, θ²/16 = 6e-6, is far below the 0.2 % allowed. The
    // measured errors are 1e-5 (slow mode) and 3.7e-4 (fast mode: the step's O(h²)
    // phase error at ω h ≈ 0.03, and the soft joints' compliance); an inertia off by 1 %
    // moves the period by 0.5 %.
    for (m1, l1, m2, l2, hz) in [(1.0, 1.0, 1.0, 1.0, 240.0), (0.5, 0.6, 2.0, 0.9, 480.0)] {
        for (mode, (omega, ratio)) in modes(m1, l1, m2, l2).into_iter().enumerate() {
            let d = dir(&format!("mode{mode}{hz}"));
            let path = write(&d, "double.urdf", &double_pendulum(m1, l1, m2, l2));
            let mut w = z_up();
            let m = load(&path, &mut w, true);
            let (s, e) = (m.joint("shoulder").unwrap(), m.joint("elbow").unwrap());
            let a = 0.01;
            w.set_joint_position(s, JointCoordinate::Scalar(a)).unwrap();
            // The elbow's angle is the lower rod's relative to the upper: θ₂ − θ₁.
            w.set_joint_position(e, JointCoordinate::Scalar(a * (ratio - 1.0)))
                .unwrap();
            let period = 2.0 * std::f64::consts::PI as Real / omega;
            let times = crossings(&mut w, s, 1.0 / hz, 10.5 * period);
            assert!(times.len() >= 9, "mode {mode}: {} crossings", times.len());
            let measured = (times[times.len() - 1] - times[0]) / (times.len() - 1) as Real;
            assert!(
                (measured / period - 1.0).abs() < 0.002,
                "mode {mode} ({m1},{l1},{m2},{l2}): period {measured} s vs {period} s"
            );
        }
    }
}

const CART_POLE: &str = r#"<robot name="cartpole">
  <link name="rail"/>
  <link name="cart">
    <inertial><mass value="MC"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><geometry><box size="0.3 0.2 0.1"/></geometry></collision>
  </link>
  <link name="pole">
    <inertial><origin xyz="0 0 -C"/><mass value="MP"/><inertia ixx="IP" iyy="IP" izz="0.0001" ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><origin xyz="0 0 -C"/><geometry><cylinder radius="0.02" length="L"/></geometry></collision>
  </link>
  <joint name="slider" type="prismatic">
    <parent link="rail"/><child link="cart"/><axis xyz="1 0 0"/>
    <limit lower="-2" upper="2" effort="100" velocity="10"/>
  </joint>
  <joint name="hinge" type="continuous">
    <parent link="cart"/><child link="pole"/><origin xyz="0 0 0"/><axis xyz="0 1 0"/>
  </joint>
</robot>"#;

#[test]
fn a_hanging_cart_pole_keeps_its_centre_of_mass_and_swings_at_its_closed_form_rate() {
    // Nothing pushes along the rail, so the centre of mass of cart and pole keeps its x.
    // Linearised with the cart free: ω² = (m_c + m_p) m_p g c / ((m_c + m_p)(I + m_p c²)
    // − m_p² c²), I the pole's moment about its centre. 0.2 % as for the pendulums
    // (measured 1e-5 and 3e-5).
    for (mc, mp, length) in [(1.0, 0.3, 1.0), (0.4, 1.0, 0.6)] {
        let c = 0.5 * length;
        let ip = mp * length * length / 12.0;
        let text = CART_POLE
            .replace("MC", &mc.to_string())
            .replace("MP", &mp.to_string())
            .replace("IP", &ip.to_string())
            .replace("-C", &(-c).to_string())
            .replace("\"L\"", &format!("\"{length}\""));
        let d = dir(&format!("cartpole{mc}"));
        let path = write(&d, "cartpole.urdf", &text);
        let mut w = z_up();
        let m = load(&path, &mut w, true);
        let (slider, hinge) = (m.joint("slider").unwrap(), m.joint("hinge").unwrap());
        assert!(matches!(
            w.joint(slider).unwrap().kind(),
            JointKind::Slider {
                limits: Some([-2.0, 2.0]),
                ..
            }
        ));
        w.set_joint_position(slider, JointCoordinate::Scalar(0.25))
            .unwrap();
        let cart = m.body("cart").unwrap();
        assert!((w.body(cart).unwrap().position().x - 0.25).abs() < 1e-9);
        w.set_joint_position(hinge, JointCoordinate::Scalar(0.01))
            .unwrap();
        let pole = m.body("pole").unwrap();
        let com_x = |w: &World| {
            let (a, b) = (w.body(cart).unwrap(), w.body(pole).unwrap());
            (a.mass() * a.center_of_mass().x + b.mass() * b.center_of_mass().x) / (mc + mp)
        };
        let x0 = com_x(&w);
        let omega2 = (mc + mp) * mp * G * c / ((mc + mp) * (ip + mp * c * c) - mp * mp * c * c);
        let period = 2.0 * std::f64::consts::PI as Real / omega2.sqrt();
        let times = crossings(&mut w, hinge, 1.0 / 240.0, 10.5 * period);
        let measured = (times[times.len() - 1] - times[0]) / (times.len() - 1) as Real;
        assert!(
            (measured / period - 1.0).abs() < 0.002,
            "cart-pole {mc},{mp},{length}: period {measured} s vs {period} s"
        );
        // No force along x acts on the pair: the centre keeps its x to rounding (0 and
        // 5e-16 m measured; f32 rounds at 1e-7 of the metre-sized coordinates).
        let tol = if F32 { 1e-5 } else { 1e-9 };
        assert!(
            (com_x(&w) - x0).abs() < tol,
            "centre moved {}",
            com_x(&w) - x0
        );
    }
}

/// Rz(yaw) Ry(pitch) Rx(roll) written out, independent of the loader's quaternions.
fn rpy_matrix(r: Real, p: Real, y: Real) -> Mat3 {
    let rx = Mat3::from_cols_array(&[1.0, 0.0, 0.0, 0.0, r.cos(), r.sin(), 0.0, -r.sin(), r.cos()]);
    let ry = Mat3::from_cols_array(&[p.cos(), 0.0, -p.sin(), 0.0, 1.0, 0.0, p.sin(), 0.0, p.cos()]);
    let rz = Mat3::from_cols_array(&[y.cos(), y.sin(), 0.0, -y.sin(), y.cos(), 0.0, 0.0, 0.0, 1.0]);
    rz * ry * rx
}

fn max_abs(m: Mat3) -> Real {
    m.to_cols_array().iter().fold(0.0, |a, b| a.max(b.abs()))
}

#[test]
fn an_off_diagonal_inertia_at_a_turned_offset_origin_is_kept_exactly() {
    // The tensor is given in the inertial frame, which sits at xyz turned by rpy in the
    // link frame: the body must hold R I Rᵀ about the centre at xyz (link frame).
    let d = dir("inertia");
    let (rpy, xyz) = ([0.3, -0.2, 0.5], [0.1, 0.2, -0.3]);
    let text = format!(
        r#"<robot name="odd"><link name="blob">
  <inertial><origin xyz="{} {} {}" rpy="{} {} {}"/><mass value="2.5"/>
    <inertia ixx="0.30" ixy="0.02" ixz="-0.03" iyy="0.25" iyz="0.04" izz="0.20"/></inertial>
  <collision><geometry><sphere radius="0.2"/></geometry></collision>
</link></robot>"#,
        xyz[0], xyz[1], xyz[2], rpy[0], rpy[1], rpy[2]
    );
    let path = write(&d, "odd.urdf", &text);
    let mut w = z_up();
    let opts = UrdfOptions {
        fixed_base: false,
        position: Vec3::new(1.0, 2.0, 3.0),
        ..UrdfOptions::default()
    };
    let m = urdf::load(&path, &mut w, &opts).unwrap();
    let b = w.body(m.body("blob").unwrap()).unwrap();
    assert_eq!(b.kind(), tumble::BodyKind::Dynamic);
    assert!((b.mass() - 2.5).abs() < EXACT);
    assert!((b.local_center_of_mass() - Vec3::from_array(xyz)).length() < EXACT);
    assert!((b.center_of_mass() - Vec3::new(1.1, 2.2, 2.7)).length() < EXACT);
    let i = Mat3::from_cols_array(&[0.30, 0.02, -0.03, 0.02, 0.25, 0.04, -0.03, 0.04, 0.20]);
    let r = rpy_matrix(rpy[0], rpy[1], rpy[2]);
    let expect = r * i * r.transpose();
    assert!(
        max_abs(b.inertia_local() - expect) < EXACT,
        "{}",
        b.inertia_local()
    );
}

const WELDED: &str = r#"<robot name="welded">
  <link name="a">
    <inertial><mass value="1"/><inertia ixx="0.1" iyy="0.1" izz="0.1" ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><geometry><box size="0.2 0.2 0.2"/></geometry></collision>
  </link>
  <link name="b">
    <inertial><mass value="3"/><inertia ixx="0.2" iyy="0.3" izz="0.4" ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><geometry><sphere radius="0.1"/></geometry></collision>
  </link>
  <joint name="weld" type="fixed"><parent link="a"/><child link="b"/>
    <origin xyz="0.4 0 0" rpy="0 0 1.5707963267948966"/></joint>
</robot>"#;

#[test]
fn fixed_joints_merge_into_one_body_with_parallel_axes_or_weld_two() {
    // Merged: 4 kg, centre 3·0.4/4 = 0.3 m along x. About that centre: a's 0.1 + 1·0.3²
    // for y and z; b's tensor turned 90° about z (its x and y swap: 0.3, 0.2, 0.4) plus
    // 3·0.1² for y and z.
    let d = dir("weld");
    let path = write(&d, "welded.urdf", WELDED);
    let mut w = z_up();
    let m = urdf::load(
        &path,
        &mut w,
        &UrdfOptions {
            fixed_base: false,
            ..UrdfOptions::default()
        },
    )
    .unwrap();
    assert_eq!(m.created.len(), 1);
    assert_eq!(m.body("a"), m.body("b"));
    assert!(m.joints.is_empty());
    let b = w.body(m.body("a").unwrap()).unwrap();
    assert!((b.mass() - 4.0).abs() < EXACT);
    assert!((b.local_center_of_mass() - Vec3::new(0.3, 0.0, 0.0)).length() < EXACT);
    let expect = Mat3::from_diagonal(Vec3::new(
        0.1 + 0.3,
        0.1 + 0.09 + 0.2 + 0.03,
        0.1 + 0.09 + 0.4 + 0.03,
    ));
    assert!(
        max_abs(b.inertia_local() - expect) < EXACT,
        "{}",
        b.inertia_local()
    );
    assert!(matches!(b.shape(), Shape::Compound(c) if c.len() == 2));

    let mut w = z_up();
    let opts = UrdfOptions {
        fixed_base: false,
        merge_fixed: false,
        ..UrdfOptions::default()
    };
    let m = urdf::load(&path, &mut w, &opts).unwrap();
    assert_eq!(m.created.len(), 2);
    let weld = w.joint(m.joint("weld").unwrap()).unwrap();
    assert!(matches!(weld.kind(), JointKind::Fixed));
    let b = w.body(m.body("b").unwrap()).unwrap();
    assert!((b.position() - Vec3::new(0.4, 0.0, 0.0)).length() < EXACT);
    // Welded, the pair falls as one: after 0.5 s the weld still holds to 1 mm.
    for _ in 0..60 {
        w.step(1.0 / 120.0).unwrap();
    }
    let (pa, pb) = (
        w.body(m.body("a").unwrap()).unwrap().position(),
        w.body(m.body("b").unwrap()).unwrap().position(),
    );
    assert!(((pb - pa).length() - 0.4).abs() < 1e-3);
    assert!(pa.z < -1.0, "fell to {}", pa.z);
}

/// A 0.2 × 0.4 × 0.6 m box as OBJ text (quads) and as binary STL bytes (triangles).
fn box_obj() -> String {
    let mut s = String::from("# box\no box\n");
    for i in 0..8 {
        let (x, y, z) = (
            (i & 1) as Real,
            ((i >> 1) & 1) as Real,
            ((i >> 2) & 1) as Real,
        );
        s += &format!("v {} {} {}\n", 0.2 * x - 0.1, 0.4 * y - 0.2, 0.6 * z - 0.3);
    }
    s += "vn 0 0 1\nvt 0 0\n";
    for f in [
        "1 3 4 2", "5 6 8 7", "1 2 6 5", "3 7 8 4", "1 5 7 3", "2 4 8 6",
    ] {
        let parts: Vec<String> = f.split(' ').map(|i| format!("{i}/1/1")).collect();
        s += &format!("f {}\n", parts.join(" "));
    }
    s
}

fn box_stl() -> Vec<u8> {
    let corner = |i: u32| {
        [
            0.2 * (i & 1) as f32 - 0.1,
            0.4 * ((i >> 1) & 1) as f32 - 0.2,
            0.6 * ((i >> 2) & 1) as f32 - 0.3,
        ]
    };
    let quads = [
        [0, 2, 3, 1],
        [4, 5, 7, 6],
        [0, 1, 5, 4],
        [2, 6, 7, 3],
        [0, 4, 6, 2],
        [1, 3, 7, 5],
    ];
    let mut out = b"solid but binary: the size decides".to_vec();
    out.resize(80, b' ');
    out.extend_from_slice(&12u32.to_le_bytes());
    for q in quads {
        for tri in [[q[0], q[1], q[2]], [q[0], q[2], q[3]]] {
            out.extend_from_slice(&[0u8; 12]);
            for v in tri {
                for x in corner(v) {
                    out.extend_from_slice(&x.to_le_bytes());
                }
            }
            out.extend_from_slice(&[0u8; 2]);
        }
    }
    out
}

fn mesh_robot(file: &str, scale: &str) -> String {
    format!(
        r#"<robot name="meshy">
  <link name="ground"><collision><geometry><mesh filename="{file}" scale="{scale}"/></geometry></collision></link>
  <link name="block">
    <inertial><mass value="1.5"/><inertia ixx="0.1" iyy="0.1" izz="0.1" ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><origin xyz="0 0 0.5"/><geometry><mesh filename="package://meshy/meshes/{file}" scale="{scale}"/></geometry></collision>
  </link>
  <joint name="free" type="floating"><parent link="ground"/><child link="block"/><origin xyz="0 0 1"/></joint>
</robot>"#
    )
}

#[test]
fn obj_and_binary_stl_meshes_become_hulls_and_static_meshes() {
    // The moving link's mesh is a convex hull of the scaled points: a box of 8 corners
    // and volume 2 · 0.2 · 0.4 · 0.6; the static base keeps the mesh as 12 triangles.
    let d = dir("mesh");
    let pkg = d.join("meshy");
    std::fs::create_dir_all(pkg.join("meshes")).unwrap();
    std::fs::create_dir_all(pkg.join("urdf")).unwrap();
    for (file, bytes) in [("box.obj", box_obj().into_bytes()), ("box.stl", box_stl())] {
        std::fs::write(pkg.join("urdf").join(file), &bytes).unwrap();
        std::fs::write(pkg.join("meshes").join(file), &bytes).unwrap();
        let path = write(&pkg.join("urdf"), "meshy.urdf", &mesh_robot(file, "2 1 1"));
        let mut w = z_up();
        // The block lands on its own model's ground: self-collision asked for (the
        // model's links pass through each other by default, as in PyBullet).
        let opts = UrdfOptions {
            self_collision: true,
            ..UrdfOptions::default()
        };
        let m = urdf::load(&path, &mut w, &opts).unwrap();
        let block = w.body(m.body("block").unwrap()).unwrap();
        let Shape::Compound(children) = block.shape() else {
            panic!("{file}: {:?}", block.shape().kind_name());
        };
        let Shape::ConvexHull(hull) = &children[0].shape else {
            panic!("{file}: not a hull");
        };
        assert_eq!(hull.vertices().len(), 8, "{file}");
        let volume = children[0].shape.volume();
        assert!(
            (volume - 2.0 * 0.048).abs() < 1e-6,
            "{file}: volume {volume}"
        );
        assert!((children[0].position - Vec3::new(0.0, 0.0, 0.5)).length() < EXACT);
        assert!((block.mass() - 1.5).abs() < EXACT);
        assert!((block.position() - Vec3::new(0.0, 0.0, 1.0)).length() < EXACT);
        let ground = w.body(m.body("ground").unwrap()).unwrap();
        let Shape::TriMesh(mesh) = ground.shape() else {
            panic!("{file}: ground is {}", ground.shape().kind_name());
        };
        assert_eq!(mesh.len(), 12);
        // The block falls 0.5 m onto the static box mesh (top at 0.3) and rests on it:
        // its hull's bottom (0.5 − 0.3 below its origin) at 0.3.
        for _ in 0..240 {
            w.step(1.0 / 120.0).unwrap();
        }
        let z = w.body(m.body("block").unwrap()).unwrap().position().z;
        assert!((z - 0.1).abs() < 0.01, "{file}: block rests at {z}");
    }
}

/// Loads `text` into a world that already holds a body, expects the error `line`, and
/// checks nothing was added.
fn refused(d: &Path, name: &str, text: &str, line: &str) {
    let path = write(d, name, text);
    let mut w = z_up();
    w.create_body(&tumble::BodyDef::default(), Shape::sphere(0.1))
        .unwrap();
    let err = urdf::load(&path, &mut w, &UrdfOptions::default()).unwrap_err();
    let shown = err.to_string().replace(&format!("{}/", d.display()), "");
    assert_eq!(shown, line);
    assert!(!shown.contains('\n'));
    assert_eq!(w.body_count(), 1, "{name}: the world changed");
    assert_eq!(w.joints().count(), 0, "{name}: the world changed");
}

#[test]
fn bad_files_are_refused_with_file_line_and_element_and_change_nothing() {
    let d = dir("bad");
    refused(
        &d,
        "malformed.urdf",
        "<robot name=\"x\">\n<link name=\"a\">\n</robot>\n",
        "malformed.urdf:3: malformed XML: expected 'link' tag, not 'robot' at 3:1",
    );
    let link =
        |body: &str| format!("<robot name=\"r\">\n<link name=\"a\">\n{body}\n</link>\n</robot>\n");
    refused(
        &d,
        "negative.urdf",
        &link("<inertial><mass value=\"-1\"/><inertia ixx=\"1\" iyy=\"1\" izz=\"1\"/></inertial>"),
        "negative.urdf:2: <link name=\"a\">: inertial.mass: must be >= 0, got -1",
    );
    refused(
        &d,
        "moment.urdf",
        &link(
            "<inertial><mass value=\"1\"/><inertia ixx=\"1\" iyy=\"-0.5\" izz=\"1\"/></inertial>",
        ),
        "moment.urdf:2: <link name=\"a\">: inertial.inertia.iyy: must be >= 0, got -0.5",
    );
    refused(
        &d,
        "missing.urdf",
        &link("<collision>\n<geometry><mesh filename=\"meshes/gone.stl\"/></geometry></collision>"),
        "missing.urdf:4: <mesh>: filename: mesh file 'meshes/gone.stl' not found",
    );
    write(
        &d,
        "flat.obj",
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nf 1 2 3\nf 2 4 3\n",
    );
    refused(
        &d,
        "flat.urdf",
        "<robot name=\"r\">\n<link name=\"base\"/><link name=\"a\">\n<inertial><mass value=\"1\"/><inertia ixx=\"1\" iyy=\"1\" izz=\"1\"/></inertial>\n<collision>\n<geometry><mesh filename=\"flat.obj\"/></geometry></collision>\n</link>\n<joint name=\"j\" type=\"continuous\"><parent link=\"base\"/><child link=\"a\"/></joint>\n</robot>\n",
        "flat.urdf:4: <collision>: geometry.mesh: 'flat.obj' has no volume to take a convex hull of (needs at least 4 points that are not all in one plane)",
    );
    // The engine's own refusal, met half way through creating: a second copy's second
    // body's name is taken. The first copy stays whole and nothing of the second is left.
    let path = write(&d, "twice.urdf", &double_pendulum(1.0, 1.0, 1.0, 1.0));
    let mut w = z_up();
    let opts = UrdfOptions {
        prefix: "b".into(),
        ..UrdfOptions::default()
    };
    urdf::load(&path, &mut w, &UrdfOptions::default()).unwrap();
    w.create_body(
        &tumble::BodyDef {
            name: Some("bupper".into()),
            ..Default::default()
        },
        Shape::sphere(0.1),
    )
    .unwrap();
    let err = urdf::load(&path, &mut w, &opts).unwrap_err().to_string();
    assert!(
        err.ends_with(
            "twice.urdf:4: <link name=\"upper\">: name: a body named 'bupper' already exists"
        ),
        "{err}"
    );
    assert_eq!((w.body_count(), w.joints().count()), (4, 2));
}

#[test]
fn a_scene_places_models_whose_links_its_joints_can_name() {
    // Two copies of one file, the second prefixed and free; a ball of the scene's own
    // welded to the first copy's lower rod by name. File paths are the scene file's.
    let d = dir("models");
    write(&d, "double.urdf", &double_pendulum(1.0, 1.0, 1.0, 1.0));
    let scene = r#"{"gravity": [0, 0, -9.81],
      "bodies": [{"name": "ball", "shape": {"type": "sphere", "radius": 0.1}, "mass": 1,
                  "position": [0, 0, 0]}],
      "models": [
        {"file": "double.urdf", "position": [0, 0, 2]},
        {"file": "double.urdf", "prefix": "b_", "position": [3, 0, 2],
         "orientation": [0, 0, 1, 0], "fixed_base": false, "merge_fixed": true}],
      "joints": [{"type": "fixed", "body": "ball", "other": "lower"}]}"#;
    let path = write(&d, "scene.json", scene);
    let s = tumble_scene::load(path.to_str().unwrap()).unwrap();
    assert_eq!(
        s.body_names,
        ["ball", "base", "upper", "lower", "b_base", "b_upper", "b_lower"]
    );
    assert_eq!(s.body_colors.len(), 7);
    let w = &s.world;
    let upper = w.body(w.find_body("b_upper").unwrap()).unwrap();
    assert!((upper.center_of_mass() - Vec3::new(3.0, 0.0, 1.5)).length() < EXACT);
    assert!(w.find_joint("b_elbow").is_some() && w.find_joint("elbow").is_some());
    assert_eq!(w.joints().count(), 5);

    let bad = |models: &str| {
        let path = write(&d, "bad.json", &format!(r#"{{"models": [{models}]}}"#));
        tumble_scene::load(path.to_str().unwrap())
            .unwrap_err()
            .to_string()
    };
    assert_eq!(
        bad(r#"{"file": "double.urdf", "colour": "red"}"#),
        "models[0].colour: unknown key (expected one of: file, position, orientation, fixed_base, merge_fixed, prefix, self_collision)"
    );
    assert_eq!(
        bad(r#"{"file": "double.json"}"#),
        "models[0].file: expected a model file ending in .urdf or .xml (MJCF)"
    );
    let missing = bad(r#"{"file": "gone.urdf"}"#);
    assert!(
        missing.starts_with("models[0]: ") && missing.contains("gone.urdf: cannot read"),
        "{missing}"
    );
}

/// One rod on a hinge about y with `<dynamics>`, released at `q0`.
fn damped(damping: Real, friction: Real) -> String {
    format!(
        r#"<robot name="damped"><link name="base"/>{rod}
  <joint name="j" type="continuous"><parent link="base"/><child link="rod"/><axis xyz="0 1 0"/>
    <dynamics damping="{damping}" friction="{friction}"/></joint></robot>"#,
        rod = rod("rod", 1.0, 1.0)
    )
}

#[test]
fn joint_damping_decays_the_swing_at_its_closed_form_rate_and_friction_holds() {
    // Damping c (N·m·s/rad) on a pendulum of moment I about its pivot: small swings decay
    // as q₀ e^(−γt), γ = c / 2I. The first peak of |q| after 4 s is compared with that
    // envelope at the peak's time; 0.5 % allowed (the damped solution's peaks stand
    // √(1 + (γ/ω)²) − 1 ≈ 8e-4 above the envelope, sampled at the step's nearest
    // instant; measured 3.5e-5). A damping read 10 % high would miss by
    // 6 % (e^(−0.06)).
    let d = dir("damping");
    let c = 0.1;
    let path = write(&d, "damped.urdf", &damped(c, 0.0));
    let mut w = z_up();
    let m = load(&path, &mut w, true);
    let j = m.joint("j").unwrap();
    assert!(
        matches!(w.joint(j).unwrap().kind(), JointKind::Hinge { servo: Some(s), .. } if s.damping == c && s.stiffness == 0.0)
    );
    let q0 = 0.05;
    w.set_joint_position(j, JointCoordinate::Scalar(q0))
        .unwrap();
    let i_pivot = (1.0 + 0.0025) / 12.0 + 0.25;
    let dt = 1.0 / 480.0;
    let (mut prev, mut rising, mut peak) = (q0, false, None);
    for k in 1..(6.0 / dt) as usize {
        w.step(dt).unwrap();
        let q = angle(&w, j).abs();
        let t = (k - 1) as Real * dt;
        if rising && q < prev && t > 4.0 {
            peak = Some((t, prev));
            break;
        }
        rising = q > prev;
        prev = q;
    }
    let (t, peak) = peak.expect("a peak after 4 s");
    let envelope = q0 * (-c * t / (2.0 * i_pivot)).exp();
    assert!(
        (peak / envelope - 1.0).abs() < 0.005,
        "peak {peak} at {t} s vs envelope {envelope}"
    );
    // Undamped, it would still be at q0: the damping did act.
    assert!(peak < 0.6 * q0);

    // Friction 1 N·m holds the rod at 0.1 rad, where gravity's torque is
    // m g (l/2) sin 0.1 = 0.49 N·m; at 0.3 rad (1.45 N·m) it swings.
    let path = write(&d, "stuck.urdf", &damped(0.0, 1.0));
    for (q, moves) in [(0.1 as Real, false), (0.3, true)] {
        let mut w = z_up();
        let m = load(&path, &mut w, true);
        let j = m.joint("j").unwrap();
        w.set_joint_position(j, JointCoordinate::Scalar(q)).unwrap();
        for _ in 0..120 {
            w.step(1.0 / 120.0).unwrap();
        }
        let moved = (angle(&w, j) - q).abs();
        assert_eq!(moved > 0.01, moves, "from {q} rad it moved {moved} rad");
    }
}

#[test]
fn what_is_read_but_not_built_as_written_is_warned_with_its_line() {
    let d = dir("warnings");
    let text = r#"<?xml version="1.0"?>
<robot name="w">
  <link name="base"/>
  <link name="a"><inertial><mass value="2"/><inertia ixx="0" iyy="0" izz="0" ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><geometry><box size="0.1, 0.2, 0.3"/></geometry></collision></link>
  <link name="b"><inertial><mass value="1"/><inertia ixx="0.1" iyy="0.1" izz="0.1" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <joint name="slide" type="prismatic"><parent link="base"/><child link="a"/>
    <limit lower="1" upper="-1"/></joint>
  <joint name="flat" type="planar"><parent link="a"/><child link="b"/></joint>
</robot>"#;
    let path = write(&d, "w.urdf", text);
    let mut w = z_up();
    let m = load(&path, &mut w, true);
    let warnings: Vec<String> = m
        .warnings
        .iter()
        .map(|s| s.replace(&format!("{}/", d.display()), ""))
        .collect();
    assert_eq!(
        warnings,
        [
            "w.urdf:7: <joint name=\"slide\">: limit: lower (1) > upper (-1), read as no limits (PyBullet's convention)",
            "w.urdf:4: <link name=\"a\">: inertial.inertia: all zero; taken from the collision geometry at uniform density, as PyBullet does",
        ]
    );
    // The box's own tensor at 2 kg: m (b² + c²) / 12 and so on.
    let a = w.body(m.body("a").unwrap()).unwrap();
    let expect = Vec3::new(2.0 * 0.13 / 12.0, 2.0 * 0.10 / 12.0, 2.0 * 0.05 / 12.0);
    // f32 carries about 7 digits of these 0.02 kg·m² moments.
    let tol = if F32 { 1e-7 } else { 1e-12 };
    assert!(
        (a.principal_inertia().0 - expect).length() < tol,
        "{}",
        a.principal_inertia().0
    );
    assert!(matches!(
        w.joint(m.joint("slide").unwrap()).unwrap().kind(),
        JointKind::Slider { limits: None, .. }
    ));
    assert!(m.joint("flat").is_none());
}

#[test]
fn a_zero_pose_outside_the_limits_starts_at_the_nearer_limit() {
    // URDF's zero pose need not lie within a joint's limits (a quadruped's knees); left
    // there, the limit row would snap the joint 0.5 rad in one step (measured: 49 rad/s).
    // Started at the limit instead, the rod only falls against it: released at 0.5 rad
    // it swings towards 0 and rests on the limit, its rate never above what gravity
    // gives in 0.2 s (m g c sin 0.5 / I · 0.2 ≈ 1.4 rad/s; 3 allowed).
    let d = dir("startlimit");
    let text = double_pendulum(1.0, 1.0, 1.0, 1.0).replace(
        r#"<limit lower="-3" upper="3""#,
        r#"<limit lower="0.5" upper="1.0""#,
    );
    let path = write(&d, "limited.urdf", &text);
    let mut w = z_up();
    let m = load(&path, &mut w, true);
    let elbow = m.joint("elbow").unwrap();
    assert!(
        (angle(&w, elbow) - 0.5).abs() < 1e-6,
        "starts at {}",
        angle(&w, elbow)
    );
    assert_eq!(m.warnings.len(), 1);
    assert!(m.warnings[0].ends_with(
        "<joint name=\"elbow\">: limit: the file's zero pose is outside the limits; the joint starts at 0.5"
    ));
    let mut fastest: Real = 0.0;
    for _ in 0..48 {
        w.step(1.0 / 240.0).unwrap();
        let rate = w.joint_velocity(elbow).unwrap().scalar().unwrap();
        fastest = fastest.max(rate.abs());
    }
    assert!(fastest < 3.0, "the elbow moved at up to {fastest} rad/s");
    assert!(angle(&w, elbow) > 0.5 - 0.01);
}

/// A planar joint (axis z, from a fixed base) is two sliders and a hinge, `flat/x`,
/// `flat/y`, `flat/theta`: the child keeps its height under gravity's z part and falls
/// freely along the plane under its x and y parts (the light bodies between fall with it,
/// so the acceleration is exactly g's), and its coordinates set its pose in the plane.
#[test]
fn a_planar_joint_moves_its_child_in_the_plane_only() {
    let d = dir("planar");
    let text = r#"<robot name="p"><link name="base"/>
  <link name="puck"><inertial><mass value="2"/><inertia ixx="0.1" iyy="0.2" izz="0.3" ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><geometry><box size="0.2 0.2 0.1"/></geometry></collision></link>
  <joint name="flat" type="planar"><parent link="base"/><child link="puck"/>
    <origin xyz="0 0 1"/><axis xyz="0 0 1"/></joint></robot>"#;
    let path = write(&d, "p.urdf", text);
    let g = Vec3::new(2.0, 1.0, -G);
    let mut w = World::new(&WorldDef {
        gravity: g,
        sleep: false,
        ..WorldDef::default()
    });
    let m = load(&path, &mut w, true);
    assert!(m.warnings.is_empty(), "{:?}", m.warnings);
    let names: Vec<&str> = m.joints.iter().map(|j| j.0.as_str()).collect();
    assert_eq!(names, ["flat/x", "flat/y", "flat/theta"]);
    let puck = m.body("puck").unwrap();
    let (dt, n) = (1.0 / 240.0, 240);
    for _ in 0..n {
        w.step(dt).unwrap();
    }
    let t = dt * n as Real;
    let p = w.body(puck).unwrap().position();
    // ½ g t² along the plane (1 m and 0.5 m); the chain's soft rows, holding 2 kg on
    // bodies of 20 g, let it sag 0.8 mm in z and lag 0.6 mm in y (measured): 2 mm.
    let expected = Vec3::new(0.5 * g.x * t * t, 0.5 * g.y * t * t, 1.0);
    assert!((p - expected).length() < 2e-3, "{p} vs {expected}");
    let turned = w
        .body(puck)
        .unwrap()
        .orientation()
        .angle_between(tumble::Quat::IDENTITY);
    assert!(turned < 1e-3, "{turned}");
    // Coordinates: 0.3 along x, −0.2 along y, a 0.5 rad turn about z.
    let mut w = z_up();
    let m = load(&path, &mut w, true);
    for (name, q) in [("flat/x", 0.3), ("flat/y", -0.2), ("flat/theta", 0.5)] {
        w.set_joint_position(m.joint(name).unwrap(), JointCoordinate::Scalar(q))
            .unwrap();
    }
    let b = w.body(m.body("puck").unwrap()).unwrap();
    assert!(
        (b.position() - Vec3::new(0.3, -0.2, 1.0)).length() < 1e-6,
        "{}",
        b.position()
    );
    let turn = tumble::Quat::from_rotation_z(0.5);
    assert!(b.orientation().angle_between(turn) < 1e-6);
}

/// `text` loaded with `fixed_base`; its warnings without the folder.
fn warned(d: &Path, name: &str, text: &str, fixed_base: bool) -> (World, Imported, Vec<String>) {
    let path = write(d, name, text);
    let mut w = z_up();
    let m = load(&path, &mut w, fixed_base);
    let shown = m
        .warnings
        .iter()
        .map(|s| s.replace(&format!("{}/", d.display()), ""))
        .collect();
    (w, m, shown)
}

#[test]
fn an_impossible_inertia_is_unused_on_a_static_link_and_taken_from_the_geometry_on_a_moving_one() {
    // PyBullet's random_urdfs give every object ixx = iyy = 1, izz = 0; its xarm links
    // have a moment 0.7 % above the sum of the other two. PyBullet loads both (by default
    // it takes every tensor from the collision shapes).
    let d = dir("impossible_inertia");
    let link = |tensor: &str| {
        format!(
            "<robot name=\"r\">\n<link name=\"a\">\n<inertial><mass value=\"2\"/><inertia {tensor}/></inertial>\n<collision><geometry><box size=\"0.1 0.2 0.3\"/></geometry></collision>\n</link>\n</robot>\n"
        )
    };
    let cases = [
        ("indefinite.urdf", "ixx=\"1\" ixy=\"2\" iyy=\"1\" izz=\"1\"", "is not positive definite: its principal moments [-1, 1, 3]"),
        ("flat.urdf", "ixx=\"1\" iyy=\"1\" izz=\"0\"", "is not positive definite: its principal moments [0, 1, 1]"),
        ("impossible.urdf", "ixx=\"1\" iyy=\"1\" izz=\"3\"", "is impossible: of its principal moments [1, 1, 3] the largest exceeds the sum of the other two"),
    ];
    for (name, tensor, problem) in cases {
        let (_, _, shown) = warned(&d, name, &link(tensor), true);
        assert_eq!(
            shown,
            [format!("{name}:2: <link name=\"a\">: inertial.inertia: {problem}; not used (the link does not move)")]
        );
        let (w, m, shown) = warned(&d, name, &link(tensor), false);
        assert_eq!(
            shown,
            [format!("{name}:2: <link name=\"a\">: inertial.inertia: {problem}; taken from the collision geometry at uniform density, as PyBullet does")]
        );
        // The box's own tensor at 2 kg.
        let a = w.body(m.body("a").unwrap()).unwrap();
        let expect = Vec3::new(2.0 * 0.13 / 12.0, 2.0 * 0.10 / 12.0, 2.0 * 0.05 / 12.0);
        let tol = if F32 { 1e-7 } else { 1e-12 };
        assert!((a.principal_inertia().0 - expect).length() < tol, "{name}");
        assert!((a.mass() - 2.0).abs() < EXACT);
    }
}

#[test]
fn pybullets_leniencies_trailing_nul_extra_numbers_and_sliver_triangles_are_read() {
    let d = dir("lenient");
    // PyBullet's humanoid.urdf ends in a NUL byte; its racecar_differential.urdf has
    // scale="1 1 1 1" and microtaur.urdf rpy="-3.14159 1.57079 0 0" (the first 3 read).
    write(&d, "box.obj", &box_obj());
    let text = "<robot name=\"r\">\n<link name=\"a\">\n<collision><origin rpy=\"0 0 0 0\"/><geometry><mesh filename=\"box.obj\" scale=\"1 1 1 1\"/></geometry></collision>\n</link>\n</robot>\n\0";
    let (w, m, shown) = warned(&d, "lenient.urdf", text, true);
    assert_eq!(
        shown,
        [
            "lenient.urdf:3: <origin>: origin.rpy: expected 3 numbers, got 4 ('0 0 0 0'); the first 3 used, as PyBullet does",
            "lenient.urdf:3: <mesh>: scale: expected 3 numbers, got 4 ('1 1 1 1'); the first 3 used, as PyBullet does",
        ]
    );
    assert!(matches!(
        w.body(m.body("a").unwrap()).unwrap().shape(),
        Shape::TriMesh(_)
    ));
    // A static mesh with a sliver (three corners on a line) and a repeated corner, as
    // PyBullet's samurai.urdf has: the slivers are dropped, the 12 faces kept.
    let sliver = box_obj() + "f 1 2 2\nv 0.1 0.2 0.3\nv 0.0 0.2 0.3\nf 8 9 10\n";
    write(&d, "sliver.obj", &sliver);
    let text = "<robot name=\"r\">\n<link name=\"a\">\n<collision><geometry><mesh filename=\"sliver.obj\"/></geometry></collision>\n</link>\n</robot>\n";
    let (w, m, shown) = warned(&d, "sliver.urdf", text, true);
    assert!(shown.is_empty(), "{shown:?}");
    let Shape::TriMesh(mesh) = w.body(m.body("a").unwrap()).unwrap().shape() else {
        panic!("not a mesh");
    };
    assert_eq!(mesh.len(), 12);
}

/// A base, a middle link hinged above it and a tip hinged below the middle, folded back
/// onto the base: base and tip overlap by `overlap` (m) and no joint connects them.
fn folded(overlap: Real) -> String {
    let link = |name: &str, size: Real| {
        format!(
            r#"<link name="{name}"><inertial><mass value="1"/>
    <inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><geometry><box size="{size} {size} {size}"/></geometry></collision></link>"#
        )
    };
    format!(
        r#"<robot name="folded">
  {base}{mid}{tip}
  <joint name="up" type="revolute"><parent link="base"/><child link="mid"/>
    <origin xyz="0 0 0.5"/><axis xyz="0 1 0"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
  <joint name="down" type="revolute"><parent link="mid"/><child link="tip"/>
    <origin xyz="0 0 {back}"/><axis xyz="0 1 0"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
</robot>"#,
        base = link("base", 0.2),
        mid = link("mid", 0.1),
        tip = link("tip", 0.1),
        back = -0.5 + 0.15 - overlap,
    )
}

/// The bodies touching each other after a contact update, as sorted name pairs.
fn touching(w: &mut World) -> Vec<(String, String)> {
    let ids: Vec<(BodyId, BodyId)> = w
        .update_contacts()
        .iter()
        .map(|c| (c.body_a, c.body_b))
        .collect();
    let mut pairs: Vec<(String, String)> = ids
        .into_iter()
        .map(|(a, b)| {
            let name = |id| w.body(id).unwrap().name().unwrap();
            let (a, b) = (name(a), name(b));
            (a.min(b).to_string(), a.max(b).to_string())
        })
        .collect();
    pairs.sort();
    pairs.dedup();
    pairs
}

#[test]
fn a_models_links_collide_with_each_other_only_when_asked_and_always_with_other_models() {
    let d = dir("self-collision");
    for (i, overlap) in [0.004, 0.02, 0.05].into_iter().enumerate() {
        let file = write(&d, &format!("folded{i}.urdf"), &folded(overlap));
        let add = |w: &mut World, self_collision: bool, prefix: &str, x: Real| {
            let opts = UrdfOptions {
                self_collision,
                prefix: prefix.to_string(),
                position: Vec3::new(x, 0.0, 0.0),
                ..UrdfOptions::default()
            };
            urdf::load(&file, w, &opts).unwrap();
        };
        // PyBullet's default: the model's own links pass through each other.
        let mut w = z_up();
        add(&mut w, false, "", 0.0);
        assert_eq!(touching(&mut w), Vec::<(String, String)>::new());
        // Asked for, base and tip (not joined) touch; joined links still do not.
        let mut w = z_up();
        add(&mut w, true, "", 0.0);
        assert_eq!(touching(&mut w), [("base".into(), "tip".into())]);
        // A second copy overlapping the first collides with it though neither collides
        // with itself; one with self-collision beside one without composes the same way.
        for second in [false, true] {
            let mut w = z_up();
            add(&mut w, false, "", 0.0);
            add(&mut w, second, "b_", 0.05);
            let mut expected: Vec<(String, String)> = vec![
                ("b_base".into(), "tip".into()),
                ("b_mid".into(), "mid".into()),
                ("b_tip".into(), "base".into()),
                ("b_tip".into(), "tip".into()),
            ];
            if second {
                expected.push(("b_base".into(), "b_tip".into()));
            }
            expected.sort();
            assert_eq!(
                touching(&mut w),
                expected,
                "overlap {overlap}, second {second}"
            );
            // A user's own groups stay as set, and the owners survive a save and load.
            let tip = w.find_body("tip").unwrap();
            w.set_collision_filter(tip, 2, u32::MAX).unwrap();
            let saved = tumble_scene::save(&w);
            let mut back = tumble_scene::load_str(&saved).unwrap().world;
            assert_eq!(touching(&mut back), expected);
            let tip = back.body(back.find_body("tip").unwrap()).unwrap();
            assert_eq!(tip.collision_filter(), (2, u32::MAX));
        }
    }
    // In a scene's models: the key, and MJCF refusing it.
    write(&d, "folded.urdf", &folded(0.02));
    let scene = |key: &str| {
        let text = format!(r#"{{"models": [{{"file": "folded.urdf"{key}}}]}}"#);
        let path = write(&d, "scene.json", &text);
        tumble_scene::load(path.to_str().unwrap())
    };
    assert_eq!(touching(&mut scene("").unwrap().world).len(), 0);
    let mut w = scene(r#", "self_collision": true"#).unwrap().world;
    assert_eq!(touching(&mut w), [("base".into(), "tip".into())]);
}

/// PyBullet's minitaur in outline: a 3 kg chassis of 1 kg·m² and eight 0.25 kg motors of
/// 1 kg·m² each, hinged to it, each with a leg welded on (merged) of 1 kg·m² more: each
/// motor turns as heavily as the chassis, and the eight together eight times as heavily.
fn minitaur_like() -> String {
    let mut links = String::new();
    let mut joints = String::new();
    let inertia = r#"<inertia ixx="1" iyy="1" izz="1" ixy="0" ixz="0" iyz="0"/>"#;
    for (i, (x, y)) in [
        (0.21, -0.125),
        (0.21, -0.06),
        (-0.21, -0.125),
        (-0.21, -0.06),
    ]
    .into_iter()
    .flat_map(|(x, y): (Real, Real)| [(x, y), (x, -y)])
    .enumerate()
    {
        links += &format!(
            r#"<link name="motor{i}"><inertial><mass value="0.25"/>{inertia}</inertial>
  <collision><geometry><cylinder length="0.026" radius="0.0434"/></geometry></collision></link>
<link name="leg{i}"><inertial><origin xyz="0 0 -0.1"/><mass value="0.05"/>{inertia}</inertial>
  <collision><origin xyz="0 0 -0.1"/><geometry><box size="0.01 0.01 0.2"/></geometry></collision></link>
"#
        );
        joints += &format!(
            r#"<joint name="hip{i}" type="continuous"><parent link="chassis"/><child link="motor{i}"/>
  <origin xyz="{x} {y} 0" rpy="1.5708 0 0"/><axis xyz="0 0 1"/></joint>
<joint name="knee{i}" type="fixed"><parent link="motor{i}"/><child link="leg{i}"/>
  <origin xyz="0 0 0" rpy="-1.5708 0 0"/></joint>
"#
        );
    }
    format!(
        r#"<robot name="minitaur_like"><link name="chassis"><inertial><mass value="3"/>{inertia}</inertial>
  <collision><geometry><box size="0.33 0.14 0.07"/></geometry></collision></link>
{links}{joints}</robot>"#
    )
}

#[test]
fn a_chassis_carrying_eight_motors_of_its_own_inertia_lands_without_gaining_energy() {
    // Dropped free onto the ground at PyBullet's and MuJoCo's usual steps, it loses energy
    // on landing and comes to rest; at one pass per substep it rang up from rounding to
    // 0.8 MJ within a second (solver/mass_ratio.rs, hubs), worse at the smaller steps.
    let d = dir("minitaur");
    let file = write(&d, "minitaur_like.urdf", &minitaur_like());
    for dt in [0.01, 1.0 / 240.0, 0.001] {
        let mut w = z_up();
        w.create_body(
            &tumble::BodyDef {
                kind: tumble::BodyKind::Static,
                ..Default::default()
            },
            Shape::plane(Vec3::Z, 0.0),
        )
        .unwrap();
        let opts = UrdfOptions {
            fixed_base: false,
            position: Vec3::new(0.0, 0.0, 0.5),
            ..UrdfOptions::default()
        };
        let m = urdf::load(&file, &mut w, &opts).unwrap();
        // Seventeen links, nine bodies: each leg merged into its motor.
        let mut ids: Vec<BodyId> = m.bodies.iter().map(|b| b.1).collect();
        ids.sort();
        ids.dedup();
        assert_eq!((m.bodies.len(), ids.len()), (17, 9));
        let start = total_energy(&w, &ids);
        let mut most = start;
        for _ in 0..(1.5 / dt) as usize {
            w.step(dt).unwrap();
            most = most.max(total_energy(&w, &ids));
        }
        let end = total_energy(&w, &ids);
        // Falling turns potential into kinetic energy, which the sum keeps to the
        // integrator's error: a hundredth of a joule on the way down.
        assert!(
            most < start + 0.01,
            "dt {dt}: energy rose from {start} J to {most} J"
        );
        assert!(
            end < start - 5.0,
            "dt {dt}: {start} J before landing, {end} J after"
        );
        let fastest = ids
            .iter()
            .map(|&id| w.body(id).unwrap().angular_velocity().length())
            .fold(0.0, Real::max);
        assert!(
            fastest < 1.0,
            "dt {dt}: a body still turns at {fastest} rad/s"
        );
    }
}

#[test]
fn a_spherical_joint_is_a_ball_joint_and_its_pendulum_keeps_its_energy() {
    // PyBullet's `spherical` joint (its humanoid's chest, neck, hips, ...): a rod hung
    // from a point, released 0.6 rad out of the vertical with a sideways spin, swings in
    // 3D about the point; its bounds are read but not built, with a warning.
    let d = dir("spherical");
    for (mass, length) in [(1.0, 1.0), (0.2, 0.4), (5.0, 2.0)] {
        let text = format!(
            r#"<robot name="s"><link name="base"/>{rod}
  <joint name="neck" type="spherical"><parent link="base"/><child link="rod"/>
    <limit effort="1000" lower="0.2" upper="0.8" twist="0.3"/></joint></robot>"#,
            rod = rod("rod", mass, length)
        );
        let path = write(&d, "s.urdf", &text);
        let mut w = z_up();
        let m = load(&path, &mut w, true);
        assert_eq!(m.warnings.len(), 1, "{:?}", m.warnings);
        assert!(m.warnings[0].contains("<joint name=\"neck\">: limit: its bounds are not applied"));
        let j = m.joint("neck").unwrap();
        assert!(matches!(w.joint(j).unwrap().kind(), JointKind::Ball { .. }));
        let rod_id = m.body("rod").unwrap();
        w.set_joint_position(j, JointCoordinate::Vector(Vec3::new(0.6, 0.0, 0.0)))
            .unwrap();
        w.set_angular_velocity(rod_id, Vec3::new(0.0, 0.0, 1.5))
            .unwrap();
        let start = total_energy(&w, &[rod_id]);
        let (dt, mut worst_gap, mut worst_energy) = (1.0 / 240.0, 0.0 as Real, 0.0 as Real);
        for _ in 0..480 {
            w.step(dt).unwrap();
            let b = w.body(rod_id).unwrap();
            // The rod's top (its frame's origin) stays at the pivot.
            worst_gap = worst_gap.max(b.position().length());
            worst_energy = worst_energy.max((total_energy(&w, &[rod_id]) - start).abs());
        }
        let scale = mass * G * length;
        assert!(
            worst_gap < 1e-3,
            "{mass} kg, {length} m: pivot gap {worst_gap} m"
        );
        assert!(
            worst_energy < 0.01 * scale,
            "{mass} kg, {length} m: energy off by {worst_energy} J of {scale}"
        );
    }
}

#[test]
fn pybullets_plane_geometry_is_a_static_plane_and_refused_on_a_moving_link() {
    // plane_implicit.urdf's ground: `<plane normal="0 0 1"/>` on a massless root. Placed
    // 0.3 m up and tilted about x by 0.2 rad, a ball dropped onto it comes to rest one
    // radius from the tilted plane.
    let d = dir("plane");
    let text = r#"<robot name="plane"><link name="planeLink">
  <inertial><mass value="0"/><inertia ixx="0" ixy="0" ixz="0" iyy="0" iyz="0" izz="0"/></inertial>
  <collision><origin xyz="0 0 0"/><geometry><plane normal="0 0 1"/></geometry></collision>
</link></robot>"#;
    let path = write(&d, "plane.urdf", text);
    for (lift, tilt, radius) in [(0.0, 0.0, 0.5), (0.3, 0.2, 0.1), (-1.0, -0.1, 0.25)] {
        let mut w = z_up();
        let turn = tumble::Quat::from_rotation_x(tilt);
        let opts = UrdfOptions {
            fixed_base: false,
            position: Vec3::new(0.0, 0.0, lift),
            orientation: turn,
            ..UrdfOptions::default()
        };
        let m = urdf::load(&path, &mut w, &opts).unwrap();
        let ground = w.body(m.body("planeLink").unwrap()).unwrap();
        assert_eq!(ground.shape().kind_name(), "plane");
        let ball = w
            .create_body(
                &tumble::BodyDef {
                    position: Vec3::new(0.0, 0.0, lift + 1.0),
                    // Rolling resistance stops it rolling down the slope.
                    rolling_resistance: 1.0,
                    ..Default::default()
                },
                Shape::sphere(radius),
            )
            .unwrap();
        for _ in 0..240 {
            w.step(1.0 / 120.0).unwrap();
        }
        let up = turn * Vec3::Z;
        let height = up.dot(w.body(ball).unwrap().position() - Vec3::new(0.0, 0.0, lift));
        assert!(
            (height - radius).abs() < 0.01,
            "lift {lift}, tilt {tilt}: the ball rests {height} m from the plane"
        );
    }
    // On a link that moves, a plane has no mass or volume to move with: refused.
    let moving = text.replace(r#"<mass value="0"/>"#, r#"<mass value="1"/>"#);
    let path = write(&d, "moving_plane.urdf", &moving);
    let opts = UrdfOptions {
        fixed_base: false,
        ..UrdfOptions::default()
    };
    let e = urdf::load(&path, &mut z_up(), &opts)
        .unwrap_err()
        .to_string();
    assert!(e.contains("moving_plane.urdf:3: <collision>: geometry.plane: only a static link whose only collision geometry it is may be a plane"), "{e}");
}

#[test]
fn numbered_names_xacro_defaults_and_stray_dots_load_as_pybullet_reads_them() {
    // spirit40.urdf numbers its joints "0".."11"; husky.urdf keeps xacro's
    // `$(optenv HUSKY_IMU_XYZ 0.19 0 0.149)`; biped2d_pybullet.urdf has lower="-1.57.".
    let d = dir("numbered");
    let text = "<robot name=\"r\">\n<link name=\"base\"><inertial><mass value=\"1\"/><inertia ixx=\"0.1\" iyy=\"0.1\" izz=\"0.1\"/></inertial></link>\n<link name=\"7\"><inertial><mass value=\"1\"/><inertia ixx=\"0.1\" iyy=\"0.1\" izz=\"0.1\"/></inertial></link>\n<joint name=\"8\" type=\"revolute\"><parent link=\"base\"/><child link=\"7\"/>\n<origin xyz=\"$(optenv R_XYZ 0.19 0 0.149)\"/><axis xyz=\"0 1 0\"/><limit lower=\"-1.57.\" upper=\"1.57\" effort=\"1\" velocity=\"1\"/></joint>\n</robot>\n";
    let (w, m, shown) = warned(&d, "numbered.urdf", text, true);
    assert_eq!(
        shown,
        [
            "numbered.urdf:5: <limit>: limit.lower: '-1.57.' has stray dots; read as '-1.57', as PyBullet reads it",
            "numbered.urdf:5: <origin>: origin.xyz: '$(optenv R_XYZ 0.19 0 0.149)' is xacro's optenv left unexpanded; its default '0.19 0 0.149' used",
        ]
    );
    let child = w.body(m.body("7").unwrap()).unwrap();
    assert!((child.position() - Vec3::new(0.19, 0.0, 0.149)).length() < EXACT);
    let hinge = w.find_joint("8").expect("joint named 8");
    let JointKind::Hinge { limits, .. } = w.joint(hinge).unwrap().kind() else {
        panic!("not a hinge");
    };
    assert_eq!(*limits, Some([-1.57, 1.57]));
    // Still refused: a number with other trailing text, an optenv without a default.
    for (bad, why) in [
        (
            "-1.5x",
            "limit.lower: expected 1 finite numbers, got '-1.5x'",
        ),
        ("1..", "limit.lower: expected 1 finite numbers, got '1..'"),
    ] {
        let p = write(&d, "bad.urdf", &text.replace("-1.57.", bad));
        let e = urdf::load(&p, &mut z_up(), &UrdfOptions::default())
            .unwrap_err()
            .to_string();
        assert!(e.ends_with(why), "{e}");
    }
    let p = write(
        &d,
        "bad.urdf",
        &text.replace("$(optenv R_XYZ 0.19 0 0.149)", "$(optenv R_XYZ)"),
    );
    let e = urdf::load(&p, &mut z_up(), &UrdfOptions::default())
        .unwrap_err()
        .to_string();
    assert!(
        e.ends_with("origin.xyz: expected 3 finite numbers, got '$(optenv R_XYZ)'"),
        "{e}"
    );

    // In a scene, a numbered name is refused only where it reads as an unnamed body's or
    // joint's index label.
    let scene = |bodies: &str, prefix: &str| {
        let s = format!(
            r#"{{"bodies": [{bodies}], "models": [{{"file": "numbered.urdf", "prefix": "{prefix}"}}]}}"#
        );
        let p = write(&d, "scene.json", &s);
        tumble_scene::load(p.to_str().unwrap())
    };
    let ball = r#"{"shape": {"type": "sphere", "radius": 0.1}, "position": [5, 0, 0]}"#;
    let named =
        r#"{"name": "b", "shape": {"type": "sphere", "radius": 0.1}, "position": [5, 0, 0]}"#;
    let eight = [ball; 8].join(", ");
    assert!(scene(ball, "").is_ok());
    assert_eq!(
        scene(&eight, "").unwrap_err().to_string(),
        "models: a model names a body '7', the label of the unnamed body at index 7 (name that one, or give the model a prefix)"
    );
    assert!(scene(&eight, "m_").is_ok());
    let mut seven_named = vec![ball; 7];
    seven_named.push(named);
    assert!(scene(&seven_named.join(", "), "").is_ok());
}

#[test]
fn a_rods_tensor_on_a_link_without_geometry_is_made_possible_and_its_slider_holds() {
    // biped2d_pybullet.urdf: 10 g sliders with a rod's tensor (principal moments 0,
    // 0.215, 0.215; the zero comes out at 2e-18 of the others) and no collision geometry.
    // Taken as given, the slider along y let its link fall along z.
    let d = dir("rod_tensor");
    let text = |tensor: &str| {
        format!(
            "<robot name=\"p\">\n<link name=\"base\"/>\n<link name=\"y\"><inertial><mass value=\"0.01\"/><inertia {tensor}/></inertial></link>\n<joint name=\"slide\" type=\"prismatic\"><parent link=\"base\"/><child link=\"y\"/><axis xyz=\"0 1 0\"/><limit lower=\"-1\" upper=\"1\" effort=\"0\" velocity=\"10\"/></joint>\n</robot>\n"
        )
    };
    let rod =
        "ixx=\"0.2125\" ixy=\"-0.005\" ixz=\"0.0225\" iyy=\"0.205\" iyz=\"0.045\" izz=\"0.0125\"";
    let (mut w, m, shown) = warned(&d, "rod.urdf", &text(rod), true);
    assert_eq!(shown.len(), 1, "{shown:?}");
    assert!(
        shown[0].contains("<link name=\"y\">: inertial.inertia: is not positive definite")
            && shown[0].contains("raised to at least 0.001 of the largest"),
        "{}",
        shown[0]
    );
    let y = m.body("y").unwrap();
    let (moments, _) = w.body(y).unwrap().principal_inertia();
    let mut sorted = moments.to_array();
    sorted.sort_by(Real::total_cmp);
    // Raised to a thousandth of the largest; the other two as the file has them.
    let tol = if F32 { 1e-5 } else { 1e-9 };
    for (got, want) in sorted.iter().zip([0.000215, 0.215, 0.215]) {
        assert!((got - want).abs() < tol, "{sorted:?}");
    }
    // A second at dt 1/240 under z gravity: the slider holds it at z = 0 (to the joint's
    // softness, well under a millimetre) while nothing pushes it along y.
    for _ in 0..240 {
        w.step(1.0 / 240.0).unwrap();
    }
    let p = w.body(y).unwrap().position();
    assert!(
        p.z.abs() < 1e-3 && p.x.abs() < 1e-6 && p.y.abs() < 1e-6,
        "{p}"
    );
}
