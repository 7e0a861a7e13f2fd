//! Queries on a world, through its broad phase: ray casts, shape casts, point and box
//! overlap. They read the state as of the last step or edit.

use crate::collision::geometry::{Aabb, Pose, Ray, RayHit};
use crate::collision::query::{self, ShapeCastHit};
use crate::collision::shape::Convex;
use crate::collision::shape::{convex_aabb, Shape};
use crate::dynamics::body::Body;
use crate::error::{Error, Result};
use crate::id::BodyId;
use crate::math::{Real, Vec3};
use crate::pipeline::world::World;

/// Which bodies a query sees.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct QueryFilter {
    /// Bodies whose collision group shares a bit with this mask are seen.
    pub mask: u32,
    /// A body to ignore (typically the one asking).
    pub exclude: Option<BodyId>,
}

impl Default for QueryFilter {
    fn default() -> Self {
        QueryFilter {
            mask: u32::MAX,
            exclude: None,
        }
    }
}

/// A ray hit on a body.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WorldRayHit {
    /// The body hit.
    pub body: BodyId,
    /// Where and how.
    pub hit: RayHit,
}

/// A shape-cast hit on a body.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WorldShapeHit {
    /// The body hit.
    pub body: BodyId,
    /// Fraction of the translation, normal and point.
    pub hit: ShapeCastHit,
}

impl World {
    fn sees(&self, index: usize, filter: &QueryFilter) -> Option<(BodyId, &Body)> {
        let (id, body) = self.body_at(index)?;
        let visible = body.filter.group & filter.mask != 0 && filter.exclude != Some(id);
        visible.then_some((id, body))
    }

    /// The nearest hit of the ray with t in [0, max_t] (t in units of the direction's
    /// length). Rays starting inside a body hit it at t = 0.
    pub fn cast_ray(&self, ray: &Ray, max_t: Real, filter: &QueryFilter) -> Option<WorldRayHit> {
        let mut best: Option<WorldRayHit> = None;
        self.collision
            .broad_phase
            .cast_ray(ray.origin, ray.direction, max_t, |user, limit| {
                let Some((id, body)) = self.sees(user as usize, filter) else {
                    return limit;
                };
                match query::cast_ray(&body.shape, &body.pose(), ray, limit, true) {
                    Some(hit) if best.is_none_or(|b| (hit.t, id) < (b.hit.t, b.body)) => {
                        best = Some(WorldRayHit { body: id, hit });
                        hit.t
                    }
                    _ => limit,
                }
            });
        best
    }

    /// Every body the ray hits with t in [0, max_t], nearest first (one hit per body).
    pub fn cast_ray_all(&self, ray: &Ray, max_t: Real, filter: &QueryFilter) -> Vec<WorldRayHit> {
        let mut hits = Vec::new();
        self.collision
            .broad_phase
            .cast_ray(ray.origin, ray.direction, max_t, |user, limit| {
                if let Some((id, body)) = self.sees(user as usize, filter) {
                    if let Some(hit) = query::cast_ray(&body.shape, &body.pose(), ray, max_t, true)
                    {
                        hits.push(WorldRayHit { body: id, hit });
                    }
                }
                limit
            });
        hits.sort_by(|a, b| a.hit.t.total_cmp(&b.hit.t).then(a.body.cmp(&b.body)));
        hits
    }

    /// Bodies containing the world point, in body order.
    pub fn query_point(&self, point: Vec3, filter: &QueryFilter) -> Vec<BodyId> {
        let mut found = Vec::new();
        self.collision
            .broad_phase
            .query_aabb(&Aabb::new(point, point), |user| {
                if let Some((id, body)) = self.sees(user as usize, filter) {
                    if query::contains_point(&body.shape, &body.pose(), point) {
                        found.push((user, id));
                    }
                }
            });
        sorted_ids(found)
    }

    /// Bodies whose tight bounding box overlaps `aabb`, in body order.
    pub fn query_aabb(&self, aabb: &Aabb, filter: &QueryFilter) -> Vec<BodyId> {
        let mut found = Vec::new();
        self.collision.broad_phase.query_aabb(aabb, |user| {
            if let Some((id, body)) = self.sees(user as usize, filter) {
                if body.shape.aabb(&body.pose()).overlaps(aabb) {
                    found.push((user, id));
                }
            }
        });
        sorted_ids(found)
    }

    /// Sweeps a convex `shape` from `pose` along `translation` (no rotation) and returns
    /// the first body it would touch. Fails if the shape is not convex.
    pub fn cast_shape(
        &self,
        shape: &Shape,
        pose: &Pose,
        translation: Vec3,
        filter: &QueryFilter,
    ) -> Result<Option<WorldShapeHit>> {
        let convex = Convex::from_shape(shape)
            .ok_or_else(|| Error::invalid("shape", "must be a convex shape to be cast"))?;
        shape.validate().map_err(|e| e.within("shape"))?;
        let start = convex_aabb(&convex, pose);
        let end = convex_aabb(
            &convex,
            &Pose::new(pose.position + translation, pose.rotation),
        );
        let swept = start.union(&end);
        let mut best: Option<WorldShapeHit> = None;
        self.collision.broad_phase.query_aabb(&swept, |user| {
            let Some((id, body)) = self.sees(user as usize, filter) else {
                return;
            };
            let hit = cast_against(
                &convex,
                pose,
                translation,
                &swept,
                &body.shape,
                &body.pose(),
            );
            if let Some(hit) = hit {
                if best.is_none_or(|b| (hit.t, id) < (b.hit.t, b.body)) {
                    best = Some(WorldShapeHit { body: id, hit });
                }
            }
        });
        Ok(best)
    }
}

fn sorted_ids(mut found: Vec<(u32, BodyId)>) -> Vec<BodyId> {
    found.sort();
    found.dedup();
    found.into_iter().map(|(_, id)| id).collect()
}

/// The first hit of a swept convex on one target shape of any kind.
fn cast_against(
    convex: &Convex,
    pose: &Pose,
    translation: Vec3,
    swept: &Aabb,
    target: &Shape,
    at: &Pose,
) -> Option<ShapeCastHit> {
    let earliest = |a: Option<ShapeCastHit>, b: Option<ShapeCastHit>| match (a, b) {
        (Some(x), Some(y)) => Some(if y.t < x.t { y } else { x }),
        (x, None) => x,
        (None, y) => y,
    };
    match target {
        Shape::Compound(children) => children.iter().fold(None, |acc, c| {
            let child_pose = at.mul(&Pose::new(c.position, c.orientation));
            earliest(
                acc,
                cast_against(convex, pose, translation, swept, &c.shape, &child_pose),
            )
        }),
        Shape::Plane { normal, offset } => cast_against_plane(
            convex,
            pose,
            translation,
            at.transform_vector(*normal),
            at.position,
            *offset,
        ),
        Shape::TriMesh(mesh) => {
            let mut best = None;
            mesh.for_each_triangle_in(&local_box(swept, at), |i| {
                let t = Convex::Triangle(mesh.triangle(i));
                best = earliest(best, query::cast_shape(convex, pose, translation, &t, at));
            });
            best
        }
        Shape::HeightField(field) => {
            let mut best = None;
            field.for_each_triangle_in(&local_box(swept, at), |_, tri| {
                let t = Convex::Triangle(tri);
                best = earliest(best, query::cast_shape(convex, pose, translation, &t, at));
            });
            best
        }
        _ => Convex::from_shape(target)
            .and_then(|c| query::cast_shape(convex, pose, translation, &c, at)),
    }
}

/// A world box seen in a body's frame (the box around its eight corners).
fn local_box(world: &Aabb, at: &Pose) -> Aabb {
    world.mapped(|c| at.inverse_transform_point(c))
}

/// A convex moving along `translation` against the half-space n·(x − origin) ≤ offset:
/// its deepest point along −n reaches the surface when n·(p + t d − origin) = offset.
fn cast_against_plane(
    convex: &Convex,
    pose: &Pose,
    translation: Vec3,
    n: Vec3,
    origin: Vec3,
    offset: Real,
) -> Option<ShapeCastHit> {
    let deepest = pose.transform_point(convex.support(pose.inverse_transform_vector(-n)));
    let gap = n.dot(deepest - origin) - offset;
    if gap <= 0.0 {
        return Some(ShapeCastHit {
            t: 0.0,
            normal: n,
            point: deepest,
        });
    }
    let closing = -n.dot(translation);
    if closing <= 0.0 || gap > closing {
        return None;
    }
    let t = gap / closing;
    Some(ShapeCastHit {
        t,
        normal: n,
        point: deepest + translation * t,
    })
}
