//! Lanes: [`LANES`] values of `Real` worked on together, for the contact solver's wide
//! passes (see `super::contact_wide`).
//!
//! Every operation is a plain loop over the lanes applying the very operation the scalar
//! code applies (`+`, `*`, `f64::max`, `sqrt`...), so each lane's result is bit for bit
//! the scalar one; LLVM turns the loops into vector instructions (an operation on eight
//! f64 lanes is four SSE2 instructions in a baseline build, two in a function compiled for
//! AVX2, one in a function compiled for AVX-512). There is no fused multiply–add and no
//! reassociation: callers keep the scalar code's expression order. Comparisons give a
//! [`Mask`] of all-ones or all-zeros lanes, and branches of the scalar code become
//! [`Mask::select`]s between both outcomes.

use std::ops::{Add, BitAnd, BitOr, Div, Mul, Neg, Not, Sub};

use super::wide::{Blend, LaneMask, Vector, Wide};
use crate::math::{Real, Vec3};

/// Number of lanes. A group's updates form one dependent chain through its bodies'
/// velocities, so lanes are what keeps the processor busy: 8 (two AVX2 registers of f64,
/// one of f32) measured clearly faster than 4 on the pyramid, 16 slower (spills). With
/// AVX-512, 16 f32 lanes (one register) were no faster than 8 (4 Dec: pyramid about the
/// same, the rain slower).
pub(crate) const LANES: usize = 8;

/// The unsigned integer as wide as `Real`, for masks.
#[cfg(not(feature = "f32"))]
type Bits = u64;
#[cfg(feature = "f32")]
type Bits = u32;

/// [`LANES`] values of `Real`, aligned as one vector register.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
#[repr(C, align(32))]
pub(crate) struct Lanes(pub [Real; LANES]);

/// Per lane all ones (true) or all zeros (false), as wide as `Real`.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
#[repr(C, align(32))]
pub(crate) struct Mask([Bits; LANES]);

impl Lanes {
    /// Every lane `x`.
    #[inline(always)]
    pub fn splat(x: Real) -> Lanes {
        Lanes([x; LANES])
    }

    #[inline(always)]
    fn map2(self, rhs: Lanes, f: impl Fn(Real, Real) -> Real) -> Lanes {
        let mut r = self.0;
        for (r, y) in r.iter_mut().zip(rhs.0) {
            *r = f(*r, y);
        }
        Lanes(r)
    }

    #[inline(always)]
    fn compare(self, rhs: Lanes, f: impl Fn(Real, Real) -> bool) -> Mask {
        let mut m = [0; LANES];
        for ((m, x), y) in m.iter_mut().zip(self.0).zip(rhs.0) {
            *m = if f(x, y) { Bits::MAX } else { 0 };
        }
        Mask(m)
    }

    /// `Real::max` per lane.
    #[inline(always)]
    pub fn max(self, rhs: Lanes) -> Lanes {
        self.map2(rhs, Real::max)
    }

    /// `Real::min` per lane.
    #[inline(always)]
    pub fn min(self, rhs: Lanes) -> Lanes {
        self.map2(rhs, Real::min)
    }

    /// `Real::clamp` per lane, written as it is written in the standard library (two
    /// comparisons), so that it gives the same result for every input.
    #[inline(always)]
    pub fn clamp(self, min: Lanes, max: Lanes) -> Lanes {
        let x = self.lt(min).select(min, self);
        x.gt(max).select(max, x)
    }

    /// `Real::sqrt` per lane.
    #[inline(always)]
    pub fn sqrt(self) -> Lanes {
        let mut r = self.0;
        for r in &mut r {
            *r = r.sqrt();
        }
        Lanes(r)
    }

    #[inline(always)]
    pub fn lt(self, rhs: Lanes) -> Mask {
        self.compare(rhs, |x, y| x < y)
    }
    #[inline(always)]
    pub fn le(self, rhs: Lanes) -> Mask {
        self.compare(rhs, |x, y| x <= y)
    }
    #[inline(always)]
    pub fn gt(self, rhs: Lanes) -> Mask {
        self.compare(rhs, |x, y| x > y)
    }
    #[inline(always)]
    pub fn eq(self, rhs: Lanes) -> Mask {
        self.compare(rhs, |x, y| x == y)
    }
}

macro_rules! lanes_op {
    ($trait:ident, $f:ident, $op:tt) => {
        impl $trait for Lanes {
            type Output = Lanes;
            #[inline(always)]
            fn $f(self, rhs: Lanes) -> Lanes {
                self.map2(rhs, |x, y| x $op y)
            }
        }
    };
}
lanes_op!(Add, add, +);
lanes_op!(Sub, sub, -);
lanes_op!(Mul, mul, *);
lanes_op!(Div, div, /);

impl Neg for Lanes {
    type Output = Lanes;
    #[inline(always)]
    fn neg(self) -> Lanes {
        let mut r = self.0;
        for r in &mut r {
            *r = -*r;
        }
        Lanes(r)
    }
}

impl Mask {
    /// Sets lane `l` to `on`.
    #[inline(always)]
    pub fn set(&mut self, l: usize, on: bool) {
        self.0[l] = if on { Bits::MAX } else { 0 };
    }

    /// Whether lane `l` is set.
    #[cfg(test)]
    #[inline(always)]
    pub fn test(self, l: usize) -> bool {
        self.0[l] != 0
    }

    /// Whether any lane is set.
    #[inline(always)]
    pub fn any(self) -> bool {
        self.0.iter().fold(0, |acc, &m| acc | m) != 0
    }

    /// Per lane `yes` where set, `no` elsewhere: the bits of one or the other, unchanged.
    #[inline(always)]
    pub fn select(self, yes: Lanes, no: Lanes) -> Lanes {
        let mut r = no.0;
        for ((r, y), m) in r.iter_mut().zip(yes.0).zip(self.0) {
            *r = Real::from_bits((y.to_bits() & m) | (r.to_bits() & !m));
        }
        Lanes(r)
    }

    /// [`Self::select`] for each coordinate.
    #[inline(always)]
    pub fn select3(self, yes: Lanes3, no: Lanes3) -> Lanes3 {
        Lanes3 {
            x: self.select(yes.x, no.x),
            y: self.select(yes.y, no.y),
            z: self.select(yes.z, no.z),
        }
    }
}

impl BitAnd for Mask {
    type Output = Mask;
    #[inline(always)]
    fn bitand(self, rhs: Mask) -> Mask {
        let mut m = self.0;
        for (m, r) in m.iter_mut().zip(rhs.0) {
            *m &= r;
        }
        Mask(m)
    }
}

impl BitOr for Mask {
    type Output = Mask;
    #[inline(always)]
    fn bitor(self, rhs: Mask) -> Mask {
        let mut m = self.0;
        for (m, r) in m.iter_mut().zip(rhs.0) {
            *m |= r;
        }
        Mask(m)
    }
}

impl Not for Mask {
    type Output = Mask;
    #[inline(always)]
    fn not(self) -> Mask {
        let mut m = self.0;
        for m in &mut m {
            *m = !*m;
        }
        Mask(m)
    }
}

/// [`LANES`] 3-vectors, coordinate by coordinate. Its products are glam's, operation for
/// operation (`dot` is (x·x′ + y·y′) + z·z′, `cross` as in `DVec3::cross`).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub(crate) struct Lanes3 {
    pub x: Lanes,
    pub y: Lanes,
    pub z: Lanes,
}

impl Lanes3 {
    /// Lane `l` is `field(index[l])`: written as a loop, which the compiler inlines into
    /// the kernels, where a closure per lane was left as a call.
    #[inline(always)]
    pub fn gather_by(index: &[usize; LANES], field: impl Fn(usize) -> Vec3) -> Lanes3 {
        let mut r = Lanes3::default();
        for (l, &i) in index.iter().enumerate() {
            let v = field(i);
            (r.x.0[l], r.y.0[l], r.z.0[l]) = (v.x, v.y, v.z);
        }
        r
    }

    /// The vector of lane `l`.
    #[inline(always)]
    pub fn lane(&self, l: usize) -> Vec3 {
        Vec3::new(self.x.0[l], self.y.0[l], self.z.0[l])
    }

    #[inline(always)]
    pub fn dot(self, rhs: Lanes3) -> Lanes {
        (self.x * rhs.x) + (self.y * rhs.y) + (self.z * rhs.z)
    }

    #[inline(always)]
    pub fn cross(self, rhs: Lanes3) -> Lanes3 {
        Lanes3 {
            x: self.y * rhs.z - rhs.y * self.z,
            y: self.z * rhs.x - rhs.z * self.x,
            z: self.x * rhs.y - rhs.x * self.y,
        }
    }

    /// Each coordinate times the lane's scalar.
    #[inline(always)]
    pub fn scale(self, k: Lanes) -> Lanes3 {
        Lanes3 {
            x: self.x * k,
            y: self.y * k,
            z: self.z * k,
        }
    }
}

impl Add for Lanes3 {
    type Output = Lanes3;
    #[inline(always)]
    fn add(self, rhs: Lanes3) -> Lanes3 {
        Lanes3 {
            x: self.x + rhs.x,
            y: self.y + rhs.y,
            z: self.z + rhs.z,
        }
    }
}

impl Sub for Lanes3 {
    type Output = Lanes3;
    #[inline(always)]
    fn sub(self, rhs: Lanes3) -> Lanes3 {
        Lanes3 {
            x: self.x - rhs.x,
            y: self.y - rhs.y,
            z: self.z - rhs.z,
        }
    }
}

/// The eight-lane kind of the rows' arithmetic (see `super::wide`): each operation is
/// the lane loop above, so lane by lane the `Real` one.
impl Wide for Lanes {
    type Mask = Mask;
    type V3 = Lanes3;

    #[inline(always)]
    fn splat(x: Real) -> Lanes {
        Lanes::splat(x)
    }
    #[inline(always)]
    fn max(self, rhs: Lanes) -> Lanes {
        Lanes::max(self, rhs)
    }
    #[inline(always)]
    fn min(self, rhs: Lanes) -> Lanes {
        Lanes::min(self, rhs)
    }
    #[inline(always)]
    fn clamp(self, lo: Lanes, hi: Lanes) -> Lanes {
        Lanes::clamp(self, lo, hi)
    }
    #[inline(always)]
    fn sqrt(self) -> Lanes {
        Lanes::sqrt(self)
    }
    #[inline(always)]
    fn greater(self, rhs: Lanes) -> Mask {
        self.gt(rhs)
    }
    #[inline(always)]
    fn at_most(self, rhs: Lanes) -> Mask {
        self.le(rhs)
    }
    #[inline(always)]
    fn equals(self, rhs: Lanes) -> Mask {
        Lanes::eq(self, rhs)
    }
}

impl Vector<Lanes> for Lanes3 {
    #[inline(always)]
    fn new(x: Lanes, y: Lanes, z: Lanes) -> Lanes3 {
        Lanes3 { x, y, z }
    }
    #[inline(always)]
    fn dot(self, rhs: Lanes3) -> Lanes {
        Lanes3::dot(self, rhs)
    }
    #[inline(always)]
    fn cross(self, rhs: Lanes3) -> Lanes3 {
        Lanes3::cross(self, rhs)
    }
    #[inline(always)]
    fn scale(self, k: Lanes) -> Lanes3 {
        Lanes3::scale(self, k)
    }
}

/// Lanes evaluate both branches and keep each lane's pick (see `super::wide`).
impl LaneMask for Mask {
    #[inline(always)]
    fn any(self) -> bool {
        Mask::any(self)
    }
    #[inline(always)]
    fn choose<T: Blend<Mask>>(self, yes: impl FnOnce() -> T, no: impl FnOnce() -> T) -> T {
        T::blend(self, yes(), no())
    }
}

impl Blend<Mask> for Lanes {
    #[inline(always)]
    fn blend(mask: Mask, yes: Lanes, no: Lanes) -> Lanes {
        mask.select(yes, no)
    }
}

impl Blend<Mask> for Lanes3 {
    #[inline(always)]
    fn blend(mask: Mask, yes: Lanes3, no: Lanes3) -> Lanes3 {
        mask.select3(yes, no)
    }
}

/// How the contact passes run.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum LaneMode {
    /// In lanes, compiled for AVX-512 (eight f64 or sixteen f32 per instruction: a group's
    /// eight f64 lanes are one register, not two). On this project's 2-core Xeon it made
    /// the pyramid 9 % and the rain's first 300 steps 4 % faster than AVX2, same bits.
    Avx512,
    /// In lanes, compiled for AVX2 (four f64 or eight f32 per instruction).
    Avx2,
    /// In lanes, compiled for the baseline processor: slower than one by one without wide
    /// registers, so only chosen on request, to compare.
    Portable,
    /// One manifold after another, no groups built.
    Scalar,
}

/// The mode of this process: the widest lanes the CPU has (AVX-512, else AVX2), else one
/// by one. `TUMBLE_LANES=avx2`, `=portable` or `=scalar` in the environment (read once)
/// overrides it, to compare; every mode gives the same bits.
pub(crate) fn lane_mode() -> LaneMode {
    #[cfg(test)]
    if let Some(mode) = tests::OVERRIDE.with(|m| m.get()) {
        return checked(mode);
    }
    static MODE: std::sync::OnceLock<LaneMode> = std::sync::OnceLock::new();
    *MODE.get_or_init(|| {
        checked(match std::env::var("TUMBLE_LANES").as_deref() {
            Ok("avx2") => LaneMode::Avx2,
            Ok("portable") => LaneMode::Portable,
            Ok("scalar") => LaneMode::Scalar,
            _ => LaneMode::Avx512,
        })
    })
}

/// `mode`, narrowed to what this CPU runs: the AVX-512 and AVX2 kernels are only ever
/// called after this check, which their safety rests on.
fn checked(mode: LaneMode) -> LaneMode {
    match mode {
        LaneMode::Avx512 if !detected(Isa::Avx512) => checked(LaneMode::Avx2),
        LaneMode::Avx2 if !detected(Isa::Avx2) => LaneMode::Scalar,
        other => other,
    }
}

enum Isa {
    Avx512,
    Avx2,
}

/// Whether this CPU has every feature the kernels of `isa` are compiled for.
fn detected(isa: Isa) -> bool {
    #[cfg(target_arch = "x86_64")]
    return match isa {
        Isa::Avx512 => {
            std::is_x86_feature_detected!("avx2")
                && std::is_x86_feature_detected!("avx512f")
                && std::is_x86_feature_detected!("avx512vl")
                && std::is_x86_feature_detected!("avx512dq")
                && std::is_x86_feature_detected!("avx512bw")
        }
        Isa::Avx2 => std::is_x86_feature_detected!("avx2"),
    };
    #[cfg(not(target_arch = "x86_64"))]
    return {
        let _ = isa;
        false
    };
}

/// Defines `fn $name(args)`, which calls `$body(args)` (an `#[inline(always)]` function
/// with the same arguments) compiled for the lane mode's instruction set: inlined into a
/// function built for AVX-512 or AVX2, or as it is in the portable and scalar modes. A
/// closure handed to one generic dispatcher was not inlined into it (the pyramid ran 25 %
/// slower than with AVX2), so each kernel gets functions of its own.
macro_rules! wide_kernel {
    ($(#[$doc:meta])* $vis:vis fn $name:ident $(<$g:ident: $bound:path>)?
        ($($arg:ident: $ty:ty),* $(,)?) => $body:ident) => {
        $(#[$doc])*
        #[inline(always)]
        $vis fn $name $(<$g: $bound>)? ($($arg: $ty),*) {
            #[cfg(target_arch = "x86_64")]
            {
                #[target_feature(enable = "avx2,avx512f,avx512vl,avx512dq,avx512bw")]
                unsafe fn avx512 $(<$g: $bound>)? ($($arg: $ty),*) {
                    $body($($arg),*)
                }
                #[target_feature(enable = "avx2")]
                unsafe fn avx2 $(<$g: $bound>)? ($($arg: $ty),*) {
                    $body($($arg),*)
                }
                match $crate::dynamics::solver::lanes::lane_mode() {
                    // SAFETY: `lane_mode` is checked: Avx512 only where this CPU has AVX2
                    // and AVX-512 F, VL, DQ and BW, all that `avx512` is compiled for.
                    $crate::dynamics::solver::lanes::LaneMode::Avx512 => {
                        return unsafe { avx512($($arg),*) }
                    }
                    // SAFETY: as above, Avx2 only where this CPU has AVX2, all `avx2` needs.
                    $crate::dynamics::solver::lanes::LaneMode::Avx2 => {
                        return unsafe { avx2($($arg),*) }
                    }
                    _ => {}
                }
            }
            $body($($arg),*)
        }
    };
}
pub(crate) use wide_kernel;

/// Runs `f` with the lane mode of this thread set to `mode` (tests only).
#[cfg(test)]
pub(crate) fn with_lane_mode<R>(mode: LaneMode, f: impl FnOnce() -> R) -> R {
    tests::OVERRIDE.with(|m| m.set(Some(mode)));
    let result = f();
    tests::OVERRIDE.with(|m| m.set(None));
    result
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::hint::black_box;

    thread_local! {
        pub(super) static OVERRIDE: std::cell::Cell<Option<LaneMode>> =
            const { std::cell::Cell::new(None) };
    }

    /// Values where lane operations could differ from scalar ones: signed zeros,
    /// infinities, tiny and huge numbers.
    fn specials() -> Vec<Real> {
        vec![
            0.0,
            -0.0,
            1.0,
            -1.0,
            0.5,
            Real::MIN_POSITIVE,
            -Real::MIN_POSITIVE,
            Real::MAX,
            Real::INFINITY,
            Real::NEG_INFINITY,
            3.0e-3,
            -7.25,
        ]
    }

    fn same(x: Real, y: Real) -> bool {
        x.to_bits() == y.to_bits()
    }

    #[test]
    fn lane_operations_are_the_scalar_ones_bit_for_bit() {
        let v = specials();
        for &x in &v {
            for &y in &v {
                let (a, b) = (black_box(Lanes::splat(x)), black_box(Lanes::splat(y)));
                let (x, y) = (black_box(x), black_box(y));
                let checks = [
                    ((a + b).0[0], x + y),
                    ((a - b).0[0], x - y),
                    ((a * b).0[0], x * y),
                    ((a / b).0[0], x / y),
                    ((-a).0[0], -x),
                    (a.max(b).0[1], x.max(y)),
                    (a.min(b).0[2], x.min(y)),
                    (a.sqrt().0[3], x.sqrt()),
                ];
                for (k, (wide, scalar)) in checks.into_iter().enumerate() {
                    assert!(
                        same(wide, scalar) || (wide.is_nan() && scalar.is_nan()),
                        "op {k} on {x:?}, {y:?}: {wide:?} vs {scalar:?}"
                    );
                }
                assert_eq!(a.lt(b).test(0), x < y);
                assert_eq!(a.le(b).test(1), x <= y);
                assert_eq!(a.gt(b).test(2), x > y);
                assert_eq!(a.eq(b).test(3), x == y);
                if x <= y {
                    for &z in &v {
                        let c = black_box(Lanes::splat(z));
                        assert!(same(c.clamp(a, b).0[0], black_box(z).clamp(x, y)));
                    }
                }
            }
        }
    }

    #[test]
    fn select_keeps_the_bits_of_the_chosen_lane() {
        let mut m = Mask::default();
        m.set(0, true);
        m.set(2, true);
        let mut yes = Lanes::splat(2.0);
        let mut no = Lanes::splat(-0.0);
        (yes.0[0], yes.0[1], yes.0[2]) = (-0.0, 1.0, Real::NAN);
        (no.0[0], no.0[1], no.0[2]) = (0.0, -1.0, 3.0);
        let r = m.select(yes, no);
        assert!(same(r.0[0], -0.0) && same(r.0[1], -1.0));
        assert!(r.0[2].is_nan() && same(r.0[3], -0.0));
        assert!(m.any() && !(m & !m).any() && (m | !m).test(1));
    }
}
