//! Collision: geometry and shapes, and the questions asked of them, with no notion of
//! bodies, mass or time. The layer above (`dynamics`) owns bodies; nothing here imports
//! it.
//!
//! ```text
//! geometry      Pose, Aabb, Ray: the vocabulary
//! shape         Shape and its kinds, mass properties, bounds, Convex (support view)
//! broad_phase   dynamic AABB trees, the pair set, filters
//! narrow_phase  contact manifolds of a shape pair
//! query         ray casts, point queries, shape casts and time of impact
//! contact       a contact between two bodies as data: the manifold, ids, events
//! ```

pub mod broad_phase;
pub mod contact;
pub mod geometry;
pub mod narrow_phase;
pub mod query;
pub mod shape;
