//! The joint's 1D rows: limits, motors, springs and the distance rod, each one Jacobian
//! row J with effective mass m = 1 / (J M⁻¹ Jᵀ), solved in that order (softest first).
//!
//! ```text
//! spring  soft at its own hertz/damping:   Δλ = −m·mass_scale·(Jv + bias_rate·(x − target)) − impulse_scale·λ
//! servo   implicit spring k and damper c towards its target, |λ| ≤ max_force·h:
//!         Δλ = −(Jv + k/(c + h k)·(x − target)) / (K + 1/(h(c + h k))) − λ/(1 + h(c + h k)·K)
//! motor   towards its speed, |λ| ≤ max_force·h:   Δλ = −m·(Jv − speed)
//! limit   one-sided, λ ≥ 0, keeps margin ≥ 0: speculative (bias margin/h, rigid) while
//!         the margin is positive, the joint softness once violated
//! rod     the distance held at rest by the joint softness
//! ```
//!
//! The upper limit is the lower one on the negated row. Which of these a joint has
//! follows from its options ([`FreeDrive::of`]).

use super::{Frame, JointPass, Row};
use crate::dynamics::joint::{FreeAxis, JointImpulses, JointOptions, JointSpring, Motor, Servo};
use crate::dynamics::solver::body::BodyState;
use crate::dynamics::solver::softness::Softness;
use crate::math::Real;

/// A one-sided limit row: keeps `margin` ≥ 0 (speculatively while it is positive, as a
/// contact does). Returns the new accumulated impulse (≥ 0).
#[allow(clippy::too_many_arguments)]
pub(super) fn solve_limit(
    line: Line,
    margin: Real,
    acc: Real,
    fr: &Frame,
    pass: &JointPass,
    a: &mut BodyState,
    b: &mut BodyState,
) -> Real {
    let Line { row, mass, .. } = line;
    let (bias, mass_scale, impulse_scale) = if margin > 0.0 {
        (margin * pass.inv_h, 1.0, 0.0)
    } else if pass.bias {
        (
            margin * pass.soft.bias_rate,
            pass.soft.mass_scale,
            pass.soft.impulse_scale,
        )
    } else {
        (0.0, 1.0, 0.0)
    };
    let delta = -mass * mass_scale * (line.velocity(a, b) + bias) - impulse_scale * acc;
    let total = (acc + delta).max(0.0);

    row.apply(total - acc, &fr.sa, &fr.sb, a, b);
    total
}

/// A free row as its drive solves it: the row, its effective mass, and what its velocity
/// reads besides the bodies' (a chain's pending correction of its hard rows, see
/// `joint_chain.rs`; zero for a joint of its own).
#[derive(Clone, Copy)]
pub(super) struct Line {
    pub row: Row,
    pub mass: Real,
    pub offset: Real,
}

impl Line {
    /// The row as it is for a joint of its own.
    pub fn own(row: Row, fr: &Frame) -> Line {
        Line {
            row,
            mass: row.mass(&fr.sa, &fr.sb),
            offset: 0.0,
        }
    }

    fn negated(self) -> Line {
        Line {
            row: self.row.negated(),
            offset: -self.offset,
            ..self
        }
    }

    /// J v, plus the offset when there is one (a +0 added to a −0 would change recorded
    /// results).
    pub fn velocity(&self, a: &BodyState, b: &BodyState) -> Real {
        let v = self.row.velocity(a, b);
        if self.offset != 0.0 {
            v + self.offset
        } else {
            v
        }
    }
}

/// The impulse along the free coordinate's row: limits (the upper one's row is negated),
/// motor, spring, rod and armature.
pub(super) fn free_impulse(imp: &JointImpulses) -> Real {
    let sum = imp.lower - imp.upper + imp.motor + imp.spring + imp.axial;
    // Added only when there is one: a +0 added to a −0 sum would change recorded results.
    let add = |sum: Real, x: Real| if x != 0.0 { sum + x } else { sum };
    add(add(sum, imp.servo), imp.armature)
}

/// What acts on a joint's free coordinate, from its options: the limits (`limits`, a
/// ball's `twist`, or a distance joint's `min`/`max` with an open end for the one left
/// out), motor, spring (a distance spring pulls towards the rest length, whatever its
/// `target`) and, for a distance joint with none of these, the rigid rod.
#[derive(Clone, Copy, Default)]
pub(super) struct FreeDrive {
    limits: Option<[Real; 2]>,
    motor: Option<Motor>,
    spring: Option<JointSpring>,
    servo: Option<Servo>,
    rod: Option<Real>,
}

impl FreeDrive {
    /// The drive of a free axis `free` with `options`; `rest` is the rest length.
    pub fn of(free: Option<FreeAxis>, o: &JointOptions, rest: Real) -> FreeDrive {
        let Some(free) = free else {
            return FreeDrive::default();
        };
        let range = (o.min.is_some() || o.max.is_some()).then(|| {
            [
                o.min.unwrap_or(Real::NEG_INFINITY),
                o.max.unwrap_or(Real::INFINITY),
            ]
        });
        let distance = free == FreeAxis::Distance;
        let spring = match o.spring {
            Some(s) if distance => Some(JointSpring { target: rest, ..s }),
            s => s,
        };
        let rigid = distance && o.spring.is_none() && range.is_none();
        FreeDrive {
            limits: o.limits.or(o.twist).or(range),
            motor: o.motor,
            spring,
            servo: o.servo,
            rod: rigid.then_some(rest),
        }
    }

    /// An angle of the free coordinate (a hinge's or a twist's, in (−π, π]) read in the
    /// turn its limits, servo or spring centre (see `coords::angle_window`).
    pub fn in_window(&self, angle: Real) -> Real {
        let centre = crate::dynamics::joint::coords::angle_window(
            self.limits,
            self.servo.map(|s| s.target),
            self.spring.map(|s| s.target),
        );
        crate::dynamics::joint::coords::in_window(angle, centre)
    }

    /// The drive's rows one at a time, in `solve_free`'s order, each as a drive of its
    /// own (the limits as two, one-sided), for a chain to carry each row's impulse through
    /// its hard rows before the next row reads the velocities.
    pub fn parts(&self) -> impl Iterator<Item = FreeDrive> {
        let none = FreeDrive::default();
        let side = |lower: bool| {
            self.limits
                .map(|[l, u]| match lower {
                    true => [l, Real::INFINITY],
                    false => [Real::NEG_INFINITY, u],
                })
                .filter(|[l, u]| l.is_finite() || u.is_finite())
        };
        [
            FreeDrive {
                spring: self.spring,
                ..none
            },
            FreeDrive {
                servo: self.servo,
                ..none
            },
            FreeDrive {
                motor: self.motor,
                ..none
            },
            FreeDrive {
                limits: side(true),
                ..none
            },
            FreeDrive {
                limits: side(false),
                ..none
            },
            FreeDrive {
                rod: self.rod,
                ..none
            },
        ]
        .into_iter()
        .filter(|d| !d.is_idle())
    }

    /// Whether nothing acts on the free coordinate.
    pub fn is_idle(&self) -> bool {
        self.limits.is_none()
            && self.motor.is_none()
            && self.spring.is_none()
            && self.servo.is_none()
            && self.rod.is_none()
    }
}

/// Spring, servo, motor, limits and (distance joints) the rigid rod along the free coordinate.
#[allow(clippy::too_many_arguments)]
pub(super) fn solve_free(
    drive: &FreeDrive,
    line: Line,
    coordinate: Real,
    fr: &Frame,
    pass: &JointPass,
    imp: &mut JointImpulses,
    a: &mut BodyState,
    b: &mut BodyState,
) {
    if let Some(s) = drive.spring {
        imp.spring = solve_spring(line, coordinate, &s, imp.spring, fr, pass, a, b);
    }
    // Solved in both passes, as the frequency spring is. Its row's mass is the free
    // coordinate's own (a hinge: the body's inertia about its centre, not the pivot's),
    // and the hard rows solved after it carry the load's torque around to it, so the
    // static stiffness is only near k (measured: a hinged arm sagged 0.67 τ/k at k = 5000
    // N·m/rad, 0.83 τ/k at 500); solved once a substep it came out 0.36 τ/k.
    if let Some(s) = drive.servo {
        imp.servo = solve_servo(line, coordinate, &s, imp.servo, fr, pass, a, b);
    }
    if let Some(m) = drive.motor {
        imp.motor = solve_motor(line, &m, imp.motor, fr, pass, a, b);
    }
    if let Some([lower, upper]) = drive.limits {
        if lower.is_finite() {
            imp.lower = solve_limit(line, coordinate - lower, imp.lower, fr, pass, a, b);
        }
        if upper.is_finite() {
            let margin = upper - coordinate;
            imp.upper = solve_limit(line.negated(), margin, imp.upper, fr, pass, a, b);
        }
    }
    if let Some(rest) = drive.rod {
        imp.axial = solve_rod(line, coordinate, rest, imp.axial, fr, pass, a, b);
    }
}

/// The distance joint's rigid rod: the distance held at `rest` by the joint softness.
#[allow(clippy::too_many_arguments)]
fn solve_rod(
    line: Line,
    distance: Real,
    rest: Real,
    acc: Real,
    fr: &Frame,
    pass: &JointPass,
    a: &mut BodyState,
    b: &mut BodyState,
) -> Real {
    let Line { row, mass, .. } = line;
    let bias = if pass.bias {
        pass.soft.bias_rate * (distance - rest)
    } else {
        0.0
    };
    let delta =
        -mass * pass.soft.mass_scale * (line.velocity(a, b) + bias) - pass.soft.impulse_scale * acc;
    row.apply(delta, &fr.sa, &fr.sb, a, b);
    acc + delta
}

#[allow(clippy::too_many_arguments)]
fn solve_spring(
    line: Line,
    coordinate: Real,
    spring: &JointSpring,
    acc: Real,
    fr: &Frame,
    pass: &JointPass,
    a: &mut BodyState,
    b: &mut BodyState,
) -> Real {
    let Line { row, mass, .. } = line;
    let soft = Softness::new(spring.hertz, spring.damping_ratio, pass.h);
    let bias = soft.bias_rate * (coordinate - spring.target);
    let delta = -mass * soft.mass_scale * (line.velocity(a, b) + bias) - soft.impulse_scale * acc;
    row.apply(delta, &fr.sa, &fr.sb, a, b);
    acc + delta
}

fn solve_motor(
    line: Line,
    motor: &Motor,
    acc: Real,
    fr: &Frame,
    pass: &JointPass,
    a: &mut BodyState,
    b: &mut BodyState,
) -> Real {
    let Line { row, mass, .. } = line;
    let limit = motor.max_force * pass.h;
    let delta = -mass * (line.velocity(a, b) - motor.speed);
    let total = (acc + delta).clamp(-limit, limit);
    row.apply(total - acc, &fr.sa, &fr.sb, a, b);
    total
}

/// The servo as an implicit spring–damper with a force cap. Backward Euler over the
/// substep h, for a row of inverse effective mass K = J M⁻¹ Jᵀ: the impulse λ = h F with
/// F = −k (x + h v⁺ − target) − c v⁺ and v⁺ = v + K λ gives, with s = h (c + h k),
/// λ = −(v + k/(c + h k)·(x − target)) / (K + 1/s); in the soft-step form (the same as
/// `Softness`, with the gains given instead of derived from a frequency) the accumulated
/// impulse enters scaled by 1/(1 + s K). Stable for any k, c ≥ 0.
#[allow(clippy::too_many_arguments)]
fn solve_servo(
    line: Line,
    coordinate: Real,
    servo: &Servo,
    acc: Real,
    fr: &Frame,
    pass: &JointPass,
    a: &mut BodyState,
    b: &mut BodyState,
) -> Real {
    let Line { row, mass, .. } = line;
    let s = pass.h * (servo.damping + pass.h * servo.stiffness);
    if mass <= 0.0 || s <= 0.0 {
        return acc;
    }
    let k_inv = 1.0 / mass;
    let bias = servo.stiffness / (servo.damping + pass.h * servo.stiffness);
    let delta = -(line.velocity(a, b) + bias * (coordinate - servo.target)) / (k_inv + 1.0 / s)
        - acc / (1.0 + s * k_inv);
    let limit = servo.max_force * pass.h;
    let total = (acc + delta).clamp(-limit, limit);
    row.apply(total - acc, &fr.sa, &fr.sb, a, b);
    total
}
