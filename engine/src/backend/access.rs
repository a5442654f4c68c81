//! What the commands of a pass touch: every buffer and image bound to a pipeline, drawn from,
//! rendered into or copied, and whether the pass may write it. The backend's recording methods
//! log it into the [`Cmd`](super::Cmd) they record into, so a pass's reads and writes follow
//! from the resources it uses (the pass layer orders passes by them) and are never declared
//! apart from them.
use std::cell::RefCell;
use std::sync::Arc;

/// A buffer or image touched by a pass.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Touch {
    /// The Vulkan handle's value: unique among the objects alive during a frame.
    pub id: u64,
    pub name: Arc<str>,
    /// True where the pass may write it (a storage binding the shader does not declare
    /// `readonly`, a render target, a copy's destination); false where it only reads it.
    pub writes: bool,
}

/// The touches of one pass, in the order its commands made them.
#[derive(Default)]
pub struct AccessLog(RefCell<Vec<Touch>>);

impl AccessLog {
    pub(super) fn add(&self, id: u64, name: &Arc<str>, writes: bool) {
        self.0.borrow_mut().push(Touch { id, name: name.clone(), writes });
    }

    pub fn take(&self) -> Vec<Touch> {
        self.0.take()
    }
}
