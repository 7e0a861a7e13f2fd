//! Joint trees solved in reduced coordinates (`SolverSettings::joint_trees` = `Reduced`,
//! `dynamics/solver/articulation.rs`), against closed forms, against the soft step where
//! both converge, and for what must fall back to the soft step unchanged.

// Casts between Real and f64 are no-ops in the default build but needed in the f32 one.
#![allow(clippy::unnecessary_cast)]

use crate::common::*;
use tumble::prelude::*;

const G: Real = 9.81;

/// `w` with its joint trees solved in reduced coordinates, at `substeps` a step.
fn reduced(w: &mut World, substeps: u32) {
    w.set_solver_settings(SolverSettings {
        joint_trees: JointTrees::Reduced,
        substeps,
        ..w.solver_settings()
    })
    .unwrap();
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
    join(
        &mut w,
        free_hinge(),
        (rod, top),
        (None, Vec3::ZERO),
        Vec3::Z,
    );
    (w, rod)
}

/// The rod's angle from hanging down (rad).
fn rod_angle(w: &World, rod: BodyId) -> Real {
    let c = w.body(rod).unwrap().center_of_mass();
    c.x.atan2(-c.y)
}

/// Complete elliptic integral of the first kind K(k), by the arithmetic–geometric mean.
fn elliptic_k(k: f64) -> f64 {
    let (mut a, mut b) = (1.0f64, (1.0 - k * k).sqrt());
    for _ in 0..30 {
        (a, b) = (0.5 * (a + b), (a * b).sqrt());
    }
    std::f64::consts::PI / (2.0 * a)
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
        join(
            &mut w,
            free_hinge(),
            (first, left),
            (None, Vec3::ZERO),
            Vec3::Z,
        );
        let right = Vec3::new(0.5, 0.0, 0.0);
        join(
            &mut w,
            free_hinge(),
            (second, left),
            (Some(first), right),
            Vec3::Z,
        );
        (w, second)
    };
    let energy = |w: &World| {
        w.bodies()
            .map(|(_, b)| b.kinetic_energy() + b.mass() * G * b.center_of_mass().y)
            .sum::<Real>()
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
        w.set_solver_settings(SolverSettings {
            joint_trees: trees,
            substeps,
            ..w.solver_settings()
        })
        .unwrap();
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
