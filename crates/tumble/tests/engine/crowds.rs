//! Crowds: bodies created inside each other keep contacts, and so memory, in proportion to
//! their number; bodies that merely touch, however many, keep every contact, and give the
//! same results bit for bit as with no caps at all.

// Casts between Real and f64 are no-ops in the default build but needed in the f32 one.
#![allow(clippy::unnecessary_cast)]

use std::collections::BTreeSet;
use tumble::limits::{ContactLimits, MAX_MANIFOLDS_PER_PAIR};
use tumble::prelude::*;

const DT: Real = 1.0 / 60.0;

/// No caps: what the world does without them.
const UNCAPPED: ContactLimits = ContactLimits {
    per_body: u32::MAX,
    per_step: u32::MAX,
};

fn world_with(limits: ContactLimits, gravity: Vec3) -> World {
    World::try_new(&WorldDef {
        gravity,
        contact_limits: limits,
        ..Default::default()
    })
    .unwrap()
}

fn ground(w: &mut World) -> BodyId {
    let def = BodyDef {
        kind: BodyKind::Static,
        ..Default::default()
    };
    w.create_body(&def, Shape::plane(Vec3::Y, 0.0)).unwrap()
}

fn dynamic(w: &mut World, shape: Shape, position: Vec3) -> BodyId {
    let def = BodyDef {
        position,
        ..Default::default()
    };
    w.create_body(&def, shape).unwrap()
}

/// `n` bodies of `shape` on a ground, their centres within `spread` of one point (a
/// fixed pseudo-random cloud; 0 puts them all at the point).
fn pile(shape: &Shape, n: usize, spread: Real, limits: ContactLimits) -> World {
    let mut w = world_with(limits, Vec3::new(0.0, -9.8, 0.0));
    ground(&mut w);
    let mut seed = 0x9e37_79b9_7f4a_7c15_u64;
    let mut unit = || {
        seed = seed.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1);
        (seed >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
    };
    let lift = shape.bounding_radius();
    for _ in 0..n {
        let jitter = Vec3::new(unit() as Real, unit() as Real, unit() as Real) * spread;
        dynamic(&mut w, shape.clone(), Vec3::new(0.0, lift, 0.0) + jitter);
    }
    w
}

/// The body pairs with a non-empty manifold.
fn touching(w: &World) -> BTreeSet<(BodyId, BodyId)> {
    w.contacts()
        .iter()
        .filter(|c| !c.manifold.is_empty())
        .map(|c| (c.body_a, c.body_b))
        .collect()
}

fn all_finite(w: &World) -> bool {
    w.bodies().all(|(_, b)| {
        b.position().is_finite()
            && b.linear_velocity().is_finite()
            && b.angular_velocity().is_finite()
            && b.orientation().is_finite()
    })
}

#[test]
fn bodies_created_at_one_point_keep_contacts_in_proportion_to_their_number() {
    let shapes = [
        ("unit box", Shape::cuboid(Vec3::splat(0.5)), 600),
        ("ball", Shape::sphere(0.3), 500),
        ("capsule", Shape::capsule(0.2, 0.3), 400),
        ("small slab", Shape::cuboid(Vec3::new(0.05, 0.02, 0.1)), 400),
    ];
    for (name, shape, n) in shapes {
        for (per_body, spread) in [(16, 0.0), (4, 0.0), (16, 0.05)] {
            let limits = ContactLimits {
                per_body,
                ..ContactLimits::default()
            };
            let mut w = pile(&shape, n, spread, limits);
            // Uncapped, every pair of the n bodies would touch: n (n - 1) / 2 of them.
            let all = n * (n - 1) / 2;
            for step in 0..3 {
                w.step(DT).unwrap_or_else(|e| panic!("{name}: {e}"));
                let kept = w.contacts().len();
                // At one point every pair is sunk: at most per_body counted per body, plus
                // the four per body an update holds before it counts, plus the ground's.
                // In a cloud some pairs overlap by less than a quarter of the thinner
                // body (a 4 cm slab against one 3 cm above it), are not counted, and are
                // kept while one body is not yet crowded: measured, up to twice as many.
                // Overlap recovery makes a cloud of the one-point pile after its first
                // step (400 slabs: 3,907 contacts at step 2, against 3,608 for one point).
                let mut bound = (per_body as usize + 4) * (n + 1) + n;
                if spread > 0.0 || step > 0 {
                    bound *= 2;
                }
                assert!(kept <= bound, "{name} step {step}: {kept} > {bound}");
                assert!(kept < all / 4, "{name}: {kept} of {all}");
                let (candidates, pairs) = w.crowded_pairs();
                assert!(candidates > 0 && pairs > 0, "{name}: {candidates} {pairs}");
            }
            assert!(all_finite(&w), "{name}");
        }
    }
}

#[test]
fn without_caps_every_pair_of_the_pile_is_kept() {
    // The caps above are what bounds the piles: this one, small enough to keep whole,
    // keeps every pair with them off and sheds pairs with them on.
    let shape = Shape::cuboid(Vec3::splat(0.5));
    let n = 80;
    let mut open = pile(&shape, n, 0.0, UNCAPPED);
    open.step(DT).unwrap();
    // Lifted by their bounding radius, they do not reach the ground yet.
    assert_eq!(touching(&open).len(), n * (n - 1) / 2);
    assert_eq!(open.crowded_pairs(), (0, 0));
    let mut capped = pile(&shape, n, 0.0, ContactLimits::default());
    capped.step(DT).unwrap();
    assert!(touching(&capped).len() < n * (n - 1) / 2);
}

#[test]
fn a_crowded_pile_is_pushed_apart() {
    // Boxes created within 5 cm of one point spread out although most of their pairs are
    // shed: each is still pushed by its kept neighbours, and the kept set changes as they
    // part (a proxy that lost a pair searches again every step).
    let shape = Shape::cuboid(Vec3::splat(0.25));
    let mut w = pile(&shape, 300, 0.05, ContactLimits::default());
    let spread = |w: &World| {
        let xs: Vec<Vec3> = w.bodies().skip(1).map(|(_, b)| b.position()).collect();
        let mean = xs.iter().copied().sum::<Vec3>() / xs.len() as Real;
        let var = xs
            .iter()
            .map(|x| (*x - mean).length_squared())
            .sum::<Real>();
        (var / xs.len() as Real).sqrt()
    };
    let before = spread(&w);
    for _ in 0..60 {
        w.step(DT).unwrap();
    }
    assert!(all_finite(&w));
    let after = spread(&w);
    assert!(after > 4.0 * before, "spread {before} m -> {after} m");
}

/// A plate of `mass` kg resting on a bed of `side` x `side` balls of radius 5 cm, which
/// stand touching on a ground.
fn plate_on_balls(side: usize, mass: Real, limits: ContactLimits) -> (World, BodyId) {
    let mut w = world_with(limits, Vec3::new(0.0, -9.8, 0.0));
    ground(&mut w);
    let r = 0.05;
    for i in 0..side {
        for k in 0..side {
            let x = Vec3::new(i as Real * 2.0 * r, r, k as Real * 2.0 * r);
            dynamic(&mut w, Shape::sphere(r), x);
        }
    }
    let half = side as Real * r;
    let def = BodyDef {
        position: Vec3::new(half - r, 2.0 * r + 0.02, half - r),
        mass: MassSpec::Mass(mass),
        ..Default::default()
    };
    let plate = w
        .create_body(&def, Shape::cuboid(Vec3::new(half, 0.02, half)))
        .unwrap();
    (w, plate)
}

#[test]
fn a_plate_on_a_bed_of_balls_keeps_every_contact_whatever_the_cap() {
    // 900 balls under one plate: the plate touches 900 bodies, far past any cap, but each
    // ball touches at most five dynamic ones and is sunk into none; nothing is shed even
    // with a cap of 8, and the plate rests where it would with no caps.
    let side = 30;
    for per_body in [8, 16] {
        let limits = ContactLimits {
            per_body,
            ..ContactLimits::default()
        };
        let (mut capped, plate) = plate_on_balls(side, 50.0, limits);
        let (mut open, _) = plate_on_balls(side, 50.0, UNCAPPED);
        for step in 0..40 {
            capped.step(DT).unwrap();
            open.step(DT).unwrap();
            let under = touching(&capped)
                .iter()
                .filter(|(a, b)| *a == plate || *b == plate)
                .count();
            assert_eq!(under, side * side, "step {step}");
            assert_eq!(capped.crowded_pairs().1, 0);
            assert_eq!(capped.state_hash(), open.state_hash(), "step {step}");
        }
        // Resting on the balls' tops (0.1 m) by its 2 cm half thickness, to the slop.
        let y = capped.body(plate).unwrap().position().y;
        assert!((y - 0.12).abs() < 0.006, "{y}");
    }
}

#[test]
fn a_pack_of_small_marbles_is_not_a_crowd() {
    // Marbles of 5 mm radius, 0.5 mm apart: within the broad phase's 0.1 m margin each has
    // every other of the 1,728 as a candidate, and 26 neighbours within the contact
    // margin; they settle under gravity exactly as with no caps (the far candidates the
    // broad phase sheds are ones the narrow phase would pass over).
    let build = |limits: ContactLimits| {
        let mut w = world_with(limits, Vec3::new(0.0, -9.8, 0.0));
        ground(&mut w);
        let (r, pitch) = (0.005, 0.0105);
        for i in 0..12 {
            for j in 0..12 {
                for k in 0..12 {
                    let x = Vec3::new(i as Real, j as Real, k as Real) * pitch;
                    dynamic(&mut w, Shape::sphere(r), x + Vec3::new(0.0, r, 0.0));
                }
            }
        }
        w
    };
    let mut capped = build(ContactLimits::default());
    let mut open = build(UNCAPPED);
    for step in 0..10 {
        capped.step(DT).unwrap();
        open.step(DT).unwrap();
        assert_eq!(touching(&capped), touching(&open), "step {step}");
        assert_eq!(capped.crowded_pairs().1, 0, "step {step}");
        assert_eq!(capped.state_hash(), open.state_hash(), "step {step}");
    }
    assert!(capped.crowded_pairs().0 > 0, "the broad phase was crowded");
}

#[test]
fn a_step_past_the_contact_limit_is_undone_and_named() {
    let shape = Shape::cuboid(Vec3::splat(0.5));
    let limits = ContactLimits {
        per_step: 100,
        ..ContactLimits::default()
    };
    let mut w = pile(&shape, 40, 0.0, limits);
    let hash = w.state_hash();
    let e = w.step(DT).unwrap_err();
    assert!(matches!(e, Error::TooManyContacts(_)), "{e}");
    assert!(e.is_step_failure());
    assert_eq!(
        e.to_string(),
        "step 1 (t = 0.0166667 s): max_contacts: the step needs more than 100 contact \
         manifolds; raise max_contacts, or start the bodies apart"
    );
    assert_eq!(w.state_hash(), hash);
    assert_eq!((w.time(), w.contacts().len()), (0.0, 0));
    // Raised, the same world steps on.
    w.set_contact_limits(ContactLimits::default()).unwrap();
    w.step(DT).unwrap();
    assert!(!w.contacts().is_empty() && all_finite(&w));
}

#[test]
fn contact_limits_must_be_at_least_one() {
    let mut w = world_with(ContactLimits::default(), Vec3::ZERO);
    for (limits, text) in [
        (
            ContactLimits {
                per_body: 0,
                per_step: 10,
            },
            "max_contacts_per_body: must be >= 1",
        ),
        (
            ContactLimits {
                per_body: 10,
                per_step: 0,
            },
            "max_contacts: must be >= 1",
        ),
    ] {
        let e = w.set_contact_limits(limits).unwrap_err();
        assert_eq!(e.to_string(), text);
        assert_eq!(w.contact_limits(), ContactLimits::default());
        let def = WorldDef {
            contact_limits: limits,
            ..Default::default()
        };
        assert_eq!(World::try_new(&def).err().unwrap().to_string(), text);
    }
}

#[test]
fn a_pair_keeps_its_deepest_manifolds_up_to_the_cap() {
    // A compound of 300 small balls in a row on a ground: one manifold per ball, sunk by
    // 0 to 9 mm (ten depths, thirty balls each). The pair keeps the 256 deepest: every
    // ball sunk 2 mm or more (240), and 16 of the 30 sunk 1 mm.
    let mut w = world_with(ContactLimits::default(), Vec3::ZERO);
    ground(&mut w);
    let r = 0.01;
    let depth = |i: usize| (i % 10) as Real * 0.001;
    let children = (0..300)
        .map(|i| CompoundChild {
            shape: Shape::sphere(r),
            position: Vec3::new(i as Real * 3.0 * r, r - depth(i), 0.0),
            orientation: Quat::IDENTITY,
        })
        .collect();
    let def = BodyDef {
        mass: MassSpec::Mass(1.0),
        ..Default::default()
    };
    w.create_body(&def, Shape::Compound(children)).unwrap();
    let contacts = w.update_contacts();
    assert_eq!(contacts.len(), MAX_MANIFOLDS_PER_PAIR);
    let mut per_depth = [0usize; 10];
    for c in contacts {
        let sep = c.manifold.points().iter().map(|p| p.separation);
        let sep = sep.fold(Real::INFINITY, Real::min);
        let mm = (-sep * 1000.0).round() as usize;
        per_depth[mm] += 1;
    }
    assert_eq!(per_depth, [0, 16, 30, 30, 30, 30, 30, 30, 30, 30]);
}
