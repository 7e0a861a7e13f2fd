//! Persistent contacts: the narrow phase run over the broad phase's pairs, with every new
//! manifold point matched by feature id to last step's, so the solver can start from the
//! impulses it found then (warm starting).

use crate::collision::broad_phase::{BroadPhase, Crowding};
use crate::collision::contact::{Basis, Key, REUSE_DISTANCE};
pub use crate::collision::contact::{Contact, ContactEvent, ContactEventKind};
use crate::collision::geometry::{Aabb, Pose};
use crate::collision::narrow_phase::{collide, collide_solids, ContactPoint, Manifold};
use crate::dynamics::body::{Body, BodyKind};
use crate::id::BodyId;
use crate::limits::{ContactLimits, MAX_MANIFOLDS_PER_PAIR};
use crate::math::{Real, Vec3};
use crate::threads::Par;
use std::mem::MaybeUninit;

/// Shapes whose pair yields at most one manifold with fixed sub-shapes (0, 0), so that a
/// reused manifold stands for the whole pair.
fn reusable(shape: &crate::collision::shape::Shape) -> bool {
    use crate::collision::shape::Shape as S;
    matches!(
        shape,
        S::Sphere { .. }
            | S::Box { .. }
            | S::Capsule { .. }
            | S::Cylinder { .. }
            | S::ConvexHull(_)
    )
}

/// The current contacts and the previous step's, for matching.
#[derive(Debug, Default)]
pub(crate) struct ContactCache {
    contacts: Vec<Contact>,
    previous: Vec<Contact>,
    /// Indices of `previous` sorted by contact key: sorting indices moves 4 bytes each
    /// where sorting the contacts would move hundreds.
    order: Vec<u32>,
    /// The contact keys of `previous` in that order: searches read these 24 bytes, not
    /// a cache line of each kilobyte-sized contact.
    keys: Vec<Key>,
    /// Scratch for sorting `keys` with their indices.
    keyed: Vec<(Key, u32)>,
    events: Vec<ContactEvent>,
    /// The events of the update before, kept so that a failed step can be undone.
    events_before: Vec<ContactEvent>,
    pairs: Vec<(u32, u32)>,
    /// The touching body pairs of `contacts` and of `previous`, sorted: last update's
    /// list is this one's `before`, so each update sorts only its own.
    touching: Vec<(BodyId, BodyId)>,
    touching_before: Vec<(BodyId, BodyId)>,
    scratch: PairScratch,
    /// Per body: the dynamic partners it overlaps in this update (a manifold point with
    /// negative separation), and those it is sunk into (deeper than `deep`).
    degree: Vec<Degree>,
    /// Pairs the last update left out because both bodies were at their cap.
    crowded: usize,
    /// Whether the last update stopped at `ContactLimits::per_step` manifolds.
    overflowed: bool,
    /// Each piece's scratch and contacts when the pairs are split over threads.
    pieces: Vec<(PairScratch, Vec<Contact>)>,
    /// Every body's motion, for the pieces.
    motions: Vec<Motion>,
    /// Pairs the last update took to the narrow phase, rather than kept or reused: the
    /// work that splitting over threads shares out.
    collided: usize,
}

/// What the contacts of one pair are computed with, kept to reuse allocations.
#[derive(Debug, Default)]
struct PairScratch {
    /// The bodies' tight boxes and motions, computed as pairs need them.
    motions: Motions,
    manifolds: Vec<Manifold>,
    /// Scratch for broad-phase queries.
    stack: Vec<u32>,
    /// Pairs that went to the narrow phase in this update.
    collided: usize,
}

/// What every pair of an update reads.
struct PairWorld<'a> {
    bodies: &'a [Body],
    ids: &'a [BodyId],
    /// The contact margin (m).
    margin: Real,
    /// The coming step's length (s) and the speed gravity adds over it (m/s); zero when
    /// contacts are updated outside a step.
    step: (Real, Real),
    /// How many static bodies there are.
    statics: usize,
}

impl PairWorld<'_> {
    /// The margin for a pair: the world's, or farther if the bodies can close more than
    /// that in the coming step. A speculative contact stops a body only if it exists: with
    /// the fixed 2 cm margin, a ball falling faster than 1.2 m/s at dt 1/60 moved from
    /// outside the margin to 1.3 cm into the ground within one step, and the push-out
    /// and the late bounce then made its rebound wrong by up to half. Slow pairs keep the
    /// world's margin, so resting scenes find the same manifolds as before.
    ///
    /// Only pairs that bounce (a restitution above zero, combined by the larger) are
    /// widened: an inelastic one that sinks a step's travel into the ground is pushed out
    /// at the push-out speed and nothing reflects the late contact, while the rain, whose
    /// bodies land at up to 10 m/s, took 40 % more instructions over its landing with
    /// every pair widened (speculative manifolds up to half a metre apart, and their
    /// narrow phase).
    ///
    /// Only relative motion counts: bodies falling side by side (the rain) close nothing,
    /// and gravity changes their relative velocity only by the difference of their
    /// gravity scales, 1 when one of them does not fall (summing each body's own speed made the rain's narrow phase see pairs 30 cm apart,
    /// +11 % instructions). And each body's share stops at its CCD extent: a body moving
    /// farther is swept against static geometry by `pipeline/ccd.rs`, and a margin of its
    /// whole travel (8 m for a 500 m/s shot) found speculative points on every triangle
    /// of a mesh along the path, whose edges held a grazing hull in place.
    fn pair_margin(&self, a: &Motion, b: &Motion) -> Real {
        if !(a.bounces || b.bounces) {
            return self.margin;
        }
        let (dt, kick) = self.step;
        let fall = kick * (a.fall - b.fall).abs();
        let closing = ((b.velocity - a.velocity).length() + fall) * dt + a.turn + b.turn;
        self.margin.max(closing.min(a.cap + b.cap))
    }

    /// What `pair_margin` and the tight-box test read of body `i`.
    fn motion(&self, i: usize) -> Motion {
        let body = &self.bodies[i];
        let moving = body.kind != BodyKind::Static && body.awake;
        let (dt, _) = self.step;
        let pose = body.pose();
        let bounces = body.restitution > 0.0;
        Motion {
            tight: body.shape.aabb(&pose),
            pose,
            velocity: if moving { body.velocity } else { Vec3::ZERO },
            turn: if moving && bounces {
                body.angular_velocity.length() * body.shape.bounding_radius() * dt
            } else {
                0.0
            },
            fall: if moving && body.kind == BodyKind::Dynamic {
                body.gravity_scale
            } else {
                0.0
            },
            cap: if moving { body.ccd_extent } else { 0.0 },
            bounces,
        }
    }
}

/// One body as the pairs of an update see it, computed once on first use.
#[derive(Debug, Clone, Copy)]
struct Motion {
    /// Its tight box at its current pose.
    tight: Aabb,
    /// Its current pose.
    pose: Pose,
    /// Its velocity (m/s), zero if it does not move.
    velocity: Vec3,
    /// How far its spin can carry a point over the step (m); zero unless it bounces.
    turn: Real,
    /// The share of gravity that moves it: its `gravity_scale`, 0 if it does not move.
    fall: Real,
    /// Its CCD extent (m), zero if it does not move.
    cap: Real,
    /// Whether it has a restitution above zero.
    bounces: bool,
}

/// Appends the contacts of the pair at body indices `(a, b)`: last step's if both are
/// frozen or their relative pose still holds them, else the narrow phase's, warm-started.
/// The bodies' motions are `known`, or computed into the scratch on first use.
fn pair_contacts(
    w: &PairWorld<'_>,
    old: &Sorted<'_>,
    (a, b): (usize, usize),
    broad: &BroadPhase,
    (scratch, known): (&mut PairScratch, Option<&[Motion]>),
    contacts: &mut Vec<Contact>,
) {
    let (body_a, body_b) = (&w.bodies[a], &w.bodies[b]);
    // A sleeping island costs nothing: between bodies that cannot have moved, last step's
    // manifolds still hold.
    if frozen(body_a) && frozen(body_b) {
        keep_previous(old, w.ids[a], w.ids[b], a, b, contacts);
        return;
    }
    // The broad phase pairs fat boxes, stretched along each body's motion: as the rain
    // lands, six pairs in seven are farther apart than the margin. Every routine reports
    // only points closer than `margin`, and a gap between the tight boxes is a lower bound
    // of the distance, so a pair whose tight boxes stand more than twice the margin apart
    // (room to spare over rounding) has no manifold, and is passed over without asking the
    // narrow phase. Nor can it have a manifold to reuse: that needs a gap under the margin
    // a few µm ago.
    let (ma, mb) = match known {
        Some(all) => (&all[a], &all[b]),
        None => {
            let motions = &mut scratch.motions;
            motions.ensure(a, w);
            motions.ensure(b, w);
            (&motions.motions[a], &motions.motions[b])
        }
    };
    let margin = w.pair_margin(ma, mb);
    if ma.tight.apart(&mb.tight, 2.0 * margin) {
        return;
    }
    let (pa, pb) = (ma.pose, mb.pose);
    let poses = (&pa, &pb);
    if reusable(&body_a.shape) && reusable(&body_b.shape) {
        if !reuse_previous(old, (a, b), w.ids, poses, w.margin, contacts) {
            scratch.collided += 1;
            let covering = (broad, &mut scratch.stack);
            collide_in_place(w, old, (a, b), poses, (margin, covering), contacts);
        }
        return;
    }
    let manifolds = &mut scratch.manifolds;
    manifolds.clear();
    scratch.collided += 1;
    collide(&body_a.shape, &pa, &body_b.shape, &pb, margin, manifolds);
    if w.statics > 1 {
        for m in manifolds.iter_mut() {
            let stack = &mut scratch.stack;
            drop_covered_points(m, (a, b), w.bodies, (broad, stack), w.margin * 0.25);
        }
        manifolds.retain(|m| !m.is_empty());
    }
    keep_deepest(manifolds, MAX_MANIFOLDS_PER_PAIR);
    push_new(manifolds, old, (a, b), w.ids, poses, contacts);
}

/// The narrow phase for a pair of convex solids (`reusable` shapes), whose one manifold is
/// made in its place: `collide`, `drop_covered_points` and `push_new` as for any pair,
/// without the scratch list. Through the list, each pair's manifold (736 bytes in f64) was
/// zeroed on the stack, copied twice on its way into the list and once more into its
/// contact: the copies were 2.7 % of the rain's instructions. Here a blank contact is
/// appended (a memset: `Contact::BLANK` is all zeros) and the narrow phase writes into it,
/// taken back if the pair does not touch (half the rain's pairs): 3.8 % fewer instructions
/// in the rain.
fn collide_in_place(
    w: &PairWorld<'_>,
    old: &Sorted<'_>,
    (a, b): (usize, usize),
    (pa, pb): (&Pose, &Pose),
    (margin, (broad, stack)): (Real, (&BroadPhase, &mut Vec<u32>)),
    contacts: &mut Vec<Contact>,
) {
    let (body_a, body_b) = (&w.bodies[a], &w.bodies[b]);
    contacts.extend_from_slice(std::slice::from_ref(&Contact::BLANK));
    let contact = contacts.last_mut().expect("just appended");
    let m = &mut contact.manifold;
    let mut touching = collide_solids(&body_a.shape, pa, &body_b.shape, pb, margin, m);
    if touching && w.statics > 1 {
        drop_covered_points(m, (a, b), w.bodies, (broad, stack), w.margin * 0.25);
        touching = !m.is_empty();
    }
    if !touching {
        contacts.pop();
        return;
    }
    // `push_new` for one manifold (`keep_deepest` keeps at least one).
    let (missed, matched) = start_new(contact, old, (a, b), w.ids, (pa, pb));
    if missed != 0 {
        let first = contacts.len() - 1;
        warm_start_across(&mut contacts[first..], (&[missed], &[matched]), old);
    }
}

/// Each body's [`Motion`], computed once per update on first use (read in place: copied
/// out per pair, as an `Option`, it cost 70 instructions a pair in the rain).
#[derive(Debug, Default)]
struct Motions {
    motions: Vec<Motion>,
    known: Vec<bool>,
}

impl Motions {
    fn clear(&mut self, bodies: usize) {
        self.known.clear();
        self.known.resize(bodies, false);
        let unknown = Motion {
            tight: Aabb {
                min: Vec3::ZERO,
                max: Vec3::ZERO,
            },
            pose: Pose::IDENTITY,
            velocity: Vec3::ZERO,
            turn: 0.0,
            fall: 0.0,
            cap: 0.0,
            bounces: false,
        };
        self.motions.resize(bodies, unknown);
    }

    fn ensure(&mut self, i: usize, w: &PairWorld<'_>) {
        if !self.known[i] {
            self.motions[i] = w.motion(i);
            self.known[i] = true;
        }
    }
}

/// Whether the pair at body indices `(a, b)` needs contacts at all: one of the two must be
/// dynamic, and bodies a joint holds together do not collide unless it says so.
fn may_collide(
    body_a: &Body,
    body_b: &Body,
    (a, b): (usize, usize),
    joined: &[(u32, u32)],
) -> bool {
    if body_a.kind != BodyKind::Dynamic && body_b.kind != BodyKind::Dynamic {
        return false;
    }
    let key = (a.min(b) as u32, a.max(b) as u32);
    joined.is_empty() || joined.binary_search(&key).is_err()
}

/// A body that cannot have moved since the last step: static, or dynamic and asleep.
fn frozen(b: &Body) -> bool {
    b.kind == BodyKind::Static || (b.kind == BodyKind::Dynamic && !b.awake)
}

/// Reuses last step's contact of the pair if their relative pose still holds it, placing it
/// at the new poses; whether it did.
fn reuse_previous(
    old: &Sorted<'_>,
    (a, b): (usize, usize),
    ids: &[BodyId],
    (pa, pb): (&Pose, &Pose),
    margin: Real,
    contacts: &mut Vec<Contact>,
) -> bool {
    // A manifold a hook took points out of is computed afresh: its basis describes the
    // whole manifold, and the hook decides again on the new one.
    let Some(c) = old.find((ids[a], ids[b], 0, 0)).filter(|c| {
        !c.edited
            && c.basis
                .holds(&Basis::relative(pa, pb), REUSE_DISTANCE * margin)
    }) else {
        return false;
    };
    // Updated in place: a contact is a kilobyte, and a copy on the stack
    // before the push doubled what this costs. Appended as a slice, not pushed: `push(*c)`
    // still copied it to the stack first (the push might grow the list, which could move
    // `*c` as far as the compiler knows), two 1 KB copies where one suffices, 0.8 % of the
    // pyramid's instructions.
    contacts.extend_from_slice(std::slice::from_ref(c));
    let contact = contacts.last_mut().expect("just appended");
    (contact.index_a, contact.index_b) = (a as u32, b as u32);
    contact.basis.place(&mut contact.manifold, pa, pb);
    // Matches each point to itself, but re-anchors the ones that slid. The old contact is
    // `c` itself: looked up again by the copy's key, the lookup waited for the copy's
    // stores (half of `warm_start`'s time in the rain).
    warm_start(contact, Some(c), (pa, pb));
    true
}

/// What makes a body crowded: how many dynamic bodies it overlaps, and is sunk into.
#[derive(Debug, Default, Clone, Copy)]
struct Degree {
    overlapping: u32,
    sunk: u32,
}

impl Degree {
    /// Overlapping `per_body` dynamic bodies, or sunk into half as many. Resting bodies
    /// overlap by the slop and sink into nothing: an equal sphere overlaps at most twelve
    /// neighbours, a box in a wall or pile fewer.
    fn crowded(&self, per_body: u32) -> bool {
        self.overlapping >= per_body || self.sunk >= per_body.div_ceil(2)
    }
}

/// Contacts per body beyond which an update counts bodies against their caps.
const ENGAGE: usize = 4;

/// Fewest pairs worth a piece of their own on another thread: the rain's narrow phase
/// takes about 0.2 µs a pair, a hand-off a few µs.
const PAIRS_A_PIECE: usize = 256;

/// Bodies whose motions a piece computes (a motion is a few dozen flops).
const MOTIONS_A_PIECE: usize = 1024;

/// The broad phase's caps for `limits` and the contact margin (m).
/// Moves every piece's contacts, in piece order, into `into` (emptied first), each piece
/// to its own place on the step's team. Appended one piece after another, the rain's
/// 4,000 kilobyte-sized contacts took 0.44 ms of its 7.6 ms step on two threads, all on
/// one of them.
fn concat_pieces(into: &mut Vec<Contact>, pieces: &mut [(PairScratch, Vec<Contact>)], par: Par) {
    let total: usize = pieces.iter().map(|(_, out)| out.len()).sum();
    into.clear();
    into.reserve(total);
    let mut room = &mut into.spare_capacity_mut()[..total];
    let mut moves: Vec<(&mut [MaybeUninit<Contact>], &mut Vec<Contact>)> =
        Vec::with_capacity(pieces.len());
    for (_, out) in pieces.iter_mut() {
        let (mine, rest) = std::mem::take(&mut room).split_at_mut(out.len());
        moves.push((mine, out));
        room = rest;
    }
    crate::team::chunks(par.threads, &mut moves, 1, &|_, part| {
        for (room, out) in part.iter_mut() {
            for (slot, c) in room.iter_mut().zip(out.drain(..)) {
                slot.write(c);
            }
        }
    });
    // SAFETY: the rooms split the first `total` slots of the buffer (`total` ≤ its
    // capacity, reserved above) with no gap, each as long as its piece's list when it was
    // split off, and every piece was drained whole into its room (equal lengths: `zip`
    // stops at neither side early), so all `total` slots hold a contact written above. If
    // a piece panicked, the panic passes through `chunks` before this line: the contacts
    // already moved leak, and the list stays empty.
    unsafe { into.set_len(total) };
}

fn crowding(limits: &ContactLimits, margin: Real) -> Crowding {
    Crowding {
        sunk: limits
            .per_body
            .saturating_mul(ContactLimits::CANDIDATES_PER_CONTACT),
        any: limits.per_body.saturating_mul(16),
        depth: margin,
    }
}

/// How deep two bodies must interpenetrate to count as sunk into each other: the margin,
/// or a quarter of the thinner body's thickness where that is less. The same measure as
/// `Aabb::sunk_into`'s, from the bodies' sizes rather than their boxes'; resting contacts
/// sink by about the slop (5 mm), below it for any body thicker than 2 cm.
fn deep(a: &Body, b: &Body, margin: Real) -> Real {
    margin.min(a.quarter_thickness().min(b.quarter_thickness()))
}

/// Whether a contact has a point deeper than `depth`.
fn sunk_deeper(c: &Contact, depth: Real) -> bool {
    c.manifold.points().iter().any(|p| p.separation < -depth)
}

/// Keeps the `n` deepest manifolds (smallest least separation; ties by position), in their
/// order, when there are more.
fn keep_deepest(manifolds: &mut Vec<Manifold>, n: usize) {
    if manifolds.len() <= n {
        return;
    }
    let depth = |m: &Manifold| {
        let seps = m.points().iter().map(|p| p.separation);
        seps.fold(Real::INFINITY, Real::min)
    };
    let mut order: Vec<(Real, usize)> = manifolds.iter().map(depth).zip(0..).collect();
    order.sort_by(|x, y| x.0.total_cmp(&y.0).then(x.1.cmp(&y.1)));
    let mut keep = vec![false; manifolds.len()];
    for &(_, i) in &order[..n] {
        keep[i] = true;
    }
    let mut i = 0;
    manifolds.retain(|_| {
        i += 1;
        keep[i - 1]
    });
}

/// Makes `contact`, a blank (`Contact::BLANK`) holding a fresh manifold of bodies `a`
/// and `b`, a new contact of theirs, warm-started from last step's; returns its
/// unmatched and used points as `warm_start` does.
fn start_new(
    contact: &mut Contact,
    old: &Sorted<'_>,
    (a, b): (usize, usize),
    ids: &[BodyId],
    (pa, pb): (&Pose, &Pose),
) -> (u32, u32) {
    (contact.body_a, contact.body_b) = (ids[a], ids[b]);
    (contact.index_a, contact.index_b) = (a as u32, b as u32);
    contact.basis = Basis::of(&contact.manifold, pa, pb);
    contact.new = true;
    let before = old.find(contact.key());
    warm_start(contact, before, (pa, pb))
}

/// Pushes a contact for each of the pair's freshly computed manifolds, warm-started from
/// last step's.
fn push_new(
    manifolds: &[Manifold],
    old: &Sorted<'_>,
    (a, b): (usize, usize),
    ids: &[BodyId],
    (pa, pb): (&Pose, &Pose),
    contacts: &mut Vec<Contact>,
) {
    let first = contacts.len();
    // The first manifolds' unmatched points (a body resting across a mesh's triangles
    // touches a few); the rest keep `warm_start`'s matches alone.
    let (mut unmatched, mut used) = ([0u32; 16], [0u32; 16]);
    let mut any = false;
    for manifold in manifolds {
        contacts.push(Contact {
            manifold: *manifold,
            ..Contact::BLANK
        });
        let k = contacts.len() - 1 - first;
        let contact = contacts.last_mut().expect("just pushed");
        let (missed, matched) = start_new(contact, old, (a, b), ids, (pa, pb));
        if let (Some(m), Some(u)) = (unmatched.get_mut(k), used.get_mut(k)) {
            (*m, *u) = (missed, matched);
            any |= missed != 0;
        }
    }
    if any {
        warm_start_across(&mut contacts[first..], (&unmatched, &used), old);
    }
}

/// Warm starts the points of the pair's contacts that `warm_start` matched to nothing
/// (`unmatched`, per contact) from the pair's last contacts on other sub-shapes (a mesh's
/// triangles, a height field's cells, a compound's children) with the same normal, by
/// place as `warm_start` matches: nearest pairs of points first, within
/// `MATCH_DISTANCE`, each old point given to one new point only. A body crossing from one
/// triangle to the next keeps its impulses and friction anchors; started from zero, the
/// soft contact gave way for a step at each crossing (a 0.35 m cylinder rolling over a
/// height field's cell edges sank and rose at 2.7 mm/s each time, at dt 1/60 s).
fn warm_start_across(
    contacts: &mut [Contact],
    (unmatched, used): (&[u32], &[u32]),
    old: &Sorted<'_>,
) {
    let Some(c0) = contacts.first() else {
        return;
    };
    let mid = |p: &ContactPoint| (p.point_a + p.point_b) * 0.5;
    let olds: Vec<&Contact> = old.pair(c0.body_a, c0.body_b).collect();
    // (distance², new contact, its point, old contact, its point)
    let mut near = Vec::new();
    for (i, (c, &missed)) in contacts
        .iter()
        .zip(unmatched)
        .enumerate()
        .filter(|(_, (_, &m))| m != 0)
    {
        let n = c.manifold.normal;
        let points = c.manifold.points().iter().enumerate();
        for (j, p) in points.filter(|&(j, _)| missed & (1 << j) != 0) {
            for (k, o) in olds.iter().enumerate() {
                if o.key() == c.key() || o.manifold.normal.dot(n) < 1.0 - SAME_NORMAL {
                    continue;
                }
                for (l, q) in o.manifold.points().iter().enumerate() {
                    let d2 = (mid(q) - mid(p)).length_squared();
                    if d2 < MATCH_DISTANCE * MATCH_DISTANCE {
                        near.push((d2, i, j, k, l));
                    }
                }
            }
        }
    }
    near.sort_by(|x, y| x.0.total_cmp(&y.0));
    // The old points `warm_start` gave to their own key's new points are taken already:
    // handed on again, one old impulse would push twice.
    let mut taken = Vec::new();
    for (c, &bits) in contacts.iter().zip(used).filter(|(_, &b)| b != 0) {
        if let Some(k) = olds.iter().position(|o| o.key() == c.key()) {
            let points = 0..olds[k].manifold.len();
            taken.extend(points.filter(|l| bits & (1 << l) != 0).map(|l| (k, l)));
        }
    }
    let mut given = Vec::new();
    for (_, i, j, k, l) in near {
        // Impulses are per substep of the length their contact was solved at (`fine`,
        // see `solver/stacks.rs`): a contact takes them from contacts solved as it was, or,
        // new by its key, as the first it takes from was.
        let (o, c) = (&olds[k].manifold, &contacts[i]);
        let first_of_new = c.new && !given.iter().any(|&(g, _)| g == i);
        let same_rate = o.fine.max(1) == c.manifold.fine.max(1);
        if given.contains(&(i, j)) || taken.contains(&(k, l)) || !(first_of_new || same_rate) {
            continue;
        }
        given.push((i, j));
        taken.push((k, l));
        let c = &mut contacts[i].manifold;
        let q = &o.points()[l];
        c.fine = o.fine;
        let p = &mut c.points_mut()[j];
        p.normal_impulse = q.normal_impulse;
        p.tangent_impulse = q.tangent_impulse;
        if q.anchored && !q.sliding {
            (p.anchor_a, p.anchor_b) = (q.anchor_a, q.anchor_b);
        }
    }
}

/// Two contact normals whose dot product is at least 1 − this are the same direction:
/// their tangent bases (made from the normal alone) agree, and so do their impulses.
const SAME_NORMAL: Real = 1e-9;

impl ContactCache {
    /// The contacts found by the last update, ordered by body pair.
    pub fn contacts(&self) -> &[Contact] {
        &self.contacts
    }

    /// Recomputes every contact from the broad phase's pairs. Pairs in which neither body
    /// is dynamic are skipped: nothing could respond to them. So is a pair of two crowded
    /// dynamic bodies, each already overlapping `limits.per_body` others or sunk into half
    /// as many (see `ContactLimits`); and the update stops, with
    /// [`ContactCache::overflowed`] set, on reaching `limits.per_step` manifolds.
    /// `filter` takes out the pairs the contact filter refuses (see `pipeline/hooks.rs`).
    /// The events are found by [`ContactCache::find_events`], once the hooks have acted.
    pub(crate) fn update<F: FnOnce(&mut Vec<(u32, u32)>)>(
        &mut self,
        broad: &mut BroadPhase,
        bodies: &[Body],
        ids: &[BodyId],
        (margin, step): (Real, (Real, Real)),
        (joined, filter): (&[(u32, u32)], F),
        (limits, par): (&ContactLimits, Par),
    ) {
        broad.set_crowding(crowding(limits, margin));
        broad.pairs(&mut self.pairs);
        filter(&mut self.pairs);
        let statics = bodies.iter().filter(|b| b.kind == BodyKind::Static).count();
        std::mem::swap(&mut self.contacts, &mut self.previous);
        self.index_previous();
        (self.crowded, self.overflowed) = (0, false);
        let world = PairWorld {
            bodies,
            ids,
            margin,
            step,
            statics,
        };
        // Split by the narrow phase's work in the last update: kept and reused pairs are
        // copies, which two threads only contend for (the settled pyramid, 1,500 pairs
        // nearly all reused, took 15 % longer a step split in two).
        let parallel = par.pieces(self.collided, PAIRS_A_PIECE) > 1
            && self.update_in_pieces(&world, broad, joined, (limits, par));
        if !parallel {
            self.update_in_order(&world, broad, joined, limits);
        }
    }

    /// The pairs one after another, counting each body's overlaps for the crowding caps
    /// and stopping at the step's limit.
    fn update_in_order(
        &mut self,
        world: &PairWorld<'_>,
        broad: &BroadPhase,
        joined: &[(u32, u32)],
        limits: &ContactLimits,
    ) {
        let bodies = world.bodies;
        let margin = world.margin;
        self.contacts.clear();
        self.scratch.motions.clear(bodies.len());
        self.degree.clear();
        self.degree.resize(bodies.len(), Degree::default());
        let old = Sorted::of(&self.previous, &self.order, &self.keys);
        self.scratch.collided = 0;
        let (per_body, per_step) = (limits.per_body, limits.per_step as usize);
        for &(a, b) in &self.pairs {
            let (a, b) = (a as usize, b as usize);
            let (Some(body_a), Some(body_b)) = (bodies.get(a), bodies.get(b)) else {
                continue;
            };
            if !may_collide(body_a, body_b, (a, b), joined) {
                continue;
            }
            // Bodies are counted once the update holds more than `ENGAGE` contacts per
            // body, which no scene without crowds reaches: a step then pays one comparison
            // per pair for the caps, and at most `ENGAGE` per body escape the count.
            // Pairs with a static or kinematic body are never shed: a ground under a
            // crowd must hold all of it, and there are at most bodies × statics of them.
            let counting = self.contacts.len() >= ENGAGE * bodies.len()
                && body_a.kind == BodyKind::Dynamic
                && body_b.kind == BodyKind::Dynamic;
            let crowded = |d: &Degree| d.crowded(per_body);
            if counting && crowded(&self.degree[a]) && crowded(&self.degree[b]) {
                self.crowded += 1;
                continue;
            }
            let before = self.contacts.len();
            let scratch = &mut self.scratch;
            pair_contacts(
                world,
                &old,
                (a, b),
                broad,
                (scratch, None),
                &mut self.contacts,
            );
            if counting {
                let depth = deep(body_a, body_b, margin);
                let new = &self.contacts[before..];
                let overlaps = new.iter().any(|c| sunk_deeper(c, 0.0));
                let sunk = overlaps && new.iter().any(|c| sunk_deeper(c, depth));
                for i in [a, b] {
                    self.degree[i].overlapping += overlaps as u32;
                    self.degree[i].sunk += sunk as u32;
                }
            }
            if self.contacts.len() > per_step {
                self.contacts.truncate(per_step);
                self.overflowed = true;
                break;
            }
        }
        self.collided = self.scratch.collided;
    }

    /// The pairs in consecutive pieces on the step's threads, each into its own list,
    /// joined in pair order: the same contacts as [`Self::update_in_order`] as long as
    /// neither the crowding count (which starts past `ENGAGE` contacts a body) nor the
    /// step's limit comes into play, which is checked on the total; `false` (nothing
    /// kept) if either would have, and the pairs are then taken in order.
    fn update_in_pieces(
        &mut self,
        world: &PairWorld<'_>,
        broad: &BroadPhase,
        joined: &[(u32, u32)],
        (limits, par): (&ContactLimits, Par),
    ) -> bool {
        let count = par.pieces(self.pairs.len(), PAIRS_A_PIECE);
        let size = self.pairs.len().div_ceil(count);
        let mut pieces = std::mem::take(&mut self.pieces);
        pieces.resize_with(count, Default::default);
        // Every body's motion once, read by all pieces (each computing its own cost 5 %
        // of the rain's landing on two threads).
        let mut motions = std::mem::take(&mut self.motions);
        motions.clear();
        if let Some(first) = (!world.bodies.is_empty()).then(|| world.motion(0)) {
            motions.resize(world.bodies.len(), first);
        }
        crate::team::chunks(
            par.threads,
            &mut motions,
            MOTIONS_A_PIECE,
            &|start, part| {
                for (k, m) in part.iter_mut().enumerate() {
                    *m = world.motion(start + k);
                }
            },
        );
        let known = Some(&motions[..]);
        let (previous, order, keys, pairs) = (&self.previous, &self.order, &self.keys, &self.pairs);
        crate::team::chunks(par.threads, &mut pieces, 1, &|i, piece| {
            let (scratch, out) = &mut piece[0];
            let old = Sorted::of(previous, order, keys);
            out.clear();
            scratch.collided = 0;
            let mine = &pairs[(i * size).min(pairs.len())..((i + 1) * size).min(pairs.len())];
            for &(a, b) in mine {
                let (a, b) = (a as usize, b as usize);
                let (Some(body_a), Some(body_b)) = (world.bodies.get(a), world.bodies.get(b))
                else {
                    continue;
                };
                if may_collide(body_a, body_b, (a, b), joined) {
                    pair_contacts(world, &old, (a, b), broad, (scratch, known), out);
                }
            }
        });
        let total: usize = pieces.iter().map(|(_, out)| out.len()).sum();
        self.collided = pieces.iter().map(|(s, _)| s.collided).sum();
        let fits = total < ENGAGE * world.bodies.len() && total <= limits.per_step as usize;
        if fits {
            concat_pieces(&mut self.contacts, &mut pieces, par);
        }
        self.pieces = pieces;
        self.motions = motions;
        fits
    }

    /// Pairs the last update left out because both bodies had reached
    /// `ContactLimits::per_body` touching pairs.
    pub fn crowded(&self) -> usize {
        self.crowded
    }

    /// Whether the last update stopped at `ContactLimits::per_step` manifolds (the step
    /// that ran it is then undone).
    pub fn overflowed(&self) -> bool {
        self.overflowed
    }

    /// Sorts `previous` by key into `order` and `keys`. Keys are read once, in list order,
    /// and sorted with their indices: a sort that fetched each key from its kilobyte-sized
    /// contact missed the cache per comparison.
    fn index_previous(&mut self) {
        self.keyed.clear();
        self.keyed
            .extend(self.previous.iter().zip(0..).map(|(c, i)| (c.key(), i)));
        // Stable, as the sort of indices it replaces was.
        self.keyed.sort_by_key(|&(key, _)| key);
        self.order.clear();
        self.order.extend(self.keyed.iter().map(|&(_, i)| i));
        self.keys.clear();
        self.keys.extend(self.keyed.iter().map(|&(key, _)| key));
    }

    /// Begin and end events since the previous update, by body pair.
    pub fn events(&self) -> &[ContactEvent] {
        &self.events
    }

    /// Finds the begin and end events of the last update: the pairs with points now and
    /// not before, and the other way round.
    pub(crate) fn find_events(&mut self) {
        std::mem::swap(&mut self.touching, &mut self.touching_before);
        self.touching.clear();
        self.touching.extend(
            self.contacts
                .iter()
                .filter(|c| !c.manifold.is_empty())
                .map(|c| (c.body_a, c.body_b)),
        );
        self.touching.sort();
        self.touching.dedup();
        let (now, before) = (&self.touching, &self.touching_before);
        std::mem::swap(&mut self.events, &mut self.events_before);
        self.events.clear();
        // Both lists are sorted: one merge-like walk per direction finds what is missing
        // from the other, where a binary search per pair was a third of the update's time.
        self.events
            .extend(missing(now, before, ContactEventKind::Begin));
        self.events
            .extend(missing(before, now, ContactEventKind::End));
    }

    /// Returns the cache to its state before the last [`ContactCache::update`]: the update
    /// read last step's contacts, touching pairs and events and built new ones beside
    /// them, so three swaps undo it (what the swaps bring back in place of the old lists
    /// is scratch the next update overwrites).
    pub(crate) fn undo_update(&mut self) {
        std::mem::swap(&mut self.contacts, &mut self.previous);
        std::mem::swap(&mut self.touching, &mut self.touching_before);
        std::mem::swap(&mut self.events, &mut self.events_before);
    }

    /// The contacts, for the solver to store impulses in.
    pub fn contacts_mut(&mut self) -> &mut [Contact] {
        &mut self.contacts
    }

    /// Forgets every contact of a removed body that stood at dense index `index`, and
    /// renumbers the bodies after it.
    pub fn forget(&mut self, id: BodyId, index: usize) {
        for c in self
            .contacts
            .iter()
            .filter(|c| (c.body_a == id || c.body_b == id) && !c.manifold.is_empty())
        {
            let event = ContactEvent {
                kind: ContactEventKind::End,
                body_a: c.body_a,
                body_b: c.body_b,
            };
            if !self.events.contains(&event) {
                self.events.push(event);
            }
        }
        self.contacts.retain(|c| c.body_a != id && c.body_b != id);
        self.touching.retain(|&(a, b)| a != id && b != id);
        let shift = |i: &mut u32| {
            if *i as usize > index {
                *i -= 1;
            }
        };
        for c in &mut self.contacts {
            shift(&mut c.index_a);
            shift(&mut c.index_b);
        }
        self.previous.clear();
    }
}

/// Removes the points of a contact with a static body that press on a face another static
/// body covers. A floor of adjoining boxes has inner side faces that nothing can reach
/// without first passing through the neighbour; a body sliding over a seam would otherwise
/// meet the next box's side face (its separating axis wins while the gap is open) and catch.
/// The test: step `nudge` from the point on the static surface along its outward normal;
/// landing inside (or within a tenth of `nudge` of) another static body means the face is
/// covered there. Static bodies the moving body does not collide with (its filter) cover
/// nothing.
fn drop_covered_points(
    m: &mut Manifold,
    (a, b): (usize, usize),
    bodies: &[Body],
    (broad, stack): (&BroadPhase, &mut Vec<u32>),
    nudge: Real,
) {
    let (sa, sb) = (
        bodies[a].kind == BodyKind::Static,
        bodies[b].kind == BodyKind::Static,
    );
    if sa == sb {
        return;
    }
    // Outward from the static body: +n if it is A (the normal points from A to B).
    let (fixed, out) = if sa { (a, m.normal) } else { (b, -m.normal) };
    // Only a body the moving one collides with covers a face: a floor under a ground
    // whose layer the body's mask leaves out must still hold it.
    let filter = bodies[if sa { b } else { a }].filter;
    let mut covered = |surface: Vec3| {
        let probe = surface + out * nudge;
        let mut inside = false;
        // Static bodies have static proxies only.
        broad.query_static_aabb_with(&Aabb::new(probe, probe), stack, |user| {
            let k = user as usize;
            if !inside && k != fixed {
                let covers =
                    |o: &&Body| o.kind == BodyKind::Static && !o.sensor && o.filter.allows(&filter);
                if let Some(other) = bodies.get(k).filter(covers) {
                    // Within a tenth of the step of the other body counts: the normal can be
                    // tilted by a hair and lift the probe off a face level with this one.
                    inside =
                        crate::collision::query::project_point(&other.shape, &other.pose(), probe)
                            .is_some_and(|p| p.distance <= 0.1 * nudge);
                }
            }
        });
        inside
    };
    m.retain(|p| !covered(if sa { p.point_a } else { p.point_b }));
}

/// Last step's contacts, searchable by key.
struct Sorted<'a> {
    list: &'a [Contact],
    order: &'a [u32],
    keys: &'a [Key],
    /// Where the last `find` ended (see [`Sorted::first_not_below`]).
    hint: std::cell::Cell<usize>,
}

impl<'a> Sorted<'a> {
    fn of(list: &'a [Contact], order: &'a [u32], keys: &'a [Key]) -> Sorted<'a> {
        Sorted {
            list,
            order,
            keys,
            hint: std::cell::Cell::new(0),
        }
    }

    fn at(&self, k: usize) -> &Contact {
        &self.list[self.order[k] as usize]
    }

    /// The contact with exactly this key.
    fn find(&self, key: Key) -> Option<&Contact> {
        let k = self.first_not_below(key);
        self.hint.set(k);
        (self.keys.get(k) == Some(&key)).then(|| self.at(k))
    }

    /// The first position whose key is not below `key` (a partition point). Lookups come
    /// in key order (the broad phase lists pairs sorted, and contacts were made in that
    /// order), so it is usually a few steps on from the last one's; a binary search
    /// otherwise.
    fn first_not_below(&self, key: Key) -> usize {
        let keys = self.keys;
        let mut k = self.hint.get().min(keys.len());
        if k == 0 || keys[k - 1] < key {
            for _ in 0..8 {
                if k == keys.len() || keys[k] >= key {
                    return k;
                }
                k += 1;
            }
        }
        keys.partition_point(|&x| x < key)
    }

    /// Every contact between the two bodies, in key order.
    fn pair(&self, a: BodyId, b: BodyId) -> impl Iterator<Item = &Contact> {
        let k = self.keys.partition_point(|x| (x.0, x.1) < (a, b));
        (k..self.order.len())
            .map(|k| self.at(k))
            .take_while(move |c| (c.body_a, c.body_b) == (a, b))
    }
}

/// The pairs of sorted `list` absent from sorted `other`, as events of `kind`.
fn missing<'a>(
    list: &'a [(BodyId, BodyId)],
    other: &'a [(BodyId, BodyId)],
    kind: ContactEventKind,
) -> impl Iterator<Item = ContactEvent> + 'a {
    let mut k = 0;
    list.iter().filter_map(move |&pair| {
        while other.get(k).is_some_and(|&p| p < pair) {
            k += 1;
        }
        (other.get(k) != Some(&pair)).then_some(ContactEvent {
            kind,
            body_a: pair.0,
            body_b: pair.1,
        })
    })
}

/// Carries the previous contacts of the pair (a, b) over unchanged.
fn keep_previous(
    previous: &Sorted<'_>,
    id_a: BodyId,
    id_b: BodyId,
    a: usize,
    b: usize,
    out: &mut Vec<Contact>,
) {
    for c in previous.pair(id_a, id_b) {
        // Appended as a slice and then updated, for `reuse_previous`'s reason: one copy.
        out.extend_from_slice(std::slice::from_ref(c));
        let kept = out.last_mut().expect("just appended");
        (kept.index_a, kept.index_b, kept.new) = (a as u32, b as u32, false);
    }
}

/// Copies last step's impulses onto this step's points from `previous`, last step's
/// contact of the same key if there was one: by feature id, or, for a point
/// whose features were renamed (a pair routine may pick the other box's face as reference
/// from one step to the next), by proximity — the old point within `MATCH_DISTANCE` of it.
/// Losing warm starts on a resting stack would restart its solution from zero each time.
/// Returns the new points matched to none and the old points matched (bit j for point j).
fn warm_start(
    contact: &mut Contact,
    previous: Option<&Contact>,
    poses: (&Pose, &Pose),
) -> (u32, u32) {
    let anchor_here = |p: &mut crate::collision::narrow_phase::ContactPoint| {
        let mid = (p.point_a + p.point_b) * 0.5;
        p.anchor_a = poses.0.inverse_transform_point(mid);
        p.anchor_b = poses.1.inverse_transform_point(mid);
        p.anchored = true;
    };
    let Some(old) = previous else {
        contact
            .manifold
            .points_mut()
            .iter_mut()
            .for_each(anchor_here);
        return ((1 << contact.manifold.len()) - 1, 0);
    };
    (contact.new, contact.gate) = (false, old.gate);
    let old = &old.manifold;
    contact.manifold.angular_impulse = old.angular_impulse;
    contact.manifold.overlap = old.overlap;
    contact.manifold.fine = old.fine;
    let mid = |a: Vec3, b: Vec3| (a + b) * 0.5;
    let (mut unmatched, mut used) = (0, 0);
    for (j, p) in contact.manifold.points_mut().iter_mut().enumerate() {
        let here = mid(p.point_a, p.point_b);
        let olds = old.points().iter().enumerate();
        let by_feature = olds.clone().find(|(_, q)| q.feature == p.feature);
        let by_place = || {
            olds.map(|(l, q)| (l, q, (mid(q.point_a, q.point_b) - here).length_squared()))
                .filter(|&(_, _, d2)| d2 < MATCH_DISTANCE * MATCH_DISTANCE)
                .min_by(|x, y| x.2.total_cmp(&y.2))
                .map(|(l, q, _)| (l, q))
        };
        match by_feature.or_else(by_place) {
            Some((l, q)) => {
                used |= 1 << l;
                p.normal_impulse = q.normal_impulse;
                p.tangent_impulse = q.tangent_impulse;
                if q.anchored && !q.sliding {
                    (p.anchor_a, p.anchor_b, p.anchored) = (q.anchor_a, q.anchor_b, true);
                } else {
                    anchor_here(p);
                }
            }
            None => {
                anchor_here(p);
                unmatched |= 1 << j;
            }
        }
    }
    (unmatched, used)
}

// `warm_start`'s bit per point.
const _: () = assert!(crate::collision::narrow_phase::MAX_MANIFOLD_POINTS < 32);

/// How close an unnamed point must be to last step's to inherit its impulses (m).
const MATCH_DISTANCE: Real = 0.01;

impl ContactCache {
    /// Checks a cache read from a snapshot against the bodies' handles `ids`: each
    /// contact's dense indices in range, in order (the broad phase pairs them lower first)
    /// and naming its bodies' handles, and its manifold's point count within the array.
    /// Everything else the cache holds is rebuilt by the next update before it is read.
    pub(crate) fn check_saved(&self, ids: &[BodyId]) -> crate::codec::Decoded<()> {
        use crate::codec::{check_index, ensure};
        for (k, c) in self.contacts.iter().enumerate() {
            let field = || format!("contacts[{k}].index_b");
            check_index(c.index_b, ids.len(), (field, "body"))?;
            ensure(c.index_a < c.index_b, || {
                format!("contacts[{k}]: bodies {} and {}", c.index_a, c.index_b)
            })?;
            let named = (ids[c.index_a as usize], ids[c.index_b as usize]);
            ensure(named == (c.body_a, c.body_b), || {
                format!(
                    "contacts[{k}]: handles not those of bodies {} and {}",
                    c.index_a, c.index_b
                )
            })?;
            ensure(c.manifold.count_fits(), || {
                format!("contacts[{k}].manifold: {} points", c.manifold.len())
            })?;
        }
        Ok(())
    }
}

// Between steps a cache is its contacts, touching pairs and events (and the counts the
// next update reads); `previous` and the `_before` lists are overwritten by the next
// update before anything reads them, and the rest is scratch.
crate::codec::codec_struct!(ContactCache {
    contacts, touching, events, crowded, overflowed, collided;
    previous, order, keys, keyed, events_before, pairs, touching_before, scratch, degree,
    pieces, motions
});
