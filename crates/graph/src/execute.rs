//! Execution: compile (cached), create or reuse the graph's own resources, and record every pass
//! with its barriers, a debug label and a GPU timestamp scope into the caller's command buffer.

use std::sync::Arc;

use shine_gpu::{
    ComputePipeline, Descriptor, DescriptorArena, Device, GraphicsPipeline, PipelineLayout, vk,
};

use crate::barrier::Barrier;
use crate::compiler::Compiler;
use crate::error::ExecuteError;
use crate::gpu_resources::{DeviceMemory, GpuResource};
use crate::graph::RenderGraph;
use crate::handle::ResourceId;
use crate::objects::GraphObjects;
use crate::pipelines::PipelineCache;
use crate::plan::{Plan, PlannedPass};
use crate::raw::RawContext;
use crate::resource::AnyDesc;
use crate::timing::{PassTiming, SlotTimestamps};
use crate::work::{Bound, ComputeWork, Draw, RasterWork, TransferOp, Work};

/// Per-slot recording state: descriptor sets and timestamps of one frame in flight.
struct FrameSlot {
    descriptors: DescriptorArena,
    timestamps: SlotTimestamps,
}

/// Runs render graphs on a device, frame after frame.
///
/// The caller owns the command buffers and their submission (so a host engine can embed the
/// graph). Contract: before `execute` records frame `f`, the submission of frame
/// `f - frames_in_flight` has completed; [`Executor::timings`] is called only once the frames it
/// reads have completed. Frame `f` records with slot `f % frames_in_flight`: its own transient
/// resources, descriptor sets and timestamps, so frames in flight share none of them.
pub struct Executor {
    device: Device,
    compiler: Compiler,
    slots: Vec<FrameSlot>,
    frame: u64,
    pipelines: PipelineCache,
    objects: GraphObjects,
    timings: Vec<PassTiming>,
}

impl std::fmt::Debug for Executor {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Executor")
            .field("frame", &self.frame)
            .field("frames_in_flight", &self.slots.len())
            .finish_non_exhaustive()
    }
}

fn image_extent(plan: &Plan, id: ResourceId) -> vk::Extent3D {
    match plan.resource(id).map(|r| r.desc) {
        Some(AnyDesc::Image(d)) => d.extent,
        _ => vk::Extent3D::default(),
    }
}

fn image_range(plan: &Plan, id: ResourceId) -> vk::ImageSubresourceRange {
    match plan.resource(id).map(|r| r.desc) {
        Some(AnyDesc::Image(d)) => d.full_range(),
        _ => vk::ImageSubresourceRange::default(),
    }
}

fn buffer_size(plan: &Plan, id: ResourceId) -> u64 {
    match plan.resource(id).map(|r| r.desc) {
        Some(AnyDesc::Buffer(d)) => d.size,
        _ => 0,
    }
}

/// Everything recording needs besides the pipelines.
struct Recorder<'a> {
    device: &'a Device,
    cb: vk::CommandBuffer,
    plan: &'a Plan,
    objects: &'a [Option<GpuResource>],
}

impl Recorder<'_> {
    fn image(&self, id: ResourceId) -> (vk::Image, vk::ImageView) {
        match self.objects[id.0 as usize] {
            Some(GpuResource::Image { image, view }) => (image, view),
            _ => (vk::Image::null(), vk::ImageView::null()),
        }
    }

    fn buffer(&self, id: ResourceId) -> vk::Buffer {
        match self.objects[id.0 as usize] {
            Some(GpuResource::Buffer(b)) => b,
            _ => vk::Buffer::null(),
        }
    }

    fn barriers(&self, barriers: &[Barrier]) {
        if barriers.is_empty() {
            return;
        }
        let mut images = Vec::new();
        let mut buffers = Vec::new();
        for b in barriers {
            match self.objects[b.resource.0 as usize] {
                Some(GpuResource::Image { image, .. }) => images.push(
                    vk::ImageMemoryBarrier2::default()
                        .src_stage_mask(b.src.stage)
                        .src_access_mask(b.src.access)
                        .dst_stage_mask(b.dst.stage)
                        .dst_access_mask(b.dst.access)
                        .old_layout(b.old_layout)
                        .new_layout(b.new_layout)
                        .src_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
                        .dst_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
                        .image(image)
                        .subresource_range(image_range(self.plan, b.resource)),
                ),
                Some(GpuResource::Buffer(buffer)) => buffers.push(
                    vk::BufferMemoryBarrier2::default()
                        .src_stage_mask(b.src.stage)
                        .src_access_mask(b.src.access)
                        .dst_stage_mask(b.dst.stage)
                        .dst_access_mask(b.dst.access)
                        .src_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
                        .dst_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
                        .buffer(buffer)
                        .offset(0)
                        .size(vk::WHOLE_SIZE),
                ),
                None => {}
            }
        }
        let dependency = vk::DependencyInfo::default()
            .image_memory_barriers(&images)
            .buffer_memory_barriers(&buffers);
        // SAFETY: `cb` is recording; every object belongs to this device and lives for the frame.
        unsafe {
            self.device
                .raw()
                .cmd_pipeline_barrier2(self.cb, &dependency)
        };
    }

    /// The descriptors of `bindings`. An image is described in the layout the plan gives it
    /// in `pass` (a sampled depth attachment is in DEPTH_STENCIL_READ_ONLY_OPTIMAL), which is
    /// the binding's own layout otherwise.
    fn descriptors(
        &self,
        pass: &PlannedPass,
        bindings: &[(&'static str, Bound)],
    ) -> Vec<(&'static str, Descriptor)> {
        bindings
            .iter()
            .map(|(name, bound)| {
                let d = match *bound {
                    Bound::Sampler(s) => Descriptor::Sampler(s),
                    Bound::Resource(id, bound_layout) => match self.objects[id.0 as usize] {
                        Some(GpuResource::Image { view, .. }) => Descriptor::Image {
                            view,
                            layout: pass
                                .resources
                                .iter()
                                .find(|r| r.resource == id)
                                .map_or(bound_layout, |r| r.info.layout),
                        },
                        _ => Descriptor::Buffer {
                            buffer: self.buffer(id),
                            offset: 0,
                            range: vk::WHOLE_SIZE,
                        },
                    },
                };
                (*name, d)
            })
            .collect()
    }

    fn push(&self, layout: &PipelineLayout, data: &[u8]) -> Result<(), ExecuteError> {
        let (size, stages) = layout.push_constants;
        if data.len() != size as usize {
            return Err(shine_gpu::Error::Binding {
                pipeline: layout.name.clone(),
                message: format!(
                    "push constants are {size} bytes in the shader, {} given",
                    data.len()
                ),
            }
            .into());
        }
        if size > 0 {
            // SAFETY: the range matches the layout's push-constant range.
            unsafe {
                self.device
                    .raw()
                    .cmd_push_constants(self.cb, layout.raw, stages, 0, data)
            };
        }
        Ok(())
    }

    fn compute(
        &self,
        pass: &PlannedPass,
        work: &ComputeWork,
        pipeline: &ComputePipeline,
        arena: &mut DescriptorArena,
    ) -> Result<(), ExecuteError> {
        let raw = self.device.raw();
        // SAFETY: `cb` is recording; the pipeline belongs to this device.
        unsafe { raw.cmd_bind_pipeline(self.cb, vk::PipelineBindPoint::COMPUTE, pipeline.raw()) };
        arena.bind(
            self.cb,
            vk::PipelineBindPoint::COMPUTE,
            pipeline.layout(),
            &self.descriptors(pass, &work.bindings),
        )?;
        self.push(pipeline.layout(), &work.push)?;
        let [x, y, z] = work.shader.groups_for(work.threads);
        // SAFETY: a compute pipeline and its sets are bound.
        unsafe { raw.cmd_dispatch(self.cb, x, y, z) };
        Ok(())
    }

    fn raster(
        &self,
        pass: &PlannedPass,
        work: &RasterWork,
        pipeline: &GraphicsPipeline,
        arena: &mut DescriptorArena,
        attachment: impl Fn(ResourceId) -> (vk::ImageLayout, vk::AttachmentStoreOp),
    ) -> Result<(), ExecuteError> {
        let raw = self.device.raw();
        let first = work.colors.first().or(work.depth.as_ref());
        let extent = first.map_or_else(vk::Extent3D::default, |a| {
            image_extent(self.plan, a.resource)
        });
        let whole = vk::Rect2D {
            offset: vk::Offset2D::default(),
            extent: vk::Extent2D {
                width: extent.width,
                height: extent.height,
            },
        };
        // Checked against every attachment before recording began (`check_area`).
        let area = work.area.unwrap_or(whole);
        let colors: Vec<vk::RenderingAttachmentInfo<'_>> = work
            .colors
            .iter()
            .map(|a| {
                let (layout, store) = attachment(a.resource);
                vk::RenderingAttachmentInfo::default()
                    .image_view(self.image(a.resource).1)
                    .image_layout(layout)
                    .load_op(a.load)
                    .store_op(store)
                    .clear_value(vk::ClearValue {
                        color: vk::ClearColorValue { float32: a.clear },
                    })
            })
            .collect();
        let depth = work.depth.map(|a| {
            let (layout, store) = attachment(a.resource);
            vk::RenderingAttachmentInfo::default()
                .image_view(self.image(a.resource).1)
                .image_layout(layout)
                .load_op(a.load)
                .store_op(store)
                .clear_value(vk::ClearValue {
                    depth_stencil: vk::ClearDepthStencilValue {
                        depth: a.clear[0],
                        stencil: 0,
                    },
                })
        });
        let mut rendering = vk::RenderingInfo::default()
            .render_area(area)
            .layer_count(1)
            .color_attachments(&colors);
        if let Some(d) = depth.as_ref() {
            rendering = rendering.depth_attachment(d);
        }
        let viewport = vk::Viewport {
            x: area.offset.x as f32,
            y: area.offset.y as f32,
            width: area.extent.width as f32,
            height: area.extent.height as f32,
            min_depth: 0.0,
            max_depth: 1.0,
        };
        // SAFETY: `cb` is recording outside rendering; attachments are in the planned layouts.
        unsafe {
            raw.cmd_begin_rendering(self.cb, &rendering);
            raw.cmd_bind_pipeline(self.cb, vk::PipelineBindPoint::GRAPHICS, pipeline.raw());
            raw.cmd_set_viewport(self.cb, 0, &[viewport]);
            raw.cmd_set_scissor(self.cb, 0, &[area]);
        }
        let bound = arena
            .bind(
                self.cb,
                vk::PipelineBindPoint::GRAPHICS,
                pipeline.layout(),
                &self.descriptors(pass, &work.bindings),
            )
            .map_err(ExecuteError::from)
            .and_then(|()| self.push(pipeline.layout(), &work.push));
        if bound.is_ok() {
            let buffers: Vec<vk::Buffer> = work
                .vertex_buffers
                .iter()
                .map(|&b| self.buffer(b))
                .collect();
            let offsets = vec![0; buffers.len()];
            // SAFETY: the pipeline is bound inside rendering; buffers live for the frame.
            unsafe {
                if !buffers.is_empty() {
                    raw.cmd_bind_vertex_buffers(self.cb, 0, &buffers, &offsets);
                }
                if let Some((index, index_type)) = work.index_buffer {
                    raw.cmd_bind_index_buffer(self.cb, self.buffer(index), 0, index_type);
                }
                for draw in &work.draws {
                    match *draw {
                        Draw::Vertices { count, instances } => {
                            raw.cmd_draw(self.cb, count, instances, 0, 0)
                        }
                        Draw::Indexed { count, instances } => {
                            raw.cmd_draw_indexed(self.cb, count, instances, 0, 0, 0)
                        }
                    }
                }
            }
        }
        // SAFETY: rendering was begun above in this command buffer.
        unsafe { raw.cmd_end_rendering(self.cb) };
        bound
    }

    fn transfer(&self, op: TransferOp) {
        let raw = self.device.raw();
        let layer0 = |id: ResourceId| {
            let range = image_range(self.plan, id);
            vk::ImageSubresourceLayers {
                aspect_mask: range.aspect_mask,
                mip_level: 0,
                base_array_layer: 0,
                layer_count: 1,
            }
        };
        let corner = |id: ResourceId| {
            let e = image_extent(self.plan, id);
            vk::Offset3D {
                x: e.width as i32,
                y: e.height as i32,
                z: e.depth as i32,
            }
        };
        let copy = |image: ResourceId| vk::BufferImageCopy {
            buffer_offset: 0,
            buffer_row_length: 0,
            buffer_image_height: 0,
            image_subresource: layer0(image),
            image_offset: vk::Offset3D::default(),
            image_extent: image_extent(self.plan, image),
        };
        let cb = self.cb;
        // SAFETY: `cb` is recording outside rendering; the plan put every resource in the
        // layout and scope of its transfer access.
        unsafe {
            match op {
                TransferOp::CopyBuffer { src, dst } => {
                    let size = buffer_size(self.plan, src).min(buffer_size(self.plan, dst));
                    let region = vk::BufferCopy {
                        src_offset: 0,
                        dst_offset: 0,
                        size,
                    };
                    raw.cmd_copy_buffer(cb, self.buffer(src), self.buffer(dst), &[region]);
                }
                TransferOp::CopyImageToBuffer { src, dst } => raw.cmd_copy_image_to_buffer(
                    cb,
                    self.image(src).0,
                    vk::ImageLayout::TRANSFER_SRC_OPTIMAL,
                    self.buffer(dst),
                    &[copy(src)],
                ),
                TransferOp::CopyBufferToImage { src, dst } => raw.cmd_copy_buffer_to_image(
                    cb,
                    self.buffer(src),
                    self.image(dst).0,
                    vk::ImageLayout::TRANSFER_DST_OPTIMAL,
                    &[copy(dst)],
                ),
                TransferOp::ClearImage { dst, color } => raw.cmd_clear_color_image(
                    cb,
                    self.image(dst).0,
                    vk::ImageLayout::TRANSFER_DST_OPTIMAL,
                    &vk::ClearColorValue { float32: color },
                    &[image_range(self.plan, dst)],
                ),
                TransferOp::FillBuffer { dst, value } => {
                    raw.cmd_fill_buffer(cb, self.buffer(dst), 0, vk::WHOLE_SIZE, value)
                }
                TransferOp::Blit { src, dst, filter } => {
                    let region = vk::ImageBlit {
                        src_subresource: layer0(src),
                        src_offsets: [vk::Offset3D::default(), corner(src)],
                        dst_subresource: layer0(dst),
                        dst_offsets: [vk::Offset3D::default(), corner(dst)],
                    };
                    raw.cmd_blit_image(
                        cb,
                        self.image(src).0,
                        vk::ImageLayout::TRANSFER_SRC_OPTIMAL,
                        self.image(dst).0,
                        vk::ImageLayout::TRANSFER_DST_OPTIMAL,
                        &[region],
                        filter,
                    )
                }
            }
        }
    }
}

impl Executor {
    /// An executor for `device` with `frames_in_flight` (at least 1) recordings in flight.
    pub fn new(device: &Device, frames_in_flight: usize) -> Result<Self, ExecuteError> {
        let slots = (0..frames_in_flight.max(1))
            .map(|_| {
                Ok(FrameSlot {
                    descriptors: DescriptorArena::new(device),
                    timestamps: SlotTimestamps::new(device)?,
                })
            })
            .collect::<Result<Vec<_>, shine_gpu::Error>>()?;
        Ok(Self {
            device: device.clone(),
            compiler: Compiler::new(),
            slots,
            frame: 0,
            pipelines: PipelineCache::default(),
            objects: GraphObjects::default(),
            timings: Vec::new(),
        })
    }

    /// An empty graph for the next frame.
    pub fn begin_frame(&self) -> RenderGraph {
        RenderGraph::new(self.frame)
    }

    /// The number of the next frame.
    pub fn frame(&self) -> u64 {
        self.frame
    }

    /// The compiler (plan cache and temporal history).
    pub fn compiler(&self) -> &Compiler {
        &self.compiler
    }

    /// Compiles `graph` (cached while its shape is unchanged) and records it into `cb`, which
    /// must be recording outside a render pass. Returns the plan it ran.
    ///
    /// Compilation, resource creation and pipeline creation happen before anything is recorded:
    /// an error from them leaves `cb` untouched. An error while recording (a raw pass's, a
    /// binding or push-constant mismatch) leaves every debug label and timestamp scope closed
    /// but the frame half recorded: don't submit `cb` after any error, and the frame is not
    /// counted.
    pub fn execute(
        &mut self,
        cb: vk::CommandBuffer,
        graph: RenderGraph,
    ) -> Result<Arc<Plan>, ExecuteError> {
        self.run(graph, Some(cb)).map(|(plan, _)| plan)
    }

    /// Compiles and runs `graph` one pass at a time: each pass (with its barriers) is recorded
    /// into its own command buffer, submitted and waited for, and timed on the host from submit
    /// to completion. Returns the plan and the host times of its passes (origin: the first
    /// submit).
    ///
    /// For devices whose timestamps do not bracket the work of a pass (lavapipe writes them when
    /// it flushes rasterisation, not when a compute dispatch runs): the times are exact up to a
    /// submission's overhead (tens of µs), at the cost of serialising the frame.
    pub fn execute_serialized(
        &mut self,
        graph: RenderGraph,
    ) -> Result<(Arc<Plan>, Vec<PassTiming>), ExecuteError> {
        self.run(graph, None)
    }

    /// [`Executor::execute`] into `cb`, or [`Executor::execute_serialized`] when `cb` is `None`.
    fn run(
        &mut self,
        mut graph: RenderGraph,
        cb: Option<vk::CommandBuffer>,
    ) -> Result<(Arc<Plan>, Vec<PassTiming>), ExecuteError> {
        let plan = self.compiler.compile(&graph, &DeviceMemory(&self.device))?;
        let slot_index = (self.frame % self.slots.len() as u64) as usize;
        let set = self
            .objects
            .transients_for(&self.device, &plan, slot_index, self.slots.len())?;
        self.objects.ensure_temporal(&self.device, &plan)?;
        for pass in &plan.passes {
            match &graph.works[pass.id.0 as usize] {
                Work::Compute(c) => {
                    self.pipelines.compute(&self.device, c.shader)?;
                }
                Work::Raster(r) => {
                    check_area(&plan, pass, r)?;
                    self.pipelines.graphics(&self.device, &r.pipeline)?;
                }
                Work::Declared | Work::Transfer(_) | Work::Raw(_) => {}
            }
        }

        let objects = self.objects.table(&plan, set, &graph.externals)?;

        let slot = &mut self.slots[slot_index];
        self.timings.extend(slot.timestamps.take()?);
        slot.descriptors.reset()?;
        if let Some(cb) = cb {
            slot.timestamps.pool.reset(cb);
        }
        let mut host_timings = Vec::new();
        let start = std::time::Instant::now();
        for (position, pass) in plan.passes.iter().enumerate() {
            // Serialized: a command buffer of its own for this pass.
            let mut own = match cb {
                Some(_) => None,
                None => Some(self.device.begin_commands()?),
            };
            let pass_cb = cb.or(own.as_mut().map(|c| c.raw())).unwrap_or_default();
            let recorder = Recorder {
                device: &self.device,
                cb: pass_cb,
                plan: &plan,
                objects: &objects,
            };
            recorder.barriers(&pass.barriers);
            if cb.is_some() {
                slot.timestamps.pool.begin(pass_cb, &pass.name)?;
            }
            self.device.begin_label(pass_cb, &pass.name);
            let work = std::mem::replace(&mut graph.works[pass.id.0 as usize], Work::Declared);
            let recorded = match work {
                Work::Declared => Ok(()),
                // The pipelines were created above; an error here still closes the scopes.
                Work::Compute(c) => self
                    .pipelines
                    .compute(&self.device, c.shader)
                    .map_err(ExecuteError::from)
                    .and_then(|p| recorder.compute(pass, &c, p, &mut slot.descriptors)),
                Work::Raster(r) => {
                    // Store ops follow from the plan: nothing for a read-only depth, don't-care
                    // at a transient's last use, store otherwise.
                    let attachment = |id: ResourceId| {
                        let layout = pass
                            .resources
                            .iter()
                            .find(|p| p.resource == id)
                            .map_or(vk::ImageLayout::UNDEFINED, |p| p.info.layout);
                        let last_use = plan
                            .memory
                            .placement(id)
                            .is_some_and(|p| p.lifetime.1 == position);
                        let store = if layout == vk::ImageLayout::DEPTH_STENCIL_READ_ONLY_OPTIMAL {
                            vk::AttachmentStoreOp::NONE
                        } else if last_use {
                            vk::AttachmentStoreOp::DONT_CARE
                        } else {
                            vk::AttachmentStoreOp::STORE
                        };
                        (layout, store)
                    };
                    self.pipelines
                        .graphics(&self.device, &r.pipeline)
                        .map_err(ExecuteError::from)
                        .and_then(|p| {
                            recorder.raster(pass, &r, p, &mut slot.descriptors, attachment)
                        })
                }
                Work::Transfer(op) => {
                    recorder.transfer(op);
                    Ok(())
                }
                Work::Raw(f) => {
                    let mut ctx = RawContext::new(&self.device, pass_cb, &objects);
                    f(&mut ctx).map_err(ExecuteError::from)
                }
            };
            self.device.end_label(pass_cb);
            if cb.is_some() {
                slot.timestamps.pool.end(pass_cb)?;
            }
            recorded?;
            if let Some(commands) = own {
                let begin_ns = start.elapsed().as_secs_f64() * 1e9;
                self.device.submit(commands)?.wait()?;
                host_timings.push(PassTiming {
                    name: pass.name.clone(),
                    begin_ns,
                    end_ns: start.elapsed().as_secs_f64() * 1e9,
                    frame: self.frame,
                });
            }
        }
        match cb {
            Some(cb) => {
                Recorder {
                    device: &self.device,
                    cb,
                    plan: &plan,
                    objects: &objects,
                }
                .barriers(&plan.final_barriers);
                slot.timestamps.recorded(self.frame);
            }
            None => {
                let mut commands = self.device.begin_commands()?;
                Recorder {
                    device: &self.device,
                    cb: commands.raw(),
                    plan: &plan,
                    objects: &objects,
                }
                .barriers(&plan.final_barriers);
                self.device.submit(commands)?.wait()?;
            }
        }
        self.compiler.finish_frame(&plan);
        self.frame += 1;
        Ok((plan, host_timings))
    }

    /// Per-pass GPU times of every executed frame not reported yet, oldest first. Call only
    /// once those frames' submissions have completed.
    pub fn timings(&mut self) -> Result<Vec<PassTiming>, ExecuteError> {
        let mut unread: Vec<&mut SlotTimestamps> = self
            .slots
            .iter_mut()
            .map(|s| &mut s.timestamps)
            .filter(|t| t.unread().is_some())
            .collect();
        unread.sort_by_key(|t| t.unread());
        for timestamps in unread {
            self.timings.extend(timestamps.take()?);
        }
        Ok(std::mem::take(&mut self.timings))
    }
}

/// A raster pass's area ([`crate::RasterPass::area`]) must lie inside every attachment.
fn check_area(plan: &Plan, pass: &PlannedPass, work: &RasterWork) -> Result<(), ExecuteError> {
    let Some(area) = work.area else {
        return Ok(());
    };
    let attachments = work.colors.iter().chain(work.depth.as_ref());
    for a in attachments {
        let extent = image_extent(plan, a.resource);
        let (x, y) = (area.offset.x.max(0) as u32, area.offset.y.max(0) as u32);
        let inside = area.offset.x >= 0
            && area.offset.y >= 0
            && u64::from(x) + u64::from(area.extent.width) <= u64::from(extent.width)
            && u64::from(y) + u64::from(area.extent.height) <= u64::from(extent.height);
        if !inside {
            return Err(ExecuteError::RenderArea {
                pass: pass.name.clone(),
                x,
                y,
                width: area.extent.width,
                height: area.extent.height,
                attachment_width: extent.width,
                attachment_height: extent.height,
            });
        }
    }
    Ok(())
}

impl Drop for Executor {
    fn drop(&mut self) {
        // Wait first: freeing memory (a `MemoryBlock` drop) does not wait for submissions the
        // caller made itself. If waiting fails the device is lost and nothing can still be
        // using the objects.
        let _ = self.device.wait_idle();
        self.objects.destroy(&self.device);
    }
}
