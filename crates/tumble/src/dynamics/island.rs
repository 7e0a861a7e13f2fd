//! Islands and sleeping.
//!
//! Dynamic bodies joined by contacts or joints form islands (static and kinematic bodies do not join
//! them: they are shared by everything resting on them). An island whose every body has
//! been slower than the thresholds for `TIME_TO_SLEEP` falls asleep as a whole: its bodies
//! stop, are skipped by the integrator, the solver and the narrow phase, and keep their
//! contacts. It wakes as a whole when anything could change that: an awake or moving body
//! touches it, a body of it is edited, pushed or removed, a force on it is added or removed,
//! gravity changes, or its support moves or disappears.

use crate::collision::contact::Contact;
use crate::dynamics::body::{Body, BodyKind};
use crate::math::Real;

/// How long an island must stay below the thresholds before it sleeps (s).
pub const TIME_TO_SLEEP: Real = 0.5;

/// Angular speed below which a body counts as resting (rad/s): 2°/s.
pub const SLEEP_ANGULAR_SPEED: Real = 2.0 * crate::math::PI / 180.0;

/// Whether a body keeps bodies it touches awake: an awake dynamic body, or a kinematic one
/// that moves.
fn active(b: &Body) -> bool {
    match b.kind {
        BodyKind::Dynamic => b.awake,
        BodyKind::Kinematic => {
            b.velocity != crate::math::Vec3::ZERO || b.angular_velocity != crate::math::Vec3::ZERO
        }
        BodyKind::Static => false,
    }
}

/// Wakes every body of the island `tag` (and, for a body that is awake, nothing).
pub(crate) fn wake_island(bodies: &mut [Body], index: usize) {
    let Some(b) = bodies.get(index) else { return };
    if b.awake {
        return;
    }
    let tag = b.island_tag;
    for b in bodies
        .iter_mut()
        .filter(|b| !b.awake && b.island_tag == tag)
    {
        b.awake = true;
        b.sleep_time = 0.0;
    }
}

/// The pairs of dense body indices that contacts with points and joints connect.
fn links<'a>(
    contacts: &'a [Contact],
    joints: &'a [[Option<usize>; 2]],
) -> impl Iterator<Item = (usize, usize)> + 'a {
    let touching = contacts
        .iter()
        .filter(|c| !c.manifold.is_empty())
        .map(|c| (c.index_a as usize, c.index_b as usize));
    let joined = joints.iter().filter_map(|j| match *j {
        [Some(a), Some(b)] => Some((a, b)),
        _ => None,
    });
    touching.chain(joined)
}

/// Wakes sleeping islands that an active body touches or is joined to, until nothing
/// changes (an island woken this way may itself touch another sleeping one).
pub(crate) fn wake_touched(
    bodies: &mut [Body],
    contacts: &[Contact],
    joints: &[[Option<usize>; 2]],
) {
    loop {
        let mut changed = false;
        for (a, b) in links(contacts, joints) {
            for (x, y) in [(a, b), (b, a)] {
                if active(&bodies[x]) && bodies[y].kind == BodyKind::Dynamic && !bodies[y].awake {
                    wake_island(bodies, y);
                    changed = true;
                }
            }
        }
        if !changed {
            return;
        }
    }
}

/// Advances every awake body's rest timer and puts to sleep the islands that have all
/// rested long enough. `tag` numbers the islands put to sleep.
pub(crate) fn update_sleep(
    bodies: &mut [Body],
    contacts: &[Contact],
    joints: &[[Option<usize>; 2]],
    dt: Real,
    linear_speed: Real,
    tag: &mut u32,
) {
    for b in bodies
        .iter_mut()
        .filter(|b| b.kind == BodyKind::Dynamic && b.awake)
    {
        let resting =
            b.velocity.length() < linear_speed && b.angular_velocity.length() < SLEEP_ANGULAR_SPEED;
        b.sleep_time = if resting { b.sleep_time + dt } else { 0.0 };
    }
    let mut parent: Vec<usize> = (0..bodies.len()).collect();
    for (a, b) in links(contacts, joints) {
        if bodies[a].kind == BodyKind::Dynamic && bodies[b].kind == BodyKind::Dynamic {
            union(&mut parent, a, b);
        }
    }
    // The island's shortest rest decides; a kinematic body moving against it keeps it up.
    let mut island_rest = vec![Real::INFINITY; bodies.len()];
    for (i, b) in bodies
        .iter()
        .enumerate()
        .filter(|(_, b)| b.kind == BodyKind::Dynamic && b.awake)
    {
        let root = find(&mut parent, i);
        island_rest[root] = island_rest[root].min(b.sleep_time);
    }
    for (a, b) in links(contacts, joints) {
        for (x, y) in [(a, b), (b, a)] {
            if bodies[x].kind == BodyKind::Kinematic
                && active(&bodies[x])
                && bodies[y].kind == BodyKind::Dynamic
            {
                let root = find(&mut parent, y);
                island_rest[root] = 0.0;
            }
        }
    }
    let first_tag = *tag;
    for (i, b) in bodies.iter_mut().enumerate() {
        if b.kind != BodyKind::Dynamic || !b.awake {
            continue;
        }
        let root = find(&mut parent, i);
        if island_rest[root] >= TIME_TO_SLEEP {
            b.awake = false;
            b.island_tag = first_tag.wrapping_add(root as u32);
            b.velocity = crate::math::Vec3::ZERO;
            b.angular_momentum = crate::math::Vec3::ZERO;
            b.angular_velocity = crate::math::Vec3::ZERO;
        }
    }
    *tag = first_tag.wrapping_add(bodies.len() as u32);
}

/// The root of `i`'s set in the union–find forest `parent` (path halving).
pub(crate) fn find(parent: &mut [usize], mut i: usize) -> usize {
    while parent[i] != i {
        parent[i] = parent[parent[i]];
        i = parent[i];
    }
    i
}

/// Joins the sets of `a` and `b` in `parent`.
pub(crate) fn union(parent: &mut [usize], a: usize, b: usize) {
    let (ra, rb) = (find(parent, a), find(parent, b));
    // The smaller index becomes the root so islands are numbered the same every run.
    if ra < rb {
        parent[rb] = ra;
    } else {
        parent[ra] = rb;
    }
}
