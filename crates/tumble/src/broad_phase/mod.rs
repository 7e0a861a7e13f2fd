//! The broad phase: which bodies' bounding boxes overlap.
//! PLACEHOLDER: being written (dynamic AABB trees); the interface below is fixed.
#![allow(unused_variables, dead_code)]

use crate::geometry::Aabb;
use crate::math::{Real, Vec3};

/// Handle of a proxy (one body's box) in the broad phase.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct ProxyId(pub u32);

/// Whether a proxy can move: static proxies live in their own tree and never pair with
/// each other.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum ProxyKind {
    /// Never moves.
    Static,
    /// Dynamic or kinematic: may move every step.
    Moving,
}

/// Collision filter: two proxies may pair when `a.group & b.mask != 0` and
/// `b.group & a.mask != 0`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct Filter {
    /// Layers this proxy is in (bits).
    pub group: u32,
    /// Layers it collides with (bits).
    pub mask: u32,
}

impl Default for Filter {
    fn default() -> Self {
        Filter {
            group: 1,
            mask: u32::MAX,
        }
    }
}

impl Filter {
    /// Whether the two filters let their proxies pair.
    pub fn allows(&self, other: &Filter) -> bool {
        self.group & other.mask != 0 && other.group & self.mask != 0
    }
}

/// Two dynamic AABB trees (static and moving) with enlarged boxes, so a slowly moving
/// proxy is not reinserted every step.
#[derive(Debug, Default, Clone)]
pub struct BroadPhase {}

impl BroadPhase {
    /// An empty broad phase. `margin` is how much each stored box is enlarged beyond the
    /// tight box (m).
    pub fn new(margin: Real) -> BroadPhase {
        BroadPhase {}
    }

    /// Adds a proxy for the tight box `aabb`; `user` is returned in pairs and queries.
    pub fn insert(&mut self, aabb: Aabb, user: u32, kind: ProxyKind, filter: Filter) -> ProxyId {
        ProxyId(0)
    }

    /// Removes a proxy.
    pub fn remove(&mut self, proxy: ProxyId) {}

    /// Changes the user value of a proxy (bodies are renumbered when one is removed).
    pub fn set_user(&mut self, proxy: ProxyId, user: u32) {}

    /// Changes a proxy's filter.
    pub fn set_filter(&mut self, proxy: ProxyId, filter: Filter) {}

    /// Tells the broad phase the proxy's tight box is now `aabb` after moving by
    /// `displacement` (used to stretch the enlarged box forward). Returns true when the
    /// proxy had to be reinserted (its tight box left its enlarged one).
    pub fn update(&mut self, proxy: ProxyId, aabb: Aabb, displacement: Vec3) -> bool {
        false
    }

    /// Every pair of proxies whose enlarged boxes overlap and whose filters allow it,
    /// static–static excluded, as (user, user) with the smaller first, sorted, no
    /// duplicates. Incremental: only pairs involving proxies reinserted since the last call
    /// are searched again; the rest are kept while their boxes still overlap.
    pub fn pairs(&mut self, out: &mut Vec<(u32, u32)>) {}

    /// Calls `f(user)` for every proxy whose enlarged box overlaps `aabb`.
    pub fn query_aabb(&self, aabb: &Aabb, f: impl FnMut(u32)) {}

    /// Walks the proxies whose enlarged boxes the ray `origin + t·dir`, t in [0, max_t],
    /// crosses, nearest boxes first where cheap; `f(user, max_t)` returns the new max_t
    /// (a hit shortens the ray; return the given max_t to keep it).
    pub fn cast_ray(&self, origin: Vec3, dir: Vec3, max_t: Real, f: impl FnMut(u32, Real) -> Real) {
    }

    /// Number of proxies.
    pub fn len(&self) -> usize {
        0
    }

    /// True with no proxies.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}
