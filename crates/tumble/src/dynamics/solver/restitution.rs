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
use super::contact::{ContactConstraint, Points, TOLERANCE};
use crate::math::Real;

/// Passes allowed for the replay and for the final pass; a row of n bodies needs about n
/// for the replay and a few times n for the velocities to converge.
const MAX_PASSES: usize = 64;

/// Resolves the step's bounces; `start` holds the velocities of the step's start.
pub(crate) fn resolve_bounces(
    constraints: &[ContactConstraint],
    points: &mut Points,
    states: &mut [BodyState],
    start: &[BodyState],
    moves: &[bool],
    threshold: Real,
) {
    // The wide passes' impulses go back to the points first; this pass and the contacts'
    // impulses read them there.
    points.save_lanes(constraints);
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
        constraints[k].end_replay(points, &replayed);
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
    let mut reached = vec![false; moves.len()];
    let mut seeded = false;
    for c in constraints.iter().filter(|c| c.bounces(points, threshold)) {
        let (a, b) = c.bodies();
        reached[a] |= moves[a];
        reached[b] |= moves[b];
        seeded = true;
    }
    if !seeded {
        return Vec::new();
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
