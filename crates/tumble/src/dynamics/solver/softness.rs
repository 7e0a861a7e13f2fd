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
