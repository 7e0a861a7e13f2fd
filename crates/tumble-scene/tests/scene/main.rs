//! The scene loader's integration tests (scene files, URDF, MJCF, snapshots), one module
//! per subject in one test binary: separate binaries cost CI minutes to build and link.

mod character_scene;
mod collision_keys;
mod corpus;
mod errors;
mod fuzz;
mod gallery_scenes;
mod joint_scenes;
mod mjcf;
mod robustness;
mod scenes;
mod snapshots;
mod urdf;
