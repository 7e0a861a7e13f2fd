//! The command-line program's integration tests, one module per subject in one test
//! binary: separate binaries cost CI minutes to build and link.

mod common;

mod cli;
mod failures;
mod gltf;
mod messages;
mod mjcf;
mod outputs;
mod save_state;
mod sweep;
mod thread_counts;
mod urdf;
mod visual;
