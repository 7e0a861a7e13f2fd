//! Snapshots (issue 18): `World::snapshot`, `World::restore`, `World::from_snapshot`.
//!
//! The oracle is bit-identity: a world continued from a snapshot gives the same state hash
//! after every step as the world that never stopped, and at the end the same snapshot
//! bytes (which hold everything a world keeps: contacts with warm starts and anchors,
//! broad-phase trees, sleep timers and islands, joint impulses, handles' generations and
//! free lists, integrator memory). Built-in scenes are covered in
//! crates/tumble-scene/tests/snapshots.rs; this file builds worlds that exercise edits,
//! sleep, joint limits, forces and callbacks, and feeds the decoder bad bytes.

#![allow(clippy::unnecessary_cast)]

use proptest::prelude::*;
use tumble::prelude::*;
use tumble::ForceCallback;

const DT: Real = 0.01;

fn fixed() -> BodyDef {
    BodyDef {
        kind: BodyKind::Static,
        ..Default::default()
    }
}

fn at(x: Real, y: Real, z: Real) -> BodyDef {
    BodyDef {
        position: Vec3::new(x, y, z),
        ..Default::default()
    }
}

/// A floor with a stack of boxes that falls asleep, a hinge pendulum swinging into its
/// limits, a ball on a spring to the world (free: integrated by the world's integrator,
/// Störmer–Verlet's memory included), a dragged ball, an applied force, and bodies,
/// a joint and a force added and removed (so handles have generations and free lists).
fn build(integrator: Integrator) -> (World, BodyId) {
    let mut w = World::new(&WorldDef {
        integrator,
        ..Default::default()
    });
    w.create_body(&fixed(), Shape::plane(Vec3::Y, 0.0)).unwrap();
    for i in 0..6 {
        let def = at(0.02 * i as Real, 0.25 + 0.5 * i as Real, 0.0);
        w.create_body(&def, Shape::cuboid(Vec3::splat(0.25)))
            .unwrap();
    }
    let doomed = w
        .create_body(&at(5.0, 1.0, 0.0), Shape::sphere(0.2))
        .unwrap();
    let arm = w
        .create_body(&at(-3.0, 2.0, 0.0), Shape::capsule(0.1, 0.4))
        .unwrap();
    let mut hinge = JointDef::new(
        JointKind::Hinge {
            limits: Some([-0.4, 0.4]),
            motor: None,
            spring: None,
            servo: None,
        },
        arm,
    );
    hinge.axis = Vec3::Z;
    hinge.anchor = Vec3::new(0.0, 0.5, 0.0);
    hinge.other_anchor = Vec3::new(-3.0, 2.5, 0.0);
    hinge.other_axis = Vec3::Z;
    hinge.armature = 0.05;
    w.create_joint(&hinge).unwrap();
    let mut bob_def = at(3.0, 3.0, 1.0);
    bob_def.angular_velocity = Vec3::new(0.3, 2.0, 0.1);
    let bob = w
        .create_body(&bob_def, Shape::cuboid(Vec3::new(0.1, 0.2, 0.3)))
        .unwrap();
    w.add_force(Force::Spring(Spring {
        body: bob,
        anchor: Vec3::new(0.05, 0.1, 0.0),
        other: SpringEnd::World(Vec3::new(3.0, 4.0, 0.0)),
        stiffness: 80.0,
        rest_length: 0.5,
        damping: 0.1,
    }))
    .unwrap();
    let doomed_force = w
        .add_force(Force::Drag(Drag {
            body: doomed,
            linear: 0.5,
            quadratic: 0.1,
        }))
        .unwrap();
    let mut doomed_joint = JointDef::new(JointKind::Fixed, doomed);
    doomed_joint.other_anchor = Vec3::new(5.0, 1.0, 0.0);
    let doomed_joint = w.create_joint(&doomed_joint).unwrap();
    for _ in 0..30 {
        w.step(DT).unwrap();
    }
    w.remove_force(doomed_force).unwrap();
    w.remove_joint(doomed_joint).unwrap();
    w.remove_body(doomed).unwrap();
    let late = w
        .create_body(&at(-1.0, 0.5, 1.0), Shape::sphere(0.3))
        .unwrap();
    w.add_force(Force::Drag(Drag {
        body: late,
        linear: 0.2,
        quadratic: 0.0,
    }))
    .unwrap();
    w.add_force(Force::Applied(AppliedForce {
        body: bob,
        force: Vec3::new(0.5, 0.0, 0.0),
        point: Some(Vec3::new(3.0, 3.1, 1.0)),
        torque: Vec3::ZERO,
    }))
    .unwrap();
    (w, bob)
}

/// Steps `n` times, the state hash after each.
fn hashes(w: &mut World, n: usize) -> Vec<u64> {
    (0..n)
        .map(|_| {
            w.step(DT).unwrap();
            w.state_hash()
        })
        .collect()
}

#[test]
fn continuing_from_a_snapshot_is_bit_identical_for_every_integrator() {
    for integrator in Integrator::ALL {
        let (mut straight, _) = build(integrator);
        // 2.5 s: the stack has settled and sleeps, the arm has reached its limits.
        hashes(&mut straight, 250);
        let asleep = straight
            .body_ids()
            .iter()
            .filter(|&&id| !straight.body(id).unwrap().is_awake())
            .count();
        assert!(asleep >= 6, "{integrator:?}: the stack sleeps ({asleep})");
        assert!(!straight.contacts().is_empty());
        let bytes = straight.snapshot();
        let (time, steps) = (straight.time(), straight.step_count());
        let first = hashes(&mut straight, 150);

        let mut resumed = World::from_snapshot(&bytes).unwrap();
        assert_eq!(resumed.snapshot(), bytes, "{integrator:?}: round trip");
        assert_eq!((resumed.time(), resumed.step_count()), (time, steps));
        let second = hashes(&mut resumed, 150);
        assert_eq!(first, second, "{integrator:?}: hashes differ");
        assert_eq!(straight.snapshot(), resumed.snapshot(), "{integrator:?}");
        // Handles continue the same: the next body takes the same slot and generation.
        let a = straight
            .create_body(&at(0.0, 9.0, 0.0), Shape::sphere(0.1))
            .unwrap();
        let b = resumed
            .create_body(&at(0.0, 9.0, 0.0), Shape::sphere(0.1))
            .unwrap();
        assert_eq!(a, b);
    }
}

/// A hinged and a slid box hanging under gravity, swinging: two joint blocks.
fn swinging_pair() -> (World, [BodyId; 2], JointId) {
    let mut w = World::new(&WorldDef {
        sleep: false,
        ..Default::default()
    });
    let arm = w
        .create_body(
            &at(0.5, 0.0, 0.0),
            Shape::cuboid(Vec3::new(0.5, 0.05, 0.05)),
        )
        .unwrap();
    let mut hinge = JointDef::new(
        JointKind::Hinge {
            limits: None,
            motor: None,
            spring: None,
            servo: None,
        },
        arm,
    );
    (hinge.anchor, hinge.axis, hinge.other_axis) = (Vec3::new(-0.5, 0.0, 0.0), Vec3::Z, Vec3::Z);
    let pivot = w.create_joint(&hinge).unwrap();
    let slide = w
        .create_body(&at(1.0, -0.3, 0.0), Shape::cuboid(Vec3::splat(0.1)))
        .unwrap();
    let mut slider = JointDef::new(
        JointKind::Slider {
            limits: None,
            motor: None,
            spring: None,
            servo: None,
        },
        slide,
    );
    (slider.other, slider.axis) = (Some(arm), Vec3::Y);
    slider.other_anchor = Vec3::new(0.5, -0.3, 0.0);
    w.create_joint(&slider).unwrap();
    (w, [arm, slide], pivot)
}

#[test]
fn a_body_moved_between_steps_gets_its_joint_blocks_made_again() {
    // The solver keeps a joint's factored block from the step's last frame and reuses it
    // when the next step's first frame is the same bit for bit. A body moved or turned
    // between steps changes that frame, a joint removed the blocks' places: the world
    // must then step as one restored from a snapshot taken after the edit (which keeps
    // no block) does, bit for bit.
    let (mut w, [arm, slide], pivot) = swinging_pair();
    hashes(&mut w, 30);
    let edits: [&dyn Fn(&mut World); 3] = [
        &|w| {
            w.set_position(
                slide,
                w.body(slide).unwrap().position() + Vec3::new(0.0, 0.01, 0.002),
            )
            .unwrap()
        },
        &|w| {
            let q = w.body(arm).unwrap().orientation() * Quat::from_rotation_z(0.05);
            w.set_orientation(arm, q).unwrap()
        },
        &|w| {
            let v = w.body(arm).unwrap().linear_velocity() * 2.0;
            w.set_linear_velocity(arm, v).unwrap()
        },
    ];
    for (k, edit) in edits.iter().enumerate() {
        edit(&mut w);
        let mut fresh = World::from_snapshot(&w.snapshot()).unwrap();
        assert_eq!(hashes(&mut w, 5), hashes(&mut fresh, 5), "edit {k}");
    }
    // A joint removed: the slider's block moves to the hinge's place in the list.
    w.remove_joint(pivot).unwrap();
    let mut fresh = World::from_snapshot(&w.snapshot()).unwrap();
    assert_eq!(hashes(&mut w, 5), hashes(&mut fresh, 5), "joint removed");
    // Left alone, it continues as the restored world too (the reuse changes no bit).
    let mut fresh = World::from_snapshot(&w.snapshot()).unwrap();
    assert_eq!(hashes(&mut w, 20), hashes(&mut fresh, 20));
}

#[test]
fn a_restore_wakes_nothing_and_keeps_what_the_snapshot_had() {
    // Restoring the same bytes twice gives the same world, and one restored world's
    // snapshot of a sleeping stack still says it sleeps.
    let (mut w, bob) = build(Integrator::Verlet);
    hashes(&mut w, 250);
    let bytes = w.snapshot();
    let awake: Vec<bool> = w
        .body_ids()
        .iter()
        .map(|&id| w.body(id).unwrap().is_awake())
        .collect();
    hashes(&mut w, 10);
    w.restore(&bytes).unwrap();
    let again: Vec<bool> = w
        .body_ids()
        .iter()
        .map(|&id| w.body(id).unwrap().is_awake())
        .collect();
    assert_eq!(awake, again);
    assert_eq!(w.snapshot(), bytes);
    assert!(w.body(bob).is_ok());
}

/// A deterministic callback: a push on `body` that varies with time.
fn push(body: BodyId) -> ForceCallback {
    Box::new(move |ctx: &mut ForceContext<'_>| {
        let t = ctx.time();
        ctx.add_force(body, Vec3::new((3.0 * t).sin(), 0.0, 0.0));
    })
}

#[test]
fn force_callbacks_are_reattached_by_the_caller_and_their_count_must_match() {
    let (mut w, bob) = build(Integrator::Rk4);
    w.add_force_callback(push(bob));
    hashes(&mut w, 50);
    let bytes = w.snapshot();
    let first = hashes(&mut w, 50);

    let err = World::from_snapshot(&bytes).err().unwrap();
    assert_eq!(
        err.to_string(),
        "snapshot: 1 force callbacks in the snapshot, 0 attached"
    );
    let mut two = World::new(&WorldDef::default());
    two.add_force_callback(push(bob));
    two.add_force_callback(push(bob));
    let before = two.snapshot();
    assert!(two.restore(&bytes).is_err());
    assert_eq!(two.snapshot(), before, "a refused restore changes nothing");

    let mut resumed = World::new(&WorldDef::default());
    resumed.add_force_callback(push(bob));
    resumed.restore(&bytes).unwrap();
    assert_eq!(first, hashes(&mut resumed, 50));
}

#[test]
fn the_contact_filter_stays_with_the_world_restored_into() {
    // A filter that lets nothing touch the floor: the restored world keeps it, and so
    // the stack falls through the floor as in the filtered world.
    let filtered = |w: &mut World| {
        w.set_contact_filter(|pair: &ContactPair<'_>| {
            pair.a.kind() != BodyKind::Static && pair.b.kind() != BodyKind::Static
        })
    };
    let (mut w, _) = build(Integrator::SymplecticEuler);
    filtered(&mut w);
    hashes(&mut w, 20);
    let bytes = w.snapshot();
    let first = hashes(&mut w, 30);
    let mut resumed = World::new(&WorldDef::default());
    filtered(&mut resumed);
    resumed.restore(&bytes).unwrap();
    assert_eq!(first, hashes(&mut resumed, 30));
}

fn settled() -> (World, Vec<u8>) {
    let (mut w, _) = build(Integrator::SymplecticEuler);
    hashes(&mut w, 40);
    let bytes = w.snapshot();
    (w, bytes)
}

/// Restores `bytes` into a copy of the settled world: the error's message, after
/// checking that the world did not change.
fn refused(bytes: &[u8]) -> String {
    let (mut target, good) = settled();
    let err = target.restore(bytes).expect_err("refused");
    assert_eq!(target.snapshot(), good, "a refused restore changes nothing");
    assert!(matches!(err, Error::Snapshot { .. }));
    err.to_string()
}

#[test]
fn every_kind_of_bad_snapshot_gets_its_own_error() {
    let (_, good) = settled();
    let n = good.len();
    assert_eq!(
        refused(&good[..n - 1]),
        format!("snapshot: truncated at byte {}", n - 1)
    );
    assert_eq!(refused(&good[..20]), "snapshot: truncated at byte 20");
    assert_eq!(refused(&[]), "snapshot: truncated at byte 0");
    let mut longer = good.clone();
    longer.extend_from_slice(&[1, 2, 3]);
    assert_eq!(
        refused(&longer),
        format!("snapshot: 3 bytes after the end at byte {n}")
    );
    let mut flipped = good.clone();
    flipped[n / 2] ^= 0x10;
    assert_eq!(
        refused(&flipped),
        "snapshot: checksum mismatch (the bytes were changed)"
    );
    let mut version = good.clone();
    version[8] = 2;
    assert_eq!(refused(&version), "snapshot: version 2, this build reads 5");
    let mut other = good.clone();
    let (this, that) = if std::mem::size_of::<Real>() == 8 {
        ("f64", "f32")
    } else {
        ("f32", "f64")
    };
    other[12] = if this == "f64" { 4 } else { 8 };
    assert_eq!(
        refused(&other),
        format!("snapshot: written in {that}, this build is {this}")
    );
    let random: Vec<u8> = (0..500u32)
        .map(|i| (i.wrapping_mul(2654435761) >> 13) as u8)
        .collect();
    assert_eq!(
        refused(&random),
        "snapshot: not a Tumble snapshot (bad magic bytes)"
    );
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(200))]

    /// Mutated snapshots (bytes overwritten, cut, inserted) are refused with a typed error
    /// or, if the mutation changed nothing, accepted; never a panic, and a refusal leaves
    /// the target as it was.
    #[test]
    fn mutated_snapshots_never_panic(
        edits in prop::collection::vec((any::<prop::sample::Index>(), any::<u8>(), 0u8..3), 1..6)
    ) {
        let (mut target, good) = settled();
        let mut bytes = good.clone();
        for (at, value, how) in edits {
            let i = at.index(bytes.len().max(1));
            match how {
                0 if !bytes.is_empty() => bytes[i] = value,
                1 => bytes.truncate(i),
                _ => bytes.insert(i.min(bytes.len()), value),
            }
        }
        match target.restore(&bytes) {
            Ok(()) => prop_assert_eq!(&bytes, &good),
            Err(e) => {
                prop_assert!(e.to_string().starts_with("snapshot: "));
                prop_assert_eq!(target.snapshot(), good);
            }
        }
    }

    /// Random bytes, with a valid header in front or not, are refused.
    #[test]
    fn random_bytes_are_refused(bytes in prop::collection::vec(any::<u8>(), 0..2000), keep in 0usize..40) {
        let (mut target, good) = settled();
        let mut data = good[..keep.min(good.len())].to_vec();
        data.extend_from_slice(&bytes);
        prop_assert!(target.restore(&data).is_err());
        prop_assert_eq!(target.snapshot(), good);
    }
}
