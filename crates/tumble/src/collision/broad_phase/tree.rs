//! An incremental dynamic AABB tree: a binary tree whose leaves hold one box each and
//! whose inner nodes hold the union of their children's boxes.
//!
//! Insertion picks the sibling that adds the least surface area to the tree (the
//! surface-area heuristic: the chance that a random query box hits a node grows with the
//! node's area, so the total inner-node area estimates the cost of a query), then walks
//! back up refitting boxes and rotating grandchildren where a swap shrinks an inner node,
//! until a node comes out unchanged. Removal refits the same way. This is the scheme of
//! Box2D v3's `dynamic_tree.c`, written afresh.
//!
//! Boxes are unions computed with `min`/`max`, which round nothing, so every inner box
//! contains its children's boxes exactly and a traversal finds precisely the leaves a
//! brute-force loop would. That needs boxes without NaN (glam's `min` does not treat NaN
//! symmetrically); the caller guarantees it.

use crate::collision::geometry::Aabb;
use crate::math::Real;

/// "No node": the end of the free list, a leaf's children, the root's parent.
pub(super) const NULL: u32 = u32::MAX;

/// One tree node: 64 bytes in the f64 build, aligned so each is one cache line, since a
/// query on a large tree costs about one cache miss per node visited.
#[derive(Debug, Clone)]
#[cfg_attr(not(feature = "f32"), repr(align(64)))]
pub(super) struct Node {
    aabb: Aabb,
    /// Parent, or the next free node while the node is on the free list.
    parent: u32,
    /// The two children of an inner node; `[NULL, item]` for a leaf, which keeps the
    /// caller's value in the second slot.
    children: [u32; 2],
    /// 0 for a leaf, 1 + the taller child's height otherwise.
    height: u32,
}

impl Node {
    fn is_leaf(&self) -> bool {
        self.children[0] == NULL
    }
}

/// A dynamic AABB tree over `u32` items. Nodes live in one pool with a free list, so
/// moving a leaf allocates nothing and leaf indices stay valid until the leaf is removed.
#[derive(Debug, Clone)]
pub(super) struct Tree {
    nodes: Vec<Node>,
    root: u32,
    free: u32,
    leaves: usize,
}

impl Default for Tree {
    fn default() -> Self {
        Tree {
            nodes: Vec::new(),
            root: NULL,
            free: NULL,
            leaves: 0,
        }
    }
}

/// Area with NaN read as "huge": a NaN cost (from infinite boxes, `inf - inf`) must not
/// look attractive to the comparisons below, and must not poison sums either.
fn area(b: &Aabb) -> Real {
    let a = b.surface_area();
    if a.is_nan() {
        Real::INFINITY
    } else {
        a
    }
}

impl Tree {
    /// Adds a leaf with box `aabb` (no NaN) and returns its node index.
    pub fn insert(&mut self, aabb: Aabb, item: u32) -> u32 {
        let leaf = self.alloc(Node {
            aabb,
            parent: NULL,
            children: [NULL, item],
            height: 0,
        });
        self.insert_leaf(leaf);
        self.leaves += 1;
        leaf
    }

    /// Removes the leaf `leaf` (an index returned by `insert`).
    pub fn remove(&mut self, leaf: u32) {
        self.remove_leaf(leaf);
        self.release(leaf);
        self.leaves -= 1;
    }

    /// Gives `leaf` a new box and reinserts it; the index stays the same.
    pub fn move_leaf(&mut self, leaf: u32, aabb: Aabb) {
        self.remove_leaf(leaf);
        self.nodes[leaf as usize].aabb = aabb;
        self.insert_leaf(leaf);
    }

    /// Gives each leaf of `moves` its new box and rebuilds every inner node top-down (see
    /// [`Tree::build`]): for a large share of the leaves, cheaper than as many
    /// `move_leaf` calls, and it leaves a balanced tree. Leaf indices stay valid.
    pub fn rebuild_with(&mut self, moves: &[(u32, Aabb)], scratch: &mut Vec<u32>) {
        for &(leaf, aabb) in moves {
            self.nodes[leaf as usize].aabb = aabb;
        }
        // Collect the leaves and free the inner nodes.
        scratch.clear();
        let mut stack = Vec::new();
        if self.root != NULL {
            stack.push(self.root);
        }
        while let Some(i) = stack.pop() {
            let n = &self.nodes[i as usize];
            if n.is_leaf() {
                scratch.push(i);
            } else {
                stack.extend_from_slice(&n.children);
                self.release(i);
            }
        }
        // Deterministic whatever the old shape: leaves in index order.
        scratch.sort_unstable();
        self.root = NULL;
        if !scratch.is_empty() {
            self.root = self.build(scratch);
            self.nodes[self.root as usize].parent = NULL;
        }
    }

    /// Links the leaves `leaves` under fresh inner nodes and returns their root: split at
    /// the median of the box centres along the axis where the centres spread most, then
    /// recurse. O(n log n); the halves are equal, so the height is ⌈log2 n⌉.
    fn build(&mut self, leaves: &mut [u32]) -> u32 {
        if let [leaf] = leaves {
            return *leaf;
        }
        let centre = |t: &Tree, i: u32| {
            let b = &t.nodes[i as usize].aabb;
            (b.min + b.max) * 0.5
        };
        let (mut lo, mut hi) = (centre(self, leaves[0]), centre(self, leaves[0]));
        for &i in &leaves[1..] {
            let c = centre(self, i);
            (lo, hi) = (lo.min(c), hi.max(c));
        }
        let spread = hi - lo;
        let axis = if spread.x >= spread.y && spread.x >= spread.z {
            0
        } else if spread.y >= spread.z {
            1
        } else {
            2
        };
        let mid = leaves.len() / 2;
        // Ties broken by index, so the split does not depend on the order it is given.
        leaves.select_nth_unstable_by(mid, |&a, &b| {
            centre(self, a)[axis]
                .total_cmp(&centre(self, b)[axis])
                .then(a.cmp(&b))
        });
        let (left, right) = leaves.split_at_mut(mid);
        let (l, r) = (self.build(left), self.build(right));
        let (a, b) = (&self.nodes[l as usize], &self.nodes[r as usize]);
        let node = Node {
            aabb: a.aabb.union(&b.aabb),
            parent: NULL,
            children: [l, r],
            height: 1 + a.height.max(b.height),
        };
        let parent = self.alloc(node);
        self.nodes[l as usize].parent = parent;
        self.nodes[r as usize].parent = parent;
        parent
    }

    /// Number of leaves.
    pub fn leaf_count(&self) -> usize {
        self.leaves
    }

    /// The box of node `node`.
    pub fn aabb(&self, node: u32) -> &Aabb {
        &self.nodes[node as usize].aabb
    }

    /// The root, if the tree has any leaf.
    pub fn root(&self) -> Option<u32> {
        (self.root != NULL).then_some(self.root)
    }

    /// The children of an inner node, `None` for a leaf.
    pub fn children(&self, node: u32) -> Option<[u32; 2]> {
        let n = &self.nodes[node as usize];
        (!n.is_leaf()).then_some(n.children)
    }

    /// The item of a leaf.
    pub fn item(&self, node: u32) -> u32 {
        self.nodes[node as usize].children[1]
    }

    /// Height of the tree: 0 for a single leaf (and for an empty tree).
    pub fn height(&self) -> u32 {
        self.root().map_or(0, |r| self.nodes[r as usize].height)
    }

    /// True with no leaf.
    pub fn is_empty(&self) -> bool {
        self.root == NULL
    }

    /// Calls `f(item)` for every leaf whose box overlaps `aabb`. `stack` is scratch space,
    /// passed in so repeated queries reuse one allocation.
    pub fn query(&self, aabb: &Aabb, stack: &mut Vec<u32>, mut f: impl FnMut(u32)) {
        stack.clear();
        if self.root != NULL && self.nodes[self.root as usize].aabb.overlaps(aabb) {
            stack.push(self.root);
        }
        // Children are tested before they are pushed: most are rejected, and a rejected
        // one then costs no trip through the stack. Leaves come out in the same order.
        while let Some(i) = stack.pop() {
            let n = &self.nodes[i as usize];
            if n.is_leaf() {
                f(n.children[1]);
                continue;
            }
            for c in n.children {
                if self.nodes[c as usize].aabb.overlaps(aabb) {
                    stack.push(c);
                }
            }
        }
    }

    /// Calls `f(a, b)` once for every pair of distinct leaves whose boxes overlap (their
    /// items, in no particular order), by descending the tree against itself: one walk
    /// where a query per leaf would descend from the root for each. `stack` is scratch;
    /// an entry (x, x) stands for the pairs within subtree x.
    pub fn self_pairs(&self, stack: &mut Vec<(u32, u32)>, mut f: impl FnMut(u32, u32)) {
        stack.clear();
        if self.root != NULL {
            stack.push((self.root, self.root));
        }
        while let Some((a, b)) = stack.pop() {
            let (na, nb) = (&self.nodes[a as usize], &self.nodes[b as usize]);
            if a == b {
                if !na.is_leaf() {
                    let [l, r] = na.children;
                    stack.extend_from_slice(&[(l, l), (r, r), (l, r)]);
                }
                continue;
            }
            if !na.aabb.overlaps(&nb.aabb) {
                continue;
            }
            // Split the larger box (a leaf cannot be split), so the two sides stay alike.
            let split_a = match (na.is_leaf(), nb.is_leaf()) {
                (true, true) => {
                    f(na.children[1], nb.children[1]);
                    continue;
                }
                (true, false) => false,
                (false, true) => true,
                (false, false) => area(&na.aabb) >= area(&nb.aabb),
            };
            if split_a {
                let [c0, c1] = na.children;
                stack.extend_from_slice(&[(c0, b), (c1, b)]);
            } else {
                let [c0, c1] = nb.children;
                stack.extend_from_slice(&[(a, c0), (a, c1)]);
            }
        }
    }

    fn alloc(&mut self, node: Node) -> u32 {
        if self.free != NULL {
            let i = self.free;
            self.free = self.nodes[i as usize].parent;
            self.nodes[i as usize] = node;
            i
        } else {
            // Node indices fit in u32: the broad phase caps proxies at 2^31 - 1 per tree,
            // so a tree never holds more than 2^32 - 3 nodes.
            self.nodes.push(node);
            (self.nodes.len() - 1) as u32
        }
    }

    fn release(&mut self, i: u32) {
        let n = &mut self.nodes[i as usize];
        n.parent = self.free;
        n.children = [NULL; 2];
        n.height = 0;
        self.free = i;
    }

    /// Links the detached node `leaf` into the tree next to the best sibling.
    fn insert_leaf(&mut self, leaf: u32) {
        if self.root == NULL {
            self.root = leaf;
            self.nodes[leaf as usize].parent = NULL;
            return;
        }
        let leaf_box = self.nodes[leaf as usize].aabb;
        let sibling = self.best_sibling(&leaf_box);
        let (sib_box, sib_height, old_parent) = {
            let s = &self.nodes[sibling as usize];
            (s.aabb, s.height, s.parent)
        };
        let parent = self.alloc(Node {
            aabb: leaf_box.union(&sib_box),
            parent: old_parent,
            children: [sibling, leaf],
            height: sib_height + 1,
        });
        self.nodes[sibling as usize].parent = parent;
        self.nodes[leaf as usize].parent = parent;
        if old_parent == NULL {
            self.root = parent;
        } else {
            self.replace_child(old_parent, sibling, parent);
        }
        // The new parent's box is already right (so it cannot start the "unchanged" walk
        // below); give it its rotation, then refit from the first node that is stale.
        self.rotate(parent);
        self.refit_upwards(old_parent);
    }

    /// Unlinks `leaf` (not freed); its parent is freed and its sibling takes its place.
    fn remove_leaf(&mut self, leaf: u32) {
        if leaf == self.root {
            self.root = NULL;
            return;
        }
        let parent = self.nodes[leaf as usize].parent;
        let [c0, c1] = self.nodes[parent as usize].children;
        let sibling = if c0 == leaf { c1 } else { c0 };
        let grand = self.nodes[parent as usize].parent;
        self.nodes[sibling as usize].parent = grand;
        if grand == NULL {
            self.root = sibling;
        } else {
            self.replace_child(grand, parent, sibling);
        }
        self.release(parent);
        self.nodes[leaf as usize].parent = NULL;
        if grand != NULL {
            self.refit_upwards(grand);
        }
    }

    fn replace_child(&mut self, parent: u32, old: u32, new: u32) {
        let p = &mut self.nodes[parent as usize];
        if p.children[0] == old {
            p.children[0] = new;
        } else {
            p.children[1] = new;
        }
    }

    /// The node under which a new leaf with box `b` costs least: pairing `b` with node X
    /// creates a parent of area area(X ∪ b) and grows every ancestor of X by
    /// area(A ∪ b) − area(A). The descent is greedy (one path) with a lower bound to stop
    /// early: below a child C no choice can cost less than the growth so far plus C's
    /// growth plus area(b), the smallest possible new parent.
    ///
    /// Equal costs (coinciding or nested boxes) go to the candidate whose depth plus height
    /// is least, i.e. the one that makes the tree least tall; otherwise identical boxes
    /// would all pair with the root and the tree would degenerate into a list.
    fn best_sibling(&self, b: &Aabb) -> u32 {
        let area_b = area(b);
        let mut index = self.root;
        let root = &self.nodes[index as usize];
        let mut node_area = area(&root.aabb);
        let mut direct = area(&root.aabb.union(b));
        // Growth of the ancestors of `index` (exclusive) if the leaf goes below them.
        let mut inherited: Real = 0.0;
        let mut depth = 0u32;
        // (node, cost, depth + height)
        let mut best = (index, direct, root.height);
        loop {
            let node = &self.nodes[index as usize];
            if node.is_leaf() {
                return best.0;
            }
            inherited += direct - node_area;
            depth += 1;
            // (lower bound, height, child, area, direct)
            let mut descend: Option<(Real, u32, u32, Real, Real)> = None;
            for &c in &node.children {
                let child = &self.nodes[c as usize];
                let c_area = area(&child.aabb);
                let c_direct = area(&child.aabb.union(b));
                let cost = inherited + c_direct;
                let rank = depth + child.height;
                if cost < best.1 || (cost == best.1 && rank < best.2) {
                    best = (c, cost, rank);
                }
                if child.is_leaf() {
                    continue;
                }
                let lower = inherited + (c_direct - c_area) + area_b;
                let better = match descend {
                    None => true,
                    Some((l, h, ..)) => lower < l || (lower == l && child.height < h),
                };
                // `<=`: on a tie the subtree may still hold a less tall equal-cost choice.
                if lower <= best.1 && better {
                    descend = Some((lower, child.height, c, c_area, c_direct));
                }
            }
            match descend {
                Some((_, _, c, c_area, c_direct)) => {
                    index = c;
                    node_area = c_area;
                    direct = c_direct;
                }
                None => return best.0,
            }
        }
    }

    /// From `index` towards the root: recompute boxes and heights, rotating where it
    /// helps. Stops at the first node whose box and height come out unchanged: every
    /// ancestor is a function of those, so nothing above can change, and on a large tree
    /// the walk is mostly cache misses (typically a few levels instead of all ~2 log n).
    fn refit_upwards(&mut self, mut index: u32) {
        while index != NULL {
            let (old_box, old_height) = {
                let n = &self.nodes[index as usize];
                (n.aabb, n.height)
            };
            self.refit(index);
            self.rotate(index);
            let n = &self.nodes[index as usize];
            if n.aabb == old_box && n.height == old_height {
                return;
            }
            index = n.parent;
        }
    }

    fn refit(&mut self, index: u32) {
        let [c0, c1] = self.nodes[index as usize].children;
        let (a, b) = (&self.nodes[c0 as usize], &self.nodes[c1 as usize]);
        let aabb = a.aabb.union(&b.aabb);
        let height = 1 + a.height.max(b.height);
        let n = &mut self.nodes[index as usize];
        n.aabb = aabb;
        n.height = height;
    }

    /// Tree rotation at inner node A with children B and C: swapping B with a child of C
    /// (or C with a child of B) leaves A's box and every subtree's box unchanged except the
    /// child that receives the swapped subtree. Pick the swap that shrinks that child's
    /// area most, if any does. Only areas change, so the tree stays exact.
    ///
    /// Ties matter: boxes that coincide (bodies spawned at one spot) give every swap zero
    /// gain, and inserting them one by one next to the root would build a list. So when no
    /// swap gains area, one that loses none but lowers A is taken.
    fn rotate(&mut self, a: u32) {
        let [b, c] = self.nodes[a as usize].children;
        if b == NULL {
            return;
        }
        let height_a = self.nodes[a as usize].height;
        // (moved child of A, other child of A, grandchild swapped in, grandchild kept)
        let mut best: Option<(u32, u32, u32, u32)> = None;
        let mut best_gain: Real = 0.0;
        let mut level: Option<(u32, u32, u32, u32)> = None;
        for (x, p) in [(b, c), (c, b)] {
            let Some([g0, g1]) = self.children(p) else {
                continue;
            };
            let p_area = area(&self.nodes[p as usize].aabb);
            let x_node = &self.nodes[x as usize];
            for (y, keep) in [(g0, g1), (g1, g0)] {
                let k = &self.nodes[keep as usize];
                let gain = p_area - area(&x_node.aabb.union(&k.aabb));
                if gain > best_gain {
                    best_gain = gain;
                    best = Some((x, p, y, keep));
                }
                // A's height after the swap: over y and over p's new pair (x, keep).
                let y_height = self.nodes[y as usize].height;
                let new_height = 1 + y_height.max(1 + x_node.height.max(k.height));
                if gain == 0.0 && new_height < height_a && level.is_none() {
                    level = Some((x, p, y, keep));
                }
            }
        }
        let Some((x, p, y, _)) = best.or(level) else {
            return;
        };
        self.replace_child(a, x, y);
        self.nodes[y as usize].parent = a;
        self.replace_child(p, y, x);
        self.nodes[x as usize].parent = p;
        self.refit(p);
        self.refit(a);
    }

    /// Checks every structural invariant; used by the tests.
    #[cfg(test)]
    pub fn validate(&self) -> Result<(), String> {
        self.check_saved("tree", |_, _| true).map_err(|m| m.0)
    }

    /// Checks what every walk and edit of the tree indexes or loops over without checking,
    /// for a tree read from a snapshot (`what` names it in errors): children and parents
    /// in range and pointing at each other, so the tree is a tree and a walk from the root
    /// ends; heights and inner boxes what refitting would compute (a height of `u32::MAX`
    /// would overflow `1 +`); no NaN in a leaf's box; the leaf count; a free list that
    /// ends, holding exactly the nodes not in the tree. `leaf(node, item)` checks each
    /// leaf's item against the owner's records.
    pub fn check_saved(
        &self,
        what: &str,
        mut leaf: impl FnMut(u32, u32) -> bool,
    ) -> crate::codec::Decoded<()> {
        use crate::codec::{check_index, ensure};
        let len = self.nodes.len();
        // Per node: reached from the root or from the free list already.
        let mut seen = vec![false; len];
        let mut stack = Vec::new();
        if self.root != NULL {
            check_index(self.root, len, (|| format!("{what}.root"), "node"))?;
            let parent = self.nodes[self.root as usize].parent;
            ensure(parent == NULL, || {
                format!("{what}.root: has parent {parent}")
            })?;
            stack.push(self.root);
        }
        let mut leaves = 0usize;
        while let Some(i) = stack.pop() {
            let at = || format!("{what}.nodes[{i}]");
            ensure(!seen[i as usize], || format!("{}: reached twice", at()))?;
            seen[i as usize] = true;
            let n = &self.nodes[i as usize];
            if n.is_leaf() {
                let nan = n.aabb.min.is_nan() || n.aabb.max.is_nan();
                ensure(!nan, || format!("{}.aabb: NaN", at()))?;
                ensure(n.height == 0, || {
                    format!("{}: leaf of height {}", at(), n.height)
                })?;
                let item = n.children[1];
                ensure(leaf(i, item), || {
                    format!("{}: leaf of wrong item {item}", at())
                })?;
                leaves += 1;
                continue;
            }
            self.check_inner(i, what)?;
            stack.extend_from_slice(&n.children);
        }
        ensure(leaves == self.leaves, || {
            format!("{what}.leaves: {} but {leaves} reached", self.leaves)
        })?;
        let (mut free, mut f) = (0usize, self.free);
        while f != NULL {
            check_index(f, len, (|| format!("{what}.free"), "node"))?;
            ensure(!seen[f as usize], || {
                format!("{what}.free: node {f} is in use")
            })?;
            seen[f as usize] = true;
            free += 1;
            f = self.nodes[f as usize].parent;
        }
        ensure(seen.iter().all(|&s| s), || {
            format!("{what}: {len} nodes but {free} free and the rest not all in the tree")
        })
    }

    /// Checks inner node `i` for [`Tree::check_saved`]: two distinct children in range
    /// whose parent it is, its height and its box as `refit` computes them.
    fn check_inner(&self, i: u32, what: &str) -> crate::codec::Decoded<()> {
        use crate::codec::{check_index, ensure};
        let at = || format!("{what}.nodes[{i}]");
        let n = &self.nodes[i as usize];
        let [c0, c1] = n.children;
        for (k, c) in [c0, c1].into_iter().enumerate() {
            let field = || format!("{}.children[{k}]", at());
            check_index(c, self.nodes.len(), (field, "node"))?;
            let parent = self.nodes[c as usize].parent;
            ensure(parent == i, || {
                format!("{}: child {c} has parent {parent}", at())
            })?;
        }
        ensure(c0 != c1, || format!("{}: child {c0} twice", at()))?;
        let (a, b) = (&self.nodes[c0 as usize], &self.nodes[c1 as usize]);
        let height = 1 + a.height.max(b.height) as u64;
        ensure(n.height as u64 == height, || {
            format!("{}: height {} but {height} by its children", at(), n.height)
        })?;
        ensure(n.aabb == a.aabb.union(&b.aabb), || {
            format!("{}.aabb: not the union of its children's", at())
        })
    }
}

crate::codec::codec_struct!(Node {
    aabb,
    parent,
    children,
    height
});
crate::codec::codec_struct!(Tree {
    nodes,
    root,
    free,
    leaves
});
