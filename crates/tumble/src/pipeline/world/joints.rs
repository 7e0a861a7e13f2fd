//! The world's joints: creating, finding and removing them, and what the step needs of
//! them (which bodies they join, which pairs they keep from colliding).

use crate::dynamics::joint::{self, Joint, JointDef, JointId};
use crate::error::{Error, Result};
use crate::id::BodyId;
use crate::pipeline::world::World;

impl World {
    /// Creates a joint between the bodies of `def`, measuring its angles from their poses
    /// now. Fails, changing nothing, on bad numbers (`limits: lower must be <= upper`),
    /// an unknown body (`other: unknown or removed body`) or a name already taken. Wakes
    /// both bodies.
    pub fn create_joint(&mut self, def: &JointDef) -> Result<JointId> {
        joint::validate(def)?;
        if let Some(name) = &def.name {
            if self.find_joint(name).is_some() {
                return Err(Error::invalid(
                    "name",
                    format!("a joint named '{name}' already exists"),
                ));
            }
        }
        let a = self.dense(def.body).ok_or(Error::UnknownBody {
            field: "body".into(),
            id: def.body,
        })?;
        let b = match def.other {
            Some(id) => Some(self.dense(id).ok_or(Error::UnknownBody {
                field: "other".into(),
                id,
            })?),
            None => None,
        };
        let pose = |i: usize| {
            let p = self.bodies.list[i].pose();
            (p.position, p.rotation)
        };
        let joint = joint::build(def, pose(a), b.map(pose));
        let id = self.joints.handles.insert();
        self.joints.list.push(joint);
        self.wake_around(a);
        if let Some(b) = b {
            self.wake_around(b);
        }
        self.link_last_joint([Some(a), b]);
        Ok(id)
    }

    /// Removes a joint, waking the bodies it held. Fails, changing nothing, on an unknown
    /// or stale handle (`joint: unknown or removed joint ...`), as `remove_body` does.
    pub fn remove_joint(&mut self, id: JointId) -> Result<()> {
        let k = self.joints.handles.remove(id).ok_or_else(|| unknown(id))?;
        let joint = self.joints.list.remove(k);
        for body in [Some(joint.def.body), joint.def.other]
            .into_iter()
            .flatten()
        {
            if let Some(i) = self.dense(body) {
                self.wake_around(i);
            }
        }
        self.refresh_joint_links();
        Ok(())
    }

    /// The joint with handle `id`; an error for an unknown or stale handle.
    pub fn joint(&self, id: JointId) -> Result<&Joint> {
        self.joints
            .handles
            .dense(id)
            .map(|k| &self.joints.list[k])
            .ok_or_else(|| unknown(id))
    }

    /// The handle of the joint called `name`.
    pub fn find_joint(&self, name: &str) -> Option<JointId> {
        self.joints
            .list
            .iter()
            .position(|j| j.def.name.as_deref() == Some(name))
            .map(|k| self.joints.handles.ids()[k])
    }

    /// All joints with their handles, in creation order.
    pub fn joints(&self) -> impl Iterator<Item = (JointId, &Joint)> {
        self.joints
            .handles
            .ids()
            .iter()
            .copied()
            .zip(self.joints.list.iter())
    }

    /// Removes every joint attached to `body` (the body is being removed).
    pub(crate) fn remove_joints_of(&mut self, body: BodyId) {
        let attached: Vec<JointId> = self
            .joints()
            .filter(|(_, j)| j.def.body == body || j.def.other == Some(body))
            .map(|(id, _)| id)
            .collect();
        for id in attached {
            // Just listed, so live: removal cannot fail.
            let _ = self.remove_joint(id);
        }
    }

    /// Adds the links of the joint just pushed, whose bodies are `link` (dense), to those
    /// of the others, which still hold: re-deriving every joint's made building a net of
    /// n joints take n² work (the 100 × 100 joint grid's 19,800 joints: seconds).
    fn link_last_joint(&mut self, link: [Option<usize>; 2]) {
        let store = &mut self.joints;
        let Some(joint) = store.list.last() else {
            return;
        };
        if store.links.len() + 1 != store.list.len() {
            return self.refresh_joint_links();
        }
        let link = if joint.acts() { link } else { [None, None] };
        store.links.push(link);
        if let ([Some(a), Some(b)], false) = (link, joint.def.collide_connected) {
            let pair = (a.min(b) as u32, a.max(b) as u32);
            if let Err(at) = store.joined_pairs.binary_search(&pair) {
                store.joined_pairs.insert(at, pair);
            }
        }
    }

    /// Re-derives each joint's dense body indices (broken and disabled joints join
    /// nothing) and the pairs that must not collide (those joints and the excluded pairs).
    pub(crate) fn refresh_joint_links(&mut self) {
        // The list is refilled in place: this runs every step.
        let mut links = std::mem::take(&mut self.joints.links);
        links.clear();
        let found = self.joints.list.iter().map(|j| {
            if !j.acts() {
                [None, None]
            } else {
                [
                    self.dense(j.def.body),
                    j.def.other.and_then(|o| self.dense(o)),
                ]
            }
        });
        links.extend(found);
        self.joints.joined_pairs.clear();
        for (j, link) in self.joints.list.iter().zip(&links) {
            if let [Some(a), Some(b)] = *link {
                if !j.def.collide_connected {
                    self.joints
                        .joined_pairs
                        .push((a.min(b) as u32, a.max(b) as u32));
                }
            }
        }
        for k in 0..self.joints.excluded.len() {
            let (a, b) = self.joints.excluded[k];
            if let (Some(a), Some(b)) = (self.dense(a), self.dense(b)) {
                let pair = (a.min(b) as u32, a.max(b) as u32);
                self.joints.joined_pairs.push(pair);
            }
        }
        self.joints.joined_pairs.sort_unstable();
        self.joints.joined_pairs.dedup();
        self.joints.links = links;
    }
}

/// The error for a handle naming no live joint.
pub(super) fn unknown(id: JointId) -> Error {
    Error::invalid("joint", format!("unknown or removed joint {id:?}"))
}
