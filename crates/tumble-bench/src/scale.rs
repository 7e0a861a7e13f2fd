//! Box3D's benchmark scenes at their published sizes (issue 16, point 3), built once as a
//! [`SceneSpec`] so Tumble and rapier get the same numbers, each with the step counts
//! `compare --scale` times and the quality figure it prints beside the time.
//!
//! Matched against erincatto/box3d's `shared/benchmarks.c` (`CreateLargePyramid`,
//! `CreateManyPyramids`, `CreateJointGrid`):
//!
//! - `large_pyramid`: Box3D's layout (a pyramid one cube thick in the plane z = 0, each
//!   row shifted by half a cube) with the base of 100 (5,050 cubes; Box2D's size,
//!   Box3D's current file uses 90).
//! - `many_pyramids`: Box3D's counts, 14 × 14 of the same one-cube-thick pyramids with a
//!   base of 10 (55 cubes each, 10,780 cubes), 11 m apart along x as in Box3D; along z
//!   Box3D spreads the rows over its ground (11.7 m apart), here they are 11 m apart too.
//! - `joint_grid_large`: 100 × 100, Box3D's count; see [`crate::joint_grid_large`].
//! - `rain_large`: not Box3D's rain (ragdolls on meshes, which neither engine here has in
//!   common) but this crate's rain scaled to 10,000 bodies.
//!
//! Box3D's grounds are boxes and its densities 1 or 100; here the ground is the plane
//! y = 0 and every body has the crate's density, as in [`crate::pyramid`]: a uniform
//! density does not change how a stack under gravity moves.

use crate::{fixed, rain_grid, BodySpec, SceneSpec, ShapeSpec};

/// Cubes along the base of [`large_pyramid`].
pub const LARGE_PYRAMID_BASE: usize = 100;
/// Pyramids along x and along z in [`many_pyramids`].
pub const MANY_PYRAMIDS_GRID: usize = 14;
/// Cubes along the base of each of [`many_pyramids`]' pyramids.
pub const MANY_PYRAMIDS_BASE: usize = 10;
/// Distance between neighbouring pyramids' centres in [`many_pyramids`] (m): a base of
/// 10 m and a 1 m gap.
pub const MANY_PYRAMIDS_SPACING: f64 = 11.0;
/// Bodies along each side of a layer of [`rain_large`].
pub const RAIN_LARGE_COLUMNS: usize = 25;
/// Layers of [`rain_large`].
pub const RAIN_LARGE_LAYERS: usize = 16;
/// Inner half width of [`rain_large`]'s container (m).
pub const RAIN_LARGE_HALF_WIDTH: f64 = 0.5 * RAIN_LARGE_COLUMNS as f64;

// The windows are short so that `compare --scale` (three engines, three runs each) takes
// minutes on two cores: a step of the large pyramid took about 0.5 s in Tumble and 0.07 s in
// rapier on this (shared) 2-core machine, many pyramids and the rain about 0.3 s each.

/// Untimed steps before the timed window of the two pyramid scenes (half a second: the
/// first contacts' settling is not the steady state).
pub const SCALE_PYRAMID_SETTLE_STEPS: usize = 30;
/// Timed steps of the two pyramid scenes (half a second).
pub const SCALE_PYRAMID_TIMED_STEPS: usize = 30;
/// Untimed steps before the large joint grid's timed window.
pub const SCALE_JOINT_GRID_SETTLE_STEPS: usize = 30;
/// Timed steps of the large joint grid (half a second).
pub const SCALE_JOINT_GRID_TIMED_STEPS: usize = 30;
/// Timed steps of the large rain, from the drop (two seconds: the top layer, 17.5 m up,
/// lands after 1.9 s, so the count sees every body down).
pub const RAIN_LARGE_TIMED_STEPS: usize = 120;

/// Adds a pyramid of unit cubes one cube thick in the plane z = `z`, standing on y = 0
/// and centred on x = `center_x`: row r (r = 0 at the bottom) has `base` − r cubes at
/// y = 0.5 + r, side by side, so each row sits half a cube in from the one below.
fn push_wall_pyramid(bodies: &mut Vec<BodySpec>, base: usize, center_x: f64, z: f64) {
    for row in 0..base {
        let n = base - row;
        let first = center_x - 0.5 * (n as f64 - 1.0);
        for i in 0..n {
            bodies.push(BodySpec {
                dynamic: true,
                shape: ShapeSpec::Cuboid([0.5; 3]),
                position: [first + i as f64, 0.5 + row as f64, z],
                rotation: [0.0; 3],
            });
        }
    }
}

/// Box3D's large pyramid at a base of 100: 5,050 unit cubes one cube thick in the plane
/// z = 0, centred on x = 0, on the ground y = 0.
pub fn large_pyramid() -> SceneSpec {
    let mut bodies = vec![fixed(ShapeSpec::Ground, [0.0; 3])];
    push_wall_pyramid(&mut bodies, LARGE_PYRAMID_BASE, 0.0, 0.0);
    SceneSpec {
        name: "large_pyramid",
        bodies,
        joints: Vec::new(),
    }
}

/// Box3D's many pyramids: 14 × 14 pyramids of base 10 (55 cubes each, 10,780 in all),
/// each one cube thick in a plane of constant z, their centres 11 m apart along x and z
/// on a square centred on the origin, on the ground y = 0.
pub fn many_pyramids() -> SceneSpec {
    let n = MANY_PYRAMIDS_GRID;
    let first = -0.5 * (n as f64 - 1.0) * MANY_PYRAMIDS_SPACING;
    let mut bodies = vec![fixed(ShapeSpec::Ground, [0.0; 3])];
    for row in 0..n {
        for column in 0..n {
            push_wall_pyramid(
                &mut bodies,
                MANY_PYRAMIDS_BASE,
                first + column as f64 * MANY_PYRAMIDS_SPACING,
                first + row as f64 * MANY_PYRAMIDS_SPACING,
            );
        }
    }
    SceneSpec {
        name: "many_pyramids",
        bodies,
        joints: Vec::new(),
    }
}

/// The rain scaled to 10,000 bodies: 25 × 25 per layer, 16 layers (5,000 spheres and
/// 5,000 boxes in the same checkerboard), 1 m apart across and 0.9 m up from y = 4, in a
/// 25 m × 25 m container with the same 3 m walls, on a 55 m floor; jitter and turns from
/// the same generator ([`rain_grid`]). Every body starts inside the walls
/// (12 + 0.05 + 0.433 < 12.5) and apart from the others, as in [`crate::rain`].
pub fn rain_large() -> SceneSpec {
    rain_grid("rain_large", RAIN_LARGE_COLUMNS, RAIN_LARGE_LAYERS)
}
