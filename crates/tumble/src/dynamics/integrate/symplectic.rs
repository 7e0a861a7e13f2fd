//! Kick–drift methods: symplectic Euler, Störmer–Verlet and velocity Verlet.
//!
//! A kick changes momenta under the forces (v += dt F/m, L += dt N); a drift moves the
//! pose with the momenta (x += dt v, q by the rotor splitting of rotation.rs). Composing
//! exact-or-symplectic pieces this way keeps energy bounded instead of drifting.

use super::rotation::drift;
use super::{refresh_omega, Motion, Scratch, System};
use crate::dynamics::body::{Body, BodyKind};
use crate::dynamics::force::Wrench;
use crate::math::{Real, Vec3};

/// Momenta change under the wrenches. ω is left stale: a drift reads only L, and
/// whatever reads ω next calls [`refresh_all`] first.
fn kick(bodies: &[Body], motions: &mut [Motion], wrenches: &[Wrench], dt: Real) {
    for ((m, w), body) in motions.iter_mut().zip(wrenches).zip(bodies) {
        if body.kind == BodyKind::Dynamic {
            m.v += w.force * (body.inv_mass * dt);
            m.l += w.torque * dt;
        }
    }
}

fn refresh_all(bodies: &[Body], motions: &mut [Motion]) {
    for (m, body) in motions.iter_mut().zip(bodies) {
        refresh_omega(body, m);
    }
}

fn drift_all(bodies: &[Body], motions: &mut [Motion], dt: Real) {
    for (m, body) in motions.iter_mut().zip(bodies) {
        m.x += m.v * dt;
        m.q = drift(body, m.q, m.l, m.w, dt);
        refresh_omega(body, m);
    }
}

/// v₊ = v + dt F(x, v)/m, x₊ = x + dt v₊ (and L₊ = L + dt N, q₊ = drift(q, L₊)).
/// Bodies marked in `discarded` are kicked but not drifted: the caller throws their
/// result away, and no other body's step reads their drifted state.
pub(super) fn symplectic_euler(
    sys: &mut System<'_>,
    motions: &mut [Motion],
    t: Real,
    dt: Real,
    s: &mut Scratch,
    discarded: &[bool],
) {
    sys.wrenches(t, motions, &mut s.wrench);
    kick(sys.bodies, motions, &s.wrench, dt);
    for ((m, body), _) in motions
        .iter_mut()
        .zip(sys.bodies)
        .zip(discarded.iter().chain(std::iter::repeat(&false)))
        .filter(|(_, &skip)| !skip)
    {
        m.x += m.v * dt;
        m.q = drift(body, m.q, m.l, m.w, dt);
        refresh_omega(body, m);
    }
}

/// The seed's four steps: x₊ = x + v dt + ½ a dt², v½ = v + ½ a dt, a₊ = F(x₊, v₊)/m,
/// v₊ = v½ + ½ a₊ dt; the same for L with the rotor drift in between.
///
/// Step 3 needs v₊ before it is known. Forces that do not depend on velocity ignore it
/// (and the method is then exactly the symplectic kick–drift–kick); for damping and drag
/// it is predicted as v½ + ½ a dt. Evaluating at v½ instead, as many codes do, silently
/// drops the method to first order whenever there is damping.
pub(super) fn velocity_verlet(
    sys: &mut System<'_>,
    motions: &mut [Motion],
    t: Real,
    dt: Real,
    s: &mut Scratch,
) {
    sys.wrenches(t, motions, &mut s.wrench);
    kick(sys.bodies, motions, &s.wrench, 0.5 * dt);
    drift_all(sys.bodies, motions, dt);
    s.stage.copy_from_slice(motions);
    kick(sys.bodies, &mut s.stage, &s.wrench, 0.5 * dt);
    refresh_all(sys.bodies, &mut s.stage);
    sys.wrenches(t + dt, &s.stage, &mut s.wrench);
    kick(sys.bodies, motions, &s.wrench, 0.5 * dt);
    refresh_all(sys.bodies, motions);
}

/// What Störmer–Verlet remembers of the previous step.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct VerletMemory {
    /// Centre of mass one step ago.
    x_previous: Vec3,
    /// Angular momentum at the middle of the last step, L(t − dt/2).
    l_half: Vec3,
    /// The step this memory was made with; another step size restarts the method.
    dt: Real,
}

/// Störmer–Verlet: x₊ = 2x − x₋ + a dt², one force evaluation per step.
///
/// The velocity is not part of the method; the one reported (and given to velocity-
/// dependent forces) is v₊ = (x₊ − x)/dt + ½ a dt, second-order accurate, rather than the
/// first-order (x₊ − x)/dt. The rotation uses the leapfrog on L: L(t+dt/2) = L(t−dt/2) + dt N.
/// Without memory (first step, a new dt, or a body edited from outside) the method starts
/// from the Taylor expansion x₋ = x − v dt + ½ a dt².
pub(super) fn verlet(
    sys: &mut System<'_>,
    motions: &mut [Motion],
    memory: &mut [Option<VerletMemory>],
    t: Real,
    dt: Real,
    s: &mut Scratch,
) {
    sys.wrenches(t, motions, &mut s.wrench);
    for (((m, w), body), mem) in motions
        .iter_mut()
        .zip(&s.wrench)
        .zip(sys.bodies)
        .zip(memory)
    {
        if body.kind != BodyKind::Dynamic {
            *mem = None;
            continue;
        }
        let a = w.force * body.inv_mass;
        let previous = mem.filter(|p| p.dt == dt).unwrap_or(VerletMemory {
            x_previous: m.x - m.v * dt + a * (0.5 * dt * dt),
            l_half: m.l - w.torque * (0.5 * dt),
            dt,
        });
        let x_next = m.x * 2.0 - previous.x_previous + a * (dt * dt);
        let l_half = previous.l_half + w.torque * dt;
        *mem = Some(VerletMemory {
            x_previous: m.x,
            l_half,
            dt,
        });
        m.v = if body.damping_factors(dt).is_some() {
            // A damped body starts afresh every step (see `damp_half`), where the formula
            // below is v + a dt in exact arithmetic; in f32 its x₊ − x lost a damped
            // fall's velocity to ulp(x)/dt (1.3 % after 1,800 steps at x = 28 m).
            m.v + a * dt
        } else {
            (x_next - m.x) / dt + a * (0.5 * dt)
        };
        m.x = x_next;
        m.q = drift(body, m.q, l_half, m.w, dt);
        m.l = l_half + w.torque * (0.5 * dt);
        refresh_omega(body, m);
    }
}

crate::codec::codec_struct!(VerletMemory {
    x_previous,
    l_half,
    dt
});
