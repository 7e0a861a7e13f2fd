//! Time of impact and shape casts for convex shapes, by conservative advancement.
//!
//! Conservative advancement (Mirtich): at parameter t take the signed distance d and unit
//! normal n between the shapes (GJK, `narrow_phase::closest_points`). The separation along
//! the *fixed* axis n, s_n(τ) = min_B x·n − max_A x·n, equals d at τ = t and never exceeds
//! the true distance at any τ. A point of A at offset r from its centre moves with
//! v_A + ω_A × r, so its speed along n is at most v_A·n + |ω_A|·ρ_A, ρ_A the largest |r|
//! over the shape; likewise for B. Hence
//!
//!   ds_n/dτ ≥ −((v_A − v_B)·n + |ω_A|·ρ_A + |ω_B|·ρ_B) = −μ,
//!
//! and the shapes cannot come within `target` before τ = t + (d − target)/μ. Stepping there
//! never passes the first contact; each step re-measures d and n. If μ ≤ 0 the gap along n
//! can never close, so neither can the distance: no impact. The iteration stops when d is
//! within a tolerance of the target (5 % of it, or 1e-10 of the pair's size and spacing in
//! f64, 1e-5 in f32), when t passes 1 (no impact) or after [`MAX_ITERATIONS`] steps (then the
//! t reached is returned: it is still no later than the first contact, which is what
//! continuous collision needs).
//!
//! The same holds with signed distances: overlapping, d is minus the depth along the axis
//! of least penetration, the largest separation along any axis, which the fixed axis's
//! separation still bounds from below. So a negative target is a depth the shapes are not
//! let past, which continuous collision uses for bodies that start a step touching (see
//! `sweep.rs`); there the target and tolerance are picked from the distance at t = 0.
//!
//! A linear shape cast is the same with no rotation and target 0. For a point against a
//! face the step is exact; against a curved surface or an edge it is Newton's method on a
//! convex function of t, which converges from below, quadratically.

use crate::collision::geometry::Pose;
use crate::collision::narrow_phase::closest_points;
use crate::collision::shape::Convex;
use crate::math::{quat_from_rotation_vector, Real, Vec3};

/// Advancement steps before giving up with the conservative t reached.
const MAX_ITERATIONS: usize = 50;

/// The distance counted as contact, as a fraction of the pair's size (the shapes' reach
/// plus the distance between their origins): the rounding of a distance grows with both.
#[cfg(not(feature = "f32"))]
const ABS_TOL: Real = 1e-10;
#[cfg(feature = "f32")]
const ABS_TOL: Real = 1e-5;

/// The fraction of `target` within which a TOI counts as converged.
const TARGET_TOL: Real = 0.05;

/// A rigid motion over [0, 1]: the pose at the start and constant linear and angular
/// velocity (per unit of the sweep parameter), rotation about the centre `local_center`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sweep {
    /// Pose at parameter 0.
    pub start: Pose,
    /// Displacement of the centre over the whole sweep (m).
    pub translation: Vec3,
    /// Rotation vector over the whole sweep (rad, world frame).
    pub rotation: Vec3,
    /// Centre of rotation in the shape's local frame (its centre of mass).
    pub local_center: Vec3,
}

/// The first moment two moving convex shapes come within `target` of each other.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Toi {
    /// Sweep parameter in [0, 1].
    pub t: Real,
    /// Unit normal from A to B at that moment, world frame.
    pub normal: Vec3,
    /// Witness points on A and B at that moment.
    pub point_a: Vec3,
    /// Witness point on B.
    pub point_b: Vec3,
}

/// Conservative advancement: the first t in [0, 1] at which the distance between A and B
/// drops to `target` (> 0 keeps a safety gap), or `None` if they never get that close.
/// Shapes already closer than `target` at t = 0 return t = 0.
pub fn time_of_impact(
    a: &Convex,
    sweep_a: &Sweep,
    b: &Convex,
    sweep_b: &Sweep,
    target: Real,
) -> Option<Toi> {
    let target = if target.is_nan() {
        0.0
    } else {
        target.max(0.0)
    };
    if !target.is_finite() {
        return None;
    }
    advance(a, sweep_a, b, sweep_b, |_| Goal { target, tol: None })
}

/// Where an advancement stops: the signed distance counted as impact (negative: a depth
/// of interpenetration) and the tolerance above it within which the search has converged
/// (`None`: 5 % of the target or the rounding of the pair's size and spacing, as
/// [`time_of_impact`] does).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Goal {
    pub target: Real,
    pub tol: Option<Real>,
}

/// Conservative advancement to the goal `goal` picks from the signed distance at t = 0:
/// the first t at which the distance is within the goal's tolerance above its target (t =
/// 0 if it already is), or `None` if it never gets there. The argument of the module
/// header holds for signed distances: overlapping, the distance is the largest separation
/// along any axis (minus the depth), which the fixed axis's separation still bounds from
/// below, so a negative target is a depth the shapes are not let past.
pub(crate) fn advance(
    a: &Convex,
    sweep_a: &Sweep,
    b: &Convex,
    sweep_b: &Sweep,
    goal: impl FnOnce(Real) -> Goal,
) -> Option<Toi> {
    if !sweep_a.is_finite() || !sweep_b.is_finite() {
        return None;
    }
    let (spin_a, spin_b) = (spin(a, sweep_a), spin(b, sweep_b));
    let dv = sweep_a.translation - sweep_b.translation;
    let size = reach(a, Vec3::ZERO) + reach(b, Vec3::ZERO);
    let mut t: Real = 0.0;
    // A sweep that neither moves nor turns (a static body's) has one pose for every t.
    let fixed =
        |s: &Sweep| (s.translation == Vec3::ZERO && s.rotation == Vec3::ZERO).then(|| s.at(0.0));
    let (fixed_a, fixed_b) = (fixed(sweep_a), fixed(sweep_b));
    let mut goal = Some(goal);
    let mut target = Goal {
        target: 0.0,
        tol: None,
    };
    for iteration in 0..=MAX_ITERATIONS {
        let pa = fixed_a.unwrap_or_else(|| sweep_a.at(t));
        let pb = fixed_b.unwrap_or_else(|| sweep_b.at(t));
        let c = closest_points(a, &pa, b, &pb);
        if let Some(pick) = goal.take() {
            target = pick(c.distance);
            if !target.target.is_finite() {
                return None;
            }
        }
        // Rounding in the distance grows with the coordinates of the pair as it stands.
        let scale = size + (pa.position - pb.position).length();
        let tol = target
            .tol
            .unwrap_or_else(|| (TARGET_TOL * target.target).max(ABS_TOL * scale));
        let toi = Toi {
            t,
            normal: c.normal,
            point_a: c.point_a,
            point_b: c.point_b,
        };
        if c.distance <= target.target + tol || iteration == MAX_ITERATIONS {
            return Some(toi);
        }
        let mu = dv.dot(c.normal) + spin_a + spin_b;
        if mu.is_nan() || mu <= 0.0 {
            return None;
        }
        t += (c.distance - target.target) / mu;
        if t.is_nan() || t > 1.0 {
            return None;
        }
    }
    None
}

/// A linear shape cast's hit.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ShapeCastHit {
    /// Fraction of `translation` travelled before contact, in [0, 1].
    pub t: Real,
    /// Unit contact normal on the target, pointing towards the cast shape, world frame.
    pub normal: Vec3,
    /// Contact point, world frame.
    pub point: Vec3,
}

/// Sweeps convex `a` from `pose_a` along `translation` (no rotation) against convex `b` at
/// rest at `pose_b`: the first contact, or `None` if the sweep misses.
pub fn cast_shape(
    a: &Convex,
    pose_a: &Pose,
    translation: Vec3,
    b: &Convex,
    pose_b: &Pose,
) -> Option<ShapeCastHit> {
    let finite = pose_a.position.is_finite()
        && pose_a.rotation.is_finite()
        && pose_b.position.is_finite()
        && pose_b.rotation.is_finite()
        && translation.is_finite();
    if !finite {
        return None;
    }
    let size = reach(a, Vec3::ZERO) + reach(b, Vec3::ZERO);
    let mut t: Real = 0.0;
    for iteration in 0..=MAX_ITERATIONS {
        let pa = Pose::new(pose_a.position + translation * t, pose_a.rotation);
        let c = closest_points(a, &pa, b, pose_b);
        let tol = ABS_TOL * (size + (pa.position - pose_b.position).length());
        let hit = ShapeCastHit {
            t,
            normal: -c.normal,
            point: c.point_b,
        };
        if c.distance <= tol || iteration == MAX_ITERATIONS {
            return Some(hit);
        }
        // The gap along n closes at exactly translation·n per unit t (no rotation).
        let closing = translation.dot(c.normal);
        if closing.is_nan() || closing <= 0.0 {
            return None;
        }
        t += c.distance / closing;
        if t.is_nan() || t > 1.0 {
            return None;
        }
    }
    None
}

impl Sweep {
    /// The pose at sweep parameter `t`: the centre moved by t·translation, the orientation
    /// turned by exp(t·rotation) about it.
    pub fn at(&self, t: Real) -> Pose {
        let q = (quat_from_rotation_vector(self.rotation * t) * self.start.rotation).normalize();
        let center = self.start.transform_point(self.local_center) + self.translation * t;
        Pose::new(center - q * self.local_center, q)
    }

    fn is_finite(&self) -> bool {
        self.start.position.is_finite()
            && self.start.rotation.is_finite()
            && self.translation.is_finite()
            && self.rotation.is_finite()
            && self.local_center.is_finite()
    }
}

/// How fast the sweep's turn can close a gap to the shape, per unit t: its reach about
/// its centre of rotation times its angular travel, less what its symmetry leaves in
/// place. A ball turning about its own centre fills the same region at every t, and a
/// capsule or cylinder turning about its axis too; only the turn's part that swings the
/// axis (|θ × a|, constant along a turn about a fixed axis) moves their surface, plus the
/// centre's own motion about the centre of rotation. With the full reach, a capsule
/// rolling at 8 m/s (1.3 rad a step, reach 0.4 m, resting 0.1 mm deep on a mesh) needed
/// more advancements than allowed to cross the step, and the sweep reported an impact
/// at the last one every step.
fn spin(shape: &Convex, sweep: &Sweep) -> Real {
    let theta = sweep.rotation;
    let centre = theta.length() * sweep.local_center.length();
    let swing = || theta.cross(sweep.start.rotation * Vec3::Y).length();
    match shape {
        Convex::Sphere { .. } => centre,
        Convex::Capsule { half_height, .. } => swing() * half_height + centre,
        Convex::Cylinder {
            radius,
            half_height,
        } => swing() * radius.hypot(*half_height) + centre,
        _ => reach(shape, sweep.local_center) * theta.length(),
    }
}

/// The largest distance from the local point `c` to any point of the shape (m).
fn reach(shape: &Convex, c: Vec3) -> Real {
    let r = match shape {
        Convex::Sphere { radius } => c.length() + radius,
        Convex::Box { half_extents } => (c.abs() + *half_extents).length(),
        Convex::Capsule {
            radius,
            half_height,
        } => {
            let h = Vec3::new(0.0, *half_height, 0.0);
            (c - h).length().max((c + h).length()) + radius
        }
        Convex::Cylinder {
            radius,
            half_height,
        } => {
            // The farthest rim point: radially opposite c, at the farther cap.
            let radial = (c.x * c.x + c.z * c.z).sqrt() + radius;
            let axial = c.y.abs() + half_height;
            (radial * radial + axial * axial).sqrt()
        }
        Convex::Hull(h) => h
            .vertices()
            .iter()
            .fold(0.0, |m: Real, v| m.max((*v - c).length())),
        Convex::Triangle(t) => t.iter().fold(0.0, |m: Real, v| m.max((*v - c).length())),
    };
    if r.is_finite() {
        r
    } else {
        0.0
    }
}
