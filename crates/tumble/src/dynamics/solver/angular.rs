//! Rolling resistance and torsional (spinning) friction: a manifold's angular friction
//! rows, for pairs where a body has either coefficient (`BodyDef::rolling_resistance`,
//! `BodyDef::torsional_friction`); every other manifold has none and pays one branch.
//!
//! The rows act on the relative angular velocity ω_rel = ω_b − ω_a, about the manifold's
//! tangents t₁, t₂ (rolling) and its normal n (twist):
//!
//! ```text
//! Ċ_k = d_k · (ω_b − ω_a)                 J = [0, −d_k, 0, d_k]    (pure angular)
//! K   = d_i · (I_a⁻¹ + I_b⁻¹) d_j          the images I⁻¹ d are the rows' `turn`s
//! |λ_roll| ≤ μ_r r Σλ_n                   a disc in the (t₁, t₂) plane, as the friction cone
//! |λ_twist| ≤ μ_t Σλ_n
//! ```
//!
//! with Σλ_n the manifold's normal impulse (the sum over its points, as they stand when the
//! rows are solved), μ_r and μ_t the pair's coefficients (the larger of each, see
//! [`combine`]) and r the contact's rolling radius ([`rolling_radius`]). The two rolling rows
//! couple through I⁻¹ unless the inertia is isotropic, so they are solved as one 2×2 block.
//! Like friction the rows have no position error: the solve and the relax passes run them
//! alike, after the manifold's normal and friction rows, and each substep warm-starts them
//! with the accumulated impulses, which the manifold keeps for the next step
//! (`Manifold::angular_impulse`).
//!
//! Closed form: a solid ball (I = ⅖ m r²) rolling without slipping on a level plane, with
//! friction force F at the contact and the rolling torque τ = μ_r r N against its turning:
//! m v̇ = −F, I ω̇ = r F − μ_r r N, v = r ω, so v̇ (m + I/r²) = −μ_r N and
//! a = μ_r g / (1 + I/(m r²)) = (5/7) μ_r g. A ball spinning about the normal on its point of
//! contact slows at ω̇ = μ_t m g / I. Both are measured in `tests/engine/rolling_friction.rs`.

use super::body::BodySim;
use super::contact::Point;
use super::rows::Pair;
use crate::collision::narrow_phase::Manifold;
use crate::math::{Real, Vec3};

/// The pair's rolling resistance (dimensionless) and torsional friction (m): each the
/// larger of the two bodies'. Not the geometric mean that friction uses: the ground, like
/// every body, defaults to zero, and a ball given rolling resistance should roll resisted
/// on any floor (with √(μ_a μ_b) it would need both set); the loss comes from the body that
/// deforms more, so the lossier surface decides. Box2D v3 and MuJoCo combine by the
/// maximum too, so values carry over. Zero for both bodies stays zero: no rows.
#[inline]
pub(super) fn combine(a: &BodySim, b: &BodySim) -> (Real, Real) {
    (
        a.rolling_resistance.max(b.rolling_resistance),
        a.torsional_friction.max(b.torsional_friction),
    )
}

/// The contact's rolling radius (m): for each body the solver moves, the distance from its
/// centre of mass to the contact plane (mean over the points, on its own surface, so a
/// ball's is its radius exactly); the smaller of the two. Static and kinematic bodies do not
/// roll (a plane's or a mesh's centre is anywhere), so a ball on the ground has the ball's
/// radius, and a ball on a crate too (the crate's half-height is the larger).
fn rolling_radius(m: &Manifold, (a, b): (&BodySim, &BodySim)) -> Real {
    let (n, count) = (m.normal, m.len() as Real);
    let mean = |side: &dyn Fn(&crate::collision::narrow_phase::ContactPoint) -> Real| {
        m.points().iter().map(side).sum::<Real>() / count
    };
    let ra = match a.moves {
        true => mean(&|p| n.dot(p.point_a - a.x)).max(0.0),
        false => Real::INFINITY,
    };
    let rb = match b.moves {
        true => mean(&|p| n.dot(b.x - p.point_b)).max(0.0),
        false => Real::INFINITY,
    };
    let r = ra.min(rb);
    if r.is_finite() {
        r
    } else {
        0.0
    }
}

/// A manifold's rolling and twist rows (see the module docs).
#[derive(Debug, Clone, Copy)]
pub(crate) struct AngularRows {
    /// The torque limits per unit normal impulse (m): μ_r r for rolling, μ_t for the twist.
    rolling_arm: Real,
    twist_arm: Real,
    /// t₁, t₂, n: the manifold's tangents and normal.
    axes: [Vec3; 3],
    /// I_a⁻¹ d and I_b⁻¹ d per axis: the change of ω per unit angular impulse.
    turn_a: [Vec3; 3],
    turn_b: [Vec3; 3],
    /// The rolling block's inverse K⁻¹ (a pseudo-inverse where K is singular: a planar
    /// body turns about z alone), and the twist row's effective mass.
    rolling_mass: [[Real; 2]; 2],
    twist_mass: Real,
    /// Accumulated impulses about t₁, t₂ (rolling) and n (twist) (N·m·s).
    impulse: [Real; 3],
}

impl AngularRows {
    /// The rows of manifold `m` between `a` and `b` with the pair's coefficients (see
    /// [`combine`]; not both zero), along the constraint's `tangents`, warm-started from the
    /// manifold's last angular impulse.
    pub fn new(
        m: &Manifold,
        (a, b): (&BodySim, &BodySim),
        tangents: [Vec3; 2],
        (rolling, twist): (Real, Real),
    ) -> AngularRows {
        let axes = [tangents[0], tangents[1], m.normal];
        let turn_a = axes.map(|d| a.inv_inertia * d);
        let turn_b = axes.map(|d| b.inv_inertia * d);
        let k = |i: usize, j: usize| axes[i].dot(turn_a[j] + turn_b[j]);
        let twist_k = k(2, 2);
        let warm = |i: usize, on: bool| {
            if on {
                axes[i].dot(m.angular_impulse)
            } else {
                0.0
            }
        };
        AngularRows {
            rolling_arm: rolling * rolling_radius(m, (a, b)),
            twist_arm: twist,
            axes,
            turn_a,
            turn_b,
            rolling_mass: inverse_2x2([[k(0, 0), k(0, 1)], [k(1, 0), k(1, 1)]]),
            twist_mass: if twist_k > 0.0 { 1.0 / twist_k } else { 0.0 },
            impulse: [
                warm(0, rolling > 0.0),
                warm(1, rolling > 0.0),
                warm(2, twist > 0.0),
            ],
        }
    }

    /// Applies angular impulse `lambda` about axis `k`: −to body a, + to body b. A body
    /// the solver does not move has zero inverse inertia, and its velocities are not
    /// stored back (`Pair::store`).
    #[inline]
    fn apply(&self, k: usize, lambda: Real, s: &mut Pair) {
        s.wa -= self.turn_a[k] * lambda;
        s.wb += self.turn_b[k] * lambda;
    }

    /// Scales the warm-start impulses by `k` (a substep `k` times as long).
    pub fn rescale(&mut self, k: Real) {
        self.impulse = self.impulse.map(|i| i * k);
    }

    /// Applies the accumulated impulses again (each substep).
    pub fn warm_start(&self, s: &mut Pair) {
        for k in 0..3 {
            self.apply(k, self.impulse[k], s);
        }
    }

    /// One pass: the twist, then rolling, each clamped by the manifold's normal impulse
    /// (the sum over `points`, as the pass left it).
    pub fn solve(&mut self, points: &[Point], s: &mut Pair) {
        let pressed: Real = points.iter().map(|p| p.normal_impulse).sum();
        if self.twist_arm > 0.0 {
            let limit = self.twist_arm * pressed;
            let spin = self.axes[2].dot(s.wb - s.wa);
            let old = self.impulse[2];
            let total = (old - self.twist_mass * spin).max(-limit).min(limit);
            self.apply(2, total - old, s);
            self.impulse[2] = total;
        }
        if self.rolling_arm > 0.0 {
            let limit = self.rolling_arm * pressed;
            let w = s.wb - s.wa;
            let roll = [self.axes[0].dot(w), self.axes[1].dot(w)];
            let (k, old) = (&self.rolling_mass, [self.impulse[0], self.impulse[1]]);
            let mut total = [
                old[0] - (k[0][0] * roll[0] + k[0][1] * roll[1]),
                old[1] - (k[1][0] * roll[0] + k[1][1] * roll[1]),
            ];
            // Inside the disc the rolling stops; outside, the impulse is scaled back onto it.
            let length2 = total[0] * total[0] + total[1] * total[1];
            if length2 > limit * limit {
                let scale = limit / length2.sqrt();
                total = [total[0] * scale, total[1] * scale];
            }
            self.apply(0, total[0] - old[0], s);
            self.apply(1, total[1] - old[1], s);
            (self.impulse[0], self.impulse[1]) = (total[0], total[1]);
        }
    }

    /// Into the manifold: the accumulated impulse as a world vector on body b (N·m·s),
    /// for the next step's warm start and for reports.
    pub fn store(&self, m: &mut Manifold) {
        let [i0, i1, i2] = self.impulse;
        m.angular_impulse = self.axes[0] * i0 + self.axes[1] * i1 + self.axes[2] * i2;
    }
}

/// K⁻¹ of a symmetric positive semi-definite 2×2 block; where K is singular (rank one, as
/// for a planar body, which turns about z alone) its pseudo-inverse K / tr(K)², exact for
/// K = λ u uᵀ; zero where K is.
fn inverse_2x2(k: [[Real; 2]; 2]) -> [[Real; 2]; 2] {
    let det = k[0][0] * k[1][1] - k[0][1] * k[1][0];
    let trace = k[0][0] + k[1][1];
    if det > 1e-6 * k[0][0] * k[1][1] && det > 0.0 {
        let inv = 1.0 / det;
        [
            [k[1][1] * inv, -k[0][1] * inv],
            [-k[1][0] * inv, k[0][0] * inv],
        ]
    } else if trace > 0.0 {
        let s = 1.0 / (trace * trace);
        [[k[0][0] * s, k[0][1] * s], [k[1][0] * s, k[1][1] * s]]
    } else {
        [[0.0; 2]; 2]
    }
}
