//! Backward (implicit) Euler, linearised: one Newton step of
//!
//! ```text
//! M (u₊ − u) = dt f(p₊, u₊),   p₊ = p + dt u₊
//! ```
//!
//! with u = (v, ω) per body and f linearised about the start of the step,
//! f(p₊, u₊) ≈ f₀ − S dt u₊ − C Δu, S = −∂f/∂p, C = −∂f/∂u (both positive semidefinite).
//! That gives the symmetric positive definite system (Baraff & Witkin's)
//!
//! ```text
//! (M + dt C + dt² S) Δu = dt f₀ − dt² S u
//! ```
//!
//! solved matrix-free by preconditioned conjugate gradients. Springs contribute S and C
//! through their anchor points (anchor velocity = J u, J = [E, −[r]×]); drag contributes C.
//! Forces without a Jacobian (applied forces, callbacks) stay explicit in f₀. The rotation
//! is backward Euler too: q₊ = exp(dt ω(q₊, L₊)/2) q, solved by fixed-point iteration.
//! A spring compressed below its rest length has an indefinite transverse stiffness; its
//! (1 − l₀/l) term is clamped at zero so the system stays definite (the usual remedy).

use super::{refresh_omega, Motion, Scratch, System};
use crate::dynamics::body::{Body, BodyKind};
use crate::dynamics::force::{Force, SpringGeometry};
use crate::math::{outer, quat_from_rotation_vector, Mat3, Real, Vec3, EPSILON};

/// A generalised velocity (v, ω) or force (F, τ) of one body.
#[derive(Debug, Clone, Copy, Default)]
struct Twist {
    lin: Vec3,
    ang: Vec3,
}

impl Twist {
    fn dot(self, o: Twist) -> Real {
        self.lin.dot(o.lin) + self.ang.dot(o.ang)
    }
    fn axpy(self, a: Real, o: Twist) -> Twist {
        Twist {
            lin: self.lin + o.lin * a,
            ang: self.ang + o.ang * a,
        }
    }
}

/// One spring linearised about the start of the step.
struct SpringJacobian {
    a: usize,
    b: Option<usize>,
    ra: Vec3,
    rb: Vec3,
    stiffness: Mat3,
    damping: Mat3,
}

/// Buffers reused from step to step.
#[derive(Default)]
pub(crate) struct Buffers {
    springs: Vec<SpringJacobian>,
    drag: Vec<Mat3>,
    inertia: Vec<Mat3>,
    inv_inertia: Vec<Mat3>,
    u0: Vec<Twist>,
    rhs: Vec<Twist>,
    x: Vec<Twist>,
    r: Vec<Twist>,
    z: Vec<Twist>,
    p: Vec<Twist>,
    ap: Vec<Twist>,
    cu: Vec<Twist>,
}

pub(super) fn step(
    sys: &mut System<'_>,
    motions: &mut [Motion],
    t: Real,
    dt: Real,
    s: &mut Scratch,
) {
    let n = motions.len();
    sys.wrenches(t, motions, &mut s.wrench);
    let b = &mut s.implicit;
    linearise(sys, motions, b);
    for v in [
        &mut b.u0, &mut b.rhs, &mut b.x, &mut b.r, &mut b.z, &mut b.p, &mut b.ap, &mut b.cu,
    ] {
        v.clear();
        v.resize(n, Twist::default());
    }
    for (u, m) in b.u0.iter_mut().zip(motions.iter()) {
        *u = Twist { lin: m.v, ang: m.w };
    }
    // rhs = dt f₀ − dt² S u₀
    apply_springs(&b.springs, &b.u0, &mut b.rhs, true);
    for ((rhs, w), body) in b.rhs.iter_mut().zip(&s.wrench).zip(sys.bodies) {
        rhs.lin = w.force * dt - rhs.lin * (dt * dt);
        rhs.ang = w.torque * dt - rhs.ang * (dt * dt);
        project(body, rhs);
    }
    conjugate_gradient(sys.bodies, b, dt);
    for (((m, du), body), inertia) in motions.iter_mut().zip(&b.x).zip(sys.bodies).zip(&b.inertia) {
        if body.kind != BodyKind::Dynamic {
            continue;
        }
        let q0 = m.q;
        m.v += du.lin;
        m.l += *inertia * du.ang;
        m.x += m.v * dt;
        m.q = implicit_rotation(body, q0, m.l, dt);
        refresh_omega(body, m);
    }
}

/// Collects the spring and drag Jacobians and each body's world inertia.
fn linearise(sys: &System<'_>, motions: &[Motion], b: &mut Buffers) {
    b.springs.clear();
    b.drag.clear();
    b.drag.resize(motions.len(), Mat3::ZERO);
    b.inertia.clear();
    b.inv_inertia.clear();
    for (m, body) in motions.iter().zip(sys.bodies) {
        let (inertia, inverse) = if body.planar {
            let i = body.planar_inertia;
            (
                Mat3::from_diagonal(Vec3::new(0.0, 0.0, i)),
                Mat3::from_diagonal(Vec3::new(0.0, 0.0, 1.0 / i)),
            )
        } else {
            let r = Mat3::from_quat(m.q);
            (
                r * body.inertia_local * r.transpose(),
                r * body.inv_inertia_local * r.transpose(),
            )
        };
        b.inertia.push(inertia);
        b.inv_inertia.push(inverse);
    }
    for f in sys.forces {
        match f {
            Force::Spring(spring) => {
                let Some(g) = SpringGeometry::new(spring, sys.bodies, motions, sys.lookup) else {
                    continue;
                };
                let len = g.d.length();
                let (stiffness, damping) = if len > EPSILON {
                    let u = g.d / len;
                    let uu = outer(u, u);
                    let transverse = (1.0 - spring.rest_length / len).max(0.0);
                    (
                        (uu + (Mat3::IDENTITY - uu) * transverse) * spring.stiffness,
                        uu * spring.damping,
                    )
                } else {
                    (Mat3::IDENTITY * spring.stiffness, Mat3::ZERO)
                };
                b.springs.push(SpringJacobian {
                    a: g.a,
                    b: g.b,
                    ra: g.ra,
                    rb: g.rb,
                    stiffness,
                    damping,
                });
            }
            Force::Drag(d) => {
                let Some(i) = (sys.lookup)(d.body) else {
                    continue;
                };
                let v = motions[i].v;
                let speed = v.length();
                // F = −c₁ v − c₂ |v| v  ⇒  −∂F/∂v = c₁ E + c₂ (|v| E + v vᵀ/|v|)
                let mut c = Mat3::IDENTITY * (d.linear + d.quadratic * speed);
                if speed > 0.0 {
                    c += outer(v, v) * (d.quadratic / speed);
                }
                b.drag[i] += c;
            }
            Force::Applied(_) => {}
        }
    }
}

/// out = S u (or, with `stiffness == false`, C u) summed over the springs.
fn apply_springs(springs: &[SpringJacobian], u: &[Twist], out: &mut [Twist], stiffness: bool) {
    for o in out.iter_mut() {
        *o = Twist::default();
    }
    for s in springs {
        let point = |i: usize, r: Vec3| u[i].lin + u[i].ang.cross(r);
        let stretch = s.b.map_or(Vec3::ZERO, |b| point(b, s.rb)) - point(s.a, s.ra);
        let k = if stiffness { s.stiffness } else { s.damping };
        let f = k * stretch;
        out[s.a].lin -= f;
        out[s.a].ang -= s.ra.cross(f);
        if let Some(b) = s.b {
            out[b].lin += f;
            out[b].ang += s.rb.cross(f);
        }
    }
}

/// Unknowns of non-dynamic bodies are fixed at zero; planar bodies keep in-plane ones.
fn project(body: &Body, t: &mut Twist) {
    if body.kind != BodyKind::Dynamic {
        *t = Twist::default();
    } else if body.planar {
        t.lin.z = 0.0;
        t.ang = Vec3::new(0.0, 0.0, t.ang.z);
    }
}

/// out = (M + dt C + dt² S) u, projected.
fn apply_system(
    bodies: &[Body],
    b: &Buffers,
    dt: Real,
    u: &[Twist],
    out: &mut [Twist],
    tmp: &mut [Twist],
) {
    apply_springs(&b.springs, u, out, true);
    apply_springs(&b.springs, u, tmp, false);
    for i in 0..u.len() {
        let body = &bodies[i];
        let mut y = Twist {
            lin: u[i].lin * body.mass
                + (b.drag[i] * u[i].lin + tmp[i].lin) * dt
                + out[i].lin * (dt * dt),
            ang: b.inertia[i] * u[i].ang + tmp[i].ang * dt + out[i].ang * (dt * dt),
        };
        project(body, &mut y);
        out[i] = y;
    }
}

/// Solves for Δu into `b.x`, preconditioned by the inverse mass and inertia.
#[allow(clippy::needless_range_loop)] // the CG updates read best as the textbook's loops
fn conjugate_gradient(bodies: &[Body], b: &mut Buffers, dt: Real) {
    let norm_b: Real = b.rhs.iter().map(|t| t.dot(*t)).sum::<Real>().sqrt();
    if norm_b == 0.0 {
        return;
    }
    let precondition = |b: &Buffers, i: usize, r: Twist| {
        let mut z = Twist {
            lin: r.lin * bodies[i].inv_mass,
            ang: b.inv_inertia[i] * r.ang,
        };
        project(&bodies[i], &mut z);
        z
    };
    let n = bodies.len();
    b.r.copy_from_slice(&b.rhs);
    for i in 0..n {
        b.z[i] = precondition(b, i, b.r[i]);
    }
    b.p.copy_from_slice(&b.z);
    let mut rz: Real = dot(&b.r, &b.z);
    let tolerance = 1e3 * EPSILON * norm_b;
    let (mut ap, mut cu) = (std::mem::take(&mut b.ap), std::mem::take(&mut b.cu));
    for _ in 0..(6 * n + 20).min(1000) {
        apply_system(bodies, b, dt, &b.p, &mut ap, &mut cu);
        let pap = dot(&b.p, &ap);
        if pap <= 0.0 {
            break;
        }
        let alpha = rz / pap;
        for i in 0..n {
            b.x[i] = b.x[i].axpy(alpha, b.p[i]);
            b.r[i] = b.r[i].axpy(-alpha, ap[i]);
        }
        if dot(&b.r, &b.r).sqrt() <= tolerance {
            break;
        }
        for i in 0..n {
            b.z[i] = precondition(b, i, b.r[i]);
        }
        let rz_next = dot(&b.r, &b.z);
        let beta = rz_next / rz;
        rz = rz_next;
        for i in 0..n {
            b.p[i] = b.z[i].axpy(beta, b.p[i]);
        }
    }
    (b.ap, b.cu) = (ap, cu);
}

fn dot(a: &[Twist], b: &[Twist]) -> Real {
    a.iter().zip(b).map(|(x, y)| x.dot(*y)).sum()
}

/// q₊ = exp(dt ω(q₊, L₊)/2) q by fixed-point iteration; it contracts for dt|ω| below about
/// one radian per step and is stopped after a bounded number of sweeps otherwise.
fn implicit_rotation(body: &Body, q0: crate::math::Quat, l: Vec3, dt: Real) -> crate::math::Quat {
    let mut q = q0;
    for _ in 0..50 {
        let w = body.omega_from_momentum(q, l);
        let next = (quat_from_rotation_vector(w * dt) * q0).normalize();
        let change = (next - q).length();
        q = next;
        if change <= 4.0 * EPSILON {
            break;
        }
    }
    q
}
