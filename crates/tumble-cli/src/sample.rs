//! Running a scene and looking at it at a steady frame rate, for pictures and the viewer.

use tumble::{Real, World};
use tumble_scene::{RunPlan, Scene};

use crate::progress::Progress;
use crate::Failure;

/// Number of frames at `fps` in a run of `plan`: one at t = 0 and one every 1/fps s up to
/// the end (inclusive when it falls on a frame).
pub fn frame_count(plan: &RunPlan, fps: Real) -> u64 {
    (plan.end_time * fps + 1e-6).floor() as u64 + 1
}

/// Steps `scene` through `plan` (its character's move, then the world's step), calling
/// `frame(world, k)` for frame k = 0, 1, ... at the step nearest to k / fps s. Frames past
/// the last step show the final state. A step that fails stops the run with no more
/// frames: its failure is returned in `Ok(Some(..))`, so that the caller can still write
/// the frames it has; `Err` is the callback's own.
pub fn run_frames(
    scene: &mut Scene,
    plan: &RunPlan,
    fps: Real,
    progress: &mut Progress,
    mut frame: impl FnMut(&World, u64) -> Result<(), Failure>,
) -> Result<Option<Failure>, Failure> {
    let frames = frame_count(plan, fps);
    frame(&scene.world, 0)?;
    let mut next = 1;
    for k in 1..=plan.steps {
        let h = plan.step_dt(k);
        if let Err(e) = scene.step(h) {
            return Ok(Some(step_failure(k, e)));
        }
        let t = plan.time_after(k);
        while next < frames && t + 0.5 * h >= next as Real / fps {
            frame(&scene.world, next)?;
            next += 1;
        }
        progress.inc(1);
    }
    while next < frames {
        frame(&scene.world, next)?;
        next += 1;
    }
    Ok(None)
}

/// The line a failed step `k` ends a run with (exit 1). The engine's account of an unstable
/// step already names the step, the time, the body and the quantity; any other refusal
/// gets the step's number in front.
pub fn step_failure(k: u64, e: tumble::Error) -> Failure {
    match e {
        tumble::Error::Unstable(_)
        | tumble::Error::TooManyContacts(_)
        | tumble::Error::CallbackFailed(_) => Failure::Runtime(e.to_string()),
        other => Failure::Runtime(format!("step {k}: {other}")),
    }
}
