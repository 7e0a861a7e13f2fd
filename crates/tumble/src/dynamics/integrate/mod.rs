//! Time integration of the rigid-body equations of motion.
//!
//! The state of a body is (x, q, v, L): centre of mass, orientation, velocity (p / m) and
//! angular momentum. Its derivative, shared by every method, is
//!
//! ```text
//! ẋ = v      v̇ = F / m      q̇ = ½ ω q      L̇ = N      with ω = R I_body⁻¹ Rᵀ L
//! ```
//!
//! The methods come in three families, one file each:
//! - `explicit.rs`: explicit Euler, midpoint and RK4 treat the state as one ODE vector.
//! - `symplectic.rs`: symplectic Euler, Störmer–Verlet and velocity Verlet split the step
//!   into kicks (v, L change under forces) and drifts (x, q move with the new momenta);
//!   their rotational drift is the exact-per-axis splitting in `rotation.rs`, which keeps
//!   |L| and the energy of a torque-free body from drifting.
//! - `implicit_euler.rs`: backward Euler, a linearised solve with the force Jacobian.

mod explicit;
mod implicit_euler;
mod rotation;
mod symplectic;

use crate::dynamics::body::{Body, BodyKind, Motion};
use crate::dynamics::force::{self, Force, ForceCallback, ForceContext, Wrench};
use crate::id::BodyId;
use crate::math::{quat_rate, Quat, Real, Vec3, Vec4};

/// The time-stepping method of a world.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum Integrator {
    /// Forward Euler: every derivative taken at the start of the step. Order 1, gains
    /// energy on oscillators and rotating bodies.
    ExplicitEuler,
    /// Semi-implicit Euler: velocity first, then position with the new velocity.
    /// Order 1, symplectic: energy stays bounded. The default.
    #[default]
    SymplecticEuler,
    /// Backward Euler, linearised with the force Jacobian. Order 1, unconditionally
    /// stable for springs and dampers, and dissipative.
    ImplicitEuler,
    /// Explicit midpoint (RK2). Order 2.
    Midpoint,
    /// Classic fourth-order Runge–Kutta. Order 4.
    Rk4,
    /// Störmer–Verlet on positions: x₊ = 2x − x₋ + a dt². Order 2, symplectic.
    Verlet,
    /// Velocity Verlet (kick–drift–kick). Order 2, symplectic.
    VelocityVerlet,
}

impl Integrator {
    /// Every integrator, in the order the documentation lists them.
    pub const ALL: [Integrator; 7] = [
        Integrator::ExplicitEuler,
        Integrator::SymplecticEuler,
        Integrator::ImplicitEuler,
        Integrator::Midpoint,
        Integrator::Rk4,
        Integrator::Verlet,
        Integrator::VelocityVerlet,
    ];

    /// The name used in scene files and on the command line.
    pub fn name(self) -> &'static str {
        match self {
            Integrator::ExplicitEuler => "explicit_euler",
            Integrator::SymplecticEuler => "symplectic_euler",
            Integrator::ImplicitEuler => "implicit_euler",
            Integrator::Midpoint => "midpoint",
            Integrator::Rk4 => "rk4",
            Integrator::Verlet => "verlet",
            Integrator::VelocityVerlet => "velocity_verlet",
        }
    }

    /// The integrator called `name`, as in scene files.
    pub fn from_name(name: &str) -> Option<Integrator> {
        Integrator::ALL.into_iter().find(|i| i.name() == name)
    }

    /// The order of accuracy the method is built to have.
    pub fn order(self) -> u32 {
        match self {
            Integrator::ExplicitEuler | Integrator::SymplecticEuler | Integrator::ImplicitEuler => {
                1
            }
            Integrator::Midpoint | Integrator::Verlet | Integrator::VelocityVerlet => 2,
            Integrator::Rk4 => 4,
        }
    }

    /// Every name, comma separated, for error messages and help.
    pub fn names() -> String {
        Integrator::ALL.map(|i| i.name()).join(", ")
    }
}

/// The time derivative of a [`Motion`].
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct Rate {
    dx: Vec3,
    dq: Vec4,
    dv: Vec3,
    dl: Vec3,
}

/// The forces acting on a world's bodies, as the integrators see them: a function from
/// a state to the wrench on every body.
pub(crate) struct System<'a> {
    pub gravity: Vec3,
    pub forces: &'a [Force],
    pub bodies: &'a [Body],
    /// Each body's handle, in the order of `bodies`.
    pub ids: &'a [BodyId],
    pub lookup: &'a dyn Fn(BodyId) -> Option<usize>,
    pub callbacks: &'a mut [ForceCallback],
    /// Set by the first callback that fails the step; no callback runs after it.
    pub failure: &'a mut Option<String>,
}

impl System<'_> {
    /// The wrench on every body in state `motions` at time `t`. Planar bodies only feel
    /// the in-plane force and the torque about z; non-dynamic bodies feel nothing.
    pub fn wrenches(&mut self, t: Real, motions: &[Motion], out: &mut [Wrench]) {
        force::accumulate(
            self.gravity,
            self.forces,
            self.bodies,
            motions,
            self.lookup,
            out,
        );
        for callback in self.callbacks.iter_mut() {
            if self.failure.is_some() {
                // The step will be undone: its forces no longer matter, and a callback
                // that failed (a Python exception) must not be asked again.
                break;
            }
            let mut ctx = ForceContext {
                time: t,
                bodies: self.bodies,
                ids: self.ids,
                motions,
                lookup: self.lookup,
                out,
                failure: &mut *self.failure,
            };
            callback(&mut ctx);
        }
        for (w, body) in out.iter_mut().zip(self.bodies) {
            if body.kind != BodyKind::Dynamic {
                *w = Wrench::default();
            } else if body.planar {
                w.force.z = 0.0;
                w.torque = Vec3::new(0.0, 0.0, w.torque.z);
            }
        }
    }

    /// The derivative of every body's state, given the wrenches on them.
    fn rates(&self, motions: &[Motion], wrenches: &[Wrench], out: &mut [Rate]) {
        for (((r, m), w), body) in out.iter_mut().zip(motions).zip(wrenches).zip(self.bodies) {
            *r = match body.kind {
                BodyKind::Static => Rate::default(),
                BodyKind::Kinematic => Rate {
                    dx: m.v,
                    dq: quat_rate(m.w, m.q),
                    ..Rate::default()
                },
                BodyKind::Dynamic => Rate {
                    dx: m.v,
                    dq: quat_rate(m.w, m.q),
                    dv: w.force * body.inv_mass,
                    dl: w.torque,
                },
            };
        }
    }
}

/// Re-derives ω = I_world⁻¹ L of a dynamic body after its q or L changed.
#[inline]
pub(crate) fn refresh_omega(body: &Body, m: &mut Motion) {
    if body.kind == BodyKind::Dynamic {
        m.w = body.omega_from_momentum(m.q, m.l);
    }
}

/// Scratch buffers kept between steps so stepping allocates nothing.
#[derive(Default)]
pub(crate) struct Scratch {
    pub start: Vec<Motion>,
    pub stage: Vec<Motion>,
    pub wrench: Vec<Wrench>,
    pub rates: [Vec<Rate>; 4],
    pub implicit: implicit_euler::Buffers,
}

impl Scratch {
    fn resize(&mut self, n: usize) {
        self.stage
            .resize(n, self.start.first().copied().unwrap_or(ZERO_MOTION));
        self.wrench.resize(n, Wrench::default());
        for r in &mut self.rates {
            r.resize(n, Rate::default());
        }
    }
}

const ZERO_MOTION: Motion = Motion {
    x: Vec3::ZERO,
    q: Quat::IDENTITY,
    v: Vec3::ZERO,
    l: Vec3::ZERO,
    w: Vec3::ZERO,
};

/// What an integrator carries from one step to the next: Störmer–Verlet's previous
/// position and half-step angular momentum, per body. Lasting state of the world (a
/// snapshot must keep it); every edit that breaks the sequence of equal steps it assumes
/// forgets it: a body edited from outside, a body the solver moved, a change of method.
#[derive(Debug, Default)]
pub(crate) struct IntegratorMemory {
    verlet: Vec<Option<VerletMemory>>,
}

// By hand for `clone_from` in place: the world keeps a copy every step to undo a failed
// one, and the derived one allocated a new list each time.
impl Clone for IntegratorMemory {
    fn clone(&self) -> Self {
        IntegratorMemory {
            verlet: self.verlet.clone(),
        }
    }

    fn clone_from(&mut self, source: &Self) {
        self.verlet.clone_from(&source.verlet);
    }
}

impl IntegratorMemory {
    /// Room for one more body (created last), with no memory.
    pub fn push(&mut self) {
        self.verlet.push(None);
    }

    /// Drops dense body `i`'s entry (the body is removed).
    pub fn remove(&mut self, i: usize) {
        self.verlet.remove(i);
    }

    /// Forgets dense body `i`'s memory: its next step starts the method afresh.
    pub fn forget(&mut self, i: usize) {
        self.verlet[i] = None;
    }

    /// Forgets every body's memory.
    pub fn clear(&mut self) {
        self.verlet.iter_mut().for_each(|m| *m = None);
    }
}

/// Advances `motions` (one per body of `sys`) from time `t` by `dt` with `integrator`.
/// `memory` holds the Störmer–Verlet memory of each body and whether it is still valid.
/// `discarded` marks bodies whose result the caller will throw away (the solver moves
/// them, or they sleep); methods whose bodies do not read each other's intermediate
/// states may leave them out (symplectic Euler does: as the rain lands, drifting bodies
/// already in contact was half its cost).
pub(crate) fn advance(
    integrator: Integrator,
    sys: &mut System<'_>,
    motions: &mut [Motion],
    memory: &mut IntegratorMemory,
    (t, dt): (Real, Real),
    scratch: &mut Scratch,
    discarded: &[bool],
) {
    damp_half(sys.bodies, motions, Some(memory), dt);
    scratch.start.clear();
    scratch.start.extend_from_slice(motions);
    scratch.resize(motions.len());
    match integrator {
        Integrator::ExplicitEuler => explicit::explicit_euler(sys, motions, t, dt, scratch),
        Integrator::Midpoint => explicit::midpoint(sys, motions, t, dt, scratch),
        Integrator::Rk4 => explicit::rk4(sys, motions, t, dt, scratch),
        Integrator::SymplecticEuler => {
            symplectic::symplectic_euler(sys, motions, t, dt, scratch, discarded)
        }
        Integrator::VelocityVerlet => symplectic::velocity_verlet(sys, motions, t, dt, scratch),
        Integrator::Verlet => symplectic::verlet(sys, motions, &mut memory.verlet, t, dt, scratch),
        Integrator::ImplicitEuler => implicit_euler::step(sys, motions, t, dt, scratch),
    }
    damp_half(sys.bodies, motions, None, dt);
    // Prescribed motion is known exactly; no method should add its own error to it.
    for ((m, start), body) in motions.iter_mut().zip(&scratch.start).zip(sys.bodies) {
        if body.kind != BodyKind::Dynamic {
            *m = *start;
        }
    }
    move_kinematic(sys.bodies, motions, dt);
}

/// Half a step of damping, dv/dt = −c v and dL/dt = −c L solved exactly: v, L and ω
/// (linear in L at the fixed orientation) scaled by exp(−c dt/2). `advance` puts one half
/// before the integrator's step and one after (Strang splitting), so that
/// - the decay itself is exact for every method: a free body's v is v₀ exp(−c t) to
///   rounding, where damping as a force would give explicit Euler (1 − c dt)ⁿ, 13 % off
///   at c = 5 /s, dt = 1/60 s after three time constants;
/// - the coupling with the other forces is second order and symmetric: under gravity the
///   terminal speed comes out at (g/c)·(c dt/2)/sinh(c dt/2), within (c dt)²/24 of g/c
///   (0.03 % at c = 5 /s, dt = 1/60 s), where one whole factor after the step would be
///   off by c dt/2 (4 %).
///
/// Störmer–Verlet's memory holds the undamped motion (its velocity is x − x₋), so a
/// damped body's memory is forgotten before each step: the method restarts from the
/// damped velocity (`verlet`'s Taylor start), which for forces that vary slowly over a
/// step is its own result to O(dt³).
fn damp_half(
    bodies: &[Body],
    motions: &mut [Motion],
    mut memory: Option<&mut IntegratorMemory>,
    dt: Real,
) {
    for (i, (m, body)) in motions.iter_mut().zip(bodies).enumerate() {
        let Some((fv, fw)) = body.damping_factors(0.5 * dt) else {
            continue;
        };
        m.v *= fv;
        m.l *= fw;
        m.w *= fw;
        if let Some(memory) = memory.as_deref_mut() {
            memory.forget(i);
        }
    }
}

/// Moves kinematic bodies exactly along their prescribed velocities: x + dt v,
/// exp(dt ω/2) q.
fn move_kinematic(bodies: &[Body], motions: &mut [Motion], dt: Real) {
    for (m, body) in motions.iter_mut().zip(bodies) {
        if body.kind == BodyKind::Kinematic {
            m.x += m.v * dt;
            m.q = rotation::exact_spin(m.w, m.q, dt);
        }
    }
}

pub(crate) use rotation::{drift as rotor_drift, exact_spin};
use symplectic::VerletMemory;

crate::codec::codec_unit_enum!(Integrator {
    ExplicitEuler,
    SymplecticEuler,
    ImplicitEuler,
    Midpoint,
    Rk4,
    Verlet,
    VelocityVerlet
});
crate::codec::codec_struct!(IntegratorMemory { verlet });

impl IntegratorMemory {
    /// How many bodies the memory has a slot for (one per body).
    pub(crate) fn slots(&self) -> usize {
        self.verlet.len()
    }
}
