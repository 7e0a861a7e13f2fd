//! Joints measured against physics: pendulum periods and energy, chains, limits, motors,
//! sliders and welds.

// Casts between Real and f64 are no-ops in the default build but needed in the f32 one.
#![allow(clippy::unnecessary_cast)]

use crate::common::*;
use tumble::prelude::*;

const G: Real = 9.8;

/// A ball of radius r on a massless hinge at the origin (axis z), released at `angle`
/// from the downward vertical. Returns the world, the ball, its mass, and the moment of
/// inertia about the pivot.
fn hinge_pendulum(length: Real, angle: Real) -> (World, BodyId, Real, Real) {
    let mut w = awake(Vec3::new(0.0, -G, 0.0));
    let p = Vec3::new(length * angle.sin(), -length * angle.cos(), 0.0);
    let r = 0.1;
    let ball = w
        .create_body(
            &BodyDef {
                position: p,
                mass: MassSpec::Mass(1.0),
                ..Default::default()
            },
            Shape::sphere(r),
        )
        .unwrap();
    let mut def = JointDef::new(
        JointKind::Hinge {
            limits: None,
            motor: None,
            spring: None,
            servo: None,
        },
        ball,
    );
    def.anchor = -p;
    def.axis = Vec3::Z;
    def.other_axis = Vec3::Z;
    w.create_joint(&def).unwrap();
    let inertia = 0.4 * r * r + length * length;
    (w, ball, 1.0, inertia)
}

fn energy(w: &World, id: BodyId) -> Real {
    let b = w.body(id).unwrap();
    b.kinetic_energy() + b.mass() * G * b.center_of_mass().y
}

/// Times of successive upward zero crossings of x (the bob passing the bottom moving +x),
/// linearly interpolated, and the largest energy change from the first crossing on.
fn crossings(w: &mut World, id: BodyId, dt: Real, seconds: Real) -> (Vec<Real>, Real) {
    let mut out = Vec::new();
    let mut last = w.body(id).unwrap().center_of_mass().x;
    let mut settled: Option<Real> = None;
    let mut worst: Real = 0.0;
    for i in 0..(seconds / dt) as usize {
        w.step(dt).unwrap();
        let x = w.body(id).unwrap().center_of_mass().x;
        if last < 0.0 && x >= 0.0 {
            out.push((i as Real + last / (last - x)) * dt);
            settled.get_or_insert(energy(w, id));
        }
        last = x;
        if let Some(e) = settled {
            worst = worst.max((energy(w, id) - e).abs());
        }
    }
    (out, worst)
}

#[test]
fn a_hinge_pendulum_swings_with_the_exact_period_and_keeps_its_energy() {
    // Period: the physical pendulum's 2π√(I/mgl), times 2K(sin(θ₀/2))/π for amplitude θ₀.
    // Energy is compared from the first pass through the bottom on: at release the soft
    // joint first stretches under the bob's weight (g/ω² = 0.07 mm at 60 Hz), a constant
    // offset of m·g·0.07 mm that is not drift (1.4 % of the swing energy at 0.1 rad).
    // What remains is symplectic Euler's O(h) oscillation about a conserved energy.
    let dt = 1.0 / 60.0;
    for amplitude in [0.1 as Real, 1.0, 2.0] {
        let (mut w, ball, m, inertia) = hinge_pendulum(1.0, amplitude);
        let l = 1.0;
        let t_small =
            2.0 * std::f64::consts::PI * (inertia as f64 / (m as f64 * G as f64 * l)).sqrt();
        let k = (0.5 * amplitude as f64).sin();
        let period = t_small * 2.0 / std::f64::consts::PI * elliptic_k(k);
        // Energy scale: the drop from the release height to the bottom.
        let scale = (m * G * l as Real * (1.0 - amplitude.cos())) as f64;
        let (times, worst) = crossings(&mut w, ball, dt, (20.5 * period) as Real);
        assert!(
            times.len() >= 20,
            "amplitude {amplitude}: {} swings",
            times.len()
        );
        let measured = (times[times.len() - 1] - times[0]) as f64 / (times.len() - 1) as f64;
        assert!(
            (measured / period - 1.0).abs() < 0.005,
            "amplitude {amplitude}: period {measured} vs {period}"
        );
        assert!(
            (worst as f64) < 0.01 * scale,
            "amplitude {amplitude}: energy moved {worst} J, {:.2} % of {scale} J",
            100.0 * worst as f64 / scale
        );
    }
}

fn hinge(limits: Option<[Real; 2]>, motor: Option<Motor>) -> JointKind {
    JointKind::Hinge {
        limits,
        motor,
        spring: None,
        servo: None,
    }
}

fn unit_box(w: &mut World, position: Vec3, mass: Real) -> BodyId {
    w.create_body(
        &BodyDef {
            position,
            mass: MassSpec::Mass(mass),
            ..Default::default()
        },
        Shape::cuboid(Vec3::new(0.5, 0.1, 0.1)),
    )
    .unwrap()
}

#[test]
fn a_chain_of_twenty_links_holds_a_ball_a_hundred_times_heavier() {
    // Twenty 1 kg links, 0.2 m apart, ball-jointed end to end, hanging from the world; a
    // ball of 10 to 100 kg at the bottom. A soft joint is a spring of stiffness m_eff·ω²,
    // m_eff about a link's half mass, so each joint stretches by about F/(m_eff ω²) under
    // the ~1,180 N it carries at 100 kg: 2.3 cm with 4 substeps (ω capped at a quarter of
    // 240 Hz), the same at 2 or 4 iterations (it is the spring, not Gauss–Seidel's lag).
    // From a mass ratio of 20 the island's joints are four times as stiff, with four times
    // the passes (solver/mass_ratio.rs). Measured, the whole run's largest gap at the
    // defaults: 6.8 mm (10 kg, not stiffened), 2.8 mm (30 kg), 7.4 mm (100 kg; 0.46 mm at
    // dt 1/240, 1.8 mm with 8 substeps).
    for (mass, substeps, dt) in [
        (100.0, 4, 1.0 / 60.0),
        (100.0, 4, 1.0 / 240.0),
        (100.0, 8, 1.0 / 60.0),
        (30.0, 4, 1.0 / 60.0),
        (10.0, 4, 1.0 / 60.0),
    ] {
        let gap = hanging_chain_gap(mass, substeps, dt);
        assert!(
            gap < 0.01,
            "{mass} kg, {substeps} substeps, dt {dt:.4}: gap {gap} m"
        );
    }
}

/// The largest joint gap over 10 s of the chain of twenty links holding a ball of `mass`.
fn hanging_chain_gap(mass: Real, substeps: u32, dt: Real) -> Real {
    let mut w = awake(Vec3::new(0.0, -G, 0.0));
    let mut settings = w.solver_settings();
    settings.substeps = substeps;
    w.set_solver_settings(settings).unwrap();
    let n = 20;
    let spacing = 0.2;
    let mut ids = Vec::new();
    for i in 0..n {
        let y = -(i as Real + 0.5) * spacing;
        let link = w
            .create_body(
                &BodyDef {
                    position: Vec3::new(0.0, y, 0.0),
                    mass: MassSpec::Mass(1.0),
                    ..Default::default()
                },
                Shape::capsule(0.03, 0.5 * spacing - 0.03),
            )
            .unwrap();
        let mut def = JointDef::new(
            JointKind::Ball {
                cone: None,
                twist: None,
            },
            link,
        );
        def.anchor = Vec3::new(0.0, 0.5 * spacing, 0.0);
        match ids.last() {
            Some(&above) => {
                def.other = Some(above);
                def.other_anchor = Vec3::new(0.0, -0.5 * spacing, 0.0);
            }
            None => def.other_anchor = Vec3::ZERO,
        }
        w.create_joint(&def).unwrap();
        ids.push(link);
    }
    let r = 0.15;
    let bottom = -(n as Real) * spacing - r;
    let ball = w
        .create_body(
            &BodyDef {
                position: Vec3::new(0.0, bottom, 0.0),
                mass: MassSpec::Mass(mass),
                ..Default::default()
            },
            Shape::sphere(r),
        )
        .unwrap();
    let mut def = JointDef::new(
        JointKind::Ball {
            cone: None,
            twist: None,
        },
        ball,
    );
    def.anchor = Vec3::new(0.0, r, 0.0);
    def.other = Some(ids[n - 1]);
    def.other_anchor = Vec3::new(0.0, -0.5 * spacing, 0.0);
    w.create_joint(&def).unwrap();
    // The chain starts unstretched, so the ball first bounces on it; the gaps are taken
    // over the whole run, bounce included.
    let mut gap: Real = 0.0;
    for _ in 0..(10.0 / dt).round() as usize {
        w.step(dt).unwrap();
        gap = gap.max(max_joint_gap(&w));
    }
    let below = w.body(ball).unwrap().position();
    assert!(
        below.x.abs() < 1e-6 && below.z.abs() < 1e-6,
        "the chain swung: {below}"
    );
    gap
}

/// The largest distance between a joint's two anchors, over all joints.
fn max_joint_gap(w: &World) -> Real {
    w.joints()
        .map(|(_, j)| {
            let d = j.def();
            let a = w.body(d.body).unwrap().pose().transform_point(d.anchor);
            let b = match d.other {
                Some(o) => w.body(o).unwrap().pose().transform_point(d.other_anchor),
                None => d.other_anchor,
            };
            (a - b).length()
        })
        .fold(0.0, Real::max)
}

#[test]
fn a_double_pendulum_keeps_its_energy() {
    // Two 1 kg rods, hinged end to end, released horizontal: chaotic, so only the energy
    // can be checked; within 2 % of the drop of the rods' centres over 10 s at 240 Hz.
    let mut w = awake(Vec3::new(0.0, -G, 0.0));
    let first = unit_box(&mut w, Vec3::new(0.5, 0.0, 0.0), 1.0);
    let second = unit_box(&mut w, Vec3::new(1.5, 0.0, 0.0), 1.0);
    let mut def = JointDef::new(hinge(None, None), first);
    def.anchor = Vec3::new(-0.5, 0.0, 0.0);
    def.axis = Vec3::Z;
    def.other_axis = Vec3::Z;
    w.create_joint(&def).unwrap();
    def.body = second;
    def.other = Some(first);
    def.other_anchor = Vec3::new(0.5, 0.0, 0.0);
    w.create_joint(&def).unwrap();
    let energy = |w: &World| {
        [first, second]
            .iter()
            .map(|id| {
                let b = w.body(*id).unwrap();
                b.kinetic_energy() + b.mass() * G * b.center_of_mass().y
            })
            .sum::<Real>()
    };
    let e0 = energy(&w);
    let scale = G * (0.5 + 1.5) * 1.0; // both centres dropping by their arm
    let mut worst: Real = 0.0;
    for _ in 0..2400 {
        w.step(1.0 / 240.0).unwrap();
        worst = worst.max((energy(&w) - e0).abs());
    }
    assert!(worst < 0.02 * scale, "energy moved {worst} J of {scale} J");
    assert!(max_joint_gap(&w) < 1e-3, "gap {}", max_joint_gap(&w));
}

/// A 1 kg rod hinged at one end to the world about z, starting horizontal along x.
fn hinged_rod(kind: JointKind, gravity: Vec3) -> (World, BodyId) {
    let mut w = awake(gravity);
    let rod = unit_box(&mut w, Vec3::new(0.5, 0.0, 0.0), 1.0);
    let mut def = JointDef::new(kind, rod);
    def.anchor = Vec3::new(-0.5, 0.0, 0.0);
    def.axis = Vec3::Z;
    def.other_axis = Vec3::Z;
    w.create_joint(&def).unwrap();
    (w, rod)
}

/// The rod's angle about z from +x.
fn rod_angle(w: &World, rod: BodyId) -> Real {
    let c = w.body(rod).unwrap().center_of_mass();
    c.y.atan2(c.x)
}

#[test]
fn hinge_limits_hold_against_gravity_and_a_motor() {
    // Gravity swings the rod down against a −0.5 rad limit; a motor drives it up against
    // +0.8 rad. Neither may pass its limit by more than 0.01 rad.
    let (mut w, rod) = hinged_rod(hinge(Some([-0.5, 0.8]), None), Vec3::new(0.0, -G, 0.0));
    let mut lowest: Real = 0.0;
    for _ in 0..300 {
        w.step(1.0 / 60.0).unwrap();
        lowest = lowest.min(rod_angle(&w, rod));
    }
    assert!(lowest > -0.51, "passed the lower limit: {lowest}");
    assert!(
        (rod_angle(&w, rod) + 0.5).abs() < 0.01,
        "rests at {}",
        rod_angle(&w, rod)
    );
    let motor = Motor {
        speed: 5.0,
        max_force: 100.0,
    };
    let (mut w, rod) = hinged_rod(
        hinge(Some([-0.5, 0.8]), Some(motor)),
        Vec3::new(0.0, -G, 0.0),
    );
    let mut highest: Real = 0.0;
    for _ in 0..300 {
        w.step(1.0 / 60.0).unwrap();
        highest = highest.max(rod_angle(&w, rod));
    }
    assert!(highest < 0.81, "passed the upper limit: {highest}");
    assert!(
        (rod_angle(&w, rod) - 0.8).abs() < 0.01,
        "rests at {}",
        rod_angle(&w, rod)
    );
}

#[test]
fn a_hinge_motor_reaches_its_speed_or_stalls() {
    // No gravity; a 5 N·m torque resists the motor (speed 2 rad/s). With 10 N·m to spend
    // the motor holds its speed; with 3 N·m it stalls and the rod turns backwards with
    // α = (3 − 5) / I_pivot, I_pivot = m(a² + b²)/12 + m(l/2)² for the 1 × 0.2 m rod.
    let i_pivot: Real = (1.0 + 0.04) / 12.0 + 0.25;
    for (max_force, expect_after_1s) in [(10.0, 2.0), (3.0, (3.0 - 5.0) / i_pivot)] {
        let motor = Motor {
            speed: 2.0,
            max_force,
        };
        let (mut w, rod) = hinged_rod(hinge(None, Some(motor)), Vec3::ZERO);
        w.add_force(Force::Applied(AppliedForce {
            body: rod,
            force: Vec3::ZERO,
            point: None,
            torque: Vec3::new(0.0, 0.0, -5.0),
        }))
        .unwrap();
        run(&mut w, 1.0 / 60.0, 60);
        let spin = w.body(rod).unwrap().angular_velocity().z;
        assert!(
            (spin - expect_after_1s).abs() < 0.01 * expect_after_1s.abs(),
            "max torque {max_force}: spin {spin}, expected {expect_after_1s}"
        );
    }
}

#[test]
fn a_slider_keeps_its_body_on_the_axis_and_a_weld_holds() {
    // A box on a slider along a tilted axis, pulled by gravity: it must slide along the
    // axis with g·(axis·ĝ) and leave it by less than a millimetre, without turning.
    let mut w = awake(Vec3::new(0.0, -G, 0.0));
    let axis = Vec3::new(1.0, -1.0, 0.5).normalize();
    let body = unit_box(&mut w, Vec3::ZERO, 2.0);
    let mut def = JointDef::new(free_slider(), body);
    def.axis = axis;
    def.other_axis = axis;
    w.create_joint(&def).unwrap();
    let t: Real = 1.0;
    run(&mut w, 1.0 / 60.0, 60);
    let p = w.body(body).unwrap().center_of_mass();
    let along = p.dot(axis);
    let off = (p - axis * along).length();
    let expect = 0.5 * G * axis.dot(-Vec3::Y) * t * t;
    assert!(off < 1e-3, "left the axis by {off}");
    assert!(
        (along - expect).abs() < 0.01 * expect,
        "slid {along}, expected {expect}"
    );
    assert!(w.body(body).unwrap().angular_velocity().length() < 1e-6);

    // A fixed joint: a 1 kg rod welded to a 10 kg rod hung from the world by a ball
    // joint, as a horizontal cantilever; the weld must keep their relative pose.
    let mut w = awake(Vec3::new(0.0, -G, 0.0));
    let heavy = unit_box(&mut w, Vec3::ZERO, 10.0);
    let light = unit_box(&mut w, Vec3::new(1.0, 0.0, 0.0), 1.0);
    let mut hang = JointDef::new(JointKind::Fixed, heavy);
    hang.other = None;
    w.create_joint(&hang).unwrap();
    let mut weld = JointDef::new(JointKind::Fixed, light);
    weld.anchor = Vec3::new(-0.5, 0.0, 0.0);
    weld.other = Some(heavy);
    weld.other_anchor = Vec3::new(0.5, 0.0, 0.0);
    w.create_joint(&weld).unwrap();
    run(&mut w, 1.0 / 60.0, 300);
    let l = w.body(light).unwrap();
    assert!(
        (l.position() - Vec3::new(1.0, 0.0, 0.0)).length() < 0.01,
        "sagged to {}",
        l.position()
    );
    assert!(l.orientation().angle_between(Quat::IDENTITY) < 0.01);
}

#[test]
fn a_joint_breaks_past_its_break_force_and_joined_bodies_do_not_collide() {
    // A 1 kg ball hangs from a joint that breaks beyond 20 N: it holds the 9.8 N weight,
    // and breaks when a 30 N pull is added.
    let mut w = awake(Vec3::new(0.0, -G, 0.0));
    let b = ball(&mut w, Vec3::new(0.0, -1.0, 0.0));
    let mut def = JointDef::new(
        JointKind::Ball {
            cone: None,
            twist: None,
        },
        b,
    );
    def.anchor = Vec3::new(0.0, 1.0, 0.0);
    def.break_force = Some(20.0);
    let j = w.create_joint(&def).unwrap();
    run(&mut w, 1.0 / 60.0, 60);
    let f = w.joint(j).unwrap().reaction_force();
    assert!(
        (f - Vec3::new(0.0, -G, 0.0)).length() < 0.05,
        "reaction {f}"
    );
    assert!(!w.joint(j).unwrap().is_broken());
    w.add_force(Force::Applied(AppliedForce {
        body: b,
        force: Vec3::new(0.0, -30.0, 0.0),
        point: None,
        torque: Vec3::ZERO,
    }))
    .unwrap();
    run(&mut w, 1.0 / 60.0, 2);
    assert!(w.joint(j).unwrap().is_broken());
    run(&mut w, 1.0 / 60.0, 30);
    assert!(
        w.body(b).unwrap().position().y < -1.1,
        "a broken joint still holds"
    );

    // Two overlapping boxes joined by a ball joint stay overlapped (no contact pushes
    // them apart) unless the joint asks for collisions.
    for collide in [false, true] {
        let mut w = awake(Vec3::ZERO);
        let a = unit_box(&mut w, Vec3::ZERO, 1.0);
        let c = unit_box(&mut w, Vec3::new(0.5, 0.0, 0.0), 1.0);
        let mut def = JointDef::new(
            JointKind::Ball {
                cone: None,
                twist: None,
            },
            c,
        );
        def.other = Some(a);
        def.collide_connected = collide;
        def.anchor = Vec3::new(-0.5, 0.0, 0.0);
        w.create_joint(&def).unwrap();
        run(&mut w, 1.0 / 60.0, 30);
        let moved = w.body(c).unwrap().linear_velocity().length()
            + w.body(a).unwrap().linear_velocity().length();
        assert_eq!(
            moved > 1e-3,
            collide,
            "collide_connected {collide}: speed {moved}"
        );
    }
}

#[test]
fn bad_joint_definitions_name_the_field() {
    let mut w = awake(Vec3::ZERO);
    let b = ball(&mut w, Vec3::ZERO);
    let message = |w: &mut World, def: JointDef| w.create_joint(&def).unwrap_err().to_string();
    let mut def = JointDef::new(hinge(Some([1.0, -1.0]), None), b);
    assert_eq!(
        message(&mut w, def.clone()),
        "limits: lower must be <= upper"
    );
    def.kind = hinge(None, None);
    def.axis = Vec3::ZERO;
    assert_eq!(
        message(&mut w, def.clone()),
        "axis: must be a non-zero direction"
    );
    def.axis = Vec3::X;
    def.anchor = Vec3::new(Real::NAN, 0.0, 0.0);
    assert_eq!(
        message(&mut w, def.clone()),
        "anchor: must be finite numbers"
    );
    def.anchor = Vec3::ZERO;
    def.other = Some(b);
    assert_eq!(message(&mut w, def.clone()), "other: must differ from body");
    def.other = None;
    def.kind = JointKind::Distance {
        length: Some(-1.0),
        min: None,
        max: None,
        spring: None,
    };
    assert_eq!(message(&mut w, def.clone()), "length: must be > 0");
    assert_eq!(w.joints().count(), 0);
}

#[test]
fn ball_joint_cone_and_twist_limits_hold() {
    // A rod hangs from the world by a ball joint with its axis along the rod (down). A
    // sideways push swings it against a 0.5 rad cone; a torque about the rod twists it
    // against [−0.3, 0.3] rad. Neither limit may be passed by more than 0.01 rad.
    let mut w = awake(Vec3::new(0.0, -G, 0.0));
    let rod = w
        .create_body(
            &BodyDef {
                position: Vec3::new(0.0, -0.5, 0.0),
                mass: MassSpec::Mass(1.0),
                ..Default::default()
            },
            Shape::cuboid(Vec3::new(0.1, 0.5, 0.1)),
        )
        .unwrap();
    let mut def = JointDef::new(
        JointKind::Ball {
            cone: Some(0.5),
            twist: Some([-0.3, 0.3]),
        },
        rod,
    );
    def.anchor = Vec3::new(0.0, 0.5, 0.0);
    def.axis = -Vec3::Y;
    def.other_axis = -Vec3::Y;
    w.create_joint(&def).unwrap();
    w.set_linear_velocity(rod, Vec3::new(4.0, 0.0, 1.0))
        .unwrap();
    w.add_force(Force::Applied(AppliedForce {
        body: rod,
        force: Vec3::ZERO,
        point: None,
        torque: Vec3::new(0.0, 3.0, 0.0),
    }))
    .unwrap();
    let (mut swing, mut twist): (Real, Real) = (0.0, 0.0);
    for _ in 0..180 {
        w.step(1.0 / 60.0).unwrap();
        let q = w.body(rod).unwrap().orientation();
        let down = q * -Vec3::Y;
        swing = swing.max(down.angle_between(-Vec3::Y));
        // Twist as the joint defines it: the angle between the two frames' reference
        // directions (the first of `orthonormal_basis(axis)`), both laid into the plane
        // across the axes' mean direction.
        let mid = (down - Vec3::Y).normalize();
        let flat = |r: Vec3| (r - mid * mid.dot(r)).normalize();
        let reference = tumble::math::orthonormal_basis(-Vec3::Y)[0];
        let (r_rod, r_world) = (flat(q * reference), flat(reference));
        twist = twist.max(
            mid.dot(r_world.cross(r_rod))
                .atan2(r_rod.dot(r_world))
                .abs(),
        );
    }
    assert!(swing < 0.51, "swung {swing} rad past a 0.5 rad cone");
    assert!(swing > 0.45, "never reached the cone: {swing}");
    assert!(twist < 0.31, "twisted {twist} rad past 0.3");
    assert!(twist > 0.25, "never reached the twist limit: {twist}");
}

#[test]
fn slider_limits_springs_and_distance_ropes_behave() {
    // A slider along x with a spring (2 Hz, undamped) towards 0 and limits [−0.2, 0.2]:
    // released at 0.1 m with no gravity, it oscillates at 2 Hz within the limits.
    let mut w = awake(Vec3::ZERO);
    let body = unit_box(&mut w, Vec3::new(0.1, 0.0, 0.0), 1.0);
    let mut def = JointDef::new(
        JointKind::Slider {
            limits: Some([-0.2, 0.2]),
            motor: None,
            spring: Some(JointSpring {
                hertz: 2.0,
                damping_ratio: 0.0,
                target: 0.0,
            }),
            servo: None,
        },
        body,
    );
    def.anchor = Vec3::ZERO;
    def.other_anchor = Vec3::ZERO;
    w.create_joint(&def).unwrap();
    let dt = 1.0 / 240.0;
    let mut crossings = Vec::new();
    let mut last = 0.1;
    for i in 0..(2.0 / dt) as usize {
        w.step(dt).unwrap();
        let x = w.body(body).unwrap().center_of_mass().x;
        if last > 0.0 && x <= 0.0 {
            crossings.push(i as Real * dt);
        }
        last = x;
    }
    let period = (crossings[crossings.len() - 1] - crossings[0]) / (crossings.len() - 1) as Real;
    assert!(
        (period - 0.5).abs() < 0.01,
        "spring period {period} s, expected 0.5"
    );

    // A 1 kg ball on a 1 m rope (max only) dropped from 0.5 m beside the anchor: it
    // falls freely until the rope tightens, then hangs at 1 m.
    let mut w = awake(Vec3::new(0.0, -G, 0.0));
    let b = ball(&mut w, Vec3::new(0.5, 0.0, 0.0));
    let mut def = JointDef::new(
        JointKind::Distance {
            length: Some(1.0),
            min: None,
            max: Some(1.0),
            spring: None,
        },
        b,
    );
    def.other_anchor = Vec3::ZERO;
    w.create_joint(&def).unwrap();
    w.step(1.0 / 60.0).unwrap();
    let v = w.body(b).unwrap().linear_velocity();
    assert!((v.y + G / 60.0).abs() < 1e-6, "a slack rope pulled: {v}");
    let mut longest: Real = 0.0;
    for _ in 0..600 {
        w.step(1.0 / 60.0).unwrap();
        longest = longest.max(w.body(b).unwrap().center_of_mass().length());
    }
    assert!(longest < 1.01, "the rope stretched to {longest} m");
}

#[test]
fn a_pendulum_bouncing_off_a_wall_never_gains_energy() {
    // The bob swings on its joint alone (split half kicks) and then touches a wall (the
    // whole kick of contacts), switching scheme twice a period. Contacts with e = 0.5
    // only take energy away: the total must never rise above its starting value by more
    // than the joint's 0.5 % swing-energy wobble.
    let (mut w, ball, m, _) = hinge_pendulum(1.0, 1.0);
    w.create_body(
        &BodyDef {
            kind: BodyKind::Static,
            position: Vec3::new(-0.45, -1.0, 0.0),
            restitution: 0.5,
            ..Default::default()
        },
        Shape::cuboid(Vec3::new(0.05, 0.5, 0.5)),
    )
    .unwrap();
    let e0 = energy(&w, ball);
    let scale = m * G * (1.0 - (1.0 as Real).cos());
    let mut touched = 0;
    let mut highest = e0;
    for _ in 0..600 {
        w.step(1.0 / 60.0).unwrap();
        highest = highest.max(energy(&w, ball));
        touched += usize::from(w.contacts().iter().any(|c| !c.manifold.is_empty()));
    }
    assert!(touched > 10, "the bob never reached the wall");
    assert!(
        highest - e0 < 0.005 * scale,
        "energy rose by {} J of {scale}",
        highest - e0
    );
    assert!(
        energy(&w, ball) < e0 - 0.1 * scale,
        "the bounces took no energy"
    );
}

#[test]
fn joint_handles_are_generational_and_removal_reports_stale_ones() {
    // A removed joint's handle stays dead even after a new joint takes its slot, and
    // removing it again is an error, as for bodies.
    let mut w = awake(Vec3::ZERO);
    let ball = w
        .create_body(&BodyDef::default(), Shape::sphere(0.1))
        .unwrap();
    let first = w
        .create_joint(&JointDef::new(JointKind::Fixed, ball))
        .unwrap();
    let second = w
        .create_joint(&JointDef::new(JointKind::Fixed, ball))
        .unwrap();
    w.remove_joint(first).unwrap();
    let err = w.remove_joint(first).unwrap_err().to_string();
    assert!(err.contains("unknown or removed joint"), "{err}");
    let third = w
        .create_joint(&JointDef::new(JointKind::Fixed, ball))
        .unwrap();
    assert_eq!(third.index, first.index);
    assert_ne!(third, first);
    assert!(w.joint(first).is_err());
    let ids: Vec<JointId> = w.joints().map(|(id, _)| id).collect();
    assert_eq!(ids, [second, third]);
    w.remove_body(ball).unwrap();
    assert_eq!(w.joints().count(), 0);
    assert!(w.remove_joint(third).is_err());
}

#[test]
fn every_kind_is_described_and_its_options_round_trip() {
    // The description table and the variants agree: each kind's options come back from
    // `from_options` unchanged, and an option it does not take is dropped.
    use tumble::joint::{JointOptions, JOINT_KINDS};
    let given = JointOptions {
        cone: Some(0.5),
        twist: Some([-0.1, 0.2]),
        limits: Some([-1.0, 1.0]),
        motor: Some(Motor {
            speed: 1.0,
            max_force: 2.0,
        }),
        spring: Some(JointSpring {
            hertz: 3.0,
            damping_ratio: 0.5,
            target: 0.1,
        }),
        servo: Some(Servo {
            target: 0.2,
            stiffness: 50.0,
            damping: 1.0,
            max_force: 10.0,
        }),
        length: Some(1.5),
        min: Some(0.5),
        max: Some(2.0),
    };
    for spec in &JOINT_KINDS {
        let kind = JointKind::from_options(spec.name, &given).unwrap();
        assert_eq!(kind.name(), spec.name);
        assert_eq!(kind.spec(), spec);
        let back = kind.options();
        for option in tumble::joint::JointOption::ALL {
            let expected = given.get(option).filter(|_| spec.takes(option));
            assert_eq!(back.get(option), expected, "{} {option:?}", spec.name);
        }
        assert_eq!(JointKind::from_options(spec.name, &back), Some(kind));
    }
    assert_eq!(JointKind::from_options("weld", &given), None);
}

/// A chassis carrying joined partners whose masses or moments of inertia sum to many times
/// its own, as PyBullet's minitaur hangs eight hinged motors of 3 kg·m² on a 3 kg·m²
/// chassis: at one pass Gauss–Seidel rang such a hub up from rounding to hundreds of
/// rad/s within a second, 59 J to 0.8 MJ (solver/mass_ratio.rs, hubs). In zero gravity,
/// from a small spin of the partners, nothing adds energy: it may only fall (the joints'
/// springs and the relax pass take some) and must never rise above its start.
#[test]
fn a_chassis_carrying_heavier_joined_partners_never_gains_energy() {
    let hinge = JointKind::Hinge {
        limits: None,
        motor: None,
        spring: None,
        servo: None,
    };
    let slider = JointKind::Slider {
        limits: None,
        motor: None,
        spring: None,
        servo: None,
    };
    // (partners, each one's moment (kg·m²), each one's mass (kg)) on a 3.2 kg, 3 kg·m²
    // chassis: the minitaur; twelve at 10 times its moment each; eight light in turning but
    // 25 times its mass in all; six at 100 times its moment; sixteen at 10 times (a load
    // of 160, which needs the most passes a hub gets). Twenty-four at 100 times (800)
    // still ring at those passes: the cure's known limit.
    let cases = [
        (8, 3.0, 0.35),
        (12, 30.0, 0.35),
        (8, 0.01, 10.0),
        (6, 300.0, 1.0),
        (16, 30.0, 2.0),
    ];
    for kind in [hinge, JointKind::Fixed, slider] {
        for (n, moment, mass) in cases {
            for dt in [1.0 / 60.0, 0.01, 1.0 / 240.0] {
                let mut w = awake(Vec3::ZERO);
                let chassis = w
                    .create_body(
                        &BodyDef {
                            mass: MassSpec::Mass(3.2),
                            inertia: Some(InertiaSpec::Principal(Vec3::splat(3.0))),
                            ..Default::default()
                        },
                        Shape::cuboid(Vec3::new(0.17, 0.07, 0.035)),
                    )
                    .unwrap();
                let mut ids = vec![chassis];
                for i in 0..n {
                    let turn = i as Real / n as Real * 2.0 * std::f64::consts::PI as Real;
                    let at = Vec3::new(0.25 * turn.cos(), 0.25 * turn.sin(), 0.003 * turn.sin());
                    let part = w
                        .create_body(
                            &BodyDef {
                                position: at,
                                angular_velocity: Vec3::new(0.05, 0.1, -0.05),
                                mass: MassSpec::Mass(mass),
                                inertia: Some(InertiaSpec::Principal(Vec3::splat(moment))),
                                collision_group: 0,
                                ..Default::default()
                            },
                            Shape::sphere(0.04),
                        )
                        .unwrap();
                    let mut def = JointDef::new(kind, part);
                    def.other = Some(chassis);
                    def.other_anchor = at;
                    def.axis = Vec3::Y;
                    def.other_axis = Vec3::Y;
                    w.create_joint(&def).unwrap();
                    ids.push(part);
                }
                let kinetic = |w: &World| -> Real {
                    ids.iter()
                        .map(|&id| w.body(id).unwrap().kinetic_energy())
                        .sum()
                };
                let start = kinetic(&w);
                let mut most: Real = 0.0;
                for _ in 0..(1.0 / dt) as usize {
                    if let Err(e) = w.step(dt) {
                        panic!("{kind:?}, {n} partners of {moment} kg·m² and {mass} kg, dt {dt:.4}: {e}");
                    }
                    most = most.max(kinetic(&w));
                }
                assert!(
                    most <= start * 1.0001,
                    "{kind:?}, {n} partners of {moment} kg·m² and {mass} kg, dt {dt:.4}: \
                     kinetic energy rose from {start} J to {most} J"
                );
            }
        }
    }
}
