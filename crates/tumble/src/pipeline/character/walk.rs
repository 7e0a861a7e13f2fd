//! One move's stages (listed in the module header of `mod.rs`): slide, step up, ground,
//! snap down, push.

use crate::collision::geometry::Ray;
use crate::collision::query;
use crate::id::BodyId;
use crate::math::{Real, Vec3};
use crate::pipeline::character::planes::{planes, solve, Plane};
use crate::pipeline::character::surface::{sweep, touches, Touch};
use crate::pipeline::character::{CharacterController, Ground, Push, MAX_SLIDES};
use crate::pipeline::world::World;

/// What a slide did: where it ended, and whether a wall (a surface too steep to walk on)
/// held it back.
struct Slide {
    end: Vec3,
    wall: bool,
}

/// The most a dynamic body held a move back: the displacement its surface took off the
/// move (m, pointing out of the body), where, and its mass (kg).
struct Blocked {
    body: BodyId,
    mass: Real,
    push: Vec3,
    point: Vec3,
}

impl CharacterController {
    /// The move of `move_by`, its arguments checked.
    pub(super) fn walk(&mut self, world: &mut World, displacement: Vec3, dt: Real) {
        let up = self.capsule.up;
        let start = self.position;
        let was_on_ground = self.ground.is_some();
        let mut blocked = Vec::new();
        let slide = self.slide(world, start, displacement, &mut blocked);
        let mut end = slide.end;
        let mut ground = None;
        let across = displacement - up * displacement.dot(up);
        if was_on_ground && slide.wall && self.def.step_height > 0.0 {
            let progress = (end - start).dot(across.normalize_or_zero());
            if let Some((landed, g)) = self.step_up(world, start, across, progress) {
                // It went over what stopped it: nothing was pushed.
                (end, ground) = (landed, Some(g));
                blocked.clear();
            }
        }
        let mut hover = 0.0;
        if ground.is_none() {
            if let Some((g, separation)) = self.find_ground(world, end) {
                (ground, hover) = (Some(g), separation);
            }
        }
        // Walking off a slope or a stair leaves it above the ground, or with none within
        // reach: it follows the ground down, unless it was asked to rise.
        let rising = displacement.dot(up) > 0.0;
        let lost = ground.is_none() && was_on_ground;
        let above = ground.is_some() && hover > 1.1 * self.capsule.skin;
        if (lost || above) && !rising && self.def.snap_distance > 0.0 {
            if let Some((landed, g)) = self.snap(world, end) {
                (end, ground) = (landed, Some(g));
            }
        }
        self.position = end;
        self.ground = ground;
        self.velocity = (end - start) / dt;
        self.push_bodies(world, &blocked, dt);
    }

    /// Collide and slide from `from` towards `from + desired` (see the module header):
    /// passes of gather, solve, sweep until a pass hardly moves. The dynamic bodies whose
    /// steep faces held the move back are noted in `blocked`.
    fn slide(&self, world: &World, from: Vec3, desired: Vec3, blocked: &mut Vec<Blocked>) -> Slide {
        let skin = self.capsule.skin;
        let tolerance = 1e-3 * skin;
        let target = from + desired;
        let mut at = from;
        let mut wall = false;
        for _ in 0..MAX_SLIDES {
            let near = touches(world, &self.capsule, at, 2.0 * skin);
            let mut planes = planes(&near, self.capsule.up, self.cos_slope, skin);
            let delta = solve(target - at, &mut planes, tolerance);
            wall |= planes.iter().any(|p| p.steep && p.push > tolerance);
            note_blocked(&near, &planes, self.cos_slope, self.capsule.up, blocked);
            let t = sweep(world, &self.capsule, at, delta).map_or(1.0, |h| h.t);
            at += delta * t;
            if (delta * t).length() <= tolerance {
                break;
            }
        }
        Slide { end: at, wall }
    }

    /// The step-up attempt from `start` (on the ground) across `across` (the horizontal
    /// part of the displacement), where the slide got `progress` (m) along it: lifted,
    /// slid, dropped, and taken (the landing and its ground) only if it lands on walkable
    /// ground at most `step_height` above its feet and gets a tenth of the way farther
    /// than the slide (and than where it started).
    fn step_up(
        &self,
        world: &World,
        start: Vec3,
        across: Vec3,
        progress: Real,
    ) -> Option<(Vec3, Ground)> {
        let (up, skin, height) = (self.capsule.up, self.capsule.skin, self.def.step_height);
        let length = across.length();
        if length <= 0.0 {
            return None;
        }
        let lift = up * height;
        let rise = sweep(world, &self.capsule, start, lift).map_or(1.0, |h| h.t) * height;
        if rise <= skin {
            return None; // a ceiling just overhead
        }
        let raised = start + up * rise;
        let moved = self.slide(world, raised, across, &mut Vec::new()).end;
        // The slide may have moved it back (out of a skin it was inside): a step must
        // get a tenth of the way forward besides.
        if (moved - start).dot(across / length) <= progress.max(0.0) + 0.1 * length {
            return None;
        }
        let drop = up * (rise + skin);
        let hit = sweep(world, &self.capsule, moved, -drop)?;
        let landed = moved - drop * hit.t;
        if (landed - start).dot(up) > height + skin {
            return None; // climbed more than a step on the way across
        }
        // What it lands on must be walkable and within a step of its feet as they were:
        // coming down on the nose of a step too high is not having climbed it.
        let feet = start - up * (self.capsule.half_height + self.capsule.radius);
        if (hit.touch.point - feet).dot(up) > height + skin {
            return None;
        }
        self.support(world, &hit.touch)?;
        let (ground, _) = self.find_ground(world, landed)?;
        Some((landed, ground))
    }

    /// Snapping down from `at`: swept down by up to `snap_distance` (and the skin), kept
    /// there if it lands on walkable ground.
    fn snap(&self, world: &World, at: Vec3) -> Option<(Vec3, Ground)> {
        let drop = self.capsule.up * (self.def.snap_distance + self.capsule.skin);
        let hit = sweep(world, &self.capsule, at, -drop)?;
        let landed = at - drop * hit.t;
        let (ground, _) = self.find_ground(world, landed)?;
        Some((landed, ground))
    }

    /// The ground under the capsule at `center`: of the surfaces within two skins that
    /// support it, the one facing most nearly up (the first of equals), and its
    /// separation (m).
    pub(super) fn find_ground(&self, world: &World, center: Vec3) -> Option<(Ground, Real)> {
        let skin = self.capsule.skin;
        let mut best: Option<(Real, Ground, Real)> = None;
        for t in touches(world, &self.capsule, center, 2.0 * skin) {
            let Some(normal) = self.support(world, &t) else {
                continue;
            };
            let rise = normal.dot(self.capsule.up);
            if best.is_none_or(|(r, _, _)| rise > r) {
                let ground = Ground {
                    body: t.body,
                    normal,
                    point: t.point,
                };
                best = Some((rise, ground, t.separation));
            }
        }
        best.map(|(_, g, s)| (g, s))
    }

    /// The walkable normal a surface offers the character: its own if walkable; for a
    /// steep contact under the capsule (a step's nose, a box's edge), the normal of the
    /// face beyond the edge if that is walkable, found by a ray down from a skin past the
    /// contact, away from the character, and a skin above it. A ray starting inside the
    /// body (a steep face, not an edge) hits at once and does not count.
    fn support(&self, world: &World, t: &Touch) -> Option<Vec3> {
        let up = self.capsule.up;
        let rise = t.normal.dot(up);
        if rise >= self.cos_slope {
            return Some(t.normal);
        }
        if rise <= 1e-3 {
            return None;
        }
        let skin = self.capsule.skin;
        let away = (t.normal - up * rise).normalize_or_zero();
        let origin = t.point - away * skin + up * skin;
        let body = world.body(t.body).ok()?;
        let ray = Ray::new(origin, -up);
        let hit = query::cast_ray(body.shape(), &body.pose(), &ray, 2.0 * skin, true)?;
        (hit.t > 0.1 * skin && hit.normal.dot(up) >= self.cos_slope).then_some(hit.normal)
    }

    /// The impulses of the pushes: each blocked body gets m·p/dt against the push p its
    /// surface made (the momentum that takes it off at the speed it blocked, no faster
    /// than half the world's speed limit), at most `max_push_force · dt`. The world
    /// checks each (and wakes the body); one it refuses is left out.
    fn push_bodies(&mut self, world: &mut World, blocked: &[Blocked], dt: Real) {
        self.pushes.clear();
        let bound = self.def.max_push_force * dt;
        let fastest = 0.5 * world.speed_limits().max_speed;
        for b in blocked {
            let length = b.push.length();
            if length <= 0.0 || bound <= 0.0 {
                continue;
            }
            let size = (b.mass * (length / dt).min(fastest)).min(bound);
            let impulse = -b.push * (size / length);
            if world.apply_impulse(b.body, impulse, b.point).is_ok() {
                self.pushes.push(Push {
                    body: b.body,
                    impulse,
                    point: b.point,
                });
            }
        }
    }
}

/// Notes in `blocked` how far each dynamic body's steep surface pushed the move back in
/// this pass (the sum over its planes of push × normal, less the part of each push that
/// restores the skin), for the bodies not noted in an earlier pass: later passes solve
/// again for the whole rest of the displacement, the part already held back included.
/// Walkable surfaces are not pushed: standing on a body presses on it only through the
/// world's own contacts, which the character is not part of.
fn note_blocked(
    near: &[Touch],
    planes: &[Plane],
    cos_slope: Real,
    up: Vec3,
    blocked: &mut Vec<Blocked>,
) {
    for (i, t) in near.iter().enumerate() {
        let Some(mass) = t.dynamic else { continue };
        if t.normal.dot(up) >= cos_slope {
            continue;
        }
        // Less what only restores the skin: that is the character's own correction,
        // not a move the body stood in the way of.
        let push: Vec3 = planes
            .iter()
            .filter(|p| p.touch == i)
            .map(|p| p.normal * (p.push - (-p.gap).max(0.0)).max(0.0))
            .sum();
        if push == Vec3::ZERO {
            continue;
        }
        if blocked.iter().all(|b| b.body != t.body) {
            blocked.push(Blocked {
                body: t.body,
                mass,
                push,
                point: t.point,
            });
        }
    }
}
