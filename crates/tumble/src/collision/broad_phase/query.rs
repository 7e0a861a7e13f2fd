//! Read-only queries of the broad phase: the proxies whose fat boxes overlap a box (static
//! ones alone, or all), and a ray walk over both trees.
//!
//! The walk visits nearer boxes first where cheap (of two siblings, the nearer is popped
//! first) and lets each hit shorten the ray, so a nearest-hit cast prunes the boxes behind
//! its hit. A NaN anywhere in the ray visits nothing: the slab test would read a NaN
//! coordinate as inside.

use super::tree::Tree;
use super::{tree_index, BroadPhase, ProxyKind};
use crate::collision::geometry::Aabb;
use crate::math::{Real, Vec3};

impl BroadPhase {
    /// Calls `f(user)` for every static proxy whose box overlaps `aabb`: the moving tree,
    /// which holds nearly every proxy, is not walked.
    pub fn query_static_aabb(&self, aabb: &Aabb, f: impl FnMut(u32)) {
        self.query_static_aabb_with(aabb, &mut Vec::new(), f);
    }

    /// [`BroadPhase::query_static_aabb`] with the caller's scratch `stack`, for callers
    /// that query once per contact point and would otherwise allocate each time.
    pub fn query_static_aabb_with(
        &self,
        aabb: &Aabb,
        stack: &mut Vec<u32>,
        mut f: impl FnMut(u32),
    ) {
        self.trees[tree_index(ProxyKind::Static)]
            .query(aabb, stack, |id| f(self.proxies[id as usize].user));
    }

    /// Calls `f(user)` for every proxy whose enlarged box overlaps `aabb` (static proxies
    /// first).
    pub fn query_aabb(&self, aabb: &Aabb, f: impl FnMut(u32)) {
        self.query_aabb_with(aabb, &mut Vec::new(), f);
    }

    /// [`BroadPhase::query_aabb`] with the caller's scratch `stack`.
    pub fn query_aabb_with(&self, aabb: &Aabb, stack: &mut Vec<u32>, mut f: impl FnMut(u32)) {
        for tree in &self.trees {
            tree.query(aabb, stack, |id| f(self.proxies[id as usize].user));
        }
    }

    /// Walks the proxies whose enlarged boxes the ray `origin + t·dir`, t in [0, max_t],
    /// crosses, nearest boxes first where cheap; `f(user, max_t)` returns the new max_t
    /// (a hit shortens the ray; return the given max_t to keep it).
    ///
    /// A returned value larger than the current max_t, or NaN, leaves it unchanged; a
    /// negative one ends the walk. Boxes entered at t ≤ the current max_t are visited, so
    /// returning 0 still visits the boxes containing the origin. A NaN or negative
    /// `max_t`, or a NaN in the origin or direction, visits nothing.
    pub fn cast_ray(
        &self,
        origin: Vec3,
        dir: Vec3,
        max_t: Real,
        mut f: impl FnMut(u32, Real) -> Real,
    ) {
        // The slab test reads a NaN coordinate as "inside" on axes the ray is parallel to.
        if max_t.is_nan() || max_t < 0.0 || origin.is_nan() || dir.is_nan() {
            return;
        }
        let mut limit = max_t;
        // (entry t, tree, node); the nearer of two siblings is pushed last, popped first.
        let mut stack: Vec<(Real, usize, u32)> = Vec::with_capacity(64);
        let entry = |tree: &Tree, node: u32, limit: Real| {
            tree.aabb(node)
                .ray_interval(origin, dir, limit)
                .map(|(t, _)| t)
        };
        let roots = self.trees.iter().enumerate().filter_map(|(i, tree)| {
            let root = tree.root()?;
            entry(tree, root, limit).map(|t| (t, i, root))
        });
        push_nearest_last(&mut stack, roots);
        while let Some((t, i, node)) = stack.pop() {
            if t > limit {
                continue; // the ray has been shortened past this box since it was pushed
            }
            let tree = &self.trees[i];
            match tree.children(node) {
                Some(children) => {
                    let hits = children
                        .into_iter()
                        .filter_map(|c| entry(tree, c, limit).map(|t| (t, i, c)));
                    push_nearest_last(&mut stack, hits);
                }
                None => {
                    let user = self.proxies[tree.item(node) as usize].user;
                    let new_limit = f(user, limit);
                    if new_limit < limit {
                        limit = new_limit;
                    }
                    if limit < 0.0 {
                        return;
                    }
                }
            }
        }
    }
}

/// Pushes up to two (t, ..) entries so that the smallest t is on top of the stack.
fn push_nearest_last(
    stack: &mut Vec<(Real, usize, u32)>,
    entries: impl Iterator<Item = (Real, usize, u32)>,
) {
    let start = stack.len();
    stack.extend(entries);
    if stack.len() == start + 2 && stack[start].0 < stack[start + 1].0 {
        stack.swap(start, start + 1);
    }
}
