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

use super::body::{BodySim, BodyState};
use super::softness::Softness;
use crate::contact_cache::Contact;
use crate::geometry::Pose;
use crate::math::{Real, Vec3};
use crate::narrow_phase::MAX_MANIFOLD_POINTS;

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

/// One Jacobian row at one point: angular parts and their images under I⁻¹.
#[derive(Debug, Clone, Copy, Default)]
struct Row {
    /// r_a × d and r_b × d.
    ang_a: Vec3,
    ang_b: Vec3,
    /// I_a⁻¹ (r_a × d) and I_b⁻¹ (r_b × d): the change of ω per unit impulse.
    turn_a: Vec3,
    turn_b: Vec3,
    mass: Real,
}

impl Row {
    fn new(d: Vec3, ra: Vec3, rb: Vec3, a: &BodySim, b: &BodySim) -> Row {
        let k = a.inverse_mass_along(d, ra) + b.inverse_mass_along(d, rb);
        let (ang_a, ang_b) = (ra.cross(d), rb.cross(d));
        Row {
            ang_a,
            ang_b,
            turn_a: a.inv_inertia * ang_a,
            turn_b: b.inv_inertia * ang_b,
            mass: if k > 0.0 { 1.0 / k } else { 0.0 },
        }
    }

    /// Relative velocity along the row's direction `d`.
    #[inline]
    fn velocity(&self, d: Vec3, a: &BodyState, b: &BodyState) -> Real {
        d.dot(b.v - a.v) + self.ang_b.dot(b.w) - self.ang_a.dot(a.w)
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

#[derive(Debug, Clone, Copy, Default)]
struct Point {
    /// Anchors from each centre of mass, world frame, at the start of the step.
    ra: Vec3,
    rb: Vec3,
    /// Separation at the start of the step.
    separation: Real,
    /// n · (r_b − r_a): with the bodies' motion since the step began it gives the current
    /// separation without rotating the anchors (see `solve`).
    lever: Real,
    normal: Row,
    tangent: [Row; 2],
    normal_impulse: Real,
    tangent_impulse: [Real; 2],
    /// Largest normal impulse of the step: restitution only acts where contact pushed.
    max_normal_impulse: Real,
    /// Normal velocity before the step, lowered to the velocity at the moment of impact
    /// if the step's gravity sped the approach up: the speed restitution reflects.
    approach_velocity: Real,
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
    total_normal: Real,
    total_tangent: [Real; 2],
    /// Friction anchors: how far apart, along each tangent, the two material points that
    /// touched when the contact began were at the step's start (zero for a new point).
    anchor_gap: [Real; 2],
    /// t · (r_b − r_a) per tangent, for the anchors' current gap (as `lever` for the normal).
    tangent_lever: [Real; 2],
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

/// One manifold as the solver works on it.
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
    points: [Point; MAX_MANIFOLD_POINTS],
    count: usize,
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
const ANCHOR_STIFFNESS: Real = 0.5;

/// Passes over a manifold's points when the bounce replay resolves one collision.
const REPLAY_ITERATIONS: usize = 4;
/// Speed changes below this fraction of the restitution threshold count as none.
pub(crate) const TOLERANCE: Real = 1e-4;

/// Two unit vectors completing `n` to a right-handed basis, chosen from n alone so the
/// result does not depend on history (Duff et al., "Building an orthonormal basis").
pub(crate) fn tangent_basis(n: Vec3) -> [Vec3; 2] {
    let sign = if n.z >= 0.0 { 1.0 } else { -1.0 };
    let a = -1.0 / (sign + n.z);
    let b = n.x * n.y * a;
    [
        Vec3::new(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x),
        Vec3::new(b, sign + n.y * n.y * a, -n.y),
    ]
}

/// The two bodies' states, mutably; `a != b` always (a body never touches itself).
fn pair(states: &mut [BodyState], a: usize, b: usize) -> Option<(&mut BodyState, &mut BodyState)> {
    let [x, y] = states.get_disjoint_mut([a, b]).ok()?;
    Some((x, y))
}

impl ContactConstraint {
    /// Anchors, Jacobians, effective masses and the warm-start impulses of a manifold.
    pub fn prepare(
        index: usize,
        contact: &Contact,
        pair: &PairData,
        sims: &[BodySim],
        states: &[BodyState],
    ) -> Self {
        let (a, b) = pair.bodies;
        let (friction, restitution) = pair.material;
        let poses = pair.poses;
        let m = &contact.manifold;
        let (sa, sb) = (&sims[a], &sims[b]);
        let normal = m.normal;
        let tangents = tangent_basis(normal);
        let dirs = [normal, tangents[0], tangents[1]];
        let mut c = ContactConstraint {
            a,
            b,
            contact: index,
            normal,
            tangents,
            push_a: dirs.map(|d| sa.linear_mask * d * sa.inv_mass),
            push_b: dirs.map(|d| sb.linear_mask * d * sb.inv_mass),
            moves: (sa.moves, sb.moves),
            friction,
            restitution,
            points: [Point::default(); MAX_MANIFOLD_POINTS],
            count: m.len(),
        };
        for (p, mp) in c.points.iter_mut().zip(m.points()) {
            let mid = (mp.point_a + mp.point_b) * 0.5;
            let (ra, rb) = (mid - sa.x, mid - sb.x);
            let normal_row = Row::new(normal, ra, rb, sa, sb);
            *p = Point {
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
                approach_velocity: normal_row.velocity(normal, &states[a], &states[b]),
                start_velocity: normal_row.velocity(normal, &states[a], &states[b]),
                replay_approach: 0.0,
                replay_target: 0.0,
                replay_impulse: 0.0,
                replay_bounced: false,
                bounce_target: None,
                bounce_impulse: 0.0,
                total_normal: 0.0,
                total_tangent: [0.0; 2],
                anchor_gap: if mp.anchored {
                    let gap =
                        poses.1.transform_point(mp.anchor_b) - poses.0.transform_point(mp.anchor_a);
                    [tangents[0].dot(gap), tangents[1].dot(gap)]
                } else {
                    [0.0; 2]
                },
                tangent_lever: [tangents[0].dot(rb - ra), tangents[1].dot(rb - ra)],
            };
        }
        c
    }

    /// Dense indices of the two bodies.
    pub fn bodies(&self) -> (usize, usize) {
        (self.a, self.b)
    }

    /// Applies the accumulated impulses again (each substep, as Box2D v3 does).
    pub fn warm_start(&self, states: &mut [BodyState]) {
        let Some((a, b)) = pair(states, self.a, self.b) else {
            return;
        };
        for p in &self.points[..self.count] {
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
    pub fn solve(&mut self, states: &mut [BodyState], rule: &BiasRule, bias: bool) {
        let Some((a, b)) = pair(states, self.a, self.b) else {
            return;
        };
        // Gauss–Seidel favours the point solved first; a symmetric stack would lean the
        // same way every pass and sway. The relax pass therefore walks the points in the
        // opposite order, so the bias of one pass cancels that of the other.
        let count = self.count;
        let order = move |k: usize| if bias { k } else { count - 1 - k };
        // Current separation of a point: s₀ + n·(Δp_b + ΔR_b r_b − r_b − Δp_a − ΔR_a r_a + r_a)
        // = s₀ + n·(Δp_b − Δp_a) + (ΔR_bᵀn)·r_b − (ΔR_aᵀn)·r_a − n·(r_b − r_a); the first
        // three factors are shared by the manifold's points.
        let n = self.normal;
        let moved = (
            n.dot(b.dp - a.dp),
            a.dr.transpose() * n,
            b.dr.transpose() * n,
        );
        for k in 0..count {
            self.solve_normal(order(k), a, b, rule, bias, moved);
        }
        // The anchors' gap along each tangent moves like the separation along n.
        let t = self.tangents;
        let slip = bias.then(|| {
            [0, 1].map(|k| {
                (
                    t[k].dot(b.dp - a.dp),
                    a.dr.transpose() * t[k],
                    b.dr.transpose() * t[k],
                )
            })
        });
        for k in 0..count {
            self.solve_friction(order(k), a, b, rule, slip);
        }
    }

    fn solve_normal(
        &mut self,
        i: usize,
        a: &mut BodyState,
        b: &mut BodyState,
        rule: &BiasRule,
        bias: bool,
        moved: (Real, Vec3, Vec3),
    ) {
        let n = self.normal;
        let p = &mut self.points[i];
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
        let vn = p.normal.velocity(n, a, b);
        let delta =
            -p.normal.mass * mass_scale * (vn + velocity_bias) - impulse_scale * p.normal_impulse;
        let total = (p.normal_impulse + delta).max(0.0);
        let applied = total - p.normal_impulse;
        if p.max_normal_impulse == 0.0 && applied > 0.0 {
            // The moment of impact: the velocity to reflect is this one, gravity of
            // the substeps so far included, not the one at the start of the step.
            p.approach_velocity = p.approach_velocity.min(vn);
        }
        p.normal_impulse = total;
        p.max_normal_impulse = p.max_normal_impulse.max(applied);
        p.normal
            .apply(applied, (self.push_a[0], self.push_b[0]), self.moves, a, b);
    }

    /// Coulomb friction at one point. In the biased pass a sticking point is also pulled
    /// back towards its anchors by the contact's soft spring, so that the slow creep a
    /// velocity-only friction leaves (a pile spreading by millimetres) is undone; the
    /// spring cannot exceed the cone, so it never holds a body that should slide.
    fn solve_friction(
        &mut self,
        i: usize,
        a: &mut BodyState,
        b: &mut BodyState,
        rule: &BiasRule,
        slip: Option<[(Real, Vec3, Vec3); 2]>,
    ) {
        let soft = rule.softness;
        let p = &mut self.points[i];
        if p.normal_impulse == 0.0 && p.tangent_impulse == [0.0; 2] {
            // A point that pushes nothing has a zero friction cone: nothing to do. Most
            // speculative points (neighbours side by side in a pile) are such.
            return;
        }
        let vt = [
            p.tangent[0].velocity(self.tangents[0], a, b),
            p.tangent[1].velocity(self.tangents[1], a, b),
        ];
        let want = match slip {
            Some(moved) => [0, 1].map(|k| {
                let (m, da, db) = moved[k];
                let gap = p.anchor_gap[k] + m + db.dot(p.rb) - da.dot(p.ra) - p.tangent_lever[k];
                let bias =
                    (ANCHOR_STIFFNESS * soft.bias_rate * gap).clamp(-rule.max_push, rule.max_push);
                p.tangent_impulse[k]
                    - p.tangent[k].mass * soft.mass_scale * (vt[k] + bias)
                    - soft.impulse_scale * p.tangent_impulse[k]
            }),
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
    pub fn bounces(&self, threshold: Real) -> bool {
        self.restitution > 0.0
            && self.points[..self.count]
                .iter()
                .any(|p| p.max_normal_impulse > 0.0 && p.approach_velocity < -threshold)
    }

    /// Whether any point pushed this step.
    pub fn touched(&self) -> bool {
        self.points[..self.count]
            .iter()
            .any(|p| p.max_normal_impulse > 0.0)
    }

    /// Starts the replay: points that hit faster than `threshold` before the solver
    /// acted remember how fast; the others learn it during the replay.
    pub fn begin_replay(&mut self, threshold: Real) {
        for p in &mut self.points[..self.count] {
            p.replay_impulse = 0.0;
            p.replay_bounced = false;
            p.bounce_target = None;
            p.replay_approach = if p.start_velocity < -threshold {
                p.approach_velocity
            } else {
                Real::INFINITY
            };
        }
    }

    /// One replay visit. If the manifold's touched points approach, that is a collision
    /// of the two bodies: resolved on its own (impulses from zero, the points together)
    /// so that each point leaves at −e times its approach, or merely stops approaching
    /// below `threshold`. Later visits see a new collision only if a later impact sets
    /// the pair approaching again. Returns the largest velocity change made.
    pub fn replay(&mut self, velocities: &mut [BodyState], threshold: Real) -> Real {
        let Some((a, b)) = pair(velocities, self.a, self.b) else {
            return 0.0;
        };
        let n = self.normal;
        let touched = |p: &&mut Point| p.max_normal_impulse > 0.0 && p.normal.mass > 0.0;
        let approaching = self.points[..self.count]
            .iter_mut()
            .filter(touched)
            .any(|p| p.normal.velocity(n, a, b) < -TOLERANCE * threshold);
        if !approaching {
            return 0.0;
        }
        for p in self.points[..self.count].iter_mut().filter(touched) {
            let approach = p.normal.velocity(n, a, b).min(p.replay_approach);
            p.replay_target = if approach < -threshold {
                p.replay_bounced |= self.restitution > 0.0;
                -self.restitution * approach
            } else {
                0.0
            };
            p.replay_impulse = 0.0;
        }
        let mut largest: Real = 0.0;
        for _ in 0..REPLAY_ITERATIONS {
            for p in self.points[..self.count].iter_mut().filter(touched) {
                // Only the first collision uses the step's measured approach.
                p.replay_approach = Real::INFINITY;
                let vn = p.normal.velocity(n, a, b);
                let total = (p.replay_impulse + p.normal.mass * (p.replay_target - vn)).max(0.0);
                let applied = total - p.replay_impulse;
                p.replay_impulse = total;
                largest = largest.max((applied / p.normal.mass).abs());
                p.normal
                    .apply(applied, (self.push_a[0], self.push_b[0]), self.moves, a, b);
            }
        }
        largest
    }

    /// Ends the replay: a point that bounced in it aims for the separation speed it
    /// reached there; the others only for not approaching.
    pub fn end_replay(&mut self, velocities: &[BodyState]) {
        let n = self.normal;
        let (a, b) = (&velocities[self.a], &velocities[self.b]);
        for p in &mut self.points[..self.count] {
            if p.replay_bounced {
                p.bounce_target = Some(p.normal.velocity(n, a, b).max(0.0));
            }
        }
    }

    /// One pass bringing the real velocities to the replay's outcome; returns the largest
    /// velocity change made. The impulse it adds is kept apart from the normal impulse:
    /// a bounce happens once, and warm-starting the next step with it would push the
    /// bodies apart again (measured: a cradle's first ball recoiling at 0.3 m/s).
    pub fn restitution(&mut self, states: &mut [BodyState]) -> Real {
        let Some((a, b)) = pair(states, self.a, self.b) else {
            return 0.0;
        };
        let n = self.normal;
        let mut largest: Real = 0.0;
        for p in self.points[..self.count]
            .iter_mut()
            .filter(|p| p.max_normal_impulse > 0.0 && p.normal.mass > 0.0)
        {
            let vn = p.normal.velocity(n, a, b);
            let target = p.bounce_target.unwrap_or(0.0);
            let before = p.normal_impulse + p.bounce_impulse;
            let applied = (before + p.normal.mass * (target - vn)).max(0.0) - before;
            p.bounce_impulse += applied;
            p.total_normal += applied;
            largest = largest.max((applied / p.normal.mass).abs());
            p.normal
                .apply(applied, (self.push_a[0], self.push_b[0]), self.moves, a, b);
        }
        largest
    }

    /// Adds the substep's impulses to the step's totals (each substep applies the
    /// accumulated impulse in full: warm start plus corrections).
    pub fn add_to_totals(&mut self) {
        for p in &mut self.points[..self.count] {
            p.total_normal += p.normal_impulse;
            p.total_tangent[0] += p.tangent_impulse[0];
            p.total_tangent[1] += p.tangent_impulse[1];
        }
    }

    /// Writes the impulses into the contact for next step's warm start and for reports.
    pub fn store_impulses(&self, contact: &mut Contact) {
        for (mp, p) in contact
            .manifold
            .points_mut()
            .iter_mut()
            .zip(&self.points[..self.count])
        {
            mp.normal_impulse = p.normal_impulse;
            mp.tangent_impulse = p.tangent_impulse;
            mp.total_normal_impulse = p.total_normal;
            let cone = self.friction * p.normal_impulse;
            let friction = (p.tangent_impulse[0].powi(2) + p.tangent_impulse[1].powi(2)).sqrt();
            mp.sliding = p.normal_impulse == 0.0 || friction >= 0.999 * cone;
            mp.total_tangent_impulse =
                self.tangents[0] * p.total_tangent[0] + self.tangents[1] * p.total_tangent[1];
        }
    }
}
