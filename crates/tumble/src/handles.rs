//! A generational handle store: the bookkeeping behind `BodyId`-like handles, apart from
//! whatever the handles name.
//!
//! Specification:
//!
//! - The store hands out handles `{index, generation}`. `index` names a *slot*; a slot's
//!   `generation` grows by one (wrapping) each time its occupant is removed, so a handle
//!   taken before the removal no longer matches: a stale handle resolves to `None`, never
//!   to whatever took the slot afterwards.
//! - Freed slots are reused last-freed first (a free list), so the slot table never grows
//!   beyond the most items alive at once.
//! - Live items also have a *dense* index, 0..len, in insertion order: the owner keeps its
//!   data in plain `Vec`s indexed by it (one or several, side by side), which is what the
//!   step iterates over. [`Handles::remove`] keeps that order (a `Vec::remove`, O(n)):
//!   outputs and solve order follow creation order, and removal is rare.
//! - The store keeps no data itself. Whoever inserts pushes the item's data onto its own
//!   `Vec`s (the new item's dense index is the old `len`); whoever removes removes the
//!   dense index [`Handles::remove`] returns from each of them.
//!
//! ```text
//! slots:  [gen 0 → dense 1] [gen 3 → free] [gen 1 → dense 0]     free list: [1]
//! ids:    [{2, 1}, {0, 0}]                                        (dense order)
//! ```

/// A handle the store can make and read: a slot index and that slot's generation.
pub(crate) trait Handle: Copy + Eq {
    /// The handle of slot `index` in its `generation`.
    fn from_parts(index: u32, generation: u32) -> Self;
    /// The slot index.
    fn index(self) -> u32;
    /// The slot's generation when the handle was made.
    fn generation(self) -> u32;
}

macro_rules! generational {
    ($($id:ident),*) => {$(
        impl Handle for $id {
            fn from_parts(index: u32, generation: u32) -> Self {
                $id { index, generation }
            }
            fn index(self) -> u32 {
                self.index
            }
            fn generation(self) -> u32 {
                self.generation
            }
        }
    )*};
}

generational!(BodyId, JointId, ForceId);

use crate::id::{BodyId, ForceId, JointId};

#[derive(Debug, Clone, Copy)]
struct Slot {
    generation: u32,
    /// Dense index of the slot's live item; `None` while the slot is free.
    dense: Option<u32>,
}

/// Slots with generations, a free list, and the live handles in dense (insertion) order.
#[derive(Debug, Clone)]
pub(crate) struct Handles<H> {
    slots: Vec<Slot>,
    free: Vec<u32>,
    ids: Vec<H>,
}

impl<H> Default for Handles<H> {
    fn default() -> Self {
        Handles {
            slots: Vec::new(),
            free: Vec::new(),
            ids: Vec::new(),
        }
    }
}

impl<H: Handle> Handles<H> {
    /// A handle for a new item, whose dense index is `self.len()` before the call.
    pub fn insert(&mut self) -> H {
        let index = match self.free.pop() {
            Some(i) => i,
            None => {
                self.slots.push(Slot {
                    generation: 0,
                    dense: None,
                });
                (self.slots.len() - 1) as u32
            }
        };
        let slot = &mut self.slots[index as usize];
        slot.dense = Some(self.ids.len() as u32);
        let id = H::from_parts(index, slot.generation);
        self.ids.push(id);
        id
    }

    /// The dense index of `id`'s item; `None` for a stale or never-issued handle.
    pub fn dense(&self, id: H) -> Option<usize> {
        let slot = self.slots.get(id.index() as usize)?;
        if slot.generation != id.generation() {
            return None;
        }
        slot.dense.map(|d| d as usize)
    }

    /// Removes `id`'s item and returns the dense index it had (the caller removes that
    /// index from its own `Vec`s); `None`, changing nothing, for a stale handle. Later
    /// items move down one place, keeping their order.
    pub fn remove(&mut self, id: H) -> Option<usize> {
        let dense = self.dense(id)?;
        self.ids.remove(dense);
        let slot = &mut self.slots[id.index() as usize];
        slot.dense = None;
        slot.generation = slot.generation.wrapping_add(1);
        self.free.push(id.index());
        for (i, later) in self.ids.iter().enumerate().skip(dense) {
            self.slots[later.index() as usize].dense = Some(i as u32);
        }
        Some(dense)
    }

    /// The live handles, in dense order (their count is the number of live items).
    pub fn ids(&self) -> &[H] {
        &self.ids
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::id::JointId;

    #[test]
    fn a_stale_handle_finds_nothing_after_its_slot_is_reused() {
        let mut h = Handles::<JointId>::default();
        let a = h.insert();
        let b = h.insert();
        assert_eq!((h.dense(a), h.dense(b)), (Some(0), Some(1)));
        assert_eq!(h.remove(a), Some(0));
        assert_eq!(h.remove(a), None);
        assert_eq!(h.dense(b), Some(0));
        let c = h.insert();
        assert_eq!(c.index, a.index);
        assert_eq!(c.generation, a.generation + 1);
        assert_eq!(h.dense(a), None);
        assert_eq!(h.dense(c), Some(1));
        assert_eq!(h.ids(), &[b, c]);
        let never = JointId {
            index: 7,
            generation: 0,
        };
        assert_eq!(h.dense(never), None);
    }

    #[test]
    fn removal_keeps_the_order_of_the_rest() {
        let mut h = Handles::<JointId>::default();
        let ids: Vec<JointId> = (0..5).map(|_| h.insert()).collect();
        assert_eq!(h.remove(ids[1]), Some(1));
        assert_eq!(h.ids(), &[ids[0], ids[2], ids[3], ids[4]]);
        for (i, id) in h.ids().iter().enumerate() {
            assert_eq!(h.dense(*id), Some(i));
        }
    }
}

crate::codec::codec_struct!(Slot { generation, dense });

impl<H: Handle> crate::codec::Code for Handles<H> {
    fn put(&self, w: &mut crate::codec::Writer) {
        self.slots.put(w);
        self.free.put(w);
        w.len(self.ids.len());
        for id in &self.ids {
            id.index().put(w);
            id.generation().put(w);
        }
    }
    fn get(r: &mut crate::codec::Reader<'_>) -> crate::codec::Decoded<Self> {
        use crate::codec::Code;
        let slots: Vec<Slot> = Code::get(r)?;
        let free: Vec<u32> = Code::get(r)?;
        let n = r.len()?;
        let mut ids = Vec::with_capacity(n);
        for _ in 0..n {
            ids.push(H::from_parts(Code::get(r)?, Code::get(r)?));
        }
        let handles = Handles { slots, free, ids };
        if !handles.consistent() {
            let at = r.offset();
            return Err(crate::codec::Malformed(format!(
                "handles ending at byte {at} do not match their slots"
            )));
        }
        Ok(handles)
    }
}

impl<H: Handle> Handles<H> {
    /// How many items are live.
    pub(crate) fn len(&self) -> usize {
        self.ids.len()
    }

    /// Whether every live handle names a slot of its generation that points back at it,
    /// and the free list holds each free slot once: what a snapshot must hold before it is
    /// trusted (a slot listed twice would be handed out twice, to two live items).
    fn consistent(&self) -> bool {
        let live = self.ids.iter().enumerate().all(|(i, id)| {
            self.slots
                .get(id.index() as usize)
                .is_some_and(|s| s.generation == id.generation() && s.dense == Some(i as u32))
        });
        let mut listed = vec![false; self.slots.len()];
        let free = self.free.iter().all(|&f| {
            let free = self
                .slots
                .get(f as usize)
                .is_some_and(|s| s.dense.is_none());
            free && !std::mem::replace(&mut listed[f as usize], true)
        });
        let taken = self.slots.iter().filter(|s| s.dense.is_some()).count();
        live && free && taken == self.ids.len() && taken + self.free.len() == self.slots.len()
    }
}
