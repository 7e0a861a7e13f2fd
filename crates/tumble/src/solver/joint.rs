//! Joint constraints in the soft step.
//!
//! Each joint is solved in the order Box2D uses (the softest first, the hard constraint
//! last, so it has the final word): spring, motor, limits, then the hard rows as one
//! block. The hard rows are the joint's equalities, each a Jacobian row
//! Ċ = lin·(v_b − v_a) + ang_b·ω_b − ang_a·ω_a:
//!
//! ```text
//! point (ball, hinge, fixed)  lin = eᵢ, ang = r × eᵢ       C = eᵢ·(p_b − p_a)
//! across a slider's axis      lin = pᵢ, ang_a = (r_a + d) × pᵢ, ang_b = r_b × pᵢ
//! across a hinge's axis       ang = bᵢ (the two directions ⊥ the axis), C = bᵢ·(h_a × h_b)
//! angular lock (fixed, slider) ang = eᵢ, C = the rotation of q_b from q_a·q_rel
//! ```
//!
//! solved together, K = J M⁻¹ Jᵀ (up to 6×6) by Gaussian elimination. Solving the point
//! and the lock one after the other instead leaves them fighting: a slider's across rows
//! push at the anchor's lever arm and turn the body, the lock turns it back, and the body
//! drifted 4 cm off a tilted axis in a second. Limits, motors, springs and distance rows
//! are 1D rows. The hard rows use
//! the joint softness (a spring at a quarter of the substep rate in the biased pass, none
//! in the relax pass), so drift is corrected without the push-out becoming motion, as for
//! contacts. Anchors are recomputed from the current poses every pass: a joint turns far
//! within a step (a pendulum's anchor swings), unlike a contact.

use super::body::{BodySim, BodyState};
use super::softness::Softness;
use crate::joint::{Joint, JointImpulses, JointKind, JointSpring, Motor};
use crate::math::{orthonormal_basis, Mat3, Quat, Real, Vec3};

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
    fn of(sims: &[BodySim], k: Option<usize>) -> Side {
        match k.map(|k| &sims[k]) {
            Some(s) => Side {
                x: s.x,
                q: s.q,
                inv_mass: s.inv_mass,
                mask: s.linear_mask,
                inv_inertia: s.inv_inertia,
                moves: s.moves,
            },
            None => Side {
                x: Vec3::ZERO,
                q: Quat::IDENTITY,
                inv_mass: 0.0,
                mask: Vec3::ZERO,
                inv_inertia: Mat3::ZERO,
                moves: false,
            },
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
    kind: JointKind,
    /// Anchors from each centre of mass, in body frames (world frame for the world).
    anchor_a: Vec3,
    anchor_b: Vec3,
    axis_a: Vec3,
    axis_b: Vec3,
    reference_a: Vec3,
    reference_b: Vec3,
    relative_rotation: Quat,
    length: Real,
    impulses: JointImpulses,
    /// Impulses summed over the step's substeps: linear on b at its anchor, angular.
    total_linear: Vec3,
    total_angular: Vec3,
    /// A ball joint's point block K⁻¹, from the anchors at its first solve in the substep
    /// (`Some(None)`: K is singular there); see [`point_inverse_mass`].
    point_mass: Option<Option<Mat3>>,
}

/// Where the geometry of a joint stands in a pass.
struct Frame {
    sa: Side,
    sb: Side,
    ra: Vec3,
    rb: Vec3,
    /// p_b − p_a: the anchors' separation.
    d: Vec3,
}

impl JointConstraint {
    /// The constraint for `joint`, with dense body indices (`None`: the world) and local
    /// centres of mass.
    pub fn new(index: usize, joint: &Joint, bodies: [(Option<usize>, Vec3); 2]) -> Self {
        let [(a, center_a), (b, center_b)] = bodies;
        JointConstraint {
            joint: index,
            a,
            b,
            kind: joint.def.kind,
            anchor_a: joint.def.anchor - center_a,
            anchor_b: joint.def.other_anchor - center_b,
            axis_a: joint.axis,
            axis_b: joint.other_axis,
            reference_a: joint.reference,
            reference_b: joint.other_reference,
            relative_rotation: joint.relative_rotation,
            length: joint.length,
            impulses: joint.impulses,
            total_linear: Vec3::ZERO,
            total_angular: Vec3::ZERO,
            point_mass: None,
        }
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

    fn frame(&self, sims: &[BodySim]) -> Frame {
        let (sa, sb) = (Side::of(sims, self.a), Side::of(sims, self.b));
        let (ra, rb) = (sa.q * self.anchor_a, sb.q * self.anchor_b);
        Frame {
            sa,
            sb,
            ra,
            rb,
            d: (sb.x + rb) - (sa.x + ra),
        }
    }

    /// Runs `f` with both bodies' states; the world's is a still copy.
    fn with_states<R>(
        &self,
        states: &mut [BodyState],
        f: impl FnOnce(&mut BodyState, &mut BodyState) -> R,
    ) -> R {
        // Made only when needed: two of these per call cost the joint grid a tenth of its
        // time in copies.
        let still = || BodyState {
            v: Vec3::ZERO,
            w: Vec3::ZERO,
            dp: Vec3::ZERO,
            dr: Mat3::IDENTITY,
        };
        match (self.a, self.b) {
            (Some(a), Some(b)) => match states.get_disjoint_mut([a, b]) {
                Ok([x, y]) => f(x, y),
                Err(_) => f(&mut still(), &mut still()),
            },
            (Some(a), None) => f(&mut states[a], &mut still()),
            (None, Some(b)) => f(&mut still(), &mut states[b]),
            (None, None) => f(&mut still(), &mut still()),
        }
    }

    /// Applies the accumulated impulses again (every substep).
    pub fn warm_start(&mut self, sims: &[BodySim], states: &mut [BodyState]) {
        self.point_mass = None;
        let fr = self.frame(sims);
        let imp = self.impulses;
        let hard = self.hard_rows(&fr);
        let free = self.free_rows(&fr);
        let cone = self.cone_row(&fr);
        let point = self.point_apart().then(|| point_impulse(&imp));
        self.with_states(states, |a, b| {
            if let Some(p) = point {
                apply_point(p, &fr, a, b);
            }
            for (row, lambda) in hard
                .iter()
                .flat_map(|h| h.rows[..h.count].iter().zip(imp.hard))
            {
                row.apply(lambda, &fr.sa, &fr.sb, a, b);
            }
            if let Some((row, _)) = free {
                row.apply(free_impulse(&imp), &fr.sa, &fr.sb, a, b);
            }
            if let Some((row, _)) = cone {
                row.apply(imp.cone, &fr.sa, &fr.sb, a, b);
            }
        });
    }

    /// One pass over the joint's rows.
    pub fn solve(&mut self, sims: &[BodySim], states: &mut [BodyState], pass: &JointPass) {
        let fr = self.frame(sims);
        let mut imp = self.impulses;
        let kind = self.kind;
        let rest = self.length;
        let free = self.free_rows(&fr);
        let cone = self.cone_row(&fr);
        let hard = self.hard_rows(&fr);
        let point_mass = self.point_apart().then(|| {
            *self
                .point_mass
                .get_or_insert_with(|| point_inverse_mass(&fr))
        });
        self.with_states(states, |a, b| {
            if let Some((row, coordinate)) = free {
                solve_free(&kind, row, coordinate, rest, &fr, pass, &mut imp, a, b);
            }
            if let Some((row, c)) = cone {
                imp.cone = solve_limit(row, c, imp.cone, &fr, pass, a, b);
            }
            if let Some(hard) = &hard {
                imp.hard = solve_hard(hard, imp.hard, &fr, pass, a, b);
            }
            if let Some(k_inv) = point_mass {
                let p = solve_point(point_impulse(&imp), k_inv, &fr, pass, a, b);
                imp.hard[..3].copy_from_slice(&p.to_array());
            }
        });
        self.impulses = imp;
    }

    /// Adds the substep's impulses to the step's totals: the force on `other` at its
    /// anchor and the pure torques.
    pub fn add_to_totals(&mut self, sims: &[BodySim]) {
        let imp = self.impulses;
        if let JointKind::Ball {
            cone: None,
            twist: None,
        } = self.kind
        {
            // The point's impulse is all there is, and it is already a world vector.
            self.total_linear += point_impulse(&imp);
            return;
        }
        let fr = self.frame(sims);
        let hard = self.hard_rows(&fr);
        let free = self
            .free_rows(&fr)
            .map(|(row, _)| (row, free_impulse(&imp)));
        let cone = self.cone_row(&fr).map(|(row, _)| (row, imp.cone));
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
        if let Some(limit) = joint.def.break_force {
            if joint.reaction_force.length() > limit {
                joint.broken = true;
                joint.impulses = JointImpulses::default();
            }
        }
    }

    /// Whether the point constraint is solved on its own, as a 3×3 block with glam: a
    /// ball joint has no other equality rows to couple it to (the joint grid benchmark
    /// spent a third of its time in the general elimination).
    fn point_apart(&self) -> bool {
        matches!(self.kind, JointKind::Ball { .. })
    }

    /// The joint's equality rows (see the module's table); a ball joint's point is solved
    /// apart (see `point_apart`).
    fn hard_rows(&self, fr: &Frame) -> Option<HardRows> {
        if self.point_apart() {
            return None;
        }
        let mut hard = HardRows {
            rows: [Row::angular(Vec3::ZERO); 6],
            error: [0.0; 6],
            count: 0,
        };
        if matches!(self.kind, JointKind::Hinge { .. } | JointKind::Fixed) {
            for e in [Vec3::X, Vec3::Y, Vec3::Z] {
                let row = Row {
                    lin: e,
                    ang_a: fr.ra.cross(e),
                    ang_b: fr.rb.cross(e),
                };
                hard.push(row, e.dot(fr.d));
            }
        }
        match self.kind {
            JointKind::Hinge { .. } => {
                let (ha, hb) = (fr.sa.q * self.axis_a, fr.sb.q * self.axis_b);
                let [b1, b2] = orthonormal_basis(ha);
                let error = ha.cross(hb);
                hard.push(Row::angular(b1), b1.dot(error));
                hard.push(Row::angular(b2), b2.dot(error));
            }
            JointKind::Slider { .. } => {
                let axis = self.axis(fr);
                for p in orthonormal_basis(axis) {
                    let row = Row {
                        lin: p,
                        ang_a: (fr.ra + fr.d).cross(p),
                        ang_b: fr.rb.cross(p),
                    };
                    hard.push(row, p.dot(fr.d));
                }
            }
            _ => {}
        }
        if matches!(self.kind, JointKind::Fixed | JointKind::Slider { .. }) {
            let target = fr.sa.q * self.relative_rotation;
            let mut e = fr.sb.q * target.inverse();
            if e.w < 0.0 {
                e = -e;
            }
            let error = 2.0 * Vec3::new(e.x, e.y, e.z);
            for axis in [Vec3::X, Vec3::Y, Vec3::Z] {
                hard.push(Row::angular(axis), axis.dot(error));
            }
        }
        Some(hard)
    }

    /// The slider's (or hinge's) axis in the world, carried by body a.
    fn axis(&self, fr: &Frame) -> Vec3 {
        fr.sa.q * self.axis_a
    }

    /// The row of the joint's free coordinate and the coordinate's value: the hinge
    /// angle, the slider translation and a ball joint's twist, each of `body` relative to
    /// `other` (a motor's positive speed turns or pushes `body` the positive way about or
    /// along its axis), or a distance joint's length.
    fn free_rows(&self, fr: &Frame) -> Option<(Row, Real)> {
        match self.kind {
            JointKind::Hinge { .. } => {
                let axis = self.axis(fr);
                let (ra, rb) = (fr.sa.q * self.reference_a, fr.sb.q * self.reference_b);
                let angle = axis.dot(rb.cross(ra)).atan2(ra.dot(rb));
                Some((Row::angular(axis).negated(), angle))
            }
            JointKind::Ball { twist: Some(_), .. } => {
                let (ta, tb) = (fr.sa.q * self.axis_a, fr.sb.q * self.axis_b);
                let mid = (ta + tb).try_normalize()?;
                let flat = |r: Vec3| (r - mid * mid.dot(r)).try_normalize();
                let ra = flat(fr.sa.q * self.reference_a)?;
                let rb = flat(fr.sb.q * self.reference_b)?;
                let angle = mid.dot(rb.cross(ra)).atan2(ra.dot(rb));
                Some((Row::angular(mid).negated(), angle))
            }
            JointKind::Slider { .. } => {
                let axis = self.axis(fr);
                let row = Row {
                    lin: axis,
                    ang_a: (fr.ra + fr.d).cross(axis),
                    ang_b: fr.rb.cross(axis),
                };
                Some((row.negated(), -axis.dot(fr.d)))
            }
            JointKind::Distance { .. } => {
                let length = fr.d.length();
                let n = if length > 1e-9 {
                    fr.d / length
                } else {
                    fr.sa.q * self.axis_a
                };
                let row = Row {
                    lin: n,
                    ang_a: fr.ra.cross(n),
                    ang_b: fr.rb.cross(n),
                };
                Some((row, length))
            }
            _ => None,
        }
    }

    /// A ball joint's swing-cone row and its margin (cone − swing angle), if limited.
    fn cone_row(&self, fr: &Frame) -> Option<(Row, Real)> {
        let JointKind::Ball {
            cone: Some(cone), ..
        } = self.kind
        else {
            return None;
        };
        let (ta, tb) = (fr.sa.q * self.axis_a, fr.sb.q * self.axis_b);
        let swing = ta.cross(tb);
        let angle = swing.length().atan2(ta.dot(tb));
        let n = swing
            .try_normalize()
            .unwrap_or_else(|| orthonormal_basis(ta)[0]);
        // The margin shrinks as b swings away about n: Ċ = −n·(ω_b − ω_a).
        Some((Row::angular(n).negated(), cone - angle))
    }
}

/// The point constraint's accumulated impulse (on `other`, world frame).
fn point_impulse(imp: &JointImpulses) -> Vec3 {
    Vec3::new(imp.hard[0], imp.hard[1], imp.hard[2])
}

/// Applies a linear impulse `p` at the anchors: −p on `body`, +p on `other`.
fn apply_point(p: Vec3, fr: &Frame, a: &mut BodyState, b: &mut BodyState) {
    if fr.sa.moves {
        a.v -= fr.sa.mask * p * fr.sa.inv_mass;
        a.w -= fr.sa.inv_inertia * fr.ra.cross(p);
    }
    if fr.sb.moves {
        b.v += fr.sb.mask * p * fr.sb.inv_mass;
        b.w += fr.sb.inv_inertia * fr.rb.cross(p);
    }
}

/// [r]× M [r]×: the turning part of a point's inverse effective mass is minus this.
/// Column i is r × (M (r × eᵢ)), and r × eᵢ has two terms: half the work of two full
/// matrix products.
fn skew_sandwich(r: Vec3, m: Mat3) -> Mat3 {
    let column = |turned: Vec3| r.cross(turned);
    Mat3::from_cols(
        column(m.y_axis * r.z - m.z_axis * r.y),
        column(m.z_axis * r.x - m.x_axis * r.z),
        column(m.x_axis * r.y - m.y_axis * r.x),
    )
}

/// The inverse of the point constraint's 3×3 block,
/// K = (m_a⁻¹ + m_b⁻¹) 1 − [r_a]× I_a⁻¹ [r_a]× − [r_b]× I_b⁻¹ [r_b]×, or `None` where it is
/// singular. Computed once a substep and kept for its relax pass: the inverse inertias are
/// the step's start values anyway, and the velocity error is always measured at the
/// current anchors, so a K from before the drift only changes how fast the passes
/// converge. Measured on the joint grid benchmark: 7 % fewer instructions than a K per
/// pass, and the largest joint gap 6.5 mm instead of 6.8 mm. Once a step (as Box2D and
/// Rapier prepare their effective masses) saved 14 % but let the gap grow to 7.5 mm.
fn point_inverse_mass(fr: &Frame) -> Option<Mat3> {
    let k = Mat3::from_diagonal(fr.sa.mask * fr.sa.inv_mass + fr.sb.mask * fr.sb.inv_mass)
        - skew_sandwich(fr.ra, fr.sa.inv_inertia)
        - skew_sandwich(fr.rb, fr.sb.inv_inertia);
    let det = k.determinant();
    let scale = k.x_axis.x.abs().max(k.y_axis.y.abs()).max(k.z_axis.z.abs());
    (det.abs() > 1e-12 * scale.powi(3)).then(|| k.inverse())
}

/// The point constraint as one 3×3 block, with `k_inv` from [`point_inverse_mass`].
fn solve_point(
    acc: Vec3,
    k_inv: Option<Mat3>,
    fr: &Frame,
    pass: &JointPass,
    a: &mut BodyState,
    b: &mut BodyState,
) -> Vec3 {
    let cdot = b.v + b.w.cross(fr.rb) - a.v - a.w.cross(fr.ra);
    let bias = if pass.bias {
        fr.d * pass.soft.bias_rate
    } else {
        Vec3::ZERO
    };
    let x = if let Some(k_inv) = k_inv {
        k_inv * -(cdot + bias)
    } else {
        // A direction no body can move in (a planar body out of its plane): the general
        // elimination leaves it alone.
        let hard = HardRows {
            rows: [
                Vec3::X,
                Vec3::Y,
                Vec3::Z,
                Vec3::ZERO,
                Vec3::ZERO,
                Vec3::ZERO,
            ]
            .map(|e| Row {
                lin: e,
                ang_a: fr.ra.cross(e),
                ang_b: fr.rb.cross(e),
            }),
            error: [fr.d.x, fr.d.y, fr.d.z, 0.0, 0.0, 0.0],
            count: 3,
        };
        let acc6 = [acc.x, acc.y, acc.z, 0.0, 0.0, 0.0];
        let total = solve_hard(&hard, acc6, fr, pass, a, b);
        return Vec3::new(total[0], total[1], total[2]);
    };
    let impulse = x * pass.soft.mass_scale - acc * pass.soft.impulse_scale;
    apply_point(impulse, fr, a, b);
    acc + impulse
}

/// The hard rows of a joint: Jacobians and position errors.
struct HardRows {
    rows: [Row; 6],
    error: [Real; 6],
    count: usize,
}

impl HardRows {
    fn push(&mut self, row: Row, error: Real) {
        self.rows[self.count] = row;
        self.error[self.count] = error;
        self.count += 1;
    }
}

/// Solves the n×n system `k x = rhs` in place by Gaussian elimination with partial
/// pivoting; a vanishing pivot (a direction no body can move in, such as out of a planar
/// body's plane) leaves that unknown zero.
fn solve_dense(k: &mut [[Real; 6]; 6], rhs: &mut [Real; 6], n: usize) -> [Real; 6] {
    let scale = (0..n).map(|i| k[i][i].abs()).fold(0.0, Real::max);
    let tiny = 1e-12 * scale;
    let mut skip = [false; 6];
    for col in 0..n {
        let pivot = (col..n)
            .max_by(|&i, &j| k[i][col].abs().total_cmp(&k[j][col].abs()))
            .unwrap_or(col);
        k.swap(col, pivot);
        rhs.swap(col, pivot);
        if k[col][col].abs() <= tiny {
            skip[col] = true;
            continue;
        }
        let pivot_row = k[col];
        for i in col + 1..n {
            let f = k[i][col] / pivot_row[col];
            for (kij, pj) in k[i][col..n].iter_mut().zip(&pivot_row[col..n]) {
                *kij -= f * pj;
            }
            rhs[i] -= f * rhs[col];
        }
    }
    let mut x = [0.0; 6];
    for i in (0..n).rev() {
        if skip[i] {
            continue;
        }
        let sum: Real = (i + 1..n).map(|j| k[i][j] * x[j]).sum();
        x[i] = (rhs[i] - sum) / k[i][i];
    }
    x
}

/// One pass over the hard rows as a block; returns the new accumulated impulses.
fn solve_hard(
    hard: &HardRows,
    acc: [Real; 6],
    fr: &Frame,
    pass: &JointPass,
    a: &mut BodyState,
    b: &mut BodyState,
) -> [Real; 6] {
    let n = hard.count;
    let mut k = [[0.0; 6]; 6];
    let mut rhs = [0.0; 6];
    let (sa, sb) = (&fr.sa, &fr.sb);
    for i in 0..n {
        let ri = &hard.rows[i];
        // M⁻¹ Jᵢᵀ, dotted with every row.
        let (va, wa) = (sa.mask * ri.lin * sa.inv_mass, sa.inv_inertia * ri.ang_a);
        let (vb, wb) = (sb.mask * ri.lin * sb.inv_mass, sb.inv_inertia * ri.ang_b);
        for (kj, rj) in k.iter_mut().zip(&hard.rows[..n]) {
            kj[i] = rj.lin.dot(va + vb) + rj.ang_a.dot(wa) + rj.ang_b.dot(wb);
        }
        let bias = if pass.bias {
            pass.soft.bias_rate * hard.error[i]
        } else {
            0.0
        };
        rhs[i] = -(ri.velocity(a, b) + bias);
    }
    let x = solve_dense(&mut k, &mut rhs, n);
    let mut total = acc;
    for i in 0..n {
        let delta = pass.soft.mass_scale * x[i] - pass.soft.impulse_scale * acc[i];
        hard.rows[i].apply(delta, sa, sb, a, b);
        total[i] = acc[i] + delta;
    }
    total
}

/// A one-sided limit row: keeps `margin` ≥ 0 (speculatively while it is positive, as a
/// contact does). Returns the new accumulated impulse (≥ 0).
fn solve_limit(
    row: Row,
    margin: Real,
    acc: Real,
    fr: &Frame,
    pass: &JointPass,
    a: &mut BodyState,
    b: &mut BodyState,
) -> Real {
    let (bias, mass_scale, impulse_scale) = if margin > 0.0 {
        (margin * pass.inv_h, 1.0, 0.0)
    } else if pass.bias {
        (
            margin * pass.soft.bias_rate,
            pass.soft.mass_scale,
            pass.soft.impulse_scale,
        )
    } else {
        (0.0, 1.0, 0.0)
    };
    let delta =
        -row.mass(&fr.sa, &fr.sb) * mass_scale * (row.velocity(a, b) + bias) - impulse_scale * acc;
    let total = (acc + delta).max(0.0);

    row.apply(total - acc, &fr.sa, &fr.sb, a, b);
    total
}

/// The impulse along the free coordinate's row: limits (the upper one's row is negated),
/// motor, spring and rod.
fn free_impulse(imp: &JointImpulses) -> Real {
    imp.lower - imp.upper + imp.motor + imp.spring + imp.axial
}

/// Spring, motor, limits and (distance joints) the rigid rod along the free coordinate.
#[allow(clippy::too_many_arguments)]
fn solve_free(
    kind: &JointKind,
    row: Row,
    coordinate: Real,
    rest: Real,
    fr: &Frame,
    pass: &JointPass,
    imp: &mut JointImpulses,
    a: &mut BodyState,
    b: &mut BodyState,
) {
    let (limits, motor, spring, rod) = match *kind {
        JointKind::Hinge {
            limits,
            motor,
            spring,
        }
        | JointKind::Slider {
            limits,
            motor,
            spring,
        } => (limits, motor, spring, None),
        JointKind::Ball { twist, .. } => (twist, None, None, None),
        JointKind::Distance {
            min, max, spring, ..
        } => {
            let rigid = spring.is_none() && min.is_none() && max.is_none();
            let limits = (min.is_some() || max.is_some()).then(|| {
                [
                    min.unwrap_or(Real::NEG_INFINITY),
                    max.unwrap_or(Real::INFINITY),
                ]
            });
            // A distance spring pulls towards the rest length.
            let spring = spring.map(|s| JointSpring { target: rest, ..s });
            (limits, None, spring, rigid.then_some(rest))
        }
        JointKind::Fixed => return,
    };
    if let Some(s) = spring {
        imp.spring = solve_spring(row, coordinate, &s, imp.spring, fr, pass, a, b);
    }
    if let Some(m) = motor {
        imp.motor = solve_motor(row, &m, imp.motor, fr, pass, a, b);
    }
    if let Some([lower, upper]) = limits {
        if lower.is_finite() {
            imp.lower = solve_limit(row, coordinate - lower, imp.lower, fr, pass, a, b);
        }
        if upper.is_finite() {
            imp.upper = solve_limit(row.negated(), upper - coordinate, imp.upper, fr, pass, a, b);
        }
    }
    if let Some(rest) = rod {
        imp.axial = solve_rod(row, coordinate, rest, imp.axial, fr, pass, a, b);
    }
}

/// The distance joint's rigid rod: the distance held at `rest` by the joint softness.
#[allow(clippy::too_many_arguments)]
fn solve_rod(
    row: Row,
    distance: Real,
    rest: Real,
    acc: Real,
    fr: &Frame,
    pass: &JointPass,
    a: &mut BodyState,
    b: &mut BodyState,
) -> Real {
    let bias = if pass.bias {
        pass.soft.bias_rate * (distance - rest)
    } else {
        0.0
    };
    let delta = -row.mass(&fr.sa, &fr.sb) * pass.soft.mass_scale * (row.velocity(a, b) + bias)
        - pass.soft.impulse_scale * acc;
    row.apply(delta, &fr.sa, &fr.sb, a, b);
    acc + delta
}

#[allow(clippy::too_many_arguments)]
fn solve_spring(
    row: Row,
    coordinate: Real,
    spring: &JointSpring,
    acc: Real,
    fr: &Frame,
    pass: &JointPass,
    a: &mut BodyState,
    b: &mut BodyState,
) -> Real {
    let soft = Softness::new(spring.hertz, spring.damping_ratio, pass.h);
    let bias = soft.bias_rate * (coordinate - spring.target);
    let delta = -row.mass(&fr.sa, &fr.sb) * soft.mass_scale * (row.velocity(a, b) + bias)
        - soft.impulse_scale * acc;
    row.apply(delta, &fr.sa, &fr.sb, a, b);
    acc + delta
}

fn solve_motor(
    row: Row,
    motor: &Motor,
    acc: Real,
    fr: &Frame,
    pass: &JointPass,
    a: &mut BodyState,
    b: &mut BodyState,
) -> Real {
    let limit = motor.max_force * pass.h;
    let delta = -row.mass(&fr.sa, &fr.sb) * (row.velocity(a, b) - motor.speed);
    let total = (acc + delta).clamp(-limit, limit);
    row.apply(total - acc, &fr.sa, &fr.sb, a, b);
    total
}
