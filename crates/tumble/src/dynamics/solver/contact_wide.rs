//! Contact passes over [`LANES`] manifolds at once.
//!
//! Constraints of one colour below 63 share no moving body (see `Solver::colour_order`),
//! so solving several of them at the same time is the very Gauss–Seidel update that
//! solving them one after another makes. Consecutive constraints of one colour are
//! therefore grouped by [`LANES`]; a group gathers its bodies' velocities into lanes, runs
//! every point of its manifolds on them, and scatters the velocities of the moving bodies
//! back. Point j of each lane's manifold sits in slot j; a lane with fewer points is masked
//! out of the later slots, and the relax pass walks the slots downwards, so that every lane
//! meets its points in the scalar code's order.
//!
//! Each lane performs exactly the floating-point operations of the scalar code
//! (`ContactConstraint::solve`, `warm_start`), in the same order; its branches become
//! selects between both outcomes, and a masked lane keeps its old values (selected, never
//! added a zero to). Results are thus bit-identical to the scalar solver's.
//!
//! The groups keep their own copy of the points' hot data, slot by slot in lanes, built in
//! `prepare`; the scalar points get the impulses back before the end-of-step passes
//! ([`ContactLanes::write_back`]). Colour 63 and a colour's leftover single constraint
//! stay on the scalar path, in their place in the order.

use std::ops::Range;

use super::body::BodyState;
use super::contact::{BiasRule, ContactConstraint, Point, PointCold, Points, Row};
use super::lanes::{lane_mode, LaneMode, Lanes, Lanes3, Mask, LANES};

/// Fewest constraints worth a group: a single one is solved faster by the scalar code.
const MIN_LANES: usize = 2;

/// A row at one slot: each lane's I⁻¹(r × d) per body and effective mass.
#[derive(Debug, Clone, Copy, Default)]
struct RowLanes {
    turn_a: Lanes3,
    turn_b: Lanes3,
    mass: Lanes,
}

/// Point j of each lane's manifold: what the passes read and write (see `Point`).
#[derive(Debug, Clone, Copy, Default)]
struct Slot {
    ra: Lanes3,
    rb: Lanes3,
    separation: Lanes,
    lever: Lanes,
    normal: RowLanes,
    tangent: [RowLanes; 2],
    normal_impulse: Lanes,
    tangent_impulse: [Lanes; 2],
    max_normal_impulse: Lanes,
    anchor_gap: [Lanes; 2],
    tangent_lever: [Lanes; 2],
    /// The lanes whose manifold has this point, and of those the ones whose body a, b
    /// moves: only these states change.
    active: Mask,
    apply_a: Mask,
    apply_b: Mask,
}

/// Point j of each lane's manifold: what the passes seldom write (see `PointCold`).
#[derive(Debug, Clone, Copy, Default)]
struct SlotCold {
    approach_velocity: Lanes,
    total_normal: Lanes,
    total_tangent: [Lanes; 2],
}

/// Up to [`LANES`] consecutive constraints of one colour.
#[derive(Debug, Clone)]
struct Group {
    /// The group's first constraint in the solver's order, and how many lanes are used.
    first: usize,
    lanes: usize,
    /// Each lane's bodies; unused lanes repeat lane 0's, which they only read.
    a: [usize; LANES],
    b: [usize; LANES],
    /// Bit l: lane l's body a (b) moves; never set for unused lanes.
    moves_a: u32,
    moves_b: u32,
    normal: Lanes3,
    tangents: [Lanes3; 2],
    /// M⁻¹ d of each body for d = n, t₁, t₂.
    push_a: [Lanes3; 3],
    push_b: [Lanes3; 3],
    friction: Lanes,
    /// The group's slots, `slots` of them from `slot0`.
    slot0: usize,
    slots: usize,
}

/// The lane groups of a step and their points.
#[derive(Debug, Default)]
pub(crate) struct ContactLanes {
    groups: Vec<Group>,
    slots: Vec<Slot>,
    cold: Vec<SlotCold>,
    /// Whether a pass changed impulses that the scalar points do not have yet.
    unsaved: bool,
}

/// The two bodies of each lane, gathered.
#[derive(Clone, Copy)]
struct PairLanes {
    va: Lanes3,
    wa: Lanes3,
    vb: Lanes3,
    wb: Lanes3,
}

/// Each lane's motion since the step began: Δp and the columns of ΔR, per body.
struct MotionLanes {
    dp: [Lanes3; 2],
    dr: [[Lanes3; 3]; 2],
}

/// The shared factors of a direction's current separation (see `ContactConstraint::moved`).
#[derive(Clone, Copy)]
struct Moved {
    offset: Lanes,
    turn_a: Lanes3,
    turn_b: Lanes3,
}

/// Which pass: its bias rule, whether it corrects position, whether it adds the totals.
#[derive(Clone, Copy)]
pub(crate) struct Pass<'r> {
    pub rule: &'r BiasRule,
    pub bias: bool,
    pub totals: bool,
}

impl ContactLanes {
    pub fn clear(&mut self) {
        self.groups.clear();
        self.slots.clear();
        self.cold.clear();
        self.unsaved = false;
    }

    /// Groups `constraints` (in the solver's order) and copies their points into slots;
    /// groups stay on one side of `split` (the passes of the heavy islands start there,
    /// see `Solver::passes`). No groups in scalar mode.
    pub fn build(
        &mut self,
        constraints: &[ContactConstraint],
        split: usize,
        hot: &[Point],
        cold: &[PointCold],
    ) {
        self.clear();
        if lane_mode() == LaneMode::Scalar {
            return;
        }
        for part in [0..split, split..constraints.len()] {
            let mut start = part.start;
            while start < part.end {
                let colour = constraints[start].colour();
                let end = constraints[start..part.end]
                    .iter()
                    .position(|c| c.colour() != colour)
                    .map_or(part.end, |n| start + n);
                if colour < 63 {
                    for first in (start..end).step_by(LANES) {
                        let lanes = (end - first).min(LANES);
                        if lanes >= MIN_LANES {
                            let cs = &constraints[first..first + lanes];
                            self.push_group(cs, first, hot, cold);
                        }
                    }
                }
                start = end;
            }
        }
    }

    fn push_group(
        &mut self,
        cs: &[ContactConstraint],
        first: usize,
        hot: &[Point],
        cold: &[PointCold],
    ) {
        // Unused lanes repeat lane 0's constraint, which they only read; missing points
        // stay zeros, and their lanes are masked out.
        let lane = |l: usize| &cs[if l < cs.len() { l } else { 0 }];
        let vec =
            |f: &dyn Fn(&ContactConstraint) -> crate::math::Vec3| Lanes3::from_fn(|l| f(lane(l)));
        let moves = |side: usize| {
            let moving = cs.iter().map(|c| [c.moves().0, c.moves().1][side]);
            moving
                .enumerate()
                .fold(0u32, |m, (l, on)| m | (u32::from(on) << l))
        };
        let slot0 = self.slots.len();
        let slots = cs.iter().map(|c| c.range().len()).max().unwrap_or(0);
        let group = Group {
            first,
            lanes: cs.len(),
            a: std::array::from_fn(|l| lane(l).bodies().0),
            b: std::array::from_fn(|l| lane(l).bodies().1),
            moves_a: moves(0),
            moves_b: moves(1),
            normal: vec(&|c| c.normal()),
            tangents: [vec(&|c| c.tangents()[0]), vec(&|c| c.tangents()[1])],
            push_a: std::array::from_fn(|k| vec(&|c| c.pushes().0[k])),
            push_b: std::array::from_fn(|k| vec(&|c| c.pushes().1[k])),
            friction: Lanes::from_fn(|l| lane(l).friction()),
            slot0,
            slots,
        };
        self.slots.resize(slot0 + slots, Slot::default());
        self.cold.resize(slot0 + slots, SlotCold::default());
        for (l, c) in cs.iter().enumerate() {
            for (j, i) in c.range().enumerate() {
                self.slots[slot0 + j].set_lane(l, &hot[i], c.moves());
                self.cold[slot0 + j].set_lane(l, &cold[i]);
            }
        }
        self.groups.push(group);
    }

    /// Copies the impulses, the approach velocities and the totals of the grouped points
    /// back into the scalar points, for the end-of-step passes and the contacts.
    pub fn write_back(
        &mut self,
        constraints: &[ContactConstraint],
        hot: &mut [Point],
        cold: &mut [PointCold],
    ) {
        if !std::mem::take(&mut self.unsaved) {
            return;
        }
        for g in &self.groups {
            let lanes = constraints[g.first..g.first + g.lanes].iter().enumerate();
            for (l, c) in lanes {
                for (j, i) in c.range().enumerate() {
                    let (s, sc) = (&self.slots[g.slot0 + j], &self.cold[g.slot0 + j]);
                    let (p, pc) = (&mut hot[i], &mut cold[i]);
                    p.normal_impulse = s.normal_impulse.0[l];
                    p.tangent_impulse = [s.tangent_impulse[0].0[l], s.tangent_impulse[1].0[l]];
                    p.max_normal_impulse = s.max_normal_impulse.0[l];
                    pc.approach_velocity = sc.approach_velocity.0[l];
                    pc.total_normal = sc.total_normal.0[l];
                    pc.total_tangent = [sc.total_tangent[0].0[l], sc.total_tangent[1].0[l]];
                }
            }
        }
    }
}

impl RowLanes {
    fn set_lane(&mut self, l: usize, row: &Row) {
        self.turn_a.set_lane(l, row.turn_a);
        self.turn_b.set_lane(l, row.turn_b);
        self.mass.0[l] = row.mass;
    }

    /// `Row::velocity` per lane.
    #[inline(always)]
    fn velocity(&self, d: Lanes3, ra: Lanes3, rb: Lanes3, s: &PairLanes) -> Lanes {
        d.dot(s.vb - s.va) + rb.cross(d).dot(s.wb) - ra.cross(d).dot(s.wa)
    }

    /// `Row::apply` per lane, where `apply` = (a, b) says whose states change.
    #[inline(always)]
    fn apply(&self, lambda: Lanes, push: (Lanes3, Lanes3), apply: (Mask, Mask), s: &mut PairLanes) {
        s.va = apply.0.select3(s.va - push.0.scale(lambda), s.va);
        s.wa = apply.0.select3(s.wa - self.turn_a.scale(lambda), s.wa);
        s.vb = apply.1.select3(s.vb + push.1.scale(lambda), s.vb);
        s.wb = apply.1.select3(s.wb + self.turn_b.scale(lambda), s.wb);
    }
}

impl Slot {
    /// Makes lane `l` point `p`, of a manifold whose bodies move as `moves` says.
    fn set_lane(&mut self, l: usize, p: &Point, moves: (bool, bool)) {
        self.ra.set_lane(l, p.ra);
        self.rb.set_lane(l, p.rb);
        self.separation.0[l] = p.separation;
        self.lever.0[l] = p.lever;
        self.normal.set_lane(l, &p.normal);
        self.tangent[0].set_lane(l, &p.tangent[0]);
        self.tangent[1].set_lane(l, &p.tangent[1]);
        self.normal_impulse.0[l] = p.normal_impulse;
        self.tangent_impulse[0].0[l] = p.tangent_impulse[0];
        self.tangent_impulse[1].0[l] = p.tangent_impulse[1];
        self.max_normal_impulse.0[l] = p.max_normal_impulse;
        self.anchor_gap[0].0[l] = p.anchor_gap[0];
        self.anchor_gap[1].0[l] = p.anchor_gap[1];
        self.tangent_lever[0].0[l] = p.tangent_lever[0];
        self.tangent_lever[1].0[l] = p.tangent_lever[1];
        self.active.set(l, true);
        self.apply_a.set(l, moves.0);
        self.apply_b.set(l, moves.1);
    }
}

impl SlotCold {
    fn set_lane(&mut self, l: usize, c: &PointCold) {
        self.approach_velocity.0[l] = c.approach_velocity;
        self.total_normal.0[l] = c.total_normal;
        self.total_tangent[0].0[l] = c.total_tangent[0];
        self.total_tangent[1].0[l] = c.total_tangent[1];
    }
}

impl Group {
    #[inline(always)]
    fn gather(&self, states: &[BodyState]) -> PairLanes {
        PairLanes {
            va: Lanes3::gather(states, &self.a, |s| s.v),
            wa: Lanes3::gather(states, &self.a, |s| s.w),
            vb: Lanes3::gather(states, &self.b, |s| s.v),
            wb: Lanes3::gather(states, &self.b, |s| s.w),
        }
    }

    /// Writes the velocities of the moving bodies back; static and kinematic states are
    /// never written (see `Row::apply`).
    #[inline(always)]
    fn scatter(&self, s: &PairLanes, states: &mut [BodyState]) {
        for l in 0..LANES {
            if self.moves_a & (1 << l) != 0 {
                let st = &mut states[self.a[l]];
                st.v = s.va.lane(l);
                st.w = s.wa.lane(l);
            }
            if self.moves_b & (1 << l) != 0 {
                let st = &mut states[self.b[l]];
                st.v = s.vb.lane(l);
                st.w = s.wb.lane(l);
            }
        }
    }

    #[inline(always)]
    fn motion(&self, states: &[BodyState]) -> MotionLanes {
        MotionLanes {
            dp: [
                Lanes3::gather(states, &self.a, |s| s.dp),
                Lanes3::gather(states, &self.b, |s| s.dp),
            ],
            dr: [rotation(states, &self.a), rotation(states, &self.b)],
        }
    }

    /// `ContactConstraint::warm_start` per lane.
    #[inline(always)]
    fn warm_start(&self, slots: &[Slot], states: &mut [BodyState]) {
        let mut s = self.gather(states);
        for p in slots {
            let apply = (p.apply_a, p.apply_b);
            let (pa, pb) = (&self.push_a, &self.push_b);
            p.normal
                .apply(p.normal_impulse, (pa[0], pb[0]), apply, &mut s);
            p.tangent[0].apply(p.tangent_impulse[0], (pa[1], pb[1]), apply, &mut s);
            p.tangent[1].apply(p.tangent_impulse[1], (pa[2], pb[2]), apply, &mut s);
        }
        self.scatter(&s, states);
    }

    /// `ContactConstraint::solve` per lane.
    #[inline(always)]
    fn solve<const BIAS: bool>(
        &self,
        slots: &mut [Slot],
        cold: &mut [SlotCold],
        states: &mut [BodyState],
        pass: Pass<'_>,
    ) {
        let mut s = self.gather(states);
        let motion = self.motion(states);
        let n = slots.len();
        let moved = moved_along(self.normal, &motion);
        for k in 0..n {
            let j = if BIAS { k } else { n - 1 - k };
            self.solve_normal::<BIAS>(&mut slots[j], &mut cold[j], &mut s, pass.rule, moved);
        }
        let slip = [
            moved_along(self.tangents[0], &motion),
            moved_along(self.tangents[1], &motion),
        ];
        for k in 0..n {
            let j = if BIAS { k } else { n - 1 - k };
            self.solve_friction::<BIAS>(&mut slots[j], &mut s, pass.rule, slip);
        }
        if pass.totals {
            for (p, c) in slots.iter().zip(cold) {
                c.total_normal = c.total_normal + p.normal_impulse;
                c.total_tangent[0] = c.total_tangent[0] + p.tangent_impulse[0];
                c.total_tangent[1] = c.total_tangent[1] + p.tangent_impulse[1];
            }
        }
        self.scatter(&s, states);
    }

    /// `ContactConstraint::solve_normal` per lane.
    #[inline(always)]
    fn solve_normal<const BIAS: bool>(
        &self,
        p: &mut Slot,
        c: &mut SlotCold,
        s: &mut PairLanes,
        rule: &BiasRule,
        moved: Moved,
    ) {
        let (zero, one) = (Lanes::splat(0.0), Lanes::splat(1.0));
        let sep =
            p.separation + moved.offset + moved.turn_b.dot(p.rb) - moved.turn_a.dot(p.ra) - p.lever;
        let speculative = sep.gt(zero);
        let closing = sep * Lanes::splat(rule.inv_h);
        let (velocity_bias, mass_scale, impulse_scale) = if BIAS {
            let soft = &rule.softness;
            let error = (sep + Lanes::splat(rule.slop)).min(zero);
            let push = (Lanes::splat(soft.bias_rate) * error).max(Lanes::splat(-rule.max_push));
            (
                speculative.select(closing, push),
                speculative.select(one, Lanes::splat(soft.mass_scale)),
                speculative.select(zero, Lanes::splat(soft.impulse_scale)),
            )
        } else {
            (speculative.select(closing, zero), one, zero)
        };
        let vn = p.normal.velocity(self.normal, p.ra, p.rb, s);
        let delta =
            -p.normal.mass * mass_scale * (vn + velocity_bias) - impulse_scale * p.normal_impulse;
        let total = (p.normal_impulse + delta).max(zero);
        let applied = total - p.normal_impulse;
        let impact = p.active & p.max_normal_impulse.eq(zero) & applied.gt(zero);
        p.normal_impulse = p.active.select(total, p.normal_impulse);
        p.max_normal_impulse = p
            .active
            .select(p.max_normal_impulse.max(applied), p.max_normal_impulse);
        let push = (self.push_a[0], self.push_b[0]);
        p.normal.apply(applied, push, (p.apply_a, p.apply_b), s);
        if impact.any() {
            c.approach_velocity = impact.select(c.approach_velocity.min(vn), c.approach_velocity);
        }
    }

    /// `ContactConstraint::solve_friction` per lane; a lane whose point pushes nothing is
    /// masked out, as the scalar code returns early.
    #[inline(always)]
    fn solve_friction<const BIAS: bool>(
        &self,
        p: &mut Slot,
        s: &mut PairLanes,
        rule: &BiasRule,
        slip: [Moved; 2],
    ) {
        let zero = Lanes::splat(0.0);
        let ti = p.tangent_impulse;
        let idle = p.normal_impulse.eq(zero) & ti[0].eq(zero) & ti[1].eq(zero);
        let live = p.active & !idle;
        if !live.any() {
            return;
        }
        let vt = [
            p.tangent[0].velocity(self.tangents[0], p.ra, p.rb, s),
            p.tangent[1].velocity(self.tangents[1], p.ra, p.rb, s),
        ];
        let want = if BIAS {
            [
                anchored_want(p, 0, vt[0], slip[0], rule),
                anchored_want(p, 1, vt[1], slip[1], rule),
            ]
        } else {
            [
                ti[0] - p.tangent[0].mass * vt[0],
                ti[1] - p.tangent[1].mass * vt[1],
            ]
        };
        let limit = self.friction * p.normal_impulse;
        let total = friction_impulse(want, vt, limit, Lanes::splat(rule.slip_speed), live);
        let apply = (p.apply_a & live, p.apply_b & live);
        for (k, total) in total.into_iter().enumerate() {
            let push = (self.push_a[k + 1], self.push_b[k + 1]);
            p.tangent[k].apply(total - p.tangent_impulse[k], push, apply, s);
            p.tangent_impulse[k] = live.select(total, p.tangent_impulse[k]);
        }
    }
}

/// The biased pass's friction impulse along tangent `k` before the cone (see
/// `ContactConstraint::solve_friction`): the anchors' spring plus stopping the slip.
#[inline(always)]
fn anchored_want(p: &Slot, k: usize, vt: Lanes, m: Moved, rule: &BiasRule) -> Lanes {
    let soft = rule.softness;
    let rate = Lanes::splat(super::contact::ANCHOR_STIFFNESS * soft.bias_rate);
    let (lo, hi) = (Lanes::splat(-rule.max_push), Lanes::splat(rule.max_push));
    let gap =
        p.anchor_gap[k] + m.offset + m.turn_b.dot(p.rb) - m.turn_a.dot(p.ra) - p.tangent_lever[k];
    let bias = (rate * gap).clamp(lo, hi);
    let ti = p.tangent_impulse[k];
    ti - p.tangent[k].mass * Lanes::splat(soft.mass_scale) * (vt + bias)
        - Lanes::splat(soft.impulse_scale) * ti
}

/// `contact::friction_impulse` per lane; the cone's outside is only computed when a `live`
/// lane is outside it.
#[inline(always)]
fn friction_impulse(
    want: [Lanes; 2],
    vt: [Lanes; 2],
    limit: Lanes,
    slip_speed: Lanes,
    live: Mask,
) -> [Lanes; 2] {
    let want2 = want[0] * want[0] + want[1] * want[1];
    let inside = want2.le(limit * limit);
    if !(live & !inside).any() {
        return want;
    }
    let speed = (vt[0] * vt[0] + vt[1] * vt[1]).sqrt();
    let sliding = speed.gt(slip_speed);
    let scale = limit / want2.sqrt();
    let outside = [
        sliding.select(-limit * vt[0] / speed, want[0] * scale),
        sliding.select(-limit * vt[1] / speed, want[1] * scale),
    ];
    [
        inside.select(want[0], outside[0]),
        inside.select(want[1], outside[1]),
    ]
}

/// `ContactConstraint::moved` (and `slip`) for direction `d` per lane.
#[inline(always)]
fn moved_along(d: Lanes3, m: &MotionLanes) -> Moved {
    Moved {
        offset: d.dot(m.dp[1] - m.dp[0]),
        turn_a: turn_back(&m.dr[0], d),
        turn_b: turn_back(&m.dr[1], d),
    }
}

/// ΔRᵀ d per lane, from the columns of ΔR: glam's `transpose() * d`, operation for operation.
#[inline(always)]
fn turn_back(dr: &[Lanes3; 3], d: Lanes3) -> Lanes3 {
    Lanes3 {
        x: dr[0].dot(d),
        y: dr[1].dot(d),
        z: dr[2].dot(d),
    }
}

/// The columns of each lane's ΔR.
#[inline(always)]
fn rotation(states: &[BodyState], index: &[usize; LANES]) -> [Lanes3; 3] {
    [
        Lanes3::gather(states, index, |s| s.dr.x_axis),
        Lanes3::gather(states, index, |s| s.dr.y_axis),
        Lanes3::gather(states, index, |s| s.dr.z_axis),
    ]
}

/// Warm starts every contact: the groups in lanes, the others one by one, all in the
/// solver's order.
pub(crate) fn warm_start(
    constraints: &[ContactConstraint],
    points: &Points,
    states: &mut [BodyState],
) {
    #[cfg(target_arch = "x86_64")]
    if super::lanes::use_avx2() {
        // SAFETY: `use_avx2` has checked that this CPU supports AVX2, the only feature
        // `warm_start_avx2` is compiled for; it has no other requirement.
        unsafe { warm_start_avx2(constraints, points, states) };
        return;
    }
    warm_start_lanes(constraints, points, states);
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn warm_start_avx2(
    constraints: &[ContactConstraint],
    points: &Points,
    states: &mut [BodyState],
) {
    warm_start_lanes(constraints, points, states);
}

#[inline(always)]
fn warm_start_lanes(constraints: &[ContactConstraint], points: &Points, states: &mut [BodyState]) {
    let lanes = &points.lanes;
    let mut next = 0;
    for g in &lanes.groups {
        for c in &constraints[next..g.first] {
            c.warm_start(&points.hot, states);
        }
        g.warm_start(&lanes.slots[g.slot0..g.slot0 + g.slots], states);
        next = g.first + g.lanes;
    }
    for c in &constraints[next..] {
        c.warm_start(&points.hot, states);
    }
}

/// One solve or relax pass over the contacts in `range`: the groups in lanes, the others
/// one by one, all in the solver's order. No group straddles either end of `range`.
pub(crate) fn solve_pass(
    constraints: &[ContactConstraint],
    range: Range<usize>,
    points: &mut Points,
    states: &mut [BodyState],
    pass: Pass<'_>,
) {
    #[cfg(target_arch = "x86_64")]
    if super::lanes::use_avx2() {
        // SAFETY: `use_avx2` has checked that this CPU supports AVX2, the only feature
        // `solve_pass_avx2` is compiled for; it has no other requirement.
        unsafe { solve_pass_avx2(constraints, range, points, states, pass) };
        return;
    }
    solve_pass_lanes(constraints, range, points, states, pass);
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn solve_pass_avx2(
    constraints: &[ContactConstraint],
    range: Range<usize>,
    points: &mut Points,
    states: &mut [BodyState],
    pass: Pass<'_>,
) {
    solve_pass_lanes(constraints, range, points, states, pass);
}

#[inline(always)]
fn solve_pass_lanes(
    constraints: &[ContactConstraint],
    range: Range<usize>,
    points: &mut Points,
    states: &mut [BodyState],
    pass: Pass<'_>,
) {
    let (rule, bias, totals) = (pass.rule, pass.bias, pass.totals);
    let groups = &points.lanes.groups;
    let from = groups.partition_point(|g| g.first < range.start);
    let to = groups.partition_point(|g| g.first < range.end);
    let mut next = range.start;
    for gi in from..to {
        let first = points.lanes.groups[gi].first;
        for c in &constraints[next..first] {
            c.solve(points, states, rule, bias, totals);
        }
        let ContactLanes {
            groups,
            slots,
            cold,
            unsaved,
        } = &mut points.lanes;
        let g = &groups[gi];
        let span = g.slot0..g.slot0 + g.slots;
        let (slots, cold) = (&mut slots[span.clone()], &mut cold[span]);
        if bias {
            g.solve::<true>(slots, cold, states, pass);
        } else {
            g.solve::<false>(slots, cold, states, pass);
        }
        *unsaved = true;
        next = g.first + g.lanes;
    }
    for c in &constraints[next..range.end] {
        c.solve(points, states, rule, bias, totals);
    }
}

#[cfg(test)]
mod tests {
    use crate::dynamics::solver::lanes::{with_lane_mode, LaneMode};
    use crate::prelude::*;

    fn world_on_ground() -> World {
        let mut w = World::new(&WorldDef {
            sleep: false,
            ..Default::default()
        });
        let ground = BodyDef {
            kind: BodyKind::Static,
            friction: 0.6,
            ..Default::default()
        };
        w.create_body(&ground, Shape::plane(Vec3::Y, 0.0)).unwrap();
        w
    }

    /// A 1 kg box under a 1000 kg box at `x`: an island with extra passes.
    fn heavy_pair(w: &mut World, x: Real) {
        for (y, mass) in [(0.5, 1.0), (1.5, 1000.0)] {
            let def = BodyDef {
                position: Vec3::new(x, y, 0.0),
                mass: MassSpec::Mass(mass),
                ..Default::default()
            };
            w.create_body(&def, Shape::cuboid(Vec3::splat(0.5)))
                .unwrap();
        }
    }

    /// A pile that gives the lane groups work of every kind: manifolds of one to four
    /// points (spheres, boxes on edges and faces), bounces (the restitution pass reads
    /// the impulses back from the lanes), friction, and a heavy pair.
    fn pile() -> World {
        let mut w = world_on_ground();
        for i in 0..48 {
            let (x, z) = ((i % 4) as Real * 1.1, ((i / 4) % 4) as Real * 1.1);
            let y = 0.6 + (i / 16) as Real * 1.2;
            let def = BodyDef {
                position: Vec3::new(x + 0.05 * (i % 3) as Real, y, z),
                orientation: Quat::from_rotation_y(0.3 * i as Real),
                restitution: if i % 5 == 0 { 0.6 } else { 0.0 },
                friction: 0.4,
                ..Default::default()
            };
            let shape = match i % 3 {
                0 => Shape::sphere(0.45),
                _ => Shape::cuboid(Vec3::new(0.5, 0.4, 0.45)),
            };
            w.create_body(&def, shape).unwrap();
        }
        heavy_pair(&mut w, 10.0);
        w
    }

    /// Lone spheres and heavy pairs on the ground: the ordinary contacts are all of colour
    /// 0, and so are the first of the heavy islands' contacts after them, so a group that
    /// ignored the boundary would run heavy contacts in the ordinary passes.
    fn row() -> World {
        let mut w = world_on_ground();
        for k in 0..3 {
            let def = BodyDef {
                position: Vec3::new(-3.0 * k as Real - 3.0, 0.4, 0.0),
                linear_velocity: Vec3::new(0.5, 0.0, 0.0),
                ..Default::default()
            };
            w.create_body(&def, Shape::sphere(0.4)).unwrap();
            heavy_pair(&mut w, 3.0 * k as Real + 3.0);
        }
        w
    }

    /// The state bits and every contact's impulses after a second of `scene`.
    fn run(mode: LaneMode, scene: fn() -> World) -> (u64, String) {
        with_lane_mode(mode, || {
            let mut w = scene();
            for _ in 0..60 {
                w.step(1.0 / 60.0).unwrap();
            }
            (w.state_hash(), format!("{:?}", w.contacts()))
        })
    }

    #[test]
    fn lanes_give_the_scalar_solver_s_bits() {
        // The lane passes perform each lane's scalar operations in the scalar order
        // (module docs): trajectories and reported impulses must agree to the bit,
        // whichever kernels this CPU runs.
        for scene in [pile, row] {
            let scalar = run(LaneMode::Scalar, scene);
            assert_eq!(run(LaneMode::Portable, scene), scalar);
            assert_eq!(run(LaneMode::Avx2, scene), scalar);
        }
    }
}
