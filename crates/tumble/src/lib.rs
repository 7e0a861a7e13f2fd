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

pub(crate) mod codec;
pub mod collision;
pub mod dynamics;
pub mod error;
pub(crate) mod handles;
pub mod id;
pub mod limits;
pub mod math;
pub mod pipeline;
pub(crate) mod team;
pub mod threads;

// The modules under their short names, as before the layers: `tumble::shape::Shape`.
pub use collision::{broad_phase, geometry, narrow_phase, query, shape};
pub use dynamics::{body, force, integrate, joint, solver};
pub use pipeline::world::query as world_query;
pub use pipeline::{analysis, batch, character, contact_cache, diagnostics, hooks, sensors, world};

pub use batch::{Batch, JointTarget, StepFailure};
pub use body::{Body, BodyDef, BodyKind, InertiaSpec, MassSpec};
pub use character::{CharacterController, CharacterDef, Ground, Push};
pub use collision::contact::{Contact, ContactEvent, ContactEventKind};
pub use diagnostics::Diagnostics;
pub use error::{Error, Result};
pub use force::{
    AppliedForce, Drag, EvaluatedState, Force, ForceCallback, ForceContext, Spring, SpringEnd,
    Wrench,
};
pub use geometry::{Aabb, Pose, Ray, RayHit};
pub use hooks::{ContactMaterial, ContactModification, ContactPair};
pub use id::{BodyId, ForceId};
pub use integrate::Integrator;
pub use joint::{Joint, JointCoordinate, JointDef, JointId, JointKind, JointSpring, Motor, Servo};
pub use limits::SpeedLimits;
pub use math::{Mat3, Quat, Real, Vec3};
pub use narrow_phase::{ContactPoint, Manifold};
pub use sensors::SensorEvent;
pub use shape::Convex;
pub use shape::{CompoundChild, ConvexHull, HeightField, MassProperties, Shape, TriMesh};
pub use solver::{JointTrees, SolverKind, SolverSettings};
pub use world::{bulk::BodyStates, World, WorldDef};
pub use world_query::{QueryFilter, WorldRayHit, WorldShapeHit};

/// Everything a typical user needs, in one import.
pub mod prelude {
    pub use crate::{
        AppliedForce, Body, BodyDef, BodyId, BodyKind, CompoundChild, ContactModification,
        ContactPair, Diagnostics, Drag, Error, Force, ForceContext, ForceId, InertiaSpec,
        Integrator, JointDef, JointId, JointKind, JointSpring, JointTrees, MassSpec, Mat3, Motor,
        Quat, Real, SensorEvent, Servo, Shape, SolverKind, SolverSettings, Spring, SpringEnd, Vec3,
        World, WorldDef,
    };
}
