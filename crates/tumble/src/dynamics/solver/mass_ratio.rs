//! Islands with a large mass ratio get stiffer contacts and four to six times the passes.
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
//! links holding 100 kg stretched 2.3 cm per joint at the defaults, now 7.4 mm.
//! Stiffening and passes only the islands that need them keeps every other scene's cost
//! and results as they were.

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

/// For each body, whether it belongs to an island (bodies the solver moves, linked by the
/// given contacts and joints) that holds a pair with a mass ratio of at least
/// [`HEAVY_RATIO`], and the multiple of the passes those islands get (one for all, from
/// the largest ratio); `None` when no island has one, the common case, found in one scan.
pub(crate) fn heavy_islands(
    sims: &[BodySim],
    links: impl Iterator<Item = (usize, usize)> + Clone,
) -> Option<(Vec<bool>, u32)> {
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
    if largest < HEAVY_RATIO {
        return None;
    }
    let passes = if largest >= VERY_HEAVY_RATIO { 6 } else { 4 };
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
    let flags = (0..sims.len())
        .map(|k| heavy_root[find(&mut parent, k)])
        .collect();
    Some((flags, passes))
}
