//! Chains of joints through light bodies, their hard rows solved as one block.
//!
//! A body with several joints in an imported model (an MJCF body with slide x, slide z and
//! hinge y, as the roots of Gymnasium's hopper, walker and cheetah; a humanoid's hip of
//! three hinges; a URDF planar joint) becomes a chain of joints through intermediate
//! bodies of a thousandth (MJCF) or a hundredth (URDF) of the body's mass
//! (`tumble_scene`'s MJCF and URDF builders). Gauss–Seidel hands a load through a light
//! body only in proportion to the mass ratio per pass, so the chain gave way under any load
//! across its locked directions: a planar body (slides x, z, hinge y) with gravity partly
//! along y left its plane by 0.33 m in a second at dt = 0.002 s, and 2 cm at dt = 1e-4 s,
//! even with the heavy islands' sixteen passes.
//!
//! So the hard rows of every joint of such a chain are solved together: K = J M⁻¹ Jᵀ over
//! all of them and all the chain's bodies, eliminated once per frame as a joint's own block
//! is (`joint_block.rs`), each pass solving K x = −(J v + bias·C) and applying
//! Δλ = mass_scale·x − impulse_scale·λ row by row. The light bodies are thus eliminated
//! exactly: the chain acts as the one joint it stands for. Limits, motors and springs stay
//! 1D rows of their joints, solved before the block as for any joint.
//!
//! A body is a link of a chain when it moves, has exactly two joints, both with hard rows
//! solved as a block and nothing on their free axis (no limits, motor, spring, servo or
//! cone), and is lighter by [`HEAVY_RATIO`] than a heavy body it connects to, directly or
//! through other links. Chaining limited and sprung joints as well made dm_control's dog
//! (two- and three-hinge vertebrae with ranges and stiffness) fly apart within 0.7 s; why
//! is not yet understood, so such joints keep their own blocks for now. Other scenes have
//! no chain and are solved as before, bit for bit.

// Casts between Real and f64 (the block's numbers) are no-ops in the default build but
// needed in the f32 one.
#![allow(clippy::unnecessary_cast)]

use super::block::Eliminated;
use super::{Frame, JointConstraint, JointPass, Row};
use crate::dynamics::island::{find, union};
use crate::dynamics::joint::{AngularLock, LinearLock};
use crate::dynamics::solver::body::{BodySim, BodyState};
use crate::dynamics::solver::mass_ratio::HEAVY_RATIO;
use crate::math::{Real, Vec3};

/// The most hard rows a chain solves as one block: four joints of six rows (a body with
/// four joints); longer chains keep their joints' own blocks.
pub(crate) const CHAIN_ROWS: usize = 24;

/// A chain: its joints (indices in the solver's list, in that order).
#[derive(Debug, Clone)]
pub(crate) struct Chain {
    pub joints: Vec<usize>,
}

/// A chain's block at one frame: its rows and their K eliminated.
#[derive(Clone)]
pub(crate) struct ChainBlock {
    /// Per row: the member (index into `Chain::joints`) and its row in the joint's block.
    rows: Vec<(usize, usize)>,
    /// In f64 whatever `Real` is: K spans the light bodies' and the heavy ones' inverse
    /// masses (a thousand to one in MJCF's chains), and eliminated in f32 the solution's
    /// error made a planar chain at 1/1000 fly apart within a second.
    k: Eliminated<CHAIN_ROWS, f64>,
}

/// Finds the chains among `joints` (the solver's list, their `chain` unset), marks their
/// members, and returns them.
pub(crate) fn find_chains(joints: &mut [JointConstraint], sims: &[BodySim]) -> Vec<Chain> {
    // A chain has two joints at least; without, skip the per-body lists (every step).
    if joints.len() < 2 {
        return Vec::new();
    }
    let n = sims.len();
    let mut count = vec![0u32; n];
    let mut blocked = vec![0u32; n];
    // A candidate's two partners (`None`: the world), the only ones the search needs.
    let mut partners: Vec<[Option<usize>; 2]> = vec![[None; 2]; n];
    for j in joints.iter() {
        let [a, b] = j.bodies();
        for (k, other) in [(a, b), (b, a)] {
            let Some(k) = k else { continue };
            if let Some(slot) = partners[k].get_mut(count[k] as usize) {
                *slot = other;
            }
            count[k] += 1;
            blocked[k] += u32::from(j.has_block() && j.drive.is_idle() && j.cone.is_none());
        }
    }
    let candidate = |k: usize| sims[k].moves && count[k] == 2 && blocked[k] == 2;
    if !(0..n).any(candidate) {
        return Vec::new();
    }
    let mass = |k: Option<usize>| match k {
        Some(k) if sims[k].moves && sims[k].inv_mass > 0.0 => 1.0 / sims[k].inv_mass,
        _ => 0.0,
    };
    // Each link's reference: the heavy mass it is light against, spread along the chain.
    let mut reference: Vec<Real> = vec![0.0; n];
    loop {
        let mut changed = false;
        for k in (0..n).filter(|&k| candidate(k)) {
            let heaviest = partners[k]
                .into_iter()
                .map(|p| mass(p).max(p.map_or(0.0, |p| reference[p])))
                .fold(0.0, Real::max);
            if heaviest > reference[k] && mass(Some(k)) * HEAVY_RATIO <= heaviest {
                reference[k] = heaviest;
                changed = true;
            }
        }
        if !changed {
            break;
        }
    }
    let link = |k: Option<usize>| k.is_some_and(|k| candidate(k) && reference[k] > 0.0);
    // Joints joined through links, in list order: each chain is a path of them.
    let mut parent: Vec<usize> = (0..joints.len()).collect();
    let mut by_link: Vec<Option<usize>> = vec![None; n];
    for (i, j) in joints.iter().enumerate() {
        for k in j.bodies().into_iter().flatten().filter(|&k| link(Some(k))) {
            match by_link[k] {
                Some(other) => union(&mut parent, other, i),
                None => by_link[k] = Some(i),
            }
        }
    }
    let mut members: Vec<Vec<usize>> = vec![Vec::new(); joints.len()];
    for i in 0..joints.len() {
        let r = find(&mut parent, i);
        members[r].push(i);
    }
    let mut chains = Vec::new();
    for m in members.into_iter().filter(|m| m.len() >= 2) {
        if m.iter().map(|&i| hard_rows(&joints[i])).sum::<usize>() > CHAIN_ROWS {
            continue;
        }
        let index = chains.len();
        for &i in &m {
            joints[i].chain = Some(index);
        }
        chains.push(Chain { joints: m });
    }
    chains
}

/// How many hard rows joint `c` has (see `joint_rows.rs`).
fn hard_rows(c: &JointConstraint) -> usize {
    let linear = match c.spec.linear {
        LinearLock::Point => 3,
        LinearLock::AcrossAxis => 2,
        LinearLock::Free => 0,
    };
    let angular = match c.spec.angular {
        AngularLock::All => 3,
        AngularLock::AcrossAxis => 2,
        AngularLock::Free => 0,
    };
    linear + angular
}

/// One side of a row as the block sees it: the body (`None`: not moved by the solver),
/// the row's Jacobian on it (linear, angular) and M⁻¹ Jᵀ.
struct Reach {
    body: Option<usize>,
    j: (Vec3, Vec3),
    m_inv_j: (Vec3, Vec3),
}

fn reaches(c: &JointConstraint, row: &Row, fr: &Frame) -> [Reach; 2] {
    let (sa, sb) = (&fr.sa, &fr.sb);
    let side = |body: Option<usize>, moves: bool, j: (Vec3, Vec3), m: (Vec3, Vec3)| Reach {
        body: body.filter(|_| moves),
        j,
        m_inv_j: m,
    };
    [
        side(
            c.a,
            sa.moves,
            (-row.lin, -row.ang_a),
            (
                -(sa.mask * row.lin * sa.inv_mass),
                -(sa.inv_inertia * row.ang_a),
            ),
        ),
        side(
            c.b,
            sb.moves,
            (row.lin, row.ang_b),
            (sb.mask * row.lin * sb.inv_mass, sb.inv_inertia * row.ang_b),
        ),
    ]
}

impl Chain {
    /// The chain's last joint in the solver's list: its block is solved after it.
    pub(crate) fn last(&self) -> usize {
        self.joints.last().copied().unwrap_or(0)
    }

    /// The chain's block at `frames` (per joint of the solver's list), from the members'
    /// own blocks (made in `blocks` if missing).
    fn block(
        &self,
        joints: &[JointConstraint],
        frames: &[Frame],
        blocks: &mut [Option<super::Block>],
    ) -> ChainBlock {
        let mut rows = Vec::new();
        let mut reach = Vec::new();
        for (m, &i) in self.joints.iter().enumerate() {
            let (c, fr) = (&joints[i], &frames[i]);
            let Some(block) = c.block(fr, blocks) else {
                continue;
            };
            for (r, row) in block.hard.rows[..block.hard.count].iter().enumerate() {
                rows.push((m, r));
                reach.push(reaches(c, row, fr));
            }
        }
        let n = rows.len();
        let dot = |a: Vec3, b: Vec3| {
            (a.x as f64 * b.x as f64) + (a.y as f64 * b.y as f64) + (a.z as f64 * b.z as f64)
        };
        let mut k = [[0.0; CHAIN_ROWS]; CHAIN_ROWS];
        for (r, kr) in reach.iter().zip(&mut k) {
            for (s, krs) in reach.iter().zip(kr.iter_mut()) {
                let mut sum = 0.0;
                for x in r.iter().filter(|x| x.body.is_some()) {
                    for y in s.iter().filter(|y| y.body == x.body) {
                        sum += dot(x.j.0, y.m_inv_j.0) + dot(x.j.1, y.m_inv_j.1);
                    }
                }
                *krs = sum;
            }
        }
        ChainBlock {
            rows,
            k: Eliminated::new(k, n),
        }
    }

    /// One pass over the chain's hard rows as one block, each joint's rows with its own
    /// `pass` (made once per frame into `cache`).
    pub(crate) fn solve<'p>(
        &self,
        (joints, frames): (&mut [JointConstraint], &[Frame]),
        states: &mut [BodyState],
        pass: impl Fn(&JointConstraint) -> &'p JointPass,
        (blocks, cache): (&mut [Option<super::Block>], &mut Option<ChainBlock>),
    ) {
        let chain = cache.get_or_insert_with(|| self.block(joints, frames, blocks));
        let mut rhs = [0.0; CHAIN_ROWS];
        for (r, &(m, row)) in chain.rows.iter().enumerate() {
            let i = self.joints[m];
            let (c, fr) = (&joints[i], &frames[i]);
            let Some(block) = c.block(fr, blocks) else {
                continue;
            };
            let p = pass(c);
            let bias = if p.bias {
                p.soft.bias_rate * block.hard.error[row]
            } else {
                0.0
            };
            let velocity = c.with_states(states, |a, b| block.hard.rows[row].velocity(a, b));
            rhs[r] = -(velocity + bias) as f64;
        }
        let x = chain.k.solve(rhs);
        for (r, &(m, row)) in chain.rows.iter().enumerate() {
            let i = self.joints[m];
            let fr = &frames[i];
            let Some(block) = joints[i].block(fr, blocks) else {
                continue;
            };
            let line = block.hard.rows[row];
            let c = &mut joints[i];
            let p = pass(c);
            let acc = c.impulses.hard[row];
            let delta = p.soft.mass_scale * x[r] as Real - p.soft.impulse_scale * acc;
            c.with_states(states, |a, b| line.apply(delta, &fr.sa, &fr.sb, a, b));
            c.impulses.hard[row] = acc + delta;
        }
    }
}
