//! Joint trees solved in reduced coordinates (`SolverSettings::joint_trees` = `Reduced`,
//! `dynamics/solver/articulation.rs`), against closed forms, against the soft step where
//! both converge, and for what must fall back to the soft step unchanged.

// Casts between Real and f64 are no-ops in the default build but needed in the f32 one.
#![allow(clippy::unnecessary_cast)]

use crate::common::*;
use tumble::prelude::*;

const G: Real = 9.81;

/// `w` with its joint trees solved as `trees` says, at `substeps` a step.
fn solve_trees(w: &mut World, trees: JointTrees, substeps: u32) {
    w.set_solver_settings(SolverSettings {
        joint_trees: trees,
        substeps,
        ..w.solver_settings()
    })
    .unwrap();
}

/// `w` with its joint trees solved in reduced coordinates, at `substeps` a step.
fn reduced(w: &mut World, substeps: u32) {
    solve_trees(w, JointTrees::Reduced, substeps);
}

/// Kinetic plus potential energy of every body, gravity G along −y (J).
fn energy(w: &World) -> Real {
    w.bodies()
        .map(|(_, b)| b.kinetic_energy() + b.mass() * G * b.center_of_mass().y)
        .sum()
}

/// A box of `half` extents and `mass` at `position`.
fn block(w: &mut World, position: Vec3, half: Vec3, mass: Real) -> BodyId {
    w.create_body(
        &BodyDef {
            position,
            mass: MassSpec::Mass(mass),
            ..Default::default()
        },
        Shape::cuboid(half),
    )
    .unwrap()
}

/// A joint of `kind` on `body` at `anchor` (its frame) to `other` at `other_anchor`,
/// both axes `axis`.
fn join(
    w: &mut World,
    kind: JointKind,
    (body, anchor): (BodyId, Vec3),
    (other, other_anchor): (Option<BodyId>, Vec3),
    axis: Vec3,
) -> JointId {
    let mut def = JointDef::new(kind, body);
    (def.anchor, def.other, def.other_anchor) = (anchor, other, other_anchor);
    (def.axis, def.other_axis) = (axis, axis);
    w.create_joint(&def).unwrap()
}

/// A free hinge about z (see `join`): the joint of most trees here.
fn pin(w: &mut World, a: (BodyId, Vec3), b: (Option<BodyId>, Vec3)) -> JointId {
    join(w, free_hinge(), a, b, Vec3::Z)
}

/// The largest distance between a joint's two anchors, over all joints (across the
/// axis, for a slider: along it they may part).
fn max_joint_gap(w: &World) -> Real {
    w.joints()
        .map(|(_, j)| {
            let d = j.def();
            let pose = w.body(d.body).unwrap().pose();
            let a = pose.transform_point(d.anchor);
            let b = match d.other {
                Some(o) => w.body(o).unwrap().pose().transform_point(d.other_anchor),
                None => d.other_anchor,
            };
            let gap = b - a;
            match d.kind {
                JointKind::Slider { .. } => {
                    let axis = (pose.rotation * d.axis).normalize();
                    (gap - axis * axis.dot(gap)).length()
                }
                _ => gap.length(),
            }
        })
        .fold(0.0, Real::max)
}

/// A rod of `length` (a thin box, 1 kg) hinged at its top end to the world at the origin
/// about z, let go at `angle` from hanging straight down (gravity −y).
fn rod_pendulum(length: Real, angle: Real) -> (World, BodyId) {
    let mut w = awake(Vec3::new(0.0, -G, 0.0));
    let down = Vec3::new(angle.sin(), -angle.cos(), 0.0);
    let rod = w
        .create_body(
            &BodyDef {
                position: down * (0.5 * length),
                orientation: Quat::from_rotation_z(angle),
                mass: MassSpec::Mass(1.0),
                ..Default::default()
            },
            Shape::cuboid(Vec3::new(0.02, 0.5 * length, 0.02)),
        )
        .unwrap();
    let top = Vec3::new(0.0, 0.5 * length, 0.0);
    pin(&mut w, (rod, top), (None, Vec3::ZERO));
    (w, rod)
}

/// The rod's angle from hanging down (rad).
fn rod_angle(w: &World, rod: BodyId) -> Real {
    let c = w.body(rod).unwrap().center_of_mass();
    c.x.atan2(-c.y)
}

#[test]
fn a_reduced_pendulum_swings_with_the_exact_period() {
    // A physical pendulum's period: 2π√(I/(m g d)) · 2K(sin(θ₀/2))/π, I about the pivot
    // = m (L²/3 + w²/12) for the rod's thickness w, d = L/2. Semi-implicit Euler's error
    // in the period is O(h²): under 0.3 % at 60 Hz for every length and amplitude here.
    for (length, amplitude, dt) in [
        (1.0f64, 0.1f64, 1.0f64 / 60.0),
        (0.3, 1.0, 1.0 / 240.0),
        (2.0, 2.5, 1.0 / 60.0),
    ] {
        let (mut w, rod) = rod_pendulum(length as Real, amplitude as Real);
        reduced(&mut w, 1);
        let inertia = length * length / 3.0 + 0.04f64 * 0.04 / 12.0;
        let small = 2.0 * std::f64::consts::PI * (inertia / (G as f64 * 0.5 * length)).sqrt();
        let period = small * 2.0 / std::f64::consts::PI * elliptic_k((0.5 * amplitude).sin());
        let (mut last, mut crossings) = (rod_angle(&w, rod), Vec::new());
        let mut top: Real = 0.0;
        for i in 0..((10.5 * period / dt) as usize) {
            w.step(dt as Real).unwrap();
            let a = rod_angle(&w, rod);
            if last < 0.0 && a >= 0.0 {
                crossings.push((i as f64 + (last / (last - a)) as f64) * dt);
            }
            last = a;
            top = top.max(a.abs());
        }
        let n = crossings.len();
        assert!(n >= 10, "{length} m, {amplitude} rad: {n} swings");
        let measured = (crossings[n - 1] - crossings[0]) / (n - 1) as f64;
        assert!(
            (measured / period - 1.0).abs() < 3e-3,
            "{length} m, {amplitude} rad: period {measured} s, expected {period} s"
        );
        // Symplectic: the amplitude neither grows nor decays.
        assert!(
            (top as f64 - amplitude).abs() < 0.02 * amplitude,
            "{length} m, {amplitude} rad: swings to {top} rad"
        );
        assert!(
            max_joint_gap(&w) < tol(1e-12, 1e-5),
            "gap {}",
            max_joint_gap(&w)
        );
    }
}

/// A chain of `links` boxes hanging from the world along −y, each 0.5 m and 1 kg, hinged
/// about z and x in turn, with a ball of `load` kg hinged to the last; the first link
/// starts turned by `kick` rad/s about z.
fn chain(links: usize, load: Real, kick: Real) -> (World, Vec<BodyId>) {
    let mut w = awake(Vec3::new(0.0, -G, 0.0));
    let mut ids: Vec<BodyId> = Vec::new();
    let half = Vec3::new(0.05, 0.25, 0.05);
    for i in 0..=links {
        let y = -0.5 * i as Real - 0.25;
        let id = if i < links {
            block(&mut w, Vec3::new(0.0, y, 0.0), half, 1.0)
        } else {
            let def = BodyDef {
                position: Vec3::new(0.0, y - 0.25, 0.0),
                mass: MassSpec::Mass(load),
                ..Default::default()
            };
            w.create_body(&def, Shape::sphere(0.2)).unwrap()
        };
        let axis = if i % 2 == 0 { Vec3::Z } else { Vec3::X };
        let anchor = Vec3::new(0.0, if i < links { 0.25 } else { 0.5 }, 0.0);
        let other = ids.last().map(|&p| (Some(p), Vec3::new(0.0, -0.25, 0.0)));
        join(
            &mut w,
            free_hinge(),
            (id, anchor),
            other.unwrap_or((None, Vec3::ZERO)),
            axis,
        );
        ids.push(id);
    }
    w.set_angular_velocity(ids[0], Vec3::new(0.0, 0.0, kick))
        .unwrap();
    (w, ids)
}

#[test]
fn a_reduced_chain_holds_any_load_without_stretching() {
    // The soft step's 20-link chain holding 100× a link's mass stretched 21 mm; a tree in
    // its own coordinates cannot come apart at all (only rounding), whatever the load or
    // the number of links. (The substep must resolve the chain's fastest swing, though:
    // light links under a heavy load swing at ω ~ 2√(m_load g / (m_link l)), 140 rad/s for
    // the 1000 kg case, and semi-implicit Euler needs h ω < 2.)
    for (links, load, dt, substeps) in [
        (20, 100.0, 1.0 / 60.0, 4),
        (5, 1000.0, 1.0 / 60.0, 8),
        (40, 1.0, 1.0 / 120.0, 1),
    ] {
        let (mut w, ids) = chain(links, load, 0.5);
        reduced(&mut w, substeps);
        let bottom = *ids.last().unwrap();
        let length = 0.5 * links as Real + 0.5;
        let mut lowest: Real = 0.0;
        for _ in 0..(2.0 / dt) as usize {
            w.step(dt).unwrap();
            lowest = lowest.min(w.body(bottom).unwrap().center_of_mass().y);
        }
        let gap = max_joint_gap(&w);
        assert!(
            gap < tol(1e-9, 1e-3),
            "{links} links, {load} kg: gap {gap} m"
        );
        assert!(
            lowest >= -length - tol(1e-9, 1e-3),
            "{links} links: ball at {lowest} m"
        );
    }
}

#[test]
fn a_reduced_double_pendulum_keeps_its_energy_and_converges_at_first_order() {
    // Two rods hinged end to end, let go horizontal: chaotic, so the checks are the energy
    // and the order: the error at 0.2 s against a run at h/64 halves as h halves. The
    // energy: semi-implicit Euler in the joint coordinates (MuJoCo's Euler) holds it less
    // well than the soft step with its exact rotor (measured over these 10 s at 240 Hz:
    // 7.7, 2.6 and 0.11 J at 1, 4 and 16 substeps; the soft step 1.7, 0.11 and 0.006 J),
    // so it is checked at 16.
    let build = || {
        let mut w = awake(Vec3::new(0.0, -G, 0.0));
        let half = Vec3::new(0.5, 0.05, 0.05);
        let first = block(&mut w, Vec3::new(0.5, 0.0, 0.0), half, 1.0);
        let second = block(&mut w, Vec3::new(1.5, 0.0, 0.0), half, 2.0);
        let left = Vec3::new(-0.5, 0.0, 0.0);
        pin(&mut w, (first, left), (None, Vec3::ZERO));
        let right = Vec3::new(0.5, 0.0, 0.0);
        pin(&mut w, (second, left), (Some(first), right));
        (w, second)
    };
    let (mut w, _) = build();
    reduced(&mut w, 16);
    let e0 = energy(&w);
    let mut worst: Real = 0.0;
    for _ in 0..2400 {
        w.step(1.0 / 240.0).unwrap();
        worst = worst.max((energy(&w) - e0).abs());
    }
    let scale = G * (0.5 * 1.0 + 1.5 * 2.0);
    assert!(worst < 0.01 * scale, "energy moved {worst} J of {scale} J");
    let at = |dt: Real| {
        let (mut w, tip) = build();
        reduced(&mut w, 1);
        for _ in 0..(0.2 / dt).round() as usize {
            w.step(dt).unwrap();
        }
        w.body(tip).unwrap().center_of_mass()
    };
    let truth = at(0.2 / 6400.0);
    let errors: Vec<Real> = [50.0, 100.0, 200.0]
        .iter()
        .map(|n| (at(0.2 / n) - truth).length())
        .collect();
    for pair in errors.windows(2) {
        let ratio = pair[0] / pair[1];
        assert!(
            (1.6..2.5).contains(&ratio),
            "errors {errors:?}: ratio {ratio}"
        );
    }
}

#[test]
fn the_reduced_and_soft_solvers_agree_as_the_step_shrinks() {
    // A cart on a slider along x carrying a pole on a hinge (the batch bench's
    // cart-pole), pole let go 0.5 rad from upright, one second at 240 Hz: each solver at 4
    // substeps within millimetres of the reduced one at 64 (their errors are O(h), from
    // different schemes).
    let run = |trees: JointTrees, substeps: u32| {
        let mut w = awake(Vec3::new(0.0, 0.0, -G));
        let cart = block(&mut w, Vec3::ZERO, Vec3::new(0.2, 0.1, 0.05), 1.0);
        let tilt = 0.5 as Real;
        let def = BodyDef {
            position: Vec3::new(0.5 * tilt.sin(), 0.0, 0.5 * tilt.cos()),
            orientation: Quat::from_rotation_y(tilt),
            mass: MassSpec::Mass(0.1),
            ..Default::default()
        };
        let pole = w
            .create_body(&def, Shape::cuboid(Vec3::new(0.02, 0.02, 0.5)))
            .unwrap();
        join(
            &mut w,
            free_slider(),
            (cart, Vec3::ZERO),
            (None, Vec3::ZERO),
            Vec3::X,
        );
        let foot = Vec3::new(0.0, 0.0, -0.5);
        join(
            &mut w,
            free_hinge(),
            (pole, foot),
            (Some(cart), Vec3::ZERO),
            Vec3::Y,
        );
        solve_trees(&mut w, trees, substeps);
        for _ in 0..240 {
            w.step(1.0 / 240.0).unwrap();
        }
        [cart, pole].map(|id| w.body(id).unwrap().center_of_mass())
    };
    let truth = run(JointTrees::Reduced, 64);
    let (soft, tree) = (run(JointTrees::Maximal, 4), run(JointTrees::Reduced, 4));
    for ((a, b), t) in soft.iter().zip(&tree).zip(&truth) {
        assert!((*a - *t).length() < 3e-3, "soft {a:?}, truth {t:?}");
        assert!((*b - *t).length() < 3e-3, "reduced {b:?}, truth {t:?}");
    }
    // The cart moved (the pole's fall pushes it): not a test of two resting worlds.
    assert!(tree[0].x.abs() > 0.01, "cart at {:?}", tree[0]);
}

/// Two rods hinged end to end (about z) and a block on a slider (along the second rod)
/// at its end, welded to a ball: every kind a tree takes. `flip` defines the joints
/// between bodies the other way round (`body` the parent).
fn every_kind(flip: bool) -> (World, Vec<BodyId>) {
    let mut w = awake(Vec3::new(0.0, -G, 0.0));
    let half = Vec3::new(0.5, 0.05, 0.05);
    let a = block(&mut w, Vec3::new(0.5, 0.0, 0.0), half, 1.0);
    let b = block(&mut w, Vec3::new(1.5, 0.0, 0.0), half, 2.0);
    let c = block(&mut w, Vec3::new(2.2, 0.0, 0.0), Vec3::splat(0.1), 0.5);
    let d = w
        .create_body(
            &BodyDef {
                position: Vec3::new(2.2, -0.3, 0.0),
                mass: MassSpec::Mass(0.7),
                ..Default::default()
            },
            Shape::sphere(0.15),
        )
        .unwrap();
    let (left, right) = (Vec3::new(-0.5, 0.0, 0.0), Vec3::new(0.5, 0.0, 0.0));
    pin(&mut w, (a, left), (None, Vec3::ZERO));
    let pairs = [
        (free_hinge(), (b, left), (a, right), Vec3::Z),
        (
            free_slider(),
            (c, Vec3::ZERO),
            (b, Vec3::new(0.7, 0.0, 0.0)),
            Vec3::X,
        ),
        (
            JointKind::Fixed,
            (d, Vec3::new(0.0, 0.3, 0.0)),
            (c, Vec3::ZERO),
            Vec3::X,
        ),
    ];
    for (kind, child, parent, axis) in pairs {
        if flip {
            join(&mut w, kind, parent, (Some(child.0), child.1), axis);
        } else {
            join(&mut w, kind, child, (Some(parent.0), parent.1), axis);
        }
    }
    w.set_angular_velocity(a, Vec3::new(0.0, 0.0, 1.5)).unwrap();
    w.set_linear_velocity(c, Vec3::new(0.3, 0.0, 0.0)).unwrap();
    (w, vec![a, b, c, d])
}

#[test]
fn joints_defined_either_way_round_move_the_same() {
    // Which body is a joint's `body` is the user's choice: the tree takes the parent as
    // the one nearer the ground either way, and the motion must not depend on it.
    let run = |flip: bool| {
        let (mut w, ids) = every_kind(flip);
        reduced(&mut w, 2);
        for _ in 0..120 {
            w.step(1.0 / 60.0).unwrap();
        }
        let gap = max_joint_gap(&w);
        assert!(gap < tol(1e-9, 1e-4), "flip {flip}: gap {gap}");
        ids.iter()
            .map(|&id| w.body(id).unwrap().center_of_mass())
            .collect::<Vec<_>>()
    };
    let (one, other) = (run(false), run(true));
    for (a, b) in one.iter().zip(&other) {
        assert!((*a - *b).length() < tol(1e-9, 1e-3), "{a:?} vs {b:?}");
    }
    // It moved: the slider's block slid and the rods swung.
    assert!((one[2] - Vec3::new(2.2, 0.0, 0.0)).length() > 0.5);
}

#[test]
fn a_tree_of_every_kind_matches_the_soft_step_and_keeps_its_energy() {
    // The same tree under both solvers at 16 substeps, half a second at 60 Hz: within a
    // centimetre of each other (first-order schemes of their own, of a chaotic motion),
    // and the reduced one's energy within 1 % of the swing's scale.
    let run = |trees: JointTrees| {
        let (mut w, ids) = every_kind(false);
        solve_trees(&mut w, trees, 16);
        let (e0, mut worst) = (energy(&w), 0.0 as Real);
        for _ in 0..30 {
            w.step(1.0 / 60.0).unwrap();
            worst = worst.max((energy(&w) - e0).abs());
        }
        let at: Vec<Vec3> = ids
            .iter()
            .map(|&id| w.body(id).unwrap().center_of_mass())
            .collect();
        (at, worst)
    };
    let ((soft, _), (tree, worst)) = (run(JointTrees::Maximal), run(JointTrees::Reduced));
    for (a, b) in soft.iter().zip(&tree) {
        assert!((*a - *b).length() < 0.01, "soft {a:?}, reduced {b:?}");
    }
    let scale = G * (0.5 + 3.0 + 1.1 + 1.54);
    assert!(worst < 0.01 * scale, "energy moved {worst} J of {scale} J");
}

#[test]
fn an_armature_adds_to_the_inertia_of_the_swing() {
    // MuJoCo's armature: a hinge's coordinate meets −a q̈, as if its inertia about the
    // axis were I + a. Small swings then take 2π√((I + a)/(m g d)).
    for armature in [0.0 as Real, 0.2, 1.0] {
        let (mut w, rod) = rod_pendulum(1.0, 0.05);
        let (id, _) = w.joints().next().unwrap();
        let mut def = w.joint(id).unwrap().def().clone();
        def.armature = armature;
        w.remove_joint(id).unwrap();
        w.create_joint(&def).unwrap();
        reduced(&mut w, 8);
        let inertia = 1.0 / 3.0 + 0.04 * 0.04 / 12.0 + armature as f64;
        let period = 2.0 * std::f64::consts::PI * (inertia / (G as f64 * 0.5)).sqrt();
        let (dt, mut last, mut crossings) = (1.0 / 120.0, rod_angle(&w, rod), Vec::new());
        for i in 0..((6.5 * period / dt) as usize) {
            w.step(dt as Real).unwrap();
            let a = rod_angle(&w, rod);
            if last < 0.0 && a >= 0.0 {
                crossings.push((i as f64 + (last / (last - a)) as f64) * dt);
            }
            last = a;
        }
        let n = crossings.len();
        let measured = (crossings[n - 1] - crossings[0]) / (n - 1) as f64;
        assert!(
            (measured / period - 1.0).abs() < 2e-3,
            "armature {armature}: period {measured} s, expected {period} s"
        );
    }
}

#[test]
fn reaction_forces_are_the_soft_steps() {
    // A rod let go 1 rad from hanging: each step the joint's reported force on the world
    // and torque under both solvers, at 16 substeps (both converge to the same force),
    // within 1 % of the weight; hanging still, exactly the weight.
    let run = |trees: JointTrees, angle: Real| {
        let (mut w, _) = rod_pendulum(1.0, angle);
        solve_trees(&mut w, trees, 16);
        (0..30)
            .map(|_| {
                w.step(1.0 / 60.0).unwrap();
                let j = w.joints().next().unwrap().1;
                (j.reaction_force(), j.reaction_torque())
            })
            .collect::<Vec<_>>()
    };
    let (soft, tree) = (run(JointTrees::Maximal, 1.0), run(JointTrees::Reduced, 1.0));
    for ((fs, ts), (ft, tt)) in soft.iter().zip(&tree) {
        assert!(
            (*fs - *ft).length() < 0.01 * G,
            "force: soft {fs:?}, reduced {ft:?}"
        );
        assert!(
            (*ts - *tt).length() < 0.01 * G,
            "torque: soft {ts:?}, reduced {tt:?}"
        );
    }
    let still = run(JointTrees::Reduced, 0.0);
    let (f, t) = still[29];
    assert!(
        (f - Vec3::new(0.0, -G, 0.0)).length() < tol(1e-9, 1e-4),
        "force {f:?}"
    );
    assert!(t.length() < tol(1e-9, 1e-4), "torque {t:?}");
}

/// State hashes of `n` steps of 1/60 s of the world `build` makes, under `trees`.
fn hashes(build: &dyn Fn() -> World, trees: JointTrees, n: usize) -> Vec<u64> {
    let mut w = build();
    let substeps = w.solver_settings().substeps;
    solve_trees(&mut w, trees, substeps);
    (0..n)
        .map(|_| {
            w.step(1.0 / 60.0).unwrap();
            w.state_hash()
        })
        .collect()
}

#[test]
fn what_is_not_a_free_tree_is_solved_by_the_soft_step_bit_for_bit() {
    // Limits, motors, springs and servos, ball joints' cones, loops, kinematic parents
    // and trees resting in contact are the soft step's: choosing reduced trees must not
    // change their motion by a bit.
    let pendulum_with = |kind: JointKind| {
        move || {
            let mut w = awake_on_ground(Vec3::new(0.0, -G, 0.0));
            let rod = block(
                &mut w,
                Vec3::new(0.5, 2.0, 0.0),
                Vec3::new(0.5, 0.05, 0.05),
                1.0,
            );
            let left = Vec3::new(-0.5, 0.0, 0.0);
            join(
                &mut w,
                kind,
                (rod, left),
                (None, Vec3::new(0.0, 2.0, 0.0)),
                Vec3::Z,
            );
            w
        }
    };
    let limited = JointKind::Hinge {
        limits: Some([-0.5, 0.5]),
        motor: None,
        spring: None,
        servo: None,
    };
    let motor = JointKind::Hinge {
        limits: None,
        motor: Some(Motor {
            speed: 1.0,
            max_force: 5.0,
        }),
        spring: None,
        servo: None,
    };
    let ball = JointKind::Ball {
        cone: Some(0.5),
        twist: None,
    };
    type Build = Box<dyn Fn() -> World>;
    let cases: Vec<(&str, Build)> = vec![
        ("limits", Box::new(pendulum_with(limited))),
        ("motor", Box::new(pendulum_with(motor))),
        ("ball with a cone", Box::new(pendulum_with(ball))),
        (
            "loop",
            Box::new(|| {
                // A bar hinged to the world at both ends.
                let mut w = awake(Vec3::new(0.0, -G, 0.0));
                let bar = block(&mut w, Vec3::ZERO, Vec3::new(0.5, 0.05, 0.05), 1.0);
                for x in [-0.5 as Real, 0.5] {
                    let at = Vec3::new(x, 0.0, 0.0);
                    pin(&mut w, (bar, at), (None, at));
                }
                w.set_angular_velocity(bar, Vec3::new(0.0, 0.0, 1.0))
                    .unwrap();
                w
            }),
        ),
        (
            "kinematic parent",
            Box::new(|| {
                let mut w = awake(Vec3::new(0.0, -G, 0.0));
                let def = BodyDef {
                    kind: BodyKind::Kinematic,
                    angular_velocity: Vec3::new(0.0, 0.0, 2.0),
                    ..Default::default()
                };
                let hub = w.create_body(&def, Shape::sphere(0.1)).unwrap();
                let rod = block(
                    &mut w,
                    Vec3::new(0.5, 0.0, 0.0),
                    Vec3::new(0.5, 0.05, 0.05),
                    1.0,
                );
                let left = Vec3::new(-0.5, 0.0, 0.0);
                pin(&mut w, (rod, left), (Some(hub), Vec3::ZERO));
                w
            }),
        ),
        (
            "resting on the ground",
            Box::new(|| {
                // A rod hinged at its end at floor height, lying on the floor.
                let mut w = awake_on_ground(Vec3::new(0.0, -G, 0.0));
                let rod = block(
                    &mut w,
                    Vec3::new(0.5, 0.05, 0.0),
                    Vec3::new(0.5, 0.05, 0.05),
                    1.0,
                );
                let left = Vec3::new(-0.5, 0.0, 0.0);
                let at = Vec3::new(0.0, 0.05, 0.0);
                pin(&mut w, (rod, left), (None, at));
                w
            }),
        ),
    ];
    for (name, build) in &cases {
        let soft = hashes(build.as_ref(), JointTrees::Maximal, 90);
        let tree = hashes(build.as_ref(), JointTrees::Reduced, 90);
        assert_eq!(soft, tree, "{name}");
    }
    // And a free tree is not solved by the soft step (else the above proves nothing).
    let free = pendulum_with(free_hinge());
    let (soft, tree) = (
        hashes(&free, JointTrees::Maximal, 10),
        hashes(&free, JointTrees::Reduced, 10),
    );
    assert_ne!(soft, tree);
}

#[test]
fn a_pendulum_hitting_the_floor_is_handed_to_the_soft_step_and_back() {
    // A rod hinged 0.8 m above the floor, let go horizontal: its free end strikes the
    // floor, the soft step takes the tree for the steps it touches, and the rod bounces
    // back no higher than it fell (no energy made at the hand-overs) and stays on its
    // joint: the gap in the contact steps is the soft step's (1.7 mm at the impact, as
    // with the soft step throughout).
    let mut w = awake_on_ground(Vec3::new(0.0, -G, 0.0));
    let rod = block(
        &mut w,
        Vec3::new(0.5, 0.8, 0.0),
        Vec3::new(0.5, 0.05, 0.05),
        1.0,
    );
    let left = Vec3::new(-0.5, 0.0, 0.0);
    pin(&mut w, (rod, left), (None, Vec3::new(0.0, 0.8, 0.0)));
    reduced(&mut w, 4);
    let e = |w: &World| {
        let b = w.body(rod).unwrap();
        b.kinetic_energy() + b.mass() * G * b.center_of_mass().y
    };
    let e0 = e(&w);
    for _ in 0..240 {
        w.step(1.0 / 60.0).unwrap();
        // Semi-implicit Euler's own swing of the energy, O(h), is 0.2 % here.
        assert!(e(&w) < 1.005 * e0, "energy {} J from {e0} J", e(&w));
        assert!(max_joint_gap(&w) < 2.5e-3, "gap {}", max_joint_gap(&w));
    }
    let lowest = w
        .body(rod)
        .unwrap()
        .pose()
        .transform_point(Vec3::new(0.5, -0.05, 0.0));
    assert!(
        lowest.y > -0.01,
        "the rod's end went {} m into the floor",
        -lowest.y
    );
}

#[test]
fn snapshots_setters_and_static_grounds_work_with_reduced_trees() {
    // A restored snapshot continues bit for bit (the trees keep nothing between steps).
    let build = || {
        let (mut w, _) = every_kind(false);
        reduced(&mut w, 2);
        w
    };
    let mut w = build();
    run(&mut w, 1.0 / 60.0, 40);
    let snap = w.snapshot();
    let first: Vec<u64> = (0..40)
        .map(|_| {
            w.step(1.0 / 60.0).unwrap();
            w.state_hash()
        })
        .collect();
    let mut resumed = build();
    resumed.restore(&snap).unwrap();
    let second: Vec<u64> = (0..40)
        .map(|_| {
            resumed.step(1.0 / 60.0).unwrap();
            resumed.state_hash()
        })
        .collect();
    assert_eq!(first, second);
    // A body moved off its joint by a setter is put back on it by the next step.
    let (mut w, ids) = every_kind(false);
    reduced(&mut w, 1);
    w.set_position(ids[1], Vec3::new(3.0, 1.0, 0.5)).unwrap();
    w.step(1.0 / 60.0).unwrap();
    assert!(
        max_joint_gap(&w) < tol(1e-9, 1e-4),
        "gap {}",
        max_joint_gap(&w)
    );
    // A static body, turned and moved, is ground as the world is: the same pendulum
    // hung from it swings exactly as one hung from the world there.
    let hang = |from_static: bool| {
        let mut w = awake(Vec3::new(0.0, -G, 0.0));
        let pivot = Vec3::new(1.0, 2.0, -0.5);
        let rod = block(
            &mut w,
            pivot + Vec3::new(0.5, 0.0, 0.0),
            Vec3::new(0.5, 0.05, 0.05),
            1.0,
        );
        let left = Vec3::new(-0.5, 0.0, 0.0);
        if from_static {
            let turn = Quat::from_rotation_y(0.7);
            let def = BodyDef {
                kind: BodyKind::Static,
                position: pivot,
                orientation: turn,
                ..Default::default()
            };
            let beam = w.create_body(&def, Shape::sphere(0.05)).unwrap();
            let mut d = JointDef::new(free_hinge(), rod);
            (d.anchor, d.axis) = (left, Vec3::Z);
            (d.other, d.other_anchor, d.other_axis) =
                (Some(beam), Vec3::ZERO, turn.inverse() * Vec3::Z);
            w.create_joint(&d).unwrap();
        } else {
            pin(&mut w, (rod, left), (None, pivot));
        }
        reduced(&mut w, 1);
        run(&mut w, 1.0 / 60.0, 60);
        (w.body(rod).unwrap().center_of_mass(), max_joint_gap(&w))
    };
    let ((a, gap), (b, _)) = (hang(true), hang(false));
    assert!((a - b).length() < tol(1e-9, 1e-4), "{a:?} vs {b:?}");
    assert!(gap < tol(1e-9, 1e-4), "gap {gap}");
}

#[test]
fn forces_torques_damping_and_break_forces_act_on_reduced_trees() {
    // A 2 kg cart on a slider pushed by 3 N, no gravity: semi-implicit Euler's
    // x_n = (F/m) h² n(n+1)/2 exactly.
    let mut w = awake(Vec3::ZERO);
    let cart = block(&mut w, Vec3::ZERO, Vec3::splat(0.1), 2.0);
    join(
        &mut w,
        free_slider(),
        (cart, Vec3::ZERO),
        (None, Vec3::ZERO),
        Vec3::X,
    );
    let push = AppliedForce {
        body: cart,
        force: Vec3::new(3.0, 1.0, 0.0), // the y part is the slider's to hold
        point: None,
        torque: Vec3::new(0.0, 0.0, 5.0), // so is any torque
    };
    w.add_force(Force::Applied(push)).unwrap();
    reduced(&mut w, 1);
    let h = 0.01 as Real;
    for n in 1..=100 {
        w.step(h).unwrap();
        let x = w.body(cart).unwrap().center_of_mass();
        let expect = 1.5 * h * h * (n * (n + 1)) as Real / 2.0;
        assert!(
            (x - Vec3::new(expect, 0.0, 0.0)).length() < tol(1e-12, 1e-5),
            "step {n}: {x:?}"
        );
    }
    // A wheel on a hinge (no gravity) spun by a torque then slowed by its angular
    // damping c: ω̇ = τ/I − c ω, so ω → τ/(c I).
    let mut w = awake(Vec3::ZERO);
    let def = BodyDef {
        mass: MassSpec::Mass(3.0),
        angular_damping: 0.5,
        ..Default::default()
    };
    let wheel = w.create_body(&def, Shape::sphere(0.5)).unwrap();
    pin(&mut w, (wheel, Vec3::ZERO), (None, Vec3::ZERO));
    let spin = AppliedForce {
        body: wheel,
        force: Vec3::ZERO,
        point: None,
        torque: Vec3::new(0.0, 0.0, 0.6),
    };
    w.add_force(Force::Applied(spin)).unwrap();
    reduced(&mut w, 4);
    run(&mut w, 1.0 / 60.0, 60 * 30);
    let inertia = 0.4 * 3.0 * 0.25;
    let omega = w.body(wheel).unwrap().angular_velocity();
    let expect = 0.6 / (0.5 * inertia);
    assert!(
        (omega.z / expect - 1.0).abs() < 1e-3,
        "ω {omega:?}, expected {expect}"
    );
    // A joint whose load passes its break force breaks, and the body then falls free.
    let (mut w, rod) = rod_pendulum(1.0, 0.0);
    let (id, _) = w.joints().next().unwrap();
    let mut def = w.joint(id).unwrap().def().clone();
    def.break_force = Some(0.5 * G);
    w.remove_joint(id).unwrap();
    let id = w.create_joint(&def).unwrap();
    reduced(&mut w, 1);
    run(&mut w, 1.0 / 60.0, 30);
    assert!(w.joint(id).unwrap().is_broken());
    assert!(w.body(rod).unwrap().center_of_mass().y < -1.0);
}

#[test]
fn trees_are_found_again_after_every_edit_of_the_joints() {
    // The trees are kept from step to step while the joints and the bodies' kinds stay
    // as they were. After each edit, a world stepped on must equal one restored from its
    // snapshot (which starts with nothing kept): it fails if a kept tree outlives an edit.
    let (mut w, ids) = every_kind(false);
    reduced(&mut w, 2);
    let hashes = |w: &mut World| -> Vec<u64> {
        (0..5)
            .map(|_| {
                w.step(1.0 / 60.0).unwrap();
                w.state_hash()
            })
            .collect()
    };
    hashes(&mut w);
    let joints: Vec<JointId> = w.joints().map(|(id, _)| id).collect();
    type Edit = Box<dyn Fn(&mut World)>;
    let (first, second, slide) = (joints[0], joints[1], joints[2]);
    let edits: Vec<(&str, Edit)> = vec![
        (
            "limits",
            Box::new(move |w| w.set_joint_limits(second, Some([-0.2, 0.2])).unwrap()),
        ),
        (
            "no limits",
            Box::new(move |w| w.set_joint_limits(second, None).unwrap()),
        ),
        (
            "armature",
            Box::new(move |w| w.set_joint_armature(first, 0.3).unwrap()),
        ),
        (
            "disabled",
            Box::new(move |w| w.set_joint_enabled(slide, false).unwrap()),
        ),
        (
            "enabled",
            Box::new(move |w| w.set_joint_enabled(slide, true).unwrap()),
        ),
        (
            "made again elsewhere",
            Box::new(move |w| {
                let mut def = w.joint(second).unwrap().def().clone();
                w.remove_joint(second).unwrap();
                def.other_anchor = Vec3::new(0.3, 0.0, 0.0);
                w.create_joint(&def).unwrap();
            }),
        ),
        (
            "body removed",
            Box::new(move |w| w.remove_body(ids[3]).unwrap()),
        ),
    ];
    for (name, edit) in &edits {
        edit(&mut w);
        let mut fresh = every_kind(false).0;
        fresh.restore(&w.snapshot()).unwrap();
        assert_eq!(hashes(&mut w), hashes(&mut fresh), "after {name}");
    }
}

#[test]
fn a_tree_in_contact_beside_a_free_one_is_the_soft_steps_alone() {
    // Two rods hinged to the world: one lying on the floor (in contact every step, so
    // the soft step's), one swinging free above it (the trees'). The resting one must
    // move exactly as in a world without reduced trees, its joint's reaction and
    // impulses untouched by the free tree's hand-back.
    let build = || {
        let mut w = awake_on_ground(Vec3::new(0.0, -G, 0.0));
        let half = Vec3::new(0.5, 0.05, 0.05);
        let lying = block(&mut w, Vec3::new(0.5, 0.05, 0.0), half, 1.0);
        let left = Vec3::new(-0.5, 0.0, 0.0);
        pin(&mut w, (lying, left), (None, Vec3::new(0.0, 0.05, 0.0)));
        let swinging = block(&mut w, Vec3::new(0.5, 3.0, 2.0), half, 1.0);
        pin(&mut w, (swinging, left), (None, Vec3::new(0.0, 3.0, 2.0)));
        (w, lying)
    };
    let run = |trees: JointTrees| {
        let (mut w, lying) = build();
        let substeps = w.solver_settings().substeps;
        solve_trees(&mut w, trees, substeps);
        (0..60)
            .map(|_| {
                w.step(1.0 / 60.0).unwrap();
                let b = w.body(lying).unwrap();
                let j = w.joints().next().unwrap().1;
                (
                    b.center_of_mass(),
                    b.orientation(),
                    j.reaction_force(),
                    j.reaction_torque(),
                )
            })
            .collect::<Vec<_>>()
    };
    assert_eq!(run(JointTrees::Maximal), run(JointTrees::Reduced));
}

/// A chain of `links` boxes on ball joints hung from the world, bent out of plane and
/// spun, so that every joint turns about all three axes. `flip` defines the joints
/// between links with the parent as `body`.
fn ball_chain(links: usize, flip: bool) -> (World, Vec<BodyId>) {
    let mut w = awake(Vec3::new(0.0, -G, 0.0));
    let ball = JointKind::Ball {
        cone: None,
        twist: None,
    };
    let half = Vec3::new(0.05, 0.25, 0.08);
    let mut ids: Vec<BodyId> = Vec::new();
    for i in 0..links {
        let y = -0.5 * i as Real - 0.25;
        let id = block(
            &mut w,
            Vec3::new(0.1 * i as Real, y, 0.0),
            half,
            1.0 + i as Real,
        );
        let top = Vec3::new(0.0, 0.25, 0.0);
        match ids.last() {
            None => {
                join(&mut w, ball, (id, top), (None, Vec3::ZERO), Vec3::X);
            }
            Some(&p) => {
                let at = w.body(id).unwrap().pose().transform_point(top);
                let on_parent = w.body(p).unwrap().pose().inverse_transform_point(at);
                if flip {
                    join(&mut w, ball, (p, on_parent), (Some(id), top), Vec3::X);
                } else {
                    join(&mut w, ball, (id, top), (Some(p), on_parent), Vec3::X);
                }
            }
        }
        w.set_angular_velocity(id, Vec3::new(0.5, 1.0 - i as Real, 0.3 * i as Real))
            .unwrap();
        ids.push(id);
    }
    (w, ids)
}

#[test]
fn ball_joints_turn_freely_and_exactly_either_way_round() {
    // Ball joints (without a cone or twist) are three freedoms of a tree: the chain keeps
    // its anchors together to rounding, moves the same whichever body each joint names
    // first, agrees with the soft step at fine substeps, and keeps its energy.
    let run = |flip: bool, trees: JointTrees, substeps: u32| {
        let (mut w, ids) = ball_chain(4, flip);
        solve_trees(&mut w, trees, substeps);
        let (e0, mut worst) = (energy(&w), 0.0 as Real);
        for _ in 0..30 {
            w.step(1.0 / 60.0).unwrap();
            worst = worst.max((energy(&w) - e0).abs());
        }
        let at: Vec<Vec3> = ids
            .iter()
            .map(|&id| w.body(id).unwrap().center_of_mass())
            .collect();
        (at, max_joint_gap(&w), worst)
    };
    let (one, gap, _) = run(false, JointTrees::Reduced, 4);
    let (other, gap_flipped, _) = run(true, JointTrees::Reduced, 4);
    assert!(
        gap.max(gap_flipped) < tol(1e-9, 1e-4),
        "gaps {gap}, {gap_flipped}"
    );
    for (a, b) in one.iter().zip(&other) {
        assert!((*a - *b).length() < tol(1e-9, 1e-3), "{a:?} vs {b:?}");
    }
    let (soft, _, _) = run(false, JointTrees::Maximal, 16);
    let (tree, _, worst) = run(false, JointTrees::Reduced, 16);
    for (a, b) in soft.iter().zip(&tree) {
        assert!((*a - *b).length() < 0.01, "soft {a:?}, reduced {b:?}");
    }
    // It moved, about more than one axis.
    assert!(tree[3].z.abs() > 0.005, "{:?}", tree[3]);
    let scale = G * 10.0 * 1.0;
    assert!(worst < 0.01 * scale, "energy moved {worst} J of {scale} J");
}
