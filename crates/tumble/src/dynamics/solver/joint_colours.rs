//! The joints' graph colours: the order the joint passes visit them in, and which runs of
//! that order may be split over threads.
//!
//! Joint passes are Gauss–Seidel sweeps in creation order, and that order is worth
//! keeping: a net or a chain built row by row is swept from its hold outwards, so one pass
//! carries the load the whole way. Colouring joint by joint (the contacts' way, Box2D's)
//! made the 30 × 30 ball-joint net's largest gap 6.54 → 10.80 mm and its step 9 % slower
//! (5 Dec 2026). So the list is cut into stripes, runs of consecutive joints (at least
//! [`STRIPE`], at most [`STRIPES`] a part), and the stripes, not the joints, are coloured:
//! greedy, first fit, in order. A colour's stripes share no body, so solving them at once
//! on several threads, each in creation order, is the update that solving them one after
//! another makes; the passes take the colours in turn (within each part: the light
//! islands' joints, then the heavy ones', see `Solver::passes`). The stripes depend on the
//! joints alone, never on the thread count, so every thread count gives the same bits.
//!
//! What changes is the order between stripes of different colours: stripes 0, 2, 4, ...
//! of a net go before 1, 3, 5, .... A part of at most [`STRIPE`] joints (chains' members
//! aside) is one stripe, solved as it was, serially in creation order with its chains in
//! place: such scenes keep their bits. The 100 × 100 net (19,800 joints, 16 stripes in two
//! colours) keeps its largest gap (19.13 mm over Box3D's window), and two threads took its
//! step from 55 to 40 ms on this 2-core machine. Independent mechanisms (ragdolls side by
//! side) share no body, so their stripes are all one colour, again in creation order.
//!
//! Every body but the world counts, static ones too: a joint's pass takes both its bodies'
//! states (the static one to read), and two threads must not hold the same one. A joint in
//! a chain through light bodies (`joint_chain.rs`), whose block reaches the whole chain,
//! keeps its creation order after the colours of a part cut into stripes, and is solved
//! on one thread ([`SERIAL`]), as are the stripes whose bodies have used every colour.

use std::ops::Range;

use super::joint::{Chain, JointConstraint};
use crate::threads::Par;

/// The colour of the joints solved one after another, in creation order, after the others.
pub(super) const SERIAL: u32 = 63;

/// Fewest joints in a stripe, and how many stripes a part is cut into at most.
const STRIPE: usize = 1024;
const STRIPES: usize = 16;

/// A run of the solver's joint list: one colour of one part, or that part's serial rest.
#[derive(Debug, Clone, PartialEq, Eq)]
pub(super) struct JointRun {
    pub range: Range<usize>,
    /// Where each stripe of a colour starts (empty for a serial rest, which is not split).
    pub stripes: Vec<usize>,
}

impl JointRun {
    /// Whether the passes split the run over the step's threads: a colour of several
    /// stripes, on several threads. Otherwise it runs in order on the calling thread,
    /// which gives the same bits.
    pub fn splits(&self, par: Par) -> bool {
        par.threads > 1 && self.stripes.len() > 1
    }
}

/// Sorts `joints` colour by colour within each of `parts` (consecutive ranges covering
/// the list), renumbers the `chains`' members to match, and makes `runs` the runs. `used`
/// is scratch, one mask of colours per body of the step (`bodies` of them).
pub(super) fn order(
    joints: &mut [JointConstraint],
    chains: &mut [Chain],
    parts: [Range<usize>; 2],
    (bodies, used): (usize, &mut Vec<u64>),
    runs: &mut Vec<JointRun>,
) {
    // One stripe a part: solved as they were, in creation order with their chains. The
    // list is refilled in place (a small world's step comes here every time).
    let serial = |parts: &[Range<usize>], runs: &mut Vec<JointRun>| {
        let run = |part: &Range<usize>| JointRun {
            range: part.clone(),
            stripes: Vec::new(),
        };
        runs.clear();
        runs.extend(parts.iter().filter(|p| !p.is_empty()).map(run));
    };
    // Parts no longer than a stripe need no look at their joints (reading them was most
    // of this function's 1.5 % of the f32 joint grid's step).
    if parts.iter().all(|part| part.len() <= STRIPE) {
        return serial(&parts, runs);
    }
    // Each joint's bodies, and whether it is a chain's member, read once: the walks below
    // over the few-hundred-byte constraints cost the joint grid 1.7 % of its step.
    let info: Vec<Link> = joints
        .iter()
        .map(|j| (j.bodies(), j.chain.is_some()))
        .collect();
    let free = |part: &Range<usize>| info[part.clone()].iter().filter(|l| !l.1).count();
    if parts.iter().all(|part| free(part) <= STRIPE) {
        return serial(&parts, runs);
    }
    used.clear();
    used.resize(bodies, 0);
    // Per joint: part, colour, stripe.
    let mut key: Vec<(u32, u32, u32)> = Vec::with_capacity(joints.len());
    for (p, part) in parts.iter().enumerate() {
        // Colours start afresh in each part: the parts are solved one after the other.
        for k in info[part.clone()].iter().flat_map(|l| l.0).flatten() {
            used[k] = 0;
        }
        let size = STRIPE.max(free(part).div_ceil(STRIPES));
        // Stripes: runs of `size` joints outside chains (with the chain members among them).
        let mut cuts = vec![part.start];
        let mut members = 0;
        for i in part.clone() {
            members += usize::from(!info[i].1);
            if members == size && i + 1 < part.end {
                cuts.push(i + 1);
                members = 0;
            }
        }
        cuts.push(part.end);
        if cuts.len() == 2 {
            // One stripe: nothing to split, and its chains keep their place.
            key.extend(part.clone().map(|_| (p as u32, SERIAL, 0)));
            continue;
        }
        for (stripe, cut) in cuts.windows(2).enumerate() {
            let links = &info[cut[0]..cut[1]];
            let c = colour(links, used);
            for l in links {
                key.push((p as u32, if l.1 { SERIAL } else { c }, stripe as u32));
            }
        }
    }
    // New position → old: stable, so creation order holds inside a colour.
    let mut moved: Vec<usize> = (0..joints.len()).collect();
    if !key.is_sorted_by_key(|k| (k.0, k.1)) {
        moved.sort_by_key(|&i| (key[i].0, key[i].1));
        permute(joints, &moved);
        let mut to_new = vec![0; moved.len()];
        for (new, &old) in moved.iter().enumerate() {
            to_new[old] = new;
        }
        for chain in chains.iter_mut() {
            for m in &mut chain.joints {
                *m = to_new[*m];
            }
        }
    }
    runs.clear();
    for (new, &old) in moved.iter().enumerate() {
        let (part, colour, stripe) = key[old];
        match runs.last_mut() {
            Some(run)
                if (key[moved[run.range.start]].0, key[moved[run.range.start]].1)
                    == (part, colour) =>
            {
                run.range.end = new + 1;
                if colour != SERIAL && key[moved[new - 1]].2 != stripe {
                    run.stripes.push(new);
                }
            }
            _ => runs.push(JointRun {
                range: new..new + 1,
                stripes: if colour == SERIAL {
                    Vec::new()
                } else {
                    vec![new]
                },
            }),
        }
    }
}

/// Puts at each position `new` the joint that was at `moved[new]`, in place: cycle by
/// cycle, by swaps (the constraints are a few hundred bytes each, and moving them into a
/// new list and back copied the 100 × 100 joint grid's five megabytes twice a step).
fn permute(joints: &mut [JointConstraint], moved: &[usize]) {
    let mut done = vec![false; moved.len()];
    for start in 0..moved.len() {
        let mut at = start;
        while !done[at] {
            done[at] = true;
            let from = moved[at];
            if from == start {
                break;
            }
            joints.swap(at, from);
            at = from;
        }
    }
}

/// A joint's bodies, and whether it is a chain's member.
type Link = ([Option<usize>; 2], bool);

/// The first colour no body of `stripe` (but its chains' members, which are not
/// coloured) has in `used`, marked there; [`SERIAL`] when every colour is taken.
fn colour(stripe: &[Link], used: &mut [u64]) -> u32 {
    let bodies = || stripe.iter().filter(|l| !l.1).flat_map(|l| l.0).flatten();
    let taken = bodies().fold(0u64, |m, k| m | used[k]);
    let free = (!taken).trailing_zeros();
    if free >= SERIAL {
        return SERIAL;
    }
    for k in bodies() {
        used[k] |= 1 << free;
    }
    free
}
