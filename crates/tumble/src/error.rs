//! Typed errors. Every validation error names the offending field by its path, so the CLI
//! and Python can print `bodies[3].shape.radius: must be > 0` without re-deriving it.

use crate::id::BodyId;

/// Result alias used throughout the crate.
pub type Result<T, E = Error> = std::result::Result<T, E>;

/// Everything the library can refuse. It never panics on user input instead.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum Error {
    /// A value failed validation; `field` is its path (`shape.radius`, `orientation`).
    #[error("{field}: {reason}")]
    InvalidField {
        /// Path of the offending field, relative to the call that received it.
        field: String,
        /// What is wrong with it, phrased as a requirement (`must be > 0`).
        reason: String,
    },
    /// A body id that never existed or whose body was removed.
    #[error("{field}: unknown or removed body {id:?}")]
    UnknownBody {
        /// Path of the field that held the id.
        field: String,
        /// The id.
        id: BodyId,
    },
    /// A step's result broke the finite-state invariant (a quantity not finite, or a speed
    /// beyond the world's limits); the step was undone, the world is as before it.
    #[error("{}", unstable_message(.0))]
    Unstable(Box<Unstable>),
    /// A step needed more contact manifolds than `ContactLimits::per_step` allows; the step
    /// was undone, the world is as before it.
    #[error(
        "step {} (t = {} s): max_contacts: the step needs more than {} contact manifolds; \
         raise max_contacts, or start the bodies apart",
        .0.step,
        crate::limits::short(.0.time),
        .0.limit
    )]
    TooManyContacts(Box<TooManyContacts>),
    /// A force callback stopped the step ([`ForceContext::fail`]); the step was undone,
    /// the world is as before it.
    ///
    /// [`ForceContext::fail`]: crate::dynamics::force::ForceContext::fail
    #[error(
        "step {} (t = {} s): force callback: {}",
        .0.step,
        crate::limits::short(.0.time),
        .0.reason
    )]
    CallbackFailed(Box<CallbackFailed>),
    /// A snapshot could not be read (truncated, corrupted, another format version or
    /// precision, or force callbacks that do not match); the target world is unchanged.
    #[error("snapshot: {what}")]
    Snapshot {
        /// What is wrong, with the byte offset where it was found.
        what: String,
    },
}

/// Which step a force callback stopped, and the callback's reason.
#[derive(Debug, Clone, PartialEq)]
pub struct CallbackFailed {
    /// The number of the failed step (the world had taken `step - 1`).
    pub step: u64,
    /// Simulated time the failed step would have reached (s).
    pub time: crate::math::Real,
    /// What the callback said (the first callback to fail in the step).
    pub reason: String,
}

/// Which step ran out of contact capacity, and the limit it reached.
#[derive(Debug, Clone, PartialEq)]
pub struct TooManyContacts {
    /// The number of the failed step (the world had taken `step - 1`).
    pub step: u64,
    /// Simulated time the failed step would have reached (s).
    pub time: crate::math::Real,
    /// The limit, `ContactLimits::per_step`.
    pub limit: u32,
}

/// Where and when a step failed: the step number (the first step is 1), its start time,
/// the body by creation index, id and name, and what went wrong with which quantity.
#[derive(Debug, Clone, PartialEq)]
pub struct Unstable {
    /// The number of the failed step (the world had taken `step - 1`).
    pub step: u64,
    /// Simulated time the failed step would have reached (s).
    pub time: crate::math::Real,
    /// The body's index in creation order (`bodies[i]` of its scene).
    pub index: usize,
    /// The body's handle.
    pub body: BodyId,
    /// The body's name, if it has one.
    pub name: Option<String>,
    /// `position`, `orientation`, `velocity`, `angular_velocity` or `angular_momentum`.
    pub quantity: &'static str,
    /// `is not finite`, or the speed reached and the limit.
    pub problem: String,
}

fn unstable_message(u: &Unstable) -> String {
    let name = match &u.name {
        Some(n) => format!(" {n:?}"),
        None => String::new(),
    };
    format!(
        "step {} (t = {} s): bodies[{}]{name}: {} {}",
        u.step,
        crate::limits::short(u.time),
        u.index,
        u.quantity,
        u.problem
    )
}

impl Error {
    /// A snapshot error saying `what` is wrong.
    pub fn snapshot(what: impl Into<String>) -> Self {
        Error::Snapshot { what: what.into() }
    }

    /// A validation error for `field`.
    pub fn invalid(field: impl Into<String>, reason: impl Into<String>) -> Self {
        Error::InvalidField {
            field: field.into(),
            reason: reason.into(),
        }
    }

    /// The same error seen from an enclosing structure: `radius` under `shape` becomes
    /// `shape.radius`; an index prefix such as `bodies[3]` works the same way.
    pub fn within(self, prefix: &str) -> Self {
        let join = |f: String| {
            if f.is_empty() {
                prefix.to_string()
            } else if f.starts_with('[') {
                format!("{prefix}{f}")
            } else {
                format!("{prefix}.{f}")
            }
        };
        match self {
            Error::InvalidField { field, reason } => Error::InvalidField {
                field: join(field),
                reason,
            },
            Error::UnknownBody { field, id } => Error::UnknownBody {
                field: join(field),
                id,
            },
            other @ (Error::Unstable(_)
            | Error::TooManyContacts(_)
            | Error::CallbackFailed(_)
            | Error::Snapshot { .. }) => other,
        }
    }

    /// The path of the offending field.
    pub fn field(&self) -> &str {
        match self {
            Error::InvalidField { field, .. } | Error::UnknownBody { field, .. } => field,
            Error::Unstable(_) | Error::CallbackFailed(_) => "",
            Error::Snapshot { .. } => "snapshot",
            Error::TooManyContacts(_) => "max_contacts",
        }
    }

    /// Whether this is a step that failed (and was undone) rather than refused input.
    pub fn is_step_failure(&self) -> bool {
        matches!(
            self,
            Error::Unstable(_) | Error::TooManyContacts(_) | Error::CallbackFailed(_)
        )
    }
}

/// Small helpers that turn a failed check into an [`Error::InvalidField`].
pub(crate) mod check {
    use super::{Error, Result};
    use crate::limits::MAX_MAGNITUDE;
    use crate::math::{vec3_is_finite, Quat, Real, Vec3};

    /// Finite, and within `limits::MAX_MAGNITUDE`: no coefficient a step multiplies by
    /// another may overflow (see `limits.rs`).
    pub fn finite(field: &str, x: Real) -> Result<()> {
        if !x.is_finite() {
            Err(Error::invalid(field, "must be a finite number"))
        } else if x.abs() > MAX_MAGNITUDE {
            Err(Error::invalid(field, beyond(MAX_MAGNITUDE, "")))
        } else {
            Ok(())
        }
    }

    pub fn positive(field: &str, x: Real) -> Result<()> {
        finite(field, x)?;
        if x > 0.0 {
            Ok(())
        } else {
            Err(Error::invalid(field, "must be > 0"))
        }
    }

    pub fn non_negative(field: &str, x: Real) -> Result<()> {
        finite(field, x)?;
        if x >= 0.0 {
            Ok(())
        } else {
            Err(Error::invalid(field, "must be >= 0"))
        }
    }

    /// Finite and at most `limit` in magnitude (`unit` follows the limit in the message).
    pub fn at_most(field: &str, x: Real, limit: Real, unit: &str) -> Result<()> {
        finite(field, x)?;
        if x.abs() <= limit {
            Ok(())
        } else {
            Err(Error::invalid(field, beyond(limit, unit)))
        }
    }

    /// Finite, every component at most `limit` in magnitude.
    pub fn vec3_at_most(field: &str, v: Vec3, limit: Real, unit: &str) -> Result<()> {
        if !vec3_is_finite(v) {
            return Err(Error::invalid(field, "must be finite numbers"));
        }
        if v.abs().max_element() <= limit {
            Ok(())
        } else {
            Err(Error::invalid(field, beyond(limit, unit)))
        }
    }

    /// Finite, and a vector no longer than `limit`.
    pub fn length_at_most(field: &str, v: Vec3, limit: Real, unit: &str) -> Result<()> {
        vec3(field, v)?;
        // Scaled first, so that components near the largest float do not overflow.
        let scale = v.abs().max_element();
        if scale <= limit && (scale == 0.0 || (v / scale).length() * scale <= limit) {
            Ok(())
        } else {
            let unit = if unit.is_empty() {
                String::new()
            } else {
                format!(" {unit}")
            };
            let reason = format!(
                "must be no longer than {}{unit}",
                crate::limits::short(limit)
            );
            Err(Error::invalid(field, reason))
        }
    }

    fn beyond(limit: Real, unit: &str) -> String {
        let unit = if unit.is_empty() {
            String::new()
        } else {
            format!(" {unit}")
        };
        format!(
            "must be at most {}{unit} in magnitude",
            crate::limits::short(limit)
        )
    }

    pub fn vec3(field: &str, v: Vec3) -> Result<()> {
        if !vec3_is_finite(v) {
            Err(Error::invalid(field, "must be finite numbers"))
        } else if v.abs().max_element() > MAX_MAGNITUDE {
            Err(Error::invalid(field, beyond(MAX_MAGNITUDE, "")))
        } else {
            Ok(())
        }
    }

    pub fn positive_vec3(field: &str, v: Vec3) -> Result<()> {
        vec3(field, v)?;
        if v.min_element() > 0.0 {
            Ok(())
        } else {
            Err(Error::invalid(field, "every component must be > 0"))
        }
    }

    /// A rotation must be finite and non-zero; it is then normalised by the caller.
    pub fn rotation(field: &str, q: Quat) -> Result<Quat> {
        let parts = [q.x, q.y, q.z, q.w];
        if parts.iter().any(|c| !c.is_finite()) {
            return Err(Error::invalid(field, "must be finite numbers"));
        }
        // Huge ones are scaled by their largest component first: [1e308, 0, 0, 1] is a
        // rotation too, and its squared length would overflow.
        let scale = parts.iter().fold(0.0 as Real, |m, c| m.max(c.abs()));
        if scale > 1e15 {
            let q = q / scale;
            return Ok(q / q.length());
        }
        let n = q.length();
        if n < 1e-6 {
            return Err(Error::invalid(
                field,
                "must be a non-zero quaternion [x, y, z, w]",
            ));
        }
        Ok(q / n)
    }
}
