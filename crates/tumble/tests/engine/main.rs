//! The engine's integration tests, one module per subject, in one test binary: 38
//! binaries took a minute of CI's build each time to compile and link on their own.

mod common;

mod atomic_edits;
mod batch;
mod body_setters;
mod broad_phase;
mod character;
mod contact_dynamics;
mod contact_hooks;
mod contact_pairs;
mod continuous_collision;
mod convex_contacts;
mod crowds;
mod damping;
mod fast_spin_joints;
mod finite_state;
mod force_callbacks;
mod free_fall;
mod heavy_loads;
mod joint_armature;
mod joint_chains;
mod joint_control;
mod joint_trees;
mod joints;
mod kinematic_targets;
mod mass;
mod meshes;
mod one_way;
mod oscillator;
mod overlap_recovery;
mod planar_and_forces;
mod ray_casts;
mod rolling_contact;
mod rolling_friction;
mod rotation;
mod sensors;
mod slow_bounces;
mod snapshots;
mod source_shape;
mod tall_stacks;
mod threads;
mod world;
mod world_collision;
