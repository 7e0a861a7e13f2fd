//! The narrow phase: exact contact manifolds for a pair of shapes.
//!
//! [`collide`] holds the one (shape, shape) dispatch table. Dedicated routines handle the
//! pairs where a closed form is faster and exacter than the general path; every other
//! convex pair goes through GJK/EPA with face clipping (`convex.rs`). Compounds recurse
//! into their children, meshes and height fields into the triangles near the other shape.
//! Routines are written for one order of the pair; the table swaps the inputs and flips
//! the result for the other order, so "swapping the pair flips the normal" holds by
//! construction.

mod box_box;
mod clip;
mod convex;
mod epa;
mod gjk;
mod manifold;
mod mesh;
mod plane;
mod sphere;

pub(crate) use convex::within;
pub use convex::{closest_points, ClosestPoints};
pub(crate) use manifold::Overlap;
pub use manifold::{
    feature_id, reduce, swap_feature, Candidate, ContactPoint, FeatureId, Manifold,
    MAX_MANIFOLD_POINTS,
};

use crate::collision::geometry::Pose;
use crate::collision::shape::Convex;
use crate::collision::shape::Shape;
use crate::math::Real;

/// Appends to `out` the manifolds between `a` at `pose_a` and `b` at `pose_b`: one per
/// touching pair of sub-shapes, each with points whose separation is below `margin`
/// (speculative contacts: a gap smaller than `margin` is already reported). Normals point
/// from A to B.
pub fn collide(
    a: &Shape,
    pose_a: &Pose,
    b: &Shape,
    pose_b: &Pose,
    margin: Real,
    out: &mut Vec<Manifold>,
) {
    if let Shape::Compound(children) = a {
        for (i, child) in children.iter().enumerate() {
            let start = out.len();
            let pose = pose_a.mul(&Pose::new(child.position, child.orientation));
            collide(&child.shape, &pose, b, pose_b, margin, out);
            for m in &mut out[start..] {
                m.subshape_a = i as u32;
            }
        }
        return;
    }
    if matches!(b, Shape::Compound(_)) || (a.is_static_only() && !b.is_static_only()) {
        collide_swapped(a, pose_a, b, pose_b, margin, out);
        return;
    }
    let Some(ca) = Convex::from_shape(a) else {
        return; // static-only against static-only: nothing moves, nothing to report
    };
    match b {
        Shape::TriMesh(mesh) => mesh::convex_trimesh(&ca, pose_a, mesh, pose_b, margin, out),
        Shape::HeightField(field) => {
            mesh::convex_heightfield(&ca, pose_a, field, pose_b, margin, out)
        }
        _ => {
            // Built in its place in `out` and taken back if empty: made on the stack and
            // pushed, a manifold (some 800 bytes in f64) was copied once more per pair,
            // 0.4 % of the rain's step.
            out.push(Manifold::default());
            let m = out.last_mut().expect("just pushed");
            let touching = match b {
                Shape::Plane { normal, offset } => {
                    plane::convex_plane(&ca, pose_a, *normal, *offset, pose_b, margin, m)
                }
                _ => match Convex::from_shape(b) {
                    Some(cb) => convex_pair(&ca, pose_a, &cb, pose_b, margin, m),
                    None => false,
                },
            };
            if !touching || m.is_empty() {
                out.pop();
            }
        }
    }
}

/// What [`collide`] finds for two convex solids (spheres, boxes, capsules, cylinders,
/// hulls: `Convex::from_shape` takes both), which meet in one manifold at most: written
/// into `out`, which must be empty (`Manifold::default()`), and whether it has points
/// (`collide` would have appended it, else nothing); `false` with `out` untouched for
/// other shapes. The contact cache builds such a pair's manifold in its place among the
/// contacts (see `pipeline/contact_cache.rs`).
pub(crate) fn collide_solids(
    a: &Shape,
    pose_a: &Pose,
    b: &Shape,
    pose_b: &Pose,
    margin: Real,
    out: &mut Manifold,
) -> bool {
    // `collide`'s path for the pair: neither is a compound nor static-only, so neither
    // recursion nor swap, and its last arm with a convex B.
    let (Some(ca), Some(cb)) = (Convex::from_shape(a), Convex::from_shape(b)) else {
        return false;
    };
    convex_pair(&ca, pose_a, &cb, pose_b, margin, out) && !out.is_empty()
}

/// `collide` with the roles exchanged, its manifolds flipped back.
fn collide_swapped(
    a: &Shape,
    pose_a: &Pose,
    b: &Shape,
    pose_b: &Pose,
    margin: Real,
    out: &mut Vec<Manifold>,
) {
    let start = out.len();
    collide(b, pose_b, a, pose_a, margin, out);
    for m in &mut out[start..] {
        m.swap();
    }
}

/// Two convex solids: the dedicated routine for the pair if there is one, else GJK/EPA.
pub(crate) fn convex_pair(
    a: &Convex,
    pa: &Pose,
    b: &Convex,
    pb: &Pose,
    margin: Real,
    out: &mut Manifold,
) -> bool {
    use Convex as C;
    let flipped = |out: &mut Manifold, hit: bool| {
        out.swap();
        hit
    };
    match (a, b) {
        (C::Sphere { radius: ra }, C::Sphere { radius: rb }) => {
            sphere::sphere_sphere(*ra, pa, *rb, pb, margin, out)
        }
        (
            C::Sphere { radius },
            C::Capsule {
                radius: rc,
                half_height,
            },
        ) => sphere::sphere_capsule(*radius, pa, *rc, *half_height, pb, margin, out),
        (C::Capsule { .. }, C::Sphere { .. }) => {
            let hit = convex_pair(b, pb, a, pa, margin, out);
            flipped(out, hit)
        }
        (
            C::Capsule {
                radius: ra,
                half_height: ha,
            },
            C::Capsule {
                radius: rb,
                half_height: hb,
            },
        ) => sphere::capsule_capsule(*ra, *ha, pa, *rb, *hb, pb, margin, out),
        (C::Sphere { radius }, C::Box { half_extents }) => {
            sphere::sphere_box(*radius, pa, *half_extents, pb, margin, out)
        }
        (C::Box { .. }, C::Sphere { .. }) | (C::Box { .. }, C::Capsule { .. }) => {
            let hit = convex_pair(b, pb, a, pa, margin, out);
            flipped(out, hit)
        }
        (
            C::Capsule {
                radius,
                half_height,
            },
            C::Box { half_extents },
        ) => sphere::capsule_box(*radius, *half_height, pa, *half_extents, pb, margin, out),
        (C::Box { half_extents: ha }, C::Box { half_extents: hb }) => {
            box_box::box_box(*ha, pa, *hb, pb, margin, out)
        }
        _ => convex::convex_convex(a, pa, b, pb, margin, out),
    }
}
