//! Joint coordinates in the world: reading them (`joint_position`, `joint_velocity`, see
//! `dynamics/joint/coords.rs` for what each kind's are) and posing a mechanism by setting
//! one (`set_joint_position`).
//!
//! Setting a coordinate moves one side of the joint rigidly: the bodies reachable from
//! `body` through the other acting joints without crossing this one, unless that side is
//! anchored (it holds a static or kinematic body, or a joint to the world), in which case
//! `other`'s side moves instead. A hinge turns its side about the axis through the
//! moving body's anchor, a slider or distance joint translates it along the axis or the
//! line of the anchors, a ball turns it about its anchor. Velocities and angular
//! velocities turn with the bodies (unchanged by translations): a mechanism at rest stays
//! at rest, and the joint's rate is kept while the other side is still. Nothing else is
//! changed: other joints on the moved side keep their coordinates, and joints between the
//! moved side and the rest (none in a tree) would be violated.

use super::joints::unknown;
use crate::dynamics::body::BodyKind;
use crate::dynamics::joint::coords::{self, BodyMotion};
use crate::dynamics::joint::{FreeAxis, Joint, JointCoordinate, JointId};
use crate::error::{check, Error, Result};
use crate::limits::MAX_COORDINATE;
use crate::math::{quat_from_rotation_vector, Quat, Real, Vec3};
use crate::pipeline::world::World;

/// A rigid motion of the world: x ↦ rotation·(x − center) + center + shift.
#[derive(Clone, Copy)]
struct Rigid {
    rotation: Quat,
    center: Vec3,
    shift: Vec3,
}

impl Rigid {
    fn apply(&self, m: &BodyMotion) -> BodyMotion {
        let map = |p: Vec3| self.rotation * (p - self.center) + self.center + self.shift;
        BodyMotion {
            x: map(m.x),
            q: (self.rotation * m.q).normalize(),
            com: map(m.com),
            v: self.rotation * m.v,
            w: self.rotation * m.w,
        }
    }
    /// `self` after `first`.
    fn after(&self, first: &Rigid) -> Rigid {
        // R2(R1(x − c1) + c1 + s1 − c2) + c2 + s2, written about c1.
        let rotation = (self.rotation * first.rotation).normalize();
        let moved_c1 = self.rotation * (first.center + first.shift - self.center) + self.center;
        Rigid {
            rotation,
            center: first.center,
            shift: moved_c1 + self.shift - first.center,
        }
    }
}

impl World {
    /// The joint's coordinate: hinge angle (rad, counting whole turns), slider offset (m),
    /// distance (m), or a ball or fixed joint's rotation vector (rad, in `other`'s frame);
    /// see `tumble::joint::JointCoordinate`.
    pub fn joint_position(&self, id: JointId) -> Result<JointCoordinate> {
        let (joint, a, b) = self.joint_motions(id)?;
        Ok(coords::position(joint, &a, &b))
    }

    /// The joint's rate: hinge (rad/s), slider and distance (m/s), ball and fixed: the
    /// relative angular velocity ω_body − ω_other in `other`'s frame (rad/s).
    pub fn joint_velocity(&self, id: JointId) -> Result<JointCoordinate> {
        let (joint, a, b) = self.joint_motions(id)?;
        Ok(coords::velocity(joint, &a, &b))
    }

    /// Follows each hinge's angle through the step just taken (see `Joint::angle`): read
    /// in the turn about where it was plus its rate times the step, so that it counts
    /// whole turns even for a wheel turning more than half a turn a step.
    pub(super) fn follow_hinge_angles(&mut self, dt: Real) {
        for k in 0..self.joints.list.len() {
            let joint = &self.joints.list[k];
            if joint.def.kind.spec().free != Some(FreeAxis::Rotation) {
                continue;
            }
            let (a, b) = self.motions_of(joint);
            let rate = (a.q * joint.axis).dot(a.w - b.w);
            let raw = coords::raw_hinge_angle(joint, a.q, b.q);
            let angle = coords::in_window(raw, joint.angle + rate * dt);
            self.joints.list[k].angle = angle;
        }
    }

    fn joint_motions(&self, id: JointId) -> Result<(&Joint, BodyMotion, BodyMotion)> {
        let joint = self.joint(id)?;
        let (a, b) = self.motions_of(joint);
        Ok((joint, a, b))
    }

    /// The motions of the joint's two bodies (the world's for none).
    fn motions_of(&self, joint: &Joint) -> (BodyMotion, BodyMotion) {
        let motion = |body: Option<crate::id::BodyId>| match body.and_then(|b| self.dense(b)) {
            Some(i) => self.motion_of(i),
            None => BodyMotion::WORLD,
        };
        (motion(Some(joint.def.body)), motion(joint.def.other))
    }

    fn motion_of(&self, i: usize) -> BodyMotion {
        let b = &self.bodies.list[i];
        BodyMotion {
            x: b.position(),
            q: b.orientation,
            com: b.com,
            v: b.velocity,
            w: b.angular_velocity,
        }
    }

    /// Poses the mechanism so that the joint's coordinate is `q` (a number for hinges,
    /// sliders and distance joints, a rotation vector for ball joints), moving one side
    /// rigidly (see the module documentation). Refused, changing nothing, for a fixed
    /// joint, a broken or disabled one, a coordinate of the wrong shape or out of range
    /// (`position: must be > 0` for a distance), when both sides are anchored or joined
    /// by another path (a closed loop), or when a body would leave the world's range or
    /// its plane. Wakes every body it moves. A hinge is turned the short way to `q`'s
    /// pose, and reads `q` back, whole turns included (as MuJoCo's qpos).
    pub fn set_joint_position(&mut self, id: JointId, q: JointCoordinate) -> Result<()> {
        let k = self.joints.handles.dense(id).ok_or_else(|| unknown(id))?;
        let joint = &self.joints.list[k];
        check_target(joint, q)?;
        let (moving, body_side) = self.moving_side(k)?;
        let (_, a, b) = self.joint_motions(id)?;
        let motion = solve_motion(joint, q, a, b, body_side);
        let angle = match (joint.def.kind.spec().free, q) {
            (Some(FreeAxis::Rotation), JointCoordinate::Scalar(q)) => q,
            _ => joint.angle,
        };
        let moved: Vec<(usize, BodyMotion)> = moving
            .iter()
            .map(|&i| (i, motion.apply(&self.motion_of(i))))
            .collect();
        for &(i, m) in &moved {
            check::vec3_at_most("position", m.com, MAX_COORDINATE, "m")?;
            let body = &self.bodies.list[i];
            let turned = Vec3::new(motion.rotation.x, motion.rotation.y, 0.0);
            if body.planar && (turned.length() > 1e-12 || m.com.z != body.com.z) {
                let reason = format!("would move the planar bodies[{i}] out of its plane");
                return Err(Error::invalid("position", reason));
            }
        }
        for (i, m) in moved {
            let b = &mut self.bodies.list[i];
            b.com = m.com;
            b.orientation = m.q;
            b.velocity = m.v;
            b.angular_velocity = m.w;
            b.angular_momentum = motion.rotation * b.angular_momentum;
            self.memory.forget(i);
            let b = &self.bodies.list[i];
            let aabb = b.shape.aabb(&b.pose());
            let c = &mut self.collision;
            c.broad_phase.update(c.proxies[i], aabb, Vec3::ZERO);
            self.wake_around(i);
        }
        self.joints.list[k].angle = angle;
        self.wake_joint(k);
        Ok(())
    }

    /// The dense bodies on the side of joint `k` that moves, and whether it is `body`'s.
    fn moving_side(&self, k: usize) -> Result<(Vec<usize>, bool)> {
        let joint = &self.joints.list[k];
        let a = self.dense(joint.def.body);
        let b = joint.def.other.and_then(|o| self.dense(o));
        let side_a = a.map(|a| self.side_of(k, a)).unwrap_or_default();
        let side_b = b.map(|b| self.side_of(k, b)).unwrap_or_default();
        if b.is_some_and(|b| side_a.0.contains(&b)) {
            return Err(Error::invalid(
                "position",
                "the joint is in a closed loop: its two sides are joined another way",
            ));
        }
        match (a.is_some() && !side_a.1, b.is_some() && !side_b.1) {
            (true, _) => Ok((side_a.0, true)),
            (false, true) => Ok((side_b.0, false)),
            (false, false) => Err(Error::invalid(
                "position",
                "both sides of the joint are anchored (a static or kinematic body, or a \
                 joint to the world): there is nothing free to move",
            )),
        }
    }

    /// The bodies reachable from dense body `start` through acting joints other than
    /// `k` (sorted), and whether they are anchored.
    fn side_of(&self, k: usize, start: usize) -> (Vec<usize>, bool) {
        let links = &self.joints.links;
        let mut seen = vec![false; self.bodies.list.len()];
        let mut stack = vec![start];
        let mut anchored = false;
        seen[start] = true;
        while let Some(i) = stack.pop() {
            anchored |= self.bodies.list[i].kind != BodyKind::Dynamic;
            for (j, link) in links.iter().enumerate().filter(|&(j, _)| j != k) {
                if !self.joints.list[j].acts() {
                    continue;
                }
                let next = match *link {
                    [Some(x), y] if x == i => y,
                    [x, Some(y)] if y == i => x,
                    _ => continue,
                };
                match next {
                    None => anchored = true,
                    Some(n) if !seen[n] => {
                        seen[n] = true;
                        stack.push(n);
                    }
                    Some(_) => {}
                }
            }
        }
        let side = (0..seen.len()).filter(|&i| seen[i]).collect();
        (side, anchored)
    }
}

/// Refuses a target of the wrong shape or range for the joint's kind.
fn check_target(joint: &Joint, q: JointCoordinate) -> Result<()> {
    if !joint.acts() {
        return Err(Error::invalid(
            "position",
            "the joint is broken or disabled",
        ));
    }
    let spec = joint.def.kind.spec();
    match (spec.free, q) {
        (None, _) => Err(Error::invalid(
            "position",
            "a fixed joint has no free coordinate to set",
        )),
        (Some(FreeAxis::Twist), JointCoordinate::Vector(r)) => {
            check::length_at_most("position", r, std::f64::consts::PI as Real * 1e6, "rad")
        }
        (Some(FreeAxis::Twist), JointCoordinate::Scalar(_)) => Err(Error::invalid(
            "position",
            "a ball joint's position is a rotation vector (3 numbers, rad)",
        )),
        (_, JointCoordinate::Vector(_)) => Err(Error::invalid(
            "position",
            format!("a {} joint's position is one number", spec.name),
        )),
        (Some(FreeAxis::Distance), JointCoordinate::Scalar(x)) => check::positive("position", x)
            .and_then(|_| check::at_most("position", x, MAX_COORDINATE, "m")),
        (_, JointCoordinate::Scalar(x)) => check::at_most("position", x, MAX_COORDINATE, ""),
    }
}

/// The rigid motion of the moving side (`body`'s if `body_side`) that brings the joint's
/// coordinate to `q`. A hinge's angle is measured between reference directions that
/// may lean off the axis by the joint's drift, so the turn is corrected twice more.
fn solve_motion(
    joint: &Joint,
    q: JointCoordinate,
    a: BodyMotion,
    b: BodyMotion,
    body_side: bool,
) -> Rigid {
    let sign: Real = if body_side { 1.0 } else { -1.0 };
    let (pa, pb) = (
        a.x + a.q * joint.def.anchor,
        b.x + b.q * joint.def.other_anchor,
    );
    let center = if body_side { pa } else { pb };
    let still = Rigid {
        rotation: Quat::IDENTITY,
        center,
        shift: Vec3::ZERO,
    };
    match (joint.def.kind.spec().free, q) {
        (Some(FreeAxis::Rotation), JointCoordinate::Scalar(target)) => {
            let mut total = still;
            for _ in 0..3 {
                let (a2, b2) = moved(&total, a, b, body_side);
                let delta = wrap(target - coords::hinge_angle(joint, a2.q, b2.q));
                let axis = a2.q * joint.axis;
                let turn = Rigid {
                    rotation: Quat::from_axis_angle(axis, sign * delta),
                    center: if body_side {
                        a2.x + a2.q * joint.def.anchor
                    } else {
                        b2.x + b2.q * joint.def.other_anchor
                    },
                    shift: Vec3::ZERO,
                };
                total = turn.after(&total);
            }
            total
        }
        (Some(FreeAxis::Translation), JointCoordinate::Scalar(target)) => {
            let axis = a.q * joint.axis;
            let now = -axis.dot(pb - pa);
            Rigid {
                shift: axis * (sign * (target - now)),
                ..still
            }
        }
        (Some(FreeAxis::Distance), JointCoordinate::Scalar(target)) => {
            let d = pb - pa;
            let n = d.try_normalize().unwrap_or(a.q * joint.axis);
            Rigid {
                shift: n * (-sign * (target - d.length())),
                ..still
            }
        }
        (_, JointCoordinate::Vector(r)) => {
            let e = quat_from_rotation_vector(r);
            let rotation = if body_side {
                (b.q * e * joint.relative_rotation.inverse()) * a.q.inverse()
            } else {
                (a.q * joint.relative_rotation * e.inverse()) * b.q.inverse()
            };
            Rigid {
                rotation: rotation.normalize(),
                ..still
            }
        }
        _ => still,
    }
}

/// The two bodies after the moving side's motion `m`.
fn moved(m: &Rigid, a: BodyMotion, b: BodyMotion, body_side: bool) -> (BodyMotion, BodyMotion) {
    if body_side {
        (m.apply(&a), b)
    } else {
        (a, m.apply(&b))
    }
}

/// An angle brought into (−π, π].
fn wrap(x: Real) -> Real {
    let pi = std::f64::consts::PI as Real;
    let y = (x + pi).rem_euclid(2.0 * pi) - pi;
    if y == -pi {
        pi
    } else {
        y
    }
}
