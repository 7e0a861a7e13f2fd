//! Conserved and monitored quantities: energy, momentum, angular momentum, state hash.

use crate::dynamics::body::Motion;
use crate::dynamics::body::{Body, BodyKind};
use crate::dynamics::force::{spring_potential, Force};
use crate::id::BodyId;
use crate::math::{Real, Vec3};

/// Energies (J) and momenta of a world's dynamic bodies.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Diagnostics {
    /// Σ ½ m v² + ½ ω·L (J).
    pub kinetic: Real,
    /// Gravity (−Σ m g·x, zero at the origin) plus springs (Σ ½ k (l − l₀)²) (J).
    pub potential: Real,
    /// kinetic + potential (J).
    pub total: Real,
    /// Σ m v (kg·m/s).
    pub linear_momentum: Vec3,
    /// Σ (x × m v + L), about the world origin (kg·m²/s).
    pub angular_momentum: Vec3,
}

pub(crate) fn measure(
    gravity: Vec3,
    bodies: &[Body],
    forces: &[Force],
    motions: &[Motion],
    lookup: &dyn Fn(BodyId) -> Option<usize>,
) -> Diagnostics {
    let mut d = Diagnostics::default();
    for body in bodies.iter().filter(|b| b.kind == BodyKind::Dynamic) {
        let p = body.linear_momentum();
        d.kinetic += body.kinetic_energy();
        d.potential -= body.mass * body.gravity_scale * gravity.dot(body.com);
        d.linear_momentum += p;
        d.angular_momentum += body.com.cross(p) + body.angular_momentum;
    }
    d.potential += spring_potential(forces, bodies, motions, lookup);
    d.total = d.kinetic + d.potential;
    d
}

/// FNV-1a over the bits of every body's position, orientation and momenta.
pub(crate) fn state_hash(bodies: &[Body]) -> u64 {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    let mut eat = |x: Real| {
        for byte in x.to_le_bytes() {
            h ^= byte as u64;
            h = h.wrapping_mul(0x0100_0000_01b3);
        }
    };
    for b in bodies {
        let q = b.orientation;
        for x in [b.com.x, b.com.y, b.com.z, q.x, q.y, q.z, q.w] {
            eat(x);
        }
        for v in [b.velocity, b.angular_momentum] {
            eat(v.x);
            eat(v.y);
            eat(v.z);
        }
    }
    h
}
