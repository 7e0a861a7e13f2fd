//! Bounces: restitution resolved as a chain of impacts.
//!
//! Box2D's restitution pass aims each bouncing point at v_n = −e·v_approach, with
//! v_approach measured before the step. That is right for one ball on the floor but not
//! for a Newton's cradle: the balls in the row touch at rest, so their contacts saw no
//! approach, and the struck row moves off together instead of passing the blow along
//! (measured: −0.72, 0.64, 0.64, 0.72, 0.72 m/s after a 2 m/s strike).
//!
//! So when something bounces, the step's impacts are first replayed on a copy of the
//! start-of-step velocities, as sequential binary collisions over the touching contacts
//! connected to the bounce (the propagation model of Guendelman et al. 2003): an impact
//! that sets a resting neighbour moving makes its contact approach, and that contact
//! then bounces in turn. The real velocities, which the soft step has already made
//! non-penetrating, are then brought to the separation speeds the replay reached.
//! Steps without a bounce skip all of this.

use super::body::BodyState;
use super::contact::{pair, ContactConstraint, Point, PointCold, Points};
use crate::math::{Real, Vec3};

/// Passes over a manifold's points when the bounce replay resolves one collision.
const REPLAY_ITERATIONS: usize = 4;
/// Speed changes below this fraction of the restitution threshold count as none.
pub(crate) const TOLERANCE: Real = 1e-4;

/// Passes allowed for the replay and for the final pass; a row of n bodies needs about n
/// for the replay and a few times n for the velocities to converge.
const MAX_PASSES: usize = 64;

/// Resolves the step's bounces; `start` holds the velocities of the step's start. The
/// grouped points must be back in the scalar points (`Points::save_lanes`).
pub(crate) fn resolve_bounces(
    constraints: &[ContactConstraint],
    points: &mut Points,
    states: &mut [BodyState],
    start: &[BodyState],
    moves: &[bool],
    threshold: Real,
) {
    let cluster = bounce_cluster(constraints, points, moves, threshold);
    if cluster.is_empty() {
        return;
    }
    let mut replayed = start.to_vec();
    for &k in &cluster {
        constraints[k].begin_replay(points, threshold);
    }
    for _ in 0..MAX_PASSES {
        let mut largest: Real = 0.0;
        for &k in &cluster {
            largest = largest.max(constraints[k].replay(points, &mut replayed, threshold));
        }
        if largest < TOLERANCE * threshold {
            break;
        }
    }
    for &k in &cluster {
        constraints[k].end_replay(points, &replayed, states);
    }
    for _ in 0..MAX_PASSES {
        let mut largest: Real = 0.0;
        for &k in &cluster {
            largest = largest.max(constraints[k].restitution(points, states));
        }
        if largest < TOLERANCE * threshold {
            break;
        }
    }
}

/// The touched constraints connected, through bodies the solver moves, to one that
/// bounces; in the solver's order. Empty when nothing bounces.
fn bounce_cluster(
    constraints: &[ContactConstraint],
    points: &Points,
    moves: &[bool],
    threshold: Real,
) -> Vec<usize> {
    let mut bouncing = constraints.iter().filter(|c| c.bounces(points, threshold));
    let Some(first) = bouncing.next() else {
        // Nothing bounces (the common step): no per-body scratch.
        return Vec::new();
    };
    let mut reached = vec![false; moves.len()];
    for c in std::iter::once(first).chain(bouncing) {
        let (a, b) = c.bodies();
        reached[a] |= moves[a];
        reached[b] |= moves[b];
    }
    // Spread through touched constraints until nothing changes; a pass per link of the
    // longest chain, each linear in the number of constraints.
    let touched: Vec<usize> = (0..constraints.len())
        .filter(|&k| constraints[k].touched(points))
        .collect();
    loop {
        let mut grew = false;
        for &k in &touched {
            let (a, b) = constraints[k].bodies();
            if reached[a] != reached[b] {
                let (a_new, b_new) = (!reached[a] && moves[a], !reached[b] && moves[b]);
                if a_new || b_new {
                    reached[a] |= moves[a];
                    reached[b] |= moves[b];
                    grew = true;
                }
            }
        }
        if !grew {
            break;
        }
    }
    touched
        .into_iter()
        .filter(|&k| {
            let (a, b) = constraints[k].bodies();
            reached[a] || reached[b]
        })
        .collect()
}

/// The normal velocity (negative: approaching) at which a point whose bodies fly freely
/// from the step's start reaches the surface: from v² = v0² − 2·fall·s0, with `v0` the
/// normal velocity and `s0` the gap at the start and `fall` the rate gravity changes the
/// normal velocity at; `None` for points touching already or never reached, and when
/// `fall` is not known (see `PairData::gravity`).
///
/// The solver's own record is the fastest approach it met in a substep, which is off by
/// up to a substep's kick of gravity either way: the speculative contact first acts a
/// substep before the bodies touch (a ball dropped 2 cm met 0.59 m/s there and hits at
/// 0.63 m/s, so it rebounded to 0.88 e² of its height), and a substep's whole kick comes
/// before the solve (a ball dropped 20 cm at dt 1/60 met 2.003 m/s and hits at 1.981 m/s:
/// 2.2 % too high).
pub(crate) fn impact_velocity(v0: Real, s0: Real, fall: Option<Real>) -> Option<Real> {
    let fall = fall?;
    let closing = v0 < 0.0 || fall < 0.0;
    let square = v0 * v0 - 2.0 * fall * s0;
    (s0 > 0.0 && closing && square > 0.0).then(|| -square.sqrt())
}

/// The approach speed below which a contact does not bounce (m/s): a resting body's
/// contact meets gravity's kick of one substep, |g|·h, as an approach every substep, and
/// must not bounce on it; twice that keeps resting stacks still, while a ball dropped
/// 0.35 mm at dt 1/60 with 4 substeps (|g|·h = 0.041 m/s) still bounces. Without gravity
/// a resting contact meets no approach, and `floor` (a small fraction of the length
/// unit per second) only keeps rounding from counting as one.
pub(crate) fn bounce_threshold(gravity: Vec3, h: Real, floor: Real) -> Real {
    (2.0 * gravity.length() * h).max(floor)
}

/// The separation speed that gives a bounce leaving at `speed` from the surface the same
/// height (the same energy against gravity's `fall`) when it leaves from `gap` instead:
/// u² = speed² + 2·fall·gap. The step ends with the bodies wherever the soft contact left
/// them, some tenths of a millimetre off the surface (0.46 mm above it for a ball dropped
/// 2 cm at dt 1/240), which for a small bounce is a large part of its height (e = 0.3
/// rebounded 29 % too high there).
fn launch_speed(speed: Real, gap: Real, fall: Real) -> Real {
    (speed * speed + 2.0 * fall * gap).max(0.0).sqrt()
}

impl PointCold {
    /// The approach the bounce reflects: the free flight's impact velocity where it is
    /// known, else the solver's record.
    fn approach(&self) -> Real {
        self.impact_velocity.unwrap_or(self.sums.approach_velocity)
    }
}

/// A manifold's part in the bounces.
impl ContactConstraint {
    /// Whether a point of this manifold was pushed this step after approaching faster
    /// than `threshold`, with a restitution to reflect it: a bounce to resolve.
    pub fn bounces(&self, points: &Points, threshold: Real) -> bool {
        self.restitution > 0.0
            && points.hot[self.range()]
                .iter()
                .zip(&points.cold[self.range()])
                .any(|(p, c)| p.max_normal_impulse > 0.0 && c.approach() < -threshold)
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
            c.replay_approach = if c.impact_velocity.unwrap_or(c.start_velocity) < -threshold {
                c.approach()
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
        let Some((a, b)) = pair(velocities, self.bodies().0, self.bodies().1) else {
            return 0.0;
        };
        let (n, push) = (
            self.frame.normal,
            (self.frame.push_a[0], self.frame.push_b[0]),
        );
        let approaching = self
            .touched_points(points)
            .any(|(p, _)| p.normal.velocity_at(n, p, a, b) < -TOLERANCE * threshold);
        if !approaching {
            return 0.0;
        }
        for (p, c) in self.touched_points(points) {
            let approach = p.normal.velocity_at(n, p, a, b).min(c.replay_approach);
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
                let vn = p.normal.velocity_at(n, p, a, b);
                let total = (c.replay_impulse + p.normal.mass * (c.replay_target - vn)).max(0.0);
                let applied = total - c.replay_impulse;
                c.replay_impulse = total;
                largest = largest.max((applied / p.normal.mass).abs());
                p.normal.apply_at(applied, push, self.moves, a, b);
            }
        }
        largest
    }

    /// Ends the replay: a point that bounced in it aims for the separation speed it
    /// reached there, given where the step left it (`states`' motion); the others only
    /// for not approaching.
    pub fn end_replay(&self, points: &mut Points, velocities: &[BodyState], states: &[BodyState]) {
        let n = self.frame.normal;
        let (i, j) = self.bodies();
        let (a, b) = (&velocities[i], &velocities[j]);
        for (p, c) in points.hot[self.range()]
            .iter()
            .zip(&mut points.cold[self.range()])
        {
            if c.replay_bounced {
                let speed = p.normal.velocity_at(n, p, a, b).max(0.0);
                let gap = p.separation_now(n, &states[i], &states[j]);
                c.bounce_target = Some(launch_speed(speed, gap, c.fall.unwrap_or(0.0)));
            }
        }
    }

    /// One pass bringing the real velocities to the replay's outcome; returns the largest
    /// velocity change made. The impulse it adds is kept apart from the normal impulse:
    /// a bounce happens once, and warm-starting the next step with it would push the
    /// bodies apart again (measured: a cradle's first ball recoiling at 0.3 m/s).
    pub fn restitution(&self, points: &mut Points, states: &mut [BodyState]) -> Real {
        let Some((a, b)) = pair(states, self.bodies().0, self.bodies().1) else {
            return 0.0;
        };
        let (n, push) = (
            self.frame.normal,
            (self.frame.push_a[0], self.frame.push_b[0]),
        );
        let mut largest: Real = 0.0;
        for (p, c) in self.touched_points(points) {
            let vn = p.normal.velocity_at(n, p, a, b);
            let target = c.bounce_target.unwrap_or(0.0);
            let before = p.normal_impulse + c.bounce_impulse;
            let applied = (before + p.normal.mass * (target - vn)).max(0.0) - before;
            c.bounce_impulse += applied;
            c.sums.total_normal += applied;
            largest = largest.max((applied / p.normal.mass).abs());
            p.normal.apply_at(applied, push, self.moves, a, b);
        }
        largest
    }
}
