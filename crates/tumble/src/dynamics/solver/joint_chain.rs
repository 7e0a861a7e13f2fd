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
//! exactly: the chain acts as the one joint it stands for.
//!
//! A member's limits, servo, motor and spring stay 1D rows on its free axis, solved before
//! the block, but as the chain sees them (`Chain::solve_free`):
//! - sized by 1/(K_ff − K_fh K⁻¹ K_hf), the free row's mass with the hard rows holding.
//!   Sized by its own bodies, a row met a light body's mass (dm_control's dog: K_ff ≈ 6.1e6
//!   against 3.2e3 within the chain) and, summed over passes, worked as an integral
//!   controller: the dog flew apart within 0.7 s;
//! - each part's impulse δ carried on at once through the hard rows (−K⁻¹ K_hf δ), which
//!   leaves their velocities as they were; left on the light body, the next part of the
//!   same joint met it spun 2000 times too fast: NaN in the dog's first step;
//! - reading its velocity as it will be once the block has acted, J_f v − yᵀ(J_h v +
//!   bias) with y = K⁻¹ K_hf: read off the light body, a hard row's error turned into an impulse sized by
//!   the heavy mass, and humanoid_CMU's neck rang up to NaN within 5 steps;
//! - the block's soft leak (impulse_scale·λ) skipping the carried part: leaked, it moved
//!   the light bodies 2000 times what the free rows meant, rung up twentyfold a pass.
//!
//! With these the hip of a 10 kg rod on three sprung, limited hinges through bodies of
//! 1/100 to 1/1000 of its mass holds its pivot to 0.02 mm (1.1 cm joint by joint) at dt =
//! 1/60 s, and dm_control's dog, humanoid and humanoid_CMU run 10 s without blowing up.
//!
//! A body is a link of a chain when it moves, has exactly two joints, both with hard rows
//! solved as a block and no cone, and is lighter by [`HEAVY_RATIO`] than a heavy body it
//! connects to, directly or through other links. Other scenes have no chain and are solved
//! as before, bit for bit; a chain whose joints are idle on their free axes is solved as
//! before too.

// Casts between Real and f64 (the block's numbers) are no-ops in the default build but
// needed in the f32 one.
#![allow(clippy::unnecessary_cast)]

use super::block::Eliminated;
use super::{free_impulse, Frame, JointConstraint, JointPass, Line, Row};
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
    /// Per member with a drive on its free row (unless the hard rows leave that row no
    /// room: K_eff ≈ 0): the row's mass within the chain and its carry.
    free: Vec<Free>,
}

/// A member's free row within its chain.
#[derive(Clone)]
struct Free {
    /// The member, by its index in the solver's list.
    joint: usize,
    /// The row's effective mass within the chain.
    mass: Real,
    /// K⁻¹ K_hf: per hard row, the impulse the block answers a unit impulse on the free
    /// row with (negated), so that the hard rows' velocities stay as they were.
    carry: [f64; CHAIN_ROWS],
    /// What those impulses do to the chain's bodies, per unit impulse on the free row:
    /// each moving body's (Δv, Δω), summed over the hard rows once per frame. Applied
    /// row by row instead, the carry was a sixth of humanoid_CMU's step.
    turns: Vec<(usize, Vec3, Vec3)>,
    /// yᵀ J_h per body (linear, angular; f64), so that yᵀ J_h v is read from at most five
    /// bodies' velocities instead of every hard row's: read row by row, with a block
    /// lookup each, it was 7 % of humanoid_CMU's step.
    reads: Vec<(usize, [f64; 6])>,
    /// Per member, Σ y_s C_s over its hard rows: yᵀ (bias·C) is its pass's bias rate
    /// times this.
    errors: Vec<f64>,
}

/// Per body of the chain (moving or not), Σ yₛ Jₛ over the hard rows `reach`, in f64.
fn reads(reach: &[[Reach; 2]], y: &[f64; CHAIN_ROWS]) -> Vec<(usize, [f64; 6])> {
    let mut out: Vec<(usize, [f64; 6])> = Vec::new();
    for (sides, &ys) in reach.iter().zip(y) {
        for x in sides {
            let Some(k) = x.index else { continue };
            let (l, a) = (x.j.0, x.j.1);
            let j = [l.x, l.y, l.z, a.x, a.y, a.z].map(|c| ys * c as f64);
            match out.iter_mut().find(|(b, _)| *b == k) {
                Some((_, g)) => g.iter_mut().zip(j).for_each(|(g, j)| *g += j),
                None => out.push((k, j)),
            }
        }
    }
    out
}

/// Per moving body of the chain, the velocity change of impulses −`carry` on the hard rows
/// `reach` (see [`Free::turns`]).
fn turns(reach: &[[Reach; 2]], carry: &[f64; CHAIN_ROWS]) -> Vec<(usize, Vec3, Vec3)> {
    let mut out: Vec<(usize, Vec3, Vec3)> = Vec::new();
    for (sides, &y) in reach.iter().zip(carry) {
        let impulse = -y as Real;
        for x in sides {
            let Some(k) = x.body else { continue };
            let (dv, dw) = (x.m_inv_j.0 * impulse, x.m_inv_j.1 * impulse);
            match out.iter_mut().find(|(b, _, _)| *b == k) {
                Some((_, v, w)) => (*v, *w) = (*v + dv, *w + dw),
                None => out.push((k, dv, dw)),
            }
        }
    }
    out
}

impl ChainBlock {
    /// Per hard row, the impulse carried into it from the members' free rows as they stand
    /// (`Chain::carry`): −Σ (K⁻¹ K_hf)·λ_f. The block leaks only the rest of its impulse
    /// (its soft `impulse_scale` term): leaking the carried part moved the light bodies
    /// along the free rows by K_ff/K_eff (2000) times what the rows meant, each pass
    /// answered by the rows with as much more, and the humanoid's abdomen rang up twenty
    /// times a pass, to NaN within its first step.
    fn carried(&self, joints: &[JointConstraint]) -> [f64; CHAIN_ROWS] {
        let mut carried = [0.0; CHAIN_ROWS];
        for f in &self.free {
            let lambda = free_impulse(&joints[f.joint].impulses) as f64;
            for (c, y) in carried.iter_mut().zip(&f.carry) {
                *c -= y * lambda;
            }
        }
        carried
    }
}

/// Finds the chains among `joints` (the solver's list, their `chain` unset), marks their
/// members, and returns them.
pub(crate) fn find_chains(
    joints: &mut [JointConstraint],
    sims: &[BodySim],
    lists: &mut ChainLists,
) -> Vec<Chain> {
    let mut chains = light_chains(joints, sims, lists);
    // A joint with an armature needs its free row's mass with its hard rows holding (see
    // `joint_armature.rs`): out of a chain, it is a chain of its own.
    for (i, j) in joints.iter_mut().enumerate() {
        if j.has_armature() && j.chain.is_none() && j.has_block() && j.cone.is_none() {
            j.chain = Some(chains.len());
            chains.push(Chain { joints: vec![i] });
        }
    }
    chains
}

/// The chain search's per-body lists, kept by the solver from step to step.
#[derive(Default)]
pub(crate) struct ChainLists {
    /// Per body, its joints, and those of them with a hard block.
    count: Vec<u32>,
    blocked: Vec<u32>,
    /// A candidate's two partners (`None`: the world), the only ones the search needs.
    partners: Vec<[Option<usize>; 2]>,
    /// Each link's reference: the heavy mass it is light against.
    reference: Vec<Real>,
}

/// Empties `list` and fills it with `n` times `value`, keeping its room.
fn refill<T: Clone>(list: &mut Vec<T>, n: usize, value: T) {
    list.clear();
    list.resize(n, value);
}

/// The chains of joints through light bodies (see the module's header).
fn light_chains(
    joints: &mut [JointConstraint],
    sims: &[BodySim],
    lists: &mut ChainLists,
) -> Vec<Chain> {
    // A chain has two joints at least; without, skip the per-body lists (every step).
    if joints.len() < 2 {
        return Vec::new();
    }
    let n = sims.len();
    let ChainLists {
        count,
        blocked,
        partners,
        reference,
    } = lists;
    refill(count, n, 0);
    refill(blocked, n, 0);
    refill(partners, n, [None; 2]);
    for j in joints.iter() {
        let [a, b] = j.bodies();
        for (k, other) in [(a, b), (b, a)] {
            let Some(k) = k else { continue };
            if let Some(slot) = partners[k].get_mut(count[k] as usize) {
                *slot = other;
            }
            count[k] += 1;
            blocked[k] += u32::from(j.has_block() && j.cone.is_none());
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
    refill(reference, n, 0.0);
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
    // No light link, no chain: skip the joint lists (every step of a cart-pole).
    if !(0..n).any(|k| link(Some(k))) {
        return Vec::new();
    }
    chains_through(joints, n, link)
}

/// The chains of `joints` joined through the bodies `link` says are links (of `n`).
fn chains_through(
    joints: &mut [JointConstraint],
    n: usize,
    link: impl Fn(Option<usize>) -> bool,
) -> Vec<Chain> {
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

/// J_r M⁻¹ J_sᵀ of two rows, over the bodies they share, in f64.
fn coupling(r: &[Reach; 2], s: &[Reach; 2]) -> f64 {
    let dot = |a: Vec3, b: Vec3| {
        (a.x as f64 * b.x as f64) + (a.y as f64 * b.y as f64) + (a.z as f64 * b.z as f64)
    };
    let mut sum = 0.0;
    for x in r.iter().filter(|x| x.body.is_some()) {
        for y in s.iter().filter(|y| y.body == x.body) {
            sum += dot(x.j.0, y.m_inv_j.0) + dot(x.j.1, y.m_inv_j.1);
        }
    }
    sum
}

/// One side of a row as the block sees it: the body (`None`: not moved by the solver),
/// the row's Jacobian on it (linear, angular) and M⁻¹ Jᵀ.
struct Reach {
    body: Option<usize>,
    /// The body whatever it is (a kinematic one's velocity is read, never changed).
    index: Option<usize>,
    j: (Vec3, Vec3),
    m_inv_j: (Vec3, Vec3),
}

fn reaches(c: &JointConstraint, row: &Row, fr: &Frame) -> [Reach; 2] {
    let (sa, sb) = (&fr.sa, &fr.sb);
    let side = |body: Option<usize>, moves: bool, j: (Vec3, Vec3), m: (Vec3, Vec3)| Reach {
        body: body.filter(|_| moves),
        index: body,
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
        blocks: &mut [super::Block],
    ) -> ChainBlock {
        let mut rows = Vec::new();
        let mut reach = Vec::new();
        let mut error = Vec::new();
        for (m, &i) in self.joints.iter().enumerate() {
            let (c, fr) = (&joints[i], &frames[i]);
            let Some(block) = c.block(fr, blocks) else {
                continue;
            };
            for (r, row) in block.hard.rows[..block.hard.count].iter().enumerate() {
                rows.push((m, r));
                reach.push(reaches(c, row, fr));
                error.push(block.hard.error[r] as f64);
            }
        }
        let n = rows.len();
        let mut k = [[0.0; CHAIN_ROWS]; CHAIN_ROWS];
        for (r, kr) in reach.iter().zip(&mut k) {
            for (s, krs) in reach.iter().zip(kr.iter_mut()) {
                *krs = coupling(r, s);
            }
        }
        let k = Eliminated::new(k, n);
        let mut free = Vec::new();
        for &i in self
            .joints
            .iter()
            .filter(|&&i| joints[i].acts_on_free_row())
        {
            let (c, fr) = (&joints[i], &frames[i]);
            let Some((row, _)) = c.free_row(fr) else {
                continue;
            };
            let f = reaches(c, &row, fr);
            let mut k_hf = [0.0; CHAIN_ROWS];
            for (khf, h) in k_hf.iter_mut().zip(&reach) {
                *khf = coupling(h, &f);
            }
            let y = k.solve(k_hf);
            let k_ff = coupling(&f, &f);
            let k_eff = k_ff - (0..n).map(|s| k_hf[s] * y[s]).sum::<f64>();
            if k_eff > 1e-9 * k_ff {
                let mass = (1.0 / k_eff) as Real;
                let mut errors = vec![0.0; self.joints.len()];
                for (s, &(m, _)) in rows.iter().enumerate() {
                    errors[m] += y[s] * error[s];
                }
                free.push(Free {
                    joint: i,
                    mass,
                    carry: y,
                    turns: turns(&reach, &y),
                    reads: reads(&reach, &y),
                    errors,
                });
            }
        }
        ChainBlock { rows, k, free }
    }

    /// One pass over member `i`'s free row (limits, spring, servo, motor), each of its
    /// parts sized by the row's mass within the chain and its impulse carried on through
    /// the hard rows (`carry`) before the next part reads the velocities.
    pub(crate) fn solve_free<'p>(
        &self,
        i: usize,
        (joints, frames): (&mut [JointConstraint], &[Frame]),
        states: &mut [BodyState],
        pass: impl Fn(&JointConstraint) -> &'p JointPass,
        (blocks, cache): (&mut [super::Block], &mut Option<ChainBlock>),
    ) {
        if !joints[i].acts_on_free_row() {
            return;
        }
        let chain = cache.get_or_insert_with(|| self.block(joints, frames, blocks));
        let fr = &frames[i];
        let Some((row, coordinate)) = joints[i].free_row(fr) else {
            return;
        };
        // A row the hard rows leave no room to move (K_eff ≈ 0) is solved as its own.
        let free = chain.free.iter().find(|f| f.joint == i);
        let line = match free {
            Some(free) => Line {
                row,
                mass: free.mass,
                offset: self.offset(free, joints, states, &pass),
            },
            None => Line::own(row, fr),
        };
        let push = |delta: Real, joints: &mut [JointConstraint], states: &mut [BodyState]| {
            if let Some(free) = free.filter(|_| delta != 0.0) {
                self.carry((chain, free, delta), joints, states);
            }
        };
        let armature = joints[i].has_armature();
        if armature {
            let mu = joints[i].couple_armature(line, fr, states);
            push(mu, joints, states);
        }
        let p = pass(&joints[i]);
        let folded = joints[i].with_armature(line);
        for part in joints[i].drive.parts() {
            let mut delta = joints[i].solve_free_part(&part, (folded, coordinate), (fr, p), states);
            if armature && delta != 0.0 {
                delta += joints[i].fold_armature((delta, line.mass), (row, fr), states);
            }
            push(delta, joints, states);
        }
    }

    /// yᵀ rhs (see [`Chain::rhs`]) for `free`'s y: −(yᵀ J_h v + yᵀ bias·C), from the
    /// summed Jacobians and errors of [`Free`].
    fn offset<'p>(
        &self,
        free: &Free,
        joints: &[JointConstraint],
        states: &[BodyState],
        pass: &impl Fn(&JointConstraint) -> &'p JointPass,
    ) -> Real {
        let mut sum = 0.0;
        for (k, g) in &free.reads {
            let (v, w) = (states[*k].v, states[*k].w);
            let s = [v.x, v.y, v.z, w.x, w.y, w.z];
            sum += g.iter().zip(s).map(|(g, s)| g * s as f64).sum::<f64>();
        }
        for (&e, &i) in free.errors.iter().zip(&self.joints) {
            let p = pass(&joints[i]);
            if p.bias {
                sum += p.soft.bias_rate as f64 * e;
            }
        }
        -sum as Real
    }

    /// −(J v + bias·C) of the chain's hard rows: what the block is to add to their
    /// velocities.
    fn rhs<'p>(
        &self,
        chain: &ChainBlock,
        (joints, frames): (&[JointConstraint], &[Frame]),
        states: &mut [BodyState],
        pass: &impl Fn(&JointConstraint) -> &'p JointPass,
        blocks: &mut [super::Block],
    ) -> [f64; CHAIN_ROWS] {
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
        rhs
    }

    /// Carries `delta`, an impulse a member's free row just added, on through the chain:
    /// each hard row takes −(K⁻¹ K_hf)ₛ·delta, which leaves every hard row's velocity as
    /// it was, so the light bodies never hold the impulse alone. Sized by the chain's mass
    /// and left on a light body, the impulse spun it by K_ff/K_eff (2000 in the dog) times
    /// the row's error, and the next row of the same joint (a limit after the servo)
    /// answered that with an impulse as much larger: NaN within the dog's first step.
    fn carry(
        &self,
        (chain, free, delta): (&ChainBlock, &Free, Real),
        joints: &mut [JointConstraint],
        states: &mut [BodyState],
    ) {
        for &(k, dv, dw) in &free.turns {
            states[k].v += dv * delta;
            states[k].w += dw * delta;
        }
        for (s, &(m, row)) in chain.rows.iter().enumerate() {
            joints[self.joints[m]].impulses.hard[row] -= (free.carry[s] * delta as f64) as Real;
        }
    }

    /// One pass over the chain's hard rows as one block, each joint's rows with its own
    /// `pass` (made once per frame into `cache`).
    pub(crate) fn solve<'p>(
        &self,
        (joints, frames): (&mut [JointConstraint], &[Frame]),
        states: &mut [BodyState],
        pass: impl Fn(&JointConstraint) -> &'p JointPass,
        (blocks, cache): (&mut [super::Block], &mut Option<ChainBlock>),
    ) {
        let chain = cache.get_or_insert_with(|| self.block(joints, frames, blocks));
        let rhs = self.rhs(chain, (joints, frames), states, &pass, blocks);
        let x = chain.k.solve(rhs);
        let carried = chain.carried(joints);
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
            let own = acc - carried[r] as Real;
            let delta = p.soft.mass_scale * x[r] as Real - p.soft.impulse_scale * own;
            c.with_states(states, |a, b| line.apply(delta, &fr.sa, &fr.sb, a, b));
            c.impulses.hard[row] = acc + delta;
        }
    }
}
