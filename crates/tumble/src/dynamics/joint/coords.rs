//! Joint coordinates: where a joint's free coordinate stands and how fast it moves, from
//! the two bodies' poses and velocities. These are the coordinates the solver's limits,
//! motor, spring and servo act on (`dynamics/solver/joint_rows.rs`), each of `body`
//! relative to `other`:
//!
//! ```text
//! hinge     angle about the axis (rad), zero at creation, counting whole turns: read in
//!           the turn about the angle after the last step (`Joint::angle`, followed at
//!           every step), as MuJoCo's qpos; rate axis·(ω_a − ω_b). The solver reads it in
//!           the turn about the middle of its limits (else its servo's target, its
//!           spring's rest, or 0: (−π, π]; see `angle_window`), so a servo takes the
//!           short way to its target and a wheel's limits-free angle may grow without end
//! slider    axis·(p_a − p_b) (m): the anchors' offset along the axis (zero at creation
//!           when the anchors coincide then, as the scene format and Python's defaults
//!           make them); its rate
//! distance  the anchors' distance (m) and its rate
//! ball      the rotation vector (rad) of body relative to other since creation, in
//!           other's frame (the world's for the world): log(q_b⁻¹ q_a q_a0⁻¹ q_b0);
//!           velocity: ω_a − ω_b in other's frame
//! fixed     the same as a ball: the weld's rotational error, zero while it holds
//! ```
//!
//! For a hinge the ball's rotation vector is the angle times the axis, so the two agree.

use super::{FreeAxis, Joint};
use crate::math::{Quat, Real, Vec3};

/// A joint coordinate or rate: one number for hinges, sliders and distance joints, a
/// vector (rotation vector, rad, or relative angular velocity, rad/s) for ball and fixed
/// joints.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum JointCoordinate {
    /// Angle (rad), offset or distance (m), or their rate (rad/s, m/s).
    Scalar(Real),
    /// Rotation vector (rad) or relative angular velocity (rad/s), in `other`'s frame.
    Vector(Vec3),
}

impl JointCoordinate {
    /// The number, for a scalar coordinate.
    pub fn scalar(self) -> Option<Real> {
        match self {
            JointCoordinate::Scalar(x) => Some(x),
            JointCoordinate::Vector(_) => None,
        }
    }
    /// The vector, for a ball or fixed joint's coordinate.
    pub fn vector(self) -> Option<Vec3> {
        match self {
            JointCoordinate::Vector(v) => Some(v),
            JointCoordinate::Scalar(_) => None,
        }
    }
}

/// A body as a coordinate sees it: frame origin and rotation, centre of mass, velocity
/// of the centre of mass and angular velocity (world frame). The world is at rest at the
/// origin.
#[derive(Debug, Clone, Copy)]
pub(crate) struct BodyMotion {
    pub x: Vec3,
    pub q: Quat,
    pub com: Vec3,
    pub v: Vec3,
    pub w: Vec3,
}

impl BodyMotion {
    pub const WORLD: BodyMotion = BodyMotion {
        x: Vec3::ZERO,
        q: Quat::IDENTITY,
        com: Vec3::ZERO,
        v: Vec3::ZERO,
        w: Vec3::ZERO,
    };
    fn point_velocity(&self, p: Vec3) -> Vec3 {
        self.v + self.w.cross(p - self.com)
    }
}

/// The anchors in the world and their separation p_b − p_a.
fn anchors(joint: &Joint, a: &BodyMotion, b: &BodyMotion) -> (Vec3, Vec3, Vec3) {
    let pa = a.x + a.q * joint.def.anchor;
    let pb = b.x + b.q * joint.def.other_anchor;
    (pa, pb, pb - pa)
}

/// The hinge angle of `body` about its axis relative to `other` (rad), in (−π, π].
pub(crate) fn raw_hinge_angle(joint: &Joint, qa: Quat, qb: Quat) -> Real {
    let axis = qa * joint.axis;
    let (ra, rb) = (qa * joint.reference, qb * joint.other_reference);
    axis.dot(rb.cross(ra)).atan2(ra.dot(rb))
}

/// The hinge angle as the solver reads it: in the joint's window (see [`angle_window`]).
pub(crate) fn hinge_angle(joint: &Joint, qa: Quat, qb: Quat) -> Real {
    let angle = raw_hinge_angle(joint, qa, qb);
    let o = joint.def.kind.options();
    in_window(
        angle,
        angle_window(
            o.limits,
            o.servo.map(|s| s.target),
            o.spring.map(|s| s.target),
        ),
    )
}

/// The middle of the turn in which a joint reads its angle: the poses tell an angle only
/// up to whole turns, and read in (−π, π] a joint whose limits reach past π cannot tell
/// one side of its range from the other (a URDF arm's joint of [−0.09, 3.82] rad read
/// 3.2 rad as −3.08, below its lower limit, and the limit threw it round at 650 rad/s).
/// So the angle is read in the turn centred on the middle of its limits when they span
/// less than a turn, else on its servo's target (the servo then always takes the short
/// way), else on its spring's rest angle, else on zero: (−π, π].
pub(crate) fn angle_window(
    limits: Option<[Real; 2]>,
    servo: Option<Real>,
    spring: Option<Real>,
) -> Real {
    let tau = 2.0 * crate::math::PI;
    match limits {
        Some([lo, hi]) if lo.is_finite() && hi.is_finite() && hi - lo < tau => 0.5 * (lo + hi),
        _ => servo.or(spring).filter(|c| c.is_finite()).unwrap_or(0.0),
    }
}

/// `angle` (in (−π, π]) moved by whole turns into the turn centred on `centre`; unchanged,
/// bit for bit, when it is in it already.
pub(crate) fn in_window(angle: Real, centre: Real) -> Real {
    let tau = 2.0 * crate::math::PI;
    let turns = ((centre - angle) / tau).round();
    if turns == 0.0 {
        angle
    } else {
        angle + tau * turns
    }
}

/// The rotation of `body` relative to `other` since creation, in `other`'s frame.
pub(crate) fn relative_rotation(joint: &Joint, qa: Quat, qb: Quat) -> Quat {
    let r = qb.inverse() * qa * joint.relative_rotation;
    r.normalize()
}

/// The rotation vector (axis times angle, rad, angle in [0, π]) of a unit quaternion.
pub(crate) fn rotation_vector(q: Quat) -> Vec3 {
    let q = if q.w < 0.0 { -q } else { q };
    let v = Vec3::new(q.x, q.y, q.z);
    let s = v.length();
    if s < 1e-12 {
        return 2.0 * v;
    }
    v * (2.0 * s.atan2(q.w) / s)
}

/// The joint's coordinate (see the module's table).
pub(crate) fn position(joint: &Joint, a: &BodyMotion, b: &BodyMotion) -> JointCoordinate {
    let (_, _, d) = anchors(joint, a, b);
    match joint.def.kind.spec().free {
        Some(FreeAxis::Rotation) => {
            JointCoordinate::Scalar(in_window(raw_hinge_angle(joint, a.q, b.q), joint.angle))
        }
        Some(FreeAxis::Translation) => JointCoordinate::Scalar(-(a.q * joint.axis).dot(d)),
        Some(FreeAxis::Distance) => JointCoordinate::Scalar(d.length()),
        _ => JointCoordinate::Vector(rotation_vector(relative_rotation(joint, a.q, b.q))),
    }
}

/// The joint's rate (see the module's table).
pub(crate) fn velocity(joint: &Joint, a: &BodyMotion, b: &BodyMotion) -> JointCoordinate {
    let (pa, pb, d) = anchors(joint, a, b);
    let relative = b.point_velocity(pb) - a.point_velocity(pa);
    match joint.def.kind.spec().free {
        Some(FreeAxis::Rotation) => JointCoordinate::Scalar((a.q * joint.axis).dot(a.w - b.w)),
        Some(FreeAxis::Translation) => {
            // d/dt of −h·d with h = q_a·axis turning at ω_a.
            let h = a.q * joint.axis;
            JointCoordinate::Scalar(-a.w.cross(h).dot(d) - h.dot(relative))
        }
        Some(FreeAxis::Distance) => {
            let length = d.length();
            let n = if length > 1e-12 {
                d / length
            } else {
                a.q * joint.axis
            };
            JointCoordinate::Scalar(n.dot(relative))
        }
        _ => JointCoordinate::Vector(b.q.inverse() * (a.w - b.w)),
    }
}
