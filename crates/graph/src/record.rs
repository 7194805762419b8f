//! Recording of planned passes into a command buffer: barriers, then the pass's work (a
//! dispatch, draws inside dynamic rendering, a transfer or a raw closure) with its pipeline,
//! descriptor sets and push constants. Also the render-area check every raster pass passes
//! before anything is recorded.

use shine_gpu::{
    ComputePipeline, Descriptor, DescriptorArena, Device, GraphicsPipeline, PipelineLayout, vk,
};

use crate::barrier::Barrier;
use crate::error::ExecuteError;
use crate::gpu_resources::GpuResource;
use crate::handle::ResourceId;
use crate::pipelines::PipelineCache;
use crate::plan::{Plan, PlannedPass};
use crate::raw::RawContext;
use crate::resource::AnyDesc;
use crate::work::{Bound, ComputeWork, Draw, RasterWork, TransferOp, Work};

/// The extent of image `id` (zero when it is not an image of `plan`).
fn image_extent(plan: &Plan, id: ResourceId) -> vk::Extent3D {
    match plan.resource(id).map(|r| r.desc) {
        Some(AnyDesc::Image(d)) => d.extent,
        _ => vk::Extent3D::default(),
    }
}

/// How a tightly packed buffer of `bytes` fills 2D image `id`: its whole rows (all of them when
/// it holds the whole image, or the image is not a single-layer 2D image of a known texel
/// size), the texels of the next, partly filled row (0 when there is none or the image has no
/// room for it) and the bytes of a row: a buffer→image copy's two regions.
fn buffer_rows(plan: &Plan, bytes: u64, id: ResourceId) -> (u32, u32, u64) {
    let Some(AnyDesc::Image(d)) = plan.resource(id).map(|r| r.desc) else {
        return (0, 0, 0);
    };
    let height = d.extent.height;
    match shine_gpu::format_texel_size(d.format) {
        Some(texel) if d.extent.depth == 1 && d.layers == 1 => {
            let row = u64::from(d.extent.width) * u64::from(texel);
            let rows = (bytes / row.max(1)).min(u64::from(height)) as u32;
            let rest = if rows < height {
                ((bytes - u64::from(rows) * row) / u64::from(texel)) as u32
            } else {
                0
            };
            (rows, rest, row)
        }
        _ => (height, 0, 0),
    }
}

/// Every mip and layer of image `id` (an empty range when it is not an image of `plan`).
fn image_range(plan: &Plan, id: ResourceId) -> vk::ImageSubresourceRange {
    match plan.resource(id).map(|r| r.desc) {
        Some(AnyDesc::Image(d)) => d.full_range(),
        _ => vk::ImageSubresourceRange::default(),
    }
}

/// The size of buffer `id` (zero when it is not a buffer of `plan`).
fn buffer_size(plan: &Plan, id: ResourceId) -> u64 {
    match plan.resource(id).map(|r| r.desc) {
        Some(AnyDesc::Buffer(d)) => d.size,
        _ => 0,
    }
}

/// Everything recording needs besides the pipelines and descriptor sets.
pub(crate) struct Recorder<'a> {
    device: &'a Device,
    cb: vk::CommandBuffer,
    plan: &'a Plan,
    /// The object behind each resource of `plan`, indexed by resource id.
    objects: &'a [Option<GpuResource>],
}

impl<'a> Recorder<'a> {
    /// A recorder into `cb` of `plan`'s passes, whose resources are `objects` (indexed by
    /// resource id).
    pub fn new(
        device: &'a Device,
        cb: vk::CommandBuffer,
        plan: &'a Plan,
        objects: &'a [Option<GpuResource>],
    ) -> Self {
        Self {
            device,
            cb,
            plan,
            objects,
        }
    }

    /// The image and view behind `id` (null handles when it has none).
    fn image(&self, id: ResourceId) -> (vk::Image, vk::ImageView) {
        match self.objects[id.0 as usize] {
            Some(GpuResource::Image { image, view }) => (image, view),
            _ => (vk::Image::null(), vk::ImageView::null()),
        }
    }

    /// The buffer behind `id` (a null handle when it has none).
    fn buffer(&self, id: ResourceId) -> vk::Buffer {
        match self.objects[id.0 as usize] {
            Some(GpuResource::Buffer(b)) => b,
            _ => vk::Buffer::null(),
        }
    }

    /// Records `barriers` as one dependency (nothing when there are none).
    pub fn barriers(&self, barriers: &[Barrier]) {
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

    /// Pushes `data`, which must be as large as the layout's push-constant range.
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

    /// Records `work`, the work of `pass` at `position` in the plan, with pipelines from
    /// `pipelines` (created before recording began) and descriptor sets from `arena`.
    pub fn work(
        &self,
        pass: &PlannedPass,
        position: usize,
        work: Work,
        pipelines: &mut PipelineCache,
        arena: &mut DescriptorArena,
    ) -> Result<(), ExecuteError> {
        match work {
            Work::Declared => Ok(()),
            Work::Compute(c) => {
                let pipeline = pipelines.compute(self.device, c.shader)?;
                self.compute(pass, &c, pipeline, arena)
            }
            Work::Raster(r) => {
                let pipeline = pipelines.graphics(self.device, &r.pipeline)?;
                self.raster(pass, &r, pipeline, arena, position)
            }
            Work::Transfer(op) => {
                self.transfer(op);
                Ok(())
            }
            Work::Raw(f) => f(&mut RawContext::new(self.device, self.cb, self.objects))
                .map_err(ExecuteError::from),
        }
    }

    /// Records a dispatch with its pipeline, descriptor sets and push constants.
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

    /// Records the draws of a raster pass inside one dynamic-rendering scope over its
    /// attachments; `position` is the pass's index in the plan. The area was checked
    /// ([`check_area`]) before recording began.
    fn raster(
        &self,
        pass: &PlannedPass,
        work: &RasterWork,
        pipeline: &GraphicsPipeline,
        arena: &mut DescriptorArena,
        position: usize,
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
        // One attachment of this pass: its view, the plan's layout and store op, its load op.
        let attachment = |resource, load, clear| {
            let (layout, store) = attachment_ops(self.plan, pass, position, resource);
            vk::RenderingAttachmentInfo::default()
                .image_view(self.image(resource).1)
                .image_layout(layout)
                .load_op(load)
                .store_op(store)
                .clear_value(clear)
        };
        let colors: Vec<vk::RenderingAttachmentInfo<'_>> = work
            .colors
            .iter()
            .map(|a| {
                let clear = vk::ClearValue {
                    color: vk::ClearColorValue { float32: a.clear },
                };
                attachment(a.resource, a.load, clear)
            })
            .collect();
        let depth = work.depth.map(|a| {
            let clear = vk::ClearValue {
                depth_stencil: vk::ClearDepthStencilValue {
                    depth: a.clear[0],
                    stencil: 0,
                },
            };
            attachment(a.resource, a.load, clear)
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

    /// Records a transfer command on whole resources.
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
                TransferOp::CopyBufferToImage { src, dst } => {
                    // The whole rows the buffer fills, then the start of the next one.
                    let (rows, rest, row_bytes) =
                        buffer_rows(self.plan, buffer_size(self.plan, src), dst);
                    let mut full = copy(dst);
                    full.image_extent.height = rows;
                    let partial = vk::BufferImageCopy {
                        buffer_offset: u64::from(rows) * row_bytes,
                        image_offset: vk::Offset3D {
                            x: 0,
                            y: rows as i32,
                            z: 0,
                        },
                        image_extent: vk::Extent3D {
                            width: rest,
                            height: 1,
                            depth: 1,
                        },
                        ..copy(dst)
                    };
                    let regions: Vec<vk::BufferImageCopy> = [(rows > 0, full), (rest > 0, partial)]
                        .into_iter()
                        .filter_map(|(some, r)| some.then_some(r))
                        .collect();
                    if !regions.is_empty() {
                        raw.cmd_copy_buffer_to_image(
                            cb,
                            self.buffer(src),
                            self.image(dst).0,
                            vk::ImageLayout::TRANSFER_DST_OPTIMAL,
                            &regions,
                        );
                    }
                }
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

/// The layout and store op of attachment `id` in `pass`, at `position` in `plan`. Store ops
/// follow from the plan: nothing for a read-only depth, don't-care at a transient's last use,
/// store otherwise.
fn attachment_ops(
    plan: &Plan,
    pass: &PlannedPass,
    position: usize,
    id: ResourceId,
) -> (vk::ImageLayout, vk::AttachmentStoreOp) {
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
}

/// A raster pass's area ([`crate::RasterPass::area`]) must lie inside every attachment.
pub(crate) fn check_area(
    plan: &Plan,
    pass: &PlannedPass,
    work: &RasterWork,
) -> Result<(), ExecuteError> {
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
