//! The rows of a joint, from its kind's description: which rows a lock or a free axis
//! stands for, their Jacobians and their position errors (the table in `joint.rs`).
//!
//! - Hard rows (equalities, solved as one block): the linear lock's rows first, then the
//!   angular lock's, at most six; none for a point lock with no angular lock (the point is
//!   solved apart, see `point_apart`).
//! - The free axis's row, and the value of the free coordinate, on which limits, motor,
//!   spring and rod act (`joint_1d.rs`). A twist is measured only while something acts on
//!   it; the other free axes always have their row, idle or not, since warm-starting it
//!   with a zero impulse is part of the recorded results (it can turn a −0 into a +0).
//! - The swing-cone row, when a `cone` is set.
//!
//! A new kind whose locks and free axis are among these needs no code here; a new lock
//! or free axis is one arm below.

use super::block::HardRows;
use super::{Frame, JointConstraint, Row};
use crate::dynamics::joint::{AngularLock, FreeAxis, LinearLock};
use crate::math::{orthonormal_basis, Real, Vec3};

impl JointConstraint {
    /// Writes the joint's equality rows (see the module's table) into `hard`; `None` when
    /// there are none to solve as a block.
    pub(super) fn hard_rows(&self, fr: &Frame, hard: &mut HardRows) -> Option<()> {
        if !self.has_block() {
            return None;
        }
        hard.count = 0;
        match self.spec.linear {
            LinearLock::Point => {
                for e in [Vec3::X, Vec3::Y, Vec3::Z] {
                    hard.push(point_row(e, fr), e.dot(fr.d));
                }
            }
            LinearLock::AcrossAxis => {
                for p in orthonormal_basis(self.axis(fr)) {
                    hard.push(along_row(p, fr), p.dot(fr.d));
                }
            }
            LinearLock::Free => {}
        }
        match self.spec.angular {
            AngularLock::AcrossAxis => {
                let (ha, hb) = (fr.sa.q * self.axis_a, fr.sb.q * self.axis_b);
                let [b1, b2] = orthonormal_basis(ha);
                let error = ha.cross(hb);
                hard.push(Row::angular(b1), b1.dot(error));
                hard.push(Row::angular(b2), b2.dot(error));
            }
            AngularLock::All => {
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
            AngularLock::Free => {}
        }
        Some(())
    }

    /// The joint's axis in the world, carried by body a (hinge, slider).
    fn axis(&self, fr: &Frame) -> Vec3 {
        fr.sa.q * self.axis_a
    }

    /// The free coordinate's row alone, for the warm start and the totals: the same row
    /// as [`JointConstraint::free_row`]'s without measuring the angle (an `atan2`).
    pub(super) fn free_line(&self, fr: &Frame) -> Option<Row> {
        match self.spec.free? {
            FreeAxis::Rotation => Some(Row::angular(self.axis(fr)).negated()),
            _ => self.free_row(fr).map(|(row, _)| row),
        }
    }

    /// The row of the joint's free coordinate and the coordinate's value: the hinge
    /// angle, the slider translation and a ball joint's twist, each of `body` relative to
    /// `other` (a motor's positive speed turns or pushes `body` the positive way about or
    /// along its axis), or a distance joint's length.
    pub(super) fn free_row(&self, fr: &Frame) -> Option<(Row, Real)> {
        match self.spec.free? {
            FreeAxis::Rotation => {
                let axis = self.axis(fr);
                let (ra, rb) = (fr.sa.q * self.reference_a, fr.sb.q * self.reference_b);
                let angle = axis.dot(rb.cross(ra)).atan2(ra.dot(rb));
                Some((Row::angular(axis).negated(), self.drive.in_window(angle)))
            }
            FreeAxis::Twist => {
                if self.drive.is_idle() {
                    return None;
                }
                let (ta, tb) = (fr.sa.q * self.axis_a, fr.sb.q * self.axis_b);
                let mid = (ta + tb).try_normalize()?;
                let flat = |r: Vec3| (r - mid * mid.dot(r)).try_normalize();
                let ra = flat(fr.sa.q * self.reference_a)?;
                let rb = flat(fr.sb.q * self.reference_b)?;
                let angle = mid.dot(rb.cross(ra)).atan2(ra.dot(rb));
                Some((Row::angular(mid).negated(), self.drive.in_window(angle)))
            }
            FreeAxis::Translation => {
                let axis = self.axis(fr);
                Some((along_row(axis, fr).negated(), -axis.dot(fr.d)))
            }
            FreeAxis::Distance => {
                let length = fr.d.length();
                let n = if length > 1e-9 {
                    fr.d / length
                } else {
                    fr.sa.q * self.axis_a
                };
                Some((point_row(n, fr), length))
            }
        }
    }

    /// The swing-cone row and its margin (cone − swing angle), if a cone is set.
    pub(super) fn cone_row(&self, fr: &Frame) -> Option<(Row, Real)> {
        let cone = self.cone?;
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

/// A linear row along `e` between the two anchors: lin = e, ang = r × e.
pub(super) fn point_row(e: Vec3, fr: &Frame) -> Row {
    Row {
        lin: e,
        ang_a: fr.ra.cross(e),
        ang_b: fr.rb.cross(e),
    }
}

/// A linear row along `p` for a point carried by body a's axis line: b's anchor moves
/// along it, so a's lever arm reaches to b's anchor, r_a + d.
fn along_row(p: Vec3, fr: &Frame) -> Row {
    Row {
        lin: p,
        ang_a: (fr.ra + fr.d).cross(p),
        ang_b: fr.rb.cross(p),
    }
}
