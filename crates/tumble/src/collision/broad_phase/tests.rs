//! Unit tests of the tree's invariants and the broad phase's bookkeeping; the behaviour
//! against brute force is tested in `tests/engine/broad_phase.rs`.

use super::tree::Tree;
use super::*;

/// A small deterministic generator (SplitMix64), so the tests need no extra crate.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
    /// Uniform in [lo, hi).
    fn range(&mut self, lo: Real, hi: Real) -> Real {
        lo + (hi - lo) * ((self.next() >> 11) as f64 / (1u64 << 53) as f64) as Real
    }
    fn below(&mut self, n: usize) -> usize {
        (self.next() % n as u64) as usize
    }
    fn aabb(&mut self, extent: Real) -> Aabb {
        let c = Vec3::new(
            self.range(-extent, extent),
            self.range(-extent, extent),
            self.range(-extent, extent),
        );
        let h = Vec3::new(
            self.range(0.05, 1.0),
            self.range(0.05, 1.0),
            self.range(0.05, 1.0),
        );
        Aabb::from_center(c, h)
    }
}

fn brute_query(boxes: &[(u32, Aabb)], q: &Aabb) -> Vec<u32> {
    let mut v: Vec<u32> = boxes
        .iter()
        .filter(|(_, b)| b.overlaps(q))
        .map(|(i, _)| *i)
        .collect();
    v.sort_unstable();
    v
}

#[test]
fn tree_stays_exact_under_inserts_moves_and_removes() {
    let mut rng = Rng(7);
    let mut tree = Tree::default();
    // (item, box, leaf)
    let mut live: Vec<(u32, Aabb, u32)> = Vec::new();
    let mut next_item = 0;
    let mut stack = Vec::new();
    for round in 0..2000 {
        match rng.below(4) {
            0 | 1 => {
                let b = rng.aabb(20.0);
                live.push((next_item, b, tree.insert(b, next_item)));
                next_item += 1;
            }
            2 if !live.is_empty() => {
                let k = rng.below(live.len());
                let b = rng.aabb(20.0);
                tree.move_leaf(live[k].2, b);
                live[k].1 = b;
            }
            _ if !live.is_empty() => {
                let (_, _, leaf) = live.swap_remove(rng.below(live.len()));
                tree.remove(leaf);
            }
            _ => {}
        }
        if round % 50 == 0 {
            tree.validate().unwrap();
            let q = rng.aabb(20.0).expanded(2.0);
            let mut got = Vec::new();
            tree.query(&q, &mut stack, |i| got.push(i));
            got.sort_unstable();
            let boxes: Vec<(u32, Aabb)> = live.iter().map(|&(i, b, _)| (i, b)).collect();
            assert_eq!(got, brute_query(&boxes, &q));
        }
    }
    tree.validate().unwrap();
    for (_, _, leaf) in live.drain(..) {
        tree.remove(leaf);
    }
    tree.validate().unwrap();
    assert!(tree.root().is_none());
}

#[test]
fn tree_is_shallow_for_random_and_sorted_insertions() {
    let n = 4096; // log2 n = 12
    let mut rng = Rng(11);
    let mut random = Tree::default();
    for i in 0..n {
        random.insert(rng.aabb(50.0), i);
    }
    // Sorted along a line is the classic worst case for naive insertion (a list).
    let mut sorted = Tree::default();
    for i in 0..n {
        let c = Vec3::new(i as Real, 0.0, 0.0);
        sorted.insert(Aabb::from_center(c, Vec3::splat(0.4)), i);
    }
    // Bodies spawned at one spot: every box the same, every insertion cost a tie.
    let mut same = Tree::default();
    let mut nearly = Tree::default();
    for i in 0..n {
        same.insert(Aabb::from_center(Vec3::ZERO, Vec3::splat(0.5)), i);
        let c = Vec3::new(rng.range(0.0, 1e-4), rng.range(0.0, 1e-4), 0.0);
        nearly.insert(Aabb::from_center(c, Vec3::splat(0.5)), i);
    }
    let heights = [
        random.height(),
        sorted.height(),
        same.height(),
        nearly.height(),
    ];
    for (tree, h) in [random, sorted, same, nearly].iter().zip(heights) {
        tree.validate().unwrap();
        assert!(h <= 24, "heights {heights:?} (2 log2 n = 24)");
    }
}

#[test]
fn a_reused_slot_does_not_inherit_the_old_pairs() {
    let mut bp = BroadPhase::new(0.1);
    let unit = |x: Real| Aabb::from_center(Vec3::new(x, 0.0, 0.0), Vec3::splat(0.5));
    let a = bp.insert(unit(0.0), 1, ProxyKind::Moving, Filter::default());
    let b = bp.insert(unit(0.5), 2, ProxyKind::Moving, Filter::default());
    let mut out = Vec::new();
    bp.pairs(&mut out);
    assert_eq!(out, vec![(1, 2)]);
    // Remove b and put a far-away proxy in its slot before the pairs are asked for.
    bp.remove(b);
    let c = bp.insert(unit(100.0), 3, ProxyKind::Moving, Filter::default());
    assert_eq!(c, b, "the slot is reused");
    bp.pairs(&mut out);
    assert!(out.is_empty(), "{out:?}");
    assert_eq!(bp.move_buffer.len(), 0);
    assert!(bp.moved.iter().all(|&w| w == 0));
    bp.update(a, unit(99.6), Vec3::ZERO);
    bp.pairs(&mut out);
    assert_eq!(out, vec![(1, 3)]);
}

#[test]
fn pair_entries_sort_as_the_output() {
    let e = |ua, ub| PairEntry::new(0, ua, 1, ub);
    let mut v = [e(3, 1), e(0, u32::MAX), e(1, 2), e(u32::MAX, 1)];
    v.sort_unstable();
    let users: Vec<(u32, u32)> = v.iter().map(PairEntry::users).collect();
    assert_eq!(users, vec![(0, u32::MAX), (1, 2), (1, 3), (1, u32::MAX)]);
}

#[test]
fn merge_keeps_order() {
    let e = |u| PairEntry::new(0, 0, 1, u);
    let (a, b) = ([e(1), e(4), e(5)], [e(2), e(3), e(6)]);
    let mut out = Vec::new();
    merge(&a, &b, &mut out);
    assert!(out.windows(2).all(|w| w[0] < w[1]));
    assert_eq!(out.len(), 6);
}

#[test]
fn invalid_ids_are_ignored() {
    let mut bp = BroadPhase::new(0.1);
    let ghost = ProxyId(12);
    bp.remove(ghost);
    bp.set_user(ghost, 3);
    bp.set_filter(ghost, Filter::default());
    assert!(!bp.update(ghost, Aabb::new(Vec3::ZERO, Vec3::ONE), Vec3::ONE));
    assert_eq!(bp.fat_aabb(ghost), None);
    assert_eq!(bp.fat_aabb(ProxyId(u32::MAX)), None);
    let a = bp.insert(
        Aabb::new(Vec3::ZERO, Vec3::ONE),
        0,
        ProxyKind::Static,
        Filter::default(),
    );
    bp.remove(a);
    bp.remove(a); // twice: no effect
    assert!(bp.is_empty());
    assert!(bp.move_buffer.len() <= 1);
}

#[test]
#[cfg(not(feature = "f32"))]
fn a_node_is_one_cache_line() {
    assert_eq!(std::mem::size_of::<super::tree::Node>(), 64);
    assert_eq!(std::mem::align_of::<super::tree::Node>(), 64);
}

/// Pairs of the stored boxes by brute force: (user, user), sorted.
fn brute_pairs(bp: &BroadPhase, ids: &[(ProxyId, u32)]) -> Vec<(u32, u32)> {
    let mut v = Vec::new();
    for (i, &(a, ua)) in ids.iter().enumerate() {
        for &(b, ub) in &ids[i + 1..] {
            if bp.fat_aabb(a).unwrap().overlaps(&bp.fat_aabb(b).unwrap()) {
                v.push((ua.min(ub), ua.max(ub)));
            }
        }
    }
    v.sort_unstable();
    v
}

#[test]
fn batched_updates_rebuild_or_move_and_keep_the_pairs_exact() {
    let mut rng = Rng(5);
    let mut bp = BroadPhase::new(0.1);
    let ids: Vec<(ProxyId, u32)> = (0..300)
        .map(|u| {
            let p = bp.insert(rng.aabb(10.0), u, ProxyKind::Moving, Filter::default());
            (p, u)
        })
        .collect();
    let mut out = Vec::new();
    bp.pairs(&mut out);
    assert_eq!(out, brute_pairs(&bp, &ids));
    // Every proxy moves (a rebuild), then a handful (reinsertions), then all again.
    for moving in [300, 7, 300] {
        let updates: Vec<(ProxyId, Aabb, Vec3)> = ids[..moving]
            .iter()
            .map(|&(p, _)| (p, rng.aabb(10.0), Vec3::new(0.0, -0.3, 0.0)))
            .collect();
        bp.update_many(&updates);
        bp.trees[1].validate().unwrap();
        for (p, tight, _) in &updates {
            assert!(bp.fat_aabb(*p).unwrap().contains(tight));
        }
        bp.pairs(&mut out);
        assert_eq!(out, brute_pairs(&bp, &ids));
    }
    // 300 leaves rebuilt by halves: ⌈log2 300⌉ = 9.
    assert!(bp.tree_heights()[1] <= 12, "{:?}", bp.tree_heights());
}

#[test]
fn self_pairs_match_brute_force() {
    let mut rng = Rng(9);
    let mut tree = Tree::default();
    let boxes: Vec<Aabb> = (0..400).map(|_| rng.aabb(15.0)).collect();
    for (i, b) in boxes.iter().enumerate() {
        tree.insert(*b, i as u32);
    }
    let mut got = Vec::new();
    tree.self_pairs(&mut Vec::new(), |a, b| got.push((a.min(b), a.max(b))));
    got.sort_unstable();
    let mut want = Vec::new();
    for i in 0..boxes.len() {
        for j in i + 1..boxes.len() {
            if boxes[i].overlaps(&boxes[j]) {
                want.push((i as u32, j as u32));
            }
        }
    }
    assert!(!want.is_empty());
    assert_eq!(got, want, "each overlapping pair exactly once");
}
