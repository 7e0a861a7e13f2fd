//! The world's force elements (springs, drag, applied forces) and force callbacks.

use crate::dynamics::force::{Force, ForceCallback};
use crate::error::{Error, Result};
use crate::id::{BodyId, ForceId};
use crate::pipeline::world::World;

impl World {
    /// Adds a force element; its bodies must exist. Fields in errors are relative to it.
    pub fn add_force(&mut self, force: Force) -> Result<ForceId> {
        force.validate()?;
        let (a, b) = force.bodies();
        if self.dense(a).is_none() {
            return Err(Error::UnknownBody {
                field: "body".into(),
                id: a,
            });
        }
        if let Some(b) = b {
            if self.dense(b).is_none() {
                return Err(Error::UnknownBody {
                    field: "other".into(),
                    id: b,
                });
            }
        }
        self.wake_force_bodies(&force);
        let id = self.forces.handles.insert();
        self.forces.list.push(force);
        Ok(id)
    }

    /// Removes a force element, waking the bodies it acted on. Fails, changing nothing,
    /// on an unknown or stale handle (`force: unknown or removed force ...`), as
    /// `remove_body` and `remove_joint` do.
    pub fn remove_force(&mut self, id: ForceId) -> Result<()> {
        let i =
            self.forces.handles.remove(id).ok_or_else(|| {
                Error::invalid("force", format!("unknown or removed force {id:?}"))
            })?;
        let force = self.forces.list.remove(i);
        self.wake_force_bodies(&force);
        Ok(())
    }

    fn wake_force_bodies(&mut self, force: &Force) {
        let (a, b) = force.bodies();
        for id in std::iter::once(a).chain(b) {
            if let Some(i) = self.dense(id) {
                self.wake_around(i);
            }
        }
    }

    /// The force elements with their ids.
    pub fn forces(&self) -> impl Iterator<Item = (ForceId, &Force)> {
        self.forces
            .handles
            .ids()
            .iter()
            .copied()
            .zip(self.forces.list.iter())
    }

    /// Adds a user force function, evaluated with every other force (how often per step:
    /// [`ForceCallback`]). It may push any body, so every body is woken.
    pub fn add_force_callback(&mut self, callback: ForceCallback) {
        self.forces.callbacks.push(callback);
        self.wake_all();
    }

    /// Removes every force element attached to `body` (the body is being removed).
    pub(crate) fn remove_forces_of(&mut self, body: BodyId) {
        let attached: Vec<ForceId> = self
            .forces()
            .filter(|(_, f)| {
                let (a, b) = f.bodies();
                a == body || b == Some(body)
            })
            .map(|(id, _)| id)
            .collect();
        for id in attached {
            let i = self.forces.handles.remove(id);
            if let Some(i) = i {
                self.forces.list.remove(i);
            }
        }
    }
}
