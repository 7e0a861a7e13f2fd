//! Pictures of snapshots: every triangle projected, sorted far to near (the painter's
//! algorithm) and filled flat with tiny-skia, Lambert-shaded from a light above; planes
//! as a ground grid beneath everything; contact points and joints on top.

use glam::Vec3;
use tiny_skia::{Color, FillRule, Paint, PathBuilder, Pixmap, Stroke, Transform};

use crate::camera::{Camera, Projected};
use crate::mesh::Geometry;
use crate::model::{Model, Rgb, Snapshot};

/// The background colour (a pale blue-grey: no body's palette colour is this light).
pub const BACKGROUND: Rgb = Rgb([236, 240, 245]);
/// Colour of the ground grid's tiles and lines.
const GROUND: Rgb = Rgb([214, 218, 222]);
const GRID: Rgb = Rgb([170, 176, 184]);
const INK: Rgb = Rgb([30, 34, 40]);
const CONTACT: Rgb = Rgb([230, 40, 40]);
const JOINT: Rgb = Rgb([240, 150, 20]);

/// What to draw besides the bodies.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Overlays {
    /// Contact points as red dots.
    pub contacts: bool,
    /// Joints: a line between the anchors and the axis at the first anchor.
    pub joints: bool,
    /// The time in the top-left corner.
    pub time: bool,
}

/// Draws snapshots of one model through one camera.
#[derive(Debug, Clone)]
pub struct Renderer {
    /// The bodies.
    pub model: Model,
    /// The camera.
    pub camera: Camera,
    /// Extras.
    pub overlays: Overlays,
    /// Half the side of the ground grid drawn for planes (m), and its tile size.
    ground: (f32, f32),
}

/// A triangle ready to fill: screen corners, depth, colour.
struct Flat {
    corners: [Projected; 3],
    depth: f32,
    colour: Rgb,
}

impl Renderer {
    /// A renderer; `scale` (m) is the size of what is in view, which sets the ground
    /// grid's extent and tile size.
    pub fn new(model: Model, camera: Camera, overlays: Overlays, scale: f32) -> Renderer {
        let tile = nice_step(scale / 4.0);
        Renderer {
            model,
            camera,
            overlays,
            ground: (tile * 12.0, tile),
        }
    }

    /// The picture of `snapshot`.
    pub fn render(&self, snapshot: &Snapshot) -> Pixmap {
        let cam = &self.camera;
        let mut pixmap = Pixmap::new(cam.width, cam.height).expect("size checked by the caller");
        pixmap.fill(colour(BACKGROUND));
        let light = Vec3::new(0.35, 1.0, 0.55).normalize();
        let mut flats = Vec::new();
        for (body, (p, q)) in self.model.bodies.iter().zip(&snapshot.poses) {
            match &body.geometry {
                Geometry::Plane { normal, offset } => {
                    self.ground(&mut pixmap, *q * *normal, *p + *q * (*normal * *offset));
                }
                Geometry::Solid(tris) => {
                    for t in tris {
                        let w = t.map(|v| *q * v + *p);
                        let Some(corners) = project3(cam, &w) else {
                            continue;
                        };
                        let mut n = (w[1] - w[0]).cross(w[2] - w[0]).normalize_or_zero();
                        let centre = (w[0] + w[1] + w[2]) / 3.0;
                        // Open meshes are seen from both sides: light the side in view.
                        let to_eye = (cam.eye - centre).normalize_or_zero();
                        if n.dot(to_eye) < 0.0 {
                            n = -n;
                        }
                        let shade = 0.3 + 0.55 * n.dot(light).max(0.0) + 0.15 * n.dot(to_eye);
                        flats.push(Flat {
                            depth: (centre - cam.eye).dot(cam.forward()),
                            corners,
                            colour: shaded(body.colour, shade),
                        });
                    }
                }
            }
        }
        flats.sort_by(|a, b| b.depth.total_cmp(&a.depth));
        for f in &flats {
            fill(&mut pixmap, &f.corners, f.colour);
        }
        self.overlay(&mut pixmap, snapshot);
        pixmap
    }

    /// A square of tiles with grid lines on the plane through `point` with `normal`,
    /// centred under the camera's target.
    fn ground(&self, pixmap: &mut Pixmap, normal: Vec3, point: Vec3) {
        let (half, tile) = self.ground;
        let centre = self.camera.target - normal * (self.camera.target - point).dot(normal);
        let u = normal.any_orthonormal_vector();
        let v = normal.cross(u);
        // Snap to the tile grid so the lines stay put when the target moves.
        let snap = |x: f32| (x / tile).round() * tile;
        let centre = centre
            - u * (centre.dot(u) - snap(centre.dot(u)))
            - v * (centre.dot(v) - snap(centre.dot(v)));
        let n = (half / tile).round() as i32;
        let at = |i: i32, j: i32| centre + u * (i as f32 * tile) + v * (j as f32 * tile);
        // Tiles far to near, so the part of the floor behind the eye is simply skipped.
        for i in -n..n {
            for j in -n..n {
                let q = [at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)];
                if let (Some(a), Some(b)) = (
                    project3(&self.camera, &[q[0], q[1], q[2]]),
                    project3(&self.camera, &[q[0], q[2], q[3]]),
                ) {
                    fill(pixmap, &a, GROUND);
                    fill(pixmap, &b, GROUND);
                }
            }
        }
        for k in -n..=n {
            self.line(pixmap, at(k, -n), at(k, n), GRID, 1.0);
            self.line(pixmap, at(-n, k), at(n, k), GRID, 1.0);
        }
    }

    fn overlay(&self, pixmap: &mut Pixmap, snapshot: &Snapshot) {
        let cam = &self.camera;
        let unit = (cam.height as f32 / 240.0).max(1.0);
        if self.overlays.joints {
            for j in &snapshot.joints {
                self.line(pixmap, j.a, j.b, INK, 1.5 * unit);
                let length = 0.15 * self.ground.1 * 4.0;
                self.line(
                    pixmap,
                    j.a - j.axis * length,
                    j.a + j.axis * length,
                    JOINT,
                    2.0 * unit,
                );
                self.dot(pixmap, j.a, 2.5 * unit, JOINT);
            }
        }
        if self.overlays.contacts {
            for c in &snapshot.contacts {
                self.dot(pixmap, *c, 2.5 * unit, CONTACT);
            }
        }
        if self.overlays.time {
            let size = (cam.height as f32 / 16.0).clamp(11.0, 28.0);
            let text = format!("t = {:.2} s", snapshot.time);
            crate::text::draw(pixmap, &text, size * 0.5, size * 1.2, size, INK);
        }
    }

    /// A line between two world points, clipped to what is in front of the eye.
    fn line(&self, pixmap: &mut Pixmap, a: Vec3, b: Vec3, c: Rgb, width: f32) {
        let (Some(p), Some(q)) = (self.camera.project(a), self.camera.project(b)) else {
            return;
        };
        let mut path = PathBuilder::new();
        path.move_to(p.x, p.y);
        path.line_to(q.x, q.y);
        if let Some(path) = path.finish() {
            let stroke = Stroke {
                width,
                ..Stroke::default()
            };
            pixmap.stroke_path(&path, &paint(c, true), &stroke, Transform::identity(), None);
        }
    }

    fn dot(&self, pixmap: &mut Pixmap, p: Vec3, r: f32, c: Rgb) {
        let Some(p) = self.camera.project(p) else {
            return;
        };
        if let Some(path) = PathBuilder::from_circle(p.x, p.y, r) {
            pixmap.fill_path(
                &path,
                &paint(c, true),
                FillRule::Winding,
                Transform::identity(),
                None,
            );
        }
    }
}

fn project3(cam: &Camera, w: &[Vec3; 3]) -> Option<[Projected; 3]> {
    Some([cam.project(w[0])?, cam.project(w[1])?, cam.project(w[2])?])
}

fn fill(pixmap: &mut Pixmap, c: &[Projected; 3], rgb: Rgb) {
    let mut path = PathBuilder::new();
    path.move_to(c[0].x, c[0].y);
    path.line_to(c[1].x, c[1].y);
    path.line_to(c[2].x, c[2].y);
    path.close();
    if let Some(path) = path.finish() {
        // Without anti-aliasing neighbouring triangles tile exactly; with it, the
        // background would show through every shared edge as a faint seam.
        pixmap.fill_path(
            &path,
            &paint(rgb, false),
            FillRule::Winding,
            Transform::identity(),
            None,
        );
    }
}

fn paint(c: Rgb, anti_alias: bool) -> Paint<'static> {
    let mut paint = Paint::default();
    paint.set_color(colour(c));
    paint.anti_alias = anti_alias;
    paint
}

fn colour(c: Rgb) -> Color {
    Color::from_rgba8(c.0[0], c.0[1], c.0[2], 255)
}

fn shaded(c: Rgb, shade: f32) -> Rgb {
    Rgb(c
        .0
        .map(|x| (f32::from(x) * shade.clamp(0.0, 1.0)).round() as u8))
}

/// 1, 2 or 5 times a power of ten, at most `x`.
fn nice_step(x: f32) -> f32 {
    let p = 10f32.powf(x.max(1e-6).log10().floor());
    [5.0, 2.0, 1.0]
        .into_iter()
        .map(|m| m * p)
        .find(|s| *s <= x)
        .unwrap_or(p)
}
