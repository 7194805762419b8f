//! Synchronization2 barriers: the state tracked per resource and the barrier each access needs.
//!
//! The rules, for an access with stage `S`, access mask `A` and (images) layout `L`:
//! - a write, or a layout change, waits for the readers since the last write (execution only:
//!   source access NONE) or, when there were none, for the last write (stage and write access);
//! - a read in the same layout waits for the last write unless an earlier barrier already made
//!   that write visible to `S`/`A`; reads after reads need nothing;
//! - a fresh resource (or a transient whose memory was used by another) starts UNDEFINED.

use shine_gpu::vk;

use crate::access::{AccessInfo, write_bits};
use crate::handle::ResourceId;
use crate::resource::ExternalState;

/// A pipeline stage mask with an access mask.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct Scope {
    /// Stages.
    pub stage: vk::PipelineStageFlags2,
    /// Accesses.
    pub access: vk::AccessFlags2,
}

impl Scope {
    /// Nothing: no stage, no access.
    pub const NONE: Self = Self {
        stage: vk::PipelineStageFlags2::NONE,
        access: vk::AccessFlags2::NONE,
    };

    /// A scope of the given masks.
    pub fn new(stage: vk::PipelineStageFlags2, access: vk::AccessFlags2) -> Self {
        Self { stage, access }
    }

    fn covers(&self, other: &Scope) -> bool {
        self.stage.contains(other.stage) && self.access.contains(other.access)
    }
}

/// One pipeline barrier on one resource (whole image or whole buffer).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Barrier {
    /// The resource.
    pub resource: ResourceId,
    /// First synchronization scope: what must finish.
    pub src: Scope,
    /// Second synchronization scope: what waits.
    pub dst: Scope,
    /// Layout before (UNDEFINED for buffers, and for images whose contents may be discarded).
    pub old_layout: vk::ImageLayout,
    /// Layout after (UNDEFINED for buffers).
    pub new_layout: vk::ImageLayout,
}

impl Barrier {
    /// Whether it changes an image's layout.
    pub fn is_transition(&self) -> bool {
        self.old_layout != self.new_layout
    }
}

/// The synchronization state of one resource between passes.
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub(crate) struct Track {
    /// Current layout (images).
    pub layout: vk::ImageLayout,
    /// What a later access must wait for to be ordered after the last write (or transition).
    pub write: Scope,
    /// Scopes the last write has been made visible to by earlier barriers.
    pub visible: Vec<Scope>,
    /// Stages that read since the last write.
    pub readers: vk::PipelineStageFlags2,
    /// Whether the graph wrote it or changed its layout.
    pub dirty: bool,
}

impl Track {
    /// A resource with undefined contents and no earlier use.
    pub fn fresh() -> Self {
        Self::from_external(ExternalState::UNDEFINED)
    }

    /// A resource last used outside the graph as `state`.
    pub fn from_external(state: ExternalState) -> Self {
        let writes = write_bits(state.access);
        let (write, readers) = if writes.is_empty() {
            (Scope::NONE, state.stage)
        } else {
            (
                Scope::new(state.stage, writes),
                vk::PipelineStageFlags2::NONE,
            )
        };
        Self {
            layout: state.layout,
            write,
            visible: Vec::new(),
            readers,
            dirty: false,
        }
    }

    /// What a write (or a transition) must wait for: the readers since the last write, or else
    /// the last write itself.
    pub fn hazard_source(&self) -> Scope {
        if self.readers.is_empty() {
            self.write
        } else {
            Scope::new(self.readers, vk::AccessFlags2::NONE)
        }
    }

    /// The same state carried to a later frame: visibility is not assumed across submissions.
    pub fn next_frame(&self) -> Self {
        Self {
            visible: Vec::new(),
            dirty: false,
            ..self.clone()
        }
    }

    /// Apply a pass's (merged) access and return the barrier it needs, if any.
    pub fn access(
        &mut self,
        resource: ResourceId,
        is_image: bool,
        a: &AccessInfo,
    ) -> Option<Barrier> {
        let dst = Scope::new(a.stage, a.access);
        let transition = is_image && a.layout != self.layout;
        let barrier = |src: Scope, old, new| Barrier {
            resource,
            src,
            dst,
            old_layout: old,
            new_layout: new,
        };
        if transition || a.is_write() {
            let src = self.hazard_source();
            let out = (transition || !src.stage.is_empty()).then(|| {
                barrier(
                    src,
                    self.layout,
                    if is_image { a.layout } else { self.layout },
                )
            });
            if a.is_write() {
                self.write = Scope::new(a.stage, a.writes());
                self.visible.clear();
                self.readers = vk::PipelineStageFlags2::NONE;
            } else {
                self.write.stage |= a.stage;
                self.visible = vec![dst];
                self.readers = a.stage;
            }
            if is_image {
                self.layout = a.layout;
            }
            self.dirty = true;
            out
        } else {
            let needs =
                !self.write.stage.is_empty() && !self.visible.iter().any(|v| v.covers(&dst));
            self.readers |= a.stage;
            needs.then(|| {
                self.visible.push(dst);
                barrier(self.write, self.layout, self.layout)
            })
        }
    }

    /// The barrier that hands the resource back to the caller in `target`, if one is needed.
    pub fn release(
        &self,
        resource: ResourceId,
        is_image: bool,
        target: ExternalState,
    ) -> Option<Barrier> {
        let transition =
            is_image && target.layout != vk::ImageLayout::UNDEFINED && target.layout != self.layout;
        let src = self.hazard_source();
        let caller_writes = !write_bits(target.access).is_empty();
        let needed = transition
            || (!target.stage.is_empty()
                && !src.stage.is_empty()
                && (self.dirty || (caller_writes && !self.readers.is_empty())));
        needed.then(|| Barrier {
            resource,
            src,
            dst: Scope::new(target.stage, target.access),
            old_layout: self.layout,
            new_layout: if transition {
                target.layout
            } else {
                self.layout
            },
        })
    }
}
