//! The joint's hard rows solved as one block, and a ball joint's point as a 3×3 block.
//!
//! For hard rows J (n ≤ 6 of them, `HardRows`), one pass solves
//!
//! ```text
//! K x = −(J v + bias·C),   K = J M⁻¹ Jᵀ,   Δλ = mass_scale·x − impulse_scale·λ
//! ```
//!
//! with the joint softness's coefficients (`softness.rs`; rigid and unbiased in the relax
//! pass), K factored once per frame as L D Lᵀ (K is symmetric positive semi-definite). A
//! pivot that vanishes is a direction no body can move in (out of a planar body's plane):
//! its unknown stays zero. The impulses of all rows are summed into one before they are
//! applied (one product by each inverse inertia, not one per row).
//! The point alone (a ball joint) is the same solve with J = [1, −[r]×] per body, whose K
//! has a closed form inverted once a substep (see [`point_inverse_mass`]).

use super::rows::point_row;
use super::{Frame, JointPass, Row};
use crate::dynamics::joint::JointImpulses;
use crate::dynamics::solver::body::BodyState;
use crate::math::{Mat3, Real, Vec3};

/// The point constraint's accumulated impulse (on `other`, world frame).
pub(super) fn point_impulse(imp: &JointImpulses) -> Vec3 {
    Vec3::new(imp.hard[0], imp.hard[1], imp.hard[2])
}

/// Applies a linear impulse `p` at the anchors: −p on `body`, +p on `other`.
#[inline(always)]
pub(super) fn apply_point(p: Vec3, fr: &Frame, a: &mut BodyState, b: &mut BodyState) {
    if fr.sa.moves {
        a.v -= fr.sa.mask * p * fr.sa.inv_mass;
        a.w -= fr.sa.inv_inertia * fr.ra.cross(p);
    }
    if fr.sb.moves {
        b.v += fr.sb.mask * p * fr.sb.inv_mass;
        b.w += fr.sb.inv_inertia * fr.rb.cross(p);
    }
}

/// [r]× M [r]×: the turning part of a point's inverse effective mass is minus this.
/// Column i is r × (M (r × eᵢ)), and r × eᵢ has two terms: half the work of two full
/// matrix products.
fn skew_sandwich(r: Vec3, m: Mat3) -> Mat3 {
    let column = |turned: Vec3| r.cross(turned);
    Mat3::from_cols(
        column(m.y_axis * r.z - m.z_axis * r.y),
        column(m.z_axis * r.x - m.x_axis * r.z),
        column(m.x_axis * r.y - m.y_axis * r.x),
    )
}

/// The inverse of the point constraint's 3×3 block,
/// K = (m_a⁻¹ + m_b⁻¹) 1 − [r_a]× I_a⁻¹ [r_a]× − [r_b]× I_b⁻¹ [r_b]×, or `None` where it is
/// singular. Computed once a substep and kept for its relax pass: the inverse inertias are
/// the step's start values anyway, and the velocity error is always measured at the
/// current anchors, so a K from before the drift only changes how fast the passes
/// converge. Measured on the joint grid benchmark: 7 % fewer instructions than a K per
/// pass, and the largest joint gap 6.5 mm instead of 6.8 mm. Once a step (as Box2D and
/// Rapier prepare their effective masses) saved 14 % but let the gap grow to 7.5 mm.
pub(super) fn point_inverse_mass(fr: &Frame) -> Option<Mat3> {
    let k = Mat3::from_diagonal(fr.sa.mask * fr.sa.inv_mass + fr.sb.mask * fr.sb.inv_mass)
        - skew_sandwich(fr.ra, fr.sa.inv_inertia)
        - skew_sandwich(fr.rb, fr.sb.inv_inertia);
    let det = k.determinant();
    let scale = k.x_axis.x.abs().max(k.y_axis.y.abs()).max(k.z_axis.z.abs());
    (det.abs() > 1e-12 * scale.powi(3)).then(|| k.inverse())
}

/// The point constraint as one 3×3 block, with `k_inv` from [`point_inverse_mass`].
pub(super) fn solve_point(
    acc: Vec3,
    k_inv: Option<Mat3>,
    fr: &Frame,
    pass: &JointPass,
    a: &mut BodyState,
    b: &mut BodyState,
) -> Vec3 {
    let cdot = b.v + b.w.cross(fr.rb) - a.v - a.w.cross(fr.ra);
    let bias = if pass.bias {
        fr.d * pass.soft.bias_rate
    } else {
        Vec3::ZERO
    };
    let x = if let Some(k_inv) = k_inv {
        k_inv * -(cdot + bias)
    } else {
        // A direction no body can move in (a planar body out of its plane): the general
        // elimination leaves it alone.
        let hard = HardRows {
            rows: [
                Vec3::X,
                Vec3::Y,
                Vec3::Z,
                Vec3::ZERO,
                Vec3::ZERO,
                Vec3::ZERO,
            ]
            .map(|e| point_row(e, fr)),
            error: [fr.d.x, fr.d.y, fr.d.z, 0.0, 0.0, 0.0],
            count: 3,
        };
        let acc6 = [acc.x, acc.y, acc.z, 0.0, 0.0, 0.0];
        let mut block = Block {
            hard,
            ..Block::default()
        };
        block.eliminate(fr);
        let total = solve_hard(&block, acc6, fr, pass, a, b);
        return Vec3::new(total[0], total[1], total[2]);
    };
    let impulse = x * pass.soft.mass_scale - acc * pass.soft.impulse_scale;
    apply_point(impulse, fr, a, b);
    acc + impulse
}

/// The hard rows of a joint: Jacobians and position errors, `count` of them in use.
#[derive(Clone)]
pub(super) struct HardRows {
    pub rows: [Row; 6],
    pub error: [Real; 6],
    pub count: usize,
}

impl Default for HardRows {
    fn default() -> Self {
        HardRows {
            rows: [Row::angular(Vec3::ZERO); 6],
            error: [0.0; 6],
            count: 0,
        }
    }
}

impl HardRows {
    pub fn push(&mut self, row: Row, error: Real) {
        self.rows[self.count] = row;
        self.error[self.count] = error;
        self.count += 1;
    }
}

/// The numbers the eliminations work in: `Real` for a joint's block ([`Block`]), f64 for a
/// chain's ([`Eliminated`]), whose light bodies make K too ill-conditioned for f32 (see
/// `joint_chain.rs`).
pub(super) trait Element:
    Copy
    + PartialOrd
    + std::ops::Sub<Output = Self>
    + std::ops::Mul<Output = Self>
    + std::ops::Div<Output = Self>
    + std::ops::SubAssign
    + std::iter::Sum
{
    const ZERO: Self;
    /// A pivot at most this share of K's largest diagonal entry counts as zero.
    const TINY: Self;
    fn abs(self) -> Self;
    fn max(self, other: Self) -> Self;
    fn total_cmp(&self, other: &Self) -> std::cmp::Ordering;
}

macro_rules! element {
    ($t:ty) => {
        impl Element for $t {
            const ZERO: $t = 0.0;
            const TINY: $t = 1e-12;
            fn abs(self) -> $t {
                <$t>::abs(self)
            }
            fn max(self, other: $t) -> $t {
                <$t>::max(self, other)
            }
            fn total_cmp(&self, other: &$t) -> std::cmp::Ordering {
                <$t>::total_cmp(self, other)
            }
        }
    };
}
element!(f32);
element!(f64);

/// A chain's K (see `joint_chain.rs`), eliminated once per frame: Gaussian elimination
/// with partial pivoting, its multipliers and row swaps recorded, so that each pass only
/// replays them on its own right-hand side. The pivots depend on K alone, so the replay
/// does bit for bit the arithmetic of eliminating K and the right-hand side together. A
/// vanishing pivot (a direction no body can move in, such as out of a planar body's
/// plane) leaves that unknown zero.
#[derive(Clone)]
pub(super) struct Eliminated<const N: usize = 6, T: Element = Real> {
    /// The upper triangle left by the elimination.
    k: [[T; N]; N],
    /// Per column, the row swapped into the pivot's place, and the multipliers of the
    /// rows below it.
    pivot: [usize; N],
    factor: [[T; N]; N],
    skip: [bool; N],
    n: usize,
}

impl<const N: usize, T: Element> Eliminated<N, T> {
    /// Eliminates the n×n matrix `k` (n ≤ N).
    pub(super) fn new(k: [[T; N]; N], n: usize) -> Eliminated<N, T> {
        let mut e = Eliminated {
            k,
            pivot: [0; N],
            factor: [[T::ZERO; N]; N],
            skip: [false; N],
            n,
        };
        e.eliminate();
        e
    }

    /// Eliminates `self.k` in place.
    fn eliminate(&mut self) {
        let n = self.n;
        let k = &mut self.k;
        let scale = (0..n).map(|i| k[i][i].abs()).fold(T::ZERO, T::max);
        let tiny = T::TINY * scale;
        for col in 0..n {
            let mut pivot = col;
            for i in col + 1..n {
                if k[i][col].abs().total_cmp(&k[pivot][col].abs()).is_ge() {
                    pivot = i;
                }
            }
            k.swap(col, pivot);
            self.pivot[col] = pivot;
            self.skip[col] = k[col][col].abs() <= tiny;
            if self.skip[col] {
                continue;
            }
            let pivot_row = k[col];
            let below = k[col + 1..n]
                .iter_mut()
                .zip(&mut self.factor[col][col + 1..n]);
            for (row, factor) in below {
                let f = row[col] / pivot_row[col];
                for (kij, pj) in row[col..n].iter_mut().zip(&pivot_row[col..n]) {
                    *kij -= f * *pj;
                }
                *factor = f;
            }
        }
    }

    /// x with K x = `rhs`.
    pub(super) fn solve(&self, mut rhs: [T; N]) -> [T; N] {
        let (k, n) = (&self.k, self.n);
        for col in 0..n {
            rhs.swap(col, self.pivot[col]);
            if self.skip[col] {
                continue;
            }
            for i in col + 1..n {
                rhs[i] -= self.factor[col][i] * rhs[col];
            }
        }
        let mut x = [T::ZERO; N];
        for i in (0..n).rev() {
            if self.skip[i] {
                continue;
            }
            let sum: T = (i + 1..n).map(|j| k[i][j] * x[j]).sum();
            x[i] = (rhs[i] - sum) / k[i][i];
        }
        x
    }
}

/// K = L D Lᵀ of a joint's symmetric block (n ≤ 6), factored where it lies in the
/// solver's list. K = J M⁻¹ Jᵀ is positive semi-definite, so the factorisation needs no
/// pivoting (it is Cholesky's without the square roots); a pivot at most `TINY` of the
/// largest diagonal entry is a direction no body can move in (out of a planar body's
/// plane), and its unknown stays zero, as [`Eliminated`] leaves it. Gaussian elimination
/// with partial pivoting took some 1,100 instructions on a cart-pole's 5×5 block, made
/// once a frame per joint; with the symmetric build and the copies gone, a block costs
/// 1,350 instructions where it cost 2,500 and a kilobyte copied (callgrind, cart-pole).
#[derive(Clone, Default)]
struct Factored {
    /// Below the diagonal: L (unit diagonal, not stored); on it: D⁻¹ (0 where skipped).
    l: [[Real; 6]; 6],
    n: usize,
}

impl Factored {
    /// Factors the symmetric K whose lower triangle is in `self.l` (overwritten). Each
    /// size has its own copy, its loops unrolled (a loop bound known only at run time
    /// cost twice the arithmetic in loop control on a 5×5 block).
    fn factor(&mut self) {
        match self.n {
            1 => factor::<1>(&mut self.l),
            2 => factor::<2>(&mut self.l),
            3 => factor::<3>(&mut self.l),
            4 => factor::<4>(&mut self.l),
            5 => factor::<5>(&mut self.l),
            _ => factor::<6>(&mut self.l),
        }
    }

    /// x with K x = `rhs`.
    fn solve(&self, rhs: [Real; 6]) -> [Real; 6] {
        match self.n {
            1 => solve::<1>(&self.l, rhs),
            2 => solve::<2>(&self.l, rhs),
            3 => solve::<3>(&self.l, rhs),
            4 => solve::<4>(&self.l, rhs),
            5 => solve::<5>(&self.l, rhs),
            _ => solve::<6>(&self.l, rhs),
        }
    }
}

/// [`Factored::factor`] for an n×n K.
#[inline(always)]
fn factor<const N: usize>(l: &mut [[Real; 6]; 6]) {
    let scale = (0..N).map(|i| l[i][i].abs()).fold(0.0, Real::max);
    let tiny = <Real as Element>::TINY * scale;
    // Column j: d_j = K_jj − Σ_k L_jk² d_k, then L_ij = (K_ij − Σ_k L_ik L_jk d_k) / d_j.
    let mut d = [0.0; N];
    for j in 0..N {
        let mut scaled = [0.0; N];
        let mut dj = l[j][j];
        for k in 0..j {
            scaled[k] = l[j][k] * d[k];
            dj -= l[j][k] * scaled[k];
        }
        if dj <= tiny {
            l[j][j] = 0.0;
            for row in l[j + 1..N].iter_mut() {
                row[j] = 0.0;
            }
            continue;
        }
        d[j] = dj;
        let inv = 1.0 / dj;
        l[j][j] = inv;
        for row in l[j + 1..N].iter_mut() {
            let mut kij = row[j];
            for k in 0..j {
                kij -= row[k] * scaled[k];
            }
            row[j] = kij * inv;
        }
    }
}

/// [`Factored::solve`] for an n×n K: forward through L, D⁻¹, back through Lᵀ.
#[inline(always)]
fn solve<const N: usize>(l: &[[Real; 6]; 6], mut x: [Real; 6]) -> [Real; 6] {
    for i in 0..N {
        for k in 0..i {
            x[i] -= l[i][k] * x[k];
        }
    }
    for i in 0..N {
        x[i] *= l[i][i];
    }
    for i in (0..N).rev() {
        for k in i + 1..N {
            x[i] -= l[k][i] * x[k];
        }
    }
    x
}

/// A joint's hard rows at one frame with their K eliminated: made once per frame (the
/// rows were built again by the warm start, each pass and the totals), in place in the
/// solver's list (`ready` says whether it is at the current frame).
#[derive(Clone, Default)]
pub(crate) struct Block {
    pub(super) hard: HardRows,
    k: Factored,
    /// The masses K was made with beside `hard`'s rows: m_a⁻¹ mask_a + m_b⁻¹ mask_b, then
    /// each inverse inertia's columns (see `refresh`).
    masses: [Real; 21],
    /// Whether `hard` and `k` are at the current frame: cleared after each drift.
    pub(crate) ready: bool,
    /// Set at a step's start, cleared after each drift: the block was last made at the
    /// previous step's final frame, which is this step's first when nothing moved the
    /// bodies in between (see `refresh`).
    pub(crate) carried: bool,
}

/// `fr`'s masses as K reads them (see [`Block::masses`]).
fn masses_of(fr: &Frame) -> [Real; 21] {
    let (sa, sb) = (&fr.sa, &fr.sb);
    let mut m = [0.0; 21];
    m[..3].copy_from_slice(&(sa.mask * sa.inv_mass + sb.mask * sb.inv_mass).to_array());
    m[3..12].copy_from_slice(&sa.inv_inertia.to_cols_array());
    m[12..].copy_from_slice(&sb.inv_inertia.to_cols_array());
    m
}

/// Whether two lists of numbers are the same bit for bit (`==` would take 0 for −0).
fn same_bits<'a>(
    a: impl IntoIterator<Item = &'a Real>,
    b: impl IntoIterator<Item = &'a Real>,
) -> bool {
    a.into_iter()
        .zip(b)
        .all(|(x, y)| x.to_bits() == y.to_bits())
}

impl Row {
    fn numbers(&self) -> [Real; 9] {
        let [a, b, c] = [self.lin, self.ang_a, self.ang_b].map(|v| v.to_array());
        [a[0], a[1], a[2], b[0], b[1], b[2], c[0], c[1], c[2]]
    }
}

impl Block {
    /// Makes the block at frame `fr`: its rows by `rows` (`None`: the joint has none),
    /// and K's factors from them unless the block is `carried` and its rows and masses
    /// are those K was made from, bit for bit; the factors are then the same numbers
    /// (K depends on nothing else), so making them again is skipped. That is the case
    /// at every step's start in a world left alone between steps: the first frame is
    /// the last one's, which the relax pass used. A cart-pole at one substep made its
    /// two blocks twice a step, 12 % of its time; the check costs a tenth of a making.
    pub(super) fn refresh(
        &mut self,
        fr: &Frame,
        rows: impl FnOnce(&mut HardRows) -> Option<()>,
    ) -> Option<()> {
        if !self.carried {
            rows(&mut self.hard)?;
            self.masses = masses_of(fr);
            self.eliminate(fr);
            return Some(());
        }
        let (old, n) = (self.hard.rows, self.hard.count);
        rows(&mut self.hard)?;
        let masses = masses_of(fr);
        let same_rows = n == self.hard.count
            && old[..n]
                .iter()
                .zip(&self.hard.rows[..n])
                .all(|(a, b)| same_bits(&a.numbers(), &b.numbers()));
        if same_rows && same_bits(&masses, &self.masses) {
            self.ready = true;
        } else {
            self.masses = masses;
            self.eliminate(fr);
        }
        Some(())
    }

    /// K = J M⁻¹ Jᵀ of `self.hard` at frame `fr`, factored. K is symmetric (the inverse
    /// inertias are), so each row's M⁻¹ Jᵢᵀ is made once and only the lower triangle
    /// dotted.
    pub(super) fn eliminate(&mut self, fr: &Frame) {
        let (hard, n) = (&self.hard, self.hard.count);
        let (sa, sb) = (&fr.sa, &fr.sb);
        let linear = sa.mask * sa.inv_mass + sb.mask * sb.inv_mass;
        let k = &mut self.k.l;
        for (i, ri) in hard.rows[..n].iter().enumerate() {
            let v = linear * ri.lin;
            let (wa, wb) = (sa.inv_inertia * ri.ang_a, sb.inv_inertia * ri.ang_b);
            for (j, rj) in hard.rows[i..n].iter().enumerate() {
                k[i + j][i] = rj.lin.dot(v) + rj.ang_a.dot(wa) + rj.ang_b.dot(wb);
            }
        }
        self.k.n = n;
        self.k.factor();
        self.ready = true;
    }
}

/// One pass over the hard rows as a block; returns the new accumulated impulses.
pub(super) fn solve_hard(
    block: &Block,
    acc: [Real; 6],
    fr: &Frame,
    pass: &JointPass,
    a: &mut BodyState,
    b: &mut BodyState,
) -> [Real; 6] {
    let hard = &block.hard;
    let n = hard.count;
    let mut rhs = [0.0; 6];
    for ((r, row), error) in rhs.iter_mut().zip(&hard.rows[..n]).zip(hard.error) {
        let bias = if pass.bias {
            pass.soft.bias_rate * error
        } else {
            0.0
        };
        *r = -(row.velocity(a, b) + bias);
    }
    let x = block.k.solve(rhs);
    let mut total = acc;
    let mut sum = Row::ZERO;
    for i in 0..n {
        let delta = pass.soft.mass_scale * x[i] - pass.soft.impulse_scale * acc[i];
        sum.add_scaled(&hard.rows[i], delta);
        total[i] = acc[i] + delta;
    }
    sum.apply(1.0, &fr.sa, &fr.sb, a, b);
    total
}
