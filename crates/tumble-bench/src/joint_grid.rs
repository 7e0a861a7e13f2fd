//! The joint grid: a net of small balls held together by ball joints, as in rapier's
//! `joint_ball3` and Box2D's `joint_grid` benchmarks. It measures the joint solver: the
//! balls are too far apart to touch their neighbours, so almost all the work is joints.

use crate::{BallJointSpec, BodySpec, SceneSpec, ShapeSpec, Simulation, Timing};

/// Bodies along each side of the grid.
pub const JOINT_GRID_SIZE: usize = 30;
/// Distance between neighbouring bodies (m); each joint's anchors sit halfway.
pub const JOINT_GRID_SPACING: f64 = 1.0;
/// Radius of each ball (m), rapier's `joint_ball3` value. With 0.1 m balls (anchors five
/// radii out, so turning dominates each joint's effective mass 60 to 1) Tumble's default
/// settings tear the net apart at about step 120 as its tension peaks; 8 substeps or 2
/// iterations hold it (gaps ≤ 6.5 cm and 0.5 m). See docs/integrators.md, "Joints".
pub const JOINT_GRID_RADIUS: f64 = 0.4;
/// Untimed steps before the timed window.
pub const JOINT_GRID_SETTLE_STEPS: usize = 30;
/// Timed steps (five simulated seconds).
pub const JOINT_GRID_TIMED_STEPS: usize = 300;

/// Whether the body at column `c` (along x) of the first row (z = 0) is fixed: every
/// fourth one and the last, rapier's `joint_ball3` pattern (`i == 0 && (k % 4 == 0 ||
/// k == num - 1)`); every other body is dynamic.
fn is_fixed(column: usize, row: usize, n: usize) -> bool {
    row == 0 && (column.is_multiple_of(4) || column == n - 1)
}

/// 30 × 30 balls (radius 0.4 m) 1 m apart on the plane y = 0, body `row * 30 + column` at
/// x = column − 14.5, z = row. Nine bodies of the row z = 0 are fixed (columns 0, 4, …,
/// 28 and 29, rapier's pattern), so the net hangs from that edge and swings down.
///
/// Each body is joined by a ball joint to its neighbour at +x (anchors ±0.5 m along x)
/// and its neighbour at +z (anchors ±0.5 m along z): 2 · 30 · 29 = 1,740 pairs, less the
/// one between the two fixed bodies at columns 28 and 29, which could never move: 1,739
/// joints. There is no ground.
pub fn joint_grid() -> SceneSpec {
    joint_grid_of("joints", JOINT_GRID_SIZE)
}

/// Bodies along each side of [`joint_grid_large`]: Box2D's and Box3D's joint grid size.
pub const JOINT_GRID_LARGE_SIZE: usize = 100;

/// [`joint_grid`] at Box3D's size: 100 × 100 balls, 26 fixed (columns 0, 4, …, 96 and
/// 99 of the first row), 2 · 100 · 99 = 19,800 joints (no two fixed bodies are
/// neighbours). Box3D's own grid hangs in the vertical plane from its whole top row; this
/// is the existing net, generalised, so the two sizes compare.
pub fn joint_grid_large() -> SceneSpec {
    joint_grid_of("joint_grid_large", JOINT_GRID_LARGE_SIZE)
}

/// The joint grid with `n` × `n` balls (n ≥ 2), named `name`; [`joint_grid`] is n = 30.
pub fn joint_grid_of(name: &'static str, n: usize) -> SceneSpec {
    let s = JOINT_GRID_SPACING;
    let first = -0.5 * (n as f64 - 1.0) * s;
    let mut bodies = Vec::with_capacity(n * n);
    for row in 0..n {
        for column in 0..n {
            bodies.push(BodySpec {
                dynamic: !is_fixed(column, row, n),
                shape: ShapeSpec::Sphere(JOINT_GRID_RADIUS),
                position: [first + column as f64 * s, 0.0, row as f64 * s],
                rotation: [0.0; 3],
            });
        }
    }
    let mut joints = Vec::with_capacity(2 * n * (n - 1));
    let mut join = |a: usize, b: usize, axis: usize| {
        if bodies[a].dynamic || bodies[b].dynamic {
            let mut anchor = [0.0; 3];
            anchor[axis] = 0.5 * s;
            joints.push(BallJointSpec {
                bodies: [a, b],
                anchors: [anchor, anchor.map(|x| -x)],
            });
        }
    };
    for row in 0..n {
        for column in 0..n {
            let i = row * n + column;
            if column + 1 < n {
                join(i, i + 1, 0);
            }
            if row + 1 < n {
                join(i, i + n, 2);
            }
        }
    }
    SceneSpec {
        name,
        bodies,
        joints,
    }
}

/// The joint-grid measurement.
#[derive(Debug, Clone, PartialEq)]
pub struct JointGridResult {
    /// The timed steps.
    pub timing: Timing,
    /// Largest distance between the two world anchors of any joint after the last step
    /// (m); NaN if any is not finite.
    pub max_gap: f64,
    /// Lowest y of any body after the last step (m); NaN if any is not finite.
    pub lowest_y: f64,
}

/// Steps a freshly built joint grid `settle` times untimed, then `timed` times timed.
pub fn measure_joint_grid(
    sim: &mut dyn Simulation,
    settle: usize,
    timed: usize,
) -> JointGridResult {
    for _ in 0..settle {
        sim.step();
    }
    let timing = crate::timed_steps(sim, timed);
    JointGridResult {
        timing,
        max_gap: nan_max(sim.joint_gaps()),
        lowest_y: -nan_max(sim.dynamic_positions().iter().map(|p| -p[1])),
    }
}

/// Largest of `xs` (−∞ if empty), NaN if any is NaN.
fn nan_max(xs: impl IntoIterator<Item = f64>) -> f64 {
    xs.into_iter().fold(f64::NEG_INFINITY, |m, x| {
        if x.is_nan() || m.is_nan() {
            f64::NAN
        } else {
            m.max(x)
        }
    })
}
