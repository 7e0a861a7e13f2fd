//! Actuator controls (MuJoCo's `ctrl`) as Tumble servos and motors, joint by joint:
//!
//! ```text
//! motor     τ = gear · ctrl                      a motor at full force towards ± any speed
//! position  τ = kp (ctrl − q) − kv q̇             the joint's servo: stiffness and target
//! velocity  τ = kv (ctrl − q̇) = kv ctrl − kv q̇   the servo's damping plus a constant torque
//! ```
//!
//! The joint's own spring and damper (τ = −k (q − springref) − c q̇) and every position
//! and velocity actuator on it add into one servo (stiffness Σk, target the
//! stiffness-weighted mean of the targets, damping Σc), exactly the sum of the laws; the
//! constant torques add into one motor, whose force bound is the torque and whose speed
//! no joint reaches, so it pushes with exactly that torque. `forcerange` clamps each
//! motor's and velocity actuator's constant part; it is not applied to servos.

use tumble::{Motor, Real, Servo, World};

use super::{ImportedMjcf, SceneError};
use crate::error::{printable, Result};

/// A servo's force bound when nothing limits it (N·m or N): in effect none.
const UNLIMITED: Real = 1e12;
/// The speed a constant-torque motor drives towards (rad/s or m/s): beyond any joint's.
const MOTOR_SPEED: Real = 1e9;

impl ImportedMjcf {
    /// Sets actuator `name`'s control (clamped to its `ctrlrange`, as MuJoCo does) and
    /// updates its joint's servo and motor. Wakes the joint's bodies.
    pub fn set_control(&mut self, world: &mut World, name: &str, control: Real) -> Result<()> {
        let field = format!("actuator '{}'", printable(name));
        let Some(i) = self.actuators.iter().position(|a| a.name == name) else {
            return Err(SceneError::new(field, "no such actuator"));
        };
        if !control.is_finite() {
            return Err(SceneError::new(field, "control: must be a finite number"));
        }
        let a = &mut self.actuators[i];
        a.control = match a.ctrl_range {
            Some([lo, hi]) => control.clamp(lo, hi),
            None => control,
        };
        let id = a.id;
        let (servo, motor) = self.drive(id);
        let engine = |e| SceneError::from_engine(e, &field);
        world.set_joint_servo(id, servo).map_err(engine)?;
        world.set_joint_motor(id, motor).map_err(engine)
    }

    /// The servo and motor of joint `id` for the controls now set.
    fn drive(&self, id: tumble::JointId) -> (Option<Servo>, Option<Motor>) {
        let (k, rest, c) = self
            .joints
            .iter()
            .find(|j| j.id == Some(id))
            .map_or((0.0, 0.0, 0.0), |j| j.spring);
        let reference = self
            .joints
            .iter()
            .find(|j| j.id == Some(id))
            .map_or(0.0, |j| j.reference);
        let (mut stiff, mut pull, mut damp, mut torque) = (k, k * rest, c, 0.0);
        for a in self.actuators.iter().filter(|a| a.id == id) {
            let clamp = |t: Real| match a.force_range {
                Some([lo, hi]) => t.clamp(lo, hi),
                None => t,
            };
            match a.kind.as_str() {
                "motor" => torque += clamp(a.gain * a.control),
                "position" => {
                    stiff += a.gain;
                    pull += a.gain * (a.control - reference);
                    damp += a.damping;
                }
                _ => {
                    damp += a.gain;
                    torque += clamp(a.gain * a.control);
                }
            }
        }
        let servo = (stiff > 0.0 || damp > 0.0).then(|| Servo {
            target: if stiff > 0.0 { pull / stiff } else { 0.0 },
            stiffness: stiff,
            damping: damp,
            max_force: UNLIMITED,
        });
        let motor = (torque != 0.0).then(|| Motor {
            speed: MOTOR_SPEED * torque.signum(),
            max_force: torque.abs(),
        });
        (servo, motor)
    }
}
