//! Spatial vectors for the articulated-body algorithm (`articulation.rs`), in Plücker
//! coordinates in the world's orientation about one fixed point `o` per tree: a motion
//! is (ω, v), v the velocity of the body's point at `o`; a force is (n, f), n the moment
//! about `o` (Featherstone, *Rigid Body Dynamics Algorithms*, ch. 2). With every vector
//! in one fixed frame the algorithm needs no coordinate transforms between links, only
//! the cross products below; `o` is the tree's ground anchor, not the world origin, so
//! that the moments stay of the size of the tree (a tree 1 km from the origin would
//! otherwise lose six digits to cancellation in n = r × f).

use crate::math::{Mat3, Real, Vec3};

/// A spatial motion vector (rad/s, m/s).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub(super) struct Twist {
    pub w: Vec3,
    pub v: Vec3,
}

/// A spatial force vector (N·m about `o`, N).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub(super) struct Spatial {
    pub n: Vec3,
    pub f: Vec3,
}

impl Twist {
    pub fn new(w: Vec3, v: Vec3) -> Twist {
        Twist { w, v }
    }

    pub fn scale(self, s: Real) -> Twist {
        Twist::new(self.w * s, self.v * s)
    }

    pub fn add(self, o: Twist) -> Twist {
        Twist::new(self.w + o.w, self.v + o.v)
    }

    /// self ×ₘ m: how a motion vector fixed in a body moving with `self` changes.
    pub fn cross_motion(self, m: Twist) -> Twist {
        Twist::new(self.w.cross(m.w), self.w.cross(m.v) + self.v.cross(m.w))
    }

    /// self ×f f: the same for a force vector (the gyroscopic term is v ×f I v).
    pub fn cross_force(self, f: Spatial) -> Spatial {
        Spatial {
            n: self.w.cross(f.n) + self.v.cross(f.f),
            f: self.w.cross(f.f),
        }
    }

    /// The power of force `f` on this motion.
    pub fn dot(self, f: Spatial) -> Real {
        self.w.dot(f.n) + self.v.dot(f.f)
    }

    /// The velocity of point `r` (relative to `o`) of the body moving with this twist.
    pub fn at(self, r: Vec3) -> Vec3 {
        self.v + self.w.cross(r)
    }
}

impl Spatial {
    /// A force `f` through point `r` (relative to `o`) with a pure torque `t`.
    pub fn at(r: Vec3, f: Vec3, t: Vec3) -> Spatial {
        Spatial {
            n: t + r.cross(f),
            f,
        }
    }

    pub fn add(self, o: Spatial) -> Spatial {
        Spatial {
            n: self.n + o.n,
            f: self.f + o.f,
        }
    }

    pub fn sub(self, o: Spatial) -> Spatial {
        Spatial {
            n: self.n - o.n,
            f: self.f - o.f,
        }
    }

    pub fn scale(self, s: Real) -> Spatial {
        Spatial {
            n: self.n * s,
            f: self.f * s,
        }
    }

    /// The moment about point `r` (relative to `o`) instead of `o`.
    pub fn moment_about(self, r: Vec3) -> Vec3 {
        self.n - r.cross(self.f)
    }
}

/// A symmetric 6×6 spatial inertia [[A, B], [Bᵀ, C]]: a rigid body's, or an articulated
/// one's (a body with the subtree it carries through its joints).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Inertia {
    a: Mat3,
    b: Mat3,
    c: Mat3,
}

impl Default for Inertia {
    fn default() -> Inertia {
        Inertia {
            a: Mat3::ZERO,
            b: Mat3::ZERO,
            c: Mat3::ZERO,
        }
    }
}

impl Inertia {
    /// A rigid body of `mass` with its centre at `r` (relative to `o`) and world inertia
    /// `ic` about its centre: h = I_c ω + r × p, p = m (v + ω × r).
    pub fn rigid(mass: Real, r: Vec3, ic: Mat3) -> Inertia {
        let rx = skew(r);
        Inertia {
            a: ic - rx * rx * mass,
            b: rx * mass,
            c: Mat3::from_diagonal(Vec3::splat(mass)),
        }
    }

    pub fn apply(&self, m: Twist) -> Spatial {
        Spatial {
            n: self.a * m.w + self.b * m.v,
            f: self.b.transpose() * m.w + self.c * m.v,
        }
    }

    pub fn add(&mut self, o: &Inertia) {
        self.a += o.a;
        self.b += o.b;
        self.c += o.c;
    }

    /// self − a bᵀ, for a sum of such terms that is symmetric (U D⁻¹ Uᵀ over a joint's
    /// freedoms): the lower left block is taken as the upper right's transpose.
    pub fn less(&self, a: Spatial, b: Spatial) -> Inertia {
        Inertia {
            a: self.a - outer(a.n, b.n),
            b: self.b - outer(a.n, b.f),
            c: self.c - outer(a.f, b.f),
        }
    }

    /// self − u uᵀ / d: what a joint's freedom passes on of the inertia beyond it.
    pub fn less_outer(&self, u: Spatial, inv_d: Real) -> Inertia {
        Inertia {
            a: self.a - outer(u.n, u.n * inv_d),
            b: self.b - outer(u.n, u.f * inv_d),
            c: self.c - outer(u.f, u.f * inv_d),
        }
    }
}

/// [r]×: the matrix of r × ·.
fn skew(r: Vec3) -> Mat3 {
    Mat3::from_cols(
        Vec3::new(0.0, r.z, -r.y),
        Vec3::new(-r.z, 0.0, r.x),
        Vec3::new(r.y, -r.x, 0.0),
    )
}

/// a bᵀ.
pub(super) fn outer(a: Vec3, b: Vec3) -> Mat3 {
    Mat3::from_cols(a * b.x, a * b.y, a * b.z)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The rigid inertia gives the momentum of the body's points: p = m v_c and
    /// h = I_c ω + r × m v_c, with v_c the centre's velocity.
    #[test]
    fn rigid_inertia_gives_the_momenta() {
        let (m, r) = (2.5, Vec3::new(0.3, -1.2, 0.7));
        let ic = Mat3::from_cols(
            Vec3::new(0.4, 0.05, -0.02),
            Vec3::new(0.05, 0.3, 0.01),
            Vec3::new(-0.02, 0.01, 0.2),
        );
        let t = Twist::new(Vec3::new(0.2, -0.5, 1.1), Vec3::new(-0.7, 0.4, 0.9));
        let vc = t.at(r);
        let h = Inertia::rigid(m, r, ic).apply(t);
        // Rounding of a few products: 1e-12 in f64, 1e-5 in f32.
        let tol = if std::mem::size_of::<Real>() == 8 {
            1e-12
        } else {
            1e-5
        };
        assert!((h.f - vc * m).length() < tol);
        assert!((h.n - (ic * t.w + r.cross(vc * m))).length() < tol);
        // Kinetic energy both ways.
        let e = 0.5 * t.dot(h);
        let expect = 0.5 * m * vc.length_squared() + 0.5 * t.w.dot(ic * t.w);
        assert!((e - expect).abs() < tol);
    }
}
