//! Soft constraints (Box2D v3's "soft step"): a constraint behaves like a damped spring of
//! a chosen frequency instead of a rigid rod, which keeps stiff stacks stable at game
//! steps without velocity-dependent fudge factors.
//!
//! For a constraint with effective mass m, spring stiffness k = m ω², damping c = 2 m ζ ω
//! (ω = 2π·hertz), one implicit-Euler step of the spring–damper system gives the impulse
//!
//! ```text
//! λ = −m_eff · mass_scale · (v + bias_rate · C) − impulse_scale · λ_accumulated
//! bias_rate = ω / (2ζ + hω),  mass_scale = hω(2ζ + hω) / (1 + hω(2ζ + hω)),
//! impulse_scale = 1 / (1 + hω(2ζ + hω))
//! ```
//!
//! (derivation: Catto, "Solver2D", 2024). As hertz → ∞ it tends to the rigid constraint.

use crate::math::{Real, PI};

/// The three coefficients of a soft constraint for one substep.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Softness {
    /// Multiplies the position error into a velocity bias (1/s).
    pub bias_rate: Real,
    /// Scales the effective mass.
    pub mass_scale: Real,
    /// Scales the accumulated impulse subtracted each iteration.
    pub impulse_scale: Real,
}

impl Softness {
    /// The rigid limit (no bias, full mass).
    pub const RIGID: Softness = Softness {
        bias_rate: 0.0,
        mass_scale: 1.0,
        impulse_scale: 0.0,
    };

    /// The same spring `s` times as stiff, damped with the same ratio for `s` times the
    /// mass (see [`LoadSpring`]): the bias rate is kept and hω(2ζ + hω) multiplied by `s`.
    pub fn stiffened(&self, s: Real) -> Softness {
        if self.impulse_scale <= 0.0 || s == 1.0 {
            return *self;
        }
        let a2 = s * self.mass_scale / self.impulse_scale;
        Softness {
            bias_rate: self.bias_rate,
            mass_scale: a2 / (1.0 + a2),
            impulse_scale: 1.0 / (1.0 + a2),
        }
    }

    /// Coefficients for a spring of `hertz` and damping ratio `zeta` over substep `h`.
    pub fn new(hertz: Real, zeta: Real, h: Real) -> Softness {
        if hertz <= 0.0 {
            return Softness::RIGID;
        }
        let omega = 2.0 * PI * hertz;
        let a1 = 2.0 * zeta + h * omega;
        let a2 = h * omega * a1;
        let a3 = 1.0 / (1.0 + a2);
        Softness {
            bias_rate: omega / a1,
            mass_scale: a2 * a3,
            impulse_scale: a3,
        }
    }
}

/// The contacts' spring of an island with a large mass ratio, stiffened for its load.
///
/// The soft contact is a spring of stiffness m ω² for its effective mass m, so a load sinks
/// it by λ / (m ω² h) for an impulse λ per substep. Under a heavy body m is about the light
/// body's mass and the load the heavy one's weight: a 1:1000 pair sank 7 cm in each
/// contact. Made a spring of ω for the mass it holds up, M = λ / (h g), a manifold sinks
/// a lone box's depth whatever it carries: k = s m ω² with s = M / m, and the damping
/// c = 2 M ζ ω that keeps its damping ratio for that mass. Substituted into the implicit
/// step this leaves the bias rate unchanged and multiplies hω(2ζ + hω) by s, so the
/// impulse scale is 1 / (1 + s hω(2ζ + hω)) and the mass scale 1 minus that.
///
/// s is capped at `STIFFEST`: the quarter-substep cap on ω is what keeps one
/// Gauss–Seidel pass stable, and stiffer contacts need more passes (`mass_ratio.rs`).
/// Uncapped, or at 8, a 1:1000 pair and a 200:1 slab on cubes slid apart at 1 to 4 m/s
/// even with six passes. Stiffening every island's contacts at the default pass made a
/// 20-box tower of equal boxes lean 5.5 cm at 1.5 times (9.6 mm unstiffened) and fall
/// from 2 times (docs/integrators.md, "Tall stacks": finer substeps are the cure).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct LoadSpring {
    /// hω(2ζ + hω) of the contacts' spring; zero for a rigid row (PGS).
    stiffness: Real,
    /// The impulse scale of an unstiffened manifold.
    base: Real,
    /// 1 / (h g): the mass an impulse per substep holds up (kg per N s).
    per_impulse: Real,
}

/// The most a manifold's spring is stiffened (see [`LoadSpring`]).
pub(crate) const STIFFEST: Real = 4.0;

impl LoadSpring {
    /// For contacts of softness `soft` over substep `h`, under gravity `g` (m/s²; below
    /// 1 m/s², and without gravity, a load of 1 m/s² on a manifold's mass counts as its
    /// own, so that weightless scenes still have a scale).
    pub fn new(soft: &Softness, h: Real, g: Real) -> LoadSpring {
        let g = g.max(1.0);
        let stiffness = if soft.impulse_scale > 0.0 {
            soft.mass_scale / soft.impulse_scale
        } else {
            0.0
        };
        LoadSpring {
            stiffness,
            base: soft.impulse_scale,
            per_impulse: 1.0 / (h * g),
        }
    }

    /// The impulse scale of a manifold whose points, of effective masses summing to
    /// `mass`, pushed `impulse` in all per substep last step.
    pub fn impulse_scale(&self, impulse: Real, mass: Real) -> Real {
        let held = impulse * self.per_impulse;
        if self.stiffness == 0.0 || held <= mass {
            return self.base;
        }
        1.0 / (1.0 + (held / mass).min(STIFFEST) * self.stiffness)
    }
}
