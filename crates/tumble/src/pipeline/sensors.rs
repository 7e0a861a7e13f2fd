//! Sensors: bodies that report which bodies they overlap, with no contact response.
//!
//! A sensor's broad-phase proxy pairs with nothing (`Filter::NONE`), so no contact, solver
//! row, CCD sweep or contact limit ever involves it. Instead, at the end of every step,
//! each sensor asks the broad phase for the bodies whose boxes meet its own and tests each
//! with the narrow phase at margin 0: the pair overlaps when a point has separation ≤ 0
//! (the shapes intersect, not merely their boxes). A sensor detects every body that is not
//! a sensor and that its collision filter (and the contact filter, see `hooks.rs`) lets it
//! meet, except that a static sensor does not detect static bodies (neither can move).
//! Both may be asleep: a sleeping body inside a sensor stays reported, since the test is
//! of where the bodies are, not of whether they move.
//!
//! The overlaps are kept sorted by (sensor, body) ids; the events of a step are what
//! changed, found by one merge-like walk of the old list against the new, so they come in
//! (sensor, body) order and the same run gives the same events. An edit between steps that
//! ends overlaps (a body removed, a sensor flag cleared) ends them at once in the list and
//! reports their end events, stamped with the time of the edit, first among the next
//! step's events: every change is reported exactly once to a caller that reads the
//! events after each step.
//!
//! A mesh or height field is a surface: a sensor made of one detects what touches its
//! triangles, not what lies wholly inside a closed mesh.

use crate::collision::broad_phase::BroadPhase;
use crate::collision::narrow_phase::{collide, Manifold};
use crate::dynamics::body::{Body, BodyKind};
use crate::id::BodyId;
use crate::math::Real;

/// A body started or stopped overlapping a sensor.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SensorEvent {
    /// The sensor.
    pub sensor: BodyId,
    /// The body that entered or left it.
    pub body: BodyId,
    /// True when the overlap began, false when it ended.
    pub began: bool,
    /// The simulated time at which the change was seen (s): the end of the step that
    /// found it, or the time of the edit that ended it.
    pub time: Real,
}

/// What the sensors keep between steps.
#[derive(Debug, Default)]
pub(crate) struct SensorStore {
    /// How many bodies are sensors: with none, and nothing to end, a step skips the stage.
    pub sensor_bodies: usize,
    /// The overlapping (sensor, body) pairs as of the last step, sorted.
    overlaps: Vec<(BodyId, BodyId)>,
    /// The last step's events.
    events: Vec<SensorEvent>,
    /// End events of edits since the last step, for the next step's list.
    pending: Vec<SensorEvent>,
    /// Scratch: this update's overlaps, one sensor's candidates, a tree stack, manifolds.
    found: Vec<(BodyId, BodyId)>,
    candidates: Vec<u32>,
    stack: Vec<u32>,
    manifolds: Vec<Manifold>,
}

impl SensorStore {
    /// The last step's events.
    pub fn events(&self) -> &[SensorEvent] {
        &self.events
    }

    /// The bodies overlapping `sensor` as of the last step.
    pub fn overlaps_of(&self, sensor: BodyId) -> impl Iterator<Item = BodyId> + '_ {
        let k = self.overlaps.partition_point(|&(s, _)| s < sensor);
        self.overlaps[k..]
            .iter()
            .take_while(move |&&(s, _)| s == sensor)
            .map(|&(_, b)| b)
    }

    /// Ends every overlap `id` takes part in, as sensor or as body, at `time`: the body is
    /// removed, or its sensor flag changed.
    pub fn forget(&mut self, id: BodyId, time: Real) {
        let pending = &mut self.pending;
        self.overlaps.retain(|&(sensor, body)| {
            let ends = sensor == id || body == id;
            if ends {
                pending.push(SensorEvent {
                    sensor,
                    body,
                    began: false,
                    time,
                });
            }
            !ends
        });
    }

    /// Stage of the step, last: every sensor's overlaps at the bodies' new poses, and the
    /// events since the last step, stamped `time`. Reads the bodies and the broad phase
    /// (updated by `scatter`); `allows` is the contact filter's verdict on a dense pair.
    pub fn update(
        &mut self,
        (bodies, ids): (&[Body], &[BodyId]),
        broad: &BroadPhase,
        mut allows: impl FnMut(usize, usize) -> bool,
        time: Real,
    ) {
        if self.sensor_bodies == 0 && self.overlaps.is_empty() && self.pending.is_empty() {
            self.events.clear();
            return;
        }
        self.found.clear();
        for (i, sensor) in bodies.iter().enumerate().filter(|(_, b)| b.sensor) {
            self.candidates.clear();
            let aabb = sensor.shape.aabb(&sensor.pose());
            let candidates = &mut self.candidates;
            broad.query_aabb_with(&aabb, &mut self.stack, |user| candidates.push(user));
            candidates.sort_unstable();
            candidates.dedup();
            for k in 0..self.candidates.len() {
                let j = self.candidates[k] as usize;
                let Some(other) = bodies.get(j).filter(|o| detects(sensor, o) && j != i) else {
                    continue;
                };
                if allows(i.min(j), i.max(j)) && self.overlap(sensor, other) {
                    self.found.push((ids[i], ids[j]));
                }
            }
        }
        self.found.sort_unstable();
        self.events.clear();
        self.events.append(&mut self.pending);
        changes(&self.found, &self.overlaps, time, &mut self.events);
        std::mem::swap(&mut self.overlaps, &mut self.found);
    }

    /// Whether the shapes of `a` and `b` intersect (a point at separation ≤ 0).
    fn overlap(&mut self, a: &Body, b: &Body) -> bool {
        self.manifolds.clear();
        collide(
            &a.shape,
            &a.pose(),
            &b.shape,
            &b.pose(),
            0.0,
            &mut self.manifolds,
        );
        self.manifolds
            .iter()
            .any(|m| m.points().iter().any(|p| p.separation <= 0.0))
    }
}

/// Whether `sensor` looks for `other` at all: not another sensor, not both static, and
/// their collision filters allow it.
fn detects(sensor: &Body, other: &Body) -> bool {
    let both_static = sensor.kind == BodyKind::Static && other.kind == BodyKind::Static;
    !other.sensor && !both_static && sensor.filter.allows(&other.filter)
}

/// Appends to `events` the pairs of sorted `now` absent from sorted `before` (begun) and
/// those of `before` absent from `now` (ended), in pair order.
fn changes(
    now: &[(BodyId, BodyId)],
    before: &[(BodyId, BodyId)],
    time: Real,
    events: &mut Vec<SensorEvent>,
) {
    let (mut i, mut j) = (0, 0);
    let event = |(sensor, body): (BodyId, BodyId), began| SensorEvent {
        sensor,
        body,
        began,
        time,
    };
    loop {
        match (now.get(i), before.get(j)) {
            (Some(&x), Some(&y)) if x == y => (i, j) = (i + 1, j + 1),
            (Some(&x), Some(&y)) if y < x => {
                events.push(event(y, false));
                j += 1;
            }
            (Some(&x), _) => {
                events.push(event(x, true));
                i += 1;
            }
            (None, Some(&y)) => {
                events.push(event(y, false));
                j += 1;
            }
            (None, None) => break,
        }
    }
}

impl SensorStore {
    /// Checks sensors read from a snapshot against the bodies: the sensor count, which
    /// each removal or flag change subtracts from (it must not underflow). The overlaps
    /// and events hold handles, which nothing indexes by.
    pub(crate) fn check_saved(&self, bodies: &[Body]) -> crate::codec::Decoded<()> {
        let sensors = bodies.iter().filter(|b| b.sensor).count();
        crate::codec::ensure(self.sensor_bodies == sensors, || {
            format!(
                "sensors.sensor_bodies: {} but {sensors} bodies are sensors",
                self.sensor_bodies
            )
        })
    }
}

crate::codec::codec_struct!(SensorEvent {
    sensor,
    body,
    began,
    time
});
crate::codec::codec_struct!(SensorStore {
    sensor_bodies, overlaps, events, pending;
    found, candidates, stack, manifolds
});
