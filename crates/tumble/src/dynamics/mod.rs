//! Dynamics: bodies and what moves them, in time. Uses `collision` for shapes and
//! contacts; knows nothing of the world that owns it (`pipeline`).
//!
//! ```text
//! body        Body, its definition, mass properties and state (Motion: x, q, v, L, ω)
//! force       force elements and callbacks; the wrench every integrator asks for
//! integrate   the seven integrators, their memory, the exact free rotor
//! joint       joint kinds described as data, definitions, checks
//! solver      contacts and joints as impulses in substeps; the step's body representation
//! island      islands and sleeping
//! ```

pub mod body;
pub mod force;
pub mod integrate;
pub(crate) mod island;
pub mod joint;
pub mod solver;
