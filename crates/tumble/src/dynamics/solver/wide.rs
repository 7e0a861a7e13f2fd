//! The arithmetic the contact rows are written in (see `super::rows`), over one lane or
//! [`LANES`](super::lanes::LANES).
//!
//! [`Wide`] is a `Real` per lane with the operations the rows use, [`Vector`] a 3-vector
//! of it, and [`LaneMask`] a condition per lane. Two kinds implement them:
//!
//! - `Real` with glam's `Vec3` and `bool` (here): the scalar solver, which the rows give
//!   exactly the code it had when it was written by hand, branches included;
//! - `Lanes` with `Lanes3` and `Mask` (in `super::lanes`): eight manifolds at once.
//!
//! Every operation of the lane kind is, lane by lane, the operation of the scalar kind
//! (`super::lanes` proves it for each), so one generic expression gives each lane the bits
//! the scalar solver gives. The one place the two differ on purpose is
//! [`LaneMask::choose`]: a scalar condition runs only the branch it picks, while the
//! lanes run both branches and keep each lane's pick, never mixing the two. Either way a
//! value is the chosen branch's, bit for bit, which is what keeps the paths equal.

use std::fmt::Debug;
use std::ops::{Add, BitAnd, Div, Mul, Neg, Not, Sub};

use crate::math::{Real, Vec3};

/// Values that a condition can choose between: `yes` where `mask` holds, `no` elsewhere,
/// the chosen bits unchanged.
pub(super) trait Blend<M>: Sized {
    fn blend(mask: M, yes: Self, no: Self) -> Self;
}

/// A condition per lane: `bool` for one lane, `Mask` for eight.
pub(super) trait LaneMask: Copy + BitAnd<Output = Self> + Not<Output = Self> {
    /// Whether the condition holds in any lane: lets a pass skip work no lane needs, as
    /// the scalar code returns early.
    fn any(self) -> bool;

    /// `yes()` where the condition holds, `no()` elsewhere. One lane evaluates only the
    /// branch it takes (the scalar code's `if`); lanes evaluate both and blend.
    fn choose<T: Blend<Self>>(self, yes: impl FnOnce() -> T, no: impl FnOnce() -> T) -> T;

    /// `yes` where the condition holds, `no` elsewhere: [`Self::choose`] between values
    /// already computed.
    #[inline(always)]
    fn pick<T: Blend<Self>>(self, yes: T, no: T) -> T {
        T::blend(self, yes, no)
    }
}

/// A 3-vector over [`Wide`] `W`, with glam's products operation for operation
/// (`dot` is (x·x′ + y·y′) + z·z′, `cross` as in `DVec3::cross`).
pub(super) trait Vector<W>:
    Copy + Default + Debug + Add<Output = Self> + Sub<Output = Self>
{
    fn new(x: W, y: W, z: W) -> Self;
    fn dot(self, rhs: Self) -> W;
    fn cross(self, rhs: Self) -> Self;
    /// Each coordinate times `k`.
    fn scale(self, k: W) -> Self;
}

/// One `Real` per lane, with the operations of the contact rows. Each is the `Real`
/// operation of the same name (no fused multiply–add, no reassociation).
pub(super) trait Wide:
    Copy
    + Default
    + Debug
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Div<Output = Self>
    + Neg<Output = Self>
    + Blend<Self::Mask>
{
    type Mask: LaneMask;
    type V3: Vector<Self> + Blend<Self::Mask>;

    /// Every lane `x`.
    fn splat(x: Real) -> Self;
    fn max(self, rhs: Self) -> Self;
    fn min(self, rhs: Self) -> Self;
    /// `Real::clamp`, two comparisons as the standard library writes it.
    fn clamp(self, lo: Self, hi: Self) -> Self;
    fn sqrt(self) -> Self;
    fn greater(self, rhs: Self) -> Self::Mask;
    fn at_most(self, rhs: Self) -> Self::Mask;
    fn equals(self, rhs: Self) -> Self::Mask;
}

impl LaneMask for bool {
    #[inline(always)]
    fn any(self) -> bool {
        self
    }

    #[inline(always)]
    fn choose<T: Blend<bool>>(self, yes: impl FnOnce() -> T, no: impl FnOnce() -> T) -> T {
        if self {
            yes()
        } else {
            no()
        }
    }
}

impl Blend<bool> for Real {
    #[inline(always)]
    fn blend(mask: bool, yes: Real, no: Real) -> Real {
        if mask {
            yes
        } else {
            no
        }
    }
}

impl Blend<bool> for Vec3 {
    #[inline(always)]
    fn blend(mask: bool, yes: Vec3, no: Vec3) -> Vec3 {
        if mask {
            yes
        } else {
            no
        }
    }
}

/// Arrays and tuples blend element by element, under any kind of condition.
impl<M: Copy, T: Blend<M> + Copy, const N: usize> Blend<M> for [T; N] {
    #[inline(always)]
    fn blend(mask: M, yes: [T; N], no: [T; N]) -> [T; N] {
        let mut r = no;
        for (r, y) in r.iter_mut().zip(yes) {
            *r = T::blend(mask, y, *r);
        }
        r
    }
}

impl<M: Copy, A: Blend<M>, B: Blend<M>> Blend<M> for (A, B) {
    #[inline(always)]
    fn blend(mask: M, yes: (A, B), no: (A, B)) -> (A, B) {
        (A::blend(mask, yes.0, no.0), B::blend(mask, yes.1, no.1))
    }
}

impl<M: Copy, A: Blend<M>, B: Blend<M>, C: Blend<M>> Blend<M> for (A, B, C) {
    #[inline(always)]
    fn blend(mask: M, yes: (A, B, C), no: (A, B, C)) -> (A, B, C) {
        (
            A::blend(mask, yes.0, no.0),
            B::blend(mask, yes.1, no.1),
            C::blend(mask, yes.2, no.2),
        )
    }
}

impl Vector<Real> for Vec3 {
    #[inline(always)]
    fn new(x: Real, y: Real, z: Real) -> Vec3 {
        Vec3::new(x, y, z)
    }
    #[inline(always)]
    fn dot(self, rhs: Vec3) -> Real {
        Vec3::dot(self, rhs)
    }
    #[inline(always)]
    fn cross(self, rhs: Vec3) -> Vec3 {
        Vec3::cross(self, rhs)
    }
    #[inline(always)]
    fn scale(self, k: Real) -> Vec3 {
        self * k
    }
}

impl Wide for Real {
    type Mask = bool;
    type V3 = Vec3;

    #[inline(always)]
    fn splat(x: Real) -> Real {
        x
    }
    #[inline(always)]
    fn max(self, rhs: Real) -> Real {
        Real::max(self, rhs)
    }
    #[inline(always)]
    fn min(self, rhs: Real) -> Real {
        Real::min(self, rhs)
    }
    #[inline(always)]
    fn clamp(self, lo: Real, hi: Real) -> Real {
        Real::clamp(self, lo, hi)
    }
    #[inline(always)]
    fn sqrt(self) -> Real {
        Real::sqrt(self)
    }
    #[inline(always)]
    fn greater(self, rhs: Real) -> bool {
        self > rhs
    }
    #[inline(always)]
    fn at_most(self, rhs: Real) -> bool {
        self <= rhs
    }
    #[inline(always)]
    fn equals(self, rhs: Real) -> bool {
        self == rhs
    }
}
