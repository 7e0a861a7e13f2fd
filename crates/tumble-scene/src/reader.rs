//! A small reader over `serde_json::Value` that knows where it is in the document, so
//! every refusal names its field (`bodies[3].shape.radius`) instead of a line number.

use serde_json::{Map, Value};
use tumble::{Quat, Real, Vec3};

use crate::error::{printable, Result, SceneError};

/// The field named by errors about the document as a whole (unreadable, malformed JSON).
pub const ROOT: &str = "scene";

/// The rule a whole number in [`min`, `max`] breaks, in the words of every message about
/// one: scene keys and command-line options alike. `u64::MAX` stands for no upper bound.
pub fn whole_rule(min: u64, max: u64) -> String {
    if max == u64::MAX {
        format!("must be a whole number >= {min}")
    } else {
        format!("must be a whole number from {min} to {max}")
    }
}

/// A JSON value and its path in the scene.
#[derive(Clone)]
pub(crate) struct Node<'a> {
    value: &'a Value,
    path: String,
}

impl<'a> Node<'a> {
    /// The document root.
    pub fn root(value: &'a Value) -> Self {
        Node {
            value,
            path: String::new(),
        }
    }

    /// The path to print: the root is called `scene`.
    pub fn path(&self) -> &str {
        if self.path.is_empty() {
            ROOT
        } else {
            &self.path
        }
    }

    /// Whether the value is a JSON number.
    pub fn is_number(&self) -> bool {
        self.value.is_number()
    }

    /// Whether the value is JSON null.
    pub fn is_null(&self) -> bool {
        self.value.is_null()
    }

    /// An error about this value.
    pub fn err(&self, reason: impl Into<String>) -> SceneError {
        SceneError::new(self.path(), reason)
    }

    fn child(&self, value: &'a Value, key: &str) -> Node<'a> {
        let path = if self.path.is_empty() {
            key.to_string()
        } else {
            format!("{}.{key}", self.path)
        };
        Node { value, path }
    }

    fn element(&self, value: &'a Value, index: usize) -> Node<'a> {
        Node {
            value,
            path: format!("{}[{index}]", self.path()),
        }
    }

    /// A finite number. JSON has no NaN, but a literal such as 1e400 overflows to
    /// infinity (in f32 builds, 1e39 already does), which no physical quantity may be.
    pub fn real(&self) -> Result<Real> {
        let Value::Number(n) = self.value else {
            return Err(self.err("expected a number"));
        };
        // The number's own text is parsed straight into `Real`, so an f32 build rounds
        // once rather than through f64.
        match n.to_string().parse::<Real>() {
            Ok(x) if x.is_finite() => Ok(x),
            _ => Err(self.err("must be a finite number")),
        }
    }

    /// A whole number in [0, `max`] (indices, bit masks, counts).
    pub fn whole(&self, max: u64) -> Result<u64> {
        let Value::Number(n) = self.value else {
            return Err(self.err("expected a whole number"));
        };
        match n.as_u64() {
            Some(v) if v <= max => Ok(v),
            Some(_) => Err(self.err(format!("must be at most {max}"))),
            None => Err(self.err("must be a whole number >= 0")),
        }
    }

    /// A whole number in [`min`, `max`] (solver passes). Every other value, `0` and `-1`
    /// and `1.5` alike, is told the same rule, [`whole_rule`].
    pub fn whole_in(&self, min: u64, max: u64) -> Result<u64> {
        match self.value {
            Value::Number(n) => n.as_u64().filter(|v| (min..=max).contains(v)),
            _ => None,
        }
        .ok_or_else(|| self.err(whole_rule(min, max)))
    }

    /// A string.
    pub fn str(&self) -> Result<&'a str> {
        self.value
            .as_str()
            .ok_or_else(|| self.err("expected a string"))
    }

    /// A boolean.
    pub fn bool(&self) -> Result<bool> {
        self.value
            .as_bool()
            .ok_or_else(|| self.err("expected true or false"))
    }

    /// The elements of an array, each with its indexed path.
    pub fn array(&self) -> Result<Vec<Node<'a>>> {
        let items = self
            .value
            .as_array()
            .ok_or_else(|| self.err("expected an array"))?;
        Ok(items
            .iter()
            .enumerate()
            .map(|(i, v)| self.element(v, i))
            .collect())
    }

    /// An array of exactly `N` finite numbers; `what` spells the expected form.
    pub fn reals<const N: usize>(&self, what: &str) -> Result<[Real; N]> {
        let wrong = || self.err(format!("expected an array of {N} numbers {what}"));
        let items = self.value.as_array().ok_or_else(wrong)?;
        if items.len() != N {
            return Err(wrong());
        }
        let mut out = [0.0; N];
        for (i, (slot, v)) in out.iter_mut().zip(items).enumerate() {
            *slot = self.element(v, i).real()?;
        }
        Ok(out)
    }

    /// `[x, y, z]`.
    pub fn vec3(&self) -> Result<Vec3> {
        let [x, y, z] = self.reals::<3>("[x, y, z]")?;
        Ok(Vec3::new(x, y, z))
    }

    /// `[x, y, z, w]`, not normalised: the engine refuses zero and normalises the rest.
    pub fn quat(&self) -> Result<Quat> {
        let [x, y, z, w] = self.reals::<4>("[x, y, z, w]")?;
        Ok(Quat::from_xyzw(x, y, z, w))
    }

    /// Whether the value is an array whose first element is an array: tells the matrix
    /// form of `inertia` from the principal-moments form.
    pub fn is_array_of_arrays(&self) -> bool {
        self.value
            .as_array()
            .and_then(|a| a.first())
            .is_some_and(Value::is_array)
    }

    /// An object; its keys are checked with [`Obj::only`].
    pub fn object(&self) -> Result<Obj<'a>> {
        match self.value {
            Value::Object(map) => Ok(Obj {
                node: self.clone(),
                map,
            }),
            _ => Err(self.err("expected an object")),
        }
    }
}

/// A JSON object being read.
pub(crate) struct Obj<'a> {
    node: Node<'a>,
    map: &'a Map<String, Value>,
}

impl<'a> Obj<'a> {
    /// The object's own node.
    pub fn node(&self) -> &Node<'a> {
        &self.node
    }

    /// Refuses any key not in `allowed`. Misspelt keys would otherwise be silently
    /// ignored and the default used, which is the worst kind of scene bug to find.
    pub fn only(&self, allowed: &[&str]) -> Result<()> {
        // Document order (serde_json's preserve_order), so the first bad key is reported.
        match self.map.keys().find(|k| !allowed.contains(&k.as_str())) {
            None => Ok(()),
            Some(key) => Err(self.node.child(&Value::Null, &printable(key)).err(format!(
                "unknown key (expected one of: {})",
                allowed.join(", ")
            ))),
        }
    }

    /// The value at `key`, if present.
    pub fn get(&self, key: &str) -> Option<Node<'a>> {
        self.map.get(key).map(|v| self.node.child(v, key))
    }

    /// Whether `key` is present.
    pub fn has(&self, key: &str) -> bool {
        self.map.contains_key(key)
    }

    /// The value at `key`, which must be present.
    pub fn required(&self, key: &str) -> Result<Node<'a>> {
        self.get(key).ok_or_else(|| {
            self.node
                .child(&Value::Null, key)
                .err("missing required key")
        })
    }

    /// An error about `key` of this object, present or not.
    pub fn err_at(&self, key: &str, reason: impl Into<String>) -> SceneError {
        self.node.child(&Value::Null, key).err(reason)
    }

    /// An optional number.
    pub fn real(&self, key: &str) -> Result<Option<Real>> {
        self.get(key).map(|n| n.real()).transpose()
    }

    /// An optional `[x, y, z]`.
    pub fn vec3(&self, key: &str) -> Result<Option<Vec3>> {
        self.get(key).map(|n| n.vec3()).transpose()
    }

    /// An optional `[x, y, z, w]`.
    pub fn quat(&self, key: &str) -> Result<Option<Quat>> {
        self.get(key).map(|n| n.quat()).transpose()
    }

    /// An optional string.
    pub fn str(&self, key: &str) -> Result<Option<&'a str>> {
        self.get(key).map(|n| n.str()).transpose()
    }

    /// An optional boolean.
    pub fn bool(&self, key: &str) -> Result<Option<bool>> {
        self.get(key).map(|n| n.bool()).transpose()
    }
}
