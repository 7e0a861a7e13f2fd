//! Tumble: a rigid-body dynamics engine.
//!
//! ```
//! use tumble::prelude::*;
//! let mut world = World::new(&WorldDef::default());
//! let ball = world
//!     .create_body(
//!         &BodyDef { position: Vec3::new(0.0, 5.0, 0.0), mass: MassSpec::Mass(1.0), ..Default::default() },
//!         Shape::sphere(0.1),
//!     )
//!     .unwrap();
//! world.step(0.01).unwrap();
//! assert!(world.body(ball).unwrap().position().y < 5.0);
//! ```
#![warn(missing_docs)]

pub mod analysis;
pub mod body;
pub mod broad_phase;
pub(crate) mod ccd;
pub mod contact_cache;
pub mod diagnostics;
pub mod error;
pub mod force;
pub mod geometry;
pub(crate) mod handles;
pub mod id;
pub mod integrate;
pub(crate) mod island;
pub mod joint;
pub mod math;
pub mod narrow_phase;
pub mod query;
pub mod shape;
pub mod solver;
pub(crate) mod speculative;
mod step;
pub mod world;
mod world_bodies;
mod world_forces;
mod world_joints;
pub mod world_query;

pub use body::{Body, BodyDef, BodyKind, InertiaSpec, MassSpec};
pub use contact_cache::{Contact, ContactEvent, ContactEventKind};
pub use diagnostics::Diagnostics;
pub use error::{Error, Result};
pub use force::{
    AppliedForce, Drag, Force, ForceCallback, ForceContext, Spring, SpringEnd, Wrench,
};
pub use geometry::{Aabb, Convex, Pose, Ray, RayHit};
pub use id::{BodyId, ForceId};
pub use integrate::Integrator;
pub use joint::{Joint, JointDef, JointId, JointKind, JointSpring, Motor};
pub use math::{Mat3, Quat, Real, Vec3};
pub use narrow_phase::{ContactPoint, Manifold};
pub use shape::{CompoundChild, ConvexHull, HeightField, MassProperties, Shape, TriMesh};
pub use solver::{SolverKind, SolverSettings};
pub use world::{World, WorldDef};
pub use world_query::{QueryFilter, WorldRayHit, WorldShapeHit};

/// Everything a typical user needs, in one import.
pub mod prelude {
    pub use crate::{
        AppliedForce, Body, BodyDef, BodyId, BodyKind, CompoundChild, Diagnostics, Drag, Error,
        Force, ForceContext, ForceId, InertiaSpec, Integrator, JointDef, JointId, JointKind,
        JointSpring, MassSpec, Mat3, Motor, Quat, Real, Shape, SolverKind, SolverSettings, Spring,
        SpringEnd, Vec3, World, WorldDef,
    };
}
