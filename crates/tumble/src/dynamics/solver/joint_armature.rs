//! A hinge's or slider's armature: inertia the coordinate itself carries (MuJoCo's
//! `armature`, a geared motor's rotor reflected through its gear), so that its
//! acceleration meets a generalised force −a q̈ acting equally and oppositely on the two
//! bodies, as if the joint's own mass matrix had a more on its diagonal.
//!
//! The solver keeps the armature as a flywheel on the coordinate: a rate w, which no
//! external force moves, started each substep at the coordinate's rate u = J v before the
//! kick plus the lag behind u it ended the last substep with (`JointImpulses::
//! flywheel_lag`, kept in snapshots). Two things act on it:
//!
//! - the coupling, a row holding u = w: its impulse μ pushes the bodies along the free
//!   row and the flywheel back, μ = −(u − w) / (1/m + 1/a), w −= μ/a, for the row's mass
//!   m with the joint's hard rows holding;
//! - the free row's own parts (limits, spring, servo, motor), which move the bodies and
//!   the flywheel together: each is sized by m + a, and of the impulse δ it adds the
//!   bodies keep m δ / (m + a) (the rest, a δ / (m + a), spins the flywheel).
//!
//! Both need the row's mass with the hard rows holding: the hard rows carry most of a
//! coordinate's inertia (a pendulum bob's m l² beside its own I about its centre), and a
//! coupling sized by the row's own mass moved a quarter of the impulse it should per pass
//! and left a pendulum's bob spinning. So every joint with an armature is solved as a
//! chain (`joint_chain.rs`), of one joint when it is in none, whose free row is sized by
//! 1/(K_ff − K_fh K⁻¹ K_hf) and whose impulses are carried on through the hard rows. The
//! flywheel's push on the bodies is an impulse of the free row like the others
//! (`JointImpulses::armature`), warm started and carried with them.
//!
//! Sizing the limits by m alone while the coupling pulled back with m + a made them fight:
//! Gymnasium's ant, whose ankles start outside their limits, flew apart in its first
//! second; with the parts folded as above it stands. And the lag matters: the coupling is
//! one row among the joints' Gauss–Seidel passes, and its unsolved rest, dropped by
//! restarting the flywheel at u each substep, was lost every substep, so a double
//! pendulum with armature on its upper hinge ended 0.026 rad from MuJoCo at dt = 1e-3 s
//! and 0.16 rad at 2e-4 (worse the finer the step); kept, 9e-4 and 1e-4, as without
//! armature.

use super::{BodyState, Frame, JointConstraint, Line, PairAccess, Row};
use crate::math::Real;

impl JointConstraint {
    /// Whether the joint has an armature.
    pub fn has_armature(&self) -> bool {
        self.armature > 0.0
    }

    /// Whether anything acts on the free row as its chain solves it: a drive or an
    /// armature.
    pub fn acts_on_free_row(&self) -> bool {
        !self.drive.is_idle() || self.has_armature()
    }

    /// Starts the substep's flywheel at the coordinate's rate before the kick plus the lag
    /// it ended the last substep with, less what the warm start (which follows) will push
    /// the bodies with: the flywheel takes the opposite.
    pub fn begin_armature<S: PairAccess + ?Sized>(&mut self, fr: &Frame, states: &mut S) {
        let Some(u) = self.coordinate_rate(fr, states) else {
            return;
        };
        let imp = &self.impulses;
        self.flywheel = u + imp.flywheel_lag - imp.armature / self.armature;
    }

    /// Keeps how far the flywheel ran ahead of the coordinate at the substep's end.
    pub fn end_armature<S: PairAccess + ?Sized>(&mut self, fr: &Frame, states: &mut S) {
        if let Some(u) = self.coordinate_rate(fr, states) {
            self.impulses.flywheel_lag = self.flywheel - u;
        }
    }

    /// J v of the free row of a joint with an armature.
    fn coordinate_rate<S: PairAccess + ?Sized>(&self, fr: &Frame, states: &mut S) -> Option<Real> {
        let (row, _) = self.free_row(fr).filter(|_| self.has_armature())?;
        Some(self.with_states(states, |a, b| row.velocity(a, b)))
    }

    /// The line the free row's parts are solved on: `line`'s mass with the armature's.
    pub(super) fn with_armature(&self, line: Line) -> Line {
        Line {
            mass: line.mass + self.armature,
            ..line
        }
    }

    /// One pass of the coupling on `line` (the free row with its mass m within the
    /// joint's chain): pushes the bodies with μ along the row and returns it.
    pub(super) fn couple_armature(
        &mut self,
        line: Line,
        fr: &Frame,
        states: &mut [BodyState],
    ) -> Real {
        let (arm, w) = (self.armature, self.flywheel);
        let mu = self.with_states(states, |a, b| {
            let mu = -(line.velocity(a, b) - w) / (1.0 / line.mass + 1.0 / arm);
            line.row.apply(mu, &fr.sa, &fr.sb, a, b);
            mu
        });
        self.flywheel -= mu / arm;
        self.impulses.armature += mu;
        mu
    }

    /// For an impulse `delta` a part of the free row just added on the line of mass `m`
    /// with the armature's (`with_armature`): gives the flywheel its share, pushes the
    /// bodies back by as much and returns that push.
    pub(super) fn fold_armature(
        &mut self,
        (delta, m): (Real, Real),
        (row, fr): (Row, &Frame),
        states: &mut [BodyState],
    ) -> Real {
        let turn = delta / (m + self.armature);
        let back = -self.armature * turn;
        self.with_states(states, |a, b| row.apply(back, &fr.sa, &fr.sb, a, b));
        self.flywheel += turn;
        self.impulses.armature += back;
        back
    }
}
