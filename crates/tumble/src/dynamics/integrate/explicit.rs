//! Explicit Runge–Kutta methods on the whole state vector (x, q, v, L): explicit Euler
//! (order 1), the explicit midpoint method (order 2) and classic RK4 (order 4).
//!
//! q is advanced as the ODE q̇ = ½ ω q, like every other component, and renormalised after
//! each stage: these methods do exactly what their textbook form says, which is why
//! explicit Euler gains energy on a spinning body (its q drifts off the sphere outward
//! and ω = I⁻¹L is evaluated at stale orientations).

use super::{refresh_omega, Motion, Rate, Scratch, System};
use crate::dynamics::force::Wrench;
use crate::math::{quat_to_vec4, vec4_to_quat, Real};

/// Evaluates the derivative of `state` at time `t`.
fn eval(sys: &mut System<'_>, t: Real, state: &[Motion], wrench: &mut [Wrench], out: &mut [Rate]) {
    sys.wrenches(t, state, wrench);
    sys.rates(state, wrench, out);
}

/// `out = base + dt · rate`, with q renormalised and ω re-derived.
fn euler_update(sys: &System<'_>, base: &[Motion], rate: &[Rate], dt: Real, out: &mut [Motion]) {
    for (((o, b), r), body) in out.iter_mut().zip(base).zip(rate).zip(sys.bodies) {
        o.x = b.x + r.dx * dt;
        o.v = b.v + r.dv * dt;
        o.l = b.l + r.dl * dt;
        o.q = vec4_to_quat(quat_to_vec4(b.q) + r.dq * dt).normalize();
        o.w = b.w;
        refresh_omega(body, o);
    }
}

/// y₊ = y + dt f(t, y).
pub(super) fn explicit_euler(
    sys: &mut System<'_>,
    motions: &mut [Motion],
    t: Real,
    dt: Real,
    s: &mut Scratch,
) {
    let [k1, ..] = &mut s.rates;
    eval(sys, t, &s.start, &mut s.wrench, k1);
    euler_update(sys, &s.start, k1, dt, motions);
}

/// y₊ = y + dt f(t + dt/2, y + dt/2 f(t, y)).
pub(super) fn midpoint(
    sys: &mut System<'_>,
    motions: &mut [Motion],
    t: Real,
    dt: Real,
    s: &mut Scratch,
) {
    let [k1, k2, ..] = &mut s.rates;
    eval(sys, t, &s.start, &mut s.wrench, k1);
    euler_update(sys, &s.start, k1, 0.5 * dt, &mut s.stage);
    eval(sys, t + 0.5 * dt, &s.stage, &mut s.wrench, k2);
    euler_update(sys, &s.start, k2, dt, motions);
}

/// Classic RK4: y₊ = y + dt/6 (k₁ + 2k₂ + 2k₃ + k₄).
pub(super) fn rk4(
    sys: &mut System<'_>,
    motions: &mut [Motion],
    t: Real,
    dt: Real,
    s: &mut Scratch,
) {
    let [k1, k2, k3, k4] = &mut s.rates;
    eval(sys, t, &s.start, &mut s.wrench, k1);
    euler_update(sys, &s.start, k1, 0.5 * dt, &mut s.stage);
    eval(sys, t + 0.5 * dt, &s.stage, &mut s.wrench, k2);
    euler_update(sys, &s.start, k2, 0.5 * dt, &mut s.stage);
    eval(sys, t + 0.5 * dt, &s.stage, &mut s.wrench, k3);
    euler_update(sys, &s.start, k3, dt, &mut s.stage);
    eval(sys, t + dt, &s.stage, &mut s.wrench, k4);
    // Fold the four slopes into k1 so one Euler update applies their weighted mean.
    for (((a, b), c), d) in k1.iter_mut().zip(k2.iter()).zip(k3.iter()).zip(k4.iter()) {
        a.dx = (a.dx + (b.dx + c.dx) * 2.0 + d.dx) / 6.0;
        a.dv = (a.dv + (b.dv + c.dv) * 2.0 + d.dv) / 6.0;
        a.dq = (a.dq + (b.dq + c.dq) * 2.0 + d.dq) / 6.0;
        a.dl = (a.dl + (b.dl + c.dl) * 2.0 + d.dl) / 6.0;
    }
    euler_update(sys, &s.start, k1, dt, motions);
}
