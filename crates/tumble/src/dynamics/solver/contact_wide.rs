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
//! The passes are the scalar solver's own (`super::rows`), instantiated on `Lanes`: each
//! lane performs exactly the floating-point operations of the scalar code, in the same
//! order; its branches become blends of both outcomes, and a masked lane keeps its old
//! values (chosen, never added a zero to). Results are thus bit-identical to the scalar
//! solver's.
//!
//! The groups are planned before the constraints are prepared ([`ContactLanes::plan`]),
//! and a grouped manifold's points are prepared straight into their lanes, slot by slot:
//! their scalar entries in `Points::hot` are not written at all. Copied there first and
//! then into the lanes, the points were written twice and read once more, and the copy
//! alone was 11 % of the pyramid's step. The contacts take their impulses from the lanes
//! ([`ContactLanes::solved`]); the points are copied back whole only when a bounce or an
//! overlap pass will read them ([`ContactLanes::write_back`]). Colour 63 and a colour's
//! leftover single constraint stay on the scalar path, in their place in the order.

use std::ops::Range;

use super::body::{BodyState, SharedStates, StateAccess};
use super::contact::{ContactConstraint, Point, PointCold, Points};
use super::lanes::{lane_mode, wide_kernel, LaneMode, Lanes, Lanes3, Mask, LANES};
pub(crate) use super::rows::Pass;
use super::rows::{self, Frame, Masks, Motion, Pair, Sums};
use crate::math::Real;
use crate::team::Parts;
use crate::threads::Par;

/// A group's points in lanes, their masks and their sums, as a pass walks them.
type GroupPoints<'a> = (
    &'a mut [Point<Lanes>],
    &'a [Masks<Mask>],
    &'a mut [Sums<Lanes>],
);

/// Fewest constraints worth a group: a single one is solved faster by the scalar code.
const MIN_LANES: usize = 2;

/// Fewest groups worth a piece of a pass on another thread. A group's pass takes about
/// 0.3 µs (eight manifolds of four points), and a piece handed to the step's team (see
/// `team.rs`) about a microsecond. On rayon's fork–join, whose workers sleep between the
/// step's short passes, pieces of 16 groups made the rain's landing 15 % slower on two
/// threads and 64 broke even; with the team, on Box3D's large pyramid (colours of about
/// 300 groups), pieces of 4, 16 and 64 groups gave 409, 463 and 402 ms a step on two
/// threads against 546–576 on one (runs on this 2-core machine vary by 10–20 %).
const GROUPS_A_PIECE: usize = 32;

/// Up to [`LANES`] consecutive constraints of one colour.
#[derive(Debug, Clone, Default)]
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
    /// Each lane's manifold frame.
    frame: Frame<Lanes>,
    /// Whether a lane's manifold has a round side (only then are ∫ω dt gathered).
    round: bool,
    /// The group's slots, `slots` of them from `slot0`.
    slot0: usize,
    slots: usize,
}

/// The lane groups of a step and their points: per slot, point j of each lane's
/// manifold (the hot data, the masks of the lanes that have it, the sums).
#[derive(Debug, Default)]
pub(crate) struct ContactLanes {
    groups: Vec<Group>,
    slots: Vec<Point<Lanes>>,
    masks: Vec<Masks<Mask>>,
    cold: Vec<Sums<Lanes>>,
    /// Per constraint (in the solver's order), where its points go: slot0 · LANES + lane
    /// of its group, or [`SCALAR`] for a constraint on the scalar path.
    place: Vec<u32>,
    /// The runs of groups of one colour, as planned (`add_run` keeps the long ones once
    /// the groups are filled).
    planned: Vec<Range<usize>>,
    /// Whether the scalar points hold the grouped points whole (see `write_back`):
    /// they, not the lanes, then say what the contacts keep.
    saved: bool,
    /// Runs of consecutive groups of one colour long enough to be split over threads,
    /// each checked to share no moving body (see `add_run`).
    runs: Vec<Range<usize>>,
    /// Per body, the last run that claimed it, and the runs looked at (scratch of
    /// `add_run`).
    stamp: Vec<u32>,
    tag: u32,
}

/// [`ContactLanes::place`] of a constraint on the scalar path.
const SCALAR: u32 = u32::MAX;

/// What planning the groups needs of a constraint: its colour, its number of points, and
/// whether it has rolling or twist rows (which the lanes do not carry).
pub(crate) type Planned = (u32, usize, bool);

impl ContactLanes {
    /// Forgets the runs; `plan` replaces the groups. The group and slot buffers keep
    /// their length: `plan` plans into the old groups, and the preparation and `fill`
    /// write each group and slot whole in parallel, rather than a serial resize from zero
    /// every step (a fresh `Group` is 2 KB of defaults in f64: pushing them was 1 % of the
    /// rain's step).
    pub fn clear(&mut self) {
        self.saved = false;
        self.runs.clear();
        self.planned.clear();
        if self.tag != 0 {
            // Only once a run was checked (a zero-length fill still paid for the call).
            self.stamp.fill(0);
            self.tag = 0;
        }
    }

    /// Plans the groups of the constraints that `planned` describes (in the solver's
    /// order) and sizes the slots: groups stay between the `splits` (the passes of the
    /// heavy islands and the tall stacks start there, see `Solver::passes`); `angular`
    /// says whether any constraint has angular rows, which stay scalar. No groups in
    /// scalar mode, nor when `off` (a step without passes sums its totals from the scalar
    /// points). The preparation then writes the grouped points into their lanes (see
    /// [`LaneWriter`]), and [`ContactLanes::fill`] the rest.
    pub fn plan(
        &mut self,
        planned: &[Planned],
        ([heavy, tall], angular): ([usize; 2], bool),
        off: bool,
    ) {
        self.clear();
        self.place.clear();
        self.place.resize(planned.len(), SCALAR);
        if off || lane_mode() == LaneMode::Scalar {
            self.groups.clear();
            return;
        }
        let (mut slots, mut groups) = (0, 0);
        for part in [0..heavy, heavy..tall, tall..planned.len()] {
            let mut start = part.start;
            while start < part.end {
                let colour = planned[start].0;
                let end = planned[start..part.end]
                    .iter()
                    .position(|c| c.0 != colour)
                    .map_or(part.end, |n| start + n);
                let mut first = start;
                let run_start = groups;
                while colour < 63 && first < end {
                    let lanes = group_size(&planned[first..end], angular);
                    if lanes >= MIN_LANES {
                        let cs = &planned[first..first + lanes];
                        let count = cs.iter().map(|c| c.1).max().unwrap_or(0);
                        Group::plan(&mut self.groups, groups, (first, lanes), (slots, count));
                        for (l, place) in self.place[first..first + lanes].iter_mut().enumerate() {
                            *place = (slots * LANES + l) as u32;
                        }
                        groups += 1;
                        slots += count;
                    }
                    first += lanes.max(1);
                }
                self.planned.push(run_start..groups);
                start = end;
            }
        }
        self.groups.truncate(groups);
        if self.slots.len() < slots {
            self.slots.resize(slots, Point::default());
            self.masks.resize(slots, Masks::default());
            self.cold.resize(slots, Sums::default());
        }
    }

    /// The lanes for the preparation's pieces to write their grouped points into.
    pub fn writer(&mut self) -> LaneWriter<'_> {
        LaneWriter {
            place: &self.place,
            slots: Parts::new(&mut self.slots),
            sums: Parts::new(&mut self.cold),
        }
    }

    /// Point `j` of constraint `k` as its lane holds it, if the constraint is grouped.
    pub fn point(&self, k: usize, j: usize) -> Option<Point> {
        let (slot0, l) = place(self.place[k])?;
        Some(self.slots[slot0 + j].lane(l))
    }

    /// What the contact keeps of point `j` of constraint `k`, from its lane: its impulses
    /// and sums; `None` for a scalar constraint, or once the scalar points hold the
    /// lanes' points whole (and the bounce pass has added to their sums).
    pub fn solved(&self, k: usize, j: usize) -> Option<(Real, [Real; 2], Sums)> {
        let (slot0, l) = place(self.place[k]).filter(|_| !self.saved)?;
        let (s, sums) = (&self.slots[slot0 + j], &self.cold[slot0 + j]);
        let tangent = [s.tangent_impulse[0].0[l], s.tangent_impulse[1].0[l]];
        Some((s.normal_impulse.0[l], tangent, sums.lane(l)))
    }

    /// Sets the separation of point `j` of the grouped constraint `k`.
    pub fn set_separation(&mut self, (k, j): (usize, usize), separation: Real) {
        if let Some((slot0, l)) = place(self.place[k]) {
            self.slots[slot0 + j].separation.0[l] = separation;
        }
    }

    /// Fills what the preparation left of the planned groups, in pieces of consecutive
    /// groups on the step's team: each group's bodies, moving masks and frames, each
    /// slot's masks, and zeros in the lanes without a point (masked out, but read). Then
    /// keeps the runs long enough to be split over threads.
    pub fn fill(&mut self, constraints: &[ContactConstraint], par: Par) {
        let n = self.groups.len();
        let size = n.div_ceil(par.pieces(n, GROUPS_A_PIECE)).max(1);
        let slots = self.groups.last().map_or(0, |g| g.slot0 + g.slots);
        let groups = Parts::new(&mut self.groups);
        let slot_parts = Parts::new(&mut self.slots[..slots]);
        let mask_parts = Parts::new(&mut self.masks[..slots]);
        let sum_parts = Parts::new(&mut self.cold[..slots]);
        crate::team::pieces(par.threads, n.div_ceil(size), &|i| {
            let range = i * size..((i + 1) * size).min(n);
            // SAFETY: piece i takes groups i·size.. alone (each piece runs once).
            let groups = unsafe { groups.part(range) };
            let from = groups[0].slot0;
            let to = groups.last().map_or(from, |g| g.slot0 + g.slots);
            // SAFETY: the slots from this piece's first group's slot0 to its last group's
            // end: groups' slots were planned consecutive and disjoint, in group order,
            // so pieces of disjoint groups get disjoint slots.
            let (slots, masks, sums) = unsafe {
                (
                    slot_parts.part(from..to),
                    mask_parts.part(from..to),
                    sum_parts.part(from..to),
                )
            };
            for g in groups {
                let cs = &constraints[g.first..g.first + g.lanes];
                let at = g.slot0 - from..g.slot0 - from + g.slots;
                g.fill(cs);
                let out = (&mut slots[at.clone()], &mut masks[at.clone()]);
                fill_empty(cs, out, &mut sums[at]);
            }
        });
        for run in std::mem::take(&mut self.planned) {
            self.add_run(run);
        }
    }

    /// Keeps `run` (groups of one colour) for splitting over threads if it is long enough
    /// and, checked here, each body a group writes (a moving one) appears in no other lane
    /// of the run, which is what `SharedStates` needs. The colouring promises it; the
    /// check makes the parallel passes sound whatever the colouring did.
    fn add_run(&mut self, run: Range<usize>) {
        if Par::split_at(run.len(), GROUPS_A_PIECE) < 2 {
            return;
        }
        self.tag += 1;
        let tag = self.tag;
        let groups = &self.groups[run.clone()];
        fn lanes(g: &Group) -> impl Iterator<Item = (usize, bool)> + '_ {
            (0..g.lanes).flat_map(move |l| {
                [
                    (g.a[l], g.moves_a & (1 << l) != 0),
                    (g.b[l], g.moves_b & (1 << l) != 0),
                ]
            })
        }
        let most = groups.iter().flat_map(lanes).map(|(k, _)| k).max();
        if self.stamp.len() <= most.unwrap_or(0) {
            self.stamp.resize(most.unwrap_or(0) + 1, 0);
        }
        for (k, _) in groups.iter().flat_map(lanes).filter(|(_, w)| *w) {
            if self.stamp[k] == tag {
                return;
            }
            self.stamp[k] = tag;
        }
        for (k, _) in groups.iter().flat_map(lanes).filter(|(_, w)| !*w) {
            if self.stamp[k] == tag {
                return;
            }
        }
        self.runs.push(run);
    }

    /// Copies the grouped points whole, with their sums, into the scalar points, which
    /// the preparation did not write: for the bounce and overlap passes, which read their
    /// rows, anchors and separations, and from then on for the contacts too (see
    /// [`ContactLanes::solved`]). Without those passes the contacts read their impulses
    /// from the lanes, and nothing is copied. In pieces of consecutive groups on the
    /// step's team (a group's points are the consecutive points of its consecutive
    /// constraints).
    pub fn write_back(
        &mut self,
        constraints: &[ContactConstraint],
        (hot, cold): (&mut [Point], &mut [PointCold]),
        par: Par,
    ) {
        self.saved = true;
        if self.groups.is_empty() {
            return;
        }
        let (groups, n) = (&self.groups, self.groups.len());
        let size = n.div_ceil(par.pieces(n, GROUPS_A_PIECE)).max(1);
        let (hot, cold) = (Parts::new(hot), Parts::new(cold));
        let points = |g: &Group| {
            let first = constraints[g.first].range().start;
            first..constraints[g.first + g.lanes - 1].range().end
        };
        crate::team::pieces(par.threads, n.div_ceil(size), &|i| {
            let groups = &groups[i * size..((i + 1) * size).min(n)];
            let base = points(&groups[0]).start;
            let end = points(&groups[groups.len() - 1]).end;
            // SAFETY: the groups' point ranges are disjoint and in order (the groups'
            // constraints are consecutive, in the order their points were laid), so
            // pieces of consecutive groups own disjoint ranges of points.
            let (hot, cold) = unsafe { (hot.part(base..end), cold.part(base..end)) };
            for g in groups {
                let lanes = constraints[g.first..g.first + g.lanes].iter().enumerate();
                for (l, c) in lanes {
                    for (j, i) in c.range().enumerate() {
                        let (s, sc) = (&self.slots[g.slot0 + j], &self.cold[g.slot0 + j]);
                        hot[i - base] = s.lane(l);
                        cold[i - base].sums = sc.lane(l);
                    }
                }
            }
        });
    }
}

/// Fills a group's slots where the preparation wrote nothing, and their masks: lane l of
/// slot j holds point j of constraint l of `cs`, if it has one; lanes without one are
/// zero, and masked out.
fn fill_empty(
    cs: &[ContactConstraint],
    (slots, masks): (&mut [Point<Lanes>], &mut [Masks<Mask>]),
    sums: &mut [Sums<Lanes>],
) {
    let (zero, zero_sums) = (Point::default(), Sums::default());
    let slots = slots.iter_mut().zip(masks).zip(sums);
    for (j, ((slot, mask), sum)) in slots.enumerate() {
        let mut m = Masks::<Mask>::default();
        for l in 0..LANES {
            match cs.get(l).filter(|c| j < c.range().len()) {
                Some(c) => m.set_lane(l, c.moves()),
                None => {
                    slot.set_lane(l, &zero);
                    sum.set_lane(l, &zero_sums);
                }
            }
        }
        *mask = m;
    }
}

/// A constraint's group's first slot and its lane, from its [`ContactLanes::place`].
fn place(at: u32) -> Option<(usize, usize)> {
    (at != SCALAR).then_some((at as usize / LANES, at as usize % LANES))
}

/// The lanes handed out to the preparation's pieces (see [`ContactLanes::writer`]).
pub(crate) struct LaneWriter<'a> {
    place: &'a [u32],
    slots: Parts<'a, Point<Lanes>>,
    sums: Parts<'a, Sums<Lanes>>,
}

impl LaneWriter<'_> {
    /// The first constraint from `k` on that no group straddles (a piece of the
    /// preparation starts there): one that is not in a group's later lanes.
    pub fn boundary(&self, mut k: usize) -> usize {
        while self
            .place
            .get(k)
            .is_some_and(|&p| place(p).is_some_and(|(_, l)| l > 0))
        {
            k += 1;
        }
        k
    }

    /// The slots of the grouped constraints in `range`, which has `count(k)` points for
    /// each constraint k.
    ///
    /// # Safety
    /// `range` starts and ends at [`LaneWriter::boundary`]s, and no other live part's
    /// range overlaps it: then its groups are whole and their slots its own (the groups'
    /// slots were planned consecutive, in the order of their constraints).
    pub unsafe fn part(&self, range: Range<usize>, count: impl Fn(usize) -> usize) -> LanePart<'_> {
        let (mut from, mut to) = (usize::MAX, 0);
        for k in range {
            if let Some((slot0, _)) = place(self.place[k]) {
                from = from.min(slot0);
                to = to.max(slot0 + count(k));
            }
        }
        // A manifold without points (a hook may empty one) still places the span.
        let span = if from <= to { from..to } else { 0..0 };
        // SAFETY: within the range's own groups' slots (see above).
        let (slots, sums) =
            unsafe { (self.slots.part(span.clone()), self.sums.part(span.clone())) };
        LanePart {
            place: self.place,
            base: span.start,
            slots,
            sums,
        }
    }
}

/// The slots a piece of the preparation writes its grouped points into, from slot `base`.
pub(crate) struct LanePart<'a> {
    place: &'a [u32],
    base: usize,
    slots: &'a mut [Point<Lanes>],
    sums: &'a mut [Sums<Lanes>],
}

impl LanePart<'_> {
    /// Whether constraint `k` is grouped (its points go into lanes).
    pub fn grouped(&self, k: usize) -> bool {
        self.place[k] != SCALAR
    }

    /// Writes the grouped constraint `k`'s points and their sums into its lane.
    #[inline]
    pub fn put(&mut self, k: usize, hot: &[Point], cold: &[PointCold]) {
        let Some((slot0, l)) = place(self.place[k]) else {
            return;
        };
        let at = slot0 - self.base;
        let slots = self.slots[at..].iter_mut().zip(&mut self.sums[at..]);
        for ((slot, sum), (p, c)) in slots.zip(hot.iter().zip(cold)) {
            slot.set_lane(l, p);
            sum.set_lane(l, &c.sums);
        }
    }
}

/// Calls `$m!` on every scalar field of a [`Point`], each as its path in parentheses.
macro_rules! point_fields {
    ($m:ident) => {
        $m!((ra.x)(ra.y)(ra.z)(rb.x)(rb.y)(rb.z)(separation)(lever)(
            normal.turn_a.x
        )(normal.turn_a.y)(normal.turn_a.z)(normal.turn_b.x)(
            normal.turn_b.y
        )(normal.turn_b.z)(normal.mass)(tangent[0].turn_a.x)(
            tangent[0].turn_a.y
        )(tangent[0].turn_a.z)(tangent[0].turn_b.x)(
            tangent[0].turn_b.y
        )(tangent[0].turn_b.z)(tangent[0].mass)(
            tangent[1].turn_a.x
        )(tangent[1].turn_a.y)(tangent[1].turn_a.z)(
            tangent[1].turn_b.x
        )(tangent[1].turn_b.y)(tangent[1].turn_b.z)(
            tangent[1].mass
        )(normal_impulse)(tangent_impulse[0])(tangent_impulse[1])(
            max_normal_impulse
        )(anchor_gap[0])(anchor_gap[1])(tangent_lever[0])(
            tangent_lever[1]
        ))
    };
}

impl Point<Lanes> {
    /// Lane `l` becomes `p`, field by field.
    #[inline(always)]
    fn set_lane(&mut self, l: usize, p: &Point) {
        macro_rules! copy {
            ($(($($f:tt)*))*) => { $( self.$($f)*.0[l] = p.$($f)*; )* };
        }
        point_fields!(copy);
    }

    /// Lane `l` as a scalar point.
    fn lane(&self, l: usize) -> Point {
        let mut p: Point = Point::default();
        macro_rules! copy {
            ($(($($f:tt)*))*) => { $( p.$($f)* = self.$($f)*.0[l]; )* };
        }
        point_fields!(copy);
        p
    }
}

/// `point_fields` names every field: a field added to `Point` must be added there.
const _: () = assert!(std::mem::size_of::<Point>() == 37 * std::mem::size_of::<Real>());

impl Frame<Lanes> {
    /// Lane `l` becomes `f`, field by field (gathered through `array::from_fn` per field,
    /// a group's frame was 2 % of the pyramid's step).
    #[inline(always)]
    fn set_lane(&mut self, l: usize, f: &Frame) {
        macro_rules! copy {
            ($(($($f:tt)*))*) => { $( self.$($f)*.0[l] = f.$($f)*; )* };
        }
        copy!(
            (normal.x)(normal.y)(normal.z)(tangents[0].x)(tangents[0].y)(tangents[0].z)(
                tangents[1].x
            )(tangents[1].y)(tangents[1].z)(push_a[0].x)(push_a[0].y)(push_a[0].z)(
                push_a[1].x
            )(push_a[1].y)(push_a[1].z)(push_a[2].x)(push_a[2].y)(push_a[2].z)(
                push_b[0].x
            )(push_b[0].y)(push_b[0].z)(push_b[1].x)(push_b[1].y)(push_b[1].z)(
                push_b[2].x
            )(push_b[2].y)(push_b[2].z)(friction)(round[0])(round[1])(impulse_scale)(
                surface[0]
            )(surface[1])(anchor)
        );
    }
}

/// `Frame::set_lane` names every field: a field added to `Frame` must be added there.
const _: () = assert!(std::mem::size_of::<Frame>() == 34 * std::mem::size_of::<Real>());

impl Sums<Lanes> {
    /// Lane `l` becomes `s`.
    #[inline(always)]
    fn set_lane(&mut self, l: usize, s: &Sums) {
        self.approach_velocity.0[l] = s.approach_velocity;
        self.total_normal.0[l] = s.total_normal;
        self.total_tangent[0].0[l] = s.total_tangent[0];
        self.total_tangent[1].0[l] = s.total_tangent[1];
    }
}

impl Sums<Lanes> {
    /// Lane `l` as scalar sums.
    fn lane(&self, l: usize) -> Sums {
        Sums {
            approach_velocity: self.approach_velocity.0[l],
            total_normal: self.total_normal.0[l],
            total_tangent: [self.total_tangent[0].0[l], self.total_tangent[1].0[l]],
        }
    }
}

impl Group {
    /// Makes `groups[k]` the group of `lanes` constraints from `first`, with `slots`
    /// slots from `slot0`: an old entry gets these four fields (`fill` writes the rest
    /// whole), a new one is pushed.
    fn plan(
        groups: &mut Vec<Group>,
        k: usize,
        (first, lanes): (usize, usize),
        (slot0, slots): (usize, usize),
    ) {
        match groups.get_mut(k) {
            Some(g) => (g.first, g.lanes, g.slot0, g.slots) = (first, lanes, slot0, slots),
            None => groups.push(Group {
                first,
                lanes,
                slot0,
                slots,
                ..Group::default()
            }),
        }
    }

    /// The lanes' bodies, moving masks and frames from the group's constraints `cs`.
    fn fill(&mut self, cs: &[ContactConstraint]) {
        // Unused lanes repeat lane 0's constraint, which they only read.
        let lane = |l: usize| &cs[if l < cs.len() { l } else { 0 }];
        let moves = |side: usize| {
            let moving = cs.iter().map(|c| [c.moves().0, c.moves().1][side]);
            moving
                .enumerate()
                .fold(0u32, |m, (l, on)| m | (u32::from(on) << l))
        };
        self.a = std::array::from_fn(|l| lane(l).bodies().0);
        self.b = std::array::from_fn(|l| lane(l).bodies().1);
        self.moves_a = moves(0);
        self.moves_b = moves(1);
        for l in 0..LANES {
            self.frame.set_lane(l, &lane(l).frame);
        }
        self.round = cs.iter().any(|c| c.has_round());
    }
}

impl Masks<Mask> {
    /// Lane `l` has a point, of a manifold whose bodies move as `moves` says.
    fn set_lane(&mut self, l: usize, moves: (bool, bool)) {
        self.active.set(l, true);
        self.apply.0.set(l, moves.0);
        self.apply.1.set(l, moves.1);
    }
}

impl Group {
    #[inline(always)]
    fn gather<S: StateAccess + ?Sized>(&self, states: &S) -> Pair<Lanes> {
        Pair {
            va: Lanes3::gather_by(&self.a, |i| states.state(i).v),
            wa: Lanes3::gather_by(&self.a, |i| states.state(i).w),
            vb: Lanes3::gather_by(&self.b, |i| states.state(i).v),
            wb: Lanes3::gather_by(&self.b, |i| states.state(i).w),
        }
    }

    /// Writes the velocities of the moving bodies back; static and kinematic states are
    /// never written (see `Pair::store`).
    #[inline(always)]
    fn scatter<S: StateAccess + ?Sized>(&self, s: &Pair<Lanes>, states: &mut S) {
        for l in 0..LANES {
            if self.moves_a & (1 << l) != 0 {
                states.set_velocity(self.a[l], s.va.lane(l), s.wa.lane(l));
            }
            if self.moves_b & (1 << l) != 0 {
                states.set_velocity(self.b[l], s.vb.lane(l), s.wb.lane(l));
            }
        }
    }

    #[inline(always)]
    fn motion<S: StateAccess + ?Sized>(&self, states: &S) -> Motion<Lanes> {
        Motion {
            dp: [
                Lanes3::gather_by(&self.a, |i| states.state(i).dp),
                Lanes3::gather_by(&self.b, |i| states.state(i).dp),
            ],
            dr: [rotation(states, &self.a), rotation(states, &self.b)],
            // Read by the round gaps alone (`Moved::tangent`), which a group without a round
            // side skips.
            turned: if self.round {
                [
                    Lanes3::gather_by(&self.a, |i| states.state(i).turned),
                    Lanes3::gather_by(&self.b, |i| states.state(i).turned),
                ]
            } else {
                [Lanes3::default(); 2]
            },
        }
    }

    /// `ContactConstraint::warm_start` per lane.
    #[inline(always)]
    fn warm_start<S: StateAccess + ?Sized>(
        &self,
        slots: &[Point<Lanes>],
        masks: &[Masks<Mask>],
        states: &mut S,
    ) {
        let mut s = self.gather(states);
        rows::warm_start(
            &self.frame,
            slots,
            #[inline(always)]
            |j| masks[j],
            &mut s,
        );
        self.scatter(&s, states);
    }

    /// `ContactConstraint::solve` per lane.
    #[inline(always)]
    fn solve<const BIAS: bool, S: StateAccess + ?Sized>(
        &self,
        (slots, masks, cold): GroupPoints<'_>,
        states: &mut S,
        pass: Pass<'_>,
    ) {
        let (mut s, motion) = (self.gather(states), self.motion(states));
        rows::solve::<Lanes, _, BIAS>(
            &self.frame,
            (slots, cold),
            #[inline(always)]
            |j| masks[j],
            (&mut s, &motion),
            pass,
        );
        self.scatter(&s, states);
    }
}

/// How many of `run` (constraints of one colour, in order) the next group takes: up to
/// [`LANES`], ending before the first manifold with angular rows (rolling resistance,
/// torsional friction), which the lanes do not carry; 0 if `run` starts with one, which
/// then stays on the scalar path. Without angular rows in the step (`angular` false) the
/// groups are the run's consecutive eights, as they always were.
#[inline]
fn group_size(run: &[Planned], angular: bool) -> usize {
    let most = run.len().min(LANES);
    if !angular {
        return most;
    }
    run[..most].iter().position(|c| c.2).unwrap_or(most)
}

/// The columns of each lane's ΔR.
#[inline(always)]
fn rotation<S: StateAccess + ?Sized>(states: &S, index: &[usize; LANES]) -> [Lanes3; 3] {
    [
        Lanes3::gather_by(index, |i| states.state(i).dr.x_axis),
        Lanes3::gather_by(index, |i| states.state(i).dr.y_axis),
        Lanes3::gather_by(index, |i| states.state(i).dr.z_axis),
    ]
}

wide_kernel! {
    /// Warm starts the contacts in `range`: the groups in lanes, the others one by one, all
    /// in the solver's order. No group straddles either end of `range`.
    pub(crate) fn warm_start(
        constraints: &[ContactConstraint],
        range: Range<usize>,
        points: &Points,
        states: &mut [BodyState],
        par: Par,
    ) => warm_start_lanes
}

#[inline(always)]
fn warm_start_lanes(
    constraints: &[ContactConstraint],
    range: Range<usize>,
    points: &Points,
    states: &mut [BodyState],
    par: Par,
) {
    let lanes = &points.lanes;
    let from = lanes.groups.partition_point(|g| g.first < range.start);
    let to = lanes.groups.partition_point(|g| g.first < range.end);
    let first_run = lanes.runs.partition_point(|r| r.start < from);
    let mut runs = lanes.runs[first_run..].iter().peekable();
    let (mut next, mut gi) = (range.start, from);
    while gi < to {
        let g = &lanes.groups[gi];
        for c in &constraints[next..g.first] {
            c.warm_start(points, states);
        }
        if let Some(run) = runs.next_if(|r| par.threads > 1 && r.start == gi) {
            // SAFETY: `add_run` checked the run: a moving body in one lane of it only.
            let shared = unsafe { SharedStates::new(states) };
            let (groups, base) = (&lanes.groups[run.clone()], g.slot0);
            let pieces = par.pieces(groups.len(), GROUPS_A_PIECE);
            warm_start_run(
                groups,
                (&lanes.slots[base..], &lanes.masks[base..], base),
                shared,
                (pieces, par.threads),
            );
            next = run_inner(constraints, groups, |c| c.warm_start(points, states));
            gi = run.end;
            continue;
        }
        let span = g.slot0..g.slot0 + g.slots;
        g.warm_start(&lanes.slots[span.clone()], &lanes.masks[span], states);
        next = g.first + g.lanes;
        gi += 1;
    }
    for c in &constraints[next..range.end] {
        c.warm_start(points, states);
    }
}

/// Calls `each` on the constraints of a run's colour that are not in its groups (they
/// commute with the groups: same colour), and returns where the run's constraints end.
#[inline(always)]
fn run_inner(
    constraints: &[ContactConstraint],
    groups: &[Group],
    mut each: impl FnMut(&ContactConstraint),
) -> usize {
    let mut at = groups[0].first + groups[0].lanes;
    for g in &groups[1..] {
        constraints[at..g.first].iter().for_each(&mut each);
        at = g.first + g.lanes;
    }
    at
}

/// The groups of a run warm-started in `pieces` pieces on the step's team; `slots`
/// and `masks` start at slot `base`.
fn warm_start_run(
    groups: &[Group],
    (slots, masks, base): (&[Point<Lanes>], &[Masks<Mask>], usize),
    states: SharedStates<'_>,
    (pieces, threads): (usize, usize),
) {
    let work = |i: usize| {
        let mut states = states;
        // Inlined into the wide kernel, or it is compiled without the kernel's
        // instruction set (see `groups_leaf`).
        groups_leaf(
            &groups[share(groups.len(), pieces, i)],
            #[inline(always)]
            |g: &Group| {
                let span = g.slot0 - base..g.slot0 - base + g.slots;
                g.warm_start(&slots[span.clone()], &masks[span], &mut states);
            },
        );
    };
    crate::team::pieces(threads, pieces, &work);
}

/// Piece `i` of `n` items cut into `pieces` nearly equal consecutive shares.
fn share(n: usize, pieces: usize, i: usize) -> Range<usize> {
    n * i / pieces..n * (i + 1) / pieces
}

/// The groups of a run solved in `pieces` pieces on the step's team; the slices start at
/// slot `base`, and each piece gets its groups' slots, which no other piece's overlap
/// (a run's groups hold consecutive slots, in order).
fn solve_run<const BIAS: bool>(
    groups: &[Group],
    ((slots, masks, cold), base): (GroupPoints<'_>, usize),
    states: SharedStates<'_>,
    (pass, pieces, threads): (Pass<'_>, usize, usize),
) {
    let (slots, cold) = (Parts::new(slots), Parts::new(cold));
    let work = |i: usize| {
        let mine = &groups[share(groups.len(), pieces, i)];
        let (Some(first), Some(last)) = (mine.first(), mine.last()) else {
            return;
        };
        let span = first.slot0 - base..last.slot0 + last.slots - base;
        let at = span.start;
        // SAFETY: the pieces' group shares are disjoint and their slots consecutive, so
        // the spans of two pieces never overlap.
        let (slots, cold) = unsafe { (slots.part(span.clone()), cold.part(span)) };
        let mut states = states;
        // Inlined into the wide kernel, or it is compiled without the kernel's
        // instruction set (see `groups_leaf`).
        groups_leaf(
            mine,
            #[inline(always)]
            |g: &Group| {
                let span = g.slot0 - base - at..g.slot0 - base - at + g.slots;
                let masks = &masks[g.slot0 - base..g.slot0 - base + g.slots];
                let points = (&mut slots[span.clone()], masks, &mut cold[span]);
                g.solve::<BIAS, _>(points, &mut states, pass);
            },
        );
    };
    crate::team::pieces(threads, pieces, &work);
}

wide_kernel! {
    /// `each` over a piece of a run, compiled for the lane mode's instruction set. The
    /// closure must be `#[inline(always)]`: a closure the compiler leaves out of line is
    /// compiled for the baseline instruction set, and the threaded passes ran in SSE2:
    /// two threads gained 5 % on Box3D's large pyramid, and now 2.0× (206 → 101 ms a
    /// step; the rain 10.2 → 7.5 ms).
    fn groups_leaf<F: FnMut(&Group)>(groups: &[Group], each: F) => each_group
}

/// A plain loop: `Iterator::for_each` was left out of line, and so compiled without the
/// kernel's instruction set.
#[inline(always)]
fn each_group<F: FnMut(&Group)>(groups: &[Group], mut each: F) {
    for g in groups {
        each(g);
    }
}

wide_kernel! {
    /// One solve or relax pass over the contacts in `range`: the groups in lanes, the others
    /// one by one, all in the solver's order. No group straddles either end of `range`.
    pub(crate) fn solve_pass(
        constraints: &[ContactConstraint],
        range: Range<usize>,
        points: &mut Points,
        states: &mut [BodyState],
        pass_par: (Pass<'_>, Par),
    ) => solve_pass_lanes
}

#[inline(always)]
fn solve_pass_lanes(
    constraints: &[ContactConstraint],
    range: Range<usize>,
    points: &mut Points,
    states: &mut [BodyState],
    (pass, par): (Pass<'_>, Par),
) {
    let groups = &points.lanes.groups;
    let from = groups.partition_point(|g| g.first < range.start);
    let to = groups.partition_point(|g| g.first < range.end);
    let runs = &points.lanes.runs;
    let mut run = runs.partition_point(|r| r.start < from);
    let (mut next, mut gi) = (range.start, from);
    while gi < to {
        let first = points.lanes.groups[gi].first;
        for c in &constraints[next..first] {
            c.solve(points, states, pass);
        }
        if par.threads > 1 && points.lanes.runs.get(run).is_some_and(|r| r.start == gi) {
            let span = points.lanes.runs[run].clone();
            run += 1;
            next = solve_run_in_place(constraints, span.clone(), points, states, (pass, par));
            gi = span.end;
            continue;
        }
        let ContactLanes {
            groups,
            slots,
            masks,
            cold,
            ..
        } = &mut points.lanes;
        let g = &groups[gi];
        let span = g.slot0..g.slot0 + g.slots;
        let slots = (
            &mut slots[span.clone()],
            &masks[span.clone()],
            &mut cold[span],
        );
        if pass.bias {
            g.solve::<true, _>(slots, states, pass);
        } else {
            g.solve::<false, _>(slots, states, pass);
        }
        next = g.first + g.lanes;
        gi += 1;
    }
    for c in &constraints[next..range.end] {
        c.solve(points, states, pass);
    }
}

/// Run `span` of groups split over the pool's threads, then the scalar constraints of its
/// colour among them; returns where the run's constraints end.
#[inline(always)]
fn solve_run_in_place(
    constraints: &[ContactConstraint],
    span: Range<usize>,
    points: &mut Points,
    states: &mut [BodyState],
    (pass, par): (Pass<'_>, Par),
) -> usize {
    let ContactLanes {
        groups,
        slots,
        masks,
        cold,
        ..
    } = &mut points.lanes;
    let groups = &groups[span.clone()];
    let base = groups[0].slot0;
    let pieces = par.pieces(groups.len(), GROUPS_A_PIECE);
    let slices = (
        (&mut slots[base..], &masks[base..], &mut cold[base..]),
        base,
    );
    // SAFETY: `add_run` checked the run: a moving body in one lane of it only.
    let shared = unsafe { SharedStates::new(states) };
    if pass.bias {
        solve_run::<true>(groups, slices, shared, (pass, pieces, par.threads));
    } else {
        solve_run::<false>(groups, slices, shared, (pass, pieces, par.threads));
    }
    let lanes_end = |p: &Points, g: usize| p.lanes.groups[g].first + p.lanes.groups[g].lanes;
    let mut at = lanes_end(points, span.start);
    for g in span.start + 1..span.end {
        for c in &constraints[at..points.lanes.groups[g].first] {
            c.solve(points, states, pass);
        }
        at = lanes_end(points, g);
    }
    at
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

    /// The pile with rolling resistance on every fourth body and torsional friction on
    /// every third: manifolds with angular rows (scalar only) among the lane groups'.
    fn rolling_pile() -> World {
        let w = pile();
        let mut out = world_on_ground();
        for (i, (_, b)) in w.bodies().enumerate().skip(1) {
            let def = BodyDef {
                position: b.position(),
                orientation: b.orientation(),
                restitution: b.restitution(),
                friction: b.friction(),
                mass: MassSpec::Mass(b.mass()),
                rolling_resistance: if i % 4 == 0 { 0.05 } else { 0.0 },
                torsional_friction: if i % 3 == 0 { 0.01 } else { 0.0 },
                ..Default::default()
            };
            out.create_body(&def, b.shape().clone()).unwrap();
        }
        out
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

    /// Round bodies rolling side by side, so that their contacts fill lane groups whose
    /// gaps have round parts (`rows::Moved::normal`, `rows::Moved::tangent`): balls,
    /// lying capsules, compounds of two balls, boxes among them (groups mixing round and
    /// flat manifolds), and balls resting on capsules (both sides round).
    fn rollers() -> World {
        let mut w = world_on_ground();
        let lying = Quat::from_rotation_x(std::f64::consts::FRAC_PI_2 as Real);
        for i in 0..24 {
            let (r, z) = (0.2 + 0.05 * (i % 4) as Real, 1.5 * i as Real);
            let v = 0.5 + 0.4 * i as Real;
            let (shape, orientation) = match i % 4 {
                0 => (Shape::sphere(r), Quat::IDENTITY),
                1 => (Shape::capsule(r, 0.3), lying),
                2 => (
                    Shape::Compound(
                        [-0.3, 0.3]
                            .map(|dz| CompoundChild {
                                shape: Shape::sphere(r),
                                position: Vec3::new(0.0, 0.0, dz),
                                orientation: Quat::IDENTITY,
                            })
                            .to_vec(),
                    ),
                    Quat::IDENTITY,
                ),
                _ => (Shape::cuboid(Vec3::splat(r)), Quat::IDENTITY),
            };
            let def = BodyDef {
                position: Vec3::new(0.0, r, z),
                orientation,
                linear_velocity: Vec3::new(v, 0.0, 0.0),
                angular_velocity: Vec3::new(0.0, 0.0, -v / r),
                ..Default::default()
            };
            w.create_body(&def, shape).unwrap();
            if i % 4 == 1 {
                let on_top = BodyDef {
                    position: Vec3::new(0.0, 2.0 * r + 0.1, z),
                    linear_velocity: Vec3::new(v, 0.0, 0.0),
                    ..Default::default()
                };
                w.create_body(&on_top, Shape::sphere(0.1)).unwrap();
            }
        }
        w
    }

    /// Boxes and balls created half inside each other, without restitution: their deep
    /// points are pushed apart at the end of the step (`overlap`), which reads the grouped
    /// points back from the lanes whole.
    fn overlapping() -> World {
        let mut w = world_on_ground();
        for i in 0..40 {
            let (x, z) = ((i % 5) as Real * 0.6, ((i / 5) % 4) as Real * 0.7);
            let def = BodyDef {
                position: Vec3::new(x, 0.35 + (i / 20) as Real * 0.5, z),
                orientation: Quat::from_rotation_y(0.2 * i as Real),
                ..Default::default()
            };
            let shape = match i % 4 {
                0 => Shape::sphere(0.4),
                _ => Shape::cuboid(Vec3::new(0.45, 0.35, 0.4)),
            };
            w.create_body(&def, shape).unwrap();
        }
        w
    }

    /// The state bits and every contact's impulses after a second of `scene`.
    fn run(mode: LaneMode, scene: fn() -> World) -> (u64, String) {
        with_lane_mode(mode, || {
            let mut w = scene();
            // The lane mode is this thread's: the steps must run on it.
            w.set_threads(1).unwrap();
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
        for scene in [pile, row, rolling_pile, rollers, overlapping] {
            let scalar = run(LaneMode::Scalar, scene);
            assert_eq!(run(LaneMode::Portable, scene), scalar);
            assert_eq!(run(LaneMode::Avx2, scene), scalar);
            assert_eq!(run(LaneMode::Avx512, scene), scalar);
        }
    }
}
