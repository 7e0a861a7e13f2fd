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
//! A snapshot is read completely and checked before anything is swapped in, so a bad one
//! leaves the world as it was.

use super::{BodyStore, Clock, CollisionStore, ForceStore, JointStore, Settings, World, WorldDef};
use crate::codec::{checksum, Code, Decoded, Malformed, Reader, Writer};
use crate::dynamics::integrate::IntegratorMemory;
use crate::error::{Error, Result};
use crate::math::Real;
use crate::pipeline::hooks::Hooks;
use crate::pipeline::sensors::SensorStore;

/// The snapshot format version this build writes and reads.
pub const SNAPSHOT_VERSION: u32 = 4;
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

/// The stores' lengths agree with each other and with the header: what a world indexes
/// by body or joint without checking.
fn check(s: &Saved, (bodies, joints): (usize, usize)) -> Result<()> {
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

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(300))]

        /// Past the checksum, a changed payload is decoded with every length checked: an
        /// error or a world, never a panic or an allocation the bytes cannot back. (A
        /// payload crafted to pass the checksum is otherwise trusted: see the module notes.)
        #[test]
        fn a_resealed_mutated_payload_never_panics_the_decoder(
            edits in prop::collection::vec((any::<prop::sample::Index>(), any::<u8>()), 1..8)
        ) {
            let good = world().snapshot();
            let mut bytes = good.clone();
            for (at, value) in edits {
                let i = HEADER + at.index(bytes.len() - HEADER);
                bytes[i] = value;
            }
            reseal(&mut bytes);
            let _ = read(&bytes);
        }
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
