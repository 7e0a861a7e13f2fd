//! The world's force elements (springs, drag, applied forces) and force callbacks.

use crate::error::{Error, Result};
use crate::force::{Force, ForceCallback};
use crate::id::{BodyId, ForceId};
use crate::world::World;

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
        let id = ForceId(self.forces.next_id);
        self.forces.next_id += 1;
        self.wake_force_bodies(&force);
        self.forces.list.push(force);
        self.forces.ids.push(id);
        Ok(id)
    }

    /// Removes a force element; false if there was none with this id.
    pub fn remove_force(&mut self, id: ForceId) -> bool {
        match self.forces.ids.iter().position(|f| *f == id) {
            Some(i) => {
                let force = self.forces.list.remove(i);
                self.wake_force_bodies(&force);
                self.forces.ids.remove(i);
                true
            }
            None => false,
        }
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
        self.forces.ids.iter().copied().zip(self.forces.list.iter())
    }

    /// Adds a user force function, evaluated with every other force.
    pub fn add_force_callback(&mut self, callback: ForceCallback) {
        self.forces.callbacks.push(callback);
    }

    /// Removes every force element attached to `body` (the body is being removed).
    pub(crate) fn remove_forces_of(&mut self, body: BodyId) {
        let store = &mut self.forces;
        let keep: Vec<bool> = store
            .list
            .iter()
            .map(|f| {
                let (a, b) = f.bodies();
                a != body && b != Some(body)
            })
            .collect();
        let mut k = keep.iter();
        store.list.retain(|_| *k.next().unwrap_or(&true));
        let mut k = keep.iter();
        store.ids.retain(|_| *k.next().unwrap_or(&true));
    }
}
