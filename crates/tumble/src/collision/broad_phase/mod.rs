//! The broad phase: which proxies' (bodies') bounding boxes overlap.
//!
//! Two dynamic AABB trees (`tree.rs`), one for static proxies and one for moving ones, in
//! the manner of Box2D v3: static proxies never pair with each other, so the static tree
//! is only searched on behalf of moving proxies, and a world full of static geometry costs
//! nothing per step until something moves near it.
//!
//! Each proxy's stored ("fat") box is its tight box grown by the margin on every side and
//! stretched [`PREDICTION`] times its last displacement forward, so a body drifting slowly
//! stays inside its fat box for many steps and its tree leaf is left alone; only a proxy
//! whose tight box leaves its fat box (or whose fat box has become far too large) is
//! reinserted. Pairs are defined on fat boxes, which contain the tight ones, so every pair
//! of overlapping tight boxes is reported.
//!
//! The pair set is kept between calls. Fat boxes change only on reinsertion, so a pair
//! whose proxies were both left alone is still valid, and every new pair involves a
//! reinserted proxy: `pairs()` drops the pairs touching a proxy reinserted (or inserted,
//! removed, refiltered, renumbered) since the last call and searches the trees again for
//! those proxies alone, then merges. The result equals a brute-force test over all fat
//! boxes, at the cost of the changed proxies plus one pass over the pair list.
//!
//! Crowds are kept in proportion (see [`BroadPhase::set_crowding`]): twenty thousand
//! boxes created at one point would otherwise store 200 million pairs (3 GB), and a pack
//! of 5 mm marbles holds five thousand candidates each within the 0.1 m margin. A pair
//! whose tight boxes are sunk into each other, or far apart, is stored only while one of
//! its proxies has fewer than a cap of such pairs; a proxy that lost one searches again on
//! every call, so a far pair left out is found as the boxes close in. Without crowding
//! the result equals the brute-force test described above.
//!
//! Determinism: pairs live in a sorted `Vec`, trees in index pools; no hashing anywhere.
//!
//! Layout: this file holds the proxies, their updates and the pair set; `tree.rs` the
//! dynamic tree; `query.rs` the box and ray queries; `tests.rs` the tests.

mod query;
#[cfg(test)]
mod tests;
mod tree;

use crate::collision::geometry::Aabb;
use crate::math::{Real, Vec3};
use tree::{Tree, NULL};

/// The fat box is stretched this many times the proxy's displacement forward (Box2D's
/// `b2_aabbMultiplier`): a body moving steadily at `d` per step then stays inside it for
/// about `PREDICTION + margin / |d|` steps instead of `margin / |d|`.
pub const PREDICTION: Real = 4.0;

/// A fat box more than this many margins longer on some axis than a freshly made one is
/// "far too large" (the body was fast and has slowed, or its tight box has shrunk) and is
/// rebuilt, so stale slack does not keep producing pairs.
pub const SHRINK_MARGINS: Real = 4.0;

/// `update_many` rebuilds a tree when at least this share of its leaves must be
/// reinserted. A rebuild is O(n log n) over all leaves, a reinsertion a descent and a walk
/// back up per leaf; the landing rain runs as fast with 0.1 or 0.5 as with this, within
/// the timing noise.
pub const REBUILD_SHARE: Real = 0.25;

/// ... and at least this many: small trees are cheap to update either way.
pub const REBUILD_MIN: usize = 64;

/// The crowding caps apply once a `pairs()` holds this many pairs per proxy (see
/// `Crowd::engaged`).
const ENGAGE: usize = 32;

/// At most this many proxies (2^31 − 1): each tree then has fewer than 2^32 − 1 nodes,
/// so node and proxy indices fit in `u32` with `u32::MAX` free as "none".
const MAX_PROXIES: usize = (u32::MAX / 2) as usize;

/// The empty box, which vanishes in unions and overlaps no finite box (only one reaching
/// −∞ and +∞ on every axis): stored for a tight box with a NaN in it, so NaN never enters
/// a tree, where it would break the exact containment of children in parents that queries
/// rely on.
const EMPTY: Aabb = Aabb {
    min: Vec3::splat(Real::INFINITY),
    max: Vec3::splat(Real::NEG_INFINITY),
};

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
/// `b.group & a.mask != 0`, and they do not have the same non-zero `owner`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct Filter {
    /// Layers this proxy is in (bits).
    pub group: u32,
    /// Layers it collides with (bits).
    pub mask: u32,
    /// Proxies with the same non-zero owner never pair (the links of one model); 0: none.
    pub owner: u32,
}

impl Default for Filter {
    fn default() -> Self {
        Filter {
            group: 1,
            mask: u32::MAX,
            owner: 0,
        }
    }
}

impl Filter {
    /// The filter of a proxy that pairs with nothing (a sensor's: sensors find their
    /// overlaps by queries of their own).
    pub const NONE: Filter = Filter {
        group: 0,
        mask: 0,
        owner: 0,
    };

    /// Whether the two filters let their proxies pair.
    pub fn allows(&self, other: &Filter) -> bool {
        self.group & other.mask != 0
            && other.group & self.mask != 0
            && (self.owner == 0 || self.owner != other.owner)
    }
}

#[derive(Debug, Clone)]
struct Proxy {
    user: u32,
    kind: ProxyKind,
    filter: Filter,
    /// Leaf in the tree of `kind`; `NULL` while the slot is free.
    node: u32,
    /// Next free slot while this one is free.
    next_free: u32,
}

/// One current pair: the user values (smaller in the high half, so the key sorts as the
/// output does) and the two proxies, smaller index first.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
struct PairEntry {
    users: u64,
    a: u32,
    b: u32,
}

impl PairEntry {
    fn new(pa: u32, ua: u32, pb: u32, ub: u32) -> PairEntry {
        let (lo, hi) = (ua.min(ub) as u64, ua.max(ub) as u64);
        PairEntry {
            users: lo << 32 | hi,
            a: pa.min(pb),
            b: pa.max(pb),
        }
    }

    fn users(&self) -> (u32, u32) {
        ((self.users >> 32) as u32, self.users as u32)
    }
}

fn tree_index(kind: ProxyKind) -> usize {
    match kind {
        ProxyKind::Static => 0,
        ProxyKind::Moving => 1,
    }
}

/// Two dynamic AABB trees (static and moving) with enlarged boxes, so a slowly moving
/// proxy is not reinserted every step.
#[derive(Debug, Default, Clone)]
pub struct BroadPhase {
    margin: Real,
    proxies: Vec<Proxy>,
    free: Option<u32>,
    count: usize,
    /// Static tree, moving tree (see `tree_index`).
    trees: [Tree; 2],
    /// Proxies whose pairs must be searched again, each once.
    move_buffer: Vec<u32>,
    /// One bit per proxy slot: in `move_buffer`. A bit set rather than a field of
    /// `Proxy` because `pairs()` tests it for both ends of every pair, and 100k proxies'
    /// bits (12 kB) stay in cache where their `Proxy` records (2 MB) would not.
    moved: Vec<u64>,
    /// The current pairs, sorted.
    pairs: Vec<PairEntry>,
    /// The caps on crowded proxies' pairs, and what applying them needs.
    crowd: Crowd,
    /// Scratch for `pairs()`, kept to reuse allocations.
    found: Vec<PairEntry>,
    merged: Vec<PairEntry>,
    stack: Vec<u32>,
    /// Scratch for `Tree::self_pairs`.
    pair_stack: Vec<(u32, u32)>,
    /// Scratch for `update_many`: per tree, the leaves to reinsert with their new boxes.
    pending: [Vec<(u32, Aabb)>; 2],
}

impl BroadPhase {
    /// An empty broad phase. `margin` is how much each stored box is enlarged beyond the
    /// tight box (m); a negative, NaN or infinite margin is taken as 0.
    pub fn new(margin: Real) -> BroadPhase {
        let margin = if margin.is_finite() && margin > 0.0 {
            margin
        } else {
            0.0
        };
        BroadPhase {
            margin,
            crowd: Crowd {
                caps: Crowding::NONE,
                ..Crowd::default()
            },
            ..BroadPhase::default()
        }
    }

    /// Sets the caps that keep crowds in proportion (none by default). A proxy whose tight
    /// box is sunk into `crowding.sunk` others' (`Aabb::sunk_into` at `crowding.depth`) is
    /// crowded, and two crowded proxies do not pair; a new pair whose tight boxes are far
    /// apart (more than twice the depth) is stored only while one of its proxies has fewer
    /// than `crowding.any` pairs. Each kept pair of a crowd is charged to a proxy not yet
    /// crowded, so a crowd keeps a number of pairs in proportion to its proxies; a proxy
    /// that touches many without being sunk into them (a plate on a bed of marbles) keeps
    /// them all, as does every pair with a static proxy. The caps apply only in a call
    /// that holds more than 32 pairs per proxy.
    pub fn set_crowding(&mut self, crowding: Crowding) {
        self.crowd.caps = Crowding {
            sunk: crowding.sunk.max(1),
            any: crowding.any.max(1),
            depth: crowding.depth,
        };
    }

    /// Candidate pairs the last [`BroadPhase::pairs`] left out because both proxies had
    /// reached the pair cap (0 unless bodies are crowded into each other).
    pub fn crowded(&self) -> usize {
        self.crowd.crowded
    }

    /// The margin in use (m).
    pub fn margin(&self) -> Real {
        self.margin
    }

    /// Adds a proxy for the tight box `aabb`; `user` is returned in pairs and queries.
    /// A box with a NaN in it is stored as the empty box (see [`BroadPhase::fat_aabb`]).
    /// With 2^31 − 1 proxies already present, returns `ProxyId(u32::MAX)`, which every
    /// method ignores.
    pub fn insert(&mut self, aabb: Aabb, user: u32, kind: ProxyKind, filter: Filter) -> ProxyId {
        if self.count >= MAX_PROXIES {
            return ProxyId(NULL);
        }
        let fat = self.fat_box(&aabb, Vec3::ZERO);
        let id = match self.free {
            Some(id) => {
                self.free = Some(self.proxies[id as usize].next_free).filter(|&n| n != NULL);
                id
            }
            None => {
                self.proxies.push(Proxy {
                    user,
                    kind,
                    filter,
                    node: NULL,
                    next_free: NULL,
                });
                self.moved.resize(self.proxies.len().div_ceil(64), 0);
                self.crowd.tight.push(aabb);
                (self.proxies.len() - 1) as u32
            }
        };
        let node = self.trees[tree_index(kind)].insert(fat, id);
        self.crowd.tight[id as usize] = aabb;
        let p = &mut self.proxies[id as usize];
        // The moved bit is kept: a reused slot may still be in the move buffer from its
        // removal.
        (p.user, p.kind, p.filter, p.node, p.next_free) = (user, kind, filter, node, NULL);
        self.count += 1;
        self.mark_moved(id);
        ProxyId(id)
    }

    /// Removes a proxy, and with it its pairs. Unknown or removed ids are ignored. Its id
    /// may be handed out again by a later `insert`.
    pub fn remove(&mut self, proxy: ProxyId) {
        let Some(p) = self.live(proxy) else {
            return;
        };
        let (tree, node) = (tree_index(p.kind), p.node);
        self.trees[tree].remove(node);
        let p = &mut self.proxies[proxy.0 as usize];
        p.node = NULL;
        p.next_free = self.free.unwrap_or(NULL);
        self.free = Some(proxy.0);
        self.count -= 1;
        // Its pairs are dropped on the next `pairs()`, before the slot could pair again.
        self.mark_moved(proxy.0);
    }

    /// Changes the user value of a proxy (bodies are renumbered when one is removed).
    pub fn set_user(&mut self, proxy: ProxyId, user: u32) {
        if self.live(proxy).is_some_and(|p| p.user != user) {
            self.proxies[proxy.0 as usize].user = user;
            // Pairs are keyed by user values: have them rebuilt under the new one.
            self.mark_moved(proxy.0);
        }
    }

    /// Changes a proxy's filter.
    pub fn set_filter(&mut self, proxy: ProxyId, filter: Filter) {
        if self.live(proxy).is_some_and(|p| p.filter != filter) {
            self.proxies[proxy.0 as usize].filter = filter;
            // Pairs may appear or vanish without any box moving.
            self.mark_moved(proxy.0);
        }
    }

    /// Tells the broad phase the proxy's tight box is now `aabb` after moving by
    /// `displacement` (used to stretch the enlarged box forward). Returns true when the
    /// proxy had to be reinserted (its tight box left its enlarged one).
    ///
    /// Also reinserts, and returns true, when the enlarged box has become far too large
    /// (more than [`SHRINK_MARGINS`] margins longer on an axis than a fresh one). Pass a
    /// zero displacement for a teleport. A non-finite displacement is taken as zero.
    pub fn update(&mut self, proxy: ProxyId, aabb: Aabb, displacement: Vec3) -> bool {
        let Some(p) = self.live(proxy) else {
            return false;
        };
        let (tree, node) = (tree_index(p.kind), p.node);
        self.crowd.tight[proxy.0 as usize] = aabb;
        let Some(fresh) = self.needs_reinsert(tree, node, &aabb, displacement) else {
            return false;
        };
        self.trees[tree].move_leaf(node, fresh);
        self.mark_moved(proxy.0);
        true
    }

    /// The new fat box for leaf `node` of tree `tree` whose tight box is now `aabb`, if it
    /// must be reinserted: the tight box left its fat box, or that has grown far too large.
    fn needs_reinsert(
        &self,
        tree: usize,
        node: u32,
        aabb: &Aabb,
        displacement: Vec3,
    ) -> Option<Aabb> {
        let fresh = self.fat_box(aabb, displacement);
        let old = self.trees[tree].aabb(node);
        let slack = (old.max - old.min) - (fresh.max - fresh.min);
        // A NaN slack (infinite boxes) compares false: not too large, so such a proxy is
        // not reinserted every step while its box still contains the tight one.
        let too_large = slack.max_element() > SHRINK_MARGINS * self.margin;
        (!old.contains(aabb) || too_large).then_some(fresh)
    }

    /// [`BroadPhase::update`] for many proxies at once (a step's moving bodies). When at
    /// least [`REBUILD_SHARE`] of a tree's leaves (and [`REBUILD_MIN`]) must be reinserted
    /// (bodies falling together leave their fat boxes in the same step), that tree is
    /// rebuilt top-down around the new boxes instead: reinserting a leaf costs a descent and
    /// a walk back up with rotations, and a rain of 2,000 bodies paid that for all of them
    /// every fifth step. The stored boxes, and so the pairs, are the same either way.
    pub fn update_many(&mut self, updates: &[(ProxyId, Aabb, Vec3)]) {
        let mut pending = std::mem::take(&mut self.pending);
        for list in pending.iter_mut() {
            list.clear();
        }
        for &(proxy, aabb, displacement) in updates {
            let Some(p) = self.live(proxy) else {
                continue;
            };
            let (tree, node) = (tree_index(p.kind), p.node);
            self.crowd.tight[proxy.0 as usize] = aabb;
            if let Some(fresh) = self.needs_reinsert(tree, node, &aabb, displacement) {
                pending[tree].push((node, fresh));
                self.mark_moved(proxy.0);
            }
        }
        for (tree, moves) in self.trees.iter_mut().zip(&pending) {
            if is_burst(moves.len(), tree.leaf_count()) {
                tree.rebuild_with(moves, &mut self.stack);
            } else {
                for &(node, fresh) in moves {
                    tree.move_leaf(node, fresh);
                }
            }
        }
        self.pending = pending;
    }

    /// Every pair of proxies whose enlarged boxes overlap and whose filters allow it,
    /// static–static excluded, as (user, user) with the smaller first, sorted, no
    /// duplicates. Incremental: only pairs involving proxies reinserted since the last call
    /// are searched again; the rest are kept while their boxes still overlap.
    ///
    /// Two proxies with the same user value never pair (a body does not touch itself);
    /// distinct proxy pairs that map to the same user pair are reported once.
    pub fn pairs(&mut self, out: &mut Vec<(u32, u32)>) {
        let BroadPhase {
            proxies,
            trees,
            move_buffer,
            moved,
            pairs,
            found,
            merged,
            stack,
            pair_stack,
            crowd,
            ..
        } = self;
        // Every pair whose fat boxes may have changed, or whose proxy is gone, renamed or
        // refiltered, is dropped here and found again below if it still holds.
        if !move_buffer.is_empty() {
            pairs.retain(|e| !bit(moved, e.a) && !bit(moved, e.b));
        }
        crowd.start(moved.len(), self.count);
        let kept = &*pairs;
        let mut admit = |x: u32, y: u32, found: &[PairEntry]| {
            let fixed = |i: u32| proxies[i as usize].kind == ProxyKind::Static;
            let exempt = fixed(x) || fixed(y);
            exempt || crowd.admit(x, y, kept, found)
        };
        found.clear();
        // When a large share of the moving proxies moved (a burst, see `update_many`), one
        // walk of the moving tree against itself finds their pairs with each other for
        // less than a query per proxy; pairs of two unmoved proxies are kept already.
        let moving = tree_index(ProxyKind::Moving);
        let burst = is_burst(move_buffer.len(), trees[moving].leaf_count());
        if burst {
            trees[moving].self_pairs(pair_stack, |x, y| {
                let (p, q) = (&proxies[x as usize], &proxies[y as usize]);
                let fresh = bit(moved, x) || bit(moved, y);
                if fresh && p.user != q.user && p.filter.allows(&q.filter) && admit(x, y, found) {
                    found.push(PairEntry::new(x, p.user, y, q.user));
                }
            });
        }
        for &id in move_buffer.iter() {
            let p = &proxies[id as usize];
            if p.node == NULL {
                continue; // removed: its pairs went with the retain above
            }
            let fat = *trees[tree_index(p.kind)].aabb(p.node);
            let mut visit = |other: u32| {
                let q = &proxies[other as usize];
                // A pair of two moved proxies is found from both sides; keep one.
                if other == id || (bit(moved, other) && other < id) || q.user == p.user {
                    return;
                }
                if p.filter.allows(&q.filter) && admit(id, other, found) {
                    found.push(PairEntry::new(id, p.user, other, q.user));
                }
            };
            if !(burst && p.kind == ProxyKind::Moving) {
                trees[moving].query(&fat, stack, &mut visit);
            }
            if p.kind == ProxyKind::Moving {
                trees[tree_index(ProxyKind::Static)].query(&fat, stack, &mut visit);
            }
        }
        for &id in move_buffer.iter() {
            set_bit(moved, id, false);
        }
        move_buffer.clear();
        publish(pairs, found, merged, out);
        for i in 0..self.crowd.requery.len() {
            let id = self.crowd.requery[i];
            set_bit(&mut self.crowd.lost, id, false);
            self.mark_moved(id);
        }
    }

    /// Number of proxies.
    pub fn len(&self) -> usize {
        self.count
    }

    /// True with no proxies.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// True with no static proxy (nothing `query_static_aabb` could find).
    pub fn has_no_static(&self) -> bool {
        self.trees[tree_index(ProxyKind::Static)].is_empty()
    }

    /// The enlarged box stored for a proxy (what pairs and queries test), `None` for an
    /// unknown or removed id. A tight box with a NaN in it is stored as the empty box
    /// (min +∞, max −∞), which overlaps only a box infinite both ways on every axis.
    pub fn fat_aabb(&self, proxy: ProxyId) -> Option<Aabb> {
        let p = self.live(proxy)?;
        Some(*self.trees[tree_index(p.kind)].aabb(p.node))
    }

    /// The user value of a proxy, `None` for an unknown or removed id.
    pub fn user(&self, proxy: ProxyId) -> Option<u32> {
        self.live(proxy).map(|p| p.user)
    }

    /// Heights of the static and the moving tree (0 when empty or a single leaf): a
    /// measure of tree quality, about log2 of the proxy count for a good tree.
    pub fn tree_heights(&self) -> [u32; 2] {
        [self.trees[0].height(), self.trees[1].height()]
    }

    fn live(&self, proxy: ProxyId) -> Option<&Proxy> {
        self.proxies
            .get(proxy.0 as usize)
            .filter(|p| p.node != NULL)
    }

    fn mark_moved(&mut self, id: u32) {
        if !bit(&self.moved, id) {
            set_bit(&mut self.moved, id, true);
            self.move_buffer.push(id);
        }
    }

    /// The tight box grown by the margin and stretched along `PREDICTION · displacement`;
    /// `EMPTY` if anything in it is NaN.
    fn fat_box(&self, tight: &Aabb, displacement: Vec3) -> Aabb {
        let d = if displacement.is_finite() {
            displacement * PREDICTION
        } else {
            Vec3::ZERO
        };
        let mut fat = tight.expanded(self.margin);
        fat.min += d.min(Vec3::ZERO);
        fat.max += d.max(Vec3::ZERO);
        if fat.min.is_nan() || fat.max.is_nan() {
            EMPTY
        } else {
            fat
        }
    }
}

/// Whether `moved` of a tree's `leaves` is a burst: at least [`REBUILD_MIN`] and
/// [`REBUILD_SHARE`] of them.
fn is_burst(moved: usize, leaves: usize) -> bool {
    moved >= REBUILD_MIN && moved as Real >= REBUILD_SHARE * leaves as Real
}

/// Merges the new pairs `found` into the kept ones (both sorted after this), and lists
/// the user pairs in `out`, each once.
fn publish(
    pairs: &mut Vec<PairEntry>,
    found: &mut [PairEntry],
    merged: &mut Vec<PairEntry>,
    out: &mut Vec<(u32, u32)>,
) {
    // The kept pairs are sorted; sort the (few) new ones and merge in linear time.
    if !found.is_empty() {
        found.sort_unstable();
        merge(pairs, found, merged);
        std::mem::swap(pairs, merged);
    }
    out.clear();
    for e in pairs.iter() {
        let users = e.users();
        if out.last() != Some(&users) {
            out.push(users);
        }
    }
}

/// The caps on the pairs of crowded proxies (see [`BroadPhase::set_crowding`]).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Crowding {
    /// Sunk pairs that make a proxy crowded: two crowded proxies do not pair.
    pub sunk: u32,
    /// Pairs a proxy may have when its partner has as many, for a new pair whose tight
    /// boxes stand more than twice `depth` apart (a candidate, not a contact).
    pub any: u32,
    /// How deep tight boxes must overlap to count as sunk (m; see `Aabb::sunk_into`), and
    /// half the gap beyond which they are far apart.
    pub depth: Real,
}

impl Crowding {
    /// No caps.
    pub const NONE: Crowding = Crowding {
        sunk: u32::MAX,
        any: u32::MAX,
        depth: 0.0,
    };

    fn is_on(&self) -> bool {
        self.sunk != u32::MAX || self.any != u32::MAX
    }
}

/// The caps on crowded proxies' pairs and their bookkeeping.
#[derive(Debug, Default, Clone)]
struct Crowd {
    caps: Crowding,
    /// Per proxy slot: the tight box last given.
    tight: Vec<Aabb>,
    /// Per proxy slot: its sunk pairs and all its pairs, counted while `pairs()` builds
    /// them.
    degree: Vec<[u32; 2]>,
    /// Candidate pairs the last `pairs()` left out because both proxies were at a cap.
    crowded: usize,
    /// Whether the caps apply in this `pairs()`: only once it holds more than
    /// [`ENGAGE`] pairs per proxy, which no scene without crowds reaches (a box in a pile
    /// has about five candidates), so that they cost nothing there.
    engaged: bool,
    /// Live proxies.
    live: usize,
    /// Proxies that lost a pair to a cap, each once (bit set `lost`): searched again on
    /// the next `pairs()`, when their neighbours may have parted.
    requery: Vec<u32>,
    lost: Vec<u64>,
}

impl Crowd {
    /// Counts each proxy's sunk pairs and all its pairs into `degree` (one per slot).
    fn count(&mut self, kept: &[PairEntry], found: &[PairEntry]) {
        self.degree.clear();
        self.degree.resize(self.tight.len(), [0, 0]);
        for e in kept.iter().chain(found) {
            self.add(e.a, e.b);
        }
    }

    /// Counts the pair (x, y) in both proxies' degrees.
    fn add(&mut self, x: u32, y: u32) {
        let sunk = self.is_sunk(x, y);
        for end in [x, y] {
            self.degree[end as usize][0] += sunk as u32;
            self.degree[end as usize][1] += 1;
        }
    }

    /// Gets ready for a `pairs()` over `words` words of proxy bits and `live` proxies.
    fn start(&mut self, words: usize, live: usize) {
        self.crowded = 0;
        self.requery.clear();
        self.lost.resize(words, 0);
        (self.engaged, self.live) = (false, live);
    }

    /// Whether the tight boxes stand more than twice the depth apart on some axis: the
    /// contact cache passes such a pair over (see `contact_cache.rs`), so one left out
    /// loses nothing until the boxes come closer, by which time the proxies have searched
    /// again. NaN says no.
    fn is_far(&self, x: u32, y: u32) -> bool {
        let (a, b) = (&self.tight[x as usize], &self.tight[y as usize]);
        a.apart(b, 2.0 * self.caps.depth)
    }

    fn is_sunk(&self, x: u32, y: u32) -> bool {
        self.tight[x as usize].sunk_into(&self.tight[y as usize], self.caps.depth)
    }

    /// Whether the new pair (x, y) fits under the caps, with `kept` and `found` the pairs
    /// so far: if so it is counted, if not both proxies are noted for searching again.
    fn admit(&mut self, x: u32, y: u32, kept: &[PairEntry], found: &[PairEntry]) -> bool {
        if !self.engaged {
            let many = kept.len() + found.len() >= ENGAGE.saturating_mul(self.live);
            if !self.caps.is_on() || !many {
                return true;
            }
            self.engaged = true;
            self.count(kept, found);
        }
        let (dx, dy) = (self.degree[x as usize], self.degree[y as usize]);
        let full = |cap: u32, k: usize| dx[k] >= cap && dy[k] >= cap;
        if full(self.caps.sunk, 0) || (full(self.caps.any, 1) && self.is_far(x, y)) {
            self.crowded += 1;
            for end in [x, y] {
                if !bit(&self.lost, end) {
                    set_bit(&mut self.lost, end, true);
                    self.requery.push(end);
                }
            }
            return false;
        }
        self.add(x, y);
        true
    }
}

/// Sets or clears bit `i` of a bit set.
fn set_bit(bits: &mut [u64], i: u32, on: bool) {
    let (word, mask) = ((i / 64) as usize, 1 << (i % 64));
    if on {
        bits[word] |= mask;
    } else {
        bits[word] &= !mask;
    }
}

/// Bit `i` of a bit set.
fn bit(bits: &[u64], i: u32) -> bool {
    bits[(i / 64) as usize] & (1 << (i % 64)) != 0
}

/// Merges two sorted lists into `out` (sorted).
fn merge(a: &[PairEntry], b: &[PairEntry], out: &mut Vec<PairEntry>) {
    out.clear();
    out.reserve(a.len() + b.len());
    let (mut i, mut j) = (0, 0);
    while i < a.len() && j < b.len() {
        if a[i] <= b[j] {
            out.push(a[i]);
            i += 1;
        } else {
            out.push(b[j]);
            j += 1;
        }
    }
    out.extend_from_slice(&a[i..]);
    out.extend_from_slice(&b[j..]);
}

impl BroadPhase {
    /// Checks a broad phase read from a snapshot against the world's bodies (body `i` is
    /// static if `is_static(i)`, its proxy is `owned[i]`): each body's proxy live, in the
    /// tree of its kind, with the body's index as its user, and no other proxy live; the
    /// trees (`Tree::check_saved`), each leaf the node of the proxy it names; then the
    /// bookkeeping every call indexes by proxy without checking.
    pub(crate) fn check_saved(
        &self,
        owned: &[ProxyId],
        is_static: impl Fn(usize) -> bool,
    ) -> crate::codec::Decoded<()> {
        use crate::codec::{check_index, ensure};
        let margin = self.margin;
        ensure(margin.is_finite() && margin >= 0.0, || {
            format!("broad_phase.margin: {margin}")
        })?;
        let slots = self.proxies.len();
        for (i, &ProxyId(id)) in owned.iter().enumerate() {
            let field = || format!("proxies[{i}]");
            check_index(id, slots, (field, "proxy"))?;
            let p = &self.proxies[id as usize];
            let kind = if is_static(i) {
                ProxyKind::Static
            } else {
                ProxyKind::Moving
            };
            let fits = p.node != NULL && p.user as usize == i && p.kind == kind;
            ensure(fits, || {
                format!("proxies[{i}]: proxy {id} is not body {i}'s")
            })?;
        }
        let live = self.proxies.iter().filter(|p| p.node != NULL).count();
        ensure(live == owned.len() && self.count == live, || {
            let bodies = owned.len();
            format!(
                "broad_phase: {live} live proxies, a count of {}, {bodies} bodies",
                self.count
            )
        })?;
        for (t, tree) in self.trees.iter().enumerate() {
            let mine = |p: &Proxy| p.node != NULL && tree_index(p.kind) == t;
            let leaves = self.proxies.iter().filter(|p| mine(p)).count();
            ensure(tree.leaf_count() == leaves, || {
                format!(
                    "broad_phase.trees[{t}]: {} leaves for {leaves} proxies",
                    tree.leaf_count()
                )
            })?;
            // Each leaf the node of the proxy it names: with the counts equal, leaves and
            // proxies pair off one to one.
            tree.check_saved(&format!("broad_phase.trees[{t}]"), |node, item| {
                let p = self.proxies.get(item as usize);
                p.is_some_and(|p| mine(p) && p.node == node)
            })?;
        }
        self.check_free_proxies()?;
        self.check_moved()?;
        self.check_pairs()?;
        let tight = self.crowd.tight.len();
        ensure(tight == slots, || {
            format!("broad_phase.crowd.tight: {tight} boxes for {slots} proxies")
        })?;
        // Set only within `pairs()`, which clears them all before it returns.
        ensure(self.crowd.lost.iter().all(|&w| w == 0), || {
            "broad_phase.crowd.lost: bits set between updates".to_string()
        })
    }

    /// The free list of proxy slots: in range, free, ending, and holding every free slot.
    fn check_free_proxies(&self) -> crate::codec::Decoded<()> {
        use crate::codec::{check_index, ensure};
        let slots = self.proxies.len();
        let mut listed = vec![false; slots];
        let mut next = self.free.unwrap_or(NULL);
        while next != NULL {
            check_index(next, slots, (|| "broad_phase.free".to_string(), "proxy"))?;
            let p = &self.proxies[next as usize];
            let reused = p.node != NULL || listed[next as usize];
            ensure(!reused, || {
                format!("broad_phase.free: proxy {next} is in use")
            })?;
            listed[next as usize] = true;
            next = p.next_free;
        }
        let free = listed.iter().filter(|&&l| l).count();
        ensure(free + self.count == slots, || {
            format!(
                "broad_phase.free: {free} listed of {} free",
                slots - self.count
            )
        })
    }

    /// The moved bits (one word per 64 slots) and the move buffer: each buffered proxy in
    /// range and marked, once, and no other bit set.
    fn check_moved(&self) -> crate::codec::Decoded<()> {
        use crate::codec::{check_index, ensure};
        let slots = self.proxies.len();
        let words = self.moved.len();
        ensure(words == slots.div_ceil(64), || {
            format!("broad_phase.moved: {words} words for {slots} proxies")
        })?;
        let mut left = self.moved.clone();
        for (k, &id) in self.move_buffer.iter().enumerate() {
            let field = || format!("broad_phase.move_buffer[{k}]");
            check_index(id, slots, (field, "proxy"))?;
            ensure(bit(&left, id), || {
                format!("broad_phase.move_buffer[{k}]: proxy {id} unmarked or twice")
            })?;
            set_bit(&mut left, id, false);
        }
        ensure(left.iter().all(|&w| w == 0), || {
            "broad_phase.moved: a proxy marked but not in the move buffer".to_string()
        })
    }

    /// The kept pairs: sorted, each of two proxies in range, and, unless one of them moved
    /// (the next `pairs()` drops those first), of two live proxies under their users now:
    /// the contact update reads those users as body indices.
    fn check_pairs(&self) -> crate::codec::Decoded<()> {
        use crate::codec::{check_index, ensure};
        let slots = self.proxies.len();
        for (k, e) in self.pairs.iter().enumerate() {
            let field = || format!("broad_phase.pairs[{k}].b");
            check_index(e.b, slots, (field, "proxy"))?;
            ensure(e.a < e.b, || {
                format!("broad_phase.pairs[{k}]: proxies {} and {}", e.a, e.b)
            })?;
            if bit(&self.moved, e.a) || bit(&self.moved, e.b) {
                continue;
            }
            let (p, q) = (&self.proxies[e.a as usize], &self.proxies[e.b as usize]);
            let now = PairEntry::new(e.a, p.user, e.b, q.user);
            let fits = p.node != NULL && q.node != NULL && p.user != q.user && now == *e;
            ensure(fits, || {
                format!("broad_phase.pairs[{k}]: not a pair of live proxies")
            })?;
        }
        let sorted = self.pairs.windows(2).all(|w| w[0] < w[1]);
        ensure(sorted, || "broad_phase.pairs: not sorted".to_string())
    }
}

impl crate::codec::Code for ProxyId {
    fn put(&self, w: &mut crate::codec::Writer) {
        self.0.put(w);
    }
    fn get(r: &mut crate::codec::Reader<'_>) -> crate::codec::Decoded<Self> {
        Ok(ProxyId(crate::codec::Code::get(r)?))
    }
}
crate::codec::codec_unit_enum!(ProxyKind { Static, Moving });
crate::codec::codec_struct!(Filter { group, mask, owner });
crate::codec::codec_struct!(Proxy {
    user,
    kind,
    filter,
    node,
    next_free
});
crate::codec::codec_struct!(PairEntry { users, a, b });
crate::codec::codec_struct!(Crowding { sunk, any, depth });
crate::codec::codec_struct!(Crowd {
    caps,
    tight,
    degree,
    crowded,
    engaged,
    live,
    requery,
    lost
});
crate::codec::codec_struct!(BroadPhase {
    margin, proxies, free, count, trees, move_buffer, moved, pairs, crowd;
    found, merged, stack, pair_stack, pending
});
