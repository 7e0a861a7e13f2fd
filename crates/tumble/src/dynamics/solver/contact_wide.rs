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
//! The groups keep their own copy of the points' hot data, slot by slot in lanes, built in
//! `prepare`; the scalar points get the impulses back before the end-of-step passes
//! ([`ContactLanes::write_back`]). Colour 63 and a colour's leftover single constraint
//! stay on the scalar path, in their place in the order.

use std::ops::Range;

use super::body::BodyState;
use super::contact::{ContactConstraint, Point, PointCold, Points, Row};
use super::lanes::{lane_mode, LaneMode, Lanes, Lanes3, Mask, LANES};
pub(crate) use super::rows::Pass;
use super::rows::{self, Frame, Masks, Motion, Pair, Sums};

/// A group's points in lanes, their masks and their sums, as a pass walks them.
type GroupPoints<'a> = (
    &'a mut [Point<Lanes>],
    &'a [Masks<Mask>],
    &'a mut [Sums<Lanes>],
);

/// Fewest constraints worth a group: a single one is solved faster by the scalar code.
const MIN_LANES: usize = 2;

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
    /// Whether a pass changed impulses that the scalar points do not have yet.
    unsaved: bool,
    /// An empty slot, made once: a `Point::default()` per group was compiled, in some
    /// builds, to a memset of its kilobyte each time (1.8 % of the pyramid's instructions).
    blank: Point<Lanes>,
}

impl ContactLanes {
    pub fn clear(&mut self) {
        self.groups.clear();
        self.slots.clear();
        self.masks.clear();
        self.cold.clear();
        self.unsaved = false;
    }

    /// Groups `constraints` (in the solver's order) and copies their points into slots;
    /// groups stay on one side of `split` (the passes of the heavy islands start there,
    /// see `Solver::passes`); `angular` says whether any constraint has angular rows,
    /// which stay scalar. No groups in scalar mode.
    pub fn build(
        &mut self,
        constraints: &[ContactConstraint],
        (split, angular): (usize, bool),
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
                let mut first = start;
                while colour < 63 && first < end {
                    let lanes = group_size(&constraints[first..end], angular);
                    if lanes >= MIN_LANES {
                        let cs = &constraints[first..first + lanes];
                        self.push_group(cs, first, hot, cold);
                    }
                    first += lanes.max(1);
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
            frame: Frame {
                normal: vec(&|c| c.normal()),
                tangents: [vec(&|c| c.tangents()[0]), vec(&|c| c.tangents()[1])],
                push_a: std::array::from_fn(|k| vec(&|c| c.pushes().0[k])),
                push_b: std::array::from_fn(|k| vec(&|c| c.pushes().1[k])),
                friction: Lanes::from_fn(|l| lane(l).friction()),
                round: [
                    Lanes::from_fn(|l| lane(l).round()[0]),
                    Lanes::from_fn(|l| lane(l).round()[1]),
                ],
                impulse_scale: Lanes::from_fn(|l| lane(l).frame.impulse_scale),
            },
            round: cs.iter().any(|c| c.has_round()),
            slot0,
            slots,
        };
        self.slots.resize(slot0 + slots, self.blank);
        self.masks.resize(slot0 + slots, Masks::default());
        self.cold.resize(slot0 + slots, Sums::default());
        for (l, c) in cs.iter().enumerate() {
            for (j, i) in c.range().enumerate() {
                self.slots[slot0 + j].set_lane(l, &hot[i]);
                self.masks[slot0 + j].set_lane(l, c.moves());
                self.cold[slot0 + j].set_lane(l, &cold[i].sums);
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
                    pc.sums.approach_velocity = sc.approach_velocity.0[l];
                    pc.sums.total_normal = sc.total_normal.0[l];
                    pc.sums.total_tangent = [sc.total_tangent[0].0[l], sc.total_tangent[1].0[l]];
                }
            }
        }
    }
}

impl Row<Lanes> {
    fn set_lane(&mut self, l: usize, row: &Row) {
        self.turn_a.set_lane(l, row.turn_a);
        self.turn_b.set_lane(l, row.turn_b);
        self.mass.0[l] = row.mass;
    }
}

impl Point<Lanes> {
    /// Makes lane `l` point `p`.
    fn set_lane(&mut self, l: usize, p: &Point) {
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

impl Sums<Lanes> {
    fn set_lane(&mut self, l: usize, c: &Sums) {
        self.approach_velocity.0[l] = c.approach_velocity;
        self.total_normal.0[l] = c.total_normal;
        self.total_tangent[0].0[l] = c.total_tangent[0];
        self.total_tangent[1].0[l] = c.total_tangent[1];
    }
}

impl Group {
    #[inline(always)]
    fn gather(&self, states: &[BodyState]) -> Pair<Lanes> {
        Pair {
            va: Lanes3::gather(states, &self.a, |s| s.v),
            wa: Lanes3::gather(states, &self.a, |s| s.w),
            vb: Lanes3::gather(states, &self.b, |s| s.v),
            wb: Lanes3::gather(states, &self.b, |s| s.w),
        }
    }

    /// Writes the velocities of the moving bodies back; static and kinematic states are
    /// never written (see `Pair::store`).
    #[inline(always)]
    fn scatter(&self, s: &Pair<Lanes>, states: &mut [BodyState]) {
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
    fn motion(&self, states: &[BodyState]) -> Motion<Lanes> {
        Motion {
            dp: [
                Lanes3::gather(states, &self.a, |s| s.dp),
                Lanes3::gather(states, &self.b, |s| s.dp),
            ],
            dr: [rotation(states, &self.a), rotation(states, &self.b)],
            // Read by the round gaps alone (`Moved::tangent`), which a group without a round
            // side skips.
            turned: if self.round {
                [
                    Lanes3::gather(states, &self.a, |s| s.turned),
                    Lanes3::gather(states, &self.b, |s| s.turned),
                ]
            } else {
                [Lanes3::default(); 2]
            },
        }
    }

    /// `ContactConstraint::warm_start` per lane.
    #[inline(always)]
    fn warm_start(&self, slots: &[Point<Lanes>], masks: &[Masks<Mask>], states: &mut [BodyState]) {
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
    fn solve<const BIAS: bool>(
        &self,
        (slots, masks, cold): GroupPoints<'_>,
        states: &mut [BodyState],
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
fn group_size(run: &[ContactConstraint], angular: bool) -> usize {
    let most = run.len().min(LANES);
    if !angular {
        return most;
    }
    run[..most]
        .iter()
        .position(ContactConstraint::has_angular)
        .unwrap_or(most)
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
            c.warm_start(points, states);
        }
        let span = g.slot0..g.slot0 + g.slots;
        g.warm_start(&lanes.slots[span.clone()], &lanes.masks[span], states);
        next = g.first + g.lanes;
    }
    for c in &constraints[next..] {
        c.warm_start(points, states);
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
    let groups = &points.lanes.groups;
    let from = groups.partition_point(|g| g.first < range.start);
    let to = groups.partition_point(|g| g.first < range.end);
    let mut next = range.start;
    for gi in from..to {
        let first = points.lanes.groups[gi].first;
        for c in &constraints[next..first] {
            c.solve(points, states, pass);
        }
        let ContactLanes {
            groups,
            slots,
            masks,
            cold,
            unsaved,
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
            g.solve::<true>(slots, states, pass);
        } else {
            g.solve::<false>(slots, states, pass);
        }
        *unsaved = true;
        next = g.first + g.lanes;
    }
    for c in &constraints[next..range.end] {
        c.solve(points, states, pass);
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
        for scene in [pile, row, rolling_pile, rollers] {
            let scalar = run(LaneMode::Scalar, scene);
            assert_eq!(run(LaneMode::Portable, scene), scalar);
            assert_eq!(run(LaneMode::Avx2, scene), scalar);
        }
    }
}
