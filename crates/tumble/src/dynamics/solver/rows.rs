//! The contact rows, written once over [`Wide`]: the scalar solver runs them on `Real`,
//! one manifold at a time (`super::contact`), the wide passes on `Lanes`, eight manifolds
//! at a time (`super::contact_wide`).
//!
//! Rows, for a contact point with anchors r_a, r_b (from each centre of mass) and normal n:
//!
//! ```text
//! C   = separation = n · (p_b − p_a) + s₀
//! Ċ   = n · (v_b − v_a) + (r_b × n)·ω_b − (r_a × n)·ω_a
//! K   = n·M_a⁻¹n + n·M_b⁻¹n + (r_a × n)·I_a⁻¹(r_a × n) + (r_b × n)·I_b⁻¹(r_b × n)
//! ```
//!
//! and the same with the two tangents t₁, t₂ for friction. Everything that does not change
//! within a step (the images under I⁻¹ of r × d, the effective masses) is computed once
//! in `ContactConstraint::prepare`; a pass then costs a few dot products per row.
//!
//! Bit identity of the two paths rests on three things: each lane operation is the `Real`
//! one (`super::lanes`); the passes below are one expression tree, so each lane meets the
//! operations in the scalar order; and a condition picks whole values, never mixing
//! branches ([`LaneMask::choose`]). What a lane must not do, it is masked out of:
//! [`Masks::active`] says which lanes hold a point (a manifold with fewer points than its
//! group's largest has none in the later slots), `apply` whose bodies move. A masked lane
//! keeps its old values (chosen, never added a zero to). On one lane `active` is `true`.

use std::borrow::BorrowMut;

use super::body::BodyState;
use super::contact::{BiasRule, ANCHOR_STIFFNESS};
use super::wide::{LaneMask, Vector, Wide};
use crate::math::{Real, Vec3};

/// One Jacobian row at one point: the images under I⁻¹ of its angular parts, and its
/// effective mass. The angular parts r × d themselves are recomputed where needed: two
/// cross products cost less than streaming 48 more bytes per row through every pass.
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct Row<W: Wide = Real> {
    /// I_a⁻¹ (r_a × d) and I_b⁻¹ (r_b × d): the change of ω per unit impulse.
    pub turn_a: W::V3,
    pub turn_b: W::V3,
    pub mass: W,
}

/// What the solver passes read and write at a contact point (or a slot of lanes); the
/// rest lives in `PointCold`. Kept apart and packed in one list for all manifolds, so that
/// a pass streams only the bytes it uses: a pile's points overflow the L2 cache otherwise.
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct Point<W: Wide = Real> {
    /// Anchors from each centre of mass, world frame, at the start of the step.
    pub ra: W::V3,
    pub rb: W::V3,
    /// Separation at the start of the step.
    pub separation: W,
    /// n · (r_b − r_a): with the bodies' motion since the step began it gives the current
    /// separation without rotating the anchors (see [`Moved`]).
    pub lever: W,
    pub normal: Row<W>,
    pub tangent: [Row<W>; 2],
    pub normal_impulse: W,
    pub tangent_impulse: [W; 2],
    /// Largest normal impulse of the step: restitution only acts where contact pushed.
    pub max_normal_impulse: W,
    /// Friction anchors: how far apart, along each tangent, the two material points that
    /// touched when the contact began were at the step's start (zero for a new point).
    pub anchor_gap: [W; 2],
    /// t · (r_b − r_a) per tangent, for the anchors' current gap (as `lever` for the normal).
    pub tangent_lever: [W; 2],
}

/// What the solve passes write of a point's cold data: the approach velocity met at
/// impact and the step's summed impulses (for reports).
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct Sums<W: Wide = Real> {
    /// Normal velocity before the step, lowered to the velocity at the moment of impact
    /// if the step's gravity sped the approach up: the speed restitution reflects.
    pub approach_velocity: W,
    pub total_normal: W,
    pub total_tangent: [W; 2],
}

/// A manifold's directions and what they do to its bodies, shared by its points.
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct Frame<W: Wide = Real> {
    pub normal: W::V3,
    pub tangents: [W::V3; 2],
    /// M⁻¹ d of each body for d = n, t₁, t₂.
    pub push_a: [W::V3; 3],
    pub push_b: [W::V3; 3],
    pub friction: W,
    /// How far each side's anchors lie from its round core along the normal: a sphere's or
    /// capsule's radius (`contact::round_arms`), 0 for a side that is not round; for the
    /// gaps' round parts ([`Moved::normal`], [`Moved::tangent`]).
    pub round: [W; 2],
    /// The biased pass's impulse scale of the manifold's normal rows, its mass scale 1
    /// minus this: the contacts' spring, stiffened for a heavy load (see
    /// `softness::LoadSpring`).
    pub impulse_scale: W,
    /// The relative tangential velocity friction drives toward, along each tangent (m/s):
    /// the contact modifier's surface velocity (a conveyor belt); zero otherwise, and
    /// subtracting a zero changes no bit.
    pub surface: [W; 2],
    /// 1 where the friction anchors pull, 0 for a manifold with a surface velocity, whose
    /// anchors would pull it back against the belt (times 1 changes no bit).
    pub anchor: W,
}

/// Which lanes a point's updates reach (see the module docs).
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct Masks<M> {
    pub active: M,
    /// Body a moves, body b moves.
    pub apply: (M, M),
}

/// The velocities of the two bodies, worked on in registers and written back once.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Pair<W: Wide = Real> {
    pub va: W::V3,
    pub wa: W::V3,
    pub vb: W::V3,
    pub wb: W::V3,
}

/// Each body's motion since the step began: Δp, the columns of ΔR, and ∫ω dt.
pub(crate) struct Motion<W: Wide = Real> {
    pub dp: [W::V3; 2],
    pub dr: [[W::V3; 3]; 2],
    pub turned: [W::V3; 2],
}

/// The shared factors of a direction's current separation (see [`Moved::along`]).
#[derive(Clone, Copy)]
pub(crate) struct Moved<W: Wide = Real> {
    offset: W,
    turn_a: W::V3,
    turn_b: W::V3,
}

impl Pair {
    /// The velocities of states `a`, `b`.
    #[inline(always)]
    pub fn load(a: &BodyState, b: &BodyState) -> Pair {
        Pair {
            va: a.v,
            wa: a.w,
            vb: b.v,
            wb: b.w,
        }
    }

    /// Writes the velocities of the moving bodies back. Static and kinematic states are
    /// never written: a store every contact with the ground makes would chain all those
    /// contacts through one memory location and serialise them.
    #[inline(always)]
    pub fn store(&self, moves: (bool, bool), a: &mut BodyState, b: &mut BodyState) {
        if moves.0 {
            (a.v, a.w) = (self.va, self.wa);
        }
        if moves.1 {
            (b.v, b.w) = (self.vb, self.wb);
        }
    }
}

impl Motion {
    #[inline(always)]
    pub fn of(a: &BodyState, b: &BodyState) -> Motion {
        let columns = |s: &BodyState| [s.dr.x_axis, s.dr.y_axis, s.dr.z_axis];
        Motion {
            dp: [a.dp, b.dp],
            dr: [columns(a), columns(b)],
            turned: [a.turned, b.turned],
        }
    }
}

impl<W: Wide> Frame<W> {
    /// Which lanes' manifolds have a round side (both radii are ≥ 0).
    #[inline(always)]
    fn rounded(&self) -> W::Mask {
        (self.round[0] + self.round[1]).greater(W::splat(0.0))
    }
}

impl<W: Wide> Moved<W> {
    /// Current separation along `d` of a point: s₀ + d·(Δp_b + ΔR_b r_b − r_b − Δp_a −
    /// ΔR_a r_a + r_a) = s₀ + d·(Δp_b − Δp_a) + (ΔR_bᵀd)·r_b − (ΔR_aᵀd)·r_a − d·(r_b − r_a);
    /// the first three factors are shared by the manifold's points. ΔRᵀd is taken as the
    /// columns' dot products, glam's `transpose() * d` operation for operation.
    #[inline(always)]
    pub fn along(d: W::V3, m: &Motion<W>) -> Moved<W> {
        Moved {
            offset: d.dot(m.dp[1] - m.dp[0]),
            turn_a: turn_back::<W>(&m.dr[0], d),
            turn_b: turn_back::<W>(&m.dr[1], d),
        }
    }

    /// [`Moved::along`] the normal, with the turn of each side's round part taken out. A
    /// point on a round surface is its core's point c (fixed in the body) less ρ n, ρ the
    /// radius: as the body turns, c turns with it but the surface point stays under the
    /// normal (a rolling ball touches at its bottom, not at the material point that
    /// touched). The anchor r = c ∓ ρ n turned by ΔR would lift by ρ (1 − n·ΔR n), so the
    /// gap gains ρ_a (n·ΔR_a n − 1) + ρ_b (n·ΔR_b n − 1), shared by the manifold's points.
    /// Taken with the body's turn, a rolling ball's gap looked open by up to ρ (1 − cos θ),
    /// θ the angle turned since the step began, and the solver let it sink into the floor
    /// (a 0.3 m ball at 8 m/s: 7 mm, and 0.2 m/s downwards, at dt 1/60 s).
    /// Manifolds with no round side keep the plain gap, bit for bit (picked, not added a
    /// zero to), and a group of them skips the work.
    #[inline(always)]
    pub fn normal(f: &Frame<W>, m: &Motion<W>) -> Moved<W> {
        let moved = Moved::along(f.normal, m);
        let round = f.rounded();
        if !round.any() {
            return moved;
        }
        let one = W::splat(1.0);
        let lift_a = f.round[0] * (moved.turn_a.dot(f.normal) - one);
        let lift_b = f.round[1] * (moved.turn_b.dot(f.normal) - one);
        Moved {
            offset: round.pick(moved.offset + lift_a + lift_b, moved.offset),
            ..moved
        }
    }

    /// [`Moved::along`] tangent `k`, with each side's round part rolling rather than
    /// turning. The material point in touch on a round surface is c ∓ ρ n (see
    /// [`Moved::normal`]), and its slip integrates ω × (c ∓ ρ n): the core's part is
    /// ΔR c − c, the radius's is ∓ρ (∫ω dt) × n, whose component along t is
    /// ∓ρ (∫ω dt)·(n × t), with n × t₁ = t₂ and n × t₂ = −t₁ (the basis is right-handed).
    /// The body-fixed anchor instead moves by ∓ρ t·(ΔR n − n): ρ sin θ where the body
    /// rolled ρ θ, and the friction anchors' spring pulled a rolling body back by
    /// ρ (θ − sin θ) (a 5 cm ball at 8 m/s turns 2.7 rad in a step of 1/60 s: 11 cm).
    #[inline(always)]
    pub fn tangent(f: &Frame<W>, k: usize, m: &Motion<W>) -> Moved<W> {
        let moved = Moved::along(f.tangents[k], m);
        let round = f.rounded();
        if !round.any() {
            return moved;
        }
        let slip_a = round_slip(f, k, f.round[0], moved.turn_a, m.turned[0]);
        let slip_b = round_slip(f, k, f.round[1], moved.turn_b, m.turned[1]);
        Moved {
            offset: round.pick(moved.offset + slip_a + slip_b, moved.offset),
            ..moved
        }
    }

    /// `start` (s₀ or an anchor gap) moved by the bodies' motion, less the lever.
    #[inline(always)]
    pub(super) fn gap(&self, start: W, ra: W::V3, rb: W::V3, lever: W) -> W {
        start + self.offset + self.turn_b.dot(rb) - self.turn_a.dot(ra) - lever
    }
}

impl Point {
    /// The point's separation now, from the motion of states `a`, `b` since the step
    /// began (their `dp`, `dr`).
    pub fn separation_now(&self, n: Vec3, a: &BodyState, b: &BodyState) -> Real {
        self.separation_from(self.separation, n, a, b)
    }

    /// [`Point::separation_now`] of a point that started the step `start` apart.
    pub fn separation_from(&self, start: Real, n: Vec3, a: &BodyState, b: &BodyState) -> Real {
        Moved::along(n, &Motion::of(a, b)).gap(start, self.ra, self.rb, self.lever)
    }
}

/// One side's share of [`Moved::tangent`] along tangent `k`: ρ (t·ΔR n − (∫ω dt)·(n × t)),
/// from `turn` = ΔRᵀt and `turned` = ∫ω dt.
#[inline(always)]
fn round_slip<W: Wide>(f: &Frame<W>, k: usize, rho: W, turn: W::V3, turned: W::V3) -> W {
    let rolled = if k == 0 {
        turned.dot(f.tangents[1])
    } else {
        -turned.dot(f.tangents[0])
    };
    rho * (turn.dot(f.normal) - rolled)
}

/// ΔRᵀd from the columns of ΔR.
#[inline(always)]
fn turn_back<W: Wide>(dr: &[W::V3; 3], d: W::V3) -> W::V3 {
    W::V3::new(dr[0].dot(d), dr[1].dot(d), dr[2].dot(d))
}

impl<W: Wide> Row<W> {
    /// Relative velocity along the row's direction `d`, at anchors `ra`, `rb`.
    #[inline(always)]
    pub fn velocity(&self, d: W::V3, ra: W::V3, rb: W::V3, s: &Pair<W>) -> W {
        d.dot(s.vb - s.va) + rb.cross(d).dot(s.wb) - ra.cross(d).dot(s.wa)
    }

    /// Applies impulse `lambda` along the row; `push` is M⁻¹d of each body, `apply` says
    /// whose velocities change.
    #[inline(always)]
    pub fn apply(
        &self,
        lambda: W,
        push: (W::V3, W::V3),
        apply: (W::Mask, W::Mask),
        s: &mut Pair<W>,
    ) {
        let (va, wa, vb, wb) = (s.va, s.wa, s.vb, s.wb);
        (s.va, s.wa) = apply.0.choose(
            #[inline(always)]
            || (va - push.0.scale(lambda), wa - self.turn_a.scale(lambda)),
            #[inline(always)]
            || (va, wa),
        );
        (s.vb, s.wb) = apply.1.choose(
            #[inline(always)]
            || (vb + push.1.scale(lambda), wb + self.turn_b.scale(lambda)),
            #[inline(always)]
            || (vb, wb),
        );
    }
}

/// Applies a manifold's accumulated impulses again (each substep, as Box2D v3 does).
#[inline(always)]
pub(crate) fn warm_start<W: Wide>(
    f: &Frame<W>,
    points: &[Point<W>],
    masks: impl Fn(usize) -> Masks<W::Mask>,
    s: &mut Pair<W>,
) {
    let (pa, pb) = (&f.push_a, &f.push_b);
    for (j, p) in points.iter().enumerate() {
        let apply = masks(j).apply;
        p.normal.apply(p.normal_impulse, (pa[0], pb[0]), apply, s);
        p.tangent[0].apply(p.tangent_impulse[0], (pa[1], pb[1]), apply, s);
        p.tangent[1].apply(p.tangent_impulse[1], (pa[2], pb[2]), apply, s);
    }
}

/// Which pass: its bias rule, whether it corrects position, whether it adds the totals.
#[derive(Clone, Copy)]
pub(crate) struct Pass<'r> {
    pub rule: &'r BiasRule,
    pub bias: bool,
    pub totals: bool,
}

/// One pass over a manifold's points. With `BIAS`, penetration is pushed out by the soft
/// spring (or, for PGS, by Baumgarte); without, only velocities are made consistent
/// (relax). Positive separations are speculative: the bodies may close the gap this
/// substep, not more.
#[inline(always)]
pub(crate) fn solve<W: Wide, C: BorrowMut<Sums<W>>, const BIAS: bool>(
    f: &Frame<W>,
    (points, cold): (&mut [Point<W>], &mut [C]),
    masks: impl Fn(usize) -> Masks<W::Mask>,
    (s, motion): (&mut Pair<W>, &Motion<W>),
    pass: Pass<'_>,
) {
    // Gauss–Seidel favours the point solved first; a symmetric stack would lean the
    // same way every pass and sway. The relax pass therefore walks the points in the
    // opposite order, so the bias of one pass cancels that of the other.
    let n = points.len();
    let moved = Moved::normal(f, motion);
    for k in 0..n {
        let j = if BIAS { k } else { n - 1 - k };
        let approach = &mut cold[j].borrow_mut().approach_velocity;
        solve_normal::<W, BIAS>(f, &mut points[j], masks(j), s, pass.rule, moved, approach);
    }
    let slip = BIAS.then(
        #[inline(always)]
        || [Moved::tangent(f, 0, motion), Moved::tangent(f, 1, motion)],
    );
    for k in 0..n {
        let j = if BIAS { k } else { n - 1 - k };
        solve_friction::<W, BIAS>(f, &mut points[j], masks(j), s, pass.rule, slip);
    }
    if pass.totals {
        add_totals(points, cold);
    }
}

/// Adds the substep's impulses to the step's totals (each substep applies the
/// accumulated impulse in full: warm start plus corrections).
#[inline(always)]
pub(crate) fn add_totals<W: Wide, C: BorrowMut<Sums<W>>>(points: &[Point<W>], cold: &mut [C]) {
    for (p, c) in points.iter().zip(cold) {
        let c = c.borrow_mut();
        c.total_normal = c.total_normal + p.normal_impulse;
        c.total_tangent[0] = c.total_tangent[0] + p.tangent_impulse[0];
        c.total_tangent[1] = c.total_tangent[1] + p.tangent_impulse[1];
    }
}

/// The normal row at one point. At the moment of impact (the first push of the step) the
/// normal velocity met lowers `approach`: the velocity to reflect is this one, gravity of
/// the substeps so far included, not the one at the start of the step.
#[inline(always)]
fn solve_normal<W: Wide, const BIAS: bool>(
    f: &Frame<W>,
    p: &mut Point<W>,
    m: Masks<W::Mask>,
    s: &mut Pair<W>,
    rule: &BiasRule,
    moved: Moved<W>,
    approach: &mut W,
) {
    let (zero, one) = (W::splat(0.0), W::splat(1.0));
    let sep = moved.gap(p.separation, p.ra, p.rb, p.lever);
    let speculative = sep.greater(zero);
    let closing = sep * W::splat(rule.inv_h);
    // Without bias the scales stay constants (not blends of equal values), so that the
    // relax pass's lanes multiply by 1 no more than the scalar code does.
    let (velocity_bias, mass_scale, impulse_scale) = if BIAS {
        let soft = &rule.softness;
        speculative.choose(
            #[inline(always)]
            || (closing, one, zero),
            #[inline(always)]
            || {
                let error = (sep + W::splat(rule.slop)).min(zero);
                (
                    (W::splat(soft.bias_rate) * error).max(W::splat(-rule.max_push)),
                    if rule.stiffened {
                        one - f.impulse_scale
                    } else {
                        W::splat(soft.mass_scale)
                    },
                    if rule.stiffened {
                        f.impulse_scale
                    } else {
                        W::splat(soft.impulse_scale)
                    },
                )
            },
        )
    } else {
        (speculative.pick(closing, zero), one, zero)
    };
    let vn = p.normal.velocity(f.normal, p.ra, p.rb, s);
    let delta =
        -p.normal.mass * mass_scale * (vn + velocity_bias) - impulse_scale * p.normal_impulse;
    let total = (p.normal_impulse + delta).max(zero);
    let applied = total - p.normal_impulse;
    let impact = m.active & p.max_normal_impulse.equals(zero) & applied.greater(zero);
    let (old, max) = (p.normal_impulse, p.max_normal_impulse);
    p.normal_impulse = m.active.pick(total, old);
    p.max_normal_impulse = m.active.pick(max.max(applied), max);
    p.normal
        .apply(applied, (f.push_a[0], f.push_b[0]), m.apply, s);
    if impact.any() {
        let was = *approach;
        *approach = impact.pick(was.min(vn), was);
    }
}

/// Coulomb friction at one point. In the biased pass a sticking point is also pulled
/// back towards its anchors by the contact's soft spring, so that the slow creep a
/// velocity-only friction leaves (a pile spreading by millimetres) is undone; the
/// spring cannot exceed the cone, so it never holds a body that should slide.
#[inline(always)]
fn solve_friction<W: Wide, const BIAS: bool>(
    f: &Frame<W>,
    p: &mut Point<W>,
    m: Masks<W::Mask>,
    s: &mut Pair<W>,
    rule: &BiasRule,
    slip: Option<[Moved<W>; 2]>,
) {
    let zero = W::splat(0.0);
    let ti = p.tangent_impulse;
    // A point that pushes nothing has a zero friction cone: nothing to do. Most
    // speculative points (neighbours side by side in a pile) are such.
    let idle = p.normal_impulse.equals(zero) & ti[0].equals(zero) & ti[1].equals(zero);
    let live = m.active & !idle;
    if !live.any() {
        return;
    }
    let vt = [
        p.tangent[0].velocity(f.tangents[0], p.ra, p.rb, s) - f.surface[0],
        p.tangent[1].velocity(f.tangents[1], p.ra, p.rb, s) - f.surface[1],
    ];
    let want = match slip {
        // Written out rather than `[0, 1].map`, which the compiler left as a call.
        Some(slip) if BIAS => [
            anchored_want(p, 0, vt[0], (slip[0], f.anchor), rule),
            anchored_want(p, 1, vt[1], (slip[1], f.anchor), rule),
        ],
        _ => [
            ti[0] - p.tangent[0].mass * vt[0],
            ti[1] - p.tangent[1].mass * vt[1],
        ],
    };
    let limit = f.friction * p.normal_impulse;
    let total = friction_impulse(want, vt, limit, W::splat(rule.slip_speed), live);
    let apply = (m.apply.0 & live, m.apply.1 & live);
    for (k, total) in total.into_iter().enumerate() {
        let push = (f.push_a[k + 1], f.push_b[k + 1]);
        let old = p.tangent_impulse[k];
        p.tangent[k].apply(total - old, push, apply, s);
        p.tangent_impulse[k] = live.pick(total, old);
    }
}

/// The biased pass's friction impulse along tangent `k` before the cone: the anchors'
/// spring (`anchor`: 1 where it pulls, 0 where not) plus stopping the slip.
#[inline(always)]
fn anchored_want<W: Wide>(
    p: &Point<W>,
    k: usize,
    vt: W,
    (slip, anchor): (Moved<W>, W),
    rule: &BiasRule,
) -> W {
    let soft = rule.softness;
    let rate = W::splat(ANCHOR_STIFFNESS * soft.bias_rate) * anchor;
    let (lo, hi) = (W::splat(-rule.max_push), W::splat(rule.max_push));
    let gap = slip.gap(p.anchor_gap[k], p.ra, p.rb, p.tangent_lever[k]);
    let bias = (rate * gap).clamp(lo, hi);
    let ti = p.tangent_impulse[k];
    ti - p.tangent[k].mass * W::splat(soft.mass_scale) * (vt + bias)
        - W::splat(soft.impulse_scale) * ti
}

/// The friction impulse in the tangent plane: the impulse `want` that would stop the
/// sliding, if it lies inside the circular cone of radius `limit` (sticking); otherwise
/// `limit` against the sliding velocity `vt` (Coulomb: kinetic friction opposes the slip).
/// Scaling `want` back onto the cone instead would tilt the force towards the tangent
/// with the larger effective mass, making a box on a slope veer sideways and slide with
/// too little friction. Below `slip_speed` the slip direction is noise, and scaling is
/// the better guess (a sticking contact briefly over its cone in a soft pass). The
/// outside of the cone is only computed when a `live` lane is outside it.
#[inline(always)]
fn friction_impulse<W: Wide>(
    want: [W; 2],
    vt: [W; 2],
    limit: W,
    slip_speed: W,
    live: W::Mask,
) -> [W; 2] {
    let want2 = want[0] * want[0] + want[1] * want[1];
    let inside = want2.at_most(limit * limit);
    if !(live & !inside).any() {
        return want;
    }
    inside.choose(
        #[inline(always)]
        || want,
        #[inline(always)]
        || {
            let speed = (vt[0] * vt[0] + vt[1] * vt[1]).sqrt();
            speed.greater(slip_speed).choose(
                #[inline(always)]
                || [-limit * vt[0] / speed, -limit * vt[1] / speed],
                #[inline(always)]
                || {
                    let scale = limit / want2.sqrt();
                    [want[0] * scale, want[1] * scale]
                },
            )
        },
    )
}
