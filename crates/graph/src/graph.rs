//! Declaring a frame: resources and the passes that use them.

use crate::access::AnyAccess;
use crate::error::GraphError;
use crate::handle::{Buffer, Handle, Image, ResourceId, ResourceType};
use crate::pass::{AccessRecord, Direction, PassCost, PassDecl, PassId, PassKind, UpdateRate};
use crate::resource::{AnyDesc, BufferDesc, BufferImport, ImageDesc, ImageImport, Lifetime};
use crate::work::Work;
use shine_gpu::vk;

/// The Vulkan objects behind an imported resource.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum External {
    Image {
        image: vk::Image,
        view: vk::ImageView,
    },
    Buffer(vk::Buffer),
}

/// A declared resource.
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub(crate) struct ResourceDecl {
    pub name: String,
    pub desc: AnyDesc,
    pub lifetime: Lifetime,
    /// The newest version declared so far.
    pub latest: u32,
}

/// The two halves of a ping-pong history resource: last frame's contents and this frame's.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct History<R: ResourceType> {
    /// What the previous frame wrote into `current` (read it).
    pub previous: Handle<R>,
    /// This frame's copy (write it); next frame it is `previous`.
    pub current: Handle<R>,
}

/// One frame's render graph: resources and passes in declaration order.
///
/// Build it, compile it with a [`crate::Compiler`] (cached while its shape does not change),
/// then execute the plan.
#[derive(Debug)]
pub struct RenderGraph {
    pub(crate) frame: u64,
    /// Frames the executor lets run at once (per-frame resources come in this many slots).
    frames_in_flight: usize,
    pub(crate) resources: Vec<ResourceDecl>,
    pub(crate) passes: Vec<PassDecl>,
    /// What each pass records, by pass index.
    pub(crate) works: Vec<Work>,
    /// Caller-owned Vulkan objects behind imported resources, by resource index.
    pub(crate) externals: Vec<Option<External>>,
    /// The halves of history pairs, which share their usage flags.
    pub(crate) pairs: Vec<(ResourceId, ResourceId)>,
    /// Mistakes found while declaring, reported by compilation.
    pub(crate) errors: Vec<GraphError>,
}

impl RenderGraph {
    /// An empty graph for frame number `frame` (it decides which periodic passes run and which
    /// half of each history pair is current).
    pub fn new(frame: u64) -> Self {
        Self::in_flight(frame, 1)
    }

    /// An empty graph for frame number `frame` of an executor that lets `frames_in_flight`
    /// frames run at once: per-frame resources the caller keeps outside the graph (staging
    /// rings) need that many slots, frame `f` using slot [`RenderGraph::slot`].
    pub fn in_flight(frame: u64, frames_in_flight: usize) -> Self {
        Self {
            frame,
            frames_in_flight: frames_in_flight.max(1),
            resources: Vec::new(),
            passes: Vec::new(),
            works: Vec::new(),
            externals: Vec::new(),
            pairs: Vec::new(),
            errors: Vec::new(),
        }
    }

    /// The frame number this graph was built for.
    pub fn frame(&self) -> u64 {
        self.frame
    }

    /// How many frames may be in flight at once (at least 1).
    pub fn frames_in_flight(&self) -> usize {
        self.frames_in_flight
    }

    /// This frame's slot among [`RenderGraph::frames_in_flight`]: when the frame is declared,
    /// the last frame that used the same slot has completed.
    pub fn slot(&self) -> usize {
        (self.frame % self.frames_in_flight as u64) as usize
    }

    fn add<R: ResourceType>(
        &mut self,
        name: &str,
        desc: R::Desc,
        any: AnyDesc,
        lifetime: Lifetime,
    ) -> Handle<R> {
        let id = ResourceId(self.resources.len() as u32);
        self.resources.push(ResourceDecl {
            name: name.to_owned(),
            desc: any,
            lifetime,
            latest: 0,
        });
        self.externals.push(None);
        Handle::new(id, desc)
    }

    /// A transient image, created (and possibly aliased) by the graph for this frame.
    pub fn create_image(&mut self, name: &str, desc: ImageDesc) -> Handle<Image> {
        self.add(name, desc, AnyDesc::Image(desc), Lifetime::Transient)
    }

    /// A transient buffer, created (and possibly aliased) by the graph for this frame.
    pub fn create_buffer(&mut self, name: &str, desc: BufferDesc) -> Handle<Buffer> {
        self.add(name, desc, AnyDesc::Buffer(desc), Lifetime::Transient)
    }

    /// An image owned by the caller. Writing it makes the passes that do so outputs of the graph.
    pub fn import_image(
        &mut self,
        name: &str,
        desc: ImageDesc,
        import: ImageImport,
    ) -> Handle<Image> {
        self.add(
            name,
            desc,
            AnyDesc::Image(desc),
            Lifetime::Imported(import.into()),
        )
    }

    /// A buffer owned by the caller. Writing it makes the passes that do so outputs of the graph.
    pub fn import_buffer(
        &mut self,
        name: &str,
        desc: BufferDesc,
        import: BufferImport,
    ) -> Handle<Buffer> {
        self.add(
            name,
            desc,
            AnyDesc::Buffer(desc),
            Lifetime::Imported(import.into()),
        )
    }

    /// An imported image with the Vulkan objects the executor records with. The caller keeps
    /// them alive until the GPU is done with the frame; `view` must cover the whole image.
    pub fn import_vk_image(
        &mut self,
        name: &str,
        desc: ImageDesc,
        import: ImageImport,
        image: vk::Image,
        view: vk::ImageView,
    ) -> Handle<Image> {
        let handle = self.import_image(name, desc, import);
        self.externals[handle.id.0 as usize] = Some(External::Image { image, view });
        handle
    }

    /// An imported buffer with the Vulkan buffer the executor records with (kept alive by the
    /// caller until the GPU is done with the frame).
    pub fn import_vk_buffer(
        &mut self,
        name: &str,
        desc: BufferDesc,
        import: BufferImport,
        buffer: vk::Buffer,
    ) -> Handle<Buffer> {
        let handle = self.import_buffer(name, desc, import);
        self.externals[handle.id.0 as usize] = Some(External::Buffer(buffer));
        handle
    }

    /// Imports a shine-gpu buffer (its size and usage describe it).
    pub fn import_gpu_buffer(
        &mut self,
        buffer: &shine_gpu::Buffer,
        initial: crate::ExternalState,
        final_state: crate::ExternalState,
    ) -> Handle<Buffer> {
        let import = BufferImport {
            initial,
            final_state,
            usage: buffer.usage(),
            read_only: false,
        };
        self.import_vk_buffer(
            buffer.name(),
            BufferDesc::new(buffer.size()),
            import,
            buffer.raw(),
        )
    }

    /// Imports a shine-gpu image (its extent, format, mips, layers and usage describe it).
    pub fn import_gpu_image(
        &mut self,
        image: &shine_gpu::Image,
        initial: crate::ExternalState,
        final_state: crate::ExternalState,
    ) -> Handle<Image> {
        let range = image.full_range();
        let [w, h] = image.extent();
        let desc = ImageDesc::new_2d(image.format(), w, h)
            .with_mips(range.level_count)
            .with_layers(range.layer_count);
        let import = ImageImport {
            initial,
            final_state,
            usage: image.usage(),
            read_only: false,
        };
        self.import_vk_image(image.name(), desc, import, image.raw(), image.view())
    }

    /// An image kept across frames under `key`; version 0 holds what the last frame left in it
    /// (undefined contents the first time, see [`crate::Compiler::has_history`]).
    pub fn temporal_image(&mut self, key: &str, desc: ImageDesc) -> Handle<Image> {
        self.add(
            key,
            desc,
            AnyDesc::Image(desc),
            Lifetime::Temporal(key.to_owned()),
        )
    }

    /// A buffer kept across frames under `key`, like [`RenderGraph::temporal_image`].
    pub fn temporal_buffer(&mut self, key: &str, desc: BufferDesc) -> Handle<Buffer> {
        self.add(
            key,
            desc,
            AnyDesc::Buffer(desc),
            Lifetime::Temporal(key.to_owned()),
        )
    }

    fn history_keys(&self, key: &str) -> (String, String) {
        let parity = self.frame % 2;
        (format!("{key}#{}", 1 - parity), format!("{key}#{parity}"))
    }

    /// A ping-pong pair of temporal images under `key`: read `previous`, write `current`;
    /// they swap roles every frame.
    pub fn history_image(&mut self, key: &str, desc: ImageDesc) -> History<Image> {
        let (prev, cur) = self.history_keys(key);
        let history = History {
            previous: self.temporal_image(&prev, desc),
            current: self.temporal_image(&cur, desc),
        };
        self.pairs.push((history.previous.id, history.current.id));
        history
    }

    /// A ping-pong pair of temporal buffers under `key`, like [`RenderGraph::history_image`].
    pub fn history_buffer(&mut self, key: &str, desc: BufferDesc) -> History<Buffer> {
        let (prev, cur) = self.history_keys(key);
        let history = History {
            previous: self.temporal_buffer(&prev, desc),
            current: self.temporal_buffer(&cur, desc),
        };
        self.pairs.push((history.previous.id, history.current.id));
        history
    }

    /// Declare a pass whose accesses are given through the returned builder.
    pub fn pass(&mut self, name: &str, kind: PassKind) -> PassBuilder<'_> {
        let id = PassId(self.passes.len() as u32);
        self.passes.push(PassDecl {
            name: name.to_owned(),
            kind,
            accesses: Vec::new(),
            rate: UpdateRate::EVERY_FRAME,
            cost: None,
        });
        self.works.push(Work::Declared);
        PassBuilder { graph: self, id }
    }

    /// Number of declared passes.
    pub fn pass_count(&self) -> usize {
        self.passes.len()
    }
}

/// Declares the accesses of one pass. Obtained from [`RenderGraph::pass`].
#[derive(Debug)]
pub struct PassBuilder<'g> {
    pub(crate) graph: &'g mut RenderGraph,
    pub(crate) id: PassId,
}

impl PassBuilder<'_> {
    /// The pass being declared.
    pub fn id(&self) -> PassId {
        self.id
    }

    /// Declares the pass's work per run ([`PassCost`]), reported by the executor's timings.
    pub fn cost(&mut self, cost: PassCost) -> &mut Self {
        self.graph.passes[self.id.0 as usize].cost = Some(cost);
        self
    }

    fn record(
        &mut self,
        resource: ResourceId,
        version: u32,
        direction: Direction,
        access: AnyAccess,
    ) {
        self.graph.passes[self.id.0 as usize]
            .accesses
            .push(AccessRecord {
                resource,
                version,
                direction,
                access,
            });
    }

    pub(crate) fn bump<R: ResourceType>(&mut self, handle: &mut Handle<R>) -> u32 {
        let Some(res) = self.graph.resources.get_mut(handle.id.0 as usize) else {
            self.graph.errors.push(GraphError::UnknownResource {
                resource: handle.id,
            });
            return handle.version;
        };
        if res.latest != handle.version {
            let err = GraphError::StaleWrite {
                pass: self.graph.passes[self.id.0 as usize].name.clone(),
                resource: res.name.clone(),
                version: handle.version,
                latest: res.latest,
            };
            self.graph.errors.push(err);
        }
        let before = handle.version;
        res.latest = res.latest.max(handle.version) + 1;
        handle.version = res.latest;
        before
    }

    /// The pass reads this version of a resource.
    pub fn read<R: ResourceType>(&mut self, handle: &Handle<R>, access: R::Access) -> &mut Self {
        self.record(
            handle.id,
            handle.version,
            Direction::Read,
            R::any_access(access),
        );
        self
    }

    /// The pass writes a resource (keeping what it does not overwrite); the handle advances to
    /// the version written.
    pub fn write<R: ResourceType>(
        &mut self,
        handle: &mut Handle<R>,
        access: R::Access,
    ) -> &mut Self {
        let before = self.bump(handle);
        self.record(handle.id, before, Direction::Write, R::any_access(access));
        self
    }

    /// Run this pass only on frames where `frame % period == phase`.
    pub fn run_every(&mut self, period: u32, phase: u32) -> &mut Self {
        self.graph.passes[self.id.0 as usize].rate = UpdateRate { period, phase };
        self
    }
}
