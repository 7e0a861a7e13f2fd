//! The broad phase against brute force: pairs, the tight-box guarantee, box and ray
//! queries, filters, removal and renumbering, and when proxies are reinserted.

use proptest::prelude::*;
use tumble::broad_phase::{BroadPhase, Filter, ProxyId, ProxyKind};
use tumble::{Aabb, Real, Vec3};

/// What the test knows about one live proxy.
#[derive(Debug, Clone)]
struct Model {
    id: ProxyId,
    tight: Aabb,
    user: u32,
    kind: ProxyKind,
    filter: Filter,
}

fn v3(a: [f64; 3]) -> Vec3 {
    Vec3::new(a[0] as Real, a[1] as Real, a[2] as Real)
}

fn cube(center: Vec3, half: Real) -> Aabb {
    Aabb::from_center(center, Vec3::splat(half))
}

/// Whether two proxies may pair at all (everything but the boxes).
fn may_pair(a: &Model, b: &Model) -> bool {
    a.user != b.user
        && !(a.kind == ProxyKind::Static && b.kind == ProxyKind::Static)
        && a.filter.allows(&b.filter)
}

fn user_pair(a: &Model, b: &Model) -> (u32, u32) {
    (a.user.min(b.user), a.user.max(b.user))
}

/// Every pair whose stored (enlarged) boxes overlap, by the O(n²) loop.
fn brute_pairs(bp: &BroadPhase, live: &[Model]) -> Vec<(u32, u32)> {
    let fat: Vec<Aabb> = live.iter().map(|m| bp.fat_aabb(m.id).unwrap()).collect();
    let mut out = Vec::new();
    for i in 0..live.len() {
        for j in i + 1..live.len() {
            if may_pair(&live[i], &live[j]) && fat[i].overlaps(&fat[j]) {
                out.push(user_pair(&live[i], &live[j]));
            }
        }
    }
    out.sort_unstable();
    out.dedup();
    out
}

/// Checks `pairs()` against brute force and the guarantee users rely on: every pair of
/// overlapping tight boxes is reported.
fn check_pairs(bp: &mut BroadPhase, live: &[Model]) -> Result<(), TestCaseError> {
    prop_assert_eq!(bp.len(), live.len());
    for m in live {
        let fat = bp.fat_aabb(m.id).unwrap();
        prop_assert!(fat.contains(&m.tight), "fat {:?} tight {:?}", fat, m.tight);
        prop_assert_eq!(bp.user(m.id), Some(m.user));
    }
    let mut got = Vec::new();
    bp.pairs(&mut got);
    prop_assert_eq!(&got, &brute_pairs(bp, live));
    for (i, a) in live.iter().enumerate() {
        for b in &live[i + 1..] {
            if may_pair(a, b) && a.tight.overlaps(&b.tight) {
                prop_assert!(got.binary_search(&user_pair(a, b)).is_ok());
            }
        }
    }
    Ok(())
}

#[derive(Debug, Clone)]
enum Op {
    /// A small step, displacement passed: usually no reinsertion.
    Jitter(usize, [f64; 3]),
    /// A large step; the flag says whether the displacement is passed (else a teleport).
    Jump(usize, [f64; 3], bool),
    /// New half extents (the tight box grows or shrinks in place).
    Resize(usize, f64),
    Remove(usize),
    Insert([f64; 3], f64, bool, Filter),
    SetUser(usize, u32),
    SetFilter(usize, Filter),
}

fn filter() -> impl Strategy<Value = Filter> {
    let mask = prop_oneof![Just(u32::MAX), 0u32..8];
    (0u32..3, mask, 0u32..3).prop_map(|(g, mask, owner)| Filter {
        group: 1 << g,
        mask,
        owner,
    })
}

fn center() -> impl Strategy<Value = [f64; 3]> {
    [-8.0..8.0f64, -8.0..8.0f64, -8.0..8.0f64]
}

fn op() -> impl Strategy<Value = Op> {
    let small = [-0.05..0.05f64, -0.05..0.05f64, -0.05..0.05f64];
    let large = [-6.0..6.0f64, -6.0..6.0f64, -6.0..6.0f64];
    prop_oneof![
        4 => (any::<usize>(), small).prop_map(|(i, d)| Op::Jitter(i, d)),
        2 => (any::<usize>(), large, any::<bool>()).prop_map(|(i, d, f)| Op::Jump(i, d, f)),
        1 => (any::<usize>(), 0.05..2.0f64).prop_map(|(i, h)| Op::Resize(i, h)),
        1 => any::<usize>().prop_map(Op::Remove),
        1 => (center(), 0.05..2.0f64, prop::bool::weighted(0.3), filter())
            .prop_map(|(c, h, s, f)| Op::Insert(c, h, s, f)),
        1 => (any::<usize>(), 0u32..40).prop_map(|(i, u)| Op::SetUser(i, u)),
        1 => (any::<usize>(), filter()).prop_map(|(i, f)| Op::SetFilter(i, f)),
    ]
}

fn insert(bp: &mut BroadPhase, live: &mut Vec<Model>, tight: Aabb, user: u32, st: bool, f: Filter) {
    let kind = if st {
        ProxyKind::Static
    } else {
        ProxyKind::Moving
    };
    let id = bp.insert(tight, user, kind, f);
    live.push(Model {
        id,
        tight,
        user,
        kind,
        filter: f,
    });
}

fn apply(bp: &mut BroadPhase, live: &mut Vec<Model>, next_user: &mut u32, op: &Op) {
    let pick = |i: usize, live: &Vec<Model>| (!live.is_empty()).then(|| i % live.len());
    match *op {
        Op::Jitter(i, d) | Op::Jump(i, d, true) => {
            if let Some(k) = pick(i, live) {
                let d = v3(d);
                let m = &mut live[k];
                m.tight = Aabb::new(m.tight.min + d, m.tight.max + d);
                bp.update(m.id, m.tight, d);
            }
        }
        Op::Jump(i, d, false) => {
            if let Some(k) = pick(i, live) {
                let m = &mut live[k];
                m.tight = Aabb::new(m.tight.min + v3(d), m.tight.max + v3(d));
                bp.update(m.id, m.tight, Vec3::ZERO);
            }
        }
        Op::Resize(i, h) => {
            if let Some(k) = pick(i, live) {
                let m = &mut live[k];
                m.tight = cube(m.tight.center(), h as Real);
                bp.update(m.id, m.tight, Vec3::ZERO);
            }
        }
        Op::Remove(i) => {
            if let Some(k) = pick(i, live) {
                bp.remove(live.swap_remove(k).id);
            }
        }
        Op::Insert(c, h, st, f) => {
            *next_user += 1;
            insert(bp, live, cube(v3(c), h as Real), *next_user, st, f);
        }
        Op::SetUser(i, u) => {
            if let Some(k) = pick(i, live) {
                live[k].user = u;
                bp.set_user(live[k].id, u);
            }
        }
        Op::SetFilter(i, f) => {
            if let Some(k) = pick(i, live) {
                live[k].filter = f;
                bp.set_filter(live[k].id, f);
            }
        }
    }
}

type Scene = Vec<([f64; 3], f64, bool, Filter)>;

fn scene() -> impl Strategy<Value = Scene> {
    prop::collection::vec(
        (center(), 0.05..2.0f64, prop::bool::weighted(0.3), filter()),
        0..50,
    )
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(128))]

    #[test]
    fn pairs_match_brute_force_through_moves_removals_and_insertions(
        margin in prop_oneof![Just(0.0f64), Just(0.05), Just(0.3)],
        initial in scene(),
        rounds in prop::collection::vec(prop::collection::vec(op(), 0..30), 1..8),
    ) {
        let mut bp = BroadPhase::new(margin as Real);
        let mut live = Vec::new();
        let mut next_user = 0;
        for (c, h, st, f) in initial {
            next_user += 1;
            insert(&mut bp, &mut live, cube(v3(c), h as Real), next_user, st, f);
        }
        check_pairs(&mut bp, &live)?;
        for round in &rounds {
            for op in round {
                apply(&mut bp, &mut live, &mut next_user, op);
            }
            check_pairs(&mut bp, &live)?;
        }
        // Asking again with nothing changed gives the same answer.
        check_pairs(&mut bp, &live)?;
    }

    #[test]
    fn box_and_ray_queries_match_brute_force(
        initial in scene(),
        moves in prop::collection::vec(op(), 0..30),
        query in (center(), [0.0..4.0f64, 0.0..4.0f64, 0.0..4.0f64]),
        ray in (center(), [-1.0..1.0f64, -1.0..1.0f64, -1.0..1.0f64], 0.0..30.0f64),
    ) {
        let mut bp = BroadPhase::new(0.1);
        let mut live = Vec::new();
        let mut next_user = 0;
        for (c, h, st, f) in initial {
            next_user += 1;
            insert(&mut bp, &mut live, cube(v3(c), h as Real), next_user, st, f);
        }
        for op in moves.iter().filter(|op| !matches!(op, Op::SetUser(..))) {
            apply(&mut bp, &mut live, &mut next_user, op); // users stay distinct
        }
        let fat: Vec<(u32, Aabb)> =
            live.iter().map(|m| (m.user, bp.fat_aabb(m.id).unwrap())).collect();

        let q = Aabb::from_center(v3(query.0), v3(query.1));
        let mut got = Vec::new();
        bp.query_aabb(&q, |u| got.push(u));
        got.sort_unstable();
        let mut want: Vec<u32> =
            fat.iter().filter(|(_, b)| b.overlaps(&q)).map(|(u, _)| *u).collect();
        want.sort_unstable();
        prop_assert_eq!(got, want);

        // Unclipped: every box the ray crosses, each once.
        let (o, d, max_t) = (v3(ray.0), v3(ray.1), ray.2 as Real);
        let entry = |u: u32| {
            fat.iter()
                .find(|(v, _)| *v == u)
                .and_then(|(_, b)| b.ray_interval(o, d, max_t))
                .map(|(t, _)| t)
        };
        let mut got = Vec::new();
        bp.cast_ray(o, d, max_t, |u, limit| {
            got.push(u);
            limit
        });
        got.sort_unstable();
        let mut want: Vec<u32> =
            fat.iter().filter(|(u, _)| entry(*u).is_some()).map(|(u, _)| *u).collect();
        want.sort_unstable();
        prop_assert_eq!(&got, &want);

        // Clipped: each box "hit" where the ray enters it; the nearest must be found and no
        // box entered beyond the current limit may be offered.
        let nearest = want.iter().filter_map(|&u| entry(u)).reduce(Real::min);
        let mut found: Option<Real> = None;
        let mut ok = true;
        bp.cast_ray(o, d, max_t, |u, limit| {
            let t = entry(u).unwrap_or(Real::INFINITY);
            ok &= t <= limit;
            found = Some(found.map_or(t, |f: Real| f.min(t)));
            t
        });
        prop_assert!(ok, "a box beyond the shortened ray was visited");
        prop_assert_eq!(found, nearest);
    }
}

fn moving(bp: &mut BroadPhase, aabb: Aabb, user: u32) -> ProxyId {
    bp.insert(aabb, user, ProxyKind::Moving, Filter::default())
}

fn pairs(bp: &mut BroadPhase) -> Vec<(u32, u32)> {
    let mut out = vec![(99, 99)]; // stale content must be cleared
    bp.pairs(&mut out);
    out
}

#[test]
fn static_proxies_never_pair_with_each_other() {
    let mut bp = BroadPhase::new(0.1);
    let b = cube(Vec3::ZERO, 1.0);
    bp.insert(b, 0, ProxyKind::Static, Filter::default());
    bp.insert(b, 1, ProxyKind::Static, Filter::default());
    assert_eq!(pairs(&mut bp), vec![]);
    moving(&mut bp, b, 2);
    assert_eq!(pairs(&mut bp), vec![(0, 2), (1, 2)]);
}

#[test]
fn filters_need_both_directions_and_changes_take_effect() {
    let mut bp = BroadPhase::new(0.0);
    let b = cube(Vec3::ZERO, 1.0);
    let a = bp.insert(
        b,
        0,
        ProxyKind::Moving,
        Filter {
            group: 0b01,
            mask: 0b10,
            owner: 0,
        },
    );
    let c = bp.insert(
        b,
        1,
        ProxyKind::Moving,
        Filter {
            group: 0b10,
            mask: 0b01,
            owner: 0,
        },
    );
    bp.insert(
        b,
        2,
        ProxyKind::Static,
        Filter {
            group: 0b10,
            mask: 0b00,
            owner: 0,
        },
    );
    // a–c: each is in the other's mask. a–2: 2's mask excludes a. c–2: c's mask excludes 2.
    assert_eq!(pairs(&mut bp), vec![(0, 1)]);
    bp.set_filter(
        c,
        Filter {
            group: 0b10,
            mask: 0b00,
            owner: 0,
        },
    );
    assert_eq!(pairs(&mut bp), vec![]);
    bp.set_filter(
        a,
        Filter {
            group: 0b01,
            mask: u32::MAX,
            owner: 0,
        },
    );
    bp.set_filter(c, Filter::default());
    assert_eq!(pairs(&mut bp), vec![(0, 1)]);
    bp.set_filter(
        a,
        Filter {
            group: 0b11,
            mask: u32::MAX,
            owner: 0,
        },
    );
    bp.set_filter(
        ProxyId(2),
        Filter {
            group: 0b10,
            mask: 0b01,
            owner: 0,
        },
    );
    // Now 2 takes group 0b01 (both a and c are in it) and both take its group 0b10.
    assert_eq!(pairs(&mut bp), vec![(0, 1), (0, 2), (1, 2)]);
}

#[test]
fn removal_drops_pairs_and_set_user_renames_them() {
    let mut bp = BroadPhase::new(0.1);
    let ids: Vec<ProxyId> = (0..4)
        .map(|i| moving(&mut bp, cube(Vec3::new(i as Real, 0.0, 0.0), 0.6), i))
        .collect();
    assert_eq!(pairs(&mut bp), vec![(0, 1), (1, 2), (2, 3)]);
    assert_eq!(bp.len(), 4);
    // Remove body 1 and renumber the last into its place, as a world does.
    bp.remove(ids[1]);
    bp.set_user(ids[3], 1);
    assert_eq!(bp.len(), 3);
    assert_eq!(bp.fat_aabb(ids[1]), None);
    assert_eq!(pairs(&mut bp), vec![(1, 2)]);
    // Same user on two proxies (two boxes of one body): no self pair.
    bp.set_user(ids[2], 1);
    assert_eq!(pairs(&mut bp), vec![]);
    bp.remove(ids[1]); // already removed: nothing happens
    for &id in &[ids[0], ids[2], ids[3]] {
        bp.remove(id);
    }
    assert!(bp.is_empty());
    assert_eq!(pairs(&mut bp), vec![]);
}

#[test]
fn a_slow_proxy_stays_put_and_a_fast_one_is_reinserted() {
    let margin = 0.1;
    let mut bp = BroadPhase::new(margin);
    let start = cube(Vec3::ZERO, 0.5);
    let slow = moving(&mut bp, start, 0);
    let fast = moving(&mut bp, start, 1);
    let teleported = moving(&mut bp, start, 2);
    let (mut slow_reinserts, mut fast_reinserts, mut teleports) = (0, 0, 0);
    let steps = 40;
    for k in 1..=steps {
        let s = Vec3::new(0.001, 0.0, 0.0); // 1 mm per step: 100 steps to use the margin
        slow_reinserts += bp.update(slow, cube(s * k as Real, 0.5), s) as u32;
        let f = Vec3::new(0.0, 1.0, 0.0); // 1 m per step, ten margins
        fast_reinserts += bp.update(fast, cube(f * k as Real, 0.5), f) as u32;
        let t = Vec3::new(0.0, 0.0, 1.0); // the same, as a teleport (no displacement)
        teleports += bp.update(teleported, cube(t * k as Real, 0.5), Vec3::ZERO) as u32;
    }
    assert_eq!(slow_reinserts, 0);
    assert_eq!(
        teleports, steps,
        "a jump past the margin is reinserted every time"
    );
    // Reinserted at step k, the fat box reaches PREDICTION · 1 m + margin ahead: the tight
    // box stays inside for 4 more steps, so one reinsertion in 5.
    assert_eq!(fast_reinserts, steps / 5);
    // The fast one stops: its box, stretched 4 m forward, is far too large and shrinks.
    let here = cube(Vec3::new(0.0, steps as Real, 0.0), 0.5);
    assert!(bp.update(fast, here, Vec3::ZERO));
    assert_eq!(bp.fat_aabb(fast), Some(here.expanded(margin)));
    assert!(!bp.update(fast, here, Vec3::ZERO));
}

#[test]
fn bad_numbers_do_not_panic() {
    let mut bp = BroadPhase::new(Real::NAN);
    assert_eq!(bp.margin(), 0.0);
    let nan = Aabb::new(Vec3::splat(Real::NAN), Vec3::ONE);
    let everything = Aabb::new(Vec3::splat(Real::NEG_INFINITY), Vec3::splat(Real::INFINITY));
    let a = moving(&mut bp, nan, 0);
    let b = moving(&mut bp, everything, 1);
    let c = moving(&mut bp, cube(Vec3::ZERO, 1.0), 2);
    // The NaN box is stored empty: it meets no finite box, only the one covering all space.
    let empty = bp.fat_aabb(a).unwrap();
    assert!(empty.min.cmpgt(empty.max).all());
    assert_eq!(pairs(&mut bp), vec![(0, 1), (1, 2)]);
    bp.update(c, cube(Vec3::ONE, 1.0), Vec3::splat(Real::NAN));
    bp.update(b, everything, Vec3::splat(Real::INFINITY));
    bp.update(a, nan, Vec3::ONE);
    assert_eq!(pairs(&mut bp), vec![(0, 1), (1, 2)]);
    bp.update(a, cube(Vec3::ZERO, 1.0), Vec3::ZERO);
    assert_eq!(pairs(&mut bp), vec![(0, 1), (0, 2), (1, 2)]);
    let mut n = 0;
    bp.query_aabb(&nan, |_| n += 1);
    bp.cast_ray(Vec3::splat(Real::NAN), Vec3::X, 1.0, |_, t| {
        n += 1;
        t
    });
    bp.cast_ray(Vec3::ZERO, Vec3::X, Real::NAN, |_, t| {
        n += 1;
        t
    });
    assert_eq!(n, 0);
    // A zero direction is a point: it finds the boxes containing the origin.
    let mut hit = Vec::new();
    bp.cast_ray(Vec3::ZERO, Vec3::ZERO, 1.0, |u, t| {
        hit.push(u);
        t
    });
    hit.sort_unstable();
    assert_eq!(hit, vec![0, 1, 2]);
    // A negative return ends the walk at once.
    let mut visits = 0;
    bp.cast_ray(Vec3::ZERO, Vec3::X, 10.0, |_, _| {
        visits += 1;
        -1.0
    });
    assert_eq!(visits, 1);
}

#[test]
fn many_proxies_keep_the_trees_shallow() {
    let mut bp = BroadPhase::new(0.1);
    let grid = |i: usize| {
        let c = Vec3::new((i % 16) as Real, ((i / 16) % 16) as Real, (i / 256) as Real);
        cube(c * 1.1, 0.5)
    };
    let mut live = Vec::new();
    for i in 0..4096 {
        insert(
            &mut bp,
            &mut live,
            grid(i),
            i as u32,
            false,
            Filter::default(),
        );
    }
    let [_, h] = bp.tree_heights();
    assert!(h <= 24, "moving tree height {h} for 4096 proxies");
    let got = pairs(&mut bp);
    assert_eq!(got, brute_pairs(&bp, &live));
    // Each cell touches its 26 neighbours (fat boxes reach 1.2 > 1.1 along every axis):
    // per half-direction, (16 - 1) cells along each axis it steps on, 16 on the others.
    assert_eq!(
        got.len(),
        3 * 15 * 16 * 16 + 6 * 15 * 15 * 16 + 4 * 15 * 15 * 15
    );
    // Every proxy teleports once, in reverse order; the tree stays shallow.
    for (i, m) in live.iter_mut().enumerate().rev() {
        m.tight = grid(4095 - i);
        assert!(bp.update(m.id, m.tight, Vec3::ZERO));
    }
    let [_, h] = bp.tree_heights();
    assert!(h <= 24, "moving tree height {h} after moving every proxy");
    assert_eq!(pairs(&mut bp), brute_pairs(&bp, &live));
}

#[test]
fn a_shortened_ray_skips_the_boxes_behind_the_hit() {
    let mut bp = BroadPhase::new(0.1);
    let n = 200;
    for i in 0..n {
        let kind = if i % 2 == 0 {
            ProxyKind::Static
        } else {
            ProxyKind::Moving
        };
        bp.insert(
            cube(Vec3::new(2.0 * i as Real, 0.0, 0.0), 0.5),
            i,
            kind,
            Filter::default(),
        );
    }
    let origin = Vec3::new(-5.0, 0.1, -0.2);
    let mut all = 0;
    bp.cast_ray(origin, Vec3::X, 1000.0, |_, limit| {
        all += 1;
        limit
    });
    assert_eq!(all, n);
    // Each box is "hit" where the ray enters it. Nearest boxes come first, so after the
    // first hit almost everything lies beyond the ray's new end.
    let mut visited = Vec::new();
    bp.cast_ray(origin, Vec3::X, 1000.0, |u, _| {
        visited.push(u);
        2.0 * u as Real - 0.6 + 5.0
    });
    assert_eq!(visited[0], 0, "nearest first");
    assert!(visited.len() <= 4, "visited {visited:?}");
}
