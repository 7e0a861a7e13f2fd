//! Run-time setters of body properties (friction, restitution, collision filter, gravity
//! scale) against closed forms: each acts from the next step, wakes what it touches, and
//! is refused with the scene loader's message, changing nothing, on a bad value.

// Casts between Real and f64 are no-ops in the default build but needed in the f32 one.
#![allow(clippy::unnecessary_cast)]

use crate::common::*;
use tumble::prelude::*;

const G: Real = 9.8;

/// A cube of half extent `half` on the ground at x = 0, both of friction `mu` (a pair
/// uses √(μ_a μ_b) = μ), sliding along +x at `v0`.
fn slider(w: &mut World, half: Real, mu: Real, v0: Real) -> BodyId {
    let floor = w.body_ids()[0];
    w.set_friction(floor, mu).unwrap();
    let def = BodyDef {
        position: Vec3::new(0.0, half, 0.0),
        linear_velocity: Vec3::new(v0, 0.0, 0.0),
        friction: mu,
        ..Default::default()
    };
    w.create_body(&def, Shape::cuboid(Vec3::splat(half)))
        .unwrap()
}

/// Mid-slide, friction set to 0: the box slows at μ g before and keeps its speed after.
/// Deceleration measured over 0.3 s after a settling step, within 1 % of μ g before; after,
/// less than 1 % of μ g (Coulomb sliding is exact in the solver; the residue is rounding and
/// the box's rocking on its front edge).
#[test]
fn friction_set_to_zero_mid_slide_stops_the_deceleration() {
    for (half, mu, dt) in [(0.25, 0.3, 1.0 / 60.0), (0.1, 0.6, 1.0 / 240.0)] {
        let mut w = awake_on_ground(Vec3::new(0.0, -G, 0.0));
        let id = slider(&mut w, half, mu, 6.0);
        let speed = |w: &World| w.body(id).unwrap().linear_velocity().x;
        let steps = |t: Real| (t / dt).round() as usize;
        run(&mut w, dt, steps(0.1));
        let v1 = speed(&w);
        run(&mut w, dt, steps(0.3));
        let v2 = speed(&w);
        let before = (v1 - v2) / (steps(0.3) as Real * dt);
        assert!(
            ((before - mu * G) / (mu * G)).abs() < 0.01,
            "μ = {mu}: deceleration {before} vs μ g = {}",
            mu * G
        );
        w.set_friction(id, 0.0).unwrap();
        assert_eq!(w.body(id).unwrap().friction(), 0.0);
        run(&mut w, dt, steps(0.5));
        let after = (v2 - speed(&w)) / (steps(0.5) as Real * dt);
        assert!(
            after.abs() < 0.01 * mu * G,
            "μ = {mu}: still slowing at {after}"
        );
    }
}

/// The height of the first rebound (of the ball's bottom over the ground), read from the
/// energy in free flight just after the bounce, y + v²/2g, as `contact_dynamics.rs` does.
fn rebound(w: &mut World, id: BodyId, r: Real, dt: Real) -> Real {
    let mut bounced = false;
    for _ in 0..(3.0 / dt) as usize {
        w.step(dt).unwrap();
        let b = w.body(id).unwrap();
        let (y, vy) = (b.position().y - r, b.linear_velocity().y);
        bounced |= vy > 0.0;
        if bounced && vy > 0.0 && y > 0.05 {
            return y + vy * vy / (2.0 * G);
        }
    }
    0.0
}

/// Restitution changed between two drops from h: the rebound reaches e² h, for the old
/// e and then the new ones, within 2 % (the tolerance of `contact_dynamics.rs`'s drop
/// test: the impact falls between steps and meets the soft contact).
#[test]
fn restitution_set_between_drops_changes_the_rebound_to_e_squared_h() {
    let (r, h, dt) = (0.1, 1.0, 1.0 / 240.0);
    let mut w = awake_on_ground(Vec3::new(0.0, -G, 0.0));
    let def = BodyDef {
        position: Vec3::new(0.0, r + h, 0.0),
        restitution: 0.5,
        ..Default::default()
    };
    let id = w.create_body(&def, Shape::sphere(r)).unwrap();
    for e in [0.5, 0.8, 0.3] {
        w.set_restitution(id, e).unwrap();
        w.set_position(id, Vec3::new(0.0, r + h, 0.0)).unwrap();
        w.set_linear_velocity(id, Vec3::ZERO).unwrap();
        w.set_angular_velocity(id, Vec3::ZERO).unwrap();
        let apex = rebound(&mut w, id, r, dt);
        let expected = e * e * h;
        assert!(
            ((apex - expected) / expected).abs() < 0.02,
            "e = {e}: rebound {apex} vs e² h = {expected}"
        );
    }
}

/// A ball asleep on the ground, its mask set to nothing: woken by the edit, it falls
/// through the ground as in free fall (y = r − ½ g t², symplectic Euler's
/// −g dt² n(n+1)/2 exactly); its mask set back before it reaches a second floor below, it
/// lands on that one (a pair the new filter allows starts colliding).
#[test]
fn collision_mask_change_lets_a_body_through_and_back() {
    let (r, dt) = (0.1, 1.0 / 60.0);
    let mut w = World::new(&WorldDef::default());
    let ground = BodyDef {
        kind: BodyKind::Static,
        collision_group: 2,
        ..Default::default()
    };
    w.create_body(&ground, Shape::plane(Vec3::Y, 0.0)).unwrap();
    let lower = BodyDef {
        kind: BodyKind::Static,
        position: Vec3::new(0.0, -3.0, 0.0),
        collision_group: 4,
        ..Default::default()
    };
    w.create_body(&lower, Shape::cuboid(Vec3::new(2.0, 0.5, 2.0)))
        .unwrap();
    let id = ball(&mut w, Vec3::new(0.0, r, 0.0));
    run(&mut w, dt, 180);
    assert!(!w.body(id).unwrap().is_awake(), "the ball should sleep");
    w.set_collision_filter(id, 1, !2).unwrap();
    assert!(w.body(id).unwrap().is_awake(), "the edit wakes the ball");
    assert_eq!(w.body(id).unwrap().collision_filter(), (1, !2));
    let n = 30;
    let y0 = w.body(id).unwrap().position().y;
    run(&mut w, dt, n);
    let fall = G * dt * dt * (n * (n + 1)) as Real / 2.0;
    let y = w.body(id).unwrap().position().y;
    assert!(
        (y - (y0 - fall)).abs() < tol(1e-9, 1e-4),
        "y = {y}, free fall to {}",
        y0 - fall
    );
    // Through the ground, on towards the lower floor (top at y = -2.5) with its layer
    // masked out too, then allowed again before the ball gets there: it lands.
    w.set_collision_filter(id, 1, !(2 | 4)).unwrap();
    run(&mut w, dt, 5);
    assert!(w.body(id).unwrap().position().y > -2.0);
    w.set_collision_filter(id, 1, !2).unwrap();
    run(&mut w, dt, 240);
    let y = w.body(id).unwrap().position().y;
    assert!(
        (y - (-2.5 + r)).abs() < 0.01,
        "the ball should rest on the lower floor, y = {y}"
    );
}

/// A mask that excludes the ground from the start: the ball falls through; the same ball
/// with the mask restored mid-air (above the ground) lands.
#[test]
fn collision_filter_restored_mid_air_makes_the_pair_collide() {
    let (r, dt) = (0.1, 1.0 / 120.0);
    let mut w = awake_on_ground(Vec3::new(0.0, -G, 0.0));
    let id = ball(&mut w, Vec3::new(0.0, 1.0, 0.0));
    w.set_collision_filter(id, 1, 0).unwrap();
    run(&mut w, dt, 30);
    w.set_collision_filter(id, 1, u32::MAX).unwrap();
    run(&mut w, dt, 240);
    let y = w.body(id).unwrap().position().y;
    assert!((y - r).abs() < 0.01, "should rest on the ground, y = {y}");
    w.set_collision_filter(id, 0, u32::MAX).unwrap();
    run(&mut w, dt, 60);
    let y = w.body(id).unwrap().position().y;
    assert!(
        y < -1.0,
        "group 0 meets no mask: should fall through, y = {y}"
    );
}

/// A gravity scale s multiplies the fall: s = 0.5 gives exactly half of s = 1's velocity
/// and drop (to rounding: g (m s) / m against g), with every integrator; s = 0 floats,
/// s = −1 rises as the other falls; the energy, with the potential m s g h, is conserved
/// by velocity Verlet to rounding (constant forces).
#[test]
fn gravity_scale_scales_the_fall() {
    let dt = 1.0 / 100.0;
    for integrator in Integrator::ALL {
        let mut w = world(Vec3::new(0.0, -G, 0.0), integrator);
        let ids: Vec<BodyId> = [1.0, 0.5, 0.0, -1.0]
            .iter()
            .enumerate()
            .map(|(k, &s)| {
                let def = BodyDef {
                    position: Vec3::new(k as Real, 10.0, 0.0),
                    mass: MassSpec::Mass(1.0 + k as Real),
                    gravity_scale: s,
                    ..Default::default()
                };
                w.create_body(&def, Shape::sphere(0.1)).unwrap()
            })
            .collect();
        let e0 = w.diagnostics().total;
        run(&mut w, dt, 100);
        let state = |k: usize| {
            let b = w.body(ids[k]).unwrap();
            (b.linear_velocity().y, b.position().y - 10.0)
        };
        let (v1, d1) = state(0);
        // f32: Störmer–Verlet's velocity is (x₊ − x)/dt, rounded to ulp(10 m)/dt ≈ 1e-4
        // m/s each step (measured 2e-4 relative after 100 steps); the others 1e-5.
        let eps = tol(1e-12, 1e-3);
        for (k, s) in [(1, 0.5), (2, 0.0), (3, -1.0)] {
            let (v, d) = state(k);
            assert!(
                (v - s * v1).abs() <= eps * v1.abs(),
                "{}: s = {s}: v {v} vs {}",
                integrator.name(),
                s * v1
            );
            assert!(
                (d - s * d1).abs() <= eps * d1.abs(),
                "{}: s = {s}: drop {d} vs {}",
                integrator.name(),
                s * d1
            );
        }
        assert!(
            (v1 + G).abs() < 0.01 * G,
            "{}: v after 1 s = {v1}",
            integrator.name()
        );
        if integrator == Integrator::VelocityVerlet {
            let e = w.diagnostics().total;
            assert!(
                (e - e0).abs() < tol(1e-9, 1e-2) * e0.abs().max(1.0),
                "energy {e0} -> {e}"
            );
        }
    }
}

/// In contact, the solver kicks with the scaled gravity: a ball resting on the ground
/// given a scale of −1 lifts off and rises as ½ g t² (within g dt² per step of travel).
#[test]
fn gravity_scale_set_at_run_time_acts_in_contact() {
    let (r, dt) = (0.1, 1.0 / 120.0);
    let mut w = awake_on_ground(Vec3::new(0.0, -G, 0.0));
    let id = ball(&mut w, Vec3::new(0.0, r, 0.0));
    run(&mut w, dt, 60);
    let y0 = w.body(id).unwrap().position().y;
    assert!((y0 - r).abs() < 0.005, "resting, y = {y0}");
    w.set_gravity_scale(id, -1.0).unwrap();
    let n = 60;
    run(&mut w, dt, n);
    let t = n as Real * dt;
    let rise = w.body(id).unwrap().position().y - y0;
    assert!(
        (rise - 0.5 * G * t * t).abs() < 0.02 * 0.5 * G * t * t,
        "rose {rise} vs {}",
        0.5 * G * t * t
    );
}

/// Bad values are refused with the loader's messages, and nothing changes.
#[test]
fn bad_values_are_refused_and_change_nothing() {
    let mut w = awake_on_ground(Vec3::new(0.0, -G, 0.0));
    let id = ball(&mut w, Vec3::new(0.0, 1.0, 0.0));
    let before = (w.state_hash(), w.body(id).unwrap().friction());
    let cases: [(tumble::Result<()>, &str); 7] = [
        (w.set_friction(id, -1.0), "friction: must be >= 0"),
        (
            w.set_friction(id, Real::INFINITY),
            "friction: must be a finite number",
        ),
        (w.set_restitution(id, 1.5), "restitution: must be <= 1"),
        (w.set_restitution(id, -0.1), "restitution: must be >= 0"),
        (
            w.set_gravity_scale(id, Real::NAN),
            "gravity_scale: must be a finite number",
        ),
        (
            w.set_gravity_scale(id, 2e6),
            "gravity_scale: must be at most",
        ),
        (
            w.set_kinematic_target(id, Vec3::ZERO, Quat::IDENTITY),
            "kind: a kinematic target needs a kinematic body",
        ),
    ];
    for (result, message) in cases {
        let e = result.unwrap_err();
        assert!(
            e.to_string().starts_with(message),
            "{e} (expected {message})"
        );
    }
    let b = w.body(id).unwrap();
    assert_eq!((b.restitution(), b.gravity_scale()), (0.0, 1.0));
    assert_eq!(before, (w.state_hash(), b.friction()));
    let bad = BodyDef {
        gravity_scale: Real::NAN,
        ..Default::default()
    };
    let e = w.create_body(&bad, Shape::sphere(0.1)).unwrap_err();
    assert_eq!(e.to_string(), "gravity_scale: must be a finite number");
    w.remove_body(id).unwrap();
    let e = w.set_friction(id, 0.5).unwrap_err();
    assert_eq!(e.field(), "body");
}

/// Every setter wakes the body it edits (and what rests on it).
#[test]
fn setters_wake_the_body() {
    let mut w = World::new(&WorldDef::default());
    let floor = BodyDef {
        kind: BodyKind::Static,
        ..Default::default()
    };
    let floor = w.create_body(&floor, Shape::plane(Vec3::Y, 0.0)).unwrap();
    let id = ball(&mut w, Vec3::new(0.0, 0.1, 0.0));
    type Edit = fn(&mut World, BodyId) -> tumble::Result<()>;
    let edits: [Edit; 6] = [
        |w, id| w.set_friction(id, 0.2),
        |w, id| w.set_restitution(id, 0.2),
        |w, id| w.set_linear_damping(id, 0.2),
        |w, id| w.set_angular_damping(id, 0.2),
        |w, id| w.set_gravity_scale(id, 0.9),
        |w, id| w.set_collision_filter(id, 1, u32::MAX),
    ];
    for (k, edit) in edits.iter().enumerate() {
        run(&mut w, 1.0 / 60.0, 120);
        assert!(
            !w.body(id).unwrap().is_awake(),
            "edit {k}: should sleep first"
        );
        // Editing the floor wakes what rests on it.
        let target = if k % 2 == 0 { id } else { floor };
        edit(&mut w, target).unwrap();
        assert!(
            w.body(id).unwrap().is_awake(),
            "edit {k} should wake the ball"
        );
    }
}

/// Three overlapping cubes in the air, the first two of one collision owner: only the
/// pairs with the third touch. Setting a mask keeps the owner; setting the third's owner
/// to theirs ends its contacts, to 0 brings them back. A snapshot keeps the owners.
#[test]
fn bodies_of_one_collision_owner_do_not_collide() {
    let mut w = World::new(&WorldDef::default());
    assert_eq!(w.unused_collision_owner(), 1);
    let owner = w.unused_collision_owner();
    let cube = |w: &mut World, x: Real, owner: u32| {
        let def = BodyDef {
            position: Vec3::new(x, 5.0, 0.0),
            collision_owner: owner,
            ..Default::default()
        };
        w.create_body(&def, Shape::cuboid(Vec3::splat(0.5)))
            .unwrap()
    };
    let a = cube(&mut w, 0.0, owner);
    let b = cube(&mut w, 0.3, owner);
    let c = cube(&mut w, 0.6, 0);
    assert_eq!(w.unused_collision_owner(), owner + 1);
    let pairs = |w: &mut World| {
        let mut p: Vec<(BodyId, BodyId)> = w
            .update_contacts()
            .iter()
            .map(|k| (k.body_a.min(k.body_b), k.body_a.max(k.body_b)))
            .collect();
        p.sort_unstable();
        p
    };
    assert_eq!(pairs(&mut w), vec![(a, c), (b, c)]);
    w.set_collision_filter(a, 1, u32::MAX).unwrap();
    assert_eq!(w.body(a).unwrap().collision_owner(), owner);
    assert_eq!(pairs(&mut w), vec![(a, c), (b, c)]);
    w.set_collision_owner(c, owner).unwrap();
    assert_eq!(pairs(&mut w), vec![]);
    let restored = World::from_snapshot(&w.snapshot()).unwrap();
    let owners: Vec<u32> = [a, b, c]
        .iter()
        .map(|&id| restored.body(id).unwrap().collision_owner())
        .collect();
    assert_eq!(owners, vec![owner; 3]);
    w.set_collision_owner(c, 0).unwrap();
    assert_eq!(pairs(&mut w), vec![(a, c), (b, c)]);
}
