//! Generational handles. A handle is `Copy` and cheap; a stale one is an error, never a
//! silent reference to whatever body reused its slot (see `handles.rs` for the store).

/// Handle of a body in a [`crate::World`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct BodyId {
    /// Slot index.
    pub index: u32,
    /// Generation of the slot when the body was created.
    pub generation: u32,
}

/// Handle of a joint in a [`crate::World`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct JointId {
    /// Slot index.
    pub index: u32,
    /// Generation of the slot when the joint was created.
    pub generation: u32,
}

/// Handle of a force element (spring, drag, applied force) in a [`crate::World`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct ForceId {
    /// Slot index.
    pub index: u32,
    /// Generation of the slot when the force element was added.
    pub generation: u32,
}
