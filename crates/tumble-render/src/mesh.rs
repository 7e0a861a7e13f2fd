//! Shapes as triangles in their body's frame, in f32 (pictures need no more).
//!
//! Spheres, capsules and cylinders are surfaces of revolution about the local y axis, so
//! one lathe draws all three. Large triangles are split until no edge is longer than the
//! scene's `max_edge`: the painter's algorithm sorts whole triangles by depth, and a
//! ground box's top face as two triangles would sort in front of a box standing on it.

use glam::{Quat, Vec3};
use tumble::Shape;

use crate::convert::{quat, real, vec3};

/// A triangle, vertices in order.
pub type Tri = [Vec3; 3];

/// What a body looks like.
#[derive(Debug, Clone)]
pub enum Geometry {
    /// A closed or open surface of triangles (body frame).
    Solid(Vec<Tri>),
    /// An infinite half-space, drawn as a ground grid: n·x = offset (body frame).
    Plane {
        /// Outward unit normal.
        normal: Vec3,
        /// Distance of the surface from the body origin along the normal (m).
        offset: f32,
    },
}

/// Segments around the axis of revolution, and per quarter circle of a cap.
const SLICES: usize = 24;
const QUARTER: usize = 6;
/// No triangle is split into more than 2^this pieces.
const MAX_SPLIT_DEPTH: u32 = 10;

/// The triangles of `shape`, no edge longer than `max_edge` (m).
pub fn tessellate(shape: &Shape, max_edge: f32) -> Geometry {
    match shape {
        Shape::Plane { normal, offset } => Geometry::Plane {
            normal: vec3(*normal).normalize_or(Vec3::Y),
            offset: real(*offset),
        },
        _ => {
            let mut tris = Vec::new();
            solid(shape, Vec3::ZERO, Quat::IDENTITY, &mut tris);
            let mut out = Vec::with_capacity(tris.len());
            for t in tris {
                split(t, max_edge, MAX_SPLIT_DEPTH, &mut out);
            }
            Geometry::Solid(out)
        }
    }
}

fn solid(shape: &Shape, at: Vec3, rot: Quat, out: &mut Vec<Tri>) {
    let start = out.len();
    match shape {
        Shape::Sphere { radius } => lathe(&arc(real(*radius), 0.0, -1.0, 1.0), out),
        Shape::Capsule {
            radius,
            half_height,
        } => {
            let (r, h) = (real(*radius), real(*half_height));
            let mut profile = arc(r, -h, -1.0, 0.0);
            profile.extend(arc(r, h, 0.0, 1.0));
            lathe(&profile, out);
        }
        Shape::Cylinder {
            radius,
            half_height,
        } => {
            let (r, h) = (real(*radius), real(*half_height));
            lathe(&[(0.0, -h), (r, -h), (r, h), (0.0, h)], out);
        }
        Shape::Box { half_extents } => boxed(vec3(*half_extents), out),
        Shape::ConvexHull(hull) => {
            let v = hull.vertices();
            out.extend(
                hull.triangles()
                    .iter()
                    .map(|t| t.map(|i| vec3(v[i as usize]))),
            );
        }
        Shape::TriMesh(mesh) => {
            let v = mesh.vertices();
            out.extend(
                mesh.indices()
                    .iter()
                    .map(|t| t.map(|i| vec3(v[i as usize]))),
            );
        }
        Shape::HeightField(field) => {
            out.extend(
                (0..field.triangle_count()).filter_map(|i| field.triangle(i).map(|t| t.map(vec3))),
            );
        }
        Shape::Compound(children) => {
            for child in children {
                solid(
                    &child.shape,
                    vec3(child.position),
                    quat(child.orientation),
                    out,
                );
            }
        }
        // Compounds may not hold planes (the scene format refuses them).
        Shape::Plane { .. } => {}
    }
    for t in &mut out[start..] {
        *t = t.map(|p| rot * p + at);
    }
}

/// Points (radius, y) on a circle of radius `r` centred at height `y0`, from latitude
/// `from` to `to` (sines of the angle above the equator, −1 to 1).
fn arc(r: f32, y0: f32, from: f32, to: f32) -> Vec<(f32, f32)> {
    let (a, b) = (from.asin(), to.asin());
    let n = ((b - a) / std::f32::consts::FRAC_PI_2 * QUARTER as f32)
        .round()
        .max(1.0) as usize;
    (0..=n)
        .map(|i| {
            let t = a + (b - a) * i as f32 / n as f32;
            // cos(±π/2) is −4e-8 in f32, not 0: a pole's radius is clamped to 0, so
            // that every slice meets at one point and the surface closes.
            ((r * t.cos()).max(0.0), y0 + r * t.sin())
        })
        .collect()
}

/// The surface swept by a profile of (radius, y) points turned about the y axis.
fn lathe(profile: &[(f32, f32)], out: &mut Vec<Tri>) {
    let ring = |(r, y): (f32, f32), k: usize| {
        // Slice SLICES is slice 0 again (sin τ is not 0 in f32): the seam closes.
        let phi = std::f32::consts::TAU * (k % SLICES) as f32 / SLICES as f32;
        Vec3::new(r * phi.cos(), y, -r * phi.sin())
    };
    for w in profile.windows(2) {
        for k in 0..SLICES {
            let (a, b) = (ring(w[0], k), ring(w[0], k + 1));
            let (c, d) = (ring(w[1], k), ring(w[1], k + 1));
            // Points on the axis make a fan, not a degenerate quad.
            if w[0].0 > 1e-9 {
                out.push([a, b, d]);
            }
            if w[1].0 > 1e-9 {
                out.push([a, d, c]);
            }
        }
    }
}

fn boxed(h: Vec3, out: &mut Vec<Tri>) {
    for axis in 0..3 {
        for sign in [-1.0f32, 1.0] {
            // u × v = n, so the corners below run counter-clockwise seen from outside.
            let (mut u, mut v) = (Vec3::AXES[(axis + 1) % 3], Vec3::AXES[(axis + 2) % 3]);
            if sign < 0.0 {
                std::mem::swap(&mut u, &mut v);
            }
            let (c, u, v) = (Vec3::AXES[axis] * sign * h, u * h, v * h);
            let q = [c - u - v, c + u - v, c + u + v, c - u + v];
            out.push([q[0], q[1], q[2]]);
            out.push([q[0], q[2], q[3]]);
        }
    }
}

/// Halves `t` across its longest edge until every edge is at most `max_edge`.
fn split(t: Tri, max_edge: f32, depth: u32, out: &mut Vec<Tri>) {
    let lengths = [0, 1, 2].map(|i| (t[(i + 1) % 3] - t[i]).length_squared());
    let (i, longest) = lengths
        .iter()
        .enumerate()
        .fold((0, 0.0), |m, (i, &l)| if l > m.1 { (i, l) } else { m });
    if depth == 0 || longest <= max_edge * max_edge {
        out.push(t);
        return;
    }
    let (a, b, c) = (t[i], t[(i + 1) % 3], t[(i + 2) % 3]);
    let m = (a + b) * 0.5;
    split([a, m, c], max_edge, depth - 1, out);
    split([m, b, c], max_edge, depth - 1, out);
}

/// The largest distance of any vertex from the body origin (m); 0 for planes.
pub fn radius(geometry: &Geometry) -> f32 {
    match geometry {
        Geometry::Solid(tris) => tris
            .iter()
            .flatten()
            .map(|p| p.length())
            .fold(0.0, f32::max),
        Geometry::Plane { .. } => 0.0,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn area_and_volume(tris: &[Tri]) -> (f32, f32) {
        tris.iter().fold((0.0, 0.0), |(a, v), t| {
            let c = (t[1] - t[0]).cross(t[2] - t[0]);
            (a + 0.5 * c.length(), v + t[0].dot(t[1].cross(t[2])) / 6.0)
        })
    }

    #[test]
    fn closed_shapes_enclose_their_volume_with_outward_faces() {
        // The signed volume is positive only if every face winds counter-clockwise seen
        // from outside, which the shading relies on.
        let cases = [
            (Shape::sphere(1.0), 4.0 / 3.0 * std::f32::consts::PI),
            (Shape::cuboid(tumble::Vec3::new(1.0, 2.0, 3.0)), 48.0),
            (Shape::cylinder(0.5, 1.0), std::f32::consts::PI * 0.25 * 2.0),
            (
                Shape::capsule(0.5, 1.0),
                std::f32::consts::PI * 0.25 * 2.0 + 4.0 / 3.0 * std::f32::consts::PI * 0.125,
            ),
        ];
        for (shape, exact) in cases {
            let Geometry::Solid(tris) = tessellate(&shape, 0.3) else {
                panic!("{shape:?} is solid")
            };
            let (_, volume) = area_and_volume(&tris);
            assert!(
                (volume - exact).abs() < 0.03 * exact,
                "{shape:?}: {volume} against {exact}"
            );
            let longest = tris
                .iter()
                .flat_map(|t| [0, 1, 2].map(|i| (t[(i + 1) % 3] - t[i]).length()))
                .fold(0.0, f32::max);
            assert!(longest <= 0.3 + 1e-5, "{shape:?}: edge {longest}");
        }
    }
}
