//! Contact constraints: non-penetration along the normal with soft or Baumgarte position
//! correction, Coulomb friction with a circular cone (isotropic), and restitution.
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
//! within a step (the r × d terms, their images under I⁻¹, the effective masses) is
//! computed once in `prepare`; a pass then costs a few dot products per row.
//!
//! The solve, relax and warm-start passes run most manifolds eight at a time in lanes
//! (`super::contact_wide`), bit for bit as the scalar code here runs them one by one;
//! this scalar code serves the rest, the end-of-step bounces and the reports.

use super::body::{BodySim, BodyState};
use super::contact_wide::ContactLanes;
use super::softness::Softness;
use crate::collision::contact::Contact;
use crate::collision::geometry::Pose;
use crate::math::{orthonormal_basis, Real, Vec3};

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
}

/// One Jacobian row at one point: the images under I⁻¹ of its angular parts, and its
/// effective mass. The angular parts r × d themselves are recomputed where needed: two
/// cross products cost less than streaming 48 more bytes per row through every pass.
#[derive(Debug, Clone, Copy, Default)]
pub(super) struct Row {
    /// I_a⁻¹ (r_a × d) and I_b⁻¹ (r_b × d): the change of ω per unit impulse.
    pub turn_a: Vec3,
    pub turn_b: Vec3,
    pub mass: Real,
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

    /// Relative velocity along the row's direction `d`, at anchors `r` = (r_a, r_b).
    #[inline]
    fn velocity(&self, d: Vec3, r: (Vec3, Vec3), a: &BodyState, b: &BodyState) -> Real {
        d.dot(b.v - a.v) + r.1.cross(d).dot(b.w) - r.0.cross(d).dot(a.w)
    }

    /// Applies impulse `lambda` along the row; `push_a`, `push_b` are M⁻¹d of each body,
    /// `moves` says which of the two the solver moves. Static and kinematic states are
    /// never written: a store every contact with the ground makes would chain all those
    /// contacts through one memory location and serialise them.
    #[inline]
    fn apply(
        &self,
        lambda: Real,
        push: (Vec3, Vec3),
        moves: (bool, bool),
        a: &mut BodyState,
        b: &mut BodyState,
    ) {
        if moves.0 {
            a.v -= push.0 * lambda;
            a.w -= self.turn_a * lambda;
        }
        if moves.1 {
            b.v += push.1 * lambda;
            b.w += self.turn_b * lambda;
        }
    }
}

/// What the solver passes read and write at a contact point; the rest lives in
/// [`PointCold`]. Kept apart and packed in one list for all manifolds, so that a pass
/// streams only the bytes it uses: a pile's points overflow the L2 cache otherwise.
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct Point {
    /// Anchors from each centre of mass, world frame, at the start of the step.
    pub(super) ra: Vec3,
    pub(super) rb: Vec3,
    /// Separation at the start of the step.
    pub(super) separation: Real,
    /// n · (r_b − r_a): with the bodies' motion since the step began it gives the current
    /// separation without rotating the anchors (see `solve`).
    pub(super) lever: Real,
    pub(super) normal: Row,
    pub(super) tangent: [Row; 2],
    pub(super) normal_impulse: Real,
    pub(super) tangent_impulse: [Real; 2],
    /// Largest normal impulse of the step: restitution only acts where contact pushed.
    pub(super) max_normal_impulse: Real,
    /// Friction anchors: how far apart, along each tangent, the two material points that
    /// touched when the contact began were at the step's start (zero for a new point).
    pub(super) anchor_gap: [Real; 2],
    /// t · (r_b − r_a) per tangent, for the anchors' current gap (as `lever` for the normal).
    pub(super) tangent_lever: [Real; 2],
}

/// A contact point's data that the solve passes seldom touch: bounces and reports.
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct PointCold {
    /// Normal velocity before the step, lowered to the velocity at the moment of impact
    /// if the step's gravity sped the approach up: the speed restitution reflects.
    pub(super) approach_velocity: Real,
    /// Normal velocity before the step, as it was.
    start_velocity: Real,
    /// The bounce pass's replay of the step's impacts (see `super::restitution`): the
    /// fastest approach seen, the impulse accumulated, and the separation speed reached.
    replay_approach: Real,
    replay_target: Real,
    replay_impulse: Real,
    replay_bounced: bool,
    bounce_target: Option<Real>,
    /// Impulse the bounce pass added (or took back) at the end of the step.
    bounce_impulse: Real,
    /// Impulses summed over the step's substeps (for reporting).
    pub(super) total_normal: Real,
    pub(super) total_tangent: [Real; 2],
}

/// Every contact point of the step, manifold by manifold, hot and cold parts in step;
/// `lanes` holds the wide passes' copy of the grouped manifolds' points, whose impulses
/// are the current ones until [`Points::save_lanes`] copies them back.
#[derive(Debug, Default)]
pub(crate) struct Points {
    pub hot: Vec<Point>,
    pub cold: Vec<PointCold>,
    pub lanes: ContactLanes,
}

impl Points {
    pub fn clear(&mut self) {
        self.hot.clear();
        self.cold.clear();
        self.lanes.clear();
    }

    /// Groups the constraints (in the solver's order) for the wide passes; no group
    /// spans `split`, where the passes of the heavy islands start.
    pub fn group_lanes(&mut self, constraints: &[ContactConstraint], split: usize) {
        self.lanes.build(constraints, split, &self.hot, &self.cold);
    }

    /// Brings the grouped points' impulses and totals back from the lanes.
    pub fn save_lanes(&mut self, constraints: &[ContactConstraint]) {
        self.lanes
            .write_back(constraints, &mut self.hot, &mut self.cold);
    }
}

/// What the solver knows of a contact's two bodies when it prepares the constraint.
pub(crate) struct PairData {
    /// Dense indices of the bodies.
    pub bodies: (usize, usize),
    /// The pair's friction and restitution.
    pub material: (Real, Real),
    /// The bodies' frames at the start of the step (for the friction anchors).
    pub poses: (Pose, Pose),
}

/// One manifold as the solver works on it; its points are `count` entries of [`Points`]
/// from `first`.
#[derive(Debug, Clone)]
pub(crate) struct ContactConstraint {
    a: usize,
    b: usize,
    /// Index of the contact in the world's list, to store impulses back.
    pub contact: usize,
    normal: Vec3,
    tangents: [Vec3; 2],
    /// M⁻¹ d of each body for d = n, t₁, t₂.
    push_a: [Vec3; 3],
    push_b: [Vec3; 3],
    /// Whether the solver moves body a, body b.
    moves: (bool, bool),
    friction: Real,
    restitution: Real,
    first: usize,
    count: usize,
    /// Graph colour (see `Solver::colour_order`): constraints of one colour below 63
    /// share no moving body.
    colour: u32,
}

/// The friction impulse in the tangent plane: the impulse `want` that would stop the
/// sliding, if it lies inside the circular cone of radius `limit` (sticking); otherwise
/// `limit` against the sliding velocity `vt` (Coulomb: kinetic friction opposes the slip).
/// Scaling `want` back onto the cone instead would tilt the force towards the tangent
/// with the larger effective mass, making a box on a slope veer sideways and slide with
/// too little friction. Below `slip_speed` the slip direction is noise, and scaling is
/// the better guess (a sticking contact briefly over its cone in a soft pass).
fn friction_impulse(want: [Real; 2], vt: [Real; 2], limit: Real, slip_speed: Real) -> [Real; 2] {
    let want2 = want[0] * want[0] + want[1] * want[1];
    if want2 <= limit * limit {
        return want;
    }
    let speed = (vt[0] * vt[0] + vt[1] * vt[1]).sqrt();
    if speed > slip_speed {
        [-limit * vt[0] / speed, -limit * vt[1] / speed]
    } else {
        let scale = limit / want2.sqrt();
        [want[0] * scale, want[1] * scale]
    }
}

/// How hard anchors pull, as a fraction of the contact spring's rate. At the full rate a
/// 20-box tower swayed 6.5 cm (the tangential springs feed its tilt); at half it stands
/// within millimetres and the 385-box pyramid still holds to 0.05 mm over 10 s (2 mm
/// without anchors).
pub(super) const ANCHOR_STIFFNESS: Real = 0.5;

/// Passes over a manifold's points when the bounce replay resolves one collision.
const REPLAY_ITERATIONS: usize = 4;
/// Speed changes below this fraction of the restitution threshold count as none.
pub(crate) const TOLERANCE: Real = 1e-4;

/// The two bodies' states, mutably; `a != b` always (a body never touches itself).
fn pair(states: &mut [BodyState], a: usize, b: usize) -> Option<(&mut BodyState, &mut BodyState)> {
    let [x, y] = states.get_disjoint_mut([a, b]).ok()?;
    Some((x, y))
}

impl ContactConstraint {
    /// Anchors, Jacobians, effective masses and the warm-start impulses of a manifold;
    /// its points are appended to `points`.
    pub fn prepare(
        (index, colour): (usize, u32),
        contact: &Contact,
        pair: &PairData,
        (sims, states): (&[BodySim], &[BodyState]),
        points: &mut Points,
    ) -> Self {
        let (a, b) = pair.bodies;
        let (friction, restitution) = pair.material;
        let poses = pair.poses;
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
            normal,
            tangents,
            push_a: [push(sa, 0), push(sa, 1), push(sa, 2)],
            push_b: [push(sb, 0), push(sb, 1), push(sb, 2)],
            moves: (sa.moves, sb.moves),
            friction,
            restitution,
            first: points.hot.len(),
            count: m.len(),
            colour,
        };
        for mp in m.points() {
            let mid = (mp.point_a + mp.point_b) * 0.5;
            let (ra, rb) = (mid - sa.x, mid - sb.x);
            let normal_row = Row::new(normal, ra, rb, sa, sb);
            points.hot.push(Point {
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
                anchor_gap: if mp.anchored {
                    let gap =
                        poses.1.transform_point(mp.anchor_b) - poses.0.transform_point(mp.anchor_a);
                    [tangents[0].dot(gap), tangents[1].dot(gap)]
                } else {
                    [0.0; 2]
                },
                tangent_lever: [tangents[0].dot(rb - ra), tangents[1].dot(rb - ra)],
            });
            let start_velocity = normal_row.velocity(normal, (ra, rb), &states[a], &states[b]);
            points.cold.push(PointCold {
                approach_velocity: start_velocity,
                start_velocity,
                ..PointCold::default()
            });
        }
        c
    }

    /// Dense indices of the two bodies.
    pub fn bodies(&self) -> (usize, usize) {
        (self.a, self.b)
    }

    /// The manifold's points' indices in [`Points`].
    pub fn range(&self) -> std::ops::Range<usize> {
        self.first..self.first + self.count
    }

    /// Graph colour (see `Solver::colour_order`).
    pub fn colour(&self) -> u32 {
        self.colour
    }

    /// Whether the solver moves body a, body b.
    pub fn moves(&self) -> (bool, bool) {
        self.moves
    }

    pub fn normal(&self) -> Vec3 {
        self.normal
    }

    pub fn tangents(&self) -> [Vec3; 2] {
        self.tangents
    }

    /// M⁻¹ d of each body for d = n, t₁, t₂.
    pub fn pushes(&self) -> ([Vec3; 3], [Vec3; 3]) {
        (self.push_a, self.push_b)
    }

    pub fn friction(&self) -> Real {
        self.friction
    }

    /// Applies the accumulated impulses again (each substep, as Box2D v3 does).
    pub fn warm_start(&self, points: &[Point], states: &mut [BodyState]) {
        let Some((a, b)) = pair(states, self.a, self.b) else {
            return;
        };
        for p in &points[self.range()] {
            p.normal.apply(
                p.normal_impulse,
                (self.push_a[0], self.push_b[0]),
                self.moves,
                a,
                b,
            );
            p.tangent[0].apply(
                p.tangent_impulse[0],
                (self.push_a[1], self.push_b[1]),
                self.moves,
                a,
                b,
            );
            p.tangent[1].apply(
                p.tangent_impulse[1],
                (self.push_a[2], self.push_b[2]),
                self.moves,
                a,
                b,
            );
        }
    }

    /// One pass over the points. With `bias`, penetration is pushed out by the soft spring
    /// (or, for PGS, by Baumgarte); without, only velocities are made consistent (relax).
    /// Positive separations are speculative: the bodies may close the gap this substep,
    /// not more.
    pub fn solve(
        &self,
        points: &mut Points,
        states: &mut [BodyState],
        rule: &BiasRule,
        bias: bool,
        totals: bool,
    ) {
        let Some((a, b)) = pair(states, self.a, self.b) else {
            return;
        };
        let hot = &mut points.hot[self.range()];
        // Gauss–Seidel favours the point solved first; a symmetric stack would lean the
        // same way every pass and sway. The relax pass therefore walks the points in the
        // opposite order, so the bias of one pass cancels that of the other.
        let count = self.count;
        let order = move |k: usize| if bias { k } else { count - 1 - k };
        let moved = self.moved(a, b);
        for k in 0..count {
            let i = order(k);
            if let Some(vn) = self.solve_normal(&mut hot[i], a, b, rule, bias, moved) {
                // The moment of impact: the velocity to reflect is this one, gravity of
                // the substeps so far included, not the one at the start of the step.
                let cold = &mut points.cold[self.first + i];
                cold.approach_velocity = cold.approach_velocity.min(vn);
            }
        }
        let slip = bias.then(|| self.slip(a, b));
        for k in 0..count {
            self.solve_friction(&mut hot[order(k)], a, b, rule, slip);
        }
        if totals {
            ContactConstraint::add_to_totals(hot, &mut points.cold[self.range()]);
        }
    }

    /// Current separation of a point: s₀ + n·(Δp_b + ΔR_b r_b − r_b − Δp_a − ΔR_a r_a + r_a)
    /// = s₀ + n·(Δp_b − Δp_a) + (ΔR_bᵀn)·r_b − (ΔR_aᵀn)·r_a − n·(r_b − r_a); the first
    /// three factors are shared by the manifold's points.
    #[inline(always)]
    fn moved(&self, a: &BodyState, b: &BodyState) -> (Real, Vec3, Vec3) {
        let n = self.normal;
        (
            n.dot(b.dp - a.dp),
            a.dr.transpose() * n,
            b.dr.transpose() * n,
        )
    }

    /// The anchors' gap along each tangent moves like the separation along n.
    #[inline(always)]
    fn slip(&self, a: &BodyState, b: &BodyState) -> [(Real, Vec3, Vec3); 2] {
        let t = self.tangents;
        let slip = |k: usize| {
            (
                t[k].dot(b.dp - a.dp),
                a.dr.transpose() * t[k],
                b.dr.transpose() * t[k],
            )
        };
        [slip(0), slip(1)]
    }

    /// The normal row at one point; at the moment of impact (the first push of the step)
    /// it returns the normal velocity met, for the caller to record as the approach.
    #[inline(always)]
    fn solve_normal(
        &self,
        p: &mut Point,
        a: &mut BodyState,
        b: &mut BodyState,
        rule: &BiasRule,
        bias: bool,
        moved: (Real, Vec3, Vec3),
    ) -> Option<Real> {
        let n = self.normal;
        let s = p.separation + moved.0 + moved.2.dot(p.rb) - moved.1.dot(p.ra) - p.lever;
        let (velocity_bias, mass_scale, impulse_scale) = if s > 0.0 {
            (s * rule.inv_h, 1.0, 0.0)
        } else if bias {
            let soft = &rule.softness;
            let error = (s + rule.slop).min(0.0);
            (
                (soft.bias_rate * error).max(-rule.max_push),
                soft.mass_scale,
                soft.impulse_scale,
            )
        } else {
            (0.0, 1.0, 0.0)
        };
        let vn = p.normal.velocity(n, (p.ra, p.rb), a, b);
        let delta =
            -p.normal.mass * mass_scale * (vn + velocity_bias) - impulse_scale * p.normal_impulse;
        let total = (p.normal_impulse + delta).max(0.0);
        let applied = total - p.normal_impulse;
        let impact = (p.max_normal_impulse == 0.0 && applied > 0.0).then_some(vn);
        p.normal_impulse = total;
        p.max_normal_impulse = p.max_normal_impulse.max(applied);
        p.normal
            .apply(applied, (self.push_a[0], self.push_b[0]), self.moves, a, b);
        impact
    }

    /// Coulomb friction at one point. In the biased pass a sticking point is also pulled
    /// back towards its anchors by the contact's soft spring, so that the slow creep a
    /// velocity-only friction leaves (a pile spreading by millimetres) is undone; the
    /// spring cannot exceed the cone, so it never holds a body that should slide.
    #[inline(always)]
    fn solve_friction(
        &self,
        p: &mut Point,
        a: &mut BodyState,
        b: &mut BodyState,
        rule: &BiasRule,
        slip: Option<[(Real, Vec3, Vec3); 2]>,
    ) {
        let soft = rule.softness;
        if p.normal_impulse == 0.0 && p.tangent_impulse == [0.0; 2] {
            // A point that pushes nothing has a zero friction cone: nothing to do. Most
            // speculative points (neighbours side by side in a pile) are such.
            return;
        }
        let vt = [
            p.tangent[0].velocity(self.tangents[0], (p.ra, p.rb), a, b),
            p.tangent[1].velocity(self.tangents[1], (p.ra, p.rb), a, b),
        ];
        let want = match slip {
            Some(moved) => {
                let want = |k: usize| {
                    let (m, da, db) = moved[k];
                    let gap =
                        p.anchor_gap[k] + m + db.dot(p.rb) - da.dot(p.ra) - p.tangent_lever[k];
                    let bias = (ANCHOR_STIFFNESS * soft.bias_rate * gap)
                        .clamp(-rule.max_push, rule.max_push);
                    p.tangent_impulse[k]
                        - p.tangent[k].mass * soft.mass_scale * (vt[k] + bias)
                        - soft.impulse_scale * p.tangent_impulse[k]
                };
                // Written out rather than `[0, 1].map`, which the compiler left as a call.
                [want(0), want(1)]
            }
            None => [
                p.tangent_impulse[0] - p.tangent[0].mass * vt[0],
                p.tangent_impulse[1] - p.tangent[1].mass * vt[1],
            ],
        };
        let total = friction_impulse(want, vt, self.friction * p.normal_impulse, rule.slip_speed);
        for (k, total) in total.into_iter().enumerate() {
            p.tangent[k].apply(
                total - p.tangent_impulse[k],
                (self.push_a[k + 1], self.push_b[k + 1]),
                self.moves,
                a,
                b,
            );
            p.tangent_impulse[k] = total;
        }
    }

    /// Whether a point of this manifold was pushed this step after approaching faster
    /// than `threshold`, with a restitution to reflect it: a bounce to resolve.
    pub fn bounces(&self, points: &Points, threshold: Real) -> bool {
        self.restitution > 0.0
            && points.hot[self.range()]
                .iter()
                .zip(&points.cold[self.range()])
                .any(|(p, c)| p.max_normal_impulse > 0.0 && c.approach_velocity < -threshold)
    }

    /// Whether any point pushed this step.
    pub fn touched(&self, points: &Points) -> bool {
        points.hot[self.range()]
            .iter()
            .any(|p| p.max_normal_impulse > 0.0)
    }

    /// Starts the replay: points that hit faster than `threshold` before the solver
    /// acted remember how fast; the others learn it during the replay.
    pub fn begin_replay(&self, points: &mut Points, threshold: Real) {
        for c in &mut points.cold[self.range()] {
            c.replay_impulse = 0.0;
            c.replay_bounced = false;
            c.bounce_target = None;
            c.replay_approach = if c.start_velocity < -threshold {
                c.approach_velocity
            } else {
                Real::INFINITY
            };
        }
    }

    /// The touched points (pushed this step, with a body that can respond), hot and cold.
    fn touched_points<'p>(
        &self,
        points: &'p mut Points,
    ) -> impl Iterator<Item = (&'p mut Point, &'p mut PointCold)> {
        points.hot[self.range()]
            .iter_mut()
            .zip(&mut points.cold[self.range()])
            .filter(|(p, _)| p.max_normal_impulse > 0.0 && p.normal.mass > 0.0)
    }

    /// One replay visit. If the manifold's touched points approach, that is a collision
    /// of the two bodies: resolved on its own (impulses from zero, the points together)
    /// so that each point leaves at −e times its approach, or merely stops approaching
    /// below `threshold`. Later visits see a new collision only if a later impact sets
    /// the pair approaching again. Returns the largest velocity change made.
    pub fn replay(
        &self,
        points: &mut Points,
        velocities: &mut [BodyState],
        threshold: Real,
    ) -> Real {
        let Some((a, b)) = pair(velocities, self.a, self.b) else {
            return 0.0;
        };
        let n = self.normal;
        let approaching = self
            .touched_points(points)
            .any(|(p, _)| p.normal.velocity(n, (p.ra, p.rb), a, b) < -TOLERANCE * threshold);
        if !approaching {
            return 0.0;
        }
        for (p, c) in self.touched_points(points) {
            let approach = p
                .normal
                .velocity(n, (p.ra, p.rb), a, b)
                .min(c.replay_approach);
            c.replay_target = if approach < -threshold {
                c.replay_bounced |= self.restitution > 0.0;
                -self.restitution * approach
            } else {
                0.0
            };
            c.replay_impulse = 0.0;
        }
        let mut largest: Real = 0.0;
        for _ in 0..REPLAY_ITERATIONS {
            for (p, c) in self.touched_points(points) {
                // Only the first collision uses the step's measured approach.
                c.replay_approach = Real::INFINITY;
                let vn = p.normal.velocity(n, (p.ra, p.rb), a, b);
                let total = (c.replay_impulse + p.normal.mass * (c.replay_target - vn)).max(0.0);
                let applied = total - c.replay_impulse;
                c.replay_impulse = total;
                largest = largest.max((applied / p.normal.mass).abs());
                p.normal
                    .apply(applied, (self.push_a[0], self.push_b[0]), self.moves, a, b);
            }
        }
        largest
    }

    /// Ends the replay: a point that bounced in it aims for the separation speed it
    /// reached there; the others only for not approaching.
    pub fn end_replay(&self, points: &mut Points, velocities: &[BodyState]) {
        let n = self.normal;
        let (a, b) = (&velocities[self.a], &velocities[self.b]);
        for (p, c) in points.hot[self.range()]
            .iter()
            .zip(&mut points.cold[self.range()])
        {
            if c.replay_bounced {
                c.bounce_target = Some(p.normal.velocity(n, (p.ra, p.rb), a, b).max(0.0));
            }
        }
    }

    /// One pass bringing the real velocities to the replay's outcome; returns the largest
    /// velocity change made. The impulse it adds is kept apart from the normal impulse:
    /// a bounce happens once, and warm-starting the next step with it would push the
    /// bodies apart again (measured: a cradle's first ball recoiling at 0.3 m/s).
    pub fn restitution(&self, points: &mut Points, states: &mut [BodyState]) -> Real {
        let Some((a, b)) = pair(states, self.a, self.b) else {
            return 0.0;
        };
        let n = self.normal;
        let mut largest: Real = 0.0;
        for (p, c) in self.touched_points(points) {
            let vn = p.normal.velocity(n, (p.ra, p.rb), a, b);
            let target = c.bounce_target.unwrap_or(0.0);
            let before = p.normal_impulse + c.bounce_impulse;
            let applied = (before + p.normal.mass * (target - vn)).max(0.0) - before;
            c.bounce_impulse += applied;
            c.total_normal += applied;
            largest = largest.max((applied / p.normal.mass).abs());
            p.normal
                .apply(applied, (self.push_a[0], self.push_b[0]), self.moves, a, b);
        }
        largest
    }

    /// Adds the substep's impulses to the step's totals (each substep applies the
    /// accumulated impulse in full: warm start plus corrections).
    pub fn add_to_totals(hot: &[Point], cold: &mut [PointCold]) {
        for (p, c) in hot.iter().zip(cold) {
            c.total_normal += p.normal_impulse;
            c.total_tangent[0] += p.tangent_impulse[0];
            c.total_tangent[1] += p.tangent_impulse[1];
        }
    }

    /// Writes the impulses into the contact for next step's warm start and for reports.
    pub fn store_impulses(&self, points: &Points, contact: &mut Contact) {
        let hot = &points.hot[self.range()];
        let cold = &points.cold[self.range()];
        for (mp, (p, c)) in contact
            .manifold
            .points_mut()
            .iter_mut()
            .zip(hot.iter().zip(cold))
        {
            mp.normal_impulse = p.normal_impulse;
            mp.tangent_impulse = p.tangent_impulse;
            mp.total_normal_impulse = c.total_normal;
            let cone = self.friction * p.normal_impulse;
            let friction = (p.tangent_impulse[0].powi(2) + p.tangent_impulse[1].powi(2)).sqrt();
            mp.sliding = p.normal_impulse == 0.0 || friction >= 0.999 * cone;
            mp.total_tangent_impulse =
                self.tangents[0] * c.total_tangent[0] + self.tangents[1] * c.total_tangent[1];
        }
    }
}
