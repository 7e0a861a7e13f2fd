//! Contact hooks: the pair filter and the contact modifier a user sets on the world
//! (`World::set_contact_filter`, `World::set_contact_modifier`), and one-way bodies, which
//! the step builds on the same place in the pipeline.
//!
//! ```text
//! broad phase pairs -> filter (new pairs only) -> narrow phase -> one-way gates ->
//!     modifier (each touching manifold, in pair order) -> events -> solver
//! ```
//!
//! The filter is asked once about each pair when the broad phase first finds it (its boxes
//! came to overlap): `false` and the pair has no contact at all, CCD included, until its
//! boxes part and meet again. The verdicts are kept by body ids, in a sorted list.
//!
//! The modifier is called at every contact update (each step runs one) for every manifold
//! with points whose bodies are not both asleep or static, in the contacts' order (by body
//! pair), so a run is deterministic. It may change the pair's friction, restitution and
//! surface velocity for the step, and drop points; a manifold left without points does
//! not touch: no events, no solver, and CCD lets the pair pass.
//!
//! A one-way body (`BodyDef::one_way`, normal n) keeps a manifold only when the other body
//! comes at it from n's side: the manifold's normal from the one-way body to the other is
//! within 60° of n, and the other body's point of contact does not move away along n
//! faster than `speed` (the world's sleep speed) now or after the step's gravity (a body
//! at the top of its jump is about to come down). The decision is taken when the manifold
//! begins and kept while it persists, so a body passing up through a platform is not
//! snapped onto it mid-way; a manifold passed through is decided again whenever its
//! points are all apart (separation > 0), so a body that came up through and now sits
//! above lands. A kept manifold stays kept: a body resting on the platform never drops
//! through. From the side (a normal more than 60° off n) a body passes through.

pub use crate::collision::contact::ContactMaterial;
use crate::collision::contact::{Contact, Gate};
use crate::collision::narrow_phase::{ContactPoint, Manifold};
use crate::dynamics::body::{check_friction, check_restitution, Body, BodyKind};
use crate::error::{check, Result};
use crate::id::BodyId;
use crate::math::{Real, Vec3};

/// Two bodies the broad phase found near each other, as the contact filter sees them;
/// body a is the one created first.
pub struct ContactPair<'a> {
    /// The first body's handle.
    pub body_a: BodyId,
    /// The first body.
    pub a: &'a Body,
    /// The second body's handle.
    pub body_b: BodyId,
    /// The second body.
    pub b: &'a Body,
}

/// The contact filter: `false` means the pair has no contact at all.
pub type ContactFilter = Box<dyn FnMut(&ContactPair<'_>) -> bool + Send>;

/// The contact modifier, called once per step per touching manifold before the solver.
pub type ContactModifier = Box<dyn FnMut(&mut ContactModification<'_>) + Send>;

/// The pair's material by the bodies' own coefficients.
pub(crate) fn material_of(a: &Body, b: &Body) -> ContactMaterial {
    ContactMaterial {
        friction: (a.friction * b.friction).sqrt(),
        restitution: a.restitution.max(b.restitution),
        surface_velocity: Vec3::ZERO,
    }
}

/// One touching manifold as the contact modifier sees it, and what it may change. Every
/// setter checks its value as `BodyDef`'s field of the same name is checked, and changes
/// nothing when it fails.
pub struct ContactModification<'a> {
    /// The first body's handle (created first); the normal points away from it.
    pub body_a: BodyId,
    /// The first body.
    pub a: &'a Body,
    /// The second body's handle.
    pub body_b: BodyId,
    /// The second body.
    pub b: &'a Body,
    manifold: &'a mut Manifold,
    material: &'a mut ContactMaterial,
    new: bool,
    max_speed: Real,
}

impl ContactModification<'_> {
    /// The manifold's unit normal, world frame, from body a to body b.
    pub fn normal(&self) -> Vec3 {
        self.manifold.normal
    }

    /// The points left.
    pub fn points(&self) -> &[ContactPoint] {
        self.manifold.points()
    }

    /// The compound child or triangle index on each body (0 for simple shapes).
    pub fn subshapes(&self) -> (u32, u32) {
        (self.manifold.subshape_a, self.manifold.subshape_b)
    }

    /// Whether the manifold began at this update (there was none with the same bodies and
    /// sub-shapes at the one before).
    pub fn is_new(&self) -> bool {
        self.new
    }

    /// The material the solver will use, as changed so far.
    pub fn material(&self) -> ContactMaterial {
        *self.material
    }

    /// Sets the friction coefficient for this step (>= 0).
    pub fn set_friction(&mut self, friction: Real) -> Result<()> {
        check_friction(friction)?;
        self.material.friction = friction;
        Ok(())
    }

    /// Sets the coefficient of restitution for this step (in [0, 1]).
    pub fn set_restitution(&mut self, restitution: Real) -> Result<()> {
        check_restitution(restitution)?;
        self.material.restitution = restitution;
        Ok(())
    }

    /// Sets the surface velocity for this step (m/s, see
    /// [`ContactMaterial::surface_velocity`]): finite and within the world's
    /// `max_speed`. A manifold with one has no friction anchors (they would pull the
    /// bodies back against the belt): its friction acts on velocities alone.
    pub fn set_surface_velocity(&mut self, velocity: Vec3) -> Result<()> {
        check::length_at_most(
            "surface_velocity",
            velocity,
            self.max_speed,
            "m/s (max_speed)",
        )?;
        self.material.surface_velocity = velocity;
        Ok(())
    }

    /// Keeps only the points for which `keep` is true.
    pub fn retain_points(&mut self, keep: impl FnMut(&ContactPoint) -> bool) {
        self.manifold.retain(keep);
    }

    /// Drops every point: the pair does not touch this step.
    pub fn disable(&mut self) {
        self.manifold.clear();
    }
}

/// Verdicts of the contact filter on body pairs, sorted by the pair's ids, with a list
/// being built beside them for the update under way.
#[derive(Default)]
struct Verdicts {
    list: Vec<((BodyId, BodyId), bool)>,
    next: Vec<((BodyId, BodyId), bool)>,
}

impl Verdicts {
    /// The kept verdict on `key`, if any.
    fn find(&self, key: (BodyId, BodyId)) -> Option<bool> {
        let k = self.list.binary_search_by_key(&key, |&(k, _)| k).ok()?;
        Some(self.list[k].1)
    }

    /// The verdicts of this update become the kept ones.
    fn finish(&mut self) {
        self.next.sort_unstable_by_key(|&(k, _)| k);
        std::mem::swap(&mut self.list, &mut self.next);
        self.next.clear();
    }
}

/// The rule of one-way bodies at one contact update.
#[derive(Debug, Clone, Copy)]
pub(crate) struct OneWayRule {
    /// What gravity adds to a falling body's velocity over the coming step (m/s), per unit
    /// of gravity scale; zero outside a step.
    pub kick: Vec3,
    /// Fastest the other body may move away along the normal and still be held (m/s).
    pub speed: Real,
}

/// The least cosine between a one-way body's normal and a manifold's normal towards the
/// other body that keeps the manifold: within 60°.
pub(crate) const ONE_WAY_COS: Real = 0.5;

/// The hooks and what they hand to the rest of the step.
#[derive(Default)]
pub(crate) struct Hooks {
    filter: Option<ContactFilter>,
    /// The filter's verdicts on the contact pairs and on the sensor pairs.
    verdicts: Verdicts,
    sensor_verdicts: Verdicts,
    modifier: Option<ContactModifier>,
    /// How many bodies are one-way: none, and the gates cost nothing.
    pub one_way_bodies: usize,
    /// Per contact of the last update, the material the modifier left (empty without a
    /// modifier: the solver then takes the bodies' own).
    pub materials: Vec<ContactMaterial>,
    /// The dense body pairs a hook took every point of at the last update, sorted: CCD
    /// lets them pass as the solver does.
    pub passing: Vec<(u32, u32)>,
}

impl Hooks {
    /// Whether a contact filter or modifier (code, which snapshots do not keep) is set.
    pub fn has_code(&self) -> bool {
        self.filter.is_some() || self.modifier.is_some()
    }

    pub fn set_filter(&mut self, filter: Option<ContactFilter>) {
        self.filter = filter;
        self.verdicts = Verdicts::default();
        self.sensor_verdicts = Verdicts::default();
    }

    pub fn set_modifier(&mut self, modifier: Option<ContactModifier>) {
        self.modifier = modifier;
    }

    /// Takes out of `pairs` (dense, each sorted, the list sorted) those the filter refuses,
    /// asking it about the pairs it has not judged while they stayed candidates.
    pub fn filter_pairs(&mut self, pairs: &mut Vec<(u32, u32)>, bodies: &[Body], ids: &[BodyId]) {
        let Some(filter) = self.filter.as_mut() else {
            return;
        };
        let verdicts = &mut self.verdicts;
        pairs.retain(|&(a, b)| {
            let (a, b) = (a as usize, b as usize);
            let key = (ids[a], ids[b]);
            let keep = verdicts.find(key).unwrap_or_else(|| {
                filter(&ContactPair {
                    body_a: ids[a],
                    a: &bodies[a],
                    body_b: ids[b],
                    b: &bodies[b],
                })
            });
            verdicts.next.push((key, keep));
            keep
        });
        verdicts.finish();
    }

    /// Whether CCD may stop body `i` at body `j` (dense): not if a hook took every point
    /// of their manifolds at this step's update, nor if the filter refuses them (the
    /// verdict kept on the pair, or the filter's answer, then kept).
    pub fn ccd_allows(&mut self, bodies: &[Body], ids: &[BodyId], i: usize, j: usize) -> bool {
        let (a, b) = (i.min(j), i.max(j));
        if self.passing.binary_search(&(a as u32, b as u32)).is_ok() {
            return false;
        }
        let Some(filter) = self.filter.as_mut() else {
            return true;
        };
        let key = (ids[a], ids[b]);
        let list = &mut self.verdicts.list;
        match list.binary_search_by_key(&key, |&(k, _)| k) {
            Ok(k) => list[k].1,
            Err(k) => {
                let keep = filter(&ContactPair {
                    body_a: ids[a],
                    a: &bodies[a],
                    body_b: ids[b],
                    b: &bodies[b],
                });
                list.insert(k, (key, keep));
                keep
            }
        }
    }

    /// Whether the filter lets sensor pair `(a, b)` (dense, a < b) overlap; called for
    /// the candidates of one sensor update in order, between [`Hooks::begin_sensors`] and
    /// [`Hooks::end_sensors`].
    pub fn sensor_allows(&mut self, bodies: &[Body], ids: &[BodyId], a: usize, b: usize) -> bool {
        let Some(filter) = self.filter.as_mut() else {
            return true;
        };
        let verdicts = &mut self.sensor_verdicts;
        let key = (ids[a], ids[b]);
        let keep = verdicts.find(key).unwrap_or_else(|| {
            filter(&ContactPair {
                body_a: ids[a],
                a: &bodies[a],
                body_b: ids[b],
                b: &bodies[b],
            })
        });
        verdicts.next.push((key, keep));
        keep
    }

    /// Ends a sensor update: its candidates' verdicts are the ones kept.
    pub fn end_sensors(&mut self) {
        if self.filter.is_some() {
            self.sensor_verdicts.finish();
        }
    }

    /// Stage of the contact update, after the narrow phase: one-way bodies' gates, then the
    /// modifier, over `contacts` in order (see the module header). Writes the manifolds'
    /// points, gates and `edited` flags, `materials` and `passing`.
    pub fn apply(
        &mut self,
        contacts: &mut [Contact],
        bodies: &[Body],
        rule: &OneWayRule,
        max_speed: Real,
    ) {
        self.materials.clear();
        self.passing.clear();
        if self.one_way_bodies == 0 && self.modifier.is_none() {
            return;
        }
        for c in contacts.iter_mut() {
            let (a, b) = (&bodies[c.index_a as usize], &bodies[c.index_b as usize]);
            let mut material = material_of(a, b);
            // A pair that cannot have moved keeps what was decided when it fell asleep.
            let live = !(frozen(a) && frozen(b));
            let before = c.manifold.len();
            if live && (a.one_way.is_some() || b.one_way.is_some()) {
                gate(c, (a, b), rule);
            }
            if let Some(modifier) = self.modifier.as_mut().filter(|_| live) {
                if !c.manifold.is_empty() {
                    modifier(&mut ContactModification {
                        body_a: c.body_a,
                        a,
                        body_b: c.body_b,
                        b,
                        manifold: &mut c.manifold,
                        material: &mut material,
                        new: c.new,
                        max_speed,
                    });
                }
            }
            c.edited |= live && c.manifold.len() < before;
            if c.edited && c.manifold.is_empty() {
                self.passing.push((c.index_a, c.index_b));
            }
            if self.modifier.is_some() {
                self.materials.push(material);
            }
        }
        // Contacts come in body-pair order: only a pair's several manifolds repeat.
        self.passing.dedup();
    }
}

/// A body that cannot have moved since the last step: static, or dynamic and asleep.
fn frozen(b: &Body) -> bool {
    b.kind == BodyKind::Static || (b.kind == BodyKind::Dynamic && !b.awake)
}

/// Decides a manifold with a one-way body if it is new, or passed through and now apart
/// (see the module header), and empties it if it is passed through.
fn gate(c: &mut Contact, (a, b): (&Body, &Body), rule: &OneWayRule) {
    let m = &c.manifold;
    let apart = m.min_separation() > 0.0;
    if c.gate == Gate::New || (c.gate == Gate::Pass && apart) {
        let Some(deepest) = m
            .points()
            .iter()
            .min_by(|p, q| p.separation.total_cmp(&q.separation))
        else {
            return;
        };
        let at = (deepest.point_a + deepest.point_b) * 0.5;
        let keeps = holds(a, b, m.normal, at, rule) && holds(b, a, -m.normal, at, rule);
        c.gate = if keeps { Gate::Keep } else { Gate::Pass };
    }
    if c.gate == Gate::Pass {
        c.manifold.clear();
    }
}

/// Whether body `p` (if it is one-way) holds body `o` at a manifold whose normal from `p`
/// to `o` is `out`, at world point `at`: `o` comes from the side of `p`'s normal and does
/// not move away along it faster than `rule.speed`, now or after the step's gravity.
fn holds(p: &Body, o: &Body, out: Vec3, at: Vec3, rule: &OneWayRule) -> bool {
    let Some(n) = p.one_way else {
        return true;
    };
    let n = p.orientation * n;
    if out.dot(n) < ONE_WAY_COS {
        return false;
    }
    let fall = |b: &Body| {
        if b.kind == BodyKind::Dynamic && b.awake {
            b.gravity_scale
        } else {
            0.0
        }
    };
    let v = o.velocity_at_point(at) - p.velocity_at_point(at);
    let after = v + rule.kick * (fall(o) - fall(p));
    v.dot(n).min(after.dot(n)) <= rule.speed
}

impl Hooks {
    /// Checks hooks read from a snapshot against the bodies: the one-way count, which
    /// each removal subtracts from (it must not underflow). The verdicts hold handles;
    /// `materials` and `passing` are rebuilt by the next contact update before they are
    /// read (and `passing` goes stale when a body is removed, so it is not checked).
    pub(crate) fn check_saved(&self, bodies: &[Body]) -> crate::codec::Decoded<()> {
        let one_way = bodies.iter().filter(|b| b.one_way.is_some()).count();
        crate::codec::ensure(self.one_way_bodies == one_way, || {
            format!(
                "hooks.one_way_bodies: {} but {one_way} bodies are one-way",
                self.one_way_bodies
            )
        })
    }
}

crate::codec::codec_struct!(Verdicts { list, next });
// The filter and modifier are code: the world restored into keeps its own (see
// `pipeline/world/snapshot.rs`).
crate::codec::codec_struct!(Hooks {
    verdicts, sensor_verdicts, one_way_bodies, materials, passing;
    filter, modifier
});

impl Hooks {
    /// Takes `other`'s contact filter and modifier (code, which snapshots do not hold).
    pub(crate) fn take_code(&mut self, other: &mut Hooks) {
        self.filter = other.filter.take();
        self.modifier = other.modifier.take();
    }
}
