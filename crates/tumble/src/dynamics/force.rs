//! Force elements: gravity, springs, dampers, drag, applied forces and user callbacks.
//!
//! Every element is a function of the state (positions, orientations, velocities), so the
//! multi-stage integrators can evaluate it at their intermediate states. Forces are world
//! frame (N), torques world frame about the centre of mass (N·m).

use crate::dynamics::body::Motion;
use crate::dynamics::body::{Body, BodyKind};
use crate::error::{check, Result};
use crate::id::BodyId;
use crate::limits::MAX_COORDINATE;
use crate::math::{Real, Vec3};

/// Force and torque on one body (world frame, torque about the centre of mass).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Wrench {
    /// Net force (N).
    pub force: Vec3,
    /// Net torque about the centre of mass (N·m).
    pub torque: Vec3,
}

/// The far end of a spring.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum SpringEnd {
    /// A fixed world point (m).
    World(Vec3),
    /// A point on another body, in that body's frame (m).
    Body {
        /// The other body.
        body: BodyId,
        /// The anchor in the other body's frame (m).
        anchor: Vec3,
    },
}

/// A Hookean spring with a parallel damper between `anchor` on `body` and `other`:
/// F = −k (l − l₀) û − b (v_rel·û) û on `body`, the opposite on the other end.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Spring {
    /// The body the spring starts on.
    pub body: BodyId,
    /// Anchor in `body`'s frame (m).
    pub anchor: Vec3,
    /// Where the spring ends.
    pub other: SpringEnd,
    /// Stiffness k (N/m).
    pub stiffness: Real,
    /// Rest length l₀ (m).
    pub rest_length: Real,
    /// Damping b along the spring (N·s/m).
    pub damping: Real,
}

/// Air drag at the centre of mass: F = −c₁ v − c₂ |v| v.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Drag {
    /// The body.
    pub body: BodyId,
    /// Linear coefficient c₁ (N·s/m).
    pub linear: Real,
    /// Quadratic coefficient c₂ (N·s²/m²).
    pub quadratic: Real,
}

/// A constant force at a point of the body, plus a constant torque.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AppliedForce {
    /// The body.
    pub body: BodyId,
    /// Force, world frame (N).
    pub force: Vec3,
    /// Where it acts, body frame (m); `None` is the centre of mass. Off the centre it
    /// also turns the body: τ = r × F.
    pub point: Option<Vec3>,
    /// Extra torque, world frame (N·m).
    pub torque: Vec3,
}

/// One force element.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Force {
    /// Spring and damper.
    Spring(Spring),
    /// Drag.
    Drag(Drag),
    /// Constant force and torque.
    Applied(AppliedForce),
}

impl Force {
    /// Checks the element's values (not its bodies): the rule `World::add_force` applies,
    /// its fields named as the element's (`force: must be finite numbers`).
    pub fn validate(&self) -> Result<()> {
        match self {
            Force::Spring(s) => {
                check::vec3_at_most("anchor", s.anchor, MAX_COORDINATE, "m")?;
                match s.other {
                    SpringEnd::World(p) => {
                        check::vec3_at_most("world_point", p, MAX_COORDINATE, "m")?
                    }
                    SpringEnd::Body { anchor, .. } => {
                        check::vec3_at_most("other_anchor", anchor, MAX_COORDINATE, "m")?
                    }
                }
                check::non_negative("stiffness", s.stiffness)?;
                check::non_negative("rest_length", s.rest_length)?;
                check::non_negative("damping", s.damping)
            }
            Force::Drag(d) => {
                check::non_negative("linear", d.linear)?;
                check::non_negative("quadratic", d.quadratic)
            }
            Force::Applied(a) => {
                check::vec3("force", a.force)?;
                if let Some(p) = a.point {
                    check::vec3_at_most("point", p, MAX_COORDINATE, "m")?;
                }
                check::vec3("torque", a.torque)
            }
        }
    }

    /// The bodies this element acts on.
    pub fn bodies(&self) -> (BodyId, Option<BodyId>) {
        match self {
            Force::Spring(s) => match s.other {
                SpringEnd::World(_) => (s.body, None),
                SpringEnd::Body { body, .. } => (s.body, Some(body)),
            },
            Force::Drag(d) => (d.body, None),
            Force::Applied(a) => (a.body, None),
        }
    }
}

/// A user force: called at every force evaluation with the state being evaluated.
///
/// How often that is per step: bodies touching nothing advance with the world's
/// integrator, which evaluates the forces once (explicit, symplectic and implicit Euler,
/// Störmer–Verlet), twice (midpoint, velocity Verlet) or four times (RK4) a step; bodies
/// in contact or joined go through the solver, once per substep (n + 1 times for n
/// substeps when a joined body touches nothing: its kick is split around the drift).
/// A world with both kinds of body runs both, and every call sees every body (forces
/// on bodies the evaluation does not advance are ignored). A callback can stop the
/// step with [`ForceContext::fail`].
pub type ForceCallback = Box<dyn FnMut(&mut ForceContext<'_>) + Send>;

/// What a [`ForceCallback`] sees and where it writes.
pub struct ForceContext<'a> {
    pub(crate) time: Real,
    pub(crate) bodies: &'a [Body],
    pub(crate) ids: &'a [BodyId],
    pub(crate) motions: &'a [Motion],
    pub(crate) lookup: &'a dyn Fn(BodyId) -> Option<usize>,
    pub(crate) out: &'a mut [Wrench],
    pub(crate) failure: &'a mut Option<String>,
}

/// One body's state as a force evaluation sees it ([`ForceContext::state_at`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EvaluatedState {
    /// World position of the body frame's origin (m).
    pub position: Vec3,
    /// World position of the centre of mass (m).
    pub center_of_mass: Vec3,
    /// Orientation, body frame to world.
    pub orientation: crate::math::Quat,
    /// Velocity of the centre of mass (m/s).
    pub velocity: Vec3,
    /// Angular velocity, world frame (rad/s).
    pub angular_velocity: Vec3,
    /// Mass (kg).
    pub mass: Real,
}

impl ForceContext<'_> {
    /// How many bodies the world has: [`ForceContext::state_at`] takes 0 to this − 1.
    pub fn body_count(&self) -> usize {
        self.motions.len()
    }
    /// Every body's handle, in creation order (the indices of [`ForceContext::state_at`]).
    pub fn body_ids(&self) -> &[BodyId] {
        self.ids
    }
    /// Body `index`'s name (creation order), if it has one.
    pub fn name_at(&self, index: usize) -> Option<&str> {
        self.bodies.get(index)?.name()
    }
    /// Body `index`'s state in this evaluation, bodies in creation order (the order of
    /// `World::body_ids`), or `None` past the last. For reading many bodies at once.
    pub fn state_at(&self, index: usize) -> Option<EvaluatedState> {
        let (m, body) = (self.motions.get(index)?, self.bodies.get(index)?);
        Some(EvaluatedState {
            position: m.x - m.q * body.local_center,
            center_of_mass: m.x,
            orientation: m.q,
            velocity: m.v,
            angular_velocity: m.w,
            mass: body.mass,
        })
    }
    /// Stops the step: no callback is called again in it, the step is undone (the world
    /// is left as it was before it) and `World::step` returns
    /// [`Error::CallbackFailed`](crate::error::Error::CallbackFailed) with `reason`. Only
    /// the first reason in a step is kept.
    pub fn fail(&mut self, reason: impl Into<String>) {
        if self.failure.is_none() {
            *self.failure = Some(reason.into());
        }
    }
    /// Simulation time of the state being evaluated (s).
    pub fn time(&self) -> Real {
        self.time
    }
    /// Centre-of-mass position of `body` in this state (m).
    pub fn position(&self, body: BodyId) -> Option<Vec3> {
        (self.lookup)(body).map(|i| self.motions[i].x)
    }
    /// Centre-of-mass velocity of `body` in this state (m/s).
    pub fn velocity(&self, body: BodyId) -> Option<Vec3> {
        (self.lookup)(body).map(|i| self.motions[i].v)
    }
    /// Angular velocity of `body` in this state (rad/s).
    pub fn angular_velocity(&self, body: BodyId) -> Option<Vec3> {
        (self.lookup)(body).map(|i| self.motions[i].w)
    }
    /// Orientation of `body` in this state.
    pub fn orientation(&self, body: BodyId) -> Option<crate::math::Quat> {
        (self.lookup)(body).map(|i| self.motions[i].q)
    }
    /// Mass of `body` (kg).
    pub fn mass(&self, body: BodyId) -> Option<Real> {
        (self.lookup)(body).map(|i| self.bodies[i].mass)
    }
    /// Adds a force at the centre of mass. Returns false for an unknown body.
    pub fn add_force(&mut self, body: BodyId, force: Vec3) -> bool {
        self.add_wrench(body, force, Vec3::ZERO)
    }
    /// Adds a force acting at a world point; it also adds the torque (p − x) × F.
    pub fn add_force_at_point(&mut self, body: BodyId, force: Vec3, world_point: Vec3) -> bool {
        match (self.lookup)(body) {
            Some(i) => {
                let r = world_point - self.motions[i].x;
                self.out[i].force += force;
                self.out[i].torque += r.cross(force);
                true
            }
            None => false,
        }
    }
    /// Adds a force acting at `local_point` (body frame, m), as an [`AppliedForce`] with
    /// that `point` does: it also adds the torque r × F. Returns false for an unknown body.
    pub fn add_force_at_local_point(
        &mut self,
        body: BodyId,
        force: Vec3,
        local_point: Vec3,
    ) -> bool {
        match (self.lookup)(body) {
            Some(i) => {
                let r = self.motions[i].q * (local_point - self.bodies[i].local_center);
                self.out[i].force += force;
                self.out[i].torque += r.cross(force);
                true
            }
            None => false,
        }
    }
    /// Adds a torque (N·m).
    pub fn add_torque(&mut self, body: BodyId, torque: Vec3) -> bool {
        self.add_wrench(body, Vec3::ZERO, torque)
    }
    fn add_wrench(&mut self, body: BodyId, force: Vec3, torque: Vec3) -> bool {
        match (self.lookup)(body) {
            Some(i) => {
                self.out[i].force += force;
                self.out[i].torque += torque;
                true
            }
            None => false,
        }
    }
}

/// A spring with its ends resolved to dense body indices and world anchor offsets for
/// one state: the quantities both the force and its Jacobian need.
pub(crate) struct SpringGeometry {
    pub a: usize,
    pub b: Option<usize>,
    /// Anchor offsets from the centres of mass, world frame.
    pub ra: Vec3,
    pub rb: Vec3,
    /// From the anchor on `a` to the other end.
    pub d: Vec3,
    /// Velocity of the other end relative to the anchor on `a`.
    pub dv: Vec3,
}

impl SpringGeometry {
    pub fn new(
        s: &Spring,
        bodies: &[Body],
        motions: &[Motion],
        lookup: &dyn Fn(BodyId) -> Option<usize>,
    ) -> Option<SpringGeometry> {
        let a = lookup(s.body)?;
        let ma = &motions[a];
        let ra = ma.q * (s.anchor - bodies[a].local_center);
        let pa = ma.x + ra;
        let va = ma.v + ma.w.cross(ra);
        let (b, rb, pb, vb) = match s.other {
            SpringEnd::World(p) => (None, Vec3::ZERO, p, Vec3::ZERO),
            SpringEnd::Body { body, anchor } => {
                let b = lookup(body)?;
                let mb = &motions[b];
                let rb = mb.q * (anchor - bodies[b].local_center);
                (Some(b), rb, mb.x + rb, mb.v + mb.w.cross(rb))
            }
        };
        Some(SpringGeometry {
            a,
            b,
            ra,
            rb,
            d: pb - pa,
            dv: vb - va,
        })
    }

    /// Force on body `a` (the opposite acts on `b`).
    pub fn force(&self, s: &Spring) -> Vec3 {
        let len = self.d.length();
        if len <= Real::EPSILON * (1.0 + s.rest_length) {
            // Coincident ends: the direction is undefined and, with l₀ > 0, so is the
            // push; no force is the only choice that cannot inject energy.
            return Vec3::ZERO;
        }
        let u = self.d / len;
        u * (s.stiffness * (len - s.rest_length) + s.damping * self.dv.dot(u))
    }
}

/// Adds gravity (times each body's `gravity_scale`) and every force element, evaluated at `motions`, into `out`.
pub(crate) fn accumulate(
    gravity: Vec3,
    forces: &[Force],
    bodies: &[Body],
    motions: &[Motion],
    lookup: &dyn Fn(BodyId) -> Option<usize>,
    out: &mut [Wrench],
) {
    for ((w, body), _m) in out.iter_mut().zip(bodies).zip(motions) {
        *w = Wrench {
            force: if body.kind == BodyKind::Dynamic {
                gravity * (body.mass * body.gravity_scale)
            } else {
                Vec3::ZERO
            },
            torque: Vec3::ZERO,
        };
    }
    for f in forces {
        match f {
            Force::Spring(s) => {
                let Some(g) = SpringGeometry::new(s, bodies, motions, lookup) else {
                    continue;
                };
                let fa = g.force(s);
                out[g.a].force += fa;
                out[g.a].torque += g.ra.cross(fa);
                if let Some(b) = g.b {
                    out[b].force -= fa;
                    out[b].torque -= g.rb.cross(fa);
                }
            }
            Force::Drag(d) => {
                let Some(i) = lookup(d.body) else { continue };
                let v = motions[i].v;
                out[i].force -= v * (d.linear + d.quadratic * v.length());
            }
            Force::Applied(a) => {
                let Some(i) = lookup(a.body) else { continue };
                out[i].force += a.force;
                out[i].torque += a.torque;
                if let Some(p) = a.point {
                    let r = motions[i].q * (p - bodies[i].local_center);
                    out[i].torque += r.cross(a.force);
                }
            }
        }
    }
}

/// Potential energy stored in the springs (J): Σ ½ k (l − l₀)².
pub(crate) fn spring_potential(
    forces: &[Force],
    bodies: &[Body],
    motions: &[Motion],
    lookup: &dyn Fn(BodyId) -> Option<usize>,
) -> Real {
    forces
        .iter()
        .filter_map(|f| match f {
            Force::Spring(s) => SpringGeometry::new(s, bodies, motions, lookup)
                .map(|g| 0.5 * s.stiffness * (g.d.length() - s.rest_length).powi(2)),
            _ => None,
        })
        .sum()
}

crate::codec::codec_struct!(Spring {
    body,
    anchor,
    other,
    stiffness,
    rest_length,
    damping
});
crate::codec::codec_struct!(Drag {
    body,
    linear,
    quadratic
});
crate::codec::codec_struct!(AppliedForce {
    body,
    force,
    point,
    torque
});

impl crate::codec::Code for SpringEnd {
    fn put(&self, w: &mut crate::codec::Writer) {
        match self {
            SpringEnd::World(p) => (0u8, *p).put(w),
            SpringEnd::Body { body, anchor } => (1u8, (*body, *anchor)).put(w),
        }
    }

    fn get(r: &mut crate::codec::Reader<'_>) -> crate::codec::Decoded<Self> {
        use crate::codec::Code;
        Ok(match u8::get(r)? {
            0 => SpringEnd::World(Code::get(r)?),
            1 => {
                let (body, anchor) = Code::get(r)?;
                SpringEnd::Body { body, anchor }
            }
            t => return Err(r.bad_tag("spring end", t)),
        })
    }
}

impl crate::codec::Code for Force {
    fn put(&self, w: &mut crate::codec::Writer) {
        match self {
            Force::Spring(s) => (0u8, *s).put(w),
            Force::Drag(d) => (1u8, *d).put(w),
            Force::Applied(a) => (2u8, *a).put(w),
        }
    }

    fn get(r: &mut crate::codec::Reader<'_>) -> crate::codec::Decoded<Self> {
        use crate::codec::Code;
        Ok(match u8::get(r)? {
            0 => Force::Spring(Code::get(r)?),
            1 => Force::Drag(Code::get(r)?),
            2 => Force::Applied(Code::get(r)?),
            t => return Err(r.bad_tag("force", t)),
        })
    }
}
