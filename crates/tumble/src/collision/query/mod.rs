//! Geometric queries on single shapes: ray casts, point queries, shape casts and time of
//! impact, and sweeps of whole shapes (compounds, meshes, planes) built on it. The world-level queries (through the broad phase) live in `pipeline/world/query.rs`.

mod ray;
mod sweep;
mod toi;

pub use ray::{cast_ray, contains_point, project_point, PointProjection};
pub(crate) use sweep::{sweep_shapes, Allowance, Impact, Stop};
pub use toi::{cast_shape, time_of_impact, ShapeCastHit, Sweep, Toi};
