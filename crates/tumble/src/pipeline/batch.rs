//! A batch: W independent copies of one world, stepped together on a thread pool.
//!
//! Learning a controller or measuring a sensitivity runs one model thousands of times.
//! Worlds are the unit of parallelism here: each copy steps on one thread (its own
//! [`World::threads`] is 1), and the batch hands whole worlds to the threads of its pool
//! (rayon's, shared with every world and batch of the same thread count, see
//! `threads.rs`). A copy never reads another, so a copy's step is the very step it would
//! take alone, bit for bit, whatever the batch's thread count and whichever thread runs
//! it.
//!
//! The copies are made through snapshots (`World::snapshot` into `World::restore`), the
//! path already held bit-identical to a run that never stopped; the snapshot the batch was
//! made from is kept, and [`Batch::reset`] returns chosen copies to it. A world with code
//! attached (force callbacks, a contact filter or modifier) cannot be copied and is
//! refused.
//!
//! Every call that takes per-world values is all or nothing: every value is checked,
//! naming the world and the row (`worlds[2].velocities[1]: must be finite numbers`),
//! before any world changes, and each change wakes the bodies it touches, as the world's
//! own setters do.

use std::sync::Arc;

use rayon::prelude::*;

use crate::dynamics::force::{AppliedForce, Force};
use crate::dynamics::joint::{JointOption, OptionValue};
use crate::error::{check, Error, Result};
use crate::id::{BodyId, ForceId};
use crate::math::{Real, Vec3};
use crate::pipeline::world::bulk::BodyStates;
use crate::pipeline::world::{World, WorldDef};

/// A failed step of one world of a batch: which world, and the world's own error (the
/// step was undone: that world is at its last completed step; the other worlds finished
/// theirs).
#[derive(Debug, Clone, PartialEq)]
pub struct StepFailure {
    /// The world's index in the batch.
    pub world: usize,
    /// What the world's step returned.
    pub error: Error,
}

impl std::fmt::Display for StepFailure {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "worlds[{}]: {}", self.world, self.error)
    }
}

impl std::error::Error for StepFailure {}

/// What [`Batch::set_joint_targets`] drives: a motor's target speed or a servo's target
/// position.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum JointTarget {
    /// The joint's motor's `speed` (rad/s or m/s).
    Velocity,
    /// The joint's servo's `target` (rad or m).
    Position,
}

/// W copies of a world, stepped together (see the module's documentation).
pub struct Batch {
    worlds: Vec<World>,
    /// The snapshot the copies were made from, which `reset` restores.
    initial: Vec<u8>,
    /// The bodies every copy was made with, in creation order.
    bodies: Vec<BodyId>,
    /// Per world, the force elements of the last `set_forces`.
    applied: Vec<Vec<ForceId>>,
    threads: usize,
    pool: Option<Arc<rayon::ThreadPool>>,
}

/// `worlds` with a reason, for refused per-world values.
fn world_field(i: usize) -> String {
    format!("worlds[{i}]")
}

impl Batch {
    /// `copies` copies of `world` (as it is now), stepped on `threads` threads (`None`:
    /// the default count of [`crate::threads::default_threads`]). Refused for no copies,
    /// a bad thread count, and a world with force callbacks or a contact filter or
    /// modifier (code, which a snapshot does not copy).
    pub fn new(world: &World, copies: usize, threads: Option<usize>) -> Result<Batch> {
        if copies == 0 {
            return Err(Error::invalid("copies", "must be >= 1, got 0"));
        }
        let threads = match threads {
            Some(n) => crate::threads::check(n)?,
            None => crate::threads::default_threads(),
        };
        if !world.forces.callbacks.is_empty() {
            return Err(Error::invalid(
                "world",
                "has force callbacks, which are code and cannot be copied",
            ));
        }
        if world.hooks.has_code() {
            return Err(Error::invalid(
                "world",
                "has a contact filter or modifier, which is code and cannot be copied",
            ));
        }
        let initial = world.snapshot();
        let mut worlds = Vec::new();
        worlds
            .try_reserve_exact(copies)
            .map_err(|e| Error::invalid("copies", format!("{copies} worlds: {e}")))?;
        for _ in 0..copies {
            worlds.push(copy_of(&initial)?);
        }
        Ok(Batch {
            worlds,
            bodies: world.body_ids().to_vec(),
            initial,
            applied: vec![Vec::new(); copies],
            threads,
            pool: None,
        })
    }

    /// How many worlds (W, at least 1).
    pub fn len(&self) -> usize {
        self.worlds.len()
    }

    /// Always false: a batch has at least one world.
    pub fn is_empty(&self) -> bool {
        self.worlds.is_empty()
    }

    /// How many threads the batch steps its worlds on.
    pub fn threads(&self) -> usize {
        self.threads
    }

    /// Changes the thread count (1 to `MAX_THREADS`); results do not depend on it.
    pub fn set_threads(&mut self, threads: usize) -> Result<()> {
        self.threads = crate::threads::check(threads)?;
        self.pool = None;
        Ok(())
    }

    /// The bodies each world was made with, in creation order (the rows of the bulk
    /// arrays).
    pub fn body_ids(&self) -> &[BodyId] {
        &self.bodies
    }

    /// The snapshot the worlds were made from.
    pub fn initial(&self) -> &[u8] {
        &self.initial
    }

    /// World `i`; refused (`world: index 5 out of range for a batch of 4 worlds`) past the
    /// last.
    pub fn world(&self, i: usize) -> Result<&World> {
        let w = self.len();
        self.worlds
            .get(i)
            .ok_or_else(|| out_of_range("world", i, w))
    }

    /// World `i`, to edit. An edit that adds or removes bodies makes the batch's bulk
    /// calls refuse that world (`worlds[i]: ...`) until it is reset.
    pub fn world_mut(&mut self, i: usize) -> Result<&mut World> {
        let w = self.len();
        self.worlds
            .get_mut(i)
            .ok_or_else(|| out_of_range("world", i, w))
    }

    /// Every world, in order.
    pub fn worlds(&self) -> &[World] {
        &self.worlds
    }

    /// Steps every world `steps` times by `dt` (s), the worlds spread over the batch's
    /// threads. A world whose step fails stays at its last completed step while the
    /// others finish theirs; the failure of the lowest-numbered such world is returned.
    /// A bad `dt` is refused before any world steps.
    pub fn step(&mut self, dt: Real, steps: u64) -> std::result::Result<(), StepFailure> {
        check::positive("dt", dt).map_err(|error| StepFailure { world: 0, error })?;
        let all = self.len();
        self.step_worlds(0, &mut vec![(); all], 0..steps, |_| dt, |_, _, _| ())
    }

    /// Steps worlds `first..first + each.len()` through the steps numbered `steps` (step
    /// `k` lasts `dt(k)` seconds), each world all its steps in a row (its data stays in
    /// the cache: stepping every world once, then every world again, costs a tiny world
    /// twice as much, measured on 1,024 cart-poles), calling `after(&mut each[i], k,
    /// world)` after its step `k`; the worlds are spread over the batch's threads. A
    /// world whose step fails stays at its last completed step and takes no further
    /// steps; the others finish theirs, and the lowest-numbered failure is returned.
    /// Worlds past the end are refused (`world: index ...`) before any steps.
    pub fn step_worlds<S: Send>(
        &mut self,
        first: usize,
        each: &mut [S],
        steps: std::ops::Range<u64>,
        dt: impl Fn(u64) -> Real + Sync,
        after: impl Fn(&mut S, u64, &World) + Sync,
    ) -> std::result::Result<(), StepFailure> {
        let w = self.len();
        let end = first.saturating_add(each.len());
        if end > w {
            let error = out_of_range("world", end - 1, w);
            return Err(StepFailure {
                world: first,
                error,
            });
        }
        let run = |(i, (world, s)): (usize, (&mut World, &mut S))| -> Option<StepFailure> {
            for k in steps.clone() {
                if let Err(error) = world.step(dt(k)) {
                    return Some(StepFailure {
                        world: first + i,
                        error,
                    });
                }
                after(s, k, world);
            }
            None
        };
        let worlds = &mut self.worlds[first..end];
        // Every world runs all its steps, whichever fails (no short-circuit: which worlds
        // had stepped when another failed would depend on order or timing); the lowest
        // index reports.
        let serial = |worlds: &mut [World], each: &mut [S]| {
            let failures: Vec<StepFailure> = worlds
                .iter_mut()
                .zip(each)
                .enumerate()
                .filter_map(run)
                .collect();
            failures.into_iter().next()
        };
        if self.threads > 1 && worlds.len() > 1 && self.pool.is_none() {
            self.pool = crate::threads::shared_pool(self.threads);
        }
        let failure = match &self.pool {
            Some(pool) if self.threads > 1 && worlds.len() > 1 => pool.install(|| {
                worlds
                    .par_iter_mut()
                    .zip(each.par_iter_mut())
                    .enumerate()
                    .filter_map(run)
                    .min_by_key(|f| f.world)
            }),
            _ => serial(worlds, each),
        };
        failure.map_or(Ok(()), Err)
    }

    /// The indices `worlds` checked against the batch (every world for `None`).
    fn chosen(&self, worlds: Option<&[usize]>) -> Result<Vec<usize>> {
        let w = self.len();
        match worlds {
            None => Ok((0..w).collect()),
            Some(list) => {
                for (k, &i) in list.iter().enumerate() {
                    if i >= w {
                        return Err(out_of_range(&format!("worlds[{k}]"), i, w));
                    }
                }
                Ok(list.to_vec())
            }
        }
    }

    /// Returns the chosen worlds (every world for `None`) to the state the batch was made
    /// from; with `snapshot`, to that snapshot's state instead, which must hold the
    /// batch's bodies. Forces set by [`Batch::set_forces`] are dropped from those worlds
    /// (they are part of the state a snapshot replaces). All or nothing.
    pub fn reset(&mut self, worlds: Option<&[usize]>, snapshot: Option<&[u8]>) -> Result<()> {
        self.reset_with_states(worlds, snapshot, None)
    }

    /// [`Batch::reset`], then `states[k]` set in the k-th world chosen, as
    /// [`Batch::set_states`] sets them; every row is checked against the state reset to
    /// before any world changes (all or nothing).
    pub fn reset_with_states(
        &mut self,
        worlds: Option<&[usize]>,
        snapshot: Option<&[u8]>,
        states: Option<&[BodyStates<'_>]>,
    ) -> Result<()> {
        let chosen = self.chosen(worlds)?;
        let bytes = snapshot.unwrap_or(&self.initial[..]);
        let probe = copy_of(bytes)?;
        if probe.body_ids() != self.bodies.as_slice() {
            return Err(Error::snapshot(format!(
                "holds {} bodies, not the {} bodies of the batch's worlds",
                probe.body_count(),
                self.bodies.len()
            )));
        }
        if let Some(states) = states {
            count_states(states.len(), chosen.len())?;
            for (&i, s) in chosen.iter().zip(states) {
                probe
                    .check_states(s)
                    .map_err(|e| e.within(&world_field(i)))?;
            }
        }
        for (k, &i) in chosen.iter().enumerate() {
            // Checked above on a world of the same kind (no callbacks, one thread): none
            // of these fails.
            self.worlds[i].restore(bytes)?;
            self.applied[i].clear();
            if let Some(s) = states.map(|s| &s[k]) {
                self.worlds[i].set_states(s)?;
            }
        }
        Ok(())
    }

    /// World `i`'s body count checked against the batch's.
    fn same_bodies(&self, i: usize) -> Result<()> {
        if self.worlds[i].body_ids() != self.bodies.as_slice() {
            return Err(Error::invalid(
                world_field(i),
                "its bodies were added or removed since the batch was made; reset it",
            ));
        }
        Ok(())
    }

    /// Sets bodies' states in several worlds at once: `states[k]` for world `worlds[k]`
    /// (world k for `None`, one entry per world), each as [`World::set_states`]. Every
    /// row of every world is checked before any world changes; errors name the world
    /// (`worlds[3].positions[1]: ...`).
    pub fn set_states(
        &mut self,
        worlds: Option<&[usize]>,
        states: &[BodyStates<'_>],
    ) -> Result<()> {
        let chosen = self.chosen(worlds)?;
        count_states(states.len(), chosen.len())?;
        for (&i, s) in chosen.iter().zip(states) {
            self.same_bodies(i)?;
            self.worlds[i]
                .check_states(s)
                .map_err(|e| e.within(&world_field(i)))?;
        }
        for (&i, s) in chosen.iter().zip(states) {
            self.worlds[i].set_states(s)?;
        }
        Ok(())
    }
}

/// A world continuing `bytes`, stepping on one thread.
fn copy_of(bytes: &[u8]) -> Result<World> {
    let mut w = World::new(&WorldDef {
        threads: Some(1),
        ..WorldDef::default()
    });
    w.restore(bytes)?;
    Ok(w)
}

fn count_states(given: usize, worlds: usize) -> Result<()> {
    if given != worlds {
        let reason = format!("expected {worlds} entries (one per world), got {given}");
        return Err(Error::invalid("states", reason));
    }
    Ok(())
}

fn out_of_range(field: &str, i: usize, w: usize) -> Error {
    Error::invalid(
        field,
        format!("index {i} out of range for a batch of {w} worlds"),
    )
}

impl Batch {
    /// Sets constant forces (N, world frame, at the centre of mass) and torques (N·m),
    /// one row per body of every world, world after world (`forces[w * N + b]`), held
    /// from now on, every step, until the next `set_forces` or [`Batch::clear_forces`]:
    /// as [`World::add_force`]'s applied forces, which this adds (one element per body
    /// with a non-zero row) and removes. All or nothing; wakes the bodies pushed, and
    /// those no longer pushed.
    pub fn set_forces(&mut self, forces: &[Vec3], torques: Option<&[Vec3]>) -> Result<()> {
        let n = self.bodies.len();
        let rows = self.len() * n;
        for (name, len) in [
            ("forces", Some(forces.len())),
            ("torques", torques.map(<[_]>::len)),
        ] {
            match len {
                Some(l) if l != rows => {
                    let reason = format!(
                        "expected {rows} rows ({} worlds of {n} bodies), got {l}",
                        self.len()
                    );
                    return Err(Error::invalid(name, reason));
                }
                _ => {}
            }
        }
        for i in 0..self.len() {
            self.same_bodies(i)?;
        }
        let torque = |r: usize| torques.map_or(Vec3::ZERO, |t| t[r]);
        for (r, &force) in forces.iter().enumerate() {
            let row = |name: &str| format!("worlds[{}].{name}[{}]", r / n, r % n);
            check::vec3(&row("forces"), force)?;
            check::vec3(&row("torques"), torque(r))?;
        }
        self.clear_forces();
        for (i, world) in self.worlds.iter_mut().enumerate() {
            for (b, &body) in self.bodies.iter().enumerate() {
                let (force, torque) = (forces[i * n + b], torque(i * n + b));
                if force == Vec3::ZERO && torque == Vec3::ZERO {
                    continue;
                }
                let applied = AppliedForce {
                    body,
                    force,
                    point: None,
                    torque,
                };
                self.applied[i].push(world.add_force(Force::Applied(applied))?);
            }
        }
        Ok(())
    }

    /// Removes the forces of [`Batch::set_forces`] from every world, waking their bodies.
    pub fn clear_forces(&mut self) {
        for (world, ids) in self.worlds.iter_mut().zip(&mut self.applied) {
            for id in ids.drain(..) {
                // An id a restore made stale is already gone.
                let _ = world.remove_force(id);
            }
        }
    }

    /// Sets the target of the joint called `joint` in every world, `values[i]` in world i:
    /// its motor's speed ([`JointTarget::Velocity`], rad/s or m/s) or its servo's target
    /// ([`JointTarget::Position`], rad or m), keeping the motor's or servo's other
    /// settings, as [`World::set_joint_option`] would (waking both bodies, dropping the
    /// coordinate's accumulated impulses). Refused, changing nothing, for an unknown
    /// joint name, a joint without that motor or servo, or a value that is not finite.
    pub fn set_joint_targets(
        &mut self,
        joint: &str,
        target: JointTarget,
        values: &[Real],
    ) -> Result<()> {
        if values.len() != self.len() {
            let reason = format!(
                "expected {} values (one per world), got {}",
                self.len(),
                values.len()
            );
            return Err(Error::invalid("values", reason));
        }
        for (i, &v) in values.iter().enumerate() {
            check::finite(&format!("values[{i}]"), v)?;
        }
        let option = match target {
            JointTarget::Velocity => JointOption::Motor,
            JointTarget::Position => JointOption::Servo,
        };
        let mut edits = Vec::with_capacity(self.len());
        for (i, world) in self.worlds.iter().enumerate() {
            let id = world.find_joint(joint).ok_or_else(|| {
                Error::invalid("joint", format!("no joint named '{joint}'")).within(&world_field(i))
            })?;
            let current = world.joint(id)?.kind().options().get(option);
            let value = match (current, values[i]) {
                (Some(OptionValue::Motor(m)), v) => {
                    OptionValue::Motor(crate::Motor { speed: v, ..m })
                }
                (Some(OptionValue::Servo(s)), v) => {
                    OptionValue::Servo(crate::Servo { target: v, ..s })
                }
                _ => {
                    let what = if option == JointOption::Motor {
                        "motor"
                    } else {
                        "servo"
                    };
                    let reason = format!(
                        "joint '{joint}' has no {what} to set the target of; give it one first"
                    );
                    return Err(Error::invalid("joint", reason).within(&world_field(i)));
                }
            };
            edits.push((id, value));
        }
        for (world, (id, value)) in self.worlds.iter_mut().zip(edits) {
            world.set_joint_option(id, option, Some(value))?;
        }
        Ok(())
    }
}
