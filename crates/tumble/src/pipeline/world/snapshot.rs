//! Snapshots: the world's whole lasting state (see the table in `mod.rs`) as a compact,
//! versioned byte buffer, and a world restored from one that continues bit-identically.
//!
//! Layout (little-endian):
//!
//! | bytes | field |
//! |---|---|
//! | 8 | magic `TUMBLESS` |
//! | 4 | format version ([`SNAPSHOT_VERSION`]) |
//! | 1 | precision: bytes per `Real`, 8 (f64) or 4 (f32) |
//! | 4 + 4 | body and joint counts (for a reader's information; checked) |
//! | 8 | payload length |
//! | 8 | payload checksum (`codec::checksum`) |
//! | … | payload: settings, clock, bodies, forces, joints, collision, sleep tag, integrator memory, sensors, hooks |
//!
//! Not saved, because they are code or not state: force callbacks (only their count is
//! saved, and a world whose count differs is refused), the contact filter and modifier
//! (the world restored into keeps its own), the step scratch and the thread count (a
//! setting: results are bit-identical for any count; the target world keeps its own).
//!
//! A snapshot is read completely and checked before anything is swapped in, so a bad one
//! leaves the world as it was, refused with `Error::Snapshot` naming the field. The
//! checksum catches accidents; past it, the payload is decoded with every length checked
//! against the bytes left, and then (`check`) held to everything the world's code indexes
//! or loops over without checking, so a payload crafted to pass the checksum cannot make
//! a later step, query or edit panic or loop forever:
//!
//! - lengths: one handle, proxy and integrator memory slot per body, one handle per joint
//!   and force, the header's counts; handles' slots, generations and free lists agree;
//! - references: every dense body index (contacts, joint links, joined pairs, broad-phase
//!   users) below the body count, every handle (joints', forces', excluded pairs',
//!   contacts') naming a live body, contacts' handles those of their indices;
//! - structures: the broad phase's trees are trees (children and parents in range and
//!   agreeing, heights and boxes as refitting makes them, free lists that end and hold
//!   the rest), its proxies and leaves name each other, its moved bits, move buffer and
//!   pairs agree; manifolds hold at most four points; hulls', meshes' and height fields'
//!   indices are in range and a mesh's hierarchy points forward;
//! - counts kept beside the bodies (sensors, one-way bodies) equal the bodies' own;
//! - numbers by the rules of the setters that take them: settings (the solver clamps by
//!   the push-out speed, and loops over substeps and passes), bodies' coefficients and
//!   shapes, joints' limits, motors and springs (the solver clamps by them), forces. A
//!   body's state is not checked: a step refuses non-finite or too fast results itself.

use super::{check_solver_settings, Tolerances};
use super::{BodyStore, Clock, CollisionStore, ForceStore, JointStore, Settings, World, WorldDef};
use crate::codec::{check_index, checksum, ensure, Code, Decoded, Malformed, Reader, Writer};
use crate::dynamics::body::BodyKind;
use crate::dynamics::integrate::IntegratorMemory;
use crate::dynamics::joint;
use crate::error::{check, Error, Result};
use crate::limits::MAX_ACCELERATION;
use crate::math::Real;
use crate::pipeline::hooks::Hooks;
use crate::pipeline::sensors::SensorStore;

/// The snapshot format version this build writes and reads.
pub const SNAPSHOT_VERSION: u32 = 5;
const MAGIC: &[u8; 8] = b"TUMBLESS";
const HEADER: usize = 8 + 4 + 1 + 4 + 4 + 8 + 8;
const PRECISION: u8 = std::mem::size_of::<Real>() as u8;

/// Everything a snapshot holds, read and checked, ready to be swapped in.
struct Saved {
    settings: Settings,
    clock: Clock,
    bodies: BodyStore,
    forces: ForceStore,
    callbacks: usize,
    joints: JointStore,
    collision: CollisionStore,
    sleep_tag: u32,
    memory: IntegratorMemory,
    sensors: SensorStore,
    hooks: Hooks,
}

fn precision_name(bytes: u8) -> String {
    match bytes {
        8 => "f64".into(),
        4 => "f32".into(),
        n => format!("an unknown precision ({n} bytes per number)"),
    }
}

impl World {
    /// The world's whole lasting state as a compact byte buffer (see
    /// `pipeline/world/snapshot.rs` for the layout): [`World::restore`] or
    /// [`World::from_snapshot`] continue it bit-identically. Force callbacks, the contact
    /// filter and modifier are code and not saved: re-attach them to the world restored
    /// into (a world restored into must have as many force callbacks as were saved).
    pub fn snapshot(&self) -> Vec<u8> {
        let mut w = Writer {
            bytes: Vec::with_capacity(HEADER + 4096),
        };
        w.raw(MAGIC);
        SNAPSHOT_VERSION.put(&mut w);
        PRECISION.put(&mut w);
        (self.bodies.list.len() as u32).put(&mut w);
        (self.joints.list.len() as u32).put(&mut w);
        w.raw(&[0; 16]);
        self.settings.put(&mut w);
        self.clock.put(&mut w);
        self.bodies.put(&mut w);
        self.forces.list.put(&mut w);
        self.forces.handles.put(&mut w);
        self.forces.callbacks.len().put(&mut w);
        self.joints.put(&mut w);
        self.collision.put(&mut w);
        self.sleep_tag.put(&mut w);
        self.memory.put(&mut w);
        self.sensors.put(&mut w);
        self.hooks.put(&mut w);
        let payload = w.bytes.len() - HEADER;
        let sum = checksum(&w.bytes[HEADER..]);
        w.bytes[HEADER - 16..HEADER - 8].copy_from_slice(&(payload as u64).to_le_bytes());
        w.bytes[HEADER - 8..HEADER].copy_from_slice(&sum.to_le_bytes());
        w.bytes
    }

    /// A new world continuing `bytes` (from [`World::snapshot`]), with the default thread
    /// count. Refused with [`Error::Snapshot`] for a bad snapshot, and for one saved with
    /// force callbacks (build a world, add as many, then [`World::restore`]).
    pub fn from_snapshot(bytes: &[u8]) -> Result<World> {
        let mut world = World::new(&WorldDef::default());
        world.restore(bytes)?;
        Ok(world)
    }

    /// Replaces this world's state with `bytes` (from [`World::snapshot`]); stepping on is
    /// bit-identical to stepping the world it was taken from. The world keeps its force
    /// callbacks (their number must equal the saved one), contact filter and modifier and
    /// thread count. On any error ([`Error::Snapshot`] naming what is wrong and where) the
    /// world is unchanged.
    pub fn restore(&mut self, bytes: &[u8]) -> Result<()> {
        let saved = read(bytes)?;
        let attached = self.forces.callbacks.len();
        if saved.callbacks != attached {
            return Err(Error::snapshot(format!(
                "{} force callbacks in the snapshot, {attached} attached",
                saved.callbacks
            )));
        }
        let mut forces = saved.forces;
        std::mem::swap(&mut forces.callbacks, &mut self.forces.callbacks);
        let mut hooks = saved.hooks;
        hooks.take_code(&mut self.hooks);
        self.settings = saved.settings;
        self.clock = saved.clock;
        self.bodies = saved.bodies;
        self.forces = forces;
        self.joints = saved.joints;
        self.collision = saved.collision;
        self.sleep_tag = saved.sleep_tag;
        self.memory = saved.memory;
        self.sensors = saved.sensors;
        self.hooks = hooks;
        Ok(())
    }
}

/// The header's checks, then the payload's; nothing is kept unless all pass.
fn read(bytes: &[u8]) -> Result<Saved> {
    let mut r = Reader::new(bytes, 0);
    let magic: [u8; 8] = r.take()?;
    if &magic != MAGIC {
        return Err(Error::snapshot("not a Tumble snapshot (bad magic bytes)"));
    }
    let version = u32::get(&mut r)?;
    if version != SNAPSHOT_VERSION {
        return Err(Error::snapshot(format!(
            "version {version}, this build reads {SNAPSHOT_VERSION}"
        )));
    }
    let precision = u8::get(&mut r)?;
    if precision != PRECISION {
        return Err(Error::snapshot(format!(
            "written in {}, this build is {}",
            precision_name(precision),
            precision_name(PRECISION)
        )));
    }
    let counts = (u32::get(&mut r)? as usize, u32::get(&mut r)? as usize);
    let length = u64::get(&mut r)?;
    let sum = u64::get(&mut r)?;
    let payload = &bytes[HEADER..];
    if (payload.len() as u64) < length {
        return Err(Error::snapshot(format!(
            "truncated at byte {}",
            bytes.len()
        )));
    }
    if payload.len() as u64 > length {
        let extra = payload.len() as u64 - length;
        return Err(Error::snapshot(format!(
            "{extra} bytes after the end at byte {}",
            HEADER as u64 + length
        )));
    }
    if checksum(payload) != sum {
        return Err(Error::snapshot(
            "checksum mismatch (the bytes were changed)",
        ));
    }
    let saved = read_payload(&mut Reader::new(payload, HEADER))?;
    check(&saved, counts)?;
    Ok(saved)
}

impl From<Malformed> for Error {
    fn from(m: Malformed) -> Error {
        Error::snapshot(m.0)
    }
}

fn read_payload(r: &mut Reader<'_>) -> Decoded<Saved> {
    let saved = Saved {
        settings: Code::get(r)?,
        clock: Code::get(r)?,
        bodies: Code::get(r)?,
        forces: ForceStore {
            list: Code::get(r)?,
            handles: Code::get(r)?,
            callbacks: Vec::new(),
            failure: None,
        },
        callbacks: Code::get(r)?,
        joints: Code::get(r)?,
        collision: Code::get(r)?,
        sleep_tag: Code::get(r)?,
        memory: Code::get(r)?,
        sensors: Code::get(r)?,
        hooks: Code::get(r)?,
    };
    if r.remaining() > 0 {
        return Err(Malformed(format!(
            "{} bytes after the end at byte {}",
            r.remaining(),
            r.offset()
        )));
    }
    Ok(saved)
}

/// Everything a world indexes or loops over without checking, checked before a decoded
/// snapshot is trusted: the stores' lengths against each other and the header, then each
/// store's references against what they refer to and the invariants its code relies on,
/// and the settings and coefficients by the rules their setters apply. A payload crafted
/// to pass the checksum is then refused rather than left to panic a later step.
fn check(s: &Saved, counts: (usize, usize)) -> Result<()> {
    check_lengths(s, counts)?;
    check_settings(&s.settings).map_err(|e| invalid(e, "settings"))?;
    let steps = s.clock.steps;
    ensure(steps < u64::MAX, || {
        format!("clock.steps: {steps}, one step from overflow")
    })?;
    for (i, body) in s.bodies.list.iter().enumerate() {
        body.check_saved()
            .map_err(|e| invalid(e, &format!("bodies[{i}]")))?;
    }
    check_forces(&s.forces, &s.bodies)?;
    check_joints(&s.joints, &s.bodies)?;
    let bodies = &s.bodies.list;
    let fixed = |i: usize| bodies[i].kind == BodyKind::Static;
    s.collision
        .broad_phase
        .check_saved(&s.collision.proxies, fixed)?;
    s.collision.contacts.check_saved(s.bodies.ids())?;
    s.sensors.check_saved(bodies)?;
    s.hooks.check_saved(bodies)?;
    Ok(())
}

/// A validation error from a store's own rules, as a snapshot error under `at`.
fn invalid(e: Error, at: &str) -> Error {
    Error::snapshot(e.within(at).to_string())
}

/// The stores' lengths agree with each other and with the header: what a world indexes
/// by body or joint without checking.
fn check_lengths(s: &Saved, (bodies, joints): (usize, usize)) -> Result<()> {
    let n = s.bodies.list.len();
    let lengths = [
        ("body handles", s.bodies.handles.len()),
        ("broad-phase proxies", s.collision.proxies.len()),
        ("integrator memory", s.memory.slots()),
        ("header's body count", bodies),
    ];
    for (what, len) in lengths {
        if len != n {
            return Err(Error::snapshot(format!("{n} bodies but {len} {what}")));
        }
    }
    let m = s.joints.list.len();
    if s.joints.handles.len() != m || joints != m {
        return Err(Error::snapshot(format!(
            "{m} joints but {} joint handles and a header count of {joints}",
            s.joints.handles.len()
        )));
    }
    if s.forces.handles.len() != s.forces.list.len() {
        return Err(Error::snapshot("force handles do not match the forces"));
    }
    Ok(())
}

/// The settings by the rules `World::try_new` and the setters apply; the tolerances
/// those of the length unit (the solver clamps by the push-out speed, which must not be
/// negative).
fn check_settings(s: &Settings) -> Result<()> {
    check::vec3_at_most("gravity", s.gravity, MAX_ACCELERATION, "m/s²")?;
    check::positive("length_unit", s.length_unit)?;
    check_solver_settings(&s.solver).map_err(|e| e.within("solver"))?;
    check::positive("max_speed", s.limits.max_speed)?;
    check::positive("max_angular_speed", s.limits.max_angular_speed)?;
    if s.contacts.per_body == 0 || s.contacts.per_step == 0 {
        return Err(Error::invalid("contacts", "limits must be >= 1"));
    }
    let push = s.tolerances.scales.max_push;
    check::positive("max_push_speed", push)?;
    let mut derived = Tolerances::new(s.length_unit);
    derived.scales.max_push = push;
    if derived != s.tolerances {
        return Err(Error::invalid("tolerances", "are not those of length_unit"));
    }
    Ok(())
}

/// Each force by `World::add_force`'s rules, on bodies that exist (a removed body's
/// forces go with it).
fn check_forces(forces: &ForceStore, bodies: &BodyStore) -> Result<()> {
    for (k, f) in forces.list.iter().enumerate() {
        f.validate()
            .map_err(|e| invalid(e, &format!("forces[{k}]")))?;
        let (a, b) = f.bodies();
        for (field, id) in [("body", Some(a)), ("other", b)] {
            let Some(id) = id else { continue };
            ensure(bodies.dense(id).is_some(), || {
                format!("forces[{k}].{field}: unknown or removed body {id:?}")
            })?;
        }
    }
    Ok(())
}

/// Each joint by `World::create_joint`'s rules (its limits, motors and springs in range:
/// the solver clamps by them), on bodies that exist; each joint's dense bodies and the
/// pairs kept from colliding in range (the step reads them before it derives them
/// again), those pairs and the excluded ones sorted, as their binary searches need.
fn check_joints(joints: &JointStore, bodies: &BodyStore) -> Result<()> {
    let n = bodies.list.len();
    for (k, j) in joints.list.iter().enumerate() {
        joint::validate(&j.def).map_err(|e| invalid(e, &format!("joints[{k}]")))?;
        for (field, id) in [("body", Some(j.def.body)), ("other", j.def.other)] {
            let Some(id) = id else { continue };
            ensure(bodies.dense(id).is_some(), || {
                format!("joints[{k}].{field}: unknown or removed body {id:?}")
            })?;
        }
    }
    let links = joints.links.len();
    ensure(links == joints.list.len(), || {
        format!("{links} joint links for {} joints", joints.list.len())
    })?;
    for (k, link) in joints.links.iter().enumerate() {
        for (end, i) in link.iter().enumerate() {
            let Some(i) = *i else { continue };
            check_index(i as u64, n, (|| format!("joint_links[{k}][{end}]"), "body"))?;
        }
    }
    for (k, &(a, b)) in joints.joined_pairs.iter().enumerate() {
        check_index(b, n, (|| format!("joined_pairs[{k}]"), "body"))?;
        ensure(a < b, || format!("joined_pairs[{k}]: bodies {a} and {b}"))?;
    }
    let sorted = joints.joined_pairs.windows(2).all(|w| w[0] < w[1]);
    ensure(sorted, || "joined_pairs: not sorted".to_string())?;
    for (k, &(a, b)) in joints.excluded.iter().enumerate() {
        let live = bodies.dense(a).is_some() && bodies.dense(b).is_some();
        ensure(live && a < b, || {
            format!("excluded[{k}]: not a pair of bodies ({a:?}, {b:?})")
        })?;
    }
    let sorted = joints.excluded.windows(2).all(|w| w[0] < w[1]);
    ensure(sorted, || "excluded: not sorted".to_string())?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::prelude::*;
    use proptest::prelude::*;

    /// A small world in contact, with a joint, a force and a removed body.
    fn world() -> World {
        let mut w = World::new(&WorldDef::default());
        let ground = BodyDef {
            kind: BodyKind::Static,
            ..Default::default()
        };
        w.create_body(&ground, Shape::plane(Vec3::Y, 0.0)).unwrap();
        let mut ids = Vec::new();
        for i in 0..4 {
            let def = BodyDef {
                position: Vec3::new(0.3 * i as Real, 0.2 + 0.4 * i as Real, 0.0),
                name: Some(format!("b{i}")),
                ..Default::default()
            };
            ids.push(
                w.create_body(&def, Shape::cuboid(Vec3::splat(0.2)))
                    .unwrap(),
            );
        }
        w.create_joint(&JointDef::new(JointKind::Fixed, ids[3]))
            .unwrap();
        w.add_force(Force::Drag(Drag {
            body: ids[1],
            linear: 0.1,
            quadratic: 0.0,
        }))
        .unwrap();
        w.remove_body(ids[2]).unwrap();
        for _ in 0..10 {
            w.step(0.01).unwrap();
        }
        w
    }

    /// Writes a valid checksum over a changed payload.
    fn reseal(bytes: &mut [u8]) {
        let sum = checksum(&bytes[HEADER..]);
        bytes[HEADER - 8..HEADER].copy_from_slice(&sum.to_le_bytes());
    }

    /// Snapshot `bytes` with the payload bytes at `edits` (positions past the header) set,
    /// and a valid checksum written over it.
    fn resealed_edit(mut bytes: Vec<u8>, edits: &[(prop::sample::Index, u8)]) -> Vec<u8> {
        for (at, value) in edits {
            let i = HEADER + at.index(bytes.len() - HEADER);
            bytes[i] = *value;
        }
        reseal(&mut bytes);
        bytes
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(300))]

        /// Past the checksum, a changed payload is decoded with every length checked: an
        /// error or a world, never a panic or an allocation the bytes cannot back.
        #[test]
        fn a_resealed_mutated_payload_never_panics_the_decoder(
            edits in prop::collection::vec((any::<prop::sample::Index>(), any::<u8>()), 1..8)
        ) {
            let _ = read(&resealed_edit(world().snapshot(), &edits));
        }
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(2000))]

        /// A resealed payload that decodes is checked before it is trusted: restored, the
        /// world steps, saves and answers queries with results or errors, never a panic
        /// (its bodies, joints, contacts, forces, sensors and broad phase refer only to
        /// what the snapshot holds).
        #[test]
        fn a_resealed_world_that_restores_never_panics_a_step(
            edits in prop::collection::vec((any::<prop::sample::Index>(), any::<u8>()), 1..4)
        ) {
            let bytes = resealed_edit(world().snapshot(), &edits);
            let mut w = world();
            if w.restore(&bytes).is_ok() {
                for _ in 0..3 {
                    let _ = w.step(0.01);
                }
                let _ = w.snapshot();
                let _ = w.contacts().len();
            }
        }
    }

    /// A world holding something of every store: static mesh, height field and boxes;
    /// a hull, a compound, a capsule and a cylinder; a sensor, a one-way platform, a
    /// kinematic body with a target; hinge, slider, ball and distance joints with limits,
    /// motors, springs and a servo; a spring between bodies, an applied force; an excluded
    /// pair; Störmer–Verlet's memory; a removed body. Its snapshot, taken once.
    fn rich_snapshot() -> &'static [u8] {
        static BYTES: std::sync::OnceLock<Vec<u8>> = std::sync::OnceLock::new();
        BYTES.get_or_init(|| {
            let mut w = World::new(&WorldDef {
                integrator: Integrator::Verlet,
                ..Default::default()
            });
            let ids = rich_bodies(&mut w);
            rich_joints(&mut w, &ids);
            for _ in 0..20 {
                w.step(0.01).unwrap();
            }
            w.remove_body(ids[9]).unwrap();
            w.step(0.01).unwrap();
            w.snapshot()
        })
    }

    /// The rich world's bodies: what `rich_bodies` creates.
    fn rich_shapes() -> Vec<(BodyDef, Shape)> {
        use crate::{HeightField, TriMesh};
        let fixed = |x: Real| BodyDef {
            kind: BodyKind::Static,
            position: Vec3::new(x, 0.0, 0.0),
            ..Default::default()
        };
        let at = |x: Real, y: Real| BodyDef {
            position: Vec3::new(x, y, 0.0),
            restitution: 0.3,
            ..Default::default()
        };
        let v = |x: Real, y: Real, z: Real| Vec3::new(x, y, z);
        let square = vec![
            v(-2.0, 0.0, -2.0),
            v(2.0, 0.0, -2.0),
            v(2.0, 0.0, 2.0),
            v(-2.0, 0.0, 2.0),
        ];
        let mesh = TriMesh::new(square, vec![[0, 2, 1], [0, 3, 2]]).unwrap();
        let field = HeightField::new(
            vec![0.0, 0.1, 0.2, 0.1, 0.0, 0.1, 0.2, 0.1, 0.0],
            3,
            3,
            Vec3::ONE,
        )
        .unwrap();
        let corners: Vec<Vec3> = (0..8)
            .map(|i| v((i & 1) as Real, (i >> 1 & 1) as Real, (i >> 2) as Real) * 0.4)
            .collect();
        let child = |shape, x| CompoundChild {
            shape,
            position: v(x, 0.0, 0.0),
            orientation: Quat::IDENTITY,
        };
        vec![
            (fixed(0.0), Shape::TriMesh(mesh)),
            (fixed(6.0), Shape::HeightField(field)),
            (fixed(-6.0), Shape::cuboid(v(2.0, 0.1, 2.0))),
            (at(0.0, 0.5), Shape::convex_hull(&corners).unwrap()),
            (
                at(0.8, 0.4),
                Shape::Compound(vec![
                    child(Shape::sphere(0.2), -0.2),
                    child(Shape::cuboid(Vec3::splat(0.1)), 0.2),
                ]),
            ),
            (at(6.0, 0.6), Shape::capsule(0.1, 0.2)),
            (at(6.5, 0.6), Shape::cylinder(0.2, 0.1)),
            (
                BodyDef {
                    sensor: true,
                    kind: BodyKind::Static,
                    ..fixed(0.2)
                },
                Shape::sphere(1.0),
            ),
            (
                BodyDef {
                    one_way: Some(Vec3::Y),
                    kind: BodyKind::Kinematic,
                    ..at(-6.0, 0.5)
                },
                Shape::cuboid(v(1.0, 0.05, 1.0)),
            ),
            (at(-6.0, 1.0), Shape::sphere(0.2)),
            (at(-5.5, 1.0), Shape::sphere(0.2)),
            (at(2.0, 2.0), Shape::cuboid(Vec3::splat(0.2))),
        ]
    }

    fn rich_bodies(w: &mut World) -> Vec<BodyId> {
        let ids: Vec<BodyId> = rich_shapes()
            .into_iter()
            .map(|(def, shape)| w.create_body(&def, shape).unwrap())
            .collect();
        w.set_kinematic_target(ids[8], Vec3::new(-6.0, 0.6, 0.0), Quat::IDENTITY)
            .unwrap();
        w.exclude_contacts(ids[3], ids[4]).unwrap();
        let spring = Spring {
            body: ids[10],
            anchor: Vec3::ZERO,
            other: SpringEnd::Body {
                body: ids[11],
                anchor: Vec3::ZERO,
            },
            stiffness: 20.0,
            rest_length: 1.0,
            damping: 0.1,
        };
        w.add_force(Force::Spring(spring)).unwrap();
        let push = AppliedForce {
            body: ids[11],
            force: Vec3::X,
            point: Some(Vec3::Y),
            torque: Vec3::ZERO,
        };
        w.add_force(Force::Applied(push)).unwrap();
        ids
    }

    fn rich_joints(w: &mut World, ids: &[BodyId]) {
        let motor = Some(Motor {
            speed: 1.0,
            max_force: 5.0,
        });
        let spring = Some(JointSpring {
            hertz: 2.0,
            damping_ratio: 0.5,
            target: 0.1,
        });
        let servo = Some(Servo {
            target: 0.2,
            stiffness: 10.0,
            damping: 1.0,
            max_force: 5.0,
        });
        let kinds = [
            JointKind::Hinge {
                limits: Some([-0.5, 0.5]),
                motor,
                spring,
                servo: None,
            },
            JointKind::Slider {
                limits: Some([-0.2, 0.2]),
                motor: None,
                spring: None,
                servo,
            },
            JointKind::Ball {
                cone: Some(0.5),
                twist: Some([-0.3, 0.3]),
            },
            JointKind::Distance {
                length: Some(1.0),
                min: Some(0.5),
                max: Some(1.5),
                spring,
            },
        ];
        for (k, kind) in kinds.into_iter().enumerate() {
            let mut def = JointDef::new(kind, ids[5 + k % 2]);
            def.other = Some(ids[10 + k % 2]);
            def.break_force = Some(1e6);
            w.create_joint(&def).unwrap();
        }
    }

    /// The rich world's snapshot passes every check and continues as it was saved.
    #[test]
    fn the_rich_world_restores_whole() {
        let bytes = rich_snapshot();
        let mut w = World::new(&WorldDef::default());
        w.restore(bytes).unwrap();
        assert_eq!(w.snapshot(), bytes);
        assert!(!w.contacts().is_empty());
        w.step(0.01).unwrap();
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(1000))]

        /// The same for the world with something of every store, which then also answers
        /// queries and has a body removed.
        #[test]
        fn a_resealed_rich_world_that_restores_never_panics_a_step(
            edits in prop::collection::vec((any::<prop::sample::Index>(), any::<u8>()), 1..4)
        ) {
            let bytes = resealed_edit(rich_snapshot().to_vec(), &edits);
            let mut w = World::new(&WorldDef::default());
            if w.restore(&bytes).is_ok() {
                use_every_store(&mut w);
            }
        }
    }

    /// Overwrites bytes past the header where `edits` say, with what a crafted payload
    /// would hold rather than random bytes: a small integer as a `u32` or `u64` (an index
    /// or count that is wrong but plausible), a number against the rules (negative, zero,
    /// NaN, infinite, huge, tiny), `u32::MAX` (the trees' "none"), or four bytes swapped
    /// with four elsewhere.
    fn overwrite(bytes: &mut [u8], edits: &[(prop::sample::Index, u8, u32)]) {
        let numbers: [Real; 6] = [-1.0, 0.0, Real::NAN, Real::INFINITY, 1e30, -1e-30];
        let n = bytes.len() - HEADER;
        for &(at, how, v) in edits {
            let i = HEADER + at.index(n);
            let word = match how % 5 {
                0 => (v % 40).to_le_bytes().to_vec(),
                1 => (v as u64 % 40).to_le_bytes().to_vec(),
                2 => numbers[v as usize % numbers.len()].to_le_bytes().to_vec(),
                3 => u32::MAX.to_le_bytes().to_vec(),
                _ => {
                    let j = HEADER + (v as usize % n);
                    for k in 0..4 {
                        if i.max(j) + k < bytes.len() {
                            bytes.swap(i + k, j + k);
                        }
                    }
                    continue;
                }
            };
            let end = (i + word.len()).min(bytes.len());
            bytes[i..end].copy_from_slice(&word[..end - i]);
        }
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(1000))]

        /// Both worlds with plausible indices, counts and numbers written over their
        /// bytes: refused, or restored and used without a panic.
        #[test]
        fn a_resealed_world_with_crafted_values_never_panics_a_step(
            rich in any::<bool>(),
            edits in prop::collection::vec((any::<prop::sample::Index>(), any::<u8>(), any::<u32>()), 1..4)
        ) {
            let mut bytes = if rich { rich_snapshot().to_vec() } else { world().snapshot() };
            overwrite(&mut bytes, &edits);
            reseal(&mut bytes);
            let mut w = if rich { World::new(&WorldDef::default()) } else { world() };
            if w.restore(&bytes).is_ok() {
                use_every_store(&mut w);
            }
        }
    }

    /// Steps, saves, reads contacts, events, joints and sensors, casts and queries, and
    /// removes a body and steps again: every result or error is fine, a panic is not.
    fn use_every_store(w: &mut World) {
        use crate::{Aabb, QueryFilter, Ray};
        for _ in 0..3 {
            let _ = w.step(0.01);
        }
        let _ = (w.snapshot(), w.contacts().len(), w.contact_events().len());
        let ids = w.body_ids().to_vec();
        let any = QueryFilter::default();
        let ray = Ray::new(Vec3::new(-8.0, 0.3, 0.0), Vec3::X);
        let _ = w.cast_ray_all(&ray, 20.0, &any);
        let _ = w.query_aabb(&Aabb::new(Vec3::splat(-9.0), Vec3::splat(9.0)), &any);
        let _ = w.query_point(Vec3::new(0.0, 0.5, 0.0), &any);
        let joints: Vec<JointId> = w.joints().map(|(id, _)| id).collect();
        for id in joints {
            let _ = (w.joint_position(id), w.joint_velocity(id));
        }
        for &id in &ids {
            let _ = w.sensor_overlaps(id);
        }
        let _ = w.diagnostics();
        if let Some(&id) = ids.get(3) {
            let _ = w.remove_body(id);
        }
        let _ = w.step(0.01);
    }

    /// The small world's snapshot decoded, for a test to break one thing in.
    fn decoded() -> (Saved, (usize, usize)) {
        let bytes = world().snapshot();
        let saved = read_payload(&mut Reader::new(&bytes[HEADER..], HEADER)).unwrap();
        let counts = (saved.bodies.list.len(), saved.joints.list.len());
        (saved, counts)
    }

    /// Each reference out of range, count off or coefficient out of its rules is refused
    /// by name, with the index and what it indexes.
    #[test]
    fn a_broken_reference_is_refused_by_name() {
        type Break = fn(&mut Saved);
        let cases: [(Break, &str); 8] = [
            (
                |s| s.collision.contacts.contacts_mut()[0].index_b = 17,
                "contacts[0].index_b: body 17 of 4",
            ),
            (
                |s| s.joints.links[0][0] = Some(9),
                "joint_links[0][0]: body 9 of 4",
            ),
            (
                |s| s.joints.joined_pairs.push((2, 1)),
                "joined_pairs[0]: bodies 2 and 1",
            ),
            (
                |s| s.collision.proxies.swap(1, 2),
                "proxies[1]: proxy 2 is not body 1's",
            ),
            (
                |s| s.hooks.one_way_bodies = 1,
                "hooks.one_way_bodies: 1 but 0 bodies are one-way",
            ),
            (
                |s| s.sensors.sensor_bodies = 2,
                "sensors.sensor_bodies: 2 but 0 bodies are sensors",
            ),
            (
                |s| s.bodies.list[1].friction = -1.0,
                "bodies[1].friction: must be >= 0",
            ),
            (
                |s| s.settings.solver.substeps = 0,
                "settings.solver.substeps: must be >= 1",
            ),
        ];
        let (good, counts) = decoded();
        check(&good, counts).unwrap();
        for (break_it, message) in cases {
            let (mut s, counts) = decoded();
            break_it(&mut s);
            let err = check(&s, counts).unwrap_err().to_string();
            assert_eq!(err, format!("snapshot: {message}"));
        }
        let (mut s, counts) = decoded();
        let gone = s.bodies.ids()[0];
        s.joints.list[0].def.body = BodyId {
            generation: gone.generation + 1,
            ..gone
        };
        let err = check(&s, counts).unwrap_err().to_string();
        assert!(
            err.starts_with("snapshot: joints[0].body: unknown or removed body"),
            "{err}"
        );
    }

    #[test]
    fn a_length_that_lies_is_refused_without_allocating_it() {
        let good = world().snapshot();
        // The payload starts with the settings and the clock, of fixed sizes; then comes
        // the bodies' count, made huge here.
        let mut w = Writer::default();
        World::new(&WorldDef::default()).settings.put(&mut w);
        let clock = std::mem::size_of::<Real>() + 8;
        let at = HEADER + w.bytes.len() + clock;
        let mut bytes = good.clone();
        bytes[at..at + 8].copy_from_slice(&u64::MAX.to_le_bytes());
        reseal(&mut bytes);
        let err = match read(&bytes) {
            Err(e) => e.to_string(),
            Ok(_) => panic!("a count of 2^64 bodies was accepted"),
        };
        assert!(
            err.starts_with(&format!("snapshot: length {} at byte {at}", u64::MAX)),
            "{err}"
        );
    }
}
