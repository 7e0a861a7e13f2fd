//! The world's contact hooks (the pair filter and the contact modifier) and its sensors'
//! reports; the machinery is `pipeline/hooks.rs` and `pipeline/sensors.rs`.

use crate::error::{Error, Result};
use crate::id::BodyId;
use crate::pipeline::hooks::{ContactModification, ContactPair};
use crate::pipeline::sensors::SensorEvent;
use crate::pipeline::world::World;

impl World {
    /// Sets the contact filter: called once for each pair of bodies when the broad phase
    /// first finds their boxes overlapping (in pair order, so runs are deterministic); if
    /// it returns false the pair has no contact at all (no manifold, no CCD stop, no
    /// sensor overlap) until the boxes part and meet again, when it is asked again.
    /// Replacing or clearing the filter asks every pair afresh, and wakes every body.
    ///
    /// ```
    /// # use tumble::prelude::*;
    /// let mut world = World::new(&WorldDef::default());
    /// world.set_contact_filter(|pair| pair.a.is_awake() || pair.b.is_awake());
    /// ```
    pub fn set_contact_filter(
        &mut self,
        filter: impl FnMut(&ContactPair<'_>) -> bool + Send + 'static,
    ) {
        self.hooks.set_filter(Some(Box::new(filter)));
        self.wake_all();
    }

    /// Keeps bodies `a` and `b` from ever touching, as a joint between them does (MuJoCo's
    /// `<contact><exclude>`): no manifold, no CCD stop. Unlike a contact filter this is
    /// data: a world holding such pairs is copied ([`crate::Batch`]), snapshotted and
    /// saved with them. Excluding a pair twice changes nothing; both bodies are woken.
    /// Errors: an unknown body, or `a == b`.
    pub fn exclude_contacts(&mut self, a: BodyId, b: BodyId) -> Result<()> {
        let pair = self.contact_pair(a, b)?;
        if let Err(at) = self.joints.excluded.binary_search(&pair) {
            self.joints.excluded.insert(at, pair);
            self.refresh_joint_links();
        }
        Ok(())
    }

    /// Lets bodies `a` and `b` touch again after [`World::exclude_contacts`] (a joint
    /// between them still keeps them apart unless it collides connected); returns whether
    /// the pair was excluded. Both bodies are woken.
    pub fn allow_contacts(&mut self, a: BodyId, b: BodyId) -> Result<bool> {
        let pair = self.contact_pair(a, b)?;
        let Ok(at) = self.joints.excluded.binary_search(&pair) else {
            return Ok(false);
        };
        self.joints.excluded.remove(at);
        self.refresh_joint_links();
        Ok(true)
    }

    /// The pairs [`World::exclude_contacts`] keeps apart, each (older handle, newer),
    /// sorted.
    pub fn excluded_contacts(&self) -> &[(BodyId, BodyId)] {
        &self.joints.excluded
    }

    /// `(a, b)` checked and ordered, both bodies woken.
    fn contact_pair(&mut self, a: BodyId, b: BodyId) -> Result<(BodyId, BodyId)> {
        let unknown = |field: &str, id| Error::UnknownBody {
            field: field.into(),
            id,
        };
        let i = self.dense(a).ok_or_else(|| unknown("a", a))?;
        let j = self.dense(b).ok_or_else(|| unknown("b", b))?;
        if a == b {
            return Err(Error::invalid(
                "exclude",
                "a body cannot be excluded from itself",
            ));
        }
        self.wake_around(i);
        self.wake_around(j);
        Ok((a.min(b), a.max(b)))
    }

    /// Removes the contact filter: every pair the broad phase finds may touch again.
    pub fn clear_contact_filter(&mut self) {
        self.hooks.set_filter(None);
        self.wake_all();
    }

    /// Sets the contact modifier: called at every contact update (once per step) for each
    /// manifold with points whose bodies are not both asleep or static, in pair order,
    /// before the solver. It may set the manifold's friction, restitution and surface
    /// velocity for the step and drop its points (see [`ContactModification`]); a
    /// manifold left without points does not touch (no events, no solver, no CCD stop).
    /// Setting or clearing it wakes every body.
    pub fn set_contact_modifier(
        &mut self,
        modifier: impl FnMut(&mut ContactModification<'_>) + Send + 'static,
    ) {
        self.hooks.set_modifier(Some(Box::new(modifier)));
        self.wake_all();
    }

    /// Removes the contact modifier.
    pub fn clear_contact_modifier(&mut self) {
        self.hooks.set_modifier(None);
        self.wake_all();
    }

    /// The sensor events of the last step, in (sensor, body) order: a body began or
    /// stopped overlapping a sensor. End events of edits made before the step (a body
    /// removed, a sensor flag changed) come first, stamped with the time of the edit.
    pub fn sensor_events(&self) -> &[SensorEvent] {
        self.sensors.events()
    }

    /// The bodies overlapping sensor `id` as of the last step, ordered by handle (none if
    /// the body is not a sensor).
    pub fn sensor_overlaps(&self, id: BodyId) -> Result<Vec<BodyId>> {
        self.dense(id).ok_or(Error::UnknownBody {
            field: "body".into(),
            id,
        })?;
        Ok(self.sensors.overlaps_of(id).collect())
    }

    /// Stage of the step, last: each sensor's overlaps at the step's result, and the
    /// events since the last step, stamped with the world's time (see
    /// `pipeline/sensors.rs`). Reads the bodies and the broad phase; asks the contact
    /// filter about new sensor pairs.
    pub(super) fn update_sensors(&mut self) {
        let (bodies, ids) = (&self.bodies.list, self.bodies.handles.ids());
        let hooks = &mut self.hooks;
        self.sensors.update(
            (bodies, ids),
            &self.collision.broad_phase,
            |a, b| hooks.sensor_allows(bodies, ids, a, b),
            self.clock.time,
        );
        hooks.end_sensors();
    }
}
