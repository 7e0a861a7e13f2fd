//! Contact constraints: non-penetration along the normal with soft or Baumgarte position
//! correction, Coulomb friction with a circular cone (isotropic), restitution, and for
//! pairs that have them rolling resistance and torsional friction (`super::angular`).
//!
//! This module prepares a manifold's rows (`super::rows` gives their mathematics) and
//! runs them one manifold at a time. The solve, relax and warm-start passes run most
//! manifolds eight at a time in lanes (`super::contact_wide`), through the very same row
//! code; the scalar passes here serve the rest (among them every manifold with angular
//! rows, which the lanes do not carry), and the end-of-step bounces
//! (`super::restitution`) and the reports read the points here.

use std::borrow::{Borrow, BorrowMut};

use super::angular::AngularRows;
use super::body::{BodySim, BodyState};
use super::contact_wide::ContactLanes;
use super::restitution::impact_velocity;
use super::rows::{self, Frame, Masks, Motion, Pair, Pass, Sums};
pub(super) use super::rows::{Point, Row};
use super::softness::{LoadSpring, Softness};
use crate::collision::contact::Contact;
use crate::collision::geometry::Pose;
use crate::collision::narrow_phase::{ContactPoint, Manifold};
use crate::math::{orthonormal_basis, Real, Vec3};
use crate::threads::Par;

/// How position error turns into velocity in one substep.
#[derive(Debug, Clone, Copy)]
pub(crate) struct BiasRule {
    /// 1 / substep (1/s): a speculative gap s may close at s/h.
    pub inv_h: Real,
    /// Every contact's position correction: the soft-step spring, or for PGS the rigid
    /// row with Baumgarte's bias rate β/h.
    ///
    /// Unlike Box2D v3 (2D), contacts with immovable bodies are not made twice as stiff:
    /// in 3D a light box pressed between the ground and a heavy body then rings (measured:
    /// 0.1 m/s of jitter at 10:1), while the default spring of a quarter of the substep
    /// rate already holds a 20-box tower to millimetres.
    pub softness: Softness,
    /// Penetration tolerated without correction (m); zero for soft step.
    pub slop: Real,
    /// Fastest push-out speed (m/s).
    pub max_push: Real,
    /// Tangential speed above which a contact counts as sliding (m/s).
    pub slip_speed: Real,
    /// Whether the manifolds' own spring (`Frame::impulse_scale`, stiffened for their load
    /// in islands with a large mass ratio) is used rather than `softness`'s.
    pub stiffened: bool,
}

impl Row {
    /// Each side's I⁻¹(r × d) serves both the row and its effective mass,
    /// n·M⁻¹n + (r×n)·I⁻¹(r×n), so it is computed once. Bodies the solver does not move
    /// (zero inverse mass and inertia) are not skipped: a branch on which side is the
    /// ground mispredicts, and was measured slower than the arithmetic.
    #[inline]
    fn new(d: Vec3, ra: Vec3, rb: Vec3, a: &BodySim, b: &BodySim) -> Row {
        let side = |s: &BodySim, r: Vec3| {
            let ang = r.cross(d);
            let turn = s.inv_inertia * ang;
            (
                turn,
                s.inv_mass * (s.linear_mask * d).dot(d) + ang.dot(turn),
            )
        };
        let ((turn_a, ka), (turn_b, kb)) = (side(a, ra), side(b, rb));
        let k = ka + kb;
        Row {
            turn_a,
            turn_b,
            mass: if k > 0.0 { 1.0 / k } else { 0.0 },
        }
    }

    /// `Row::velocity` on two body states.
    #[inline]
    pub(super) fn velocity_at(&self, d: Vec3, p: &Point, a: &BodyState, b: &BodyState) -> Real {
        self.velocity(d, p.ra, p.rb, &Pair::load(a, b))
    }

    /// `Row::apply` on two body states, of which those that `moves` says are written.
    #[inline]
    pub(super) fn apply_at(
        &self,
        lambda: Real,
        push: (Vec3, Vec3),
        moves: (bool, bool),
        a: &mut BodyState,
        b: &mut BodyState,
    ) {
        let mut s = Pair::load(a, b);
        self.apply(lambda, push, moves, &mut s);
        s.store(moves, a, b);
    }
}

/// A contact point's data that the solve passes seldom touch: bounces and reports.
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct PointCold {
    /// What the solve passes write: the approach velocity and the step's totals.
    pub(super) sums: Sums,
    /// Normal velocity before the step, as it was.
    pub(super) start_velocity: Real,
    /// The normal velocity the point reaches at the surface if the bodies fly freely from
    /// the step's start: see `super::restitution::impact_velocity`.
    pub(super) impact_velocity: Option<Real>,
    /// The rate gravity changes the normal velocity at (m/s², negative: closing), where
    /// known.
    pub(super) fall: Option<Real>,
    /// The bounce pass's replay of the step's impacts (see `super::restitution`): the
    /// fastest approach seen, the impulse accumulated, and the separation speed reached.
    pub(super) replay_approach: Real,
    pub(super) replay_target: Real,
    pub(super) replay_impulse: Real,
    pub(super) replay_bounced: bool,
    /// Whether the point's friction anchors had rolled away (see [`rolled_away`]): it is
    /// reported sliding, and so re-anchored where it touches.
    pub(super) rolled: bool,
    pub(super) bounce_target: Option<Real>,
    /// Impulse the bounce pass added (or took back) at the end of the step.
    pub(super) bounce_impulse: Real,
}

/// The scalar passes reach a point's sums through its cold data, the lanes directly.
impl Borrow<Sums> for PointCold {
    fn borrow(&self) -> &Sums {
        &self.sums
    }
}

impl BorrowMut<Sums> for PointCold {
    #[inline(always)]
    fn borrow_mut(&mut self) -> &mut Sums {
        &mut self.sums
    }
}

/// Every contact point of the step, manifold by manifold, hot and cold parts in step;
/// `lanes` holds the grouped manifolds' points, which the preparation writes there alone
/// (their entries in `hot` are stale until [`Points::save_lanes`] copies them back whole,
/// and their sums in `cold` too; the rest of `cold` is theirs); `angular` the
/// rolling and twist rows of the manifolds that have them (see `super::angular`).
/// Where a manifold's points are written: its own entries of `Points::hot` and `cold`.
pub(crate) type PointsOut<'a> = (&'a mut [Point], &'a mut [PointCold]);

#[derive(Debug, Default)]
pub(crate) struct Points {
    pub hot: Vec<Point>,
    pub cold: Vec<PointCold>,
    pub lanes: ContactLanes,
    pub angular: Vec<AngularRows>,
}

impl Points {
    /// Forgets the lane groups and the angular rows; the points keep their lists, which
    /// `Solver::prepare` sizes and overwrites.
    pub fn clear_rows(&mut self) {
        self.lanes.clear();
        self.angular.clear();
    }

    /// Brings the grouped points back from the lanes, whole (see
    /// `ContactLanes::write_back`).
    pub fn save_lanes(&mut self, constraints: &[ContactConstraint], par: Par) {
        self.lanes
            .write_back(constraints, (&mut self.hot, &mut self.cold), par);
    }
}

/// What the solver knows of a contact's two bodies when it prepares the constraint.
pub(crate) struct PairData {
    /// Dense indices of the bodies.
    pub bodies: (usize, usize),
    /// The pair's friction and restitution.
    pub material: (Real, Real),
    /// The surface velocity friction drives body b's points to relative to a's (m/s,
    /// world frame; see `ContactMaterial::surface_velocity`).
    pub surface: Vec3,
    /// The pair's rolling resistance and torsional friction (`super::angular::combine`).
    pub angular: (Real, Real),
    /// The bodies' frames at the start of the step (for the friction anchors).
    pub poses: (Pose, Pose),
    /// How far each side's touching sub-shape is round about its core
    /// (`Shape::round_radius`): its turn does not move the contact along the normal.
    pub round: (Real, Real),
    /// The contact slop (m): friction anchors farther than this from their point have
    /// rolled away (see [`rolled_away`]).
    pub slop: Real,
    /// Each body's acceleration under gravity this step (zero for bodies the solver does
    /// not move), for the speed a falling point reaches at the surface; `None` when both
    /// move under gravity, as one may be resting on something else and not fall at all.
    pub gravity: Option<(Vec3, Vec3)>,
}

impl PairData {
    /// Whether the pair can roll on its contacts: a side is round, or it has rolling
    /// resistance or torsional friction (rows that stop it rolling). Only such pairs' friction
    /// anchors are checked for having rolled away (see [`rolled_away`]).
    fn rolls(&self) -> bool {
        self.round != (0.0, 0.0) || self.angular != (0.0, 0.0)
    }
}

/// One manifold as the solver works on it; its points are `count` entries of [`Points`]
/// from `first`.
#[derive(Debug, Clone, Default)]
pub(crate) struct ContactConstraint {
    a: usize,
    b: usize,
    /// Index of the contact in the world's list, to store impulses back.
    pub contact: usize,
    /// The directions, M⁻¹d of each body for them, and the friction.
    pub(super) frame: Frame,
    /// Whether the solver moves body a, body b.
    pub(super) moves: (bool, bool),
    pub(super) restitution: Real,
    first: usize,
    count: usize,
    /// The manifold's rolling and twist rows in `Points::angular`, if its pair has either.
    angular: Option<u32>,
}

/// How hard anchors pull, as a fraction of the contact spring's rate. At the full rate a
/// 20-box tower swayed 6.5 cm (the tangential springs feed its tilt); at half it stands
/// within millimetres and the 385-box pyramid still holds to 0.05 mm over 10 s (2 mm
/// without anchors).
pub(super) const ANCHOR_STIFFNESS: Real = 0.5;

/// The rolling and twist rows of manifold `m`, appended to `points`, if its pair has
/// either coefficient; their index.
fn angular_rows(
    m: &Manifold,
    pair: &PairData,
    bodies: (&BodySim, &BodySim),
    tangents: [Vec3; 2],
    angular: &mut Vec<AngularRows>,
) -> Option<u32> {
    let (rolling, twist) = pair.angular;
    if rolling > 0.0 || twist > 0.0 {
        let rows = AngularRows::new(m, bodies, tangents, pair.angular);
        angular.push(rows);
        Some(angular.len() as u32 - 1)
    } else {
        None
    }
}

/// Where the rows of point `mp` act: on the round side's own surface where one side of
/// the pair is round (`round`: each side's `Shape::round_radius`), else midway between the
/// two surfaces. A ball then rolls without slip where v = ω ρ, its radius, however deep it
/// sinks into its soft contact; at the midpoint the rolling radius was ρ + s/2, which
/// changed as the ball settled (s from 0 to −0.07 mm under its weight) and took 2e-6 m/s
/// from a rolling ball's speed over the 4 s after it (docs/integrators.md, "Rolling
/// contact"). Both anchors sit at the same world point, so friction's impulses still
/// balance in angular momentum too.
fn contact_point(mp: &ContactPoint, (a, b): (Real, Real)) -> Vec3 {
    match (a > 0.0, b > 0.0) {
        (true, false) => mp.point_a,
        (false, true) => mp.point_b,
        _ => (mp.point_a + mp.point_b) * 0.5,
    }
}

/// Each side's distance along the normal from its round core to where the rows act
/// (`contact_point`), for the gaps' round parts (`rows::Moved::normal`): its round radius
/// ρ where only one side is round; ρ plus half the mean separation for each where both are
/// (the rows act midway); 0 for a side that is not round.
fn round_arms(m: &Manifold, (a, b): (Real, Real)) -> [Real; 2] {
    if a > 0.0 && b > 0.0 {
        let count = m.len().max(1) as Real;
        let mean = m.points().iter().map(|p| p.separation).sum::<Real>() / count;
        [a + 0.5 * mean, b + 0.5 * mean]
    } else {
        [a, b]
    }
}

/// The two bodies' states, mutably; `a != b` always (a body never touches itself).
pub(super) fn pair(
    states: &mut [BodyState],
    a: usize,
    b: usize,
) -> Option<(&mut BodyState, &mut BodyState)> {
    let [x, y] = states.get_disjoint_mut([a, b]).ok()?;
    Some((x, y))
}

/// Whether a point's friction anchors `(wa, wb)` (world frame) rolled away: either lies
/// farther than the `slop` from where the bodies now touch (`at`), so the bodies turned on
/// each other (the material points in touch change as a ball rolls) rather than stuck.
/// Such a point's anchors are taken as this step's contact point (no gap), and it is
/// reported sliding so that the contact cache re-anchors it there for the next step. A
/// rolling contact never slides, and kept over a roll its anchors hold the point that
/// touched a while ago: their spring pulled the bodies back in the biased pass, the relax
/// pass took the velocity out again, and the position lagged (a 0.3 m ball rolling at
/// 0.5 m/s moved at 0.465 m/s at dt 1/60 s while its velocity said 0.5; one stopped by
/// rolling resistance slid back towards its old anchor at 3 cm/s). A body that sticks
/// keeps its anchors: they stay within the slop (of their creep) unless it slides, and
/// then friction's cone renews them anyway.
fn rolled_away((wa, wb): (Vec3, Vec3), at: Vec3, slop: Real) -> bool {
    let far = |w: Vec3| (w - at).length_squared() > slop * slop;
    far(wa) || far(wb)
}

impl ContactConstraint {
    /// Anchors, Jacobians, effective masses and the warm-start impulses of a manifold;
    /// its points are appended to `points`.
    pub fn prepare(
        index: usize,
        contact: &Contact,
        pair: &PairData,
        (sims, states): (&[BodySim], &[BodyState]),
        (first, out, angular): (usize, PointsOut<'_>, &mut Vec<AngularRows>),
    ) -> Self {
        let (a, b) = pair.bodies;
        let (friction, restitution) = pair.material;
        let m = &contact.manifold;
        let (sa, sb) = (&sims[a], &sims[b]);
        let normal = m.normal;
        let tangents = orthonormal_basis(normal);
        let dirs = [normal, tangents[0], tangents[1]];
        let push = |s: &BodySim, k: usize| s.linear_mask * dirs[k] * s.inv_mass;
        let c = ContactConstraint {
            a,
            b,
            contact: index,
            frame: Frame {
                normal,
                tangents,
                push_a: [push(sa, 0), push(sa, 1), push(sa, 2)],
                push_b: [push(sb, 0), push(sb, 1), push(sb, 2)],
                friction,
                round: round_arms(m, pair.round),
                // Read only by stiffened passes, after `stiffen` has set it.
                impulse_scale: 0.0,
                // Exact zeros without a surface velocity (t·0 may be −0, and x − (−0)
                // turns a −0 into +0): x − 0 is x, bit for bit.
                surface: if pair.surface == Vec3::ZERO {
                    [0.0; 2]
                } else {
                    tangents.map(|t| t.dot(pair.surface))
                },
                anchor: if pair.surface == Vec3::ZERO { 1.0 } else { 0.0 },
            },
            moves: (sa.moves, sb.moves),
            restitution,
            first,
            count: m.len(),
            angular: angular_rows(m, pair, (sa, sb), tangents, angular),
        };
        // Two builds of one loop: with the test for rolled anchors folded into the
        // `false` one, every box contact cost 40 more instructions (measured on the
        // pyramid, where it never renews anything).
        if pair.rolls() {
            c.add_points::<true>(contact, pair, (sims, states), out);
        } else {
            c.add_points::<false>(contact, pair, (sims, states), out);
        }
        c
    }

    /// Stiffens the manifold's spring for the load its points (`added`, as prepared)
    /// carried last step (an island with a large mass ratio: see `mass_ratio.rs`).
    pub fn stiffen(&mut self, spring: &LoadSpring, added: &[Point]) {
        let load = added.iter().map(|p| p.normal_impulse).sum();
        let mass = added.iter().map(|p| p.normal.mass).sum();
        self.frame.impulse_scale = spring.impulse_scale(load, mass);
    }

    /// Scales the manifold's warm-start impulses by `k`: last step's were per substep of
    /// another length (a tall stack's finer substeps, see `stacks.rs`), and an impulse per
    /// substep goes as the substep's length.
    /// Its points are `hot` (as prepared), its rolling and twist rows in `angular`.
    pub fn rescale_warm_start(&self, (hot, angular): (&mut [Point], &mut [AngularRows]), k: Real) {
        for p in hot {
            p.normal_impulse *= k;
            p.tangent_impulse = p.tangent_impulse.map(|t| t * k);
        }
        if let Some(i) = self.angular {
            angular[i as usize].rescale(k);
        }
    }

    /// Writes the manifold's points into `out` (as many as it has): anchors, rows, warm
    /// starts. `ROLLS`:
    /// the pair rolls (`PairData::rolls`), and its points' anchors are renewed where they
    /// rolled away (see [`rolled_away`]).
    fn add_points<const ROLLS: bool>(
        &self,
        contact: &Contact,
        pair: &PairData,
        (sims, states): (&[BodySim], &[BodyState]),
        (hot, cold): PointsOut<'_>,
    ) {
        let (a, b) = pair.bodies;
        let (sa, sb) = (&sims[a], &sims[b]);
        let (normal, tangents, poses) = (self.frame.normal, self.frame.tangents, pair.poses);
        let outs = hot.iter_mut().zip(cold);
        for (mp, (hot, cold)) in contact.manifold.points().iter().zip(outs) {
            let at = contact_point(mp, pair.round);
            let anchors = mp.anchored.then(|| {
                (
                    poses.0.transform_point(mp.anchor_a),
                    poses.1.transform_point(mp.anchor_b),
                )
            });
            let rolled = ROLLS && anchors.is_some_and(|w| rolled_away(w, at, pair.slop));
            let (ra, rb) = (at - sa.x, at - sb.x);
            let normal_row = Row::new(normal, ra, rb, sa, sb);
            *hot = Point {
                ra,
                rb,
                separation: mp.separation,
                lever: normal.dot(rb - ra),
                normal: normal_row,
                tangent: [
                    Row::new(tangents[0], ra, rb, sa, sb),
                    Row::new(tangents[1], ra, rb, sa, sb),
                ],
                normal_impulse: mp.normal_impulse,
                // The basis depends on the normal alone, so last step's tangent impulses
                // still point the same way.
                tangent_impulse: mp.tangent_impulse,
                max_normal_impulse: 0.0,
                anchor_gap: match anchors {
                    Some((wa, wb)) if !rolled => {
                        let gap = wb - wa;
                        [tangents[0].dot(gap), tangents[1].dot(gap)]
                    }
                    _ => [0.0; 2],
                },
                tangent_lever: [tangents[0].dot(rb - ra), tangents[1].dot(rb - ra)],
            };
            let start_velocity = Pair::load(&states[a], &states[b]);
            let start_velocity = normal_row.velocity(normal, ra, rb, &start_velocity);
            let fall = pair.gravity.map(|(ga, gb)| normal.dot(gb - ga));
            *cold = PointCold {
                sums: Sums {
                    approach_velocity: start_velocity,
                    ..Sums::default()
                },
                start_velocity,
                impact_velocity: impact_velocity(start_velocity, mp.separation, fall),
                fall,
                rolled,
                ..PointCold::default()
            };
        }
    }

    /// Dense indices of the two bodies.
    pub fn bodies(&self) -> (usize, usize) {
        (self.a, self.b)
    }

    /// The manifold's points' indices in [`Points`].
    pub fn range(&self) -> std::ops::Range<usize> {
        self.first..self.first + self.count
    }

    /// Whether the solver moves body a, body b.
    pub fn moves(&self) -> (bool, bool) {
        self.moves
    }

    /// Whether a side of the manifold is round.
    pub fn has_round(&self) -> bool {
        self.frame.round[0] + self.frame.round[1] > 0.0
    }

    /// The masks of the manifold's points: one lane, always active, reaching the bodies
    /// that move.
    #[inline(always)]
    fn masks(&self) -> impl Fn(usize) -> Masks<bool> {
        let m = Masks {
            active: true,
            apply: self.moves,
        };
        #[inline(always)]
        move |_| m
    }

    /// Applies the accumulated impulses again (each substep, as Box2D v3 does).
    pub fn warm_start(&self, points: &Points, states: &mut [BodyState]) {
        let Some((a, b)) = pair(states, self.a, self.b) else {
            return;
        };
        let mut s = Pair::load(a, b);
        rows::warm_start(&self.frame, &points.hot[self.range()], self.masks(), &mut s);
        if let Some(k) = self.angular {
            points.angular[k as usize].warm_start(&mut s);
        }
        s.store(self.moves, a, b);
    }

    /// One solve (`pass.bias`) or relax pass over the points (see `rows::solve`).
    pub fn solve(&self, points: &mut Points, states: &mut [BodyState], pass: Pass<'_>) {
        let Some((a, b)) = pair(states, self.a, self.b) else {
            return;
        };
        let (mut s, motion) = (Pair::load(a, b), Motion::of(a, b));
        let hot = &mut points.hot[self.range()];
        let cold = &mut points.cold[self.range()];
        let (f, masks) = (&self.frame, self.masks());
        if pass.bias {
            rows::solve::<Real, _, true>(f, (hot, cold), masks, (&mut s, &motion), pass);
        } else {
            rows::solve::<Real, _, false>(f, (hot, cold), masks, (&mut s, &motion), pass);
        }
        if let Some(k) = self.angular {
            points.angular[k as usize].solve(hot, &mut s);
        }
        s.store(self.moves, a, b);
    }

    /// Adds the substep's impulses to the step's totals (each substep applies the
    /// accumulated impulse in full: warm start plus corrections).
    pub fn add_to_totals(hot: &[Point], cold: &mut [PointCold]) {
        rows::add_totals(hot, cold);
    }

    /// Writes the impulses into the contact for next step's warm start and for reports;
    /// `k` is the constraint's index (a grouped one's impulses are in its lane).
    pub fn store_impulses(&self, k: usize, points: &Points, contact: &mut Contact) {
        let first = self.first;
        let points_mut = contact.manifold.points_mut().iter_mut();
        for (j, mp) in points_mut.enumerate() {
            let (p, c) = (&points.hot[first + j], &points.cold[first + j]);
            let (normal, tangent, sums) =
                points
                    .lanes
                    .solved(k, j)
                    .unwrap_or((p.normal_impulse, p.tangent_impulse, c.sums));
            mp.normal_impulse = normal;
            mp.tangent_impulse = tangent;
            mp.total_normal_impulse = sums.total_normal;
            let cone = self.frame.friction * normal;
            let friction = (tangent[0].powi(2) + tangent[1].powi(2)).sqrt();
            mp.sliding = normal == 0.0 || friction >= 0.999 * cone || c.rolled;
            let t = self.frame.tangents;
            mp.total_tangent_impulse = t[0] * sums.total_tangent[0] + t[1] * sums.total_tangent[1];
        }
        match self.angular {
            Some(k) => points.angular[k as usize].store(&mut contact.manifold),
            None => contact.manifold.angular_impulse = Vec3::ZERO,
        }
    }
}
