//! Run-time changes to a joint: its motor, servo, limits and spring, whether it is
//! enabled, and its break force. Each is checked as `create_joint` checks a definition
//! (the same field names: `motor.max_force: must be >= 0`), changes nothing when refused,
//! and wakes both bodies.

use super::joints::unknown;
use crate::dynamics::joint::{self, JointOption, JointSpring, Motor, OptionValue, Servo};
use crate::dynamics::joint::{JointId, JointKind};
use crate::error::{Error, Result};
use crate::math::Real;
use crate::pipeline::world::World;

impl World {
    /// Sets (or with `None` removes) a hinge's or slider's velocity motor. Refused on a
    /// kind with no motor (`motor: not an option of a ball joint (its options: cone,
    /// twist)`) and on bad numbers (`motor.max_force: must be >= 0`).
    pub fn set_joint_motor(&mut self, id: JointId, motor: Option<Motor>) -> Result<()> {
        self.set_joint_option(id, JointOption::Motor, motor.map(OptionValue::Motor))
    }

    /// Sets (or removes) a hinge's or slider's position servo (see [`Servo`]).
    pub fn set_joint_servo(&mut self, id: JointId, servo: Option<Servo>) -> Result<()> {
        self.set_joint_option(id, JointOption::Servo, servo.map(OptionValue::Servo))
    }

    /// Sets (or removes) a hinge's or slider's limits `[lower, upper]` (rad or m); for a
    /// ball joint use [`World::set_joint_option`] with `JointOption::Twist`.
    pub fn set_joint_limits(&mut self, id: JointId, limits: Option<[Real; 2]>) -> Result<()> {
        self.set_joint_option(id, JointOption::Limits, limits.map(OptionValue::Range))
    }

    /// Sets (or removes) the spring of a hinge, slider or distance joint.
    pub fn set_joint_spring(&mut self, id: JointId, spring: Option<JointSpring>) -> Result<()> {
        self.set_joint_option(id, JointOption::Spring, spring.map(OptionValue::Spring))
    }

    /// Sets (or with `None` removes) any option the joint's kind takes (its keys are those
    /// of scene files: `cone`, `twist`, `limits`, `motor`, `spring`, `servo`, `length`,
    /// `min`, `max`). The joint's other options must still agree with the new value
    /// (`min: must be <= max`). The accumulated impulses of the joint's free coordinate are
    /// dropped, so nothing of the old setting is applied again.
    pub fn set_joint_option(
        &mut self,
        id: JointId,
        option: JointOption,
        value: Option<OptionValue>,
    ) -> Result<()> {
        let k = self.joints.handles.dense(id).ok_or_else(|| unknown(id))?;
        let joint = &self.joints.list[k];
        let spec = joint.def.kind.spec();
        if !spec.takes(option) {
            let keys: Vec<&str> = spec.keys().collect();
            let keys = if keys.is_empty() {
                "none".to_string()
            } else {
                keys.join(", ")
            };
            let reason = format!(
                "not an option of a {} joint (its options: {keys})",
                spec.name
            );
            return Err(Error::invalid(option.key(), reason));
        }
        let mut options = joint.def.kind.options();
        clear(&mut options, option);
        if let Some(value) = value {
            options.set(option, value)?;
        }
        let kind = JointKind::from_options(spec.name, &options)
            .ok_or_else(|| Error::invalid("kind", "unknown joint kind"))?;
        let mut def = joint.def.clone();
        def.kind = kind;
        joint::validate(&def)?;
        let joint = &mut self.joints.list[k];
        joint.def.kind = kind;
        if let Some(length) = options.length.filter(|_| option == JointOption::Length) {
            // The rest length a distance joint holds (left out again: kept as it is).
            joint.length = length;
        }
        let imp = &mut joint.impulses;
        (
            imp.lower, imp.upper, imp.motor, imp.spring, imp.servo, imp.axial,
        ) = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0);
        self.wake_joint(k);
        Ok(())
    }

    /// Turns a joint off (`false`) or back on. A disabled joint is not solved, keeps its
    /// bodies from colliding no more (as if it were not there: `collide_connected` no
    /// longer matters) and reports no reaction; enabled again, it holds from the bodies'
    /// poses then, measuring its angles from its creation as before. A broken joint stays
    /// broken.
    pub fn set_joint_enabled(&mut self, id: JointId, enabled: bool) -> Result<()> {
        let k = self.joints.handles.dense(id).ok_or_else(|| unknown(id))?;
        let joint = &mut self.joints.list[k];
        if joint.enabled != enabled {
            joint.enabled = enabled;
            joint.impulses = Default::default();
            joint.reaction_force = crate::math::Vec3::ZERO;
            joint.reaction_torque = crate::math::Vec3::ZERO;
            self.refresh_joint_links();
        }
        self.wake_joint(k);
        Ok(())
    }

    /// Sets the reaction force (N) beyond which the joint breaks (`None`: unbreakable);
    /// refused unless > 0 (`break_force: must be > 0`). It is compared with the next
    /// step's reaction; a joint already broken stays broken.
    pub fn set_joint_break_force(&mut self, id: JointId, break_force: Option<Real>) -> Result<()> {
        let k = self.joints.handles.dense(id).ok_or_else(|| unknown(id))?;
        let mut def = self.joints.list[k].def.clone();
        def.break_force = break_force;
        joint::validate(&def)?;
        self.joints.list[k].def.break_force = break_force;
        self.wake_joint(k);
        Ok(())
    }

    /// Sets a hinge's or slider's armature (see [`joint::JointDef::armature`]); refused unless
    /// finite and ≥ 0 (`armature: must be >= 0`), or > 0 on another kind of joint.
    pub fn set_joint_armature(&mut self, id: JointId, armature: Real) -> Result<()> {
        let k = self.joints.handles.dense(id).ok_or_else(|| unknown(id))?;
        joint::check_armature(armature, &self.joints.list[k].def.kind)?;
        let j = &mut self.joints.list[k];
        j.def.armature = armature;
        if armature == 0.0 {
            // The flywheel's push is warm started with the free row's impulses: without a
            // flywheel left to answer it, it would push on for good.
            (j.impulses.armature, j.impulses.flywheel_lag) = (0.0, 0.0);
        }
        self.wake_joint(k);
        Ok(())
    }

    /// Wakes the bodies of joint `k` (dense) and what touches them.
    pub(super) fn wake_joint(&mut self, k: usize) {
        let def = &self.joints.list[k].def;
        let bodies = [Some(def.body), def.other];
        let dense: Vec<usize> = bodies
            .into_iter()
            .flatten()
            .filter_map(|b| self.dense(b))
            .collect();
        for i in dense {
            self.wake_around(i);
        }
    }
}

/// Removes `option`'s value from `options`.
fn clear(options: &mut joint::JointOptions, option: JointOption) {
    match option {
        JointOption::Cone => options.cone = None,
        JointOption::Twist => options.twist = None,
        JointOption::Limits => options.limits = None,
        JointOption::Motor => options.motor = None,
        JointOption::Spring => options.spring = None,
        JointOption::Servo => options.servo = None,
        JointOption::Length => options.length = None,
        JointOption::Min => options.min = None,
        JointOption::Max => options.max = None,
    }
}
