//! Every benchmark scene by name, with its measurement: the steps it times and the
//! quality figure printed beside the time (`compare` runs them in both engines, `quick`
//! in Tumble alone).

use crate::{
    count_rain_in, joint_grid, joint_grid_large, large_pyramid, many_pyramids, measure_joint_grid,
    measure_pyramid, pyramid, rain, rain_large, timed_steps, SceneSpec, Simulation, Timing,
    JOINT_GRID_SETTLE_STEPS, JOINT_GRID_TIMED_STEPS, PYRAMID_SETTLE_STEPS, PYRAMID_TIMED_STEPS,
    RAIN_HALF_WIDTH, RAIN_LARGE_HALF_WIDTH, RAIN_LARGE_TIMED_STEPS, RAIN_TIMED_STEPS,
    SCALE_JOINT_GRID_SETTLE_STEPS, SCALE_JOINT_GRID_TIMED_STEPS, SCALE_PYRAMID_SETTLE_STEPS,
    SCALE_PYRAMID_TIMED_STEPS,
};

/// The small scenes, in the order `compare` runs them by default (`all`).
pub const SMALL_SCENES: [&str; 3] = ["pyramid", "rain", "joints"];
/// The scenes at Box3D's sizes, in the order `compare --scale` runs them.
pub const SCALE_SCENES: [&str; 4] = [
    "large_pyramid",
    "many_pyramids",
    "joint_grid_large",
    "rain_large",
];

/// What a scene's quality figure is.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Check {
    /// The largest displacement of any box over the timed steps.
    Drift,
    /// Where the bodies are after the timed steps, for a container of this inner half
    /// width (m).
    Rain(f64),
    /// The largest joint gap and the lowest body after the timed steps.
    Joints,
}

/// A scene's measurement: untimed steps, then timed ones, then the check.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Window {
    /// Untimed steps from the fresh scene.
    pub settle: usize,
    /// Timed steps after them.
    pub timed: usize,
    /// The quality figure.
    pub check: Check,
}

/// The scene called `name` (one of [`SMALL_SCENES`] or [`SCALE_SCENES`]).
pub fn scene_named(name: &str) -> Option<SceneSpec> {
    Some(match name {
        "pyramid" => pyramid(),
        "rain" => rain(),
        "joints" => joint_grid(),
        "large_pyramid" => large_pyramid(),
        "many_pyramids" => many_pyramids(),
        "joint_grid_large" => joint_grid_large(),
        "rain_large" => rain_large(),
        _ => return None,
    })
}

/// How the scene called `name` is measured.
pub fn window(name: &str) -> Option<Window> {
    let w = |settle, timed, check| {
        Some(Window {
            settle,
            timed,
            check,
        })
    };
    match name {
        "pyramid" => w(PYRAMID_SETTLE_STEPS, PYRAMID_TIMED_STEPS, Check::Drift),
        "large_pyramid" | "many_pyramids" => w(
            SCALE_PYRAMID_SETTLE_STEPS,
            SCALE_PYRAMID_TIMED_STEPS,
            Check::Drift,
        ),
        "rain" => w(0, RAIN_TIMED_STEPS, Check::Rain(RAIN_HALF_WIDTH)),
        "rain_large" => w(
            0,
            RAIN_LARGE_TIMED_STEPS,
            Check::Rain(RAIN_LARGE_HALF_WIDTH),
        ),
        "joints" => w(
            JOINT_GRID_SETTLE_STEPS,
            JOINT_GRID_TIMED_STEPS,
            Check::Joints,
        ),
        "joint_grid_large" => w(
            SCALE_JOINT_GRID_SETTLE_STEPS,
            SCALE_JOINT_GRID_TIMED_STEPS,
            Check::Joints,
        ),
        _ => None,
    }
}

/// Steps a freshly built scene through `window`: the timing of the timed steps and the
/// check as one line of text.
pub fn measure(window: Window, sim: &mut dyn Simulation) -> (Timing, String) {
    let Window {
        settle,
        timed,
        check,
    } = window;
    match check {
        Check::Drift => {
            let r = measure_pyramid(sim, settle, timed);
            let note = format!(
                "drift {:.2} mm (from t = 0: {:.2} mm)",
                r.drift * 1e3,
                r.drift_from_start * 1e3
            );
            (r.timing, note)
        }
        Check::Joints => {
            let r = measure_joint_grid(sim, settle, timed);
            let note = format!(
                "max joint gap {:.2} mm, lowest y {:.3} m",
                r.max_gap * 1e3,
                r.lowest_y
            );
            (r.timing, note)
        }
        Check::Rain(half_width) => {
            for _ in 0..settle {
                sim.step();
            }
            let t = timed_steps(sim, timed);
            let c = count_rain_in(&sim.dynamic_positions(), half_width);
            let note = format!(
                "inside {} / outside {} / off floor {}",
                c.inside, c.outside, c.off_floor
            );
            (t, note)
        }
    }
}

/// What `window` times and checks, in words, for a header.
pub fn describe(window: Window) -> String {
    let check = match window.check {
        Check::Drift => {
            "drift = largest box displacement over the timed steps (and from t = 0, settling \
             included)"
        }
        Check::Rain(_) => {
            "where the bodies are after them (inside the walls / spilled onto the floor / off it)"
        }
        Check::Joints => "largest distance between a joint's two anchors, lowest body after them",
    };
    format!(
        "steps {}-{} timed; {check}",
        window.settle,
        window.settle + window.timed
    )
}
