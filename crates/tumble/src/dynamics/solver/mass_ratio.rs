//! Islands with a large mass ratio get stiffer contacts and four to sixteen times the passes.
//!
//! Gauss–Seidel hands a heavy body's weight down through a light one only in proportion to
//! their mass ratio per pass, so at the default of one pass per substep a 1000 kg box on a
//! 1 kg box sank 30 cm into it within a second, tipped it and slid off at 11 m/s. Two
//! passes held it, but the soft contact under the light body is a spring of the light
//! body's effective mass, so the pair sank by the mass ratio times a lone box's depth (7 cm
//! in each contact at 1:1000) and rocked at 3.5 cm/s with three passes; an 800 kg slab on
//! four 1 kg cubes (200:1 on each) sank 2.8 cm. Such islands' contacts are therefore
//! stiffened for the load they carry (`softness::LoadSpring`, at most four times), which
//! takes twice the passes again to stay still: at 1:1000 the pair now rests 3.5 cm deep and moves at
//! 3 mm/s, the slab sinks 6.9 mm, a 1:100 pair 3.5 mm (14 mm before) and is still. Their
//! joints' spring is four times as stiff too (`Softness::stiffened`): a chain of 1 kg
//! links holding 100 kg stretched 2.3 cm per joint at the defaults, now 7.4 mm. Joints
//! that lock rotation in an island with a hub (below) are the exception (see
//! `Solver::passes`): stiffened, they rang even with the extra passes.
//! Stiffening and passes only the islands that need them keeps every other scene's cost
//! and results as they were.
//!
//! A ratio need not sit across one pair. A body joined to several others carries their
//! sum: PyBullet's minitaur hangs eight motors of 3 kg·m² each on a 3 kg·m² chassis by
//! hinges, every pair 1:1, and at one pass the chassis's share of each hinge's angular
//! rows was handed back and forth until it rang up from rounding to 400 rad/s within
//! 0.6 s (59 J to 0.8 MJ in a second of falling onto the ground at dt = 0.01). Eight such
//! children of equal mass and inertia is the least that did (seven grew by 1.7× in 0.6 s,
//! six held); four passes held eight. So a body whose joined partners' masses, or for
//! joints that lock rotation their moments of inertia, sum to [`HUB_RATIO`] times its own,
//! shared among several, makes its island heavy as well, with passes that grow with the
//! load ([`hub_passes`]).

use super::body::BodySim;
use crate::dynamics::island::{find, union};
use crate::math::Real;

/// Mass ratio across a contact or joint, between two bodies the solver moves, from which
/// their island is solved with stiffened contacts and four times the passes. At 1:10 one
/// pass is still at rest to 0.4 mm/s; at 1:30 it rings (see the module comment).
pub(crate) const HEAVY_RATIO: Real = 20.0;

/// Mass ratio from which such islands get six times the passes: a 1:1000 pair (unstiffened)
/// rocked at 14 cm/s a second after landing with twice the passes, 3.5 cm/s with three;
/// stiffened, at 4.4 mm/s with nine and 3.1 mm/s with six (and 0.19 m/s with three).
pub(crate) const VERY_HEAVY_RATIO: Real = 200.0;

/// Sum over a body's joined partners of their mass over its own (or, across joints that
/// lock rotation, of their mean moment of inertia over its own) from which its island is
/// heavy (see the module comment): the joint grid's bodies, with four equal partners,
/// stay at 4.
pub(crate) const HUB_RATIO: Real = 6.0;

/// The most passes a hub's island gets, as a multiple of the world's.
pub(crate) const HUB_PASSES: u32 = 16;

/// The passes a hub's island gets for the largest load (see [`HUB_RATIO`]): √load + 1,
/// from four (at a load of 6 to 9) to [`HUB_PASSES`]. Measured in zero gravity from a
/// small spin (tests/engine/joints.rs): eight partners of the chassis's inertia held with 4;
/// twelve of ten times it (a load of 120) still gained 1 % at 8 passes and held at 12,
/// as did six of a hundred times; sixteen of ten times (160) rang at 12 and held at 14.
/// Twenty-four of a hundred times (800) rang even at 16: more passes are not a cure
/// without end, and such a hub needs the joints solved together (not built).
/// Saturating: a load past 2^64 (a 1e15 kg body on a 1e-12 kg one, or an infinite mass
/// ratio) overflowed the `+ 1` in a debug build and wrapped to the fewest passes in a
/// release build.
fn hub_passes(load: Real) -> u32 {
    (load.sqrt().ceil() as u32)
        .saturating_add(1)
        .clamp(4, HUB_PASSES)
}

/// A joint between two bodies of the step, as the hub search sees it.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Joined {
    pub a: usize,
    pub b: usize,
    /// Whether the joint locks their relative rotation in some direction.
    pub locks_rotation: bool,
}

/// Mean principal moment of inertia (kg·m²): a third of the world tensor's trace, which
/// turning does not change.
fn mean_moment(s: &BodySim) -> Real {
    (s.inertia.x_axis.x + s.inertia.y_axis.y + s.inertia.z_axis.z) / 3.0
}

/// The bodies that carry [`HUB_RATIO`] times their own mass or moment in joined
/// partners, shared among several (at most half of it from one: a light body under one
/// heavy partner is a pair's ratio, cured as such), and the largest such load; `None`
/// when no body does, found in one scan of the joints.
fn hubs(
    sims: &[BodySim],
    joined: &[Joined],
    load: &mut Vec<[Real; 4]>,
) -> Option<(Vec<bool>, Real)> {
    // Without joints there is no hub, and no per-body scratch to fill (the rain's 2,000).
    if joined.is_empty() {
        return None;
    }
    let moving = |k: usize| sims[k].moves;
    // Per body: [sum, largest] of the partners' mass ratios, then of their moment ratios.
    // The list is the caller's, kept from step to step (a tiny world's step allocates
    // nothing).
    load.clear();
    load.resize(sims.len(), [0.0; 4]);
    let mut add = |k: usize, at: usize, r: Real| {
        load[k][at] += r;
        load[k][at + 1] = load[k][at + 1].max(r);
    };
    for j in joined.iter().filter(|j| moving(j.a) && moving(j.b)) {
        for (k, other) in [(j.a, j.b), (j.b, j.a)] {
            add(k, 0, sims[k].inv_mass / sims[other].inv_mass);
            let own = mean_moment(&sims[k]);
            if j.locks_rotation && own > 0.0 {
                add(k, 2, mean_moment(&sims[other]) / own);
            }
        }
    }
    let shared = |sum: Real, one: Real| sum >= HUB_RATIO && sum >= 2.0 * one;
    let hub_load = |l: &[Real; 4]| {
        let lin = if shared(l[0], l[1]) { l[0] } else { 0.0 };
        let ang = if shared(l[2], l[3]) { l[2] } else { 0.0 };
        lin.max(ang)
    };
    let largest = load.iter().map(hub_load).fold(0.0, Real::max);
    (largest > 0.0).then(|| (load.iter().map(|l| hub_load(l) > 0.0).collect(), largest))
}

/// Which islands are heavy and how they are solved.
#[derive(Debug, Default)]
pub(crate) struct Heavy {
    /// Per body, whether its island is heavy.
    pub flags: Vec<bool>,
    /// The multiple of the passes those islands get (one for all, from the largest ratio
    /// or load).
    pub passes: u32,
    /// Per body, whether its island holds a hub (empty when none does): there joints
    /// that lock rotation keep their spring (see the module comment).
    pub hub: Vec<bool>,
}

/// For each body, whether it belongs to an island (bodies the solver moves, linked by the
/// given contacts and joints) that holds a pair with a mass ratio of at least
/// [`HEAVY_RATIO`] or a hub (see [`HUB_RATIO`]), the multiple of the passes those islands
/// get, and which hold a hub; `None` when no island is heavy, the common case, found in
/// one scan.
pub(crate) fn heavy_islands(
    sims: &[BodySim],
    links: impl Iterator<Item = (usize, usize)> + Clone,
    joined: &[Joined],
    load: &mut Vec<[Real; 4]>,
) -> Option<Heavy> {
    let moving = |k: usize| sims[k].moves;
    let ratio = |(a, b): (usize, usize)| {
        let (ma, mb) = (sims[a].inv_mass, sims[b].inv_mass);
        if moving(a) && moving(b) {
            ma.max(mb) / ma.min(mb)
        } else {
            1.0
        }
    };
    let heavy_pair = |l: (usize, usize)| ratio(l) >= HEAVY_RATIO;
    let largest = links.clone().map(ratio).fold(1.0, Real::max);
    let (hub, hub_load) = hubs(sims, joined, load).unzip();
    if largest < HEAVY_RATIO && hub.is_none() {
        return None;
    }
    let passes = if largest >= VERY_HEAVY_RATIO { 6 } else { 4 };
    let passes = passes.max(hub_load.map_or(0, hub_passes));
    let mut parent: Vec<usize> = (0..sims.len()).collect();
    for (a, b) in links.clone() {
        if moving(a) && moving(b) {
            union(&mut parent, a, b);
        }
    }
    let mut heavy_root = vec![false; sims.len()];
    for (a, _) in links.filter(|&l| heavy_pair(l)) {
        let root = find(&mut parent, a);
        heavy_root[root] = true;
    }
    let mut hub_root = vec![false; sims.len()];
    let hubs = hub
        .iter()
        .flat_map(|h| h.iter().enumerate().filter(|&(_, &h)| h));
    for (k, _) in hubs {
        let root = find(&mut parent, k);
        (heavy_root[root], hub_root[root]) = (true, true);
    }
    let mut of_root = |roots: &[bool]| -> Vec<bool> {
        (0..sims.len())
            .map(|k| roots[find(&mut parent, k)])
            .collect()
    };
    let flags = of_root(&heavy_root);
    let hub = if hub.is_some() {
        of_root(&hub_root)
    } else {
        Vec::new()
    };
    Some(Heavy { flags, passes, hub })
}
