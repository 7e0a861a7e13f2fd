//! The solver's settings and what each step derives from them: the substep (`StepTime`),
//! the contacts' bias rule and the joints' passes, with the softness of each.

use super::contact::BiasRule;
use super::joint::JointPass;
use super::softness::Softness;
use crate::math::Real;

/// Which velocity solver handles contacts.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum SolverKind {
    /// Substepped soft constraints with relax and restitution passes (the default).
    #[default]
    SoftStep,
    /// Classic projected Gauss–Seidel sequential impulses with Baumgarte correction.
    Pgs,
}

impl SolverKind {
    /// The name used in scene files and on the command line.
    pub fn name(self) -> &'static str {
        match self {
            SolverKind::SoftStep => "soft_step",
            SolverKind::Pgs => "pgs",
        }
    }
    /// The kind called `name`.
    pub fn from_name(name: &str) -> Option<SolverKind> {
        [SolverKind::SoftStep, SolverKind::Pgs]
            .into_iter()
            .find(|k| k.name() == name)
    }
}

/// How islands that are joint trees are solved (see `solver/articulation.rs`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum JointTrees {
    /// As every other island: bodies in world coordinates, joints as constraints in the
    /// soft step (the default).
    #[default]
    Maximal,
    /// In the joints' own coordinates (hinge angles, slider travels, ball joints'
    /// relative orientations) by the
    /// articulated-body algorithm: exact joints, and a contact-free tree's step at a
    /// fraction of the cost. Trees only: other islands are solved as with `Maximal`.
    Reduced,
}

impl JointTrees {
    /// The name used in scene files and on the command line.
    pub fn name(self) -> &'static str {
        match self {
            JointTrees::Maximal => "maximal",
            JointTrees::Reduced => "reduced",
        }
    }

    /// The choice called `name`.
    pub fn from_name(name: &str) -> Option<JointTrees> {
        [JointTrees::Maximal, JointTrees::Reduced]
            .into_iter()
            .find(|k| k.name() == name)
    }
}

/// Solver settings; `Default` is the soft step with 4 substeps and 1 iteration.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SolverSettings {
    /// Soft step or PGS.
    pub kind: SolverKind,
    /// Substeps per step.
    pub substeps: u32,
    /// Solve passes per substep (and relax passes, for the soft step).
    pub iterations: u32,
    /// Contact stiffness (Hz), capped at a quarter of the substep rate.
    pub contact_hertz: Real,
    /// Contact damping ratio (dimensionless).
    pub contact_damping_ratio: Real,
    /// Baumgarte factor for PGS (fraction of the error corrected per substep).
    pub baumgarte: Real,
    /// Stiffness of joints' drift correction (Hz), capped at a quarter of the substep rate.
    pub joint_hertz: Real,
    /// Damping ratio of joints' drift correction.
    pub joint_damping_ratio: Real,
    /// How joint trees are solved.
    pub joint_trees: JointTrees,
}

impl Default for SolverSettings {
    fn default() -> Self {
        SolverSettings {
            kind: SolverKind::SoftStep,
            substeps: 4,
            iterations: 1,
            contact_hertz: 60.0,
            contact_damping_ratio: 10.0,
            baumgarte: 0.2,
            joint_hertz: 1000.0,
            joint_damping_ratio: 0.5,
            joint_trees: JointTrees::Maximal,
        }
    }
}

/// The times of one step, derived once: the step's start `t`, its length `dt`, and the
/// solver's `substeps` of `h` = `dt` / `substeps` (`inv_h` = 1 / `h`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct StepTime {
    pub t: Real,
    pub dt: Real,
    pub substeps: u32,
    pub h: Real,
    pub inv_h: Real,
}

impl StepTime {
    pub fn new(t: Real, dt: Real, settings: &SolverSettings) -> StepTime {
        let substeps = settings.substeps.max(1);
        let h = dt / substeps as Real;
        StepTime {
            t,
            dt,
            substeps,
            h,
            inv_h: 1.0 / h,
        }
    }
}

/// Lengths and speeds the solver works with, all scaled from the world's length unit.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Scales {
    pub linear_slop: Real,
    pub max_push: Real,
    /// Floor of the bounce threshold (see `restitution::bounce_threshold`).
    pub restitution_threshold: Real,
}

/// How joints treat drift in the solve and the relax passes: the joint spring (capped at
/// a quarter of the substep rate) then none, for the soft step; Baumgarte then nothing
/// (there is no relax pass) for PGS.
pub(super) fn joint_passes(settings: &SolverSettings, time: &StepTime) -> (JointPass, JointPass) {
    let soft = biased_softness(
        settings,
        settings.joint_hertz,
        settings.joint_damping_ratio,
        time,
    );
    let pass = |soft, bias| JointPass {
        soft,
        bias,
        inv_h: time.inv_h,
        h: time.h,
    };
    (pass(soft, true), pass(Softness::RIGID, false))
}

/// Position correction in a biased pass: for the soft step a spring of `hertz` (capped at
/// a quarter of the substep rate, as in Box2D) and damping ratio `zeta`; for PGS the rigid
/// row with Baumgarte's β/h.
fn biased_softness(
    settings: &SolverSettings,
    hertz: Real,
    zeta: Real,
    time: &StepTime,
) -> Softness {
    match settings.kind {
        SolverKind::SoftStep => Softness::new(hertz.min(0.25 * time.inv_h), zeta, time.h),
        SolverKind::Pgs => Softness {
            bias_rate: settings.baumgarte * time.inv_h,
            mass_scale: 1.0,
            impulse_scale: 0.0,
        },
    }
}

/// Contacts' position correction and the lengths and speeds they work with.
pub(super) fn bias_rule(settings: &SolverSettings, scales: &Scales, time: &StepTime) -> BiasRule {
    BiasRule {
        inv_h: time.inv_h,
        softness: biased_softness(
            settings,
            settings.contact_hertz,
            settings.contact_damping_ratio,
            time,
        ),
        slop: if settings.kind == SolverKind::Pgs {
            scales.linear_slop
        } else {
            0.0
        },
        max_push: scales.max_push,
        slip_speed: scales.linear_slop,
        stiffened: false,
    }
}

crate::codec::codec_unit_enum!(SolverKind { SoftStep, Pgs });
crate::codec::codec_unit_enum!(JointTrees { Maximal, Reduced });
crate::codec::codec_struct!(SolverSettings {
    kind,
    substeps,
    iterations,
    contact_hertz,
    contact_damping_ratio,
    baumgarte,
    joint_hertz,
    joint_damping_ratio,
    joint_trees
});
crate::codec::codec_struct!(Scales {
    linear_slop,
    max_push,
    restitution_threshold
});
