//! How a run is cut into steps.
//!
//! A run of `duration` with step `dt` takes N = ⌈duration / dt⌉ steps. All are `dt` long
//! except, when duration / dt is not a whole number, the last, which is shortened so the
//! run ends exactly at `duration`. "Whole" allows a relative slack of 1e-6, so that
//! 1.0 / 0.01 (100.00000000000001 in f64, 100.0000022 with f32's 0.01) is 100 steps, not
//! 100 and a sliver.

use tumble::Real;

use crate::error::{Result, SceneError};

/// The most steps a run may take, so that a typo such as `"dt": 1e-12` is refused with a
/// message rather than running for days.
pub const MAX_STEPS: u64 = 1_000_000_000;

/// Relative slack within which duration / dt counts as a whole number.
const WHOLE: f64 = 1e-6;

/// The steps of a run: `steps` steps of `dt`, the last of which may be shorter.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RunPlan {
    /// The step (s).
    pub dt: Real,
    /// Number of steps.
    pub steps: u64,
    /// Length of the last step (s); equals `dt` unless the run was cut to a duration.
    pub last_dt: Real,
    /// Time at the end of the run (s).
    pub end_time: Real,
}

impl RunPlan {
    /// A run of `duration` seconds (see the module notes for the step count).
    pub fn from_duration(duration: Real, dt: Real) -> Result<RunPlan> {
        check_settings(duration, dt)?;
        // In f64 whatever `Real` is: the count must not depend on f32 rounding of the ratio.
        let ratio = wide(duration) / wide(dt);
        if ratio > MAX_STEPS as f64 {
            return Err(SceneError::new(
                "duration",
                format!("needs more than {MAX_STEPS} steps of dt; raise dt or shorten the run"),
            ));
        }
        let nearest = ratio.round();
        if (ratio - nearest).abs() <= WHOLE * nearest.max(1.0) {
            return RunPlan::from_steps(nearest as u64, dt);
        }
        let steps = ratio.ceil() as u64;
        let last = wide(duration) - (steps - 1) as f64 * wide(dt);
        Ok(RunPlan {
            dt,
            steps,
            last_dt: last as Real,
            end_time: duration,
        })
    }

    /// Exactly `steps` steps of `dt`.
    pub fn from_steps(steps: u64, dt: Real) -> Result<RunPlan> {
        check_dt(dt)?;
        if steps > MAX_STEPS {
            return Err(SceneError::new("steps", format!("must be <= {MAX_STEPS}")));
        }
        Ok(RunPlan {
            dt,
            steps,
            last_dt: dt,
            end_time: steps as Real * dt,
        })
    }

    /// Length of step `k` (counted from 1) (s).
    pub fn step_dt(&self, k: u64) -> Real {
        if k == self.steps {
            self.last_dt
        } else {
            self.dt
        }
    }

    /// Time after `k` steps (s): k·dt, and `end_time` after the last. Computed rather than
    /// summed so that rounding does not accumulate in the reported times.
    pub fn time_after(&self, k: u64) -> Real {
        if k >= self.steps {
            self.end_time
        } else {
            k as Real * self.dt
        }
    }
}

/// `x` as f64. A cast, not `f64::from`, because `Real` is f64 in the default build and
/// f32 with the `f32` feature; clippy sees only one of the two.
#[allow(clippy::unnecessary_cast)]
fn wide(x: Real) -> f64 {
    x as f64
}

/// Checks `duration` and `dt` each on its own. Whether they make too many steps together
/// is left to planning, since the command line may override either.
pub(crate) fn check_settings(duration: Real, dt: Real) -> Result<()> {
    check_dt(dt)?;
    if !duration.is_finite() {
        return Err(SceneError::new("duration", "must be a finite number"));
    }
    if duration < 0.0 {
        return Err(SceneError::new("duration", "must be >= 0"));
    }
    at_most_engine_magnitude("duration", duration)
}

/// The engine's bound on any coefficient (`tumble::limits::MAX_MAGNITUDE`), in seconds.
fn at_most_engine_magnitude(field: &str, x: Real) -> Result<()> {
    let most = tumble::limits::MAX_MAGNITUDE;
    if x > most {
        let most = tumble::limits::short(most);
        return Err(SceneError::new(field, format!("must be at most {most} s")));
    }
    Ok(())
}

fn check_dt(dt: Real) -> Result<()> {
    if !dt.is_finite() {
        return Err(SceneError::new("dt", "must be a finite number"));
    }
    if dt <= 0.0 {
        return Err(SceneError::new("dt", "must be > 0"));
    }
    at_most_engine_magnitude("dt", dt)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn whole_ratios_take_full_steps() {
        let p = RunPlan::from_duration(1.0, 0.01).unwrap();
        assert_eq!((p.steps, p.last_dt), (100, 0.01));
        assert_eq!(p.time_after(100), 100.0 * 0.01);
        let p = RunPlan::from_duration(20.0, 1.0 / 240.0).unwrap();
        assert_eq!(p.steps, 4800);
    }

    #[test]
    fn a_fractional_ratio_shortens_the_last_step() {
        let p = RunPlan::from_duration(1.0, 0.3).unwrap();
        assert_eq!(p.steps, 4);
        assert!((p.last_dt - 0.1).abs() < 1e-6);
        assert_eq!(p.time_after(4), 1.0);
        assert_eq!(p.step_dt(3), 0.3);
    }

    #[test]
    fn zero_duration_is_no_steps_and_bad_values_are_refused() {
        assert_eq!(RunPlan::from_duration(0.0, 0.01).unwrap().steps, 0);
        let e = |r: Result<RunPlan>| r.unwrap_err().to_string();
        assert_eq!(e(RunPlan::from_duration(1.0, 0.0)), "dt: must be > 0");
        assert_eq!(
            e(RunPlan::from_duration(-1.0, 0.1)),
            "duration: must be >= 0"
        );
        assert_eq!(
            e(RunPlan::from_duration(1e6, 1e-6)),
            "duration: needs more than 1000000000 steps of dt; raise dt or shorten the run"
        );
        assert_eq!(
            e(RunPlan::from_steps(MAX_STEPS + 1, 0.1)),
            "steps: must be <= 1000000000"
        );
    }
}
