//! Geometric queries on single shapes: ray casts, point queries, shape casts and time of
//! impact. The world-level queries (through the broad phase) live in `pipeline/world/query.rs`.

mod ray;
mod toi;

pub use ray::{cast_ray, contains_point, project_point, PointProjection};
pub use toi::{cast_shape, time_of_impact, ShapeCastHit, Sweep, Toi};
