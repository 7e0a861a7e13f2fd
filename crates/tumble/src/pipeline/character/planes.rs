//! The plane solver: the move nearest the one asked for that keeps the capsule a skin
//! outside every surface near it, each surface taken as its tangent plane.
//!
//! A surface at separation s with unit normal n (towards the capsule) is kept a skin away
//! by the linear constraint n·δ >= skin − s on the move δ. The move nearest the desired
//! δ₀ under all of them is the projection of δ₀ onto a convex polyhedron: δ = δ₀ + Σ λᵢ nᵢ
//! with every push λᵢ >= 0 (a surface pushes, it never pulls), λᵢ > 0 only on planes met
//! exactly (the KKT conditions of the projection, whose solution is unique). One plane is
//! the exact slide along it; two walls meeting at any angle give the move along their
//! crease, or none when δ₀ points into the corner, and so no jitter between them.
//!
//! In three dimensions at most three independent planes are met at the solution, so it
//! is found exactly by trying every set of one, two or three planes as the met ones
//! (their λ from the 1×1 to 3×3 Gram system), keeping the nearest δ whose pushes are
//! all at least 0 and which breaks no plane. Box2D's and Box3D's movers solve their planes by
//! Hildreth's method (projected Gauss–Seidel on the pushes) instead; it converges at a
//! rate of cos² of the angle between two planes met together, which for a steep edge's
//! tilted plane and its wall (below, a few degrees apart) left the move centimetres off
//! after 20 passes, upward. It remains the fallback past [`MAX_EXACT`] planes.
//!
//! Slopes: a surface facing up but steeper than `max_slope` gets a second plane, its
//! normal's horizontal part: a vertical wall at the same place. Alone, the tilted plane
//! would turn a walk into it into a climb up it; with the wall the nearest allowed move
//! has no part into the slope, while a fall onto it (gravity in δ₀) still slides down
//! it, as the tilted plane directs. Within the skin of such a slope, only the wall pushes
//! the capsule back out (across); the tilted plane only forbids going deeper, or each
//! push out along it would lift the character a little: a ratchet up any steep edge.

use crate::math::{Mat3, Real, Vec3};
use crate::pipeline::character::surface::Touch;

/// Passes of the fallback solver over the planes before it settles for what it has (the
/// sweep that follows still stops the move short of any surface).
const MAX_PASSES: usize = 20;

/// The most planes solved exactly: C(16, 3) = 560 triples of 3×3 systems, each checked
/// against 16 planes, a few tens of microseconds.
pub(super) const MAX_EXACT: usize = 16;

/// Planes whose unit normals differ by less than this are one (a flat mesh's triangles).
const SAME_NORMAL: Real = 1e-6;

/// A constraint n·δ >= −gap of the move δ.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Plane {
    /// Unit normal, towards the capsule.
    pub normal: Vec3,
    /// Separation less the skin (m): how far the move may go into the plane.
    pub gap: Real,
    /// The solver's push along the normal (m, >= 0).
    pub push: Real,
    /// The index of the surface it stands for in the list it was made from.
    pub touch: usize,
    /// Whether it stops the character as a wall does: too steep to walk on, or the
    /// vertical plane standing in for such a slope.
    pub steep: bool,
}

/// The planes of `touches` for a capsule with axis `up` and the walkable limit
/// `cos_slope` (the cosine of `max_slope`); planes with the same normal are kept once,
/// with the least gap.
pub(super) fn planes(touches: &[Touch], up: Vec3, cos_slope: Real, skin: Real) -> Vec<Plane> {
    let mut out: Vec<Plane> = Vec::with_capacity(touches.len() + 4);
    let mut add = |plane: Plane| match out
        .iter_mut()
        .find(|p| (p.normal - plane.normal).length() < SAME_NORMAL)
    {
        Some(p) if p.gap <= plane.gap => {}
        Some(p) => *p = plane,
        None => out.push(plane),
    };
    for (i, t) in touches.iter().enumerate() {
        let rise = t.normal.dot(up);
        let gap = t.separation - skin;
        // Ceilings (facing more than 30° down) are not what a step climbs over.
        let steep = rise < cos_slope && rise > -0.5;
        let plane = Plane {
            normal: t.normal,
            gap,
            push: 0.0,
            touch: i,
            steep,
        };
        let wall = if rise > 0.0 && rise < cos_slope {
            (t.normal - up * rise).normalize_or_zero()
        } else {
            Vec3::ZERO
        };
        if wall == Vec3::ZERO {
            add(plane);
            continue;
        }
        // An upward slope too steep to walk (see the module header). The wall first: a
        // face a hair off vertical (a crate tipped by a push) gives two planes that are
        // one, and the one kept must be the wall, or each push along the face lifts the
        // character by its tilt, a few microns a step, without end.
        add(Plane {
            normal: wall,
            ..plane
        });
        add(Plane {
            gap: gap.max(0.0),
            ..plane
        });
    }
    out
}

/// The move nearest `desired` that the planes allow (see the module header), breaking
/// none by more than `tolerance` (m); each plane's `push` is left as its λ.
pub(super) fn solve(desired: Vec3, planes: &mut [Plane], tolerance: Real) -> Vec3 {
    for p in planes.iter_mut() {
        p.push = 0.0;
    }
    if allows(planes, desired, tolerance) {
        return desired;
    }
    if planes.len() <= MAX_EXACT {
        if let Some(delta) = exact(desired, planes, tolerance) {
            return delta;
        }
    }
    hildreth(desired, planes, tolerance)
}

/// Whether `delta` breaks no plane by more than `tolerance`.
fn allows(planes: &[Plane], delta: Vec3, tolerance: Real) -> bool {
    planes
        .iter()
        .all(|p| p.normal.dot(delta) + p.gap >= -tolerance)
}

/// The projection by trying every set of up to three planes as the ones met; `None` if
/// no set gives pushes >= 0 and a move every plane allows (the planes leave no room: a
/// capsule squeezed between surfaces closer than its width).
fn exact(desired: Vec3, planes: &mut [Plane], tolerance: Real) -> Option<Vec3> {
    /// A set of planes taken as the ones met, and the move it gives.
    #[derive(Clone, Copy)]
    struct Met {
        cost: Real,
        delta: Vec3,
        set: [usize; 3],
        lambda: [Real; 3],
        size: usize,
    }
    let n = planes.len();
    let mut best: Option<Met> = None;
    let mut consider = |set: [usize; 3], size: usize| {
        let Some(lambda) = pushes(desired, planes, &set[..size]) else {
            return;
        };
        if lambda[..size].iter().any(|l| *l < 0.0) {
            return;
        }
        let delta = desired
            + (0..size)
                .map(|k| planes[set[k]].normal * lambda[k])
                .sum::<Vec3>();
        let cost = (delta - desired).length_squared();
        if best.is_none_or(|b| cost < b.cost) && allows(planes, delta, tolerance) {
            best = Some(Met {
                cost,
                delta,
                set,
                lambda,
                size,
            });
        }
    };
    for i in 0..n {
        consider([i, 0, 0], 1);
        for j in i + 1..n {
            consider([i, j, 0], 2);
            for k in j + 1..n {
                consider([i, j, k], 3);
            }
        }
    }
    let met = best?;
    for k in 0..met.size {
        planes[met.set[k]].push = met.lambda[k];
    }
    Some(met.delta)
}

/// The pushes λ that put δ₀ + Σ λ_k n_k exactly on the planes of `set`: the Gram system
/// Σ_k (n_j·n_k) λ_k = −gap_j − n_j·δ₀. `None` when the normals are (nearly) dependent,
/// so the set cannot be the one met (a smaller set then is).
fn pushes(desired: Vec3, planes: &[Plane], set: &[usize]) -> Option<[Real; 3]> {
    let n = |k: usize| planes[set[k]].normal;
    let b = |k: usize| -planes[set[k]].gap - n(k).dot(desired);
    match set.len() {
        1 => Some([b(0), 0.0, 0.0]),
        2 => {
            let c = n(0).dot(n(1));
            let det = 1.0 - c * c;
            if det < 1e-6 {
                return None;
            }
            let l0 = (b(0) - c * b(1)) / det;
            let l1 = (b(1) - c * b(0)) / det;
            Some([l0, l1, 0.0])
        }
        _ => {
            let g = Mat3::from_cols(
                Vec3::new(1.0, n(1).dot(n(0)), n(2).dot(n(0))),
                Vec3::new(n(0).dot(n(1)), 1.0, n(2).dot(n(1))),
                Vec3::new(n(0).dot(n(2)), n(1).dot(n(2)), 1.0),
            );
            if g.determinant().abs() < 1e-6 {
                return None;
            }
            let l = g.inverse() * Vec3::new(b(0), b(1), b(2));
            Some([l.x, l.y, l.z])
        }
    }
}

/// Hildreth's method: each plane in turn pushes the move out along its normal by what it
/// is broken, every plane's accumulated push kept >= 0, until a pass pushes less than
/// `tolerance` in all.
fn hildreth(desired: Vec3, planes: &mut [Plane], tolerance: Real) -> Vec3 {
    let mut delta = desired;
    for _ in 0..MAX_PASSES {
        let mut moved: Real = 0.0;
        for p in planes.iter_mut() {
            let broken = -(p.normal.dot(delta) + p.gap);
            let push = (p.push + broken).max(0.0);
            let applied = push - p.push;
            p.push = push;
            delta += p.normal * applied;
            moved += applied.abs();
        }
        if moved <= tolerance {
            break;
        }
    }
    delta
}
