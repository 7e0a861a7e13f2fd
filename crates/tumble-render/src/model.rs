//! What is drawn: each body's triangles and colour (made once), and the moving part of a
//! world at one instant (a [`Snapshot`]: poses, contact points, joint anchors).

use glam::{Quat, Vec3};
use tumble::{BodyKind, World};

use crate::convert::{quat, real, vec3};
use crate::mesh::{self, Geometry};

/// An opaque colour, 8 bits a channel.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Rgb(pub [u8; 3]);

impl Rgb {
    /// The colour as `#rrggbb`.
    pub fn hex(self) -> String {
        format!("#{:02x}{:02x}{:02x}", self.0[0], self.0[1], self.0[2])
    }
}

/// The default colour of the `index`-th body: moving bodies walk round the colour wheel by
/// the golden angle, so neighbours in creation order never look alike; static bodies are
/// greys, so the scenery stays behind the actors.
pub fn palette(index: usize, kind: BodyKind) -> Rgb {
    if kind == BodyKind::Static {
        let g = 150 + (index * 37 % 5) as u8 * 12;
        return Rgb([g, g, g.saturating_add(6)]);
    }
    // Golden-ratio steps through the hues from 30° to 330°: red stays free for a body a
    // scene paints red on purpose. The first body is blue.
    let step = (0.6 + 0.618_034 * index as f32).fract();
    let hue = 30.0 + 300.0 * step;
    hsv(hue, 0.62, 0.9)
}

fn hsv(hue: f32, s: f32, v: f32) -> Rgb {
    let c = v * s;
    let h = hue / 60.0;
    let x = c * (1.0 - (h % 2.0 - 1.0).abs());
    let (r, g, b) = match h as u32 {
        0 => (c, x, 0.0),
        1 => (x, c, 0.0),
        2 => (0.0, c, x),
        3 => (0.0, x, c),
        4 => (x, 0.0, c),
        _ => (c, 0.0, x),
    };
    let m = v - c;
    Rgb([r, g, b].map(|u| ((u + m) * 255.0).round() as u8))
}

/// One body as drawn.
#[derive(Debug, Clone)]
pub struct BodyModel {
    /// Its triangles (body frame) or plane.
    pub geometry: Geometry,
    /// Its colour.
    pub colour: Rgb,
    /// Whether it moves (dynamic or kinematic): only moving bodies set the framing.
    pub moving: bool,
    /// Largest distance of its surface from the body origin (m).
    pub radius: f32,
}

/// Every body of a world as drawn, in creation order.
#[derive(Debug, Clone)]
pub struct Model {
    /// The bodies.
    pub bodies: Vec<BodyModel>,
}

impl Model {
    /// The bodies of `world`. `colours[i]`, when given, overrides the palette for body
    /// `i`; `max_edge` (m) is the longest triangle edge kept (see [`mesh`]).
    pub fn new(world: &World, colours: &[Option<Rgb>], max_edge: f32) -> Model {
        let bodies = world
            .bodies()
            .enumerate()
            .map(|(i, (_, body))| {
                let geometry = mesh::tessellate(body.shape(), max_edge);
                BodyModel {
                    radius: mesh::radius(&geometry),
                    geometry,
                    colour: colours
                        .get(i)
                        .copied()
                        .flatten()
                        .unwrap_or_else(|| palette(i, body.kind())),
                    moving: body.kind() != BodyKind::Static,
                }
            })
            .collect();
        Model { bodies }
    }

    /// A box holding every moving body in every snapshot and every joint anchor, or, with
    /// nothing moving, every body that is not a plane. `None` when there is nothing.
    pub fn bounds(&self, snapshots: &[Snapshot]) -> Option<(Vec3, Vec3)> {
        let any_moving = self.bodies.iter().any(|b| b.moving);
        let mut min = Vec3::splat(f32::INFINITY);
        let mut max = Vec3::splat(f32::NEG_INFINITY);
        for s in snapshots {
            for (body, (p, _)) in self.bodies.iter().zip(&s.poses) {
                let counts =
                    matches!(body.geometry, Geometry::Solid(_)) && (body.moving || !any_moving);
                if counts {
                    min = min.min(*p - body.radius);
                    max = max.max(*p + body.radius);
                }
            }
            for j in &s.joints {
                min = min.min(j.a).min(j.b);
                max = max.max(j.a).max(j.b);
            }
        }
        min.is_finite().then_some((min, max))
    }
}

/// A joint as drawn: its two anchors in the world and its axis (unit, world).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct JointMark {
    /// The anchor on the first body (m).
    pub a: Vec3,
    /// The anchor on the other body, or the world point (m).
    pub b: Vec3,
    /// The joint axis as the first body carries it.
    pub axis: Vec3,
}

/// The world at one instant, as much of it as a picture needs.
#[derive(Debug, Clone, PartialEq)]
pub struct Snapshot {
    /// Simulated time (s).
    pub time: f32,
    /// Position and orientation of each body frame, creation order.
    pub poses: Vec<(Vec3, Quat)>,
    /// Contact points (midway between the surfaces, m).
    pub contacts: Vec<Vec3>,
    /// Joints that are not broken.
    pub joints: Vec<JointMark>,
}

impl Snapshot {
    /// The state of `world` now.
    pub fn capture(world: &World) -> Snapshot {
        let poses: Vec<(Vec3, Quat)> = world
            .bodies()
            .map(|(_, b)| (vec3(b.position()), quat(b.orientation())))
            .collect();
        let contacts = world
            .contacts()
            .iter()
            .flat_map(|c| {
                c.manifold
                    .points()
                    .iter()
                    .map(|p| vec3((p.point_a + p.point_b) * 0.5))
                    .collect::<Vec<_>>()
            })
            .collect();
        let pose_of = |id| {
            world
                .body_ids()
                .iter()
                .position(|b| *b == id)
                .map(|i| poses[i])
        };
        let joints = world
            .joints()
            .filter(|(_, j)| !j.is_broken())
            .filter_map(|(_, j)| {
                let d = j.def();
                let (pa, qa) = pose_of(d.body)?;
                let b = match d.other {
                    Some(other) => {
                        let (pb, qb) = pose_of(other)?;
                        pb + qb * vec3(d.other_anchor)
                    }
                    None => vec3(d.other_anchor),
                };
                Some(JointMark {
                    a: pa + qa * vec3(d.anchor),
                    b,
                    axis: (qa * vec3(d.axis)).normalize_or_zero(),
                })
            })
            .collect();
        Snapshot {
            time: real(world.time()),
            poses,
            contacts,
            joints,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn palette_colours_differ_and_none_is_red() {
        let colours: Vec<Rgb> = (0..8).map(|i| palette(i, BodyKind::Dynamic)).collect();
        for (i, a) in colours.iter().enumerate() {
            let [r, g, b] = a.0.map(i32::from);
            assert!(!(r > 150 && g < 110 && b < 110), "{i}: {a:?} is red");
            for c in &colours[..i] {
                let d: i32 =
                    a.0.iter()
                        .zip(c.0)
                        .map(|(x, y)| (i32::from(*x) - i32::from(y)).abs())
                        .sum();
                assert!(d > 60, "{a:?} and {c:?} look alike");
            }
        }
        assert_eq!(Rgb([255, 0, 16]).hex(), "#ff0010");
    }
}
