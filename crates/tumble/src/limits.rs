//! The ranges the engine accepts, and the speeds a step may reach.
//!
//! A value can be finite and still be nonsense a step cannot survive: an orientation of
//! 1e308 overflows when normalised, a density of 1e-300 gives an inverse mass of 1e300, a
//! spring of 1e300 Hz squares to infinity. Each bound below is far outside what any
//! physical scene needs and far inside what the arithmetic of a step can carry without
//! overflow, in f32 too (3.4e38): the largest product a step forms of two bounded values
//! stays below 1e32. Values beyond them are refused where they enter (scene files, setters,
//! Python), with the bound in the message.
//!
//! The speeds are different: they are the invariant every step checks on its result (see
//! `pipeline/world/step.rs`). They are settings with generous defaults, since a scene of
//! bullets or of turbines may need more; a body set faster than them is refused, a body a
//! step makes faster than them stops the run with the step undone.

use crate::math::Real;

/// Largest accepted |coordinate| of a position (m): 1e9 m, three light-seconds.
pub const MAX_COORDINATE: Real = 1e9;
/// Largest accepted |component| of gravity (m/s²): 1e6, a hundred thousand g.
pub const MAX_ACCELERATION: Real = 1e6;
/// Accepted body masses (kg): a speck of dust to a mountain.
pub const MIN_MASS: Real = 1e-12;
/// See [`MIN_MASS`].
pub const MAX_MASS: Real = 1e15;
/// Accepted principal moments of inertia (kg·m²).
pub const MIN_MOMENT: Real = 1e-30;
/// See [`MIN_MOMENT`].
pub const MAX_MOMENT: Real = 1e30;
/// The share of a tensor's largest principal moment at or below which another counts as
/// zero (not positive definite): the eigen solve leaves a moment meant to be zero at a few
/// ε of the others (a rod's tensor written with off-diagonal terms, PyBullet's biped2d
/// sliders: 2e-18 in f64, 1e-7 in f32); a needle a micrometre thick and a metre long is at
/// 6e-12, above this in f64. Accepted, such a body was too light to turn for a slider
/// joint to hold it along its locked axes.
pub const ZERO_MOMENT_SHARE: Real = 64.0 * Real::EPSILON;
/// Largest accepted frequency of a soft constraint or spring (Hz): far beyond any step's
/// resolution (1/dt), where the soft constraint is already rigid.
pub const MAX_HERTZ: Real = 1e6;
/// Largest accepted damping ratio (1 is critical).
pub const MAX_DAMPING_RATIO: Real = 1e6;
/// Largest accepted |gravity_scale| of a body: a million times the world's gravity.
pub const MAX_GRAVITY_SCALE: Real = 1e6;
/// Most solver substeps a step may take, and most passes a substep may make: far beyond
/// any scene's needs (the defaults are 4 and 1), and small enough that a tall stack's
/// finer substeps (up to 8 times as many) stay countable in `u32` and that a step with
/// both at their limit (10^8 passes: minutes for a small world) ends rather than running
/// for days, as 2^24 of each did.
pub const MAX_SUBSTEPS: u32 = 10_000;
/// See [`MAX_SUBSTEPS`].
pub const MAX_ITERATIONS: u32 = 10_000;
/// Largest accepted magnitude of any other coefficient: stiffness (N/m), damping (N·s/m),
/// forces (N), impulses (N·s), torques, drag and motor limits.
pub const MAX_MAGNITUDE: Real = 1e15;

/// The speeds no body may exceed, checked on every step's result.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SpeedLimits {
    /// Largest speed of a centre of mass (m/s); default 10 km/s, faster than a rifle
    /// bullet (1 km/s) or an orbit (7.8 km/s), times the scene's `length_unit`.
    pub max_speed: Real,
    /// Largest angular speed (rad/s); default 1e5, seven times an ultracentrifuge's.
    pub max_angular_speed: Real,
}

impl SpeedLimits {
    /// The defaults for a scene whose lengths are in `length_unit` metres.
    pub fn for_length_unit(length_unit: Real) -> SpeedLimits {
        SpeedLimits {
            max_speed: 1e4 * length_unit,
            max_angular_speed: 1e5,
        }
    }
}

impl Default for SpeedLimits {
    fn default() -> Self {
        SpeedLimits::for_length_unit(1.0)
    }
}

/// How many contacts the engine keeps, so that memory follows the number of bodies and not
/// how much they overlap. A thousand boxes created at one point touch each other in half a
/// million pairs; kept whole, their manifolds took 2 GB (about 4 kB a pair: the manifold
/// and last step's copy, the solver's rows and lanes), and twenty thousand would need 800.
///
/// The caps are on crowded bodies. A dynamic body is crowded once it overlaps `per_body`
/// other dynamic bodies (a manifold point with negative separation), or is sunk into half
/// as many (interpenetrating by more than the contact margin, or a quarter of the thinner
/// body's thickness); two crowded bodies are not paired. Every pair a crowd keeps is
/// charged to a body not yet crowded, so a crowd keeps contacts in proportion to its
/// bodies (about `per_body / 2` each when all are sunk, at most about `per_body` each),
/// whatever the overlap. Resting bodies overlap by the slop and sink into nothing: an
/// equal sphere overlaps at most twelve neighbours, a box in a pile fewer, and a ground
/// under a million bodies or a plate on a bed of marbles keeps every contact (the small
/// bodies are not crowded, and pairs with static bodies are never shed). Bodies created
/// inside each other shed the excess pairs, the last ones in pair order, and are still
/// pushed apart by the rest. What can be shed that should not: a contact between two
/// bodies that each overlap 16 others, such as two crates side by side, each on a pallet
/// of 16 loose blocks.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ContactLimits {
    /// Dynamic bodies a body may overlap (or half as many it may be sunk into) before it
    /// counts as crowded; default 16. The broad phase, whose boxes are looser, allows
    /// [`Self::CANDIDATES_PER_CONTACT`] times as many sunk boxes, and 16 times as many
    /// candidates standing far apart.
    pub per_body: u32,
    /// Contact manifolds in a step, over all pairs; a step that would exceed it is undone
    /// and stops with an error naming the limit. Default 2^20 (1,048,576), about 4 GB.
    pub per_step: u32,
}

impl ContactLimits {
    /// Sunk candidate pairs the broad phase keeps per contact the cache may keep: boxes
    /// that overlap deeply need not touch (two rotated boxes), so it keeps more.
    pub const CANDIDATES_PER_CONTACT: u32 = 4;
}

impl Default for ContactLimits {
    fn default() -> Self {
        ContactLimits {
            per_body: 16,
            per_step: 1 << 20,
        }
    }
}

/// Most manifolds one pair of bodies keeps (a compound's children against a mesh's
/// triangles may make one each): the deepest are kept. Four points a manifold, so at most
/// 1,024 points a pair.
pub const MAX_MANIFOLDS_PER_PAIR: usize = 256;

/// A number as people write it: `0.683`, `1e15`, `2.5e-7`, never 300 digits.
pub fn short(x: Real) -> String {
    if x == 0.0 || !x.is_finite() {
        return format!("{x}");
    }
    let a = x.abs();
    if (1e-4..1e6).contains(&a) {
        // Six significant digits, trailing zeros dropped.
        let digits = (5 - a.log10().floor() as i32).clamp(0, 10) as usize;
        let s = format!("{x:.digits$}");
        let s = if s.contains('.') {
            s.trim_end_matches('0').trim_end_matches('.').to_string()
        } else {
            s
        };
        return s;
    }
    let s = format!("{x:.5e}");
    let (mantissa, exponent) = s.split_once('e').unwrap_or((&s, "0"));
    let mantissa = if mantissa.contains('.') {
        mantissa.trim_end_matches('0').trim_end_matches('.')
    } else {
        mantissa
    };
    format!("{mantissa}e{exponent}")
}

#[cfg(test)]
mod tests {
    use super::short;

    #[test]
    fn numbers_in_messages_are_short() {
        assert_eq!(short(0.683), "0.683");
        assert_eq!(short(1e15), "1e15");
        assert_eq!(short(-2.5e-7), "-2.5e-7");
        assert_eq!(short(3e38), "3e38");
        assert_eq!(short(41.0), "41");
        assert_eq!(short(123456.0), "123456");
        assert_eq!(short(1.0 / 3.0), "0.333333");
        assert!(short(Real::MAX).len() < 16);
    }

    use crate::math::Real;
}

crate::codec::codec_struct!(SpeedLimits {
    max_speed,
    max_angular_speed
});
crate::codec::codec_struct!(ContactLimits { per_body, per_step });
