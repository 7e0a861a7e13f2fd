//! The finite-state invariant, and the undo of a step that breaks it.
//!
//! Every step's result is checked before it is written back: each moving body's position,
//! orientation, velocity, angular velocity and angular momentum must be finite, its
//! position within `limits::MAX_COORDINATE`, its speeds within the world's
//! [`SpeedLimits`](crate::limits::SpeedLimits). A stiff spring under an explicit
//! integrator, a joint loop the solver pumps, a shape too thin to collide: such a run
//! grows for a while (to 1e135 before its first NaN, in one ragdoll) and the speed bound
//! stops it long before. The check is one pass over the step's solver bodies, which every
//! stage wrote into and nothing has read back yet.
//!
//! A step that fails is undone: the world is left as it was before the step, bit for bit,
//! and the error names the step, the time it would have reached, the body and the
//! quantity. Undoing is cheap because of the step's shape: bodies are written back only by
//! `scatter`, after the check, so they need nothing; the contact cache built its new
//! contacts beside last step's and swaps back; what remains (the sleep state
//! `wake_touched` changes, the joints' warm starts, reactions and broken flags, the
//! integrator's memory, the kinematic targets taken) is copied before the stages run,
//! about 30 bytes per body and 180 per joint. (Whole joints were copied before: a ninth
//! of a cart-pole's step in reduced coordinates, for fields no stage writes.)
//! Force callbacks are the user's code and are not undone. A callback that stops the
//! step (`ForceContext::fail`, how Python's exceptions leave a callback) has the step
//! undone the same way, by `check_callbacks` right after the stage that called it.

use crate::dynamics::body::{Body, BodyKind};
use crate::dynamics::integrate::IntegratorMemory;
use crate::dynamics::joint::{Joint, JointImpulses};
use crate::dynamics::solver::{SolverBodies, StepTime};
use crate::error::{CallbackFailed, Error, Result, TooManyContacts, Unstable};
use crate::limits::{short, SpeedLimits, MAX_COORDINATE};
use crate::math::{vec3_is_finite, Quat, Real, Vec3};
use crate::pipeline::world::World;

/// What a step changes before its check, as it was before the step.
#[derive(Default)]
pub(crate) struct Undo {
    /// Per body: awake, sleep timer.
    sleep: Vec<(bool, Real)>,
    joints: Vec<JointUndo>,
    memory: IntegratorMemory,
    /// The kinematic targets the step took: body, target, velocity and angular velocity
    /// before (see `take_kinematic_targets`).
    pub(super) targets: Vec<(usize, (Vec3, Quat), Vec3, Vec3)>,
}

/// What a step's stages write in a joint before its check (the solver's warm starts,
/// reactions and a break; the hinge angle is followed after the check).
#[derive(Clone, Copy)]
struct JointUndo {
    impulses: JointImpulses,
    reaction: (Vec3, Vec3),
    broken: bool,
}

impl JointUndo {
    fn of(j: &Joint) -> JointUndo {
        JointUndo {
            impulses: j.impulses,
            reaction: (j.reaction_force, j.reaction_torque),
            broken: j.broken,
        }
    }

    fn restore(&self, j: &mut Joint) {
        j.impulses = self.impulses;
        (j.reaction_force, j.reaction_torque) = self.reaction;
        j.broken = self.broken;
    }
}

impl World {
    /// Keeps what the stages before `scatter` change, so that the step can be undone.
    pub(super) fn keep_undo(&mut self) {
        let undo = &mut self.scratch.undo;
        undo.sleep.clear();
        undo.sleep
            .extend(self.bodies.list.iter().map(|b| (b.awake, b.sleep_time)));
        undo.joints.clear();
        undo.joints
            .extend(self.joints.list.iter().map(JointUndo::of));
        undo.memory.clone_from(&self.memory);
        undo.targets.clear();
    }

    /// Checks the step's result; on failure undoes the step and says where and when.
    pub(super) fn check_result(&mut self, time: &StepTime) -> Result<()> {
        let limits = self.settings.limits;
        let Some((index, quantity, problem)) =
            first_violation(&self.bodies.list, &self.scratch.bodies, &limits)
        else {
            return Ok(());
        };
        self.undo();
        let body = &self.bodies.list[index];
        Err(Error::Unstable(Box::new(Unstable {
            step: self.clock.steps + 1,
            time: time.t + time.dt,
            index,
            body: self.bodies.ids()[index],
            name: body.name.clone(),
            quantity,
            problem,
        })))
    }

    /// Fails the step if its contact update stopped at the step's manifold limit: the
    /// solver would otherwise run on an arbitrary part of the scene's contacts.
    pub(super) fn check_contacts(&mut self, time: &StepTime) -> Result<()> {
        if !self.collision.contacts.overflowed() {
            return Ok(());
        }
        self.undo();
        Err(Error::TooManyContacts(Box::new(TooManyContacts {
            step: self.clock.steps + 1,
            time: time.t + time.dt,
            limit: self.settings.contacts.per_step,
        })))
    }

    /// Fails the step if a force callback stopped it (`ForceContext::fail`): the
    /// integrator or the solver ran on without the callbacks after that, so the step's
    /// result is not the forces' and is thrown away.
    pub(super) fn check_callbacks(&mut self, time: &StepTime) -> Result<()> {
        let Some(reason) = self.forces.failure.take() else {
            return Ok(());
        };
        self.undo();
        Err(Error::CallbackFailed(Box::new(CallbackFailed {
            step: self.clock.steps + 1,
            time: time.t + time.dt,
            reason,
        })))
    }

    fn undo(&mut self) {
        let undo = &mut self.scratch.undo;
        for (b, &(awake, sleep_time)) in self.bodies.list.iter_mut().zip(&undo.sleep) {
            b.awake = awake;
            b.sleep_time = sleep_time;
        }
        for (j, kept) in self.joints.list.iter_mut().zip(&undo.joints) {
            kept.restore(j);
        }
        std::mem::swap(&mut self.memory, &mut undo.memory);
        for &(i, target, v, w) in &undo.targets {
            let b = &mut self.bodies.list[i];
            (b.kinematic_target, b.velocity, b.angular_velocity) = (Some(target), v, w);
        }
        self.collision.contacts.undo_update();
    }
}

/// The first moving body whose new state breaks the invariant: its index, the quantity and
/// what is wrong with it.
fn first_violation(
    bodies: &[Body],
    step: &SolverBodies,
    limits: &SpeedLimits,
) -> Option<(usize, &'static str, String)> {
    let (v_max, w_max) = (limits.max_speed, limits.max_angular_speed);
    let states = step.sims.iter().zip(&step.states);
    for (i, (body, (sim, state))) in bodies.iter().zip(states).enumerate() {
        if body.kind == BodyKind::Static {
            continue;
        }
        let q = sim.q;
        // One comparison each, written so that NaN fails it too.
        let fine = sim.x.abs().max_element() <= MAX_COORDINATE
            && (q.x + q.y + q.z + q.w).is_finite()
            && state.v.length_squared() <= v_max * v_max
            && state.w.length_squared() <= w_max * w_max
            && sim.l.is_finite();
        if !fine {
            return Some(explain(i, sim.x, q, state.v, state.w, sim.l, limits));
        }
    }
    None
}

/// Which quantity of a body that failed the check is wrong, and how.
fn explain(
    i: usize,
    x: Vec3,
    q: crate::math::Quat,
    v: Vec3,
    w: Vec3,
    l: Vec3,
    limits: &SpeedLimits,
) -> (usize, &'static str, String) {
    let not_finite = || "is not finite".to_string();
    let beyond = |what: &str, x: Real, limit: Real, unit: &str, name: &str| {
        format!(
            "reached {what} {} {unit}, beyond {name} = {} {unit}",
            short(x),
            short(limit)
        )
    };
    let finite_q = [q.x, q.y, q.z, q.w].iter().all(|c| c.is_finite());
    let found = if !vec3_is_finite(x) {
        ("position", not_finite())
    } else if !finite_q {
        ("orientation", not_finite())
    } else if !vec3_is_finite(v) {
        ("velocity", not_finite())
    } else if !vec3_is_finite(w) {
        ("angular_velocity", not_finite())
    } else if !vec3_is_finite(l) {
        ("angular_momentum", not_finite())
    } else if x.abs().max_element() > MAX_COORDINATE {
        let far = x.abs().max_element();
        (
            "position",
            beyond("a coordinate of", far, MAX_COORDINATE, "m", "the limit"),
        )
    } else if v.length() > limits.max_speed {
        let s = v.length();
        (
            "velocity",
            beyond("the speed", s, limits.max_speed, "m/s", "max_speed"),
        )
    } else {
        let s = w.length();
        let name = "max_angular_speed";
        (
            "angular_velocity",
            beyond(
                "the angular speed",
                s,
                limits.max_angular_speed,
                "rad/s",
                name,
            ),
        )
    };
    (i, found.0, found.1)
}
