//! Joint constraints in the soft step: what each joint's rows are, and the order and way
//! they are solved.
//!
//! A joint's rows follow from its kind's description (`KindSpec` in `joint.rs`): its
//! linear and angular locks give the hard rows, its free axis the row that limits, motor,
//! spring and rod act on, and a `cone` option the swing-cone row (`joint_rows.rs`).
//!
//! Each joint is solved in the order Box2D uses (the softest first, the hard constraint
//! last, so it has the final word): spring, motor, limits (`joint_1d.rs`), then the hard
//! rows as one block (`joint_block.rs`). The hard rows are the joint's equalities, each a
//! Jacobian row Ċ = lin·(v_b − v_a) + ang_b·ω_b − ang_a·ω_a, listed linear lock first,
//! then angular lock:
//!
//! ```text
//! LinearLock::Point       lin = eᵢ, ang = r × eᵢ       C = eᵢ·(p_b − p_a)
//! LinearLock::AcrossAxis  lin = pᵢ, ang_a = (r_a + d) × pᵢ, ang_b = r_b × pᵢ
//! AngularLock::AcrossAxis ang = bᵢ (the two directions ⊥ the axis), C = bᵢ·(h_a × h_b)
//! AngularLock::All        ang = eᵢ, C = the rotation of q_b from q_a·q_rel
//! ```
//!
//! (ball, hinge and fixed lock the point; a slider locks across its axis; a hinge locks
//! across its axis angularly; fixed and slider lock all rotation), solved together,
//! K = J M⁻¹ Jᵀ (up to 6×6) factored as L D Lᵀ. Solving the point and the lock one
//! after the other instead leaves them fighting: a slider's across rows push at the
//! anchor's lever arm and turn the body, the lock turns it back, and the body drifted 4 cm
//! off a tilted axis in a second. A point lock with no angular lock (a ball joint) has no
//! rows to couple it to and is solved apart, as a 3×3 block. Limits, motors, springs and
//! distance rows are 1D rows. The hard rows use the joint softness (a spring at a quarter
//! of the substep rate in the biased pass, none in the relax pass), so drift is corrected
//! without the push-out becoming motion, as for contacts. Anchors are recomputed from the
//! current poses every pass: a joint turns far within a step (a pendulum's anchor swings),
//! unlike a contact.

#[path = "joint_armature.rs"]
mod armature;
#[path = "joint_block.rs"]
mod block;
#[path = "joint_chain.rs"]
mod chain;
#[path = "joint_1d.rs"]
mod one_d;
#[path = "joint_rows.rs"]
mod rows;

use super::body::{BodySim, BodyState, PairAccess};
use super::softness::Softness;
use crate::dynamics::joint::{AngularLock, Joint, JointImpulses, KindSpec, LinearLock};
use crate::math::{Mat3, Quat, Real, Vec3};
use crate::team::Parts;
pub(crate) use block::Block;
use block::{apply_point, point_impulse, point_inverse_mass, solve_hard, solve_point};
pub(crate) use chain::{find_chains, Chain, ChainBlock, ChainLists};
use one_d::{free_impulse, solve_free, solve_limit, FreeDrive, Line};

/// The solver's hard blocks of the joints, by `JointConstraint::block`: a slice when one
/// thread has them all, [`SharedBlocks`] when a joint colour is split over threads.
pub(crate) trait BlockSlots {
    fn slot(&mut self, i: usize) -> &mut Block;
}

impl BlockSlots for [Block] {
    #[inline(always)]
    fn slot(&mut self, i: usize) -> &mut Block {
        &mut self[i]
    }
}

/// The blocks seen by the pieces of a joint colour at once, through the team's
/// [`Parts`], each piece reaching the slots of its own joints only.
#[derive(Clone, Copy)]
pub(crate) struct SharedBlocks<'p, 'a>(&'p Parts<'a, Block>);

impl<'p, 'a> SharedBlocks<'p, 'a> {
    /// Shares the blocks in `parts` between the pieces of a job.
    ///
    /// # Safety
    /// While copies of the result are used on several threads at once, each slot must be
    /// reached through one copy only. A slot belongs to one joint (`prepare_joints` numbers
    /// them), and a joint to one piece.
    pub unsafe fn new(parts: &'p Parts<'a, Block>) -> SharedBlocks<'p, 'a> {
        SharedBlocks(parts)
    }
}

impl BlockSlots for SharedBlocks<'_, '_> {
    #[inline(always)]
    fn slot(&mut self, i: usize) -> &mut Block {
        // SAFETY: by `new`'s contract slot `i` is reached through this copy alone, so no
        // other live slice covers it (`part` checks the bounds).
        unsafe { &mut self.0.part(i..i + 1)[0] }
    }
}

/// A body as a joint sees it: pose, inverse masses, whether it moves. The world is one
/// that never moves, at the origin.
#[derive(Clone, Copy)]
struct Side {
    x: Vec3,
    q: Quat,
    inv_mass: Real,
    mask: Vec3,
    inv_inertia: Mat3,
    moves: bool,
}

impl Side {
    /// The world's side: never moves, at the origin.
    const WORLD: Side = Side {
        x: Vec3::ZERO,
        q: Quat::IDENTITY,
        inv_mass: 0.0,
        mask: Vec3::ZERO,
        inv_inertia: Mat3::ZERO,
        moves: false,
    };

    /// Overwrites the side with body `k`'s (`None`: the world's), field by field: built on
    /// the stack and copied, its fields were stored narrow and loaded wide, and the loads
    /// waited on the stores (a quarter of `write_frame`'s time on the joint grid).
    fn write(&mut self, sims: &[BodySim], k: Option<usize>) {
        match k.map(|k| &sims[k]) {
            Some(s) => {
                self.x = s.x;
                self.q = s.q;
                self.inv_mass = s.inv_mass;
                self.mask = s.linear_mask;
                self.inv_inertia = s.inv_inertia;
                self.moves = s.moves;
            }
            None => *self = Side::WORLD,
        }
    }
}

/// A Jacobian row: Ċ = lin·(v_b − v_a) + ang_b·ω_b − ang_a·ω_a.
#[derive(Clone, Copy)]
struct Row {
    lin: Vec3,
    ang_a: Vec3,
    ang_b: Vec3,
}

impl Row {
    const ZERO: Row = Row {
        lin: Vec3::ZERO,
        ang_a: Vec3::ZERO,
        ang_b: Vec3::ZERO,
    };
    /// Adds `lambda` times `row`: impulses along several rows summed into one, applied
    /// with one product by each inverse inertia instead of one per row.
    fn add_scaled(&mut self, row: &Row, lambda: Real) {
        self.lin += row.lin * lambda;
        self.ang_a += row.ang_a * lambda;
        self.ang_b += row.ang_b * lambda;
    }
    fn angular(axis: Vec3) -> Row {
        Row {
            lin: Vec3::ZERO,
            ang_a: axis,
            ang_b: axis,
        }
    }
    fn negated(self) -> Row {
        Row {
            lin: -self.lin,
            ang_a: -self.ang_a,
            ang_b: -self.ang_b,
        }
    }
    fn velocity(&self, a: &BodyState, b: &BodyState) -> Real {
        self.lin.dot(b.v - a.v) + self.ang_b.dot(b.w) - self.ang_a.dot(a.w)
    }
    fn mass(&self, sa: &Side, sb: &Side) -> Real {
        let k = sa.inv_mass * (sa.mask * self.lin).dot(self.lin)
            + sb.inv_mass * (sb.mask * self.lin).dot(self.lin)
            + self.ang_a.dot(sa.inv_inertia * self.ang_a)
            + self.ang_b.dot(sb.inv_inertia * self.ang_b);
        if k > 0.0 {
            1.0 / k
        } else {
            0.0
        }
    }
    fn apply(&self, lambda: Real, sa: &Side, sb: &Side, a: &mut BodyState, b: &mut BodyState) {
        if sa.moves {
            a.v -= sa.mask * self.lin * (sa.inv_mass * lambda);
            a.w -= sa.inv_inertia * self.ang_a * lambda;
        }
        if sb.moves {
            b.v += sb.mask * self.lin * (sb.inv_mass * lambda);
            b.w += sb.inv_inertia * self.ang_b * lambda;
        }
    }
}

/// How a pass treats position error.
#[derive(Clone, Copy)]
pub(crate) struct JointPass {
    /// Softness of the hard rows in this pass (rigid, no bias, in the relax pass).
    pub soft: Softness,
    pub bias: bool,
    pub inv_h: Real,
    pub h: Real,
}

/// One joint as the solver works on it.
pub(crate) struct JointConstraint {
    /// Index in the world's joint list.
    pub joint: usize,
    a: Option<usize>,
    b: Option<usize>,
    /// The kind's description: which rows the joint has.
    spec: &'static KindSpec,
    /// The swing-cone limit (rad), if the kind takes one and it is set.
    cone: Option<Real>,
    /// What acts on the free coordinate.
    drive: FreeDrive,
    /// Anchors from each centre of mass, in body frames (world frame for the world).
    anchor_a: Vec3,
    anchor_b: Vec3,
    axis_a: Vec3,
    axis_b: Vec3,
    reference_a: Vec3,
    reference_b: Vec3,
    relative_rotation: Quat,
    impulses: JointImpulses,
    /// Impulses summed over the step's substeps: linear on b at its anchor, angular.
    total_linear: Vec3,
    total_angular: Vec3,
    /// A ball joint's point block K⁻¹, from the anchors at its first solve in the substep
    /// (`Some(None)`: K is singular there); see [`point_inverse_mass`].
    point_mass: Option<Option<Mat3>>,
    /// A ball joint with nothing else on it (no cone, no drive): the point block is all
    /// there is, and the passes go straight to it (the row builders cost the joint grid
    /// a tenth of its time finding they had nothing to build).
    plain_ball: bool,
    /// Where this joint's hard block sits in the solver's list of them (made once per
    /// frame, see `block::Block`); `None` for joints without hard rows solved as a block
    /// (ball and distance joints).
    pub block: Option<usize>,
    /// The chain of joints through light bodies this joint belongs to (see
    /// `joint_chain.rs`), whose block solves its hard rows instead of its own.
    pub chain: Option<usize>,
    /// The coordinate's armature (see `JointDef::armature`; 0: none) and its flywheel's
    /// rate in the substep (see `joint_armature.rs`).
    armature: Real,
    flywheel: Real,
}

/// Where the geometry of a joint stands at the bodies' current poses. Poses change only
/// in the drift, so the solver keeps one per joint ([`JointConstraint::frame`]) and makes
/// it again after each drift: the warm start, the solve pass and (after the drift) the
/// relax pass and the totals each made their own before, three per substep where one
/// does (the frame was 13 % of the joint grid's time).
pub(crate) struct Frame {
    sa: Side,
    sb: Side,
    ra: Vec3,
    rb: Vec3,
    /// p_b − p_a: the anchors' separation.
    d: Vec3,
}

impl JointConstraint {
    /// Whether the joint locks the bodies' relative rotation in some direction (hinge,
    /// slider, fixed): such joints keep their spring in islands with a hub (see `passes`).
    pub(super) fn locks_rotation(&self) -> bool {
        self.spec.locks_rotation()
    }

    /// Whether either of its bodies is flagged in `flags` (per body; empty: none is).
    pub(super) fn on(&self, flags: &[bool]) -> bool {
        let flagged = |k: Option<usize>| k.is_some_and(|k| flags.get(k).copied().unwrap_or(false));
        flagged(self.a) || flagged(self.b)
    }

    /// The constraint for `joint`, with dense body indices (`None`: the world) and local
    /// centres of mass.
    pub fn new(index: usize, joint: &Joint, bodies: [(Option<usize>, Vec3); 2]) -> Self {
        let [(a, center_a), (b, center_b)] = bodies;
        let spec = joint.def.kind.spec();
        let options = joint.def.kind.options();
        let drive = FreeDrive::of(spec.free, &options, joint.length);
        let plain_ball = spec.linear == LinearLock::Point
            && spec.angular == AngularLock::Free
            && options.cone.is_none()
            && drive.is_idle();
        JointConstraint {
            joint: index,
            a,
            b,
            spec,
            cone: options.cone,
            drive,
            anchor_a: joint.def.anchor - center_a,
            anchor_b: joint.def.other_anchor - center_b,
            axis_a: joint.axis,
            axis_b: joint.other_axis,
            reference_a: joint.reference,
            reference_b: joint.other_reference,
            relative_rotation: joint.relative_rotation,
            impulses: joint.impulses,
            total_linear: Vec3::ZERO,
            total_angular: Vec3::ZERO,
            point_mass: None,
            plain_ball,
            block: None,
            chain: None,
            armature: joint.def.armature,
            flywheel: 0.0,
        }
    }

    /// Whether the joint has hard rows solved as one block (see `joint_rows.rs`): a kind
    /// with none (a distance joint) skips the block solve, which would change nothing, and
    /// a ball joint's point is solved apart.
    pub fn has_block(&self) -> bool {
        !self.point_apart()
            && (self.spec.linear != LinearLock::Free || self.spec.angular != AngularLock::Free)
    }

    /// The joint's hard block at frame `fr`, from `blocks` (the solver's, emptied after
    /// each drift), made there if missing.
    fn block<'b, B: BlockSlots + ?Sized>(
        &self,
        fr: &Frame,
        blocks: &'b mut B,
    ) -> Option<&'b Block> {
        let slot = blocks.slot(self.block?);
        if !slot.ready {
            slot.refresh(fr, |hard| self.hard_rows(fr, hard))?;
        }
        Some(slot)
    }

    /// Dense indices of the two bodies (`None`: the world).
    pub fn bodies(&self) -> [Option<usize>; 2] {
        [self.a, self.b]
    }

    /// Whether the solver moves either body.
    pub fn active(&self, sims: &[BodySim]) -> bool {
        [self.a, self.b]
            .into_iter()
            .any(|k| k.is_some_and(|k| sims[k].moves))
    }

    /// The joint's frame at the bodies' poses in `sims`.
    pub fn frame(&self, sims: &[BodySim]) -> Frame {
        let mut fr = Frame {
            sa: Side::WORLD,
            sb: Side::WORLD,
            ra: Vec3::ZERO,
            rb: Vec3::ZERO,
            d: Vec3::ZERO,
        };
        self.write_frame(sims, &mut fr);
        fr
    }

    /// Overwrites `fr` with [`JointConstraint::frame`], field by field: returned whole, the
    /// 400-byte frame went through a memcpy (3 % of the joint grid's time).
    pub fn write_frame(&self, sims: &[BodySim], fr: &mut Frame) {
        fr.sa.write(sims, self.a);
        fr.sb.write(sims, self.b);
        fr.ra = fr.sa.q * self.anchor_a;
        fr.rb = fr.sb.q * self.anchor_b;
        fr.d = (fr.sb.x + fr.rb) - (fr.sa.x + fr.ra);
    }

    /// Runs `f` with both bodies' states; the world's is a still copy.
    #[inline(always)]
    fn with_states<R, S: PairAccess + ?Sized>(
        &self,
        states: &mut S,
        f: impl FnOnce(&mut BodyState, &mut BodyState) -> R,
    ) -> R {
        states.with_pair(self.a, self.b, f)
    }

    /// Applies the accumulated impulses again (every substep).
    pub fn warm_start<S: PairAccess + ?Sized, B: BlockSlots + ?Sized>(
        &mut self,
        fr: &Frame,
        states: &mut S,
        blocks: &mut B,
    ) {
        self.point_mass = None;
        if self.plain_ball {
            let p = point_impulse(&self.impulses);
            self.with_states(states, |a, b| apply_point(p, fr, a, b));
            return;
        }
        let imp = self.impulses;
        let mut sum = Row::ZERO;
        if let Some(h) = self.block(fr, blocks).map(|b| &b.hard) {
            for (row, lambda) in h.rows[..h.count].iter().zip(imp.hard) {
                sum.add_scaled(row, lambda);
            }
        }
        if let Some(row) = self.free_line(fr) {
            sum.add_scaled(&row, free_impulse(&imp));
        }
        if let Some((row, _)) = self.cone_row(fr) {
            sum.add_scaled(&row, imp.cone);
        }
        let point = self.point_apart().then(|| point_impulse(&imp));
        self.with_states(states, |a, b| {
            if let Some(p) = point {
                apply_point(p, fr, a, b);
            }
            sum.apply(1.0, &fr.sa, &fr.sb, a, b);
        });
    }

    /// One pass over the joint's rows; a chain's member leaves its free row and hard rows
    /// to its chain (`joint_chain.rs`).
    pub fn solve<S: PairAccess + ?Sized, B: BlockSlots + ?Sized>(
        &mut self,
        fr: &Frame,
        states: &mut S,
        pass: &JointPass,
        blocks: &mut B,
    ) {
        if self.plain_ball {
            let k_inv = *self
                .point_mass
                .get_or_insert_with(|| point_inverse_mass(fr));
            let acc = point_impulse(&self.impulses);
            let p = self.with_states(states, |a, b| solve_point(acc, k_inv, fr, pass, a, b));
            self.impulses.hard[..3].copy_from_slice(&p.to_array());
            return;
        }
        let mut imp = self.impulses;
        let drive = self.drive;
        let cone = self.cone_row(fr);
        // Nothing acts on an idle free row: not even its angle is wanted (an atan2).
        let (free, hard) = match self.chain {
            Some(_) => (None, None),
            None if drive.is_idle() => (None, self.block(fr, blocks)),
            None => (self.free_row(fr), self.block(fr, blocks)),
        };
        let point_mass = self.point_apart().then(|| {
            *self
                .point_mass
                .get_or_insert_with(|| point_inverse_mass(fr))
        });
        self.with_states(states, |a, b| {
            if let Some((row, coordinate)) = free {
                solve_free(
                    &drive,
                    Line::own(row, fr),
                    coordinate,
                    fr,
                    pass,
                    &mut imp,
                    a,
                    b,
                );
            }
            if let Some((row, c)) = cone {
                imp.cone = solve_limit(Line::own(row, fr), c, imp.cone, fr, pass, a, b);
            }
            if let Some(block) = hard {
                imp.hard = solve_hard(block, imp.hard, fr, pass, a, b);
            }
            if let Some(k_inv) = point_mass {
                let p = solve_point(point_impulse(&imp), k_inv, fr, pass, a, b);
                imp.hard[..3].copy_from_slice(&p.to_array());
            }
        });
        self.impulses = imp;
    }

    /// One pass over `part` of the free row's drive (one of `FreeDrive::parts`), the row
    /// as its chain sees it, at `coordinate`; returns the impulse it added along the row.
    fn solve_free_part(
        &mut self,
        part: &FreeDrive,
        (line, coordinate): (Line, Real),
        (fr, pass): (&Frame, &JointPass),
        states: &mut [BodyState],
    ) -> Real {
        let mut imp = self.impulses;
        self.with_states(states, |a, b| {
            solve_free(part, line, coordinate, fr, pass, &mut imp, a, b);
        });
        let delta = free_impulse(&imp) - free_impulse(&self.impulses);
        self.impulses = imp;
        delta
    }

    /// Adds the substep's impulses to the step's totals: the force on `other` at its
    /// anchor and the pure torques.
    pub fn add_to_totals<B: BlockSlots + ?Sized>(&mut self, fr: &Frame, blocks: &mut B) {
        let imp = self.impulses;
        if self.plain_ball {
            // The point's impulse is all there is, and it is already a world vector.
            self.total_linear += point_impulse(&imp);
            return;
        }
        let hard = self.block(fr, blocks).map(|b| &b.hard);
        let free = self.free_line(fr).map(|row| (row, free_impulse(&imp)));
        let cone = self.cone_row(fr).map(|(row, _)| (row, imp.cone));
        let rows = hard
            .iter()
            .flat_map(|h| h.rows[..h.count].iter().copied().zip(imp.hard));
        for (row, lambda) in rows.chain(free).chain(cone) {
            self.total_linear += row.lin * lambda;
            if row.lin == Vec3::ZERO {
                self.total_angular += row.ang_b * lambda;
            }
        }
        if self.point_apart() {
            self.total_linear += point_impulse(&imp);
        }
    }

    /// Writes the impulses, reaction and breakage back into the joint.
    pub fn store(&self, joint: &mut Joint, dt: Real) {
        joint.impulses = self.impulses;
        joint.reaction_force = self.total_linear / dt;
        joint.reaction_torque = self.total_angular / dt;
        if let Some(limit) = joint.def.break_force.filter(|_| joint.enabled) {
            if joint.reaction_force.length() > limit {
                joint.broken = true;
                joint.impulses = JointImpulses::default();
            }
        }
    }

    /// Whether the point constraint is solved on its own, as a 3×3 block with glam: a
    /// point lock with no angular lock (a ball joint) has no other equality rows to couple
    /// it to (the joint grid benchmark spent a third of its time in the general
    /// elimination).
    fn point_apart(&self) -> bool {
        self.spec.linear == LinearLock::Point && self.spec.angular == AngularLock::Free
    }
}
