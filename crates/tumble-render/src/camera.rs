//! A pinhole camera: look-at view, perspective projection to pixels, automatic framing.

use glam::Vec3;

/// Vertical field of view (rad).
pub const FOV_Y: f32 = 0.75;
/// Points nearer than this in front of the eye are not drawn (m).
const NEAR: f32 = 1e-3;

/// Where the camera is and what it looks at, with the picture's size.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Camera {
    /// Eye position (m, world).
    pub eye: Vec3,
    /// Point at the centre of the picture (m, world).
    pub target: Vec3,
    /// Picture width (px).
    pub width: u32,
    /// Picture height (px).
    pub height: u32,
    forward: Vec3,
    right: Vec3,
    up: Vec3,
    focal: f32,
}

/// A point on the picture: pixel coordinates (x right, y down) and depth along the view
/// direction (m).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Projected {
    /// Pixels from the left edge.
    pub x: f32,
    /// Pixels from the top edge.
    pub y: f32,
    /// Distance in front of the eye along the view direction (m).
    pub depth: f32,
}

impl Camera {
    /// A camera at `eye` looking at `target`, world +y up. `None` if they coincide.
    pub fn look_at(eye: Vec3, target: Vec3, width: u32, height: u32) -> Option<Camera> {
        Camera::look_at_up(eye, target, Vec3::Y, width, height)
    }

    /// [`Camera::look_at`] with `up` (any length; zero means +y) as the world's up: a
    /// z-up model's pictures stand upright with `up` = +z.
    pub fn look_at_up(
        eye: Vec3,
        target: Vec3,
        up: Vec3,
        width: u32,
        height: u32,
    ) -> Option<Camera> {
        let forward = (target - eye).try_normalize()?;
        let turn = turn_to(up);
        // Looking straight up or down, up cannot be "up" on the picture: what -z is to a
        // y-up world is.
        let right = forward
            .cross(turn * Vec3::Y)
            .try_normalize()
            .unwrap_or_else(|| forward.cross(turn * Vec3::NEG_Z).normalize());
        let up = right.cross(forward);
        let focal = 0.5 * height as f32 / (0.5 * FOV_Y).tan();
        Some(Camera {
            eye,
            target,
            width,
            height,
            forward,
            right,
            up,
            focal,
        })
    }

    /// A camera that keeps the box `min..max` in view, seen from the front (+z), a little
    /// to the right and above, as a person standing before a table would look.
    pub fn framing(min: Vec3, max: Vec3, width: u32, height: u32) -> Camera {
        Camera::framing_up(min, max, Vec3::Y, width, height)
    }

    /// [`Camera::framing`] in a world whose up is `up` (zero means +y): the same view,
    /// turned with the world.
    pub fn framing_up(min: Vec3, max: Vec3, up: Vec3, width: u32, height: u32) -> Camera {
        let turn = turn_to(up);
        let centre = (min + max) * 0.5;
        let radius = ((max - min).length() * 0.5).max(0.25);
        let aspect = width as f32 / height as f32;
        // The sphere around the box must fit the narrower of the two fields of view.
        let half_fov = (0.5 * FOV_Y).min((aspect * (0.5 * FOV_Y).tan()).atan());
        let distance = radius / half_fov.sin() * 1.05;
        let direction = turn * Vec3::new(0.45, 0.4, 1.0).normalize();
        Camera::look_at_up(centre + direction * distance, centre, up, width, height)
            .expect("the direction is not zero")
    }

    /// The unit vector from the eye towards the target.
    pub fn forward(&self) -> Vec3 {
        self.forward
    }

    /// Where `p` lands on the picture; `None` behind (or at) the eye.
    pub fn project(&self, p: Vec3) -> Option<Projected> {
        let d = p - self.eye;
        let depth = d.dot(self.forward);
        if depth < NEAR {
            return None;
        }
        let s = self.focal / depth;
        Some(Projected {
            x: 0.5 * self.width as f32 + d.dot(self.right) * s,
            y: 0.5 * self.height as f32 - d.dot(self.up) * s,
            depth,
        })
    }
}

/// The rotation taking +y to `up` (the identity for +y, or a zero or non-finite `up`).
fn turn_to(up: Vec3) -> glam::Quat {
    match up.try_normalize() {
        Some(u) if u != Vec3::Y => glam::Quat::from_rotation_arc(Vec3::Y, u),
        _ => glam::Quat::IDENTITY,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_target_lands_in_the_middle_and_up_is_up() {
        let cam = Camera::look_at(Vec3::new(0.0, 1.0, 10.0), Vec3::Y, 200, 100).unwrap();
        let c = cam.project(Vec3::Y).unwrap();
        assert!((c.x - 100.0).abs() < 1e-3 && (c.y - 50.0).abs() < 1e-3);
        assert!((c.depth - 10.0).abs() < 1e-5);
        let above = cam.project(Vec3::new(0.0, 2.0, 0.0)).unwrap();
        assert!(above.y < c.y);
        let right = cam.project(Vec3::new(1.0, 1.0, 0.0)).unwrap();
        assert!(right.x > c.x);
        assert!(cam.project(Vec3::new(0.0, 1.0, 20.0)).is_none());
        assert!(Camera::look_at(Vec3::ONE, Vec3::ONE, 10, 10).is_none());
        // Straight down still gives a usable picture.
        let down = Camera::look_at(Vec3::new(0.0, 5.0, 0.0), Vec3::ZERO, 10, 10).unwrap();
        assert!(down.project(Vec3::ZERO).is_some());
    }

    #[test]
    fn framing_keeps_the_box_corners_on_the_picture() {
        let (min, max) = (Vec3::new(-1.0, 0.0, -0.5), Vec3::new(1.0, 5.0, 0.5));
        let cam = Camera::framing(min, max, 320, 240);
        for i in 0..8 {
            let p = Vec3::select(
                glam::BVec3::new(i & 1 == 1, i & 2 == 2, i & 4 == 4),
                max,
                min,
            );
            let q = cam.project(p).unwrap();
            assert!(
                (0.0..320.0).contains(&q.x) && (0.0..240.0).contains(&q.y),
                "{p} -> {q:?}"
            );
        }
    }
}
