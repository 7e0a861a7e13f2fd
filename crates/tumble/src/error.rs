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
}

impl Error {
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
        }
    }

    /// The path of the offending field.
    pub fn field(&self) -> &str {
        match self {
            Error::InvalidField { field, .. } | Error::UnknownBody { field, .. } => field,
        }
    }
}

/// Small helpers that turn a failed check into an [`Error::InvalidField`].
pub(crate) mod check {
    use super::{Error, Result};
    use crate::math::{vec3_is_finite, Quat, Real, Vec3};

    pub fn finite(field: &str, x: Real) -> Result<()> {
        if x.is_finite() {
            Ok(())
        } else {
            Err(Error::invalid(field, "must be a finite number"))
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

    pub fn vec3(field: &str, v: Vec3) -> Result<()> {
        if vec3_is_finite(v) {
            Ok(())
        } else {
            Err(Error::invalid(field, "must be finite numbers"))
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
