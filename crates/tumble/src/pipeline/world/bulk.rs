//! Every body's state at once, all or nothing.
//!
//! Python's bulk arrays (`world.positions = ...`, `world.set_state(...)`) set one or more
//! quantities of every body in one call. Made one body at a time through the single
//! setters, a refused row half-way would leave the bodies before it changed and the rest
//! not, and a refused velocity array would leave the positions given with it applied: the
//! call fails but the world has moved. Here every row of every array is checked first,
//! with the single setters' own checks, and only then is anything written; the writes go
//! through those setters, in the order a caller of them would use, so a bulk edit is the
//! same world, bit for bit, as the single edits it stands for.

use crate::error::{check, Error, Result};
use crate::limits::MAX_COORDINATE;
use crate::math::{Quat, Vec3};
use crate::pipeline::world::{check_speeds, World};

/// New values of some quantities for every body, one row per body in creation order (the
/// order of [`World::body_ids`]); a `None` leaves that quantity as it is.
#[derive(Debug, Clone, Copy, Default)]
pub struct BodyStates<'a> {
    /// Each body frame's origin (m, world frame).
    pub positions: Option<&'a [Vec3]>,
    /// Each body's orientation, body frame to world: any non-zero quaternion, normalised.
    pub orientations: Option<&'a [Quat]>,
    /// Each centre of mass's velocity (m/s, world frame).
    pub velocities: Option<&'a [Vec3]>,
    /// Each body's angular velocity (rad/s, world frame); L follows as I_world ω.
    pub angular_velocities: Option<&'a [Vec3]>,
}

/// The error of one row, renamed from the single setter's field (`velocity`) to the row's
/// (`velocities[3]`): the caller gave an array, so the array's row is what it must fix.
fn in_row(name: &'static str, i: usize) -> impl Fn(Error) -> Error {
    move |e| match e {
        Error::InvalidField { reason, .. } => Error::invalid(format!("{name}[{i}]"), reason),
        other => other,
    }
}

/// One row per body, or the error saying how many there must be.
fn rows<'a, T>(name: &str, rows: Option<&'a [T]>, bodies: usize) -> Result<&'a [T]> {
    match rows {
        Some(r) if r.len() != bodies => Err(Error::invalid(
            name,
            format!("expected {bodies} rows (one per body), got {}", r.len()),
        )),
        Some(r) => Ok(r),
        None => Ok(&[]),
    }
}

impl World {
    /// Sets the quantities of `states` for every body: all positions first, then
    /// orientations (each body turning about its new origin), velocities, and angular
    /// velocities last (so ω becomes L with the new orientation), exactly as the single
    /// setters called in that order would. Fails, changing nothing, if an array does not
    /// have one row per body or any row is refused by its single setter's check; the
    /// error names the row: `velocities[3]: must be finite numbers`.
    pub fn set_states(&mut self, states: &BodyStates<'_>) -> Result<()> {
        self.check_states(states)?;
        // Checked above with the setters' own checks, so none of these fails: a failure
        // here would be a check added to a setter and not to `check_states`.
        let ids = self.body_ids().to_vec();
        for (&id, &p) in ids.iter().zip(states.positions.unwrap_or_default()) {
            self.set_position(id, p)?;
        }
        for (&id, &q) in ids.iter().zip(states.orientations.unwrap_or_default()) {
            self.set_orientation(id, q)?;
        }
        for (&id, &v) in ids.iter().zip(states.velocities.unwrap_or_default()) {
            self.set_linear_velocity(id, v)?;
        }
        for (&id, &w) in ids
            .iter()
            .zip(states.angular_velocities.unwrap_or_default())
        {
            self.set_angular_velocity(id, w)?;
        }
        Ok(())
    }

    /// Every row of `states` against what its single setter accepts, in the order
    /// `set_states` applies them (so the error is the first the setters would meet).
    pub(crate) fn check_states(&self, states: &BodyStates<'_>) -> Result<()> {
        let n = self.body_count();
        let limits = self.settings.limits;
        for (i, &p) in rows("positions", states.positions, n)?.iter().enumerate() {
            check::vec3_at_most("position", p, MAX_COORDINATE, "m")
                .map_err(in_row("positions", i))?;
        }
        for (i, &q) in rows("orientations", states.orientations, n)?
            .iter()
            .enumerate()
        {
            check::rotation("orientation", q).map_err(in_row("orientations", i))?;
        }
        for (i, &v) in rows("velocities", states.velocities, n)?.iter().enumerate() {
            check_speeds(&limits, v, Vec3::ZERO).map_err(in_row("velocities", i))?;
        }
        let omegas = rows("angular_velocities", states.angular_velocities, n)?;
        for (i, &w) in omegas.iter().enumerate() {
            check_speeds(&limits, Vec3::ZERO, w).map_err(in_row("angular_velocities", i))?;
        }
        Ok(())
    }
}
