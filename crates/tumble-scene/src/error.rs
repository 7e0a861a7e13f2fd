//! The one error type of scene loading: a field path and what is wrong with it.

use std::fmt;

/// Why a scene was refused. `Display` prints the single line `field: reason`, e.g.
/// `bodies[3].shape.radius: must be > 0`; the CLI prints exactly that line.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct SceneError {
    /// Path of the offending field (`bodies[3].shape.radius`), or `scene` when the
    /// problem is the document as a whole (unreadable file, malformed JSON).
    pub field: String,
    /// What is wrong, phrased as a requirement where possible (`must be > 0`).
    pub reason: String,
}

impl SceneError {
    /// An error for `field`.
    pub fn new(field: impl Into<String>, reason: impl Into<String>) -> Self {
        SceneError {
            field: field.into(),
            reason: reason.into(),
        }
    }

    /// An engine error raised while building the part of the scene at `prefix`
    /// (`bodies[3]`); the engine's own field path is relative to that part.
    pub fn from_engine(error: tumble::Error, prefix: &str) -> Self {
        let error = if prefix.is_empty() {
            error
        } else {
            error.within(prefix)
        };
        let field = error.field().to_string();
        let line = error.to_string();
        // The engine prints `field: reason`; keep only the reason so that the two parts
        // stay separate whatever variants the engine adds later.
        let reason = match line.strip_prefix(&format!("{field}: ")) {
            Some(reason) => reason.to_string(),
            None => line,
        };
        SceneError { field, reason }
    }

    /// The whole line, `field: reason`.
    pub fn message(&self) -> String {
        self.to_string()
    }
}

impl fmt::Display for SceneError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}: {}", self.field, self.reason)
    }
}

impl std::error::Error for SceneError {}

/// User text (a key, a name, a path) as it appears in an error: control characters are
/// escaped, so that the error stays one line whatever the scene file holds.
pub fn printable(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for c in text.chars() {
        if c.is_control() {
            out.extend(c.escape_default());
        } else {
            out.push(c);
        }
    }
    out
}

/// Result alias of this crate.
pub type Result<T, E = SceneError> = std::result::Result<T, E>;
