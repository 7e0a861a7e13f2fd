//! Running a scene and looking at it at a steady frame rate, for pictures and the viewer.

use tumble::{Real, World};
use tumble_scene::RunPlan;

use crate::progress::Progress;
use crate::Failure;

/// Number of frames at `fps` in a run of `plan`: one at t = 0 and one every 1/fps s up to
/// the end (inclusive when it falls on a frame).
pub fn frame_count(plan: &RunPlan, fps: Real) -> u64 {
    (plan.end_time * fps + 1e-6).floor() as u64 + 1
}

/// Steps `world` through `plan`, calling `frame(world, k)` for frame k = 0, 1, ... at the
/// step nearest to k / fps s. Frames past the last step show the final state.
pub fn run_frames(
    world: &mut World,
    plan: &RunPlan,
    fps: Real,
    progress: &mut Progress,
    mut frame: impl FnMut(&World, u64) -> Result<(), Failure>,
) -> Result<u64, Failure> {
    let frames = frame_count(plan, fps);
    frame(world, 0)?;
    let mut next = 1;
    for k in 1..=plan.steps {
        let h = plan.step_dt(k);
        world
            .step(h)
            .map_err(|e| Failure::Runtime(format!("step {k}: {e}")))?;
        let t = plan.time_after(k);
        while next < frames && t + 0.5 * h >= next as Real / fps {
            frame(world, next)?;
            next += 1;
        }
        progress.inc(1);
    }
    while next < frames {
        frame(world, next)?;
        next += 1;
    }
    Ok(frames)
}
