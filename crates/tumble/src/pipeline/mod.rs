//! The pipeline: the world that owns bodies, shapes, forces and joints, and the step that
//! runs collision and dynamics over them in stages (`world/step.rs`).
//!
//! ```text
//! world/         World, WorldDef and the stores of its lasting state (mod.rs); body,
//!                force and joint edits (bodies.rs, forces.rs, joints.rs); ray casts,
//!                shape casts and overlaps (query.rs); World::step, its stages and the
//!                step context (step.rs)
//! contact_cache  persistent manifolds: broad and narrow phase into warm-started contacts
//! hooks          the contact filter and modifier, one-way bodies
//! sensors        sensors' overlaps and their begin/end events
//! speculative    speculative contacts the step will not reach (no ghost collisions)
//! ccd            sweeps of fast bodies back to their time of impact
//! character/     the character controller: a kinematic capsule that slides, climbs
//!                slopes and steps, snaps to the ground and pushes bodies, over `&World`
//! diagnostics    energies, momenta, state hash
//! batch          W copies of a world stepped together on a thread pool (worlds as the
//!                unit of parallelism), with per-world resets, states, forces, joint targets
//! analysis       convergence order, energy behaviour, stability of the integrators
//! ```

pub mod analysis;
pub mod batch;
pub(crate) mod ccd;
pub mod character;
pub mod contact_cache;
pub mod diagnostics;
pub mod hooks;
pub mod sensors;
pub(crate) mod speculative;
pub mod world;
