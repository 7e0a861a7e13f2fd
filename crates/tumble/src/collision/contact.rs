//! A contact between two bodies as data: which bodies, the manifold the narrow phase
//! found, and the geometry it was found at (so that a pair that hardly moved can reuse
//! it); and the events of pairs that start or stop touching. The cache that keeps
//! contacts from step to step is the pipeline's (`pipeline/contact_cache.rs`).

use crate::collision::geometry::Pose;
use crate::collision::narrow_phase::{Manifold, MAX_MANIFOLD_POINTS};
use crate::id::BodyId;
use crate::math::{Quat, Real, Vec3};

/// A contact manifold between two bodies.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Contact {
    /// The first body; the manifold normal points away from it.
    pub body_a: BodyId,
    /// The second body.
    pub body_b: BodyId,
    /// Points, normal and sub-shapes.
    pub manifold: Manifold,
    /// Dense indices of the two bodies when the contact was found.
    pub(crate) index_a: u32,
    pub(crate) index_b: u32,
    /// The pair's geometry when the manifold was last computed, to reuse it while the
    /// bodies hardly move relative to each other.
    pub(crate) basis: Basis,
    /// Whether no contact with this key existed at the update before (the contact
    /// modifier's `is_new`).
    pub(crate) new: bool,
    /// A one-way body's decision on this manifold, kept while the manifold persists
    /// (see `pipeline/hooks.rs`).
    pub(crate) gate: Gate,
    /// Whether a hook (a one-way body or the contact modifier) took points out of the
    /// manifold at this update: its basis no longer describes it, so it is not reused.
    pub(crate) edited: bool,
}

/// The material of one manifold for one step: what the solver uses.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ContactMaterial {
    /// Coulomb friction coefficient (dimensionless); by default √(μ_a μ_b).
    pub friction: Real,
    /// Coefficient of restitution in [0, 1]; by default the larger of the two.
    pub restitution: Real,
    /// The velocity (m/s, world frame) at which body a's surface carries body b along:
    /// friction drives b's contact points to move at this velocity relative to a's (a
    /// conveyor belt). Only its part along the contact plane counts. Default zero.
    pub surface_velocity: Vec3,
}

/// What a one-way body decided about a manifold with it (see `pipeline/hooks.rs`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub(crate) enum Gate {
    /// Not yet decided: the manifold is new, or no one-way body is in the pair.
    #[default]
    New,
    /// The other body came from the normal's side: the contact holds it.
    Keep,
    /// The other body came from below or the side: it passes through.
    Pass,
}

/// A manifold's points and normal in the bodies' own frames, and B's pose in A's frame,
/// as of the narrow-phase run that produced them.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub(crate) struct Basis {
    relative: Pose,
    normal: Vec3,
    points: [(Vec3, Vec3); MAX_MANIFOLD_POINTS],
}

impl Basis {
    /// B's pose in A's frame, unnormalised: only compared, never applied.
    #[inline]
    pub(crate) fn relative(pa: &Pose, pb: &Pose) -> Pose {
        Pose {
            position: pa.inverse_transform_point(pb.position),
            rotation: pa.rotation.inverse() * pb.rotation,
        }
    }

    #[inline]
    pub(crate) fn of(m: &Manifold, pa: &Pose, pb: &Pose) -> Basis {
        let mut points = [(Vec3::ZERO, Vec3::ZERO); MAX_MANIFOLD_POINTS];
        for (l, p) in points.iter_mut().zip(m.points()) {
            *l = (
                pa.inverse_transform_point(p.point_a),
                pb.inverse_transform_point(p.point_b),
            );
        }
        Basis {
            relative: Basis::relative(pa, pb),
            normal: pa.inverse_transform_vector(m.normal),
            points,
        }
    }

    /// Whether B sits within `tolerance` (m) and `REUSE_ANGLE` of where it sat in A's
    /// frame when the manifold was computed.
    pub(crate) fn holds(&self, relative: &Pose, tolerance: Real) -> bool {
        let turn = relative.rotation * self.relative.rotation.inverse();
        (relative.position - self.relative.position).length_squared() < tolerance * tolerance
            && Vec3::new(turn.x, turn.y, turn.z).length_squared()
                < (0.5 * REUSE_ANGLE) * (0.5 * REUSE_ANGLE)
    }

    /// The manifold moved rigidly with the bodies to poses `pa`, `pb`.
    #[inline]
    pub(crate) fn place(&self, m: &mut Manifold, pa: &Pose, pb: &Pose) {
        m.normal = pa.transform_vector(self.normal);
        let n = m.normal;
        for (p, &(la, lb)) in m.points_mut().iter_mut().zip(&self.points) {
            p.point_a = pa.transform_point(la);
            p.point_b = pb.transform_point(lb);
            p.separation = (p.point_b - p.point_a).dot(n);
        }
    }
}

/// How far (as a fraction of the contact margin) and how much (rad) a pair may move
/// relative to itself before its manifold is computed again. Its points then move rigidly
/// with the bodies: a resting pair's separations stay exact to first order, and the
/// points are never more than ~20 µm (50 µm at a 0.5 m lever) from the clipped ones.
/// Resting piles skip most of their narrow phase; anything sliding, rolling or falling
/// moves more than this in a step and is computed afresh.
pub(crate) const REUSE_DISTANCE: Real = 1e-3;
const REUSE_ANGLE: Real = 1e-4;

impl Contact {
    /// A contact with an empty manifold (`Manifold::default()`) and placeholders elsewhere,
    /// for `pipeline/contact_cache.rs` to append to its list and fill in place. Every byte
    /// is zero (the basis's rotation too, never read before it is set), so the copy is a
    /// memset: 0.5 % fewer instructions in the rain than copying it (with the basis
    /// `Basis::default()` and `new` true).
    pub(crate) const BLANK: Contact = Contact {
        body_a: BodyId {
            index: 0,
            generation: 0,
        },
        body_b: BodyId {
            index: 0,
            generation: 0,
        },
        manifold: Manifold::EMPTY,
        index_a: 0,
        index_b: 0,
        basis: Basis {
            relative: Pose {
                position: Vec3::ZERO,
                rotation: Quat::from_xyzw(0.0, 0.0, 0.0, 0.0),
            },
            normal: Vec3::ZERO,
            points: [(Vec3::ZERO, Vec3::ZERO); MAX_MANIFOLD_POINTS],
        },
        new: false,
        gate: Gate::New,
        edited: false,
    };

    /// Identity of the contact across steps: the bodies and sub-shapes involved.
    pub(crate) fn key(&self) -> Key {
        (
            self.body_a,
            self.body_b,
            self.manifold.subshape_a,
            self.manifold.subshape_b,
        )
    }
}

/// A contact's identity: its bodies and their sub-shapes.
pub(crate) type Key = (BodyId, BodyId, u32, u32);

/// Whether two bodies started or stopped touching.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ContactEventKind {
    /// The pair has contact points now and had none at the previous update.
    Begin,
    /// The pair had contact points at the previous update and has none now.
    End,
}

/// A change in which bodies touch, between two contact updates.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ContactEvent {
    /// Begin or end.
    pub kind: ContactEventKind,
    /// The first body (lower creation order).
    pub body_a: BodyId,
    /// The second body.
    pub body_b: BodyId,
}

crate::codec::codec_struct!(Contact {
    body_a,
    body_b,
    manifold,
    index_a,
    index_b,
    basis,
    new,
    gate,
    edited
});
crate::codec::codec_struct!(ContactMaterial {
    friction,
    restitution,
    surface_velocity
});
crate::codec::codec_unit_enum!(Gate { New, Keep, Pass });
crate::codec::codec_struct!(Basis {
    relative,
    normal,
    points
});
crate::codec::codec_unit_enum!(ContactEventKind { Begin, End });
crate::codec::codec_struct!(ContactEvent {
    kind,
    body_a,
    body_b
});

#[cfg(test)]
mod tests {
    use super::*;

    /// The contact cache fills `Contact::BLANK`'s manifold in place where it used to fill
    /// `Manifold::default()`: the points it does not use must hold the same (zero) values,
    /// which snapshots store.
    #[test]
    fn blank_contact_holds_the_default_manifold() {
        assert_eq!(Manifold::EMPTY, Manifold::default());
        assert_eq!(Contact::BLANK.manifold, Manifold::default());
        let blank = Contact::BLANK;
        assert_eq!(
            (blank.new, blank.edited, blank.gate),
            (false, false, Gate::New)
        );
    }
}
