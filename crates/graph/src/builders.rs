//! One-call pass builders: compute dispatches, raster draws, transfers and raw closures.
//!
//! Shader bindings are given by their reflected NAME; the access (and so the barrier, layout
//! and usage) follows from the binding's kind and stage.

use shine_gpu::{Blend, DescriptorKind, GraphicsPipelineDesc, ShaderDesc, vk};

use crate::access::{BufferAccess, ImageAccess};
use crate::error::GraphError;
use crate::graph::{PassBuilder, RenderGraph};
use crate::handle::{Buffer, Handle, Image, ResourceType};
use crate::pass::PassKind;
use crate::raw::RawContext;
use crate::work::{
    Attachment, Bound, ColorLoad, ComputeWork, DepthLoad, Draw, RasterWork, TransferOp, Work,
};

impl RenderGraph {
    /// A compute pass running `shader` (from the generated table); bind its resources by name,
    /// then [`ComputePass::dispatch`].
    pub fn compute(&mut self, name: &str, shader: &'static ShaderDesc) -> ComputePass<'_> {
        let mut pass = self.pass(name, PassKind::Compute);
        pass.set_work(Work::Compute(ComputeWork {
            shader,
            bindings: Vec::new(),
            push: Vec::new(),
            threads: [0; 3],
        }));
        ComputePass { pass }
    }

    /// A raster pass drawing with the pipeline `pipeline` inside dynamic rendering.
    pub fn raster(&mut self, name: &str, pipeline: GraphicsPipelineDesc) -> RasterPass<'_> {
        let mut pass = self.pass(name, PassKind::Raster);
        pass.set_work(Work::Raster(Box::new(RasterWork {
            pipeline,
            colors: Vec::new(),
            depth: None,
            bindings: Vec::new(),
            vertex_buffers: Vec::new(),
            index_buffer: None,
            push: Vec::new(),
            draws: Vec::new(),
            area: None,
        })));
        RasterPass { pass }
    }

    /// A pass recording `record` with the command buffer and the resolved resources; declare
    /// what it touches on the returned builder.
    pub fn raw_pass(
        &mut self,
        name: &str,
        record: impl FnOnce(&mut RawContext<'_>) -> Result<(), shine_gpu::Error> + 'static,
    ) -> PassBuilder<'_> {
        let mut pass = self.pass(name, PassKind::Raw);
        pass.set_work(Work::Raw(Box::new(record)));
        pass
    }

    fn transfer(&mut self, name: &str, op: TransferOp) -> PassBuilder<'_> {
        let mut pass = self.pass(name, PassKind::Transfer);
        pass.set_work(Work::Transfer(op));
        pass
    }

    /// Copies a whole buffer into another (sizes must match).
    pub fn copy_buffer(
        &mut self,
        name: &str,
        src: &Handle<Buffer>,
        dst: &mut Handle<Buffer>,
    ) -> PassBuilder<'_> {
        let op = TransferOp::CopyBuffer {
            src: src.id,
            dst: dst.id,
        };
        let mut pass = self.transfer(name, op);
        pass.read(src, BufferAccess::CopySrc)
            .write(dst, BufferAccess::CopyDst);
        pass
    }

    /// Copies mip 0, layer 0 of an image into a buffer, tightly packed.
    pub fn copy_image_to_buffer(
        &mut self,
        name: &str,
        src: &Handle<Image>,
        dst: &mut Handle<Buffer>,
    ) -> PassBuilder<'_> {
        let op = TransferOp::CopyImageToBuffer {
            src: src.id,
            dst: dst.id,
        };
        let mut pass = self.transfer(name, op);
        pass.read(src, ImageAccess::CopySrc)
            .write(dst, BufferAccess::CopyDst);
        pass
    }

    /// Copies a tightly packed buffer into mip 0, layer 0 of an image. A buffer shorter than a
    /// 2D image fills the whole rows it holds from the top, then the start of the next row
    /// (uploads that rewrite the start of an image, buffers mirrored into images; the other
    /// texels keep what they hold).
    pub fn copy_buffer_to_image(
        &mut self,
        name: &str,
        src: &Handle<Buffer>,
        dst: &mut Handle<Image>,
    ) -> PassBuilder<'_> {
        let op = TransferOp::CopyBufferToImage {
            src: src.id,
            dst: dst.id,
        };
        let mut pass = self.transfer(name, op);
        pass.read(src, BufferAccess::CopySrc)
            .write(dst, ImageAccess::CopyDst);
        pass
    }

    /// Clears every mip and layer of a colour image.
    pub fn clear_image(
        &mut self,
        name: &str,
        dst: &mut Handle<Image>,
        color: [f32; 4],
    ) -> PassBuilder<'_> {
        let op = TransferOp::ClearImage { dst: dst.id, color };
        let mut pass = self.transfer(name, op);
        pass.write(dst, ImageAccess::ClearDst);
        pass
    }

    /// Fills a whole buffer with a repeated 32-bit value.
    pub fn fill_buffer(
        &mut self,
        name: &str,
        dst: &mut Handle<Buffer>,
        value: u32,
    ) -> PassBuilder<'_> {
        let op = TransferOp::FillBuffer { dst: dst.id, value };
        let mut pass = self.transfer(name, op);
        pass.write(dst, BufferAccess::Fill);
        pass
    }

    /// Blits mip 0, layer 0 of `src` onto mip 0, layer 0 of `dst`, scaling with `filter`.
    pub fn blit_image(
        &mut self,
        name: &str,
        src: &Handle<Image>,
        dst: &mut Handle<Image>,
        filter: vk::Filter,
    ) -> PassBuilder<'_> {
        let op = TransferOp::Blit {
            src: src.id,
            dst: dst.id,
            filter,
        };
        let mut pass = self.transfer(name, op);
        pass.read(src, ImageAccess::BlitSrc)
            .write(dst, ImageAccess::BlitDst);
        pass
    }
}

impl PassBuilder<'_> {
    fn set_work(&mut self, work: Work) {
        self.graph.works[self.id.0 as usize] = work;
    }

    fn work(&mut self) -> &mut Work {
        &mut self.graph.works[self.id.0 as usize]
    }

    fn fail(&mut self, binding: &str, message: String) {
        let pass = self.graph.passes[self.id.0 as usize].name.clone();
        self.graph.errors.push(GraphError::Binding {
            pass,
            binding: binding.to_owned(),
            message,
        });
    }

    /// Declares the accesses of a resource bound by name in the given shaders, returning the
    /// layout an image binding needs, or `None` after recording an error.
    fn bind_shader<R: ResourceType>(
        &mut self,
        shaders: &[&'static ShaderDesc],
        binding: &str,
        handle: &mut Handle<R>,
        write: bool,
    ) -> Option<(&'static str, vk::ImageLayout)> {
        let mut found = None;
        let before = *handle;
        for shader in shaders {
            let Some(b) = shader.binding(binding) else {
                continue;
            };
            if b.kind.writes() != write {
                let verb = if write {
                    "read-only"
                } else {
                    "writable: declare it with `write`"
                };
                self.fail(binding, format!("the binding is {verb}"));
                return None;
            }
            let Some(access) = R::shader_access(b.kind, shader.stage, write) else {
                let stage = shader.stage;
                self.fail(
                    binding,
                    format!(
                        "a {:?} binding in the {stage:?} stage cannot take this resource",
                        b.kind
                    ),
                );
                return None;
            };
            let layout = R::any_access(access).info().layout;
            if write {
                self.write(handle, access);
            } else {
                self.read(&before, access);
            }
            found = Some((b.name, layout));
        }
        if found.is_none() {
            let names: Vec<&str> = shaders
                .iter()
                .flat_map(|s| s.bindings.iter().map(|b| b.name))
                .collect();
            self.fail(
                binding,
                format!("no such binding (the shaders have: {})", names.join(", ")),
            );
        }
        found
    }
}

fn push_bytes<T: bytemuck::NoUninit>(value: &T) -> Vec<u8> {
    bytemuck::bytes_of(value).to_vec()
}

/// Builds a compute pass; see [`RenderGraph::compute`].
#[derive(Debug)]
pub struct ComputePass<'g> {
    pass: PassBuilder<'g>,
}

impl ComputePass<'_> {
    /// Applies `f` to the pass's compute work (which `RenderGraph::compute` put there).
    fn with(&mut self, f: impl FnOnce(&mut ComputeWork)) {
        if let Work::Compute(c) = self.pass.work() {
            f(c);
        }
    }

    fn shader(&mut self) -> Option<&'static ShaderDesc> {
        match self.pass.work() {
            Work::Compute(c) => Some(c.shader),
            _ => None,
        }
    }

    /// Binds a resource the shader reads (sampled image, read-only storage, uniform buffer).
    pub fn read<R: ResourceType>(&mut self, binding: &str, handle: &Handle<R>) -> &mut Self {
        let shaders: Vec<_> = self.shader().into_iter().collect();
        let mut h = *handle;
        if let Some((name, layout)) = self.pass.bind_shader(&shaders, binding, &mut h, false) {
            self.with(|w| w.bindings.push((name, Bound::Resource(h.id, layout))));
        }
        self
    }

    /// Binds a resource the shader writes (writable storage image or buffer); the handle
    /// advances to the version written.
    pub fn write<R: ResourceType>(&mut self, binding: &str, handle: &mut Handle<R>) -> &mut Self {
        let shaders: Vec<_> = self.shader().into_iter().collect();
        if let Some((name, layout)) = self.pass.bind_shader(&shaders, binding, handle, true) {
            let id = handle.id;
            self.with(|w| w.bindings.push((name, Bound::Resource(id, layout))));
        }
        self
    }

    /// Binds a caller-owned sampler.
    pub fn sampler(&mut self, binding: &str, sampler: vk::Sampler) -> &mut Self {
        match self.shader().and_then(|s| s.binding(binding)) {
            Some(b) if b.kind == DescriptorKind::Sampler => {
                let name = b.name;
                self.with(|w| w.bindings.push((name, Bound::Sampler(sampler))));
            }
            _ => self
                .pass
                .fail(binding, "no sampler binding of this name".into()),
        }
        self
    }

    /// Sets the push constants (must be the shader's reflected size).
    pub fn push<T: bytemuck::NoUninit>(&mut self, value: &T) -> &mut Self {
        let bytes = push_bytes(value);
        self.with(|w| w.push = bytes);
        self
    }

    /// Dispatches enough workgroups (size from reflection) to cover `threads` invocations.
    pub fn dispatch(&mut self, threads: [u32; 3]) -> &mut Self {
        self.with(|w| w.threads = threads);
        self
    }

    /// Declares the pass's work per run ([`PassBuilder::cost`]).
    pub fn cost(&mut self, cost: crate::PassCost) -> &mut Self {
        self.pass.cost(cost);
        self
    }

    /// Run this pass only on frames where `frame % period == phase`.
    pub fn run_every(&mut self, period: u32, phase: u32) -> &mut Self {
        self.pass.run_every(period, phase);
        self
    }
}

/// Builds a raster pass; see [`RenderGraph::raster`].
#[derive(Debug)]
pub struct RasterPass<'g> {
    pass: PassBuilder<'g>,
}

impl RasterPass<'_> {
    /// Applies `f` to the pass's raster work (which `RenderGraph::raster` put there).
    fn with<T: Default>(&mut self, f: impl FnOnce(&mut RasterWork) -> T) -> T {
        match self.pass.work() {
            Work::Raster(r) => f(r),
            _ => T::default(),
        }
    }

    fn shaders(&mut self) -> Vec<&'static ShaderDesc> {
        self.with(|r| {
            std::iter::once(r.pipeline.vertex)
                .chain(r.pipeline.fragment)
                .collect()
        })
    }

    /// Adds the next colour attachment (in the pipeline's colour-target order). It is read as
    /// well as written when loaded or blended (additive splatting).
    pub fn color(&mut self, handle: &mut Handle<Image>, load: ColorLoad) -> &mut Self {
        let blend = self.with(|r| r.pipeline.color_targets.get(r.colors.len()).map(|t| t.1));
        let (op, clear) = match load {
            ColorLoad::Load => (vk::AttachmentLoadOp::LOAD, [0.0; 4]),
            ColorLoad::Clear(c) => (vk::AttachmentLoadOp::CLEAR, c),
            ColorLoad::DontCare => (vk::AttachmentLoadOp::DONT_CARE, [0.0; 4]),
        };
        let reads = op == vk::AttachmentLoadOp::LOAD || blend.is_some_and(|b| b != Blend::Replace);
        let access = if reads {
            ImageAccess::ColorAttachmentReadWrite
        } else {
            ImageAccess::ColorAttachmentWrite
        };
        self.pass.write(handle, access);
        let attachment = Attachment {
            resource: handle.id,
            load: op,
            clear,
        };
        self.with(|r| r.colors.push(attachment));
        self
    }

    /// Sets the depth attachment, tested and written.
    pub fn depth(&mut self, handle: &mut Handle<Image>, load: DepthLoad) -> &mut Self {
        let (op, clear) = match load {
            DepthLoad::Load => (vk::AttachmentLoadOp::LOAD, 0.0),
            DepthLoad::Clear(d) => (vk::AttachmentLoadOp::CLEAR, d),
            DepthLoad::DontCare => (vk::AttachmentLoadOp::DONT_CARE, 0.0),
        };
        self.pass.write(handle, ImageAccess::DepthAttachmentWrite);
        let attachment = Attachment {
            resource: handle.id,
            load: op,
            clear: [clear, 0.0, 0.0, 0.0],
        };
        self.with(|r| r.depth = Some(attachment));
        self
    }

    /// Sets the depth attachment, tested but not written (its contents are loaded).
    pub fn depth_read(&mut self, handle: &Handle<Image>) -> &mut Self {
        self.pass.read(handle, ImageAccess::DepthAttachmentRead);
        let attachment = Attachment {
            resource: handle.id,
            load: vk::AttachmentLoadOp::LOAD,
            clear: [0.0; 4],
        };
        self.with(|r| r.depth = Some(attachment));
        self
    }

    /// Restricts rendering to the rectangle at `offset` of size `extent` inside the
    /// attachments: render area, viewport and scissor (a tile of an atlas). Loads, clears and
    /// stores touch only this rectangle; the rest of the attachments keeps its contents. The
    /// rectangle must lie inside the attachments (checked when the pass is recorded).
    pub fn area(&mut self, offset: [u32; 2], extent: [u32; 2]) -> &mut Self {
        let rect = vk::Rect2D {
            offset: vk::Offset2D {
                x: offset[0] as i32,
                y: offset[1] as i32,
            },
            extent: vk::Extent2D {
                width: extent[0],
                height: extent[1],
            },
        };
        self.with(|r| r.area = Some(rect));
        self
    }

    /// Binds a resource the vertex and/or fragment shader reads, by binding name.
    pub fn read<R: ResourceType>(&mut self, binding: &str, handle: &Handle<R>) -> &mut Self {
        let shaders = self.shaders();
        let mut h = *handle;
        if let Some((name, layout)) = self.pass.bind_shader(&shaders, binding, &mut h, false) {
            self.with(|r| r.bindings.push((name, Bound::Resource(h.id, layout))));
        }
        self
    }

    /// Binds a caller-owned sampler.
    pub fn sampler(&mut self, binding: &str, sampler: vk::Sampler) -> &mut Self {
        let shaders = self.shaders();
        match shaders.iter().find_map(|s| s.binding(binding)) {
            Some(b) if b.kind == DescriptorKind::Sampler => {
                let name = b.name;
                self.with(|r| r.bindings.push((name, Bound::Sampler(sampler))));
            }
            _ => self
                .pass
                .fail(binding, "no sampler binding of this name".into()),
        }
        self
    }

    /// Adds the next vertex buffer (in the pipeline's vertex-buffer order).
    pub fn vertex_buffer(&mut self, handle: &Handle<Buffer>) -> &mut Self {
        self.pass.read(handle, BufferAccess::Vertex);
        let id = handle.id;
        self.with(|r| r.vertex_buffers.push(id));
        self
    }

    /// Sets the index buffer.
    pub fn index_buffer(
        &mut self,
        handle: &Handle<Buffer>,
        index_type: vk::IndexType,
    ) -> &mut Self {
        self.pass.read(handle, BufferAccess::Index);
        let id = handle.id;
        self.with(|r| r.index_buffer = Some((id, index_type)));
        self
    }

    /// Sets the push constants (must be the pipeline's reflected size).
    pub fn push<T: bytemuck::NoUninit>(&mut self, value: &T) -> &mut Self {
        let bytes = push_bytes(value);
        self.with(|r| r.push = bytes);
        self
    }

    /// Draws `vertices` vertices of `instances` instances.
    pub fn draw(&mut self, vertices: u32, instances: u32) -> &mut Self {
        self.with(|r| {
            r.draws.push(Draw::Vertices {
                count: vertices,
                instances,
            })
        });
        self
    }

    /// Draws `indices` indices of `instances` instances from the index buffer.
    pub fn draw_indexed(&mut self, indices: u32, instances: u32) -> &mut Self {
        self.with(|r| {
            r.draws.push(Draw::Indexed {
                count: indices,
                instances,
            })
        });
        self
    }

    /// Run this pass only on frames where `frame % period == phase`.
    pub fn run_every(&mut self, period: u32, phase: u32) -> &mut Self {
        self.pass.run_every(period, phase);
        self
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use shine_gpu::ShaderStage;

    #[test]
    fn shader_stages_map_to_accesses() {
        assert_eq!(
            Image::shader_access(DescriptorKind::SampledImage, ShaderStage::Fragment, false),
            Some(ImageAccess::SampledFragment)
        );
        assert_eq!(
            Buffer::shader_access(
                DescriptorKind::StorageBuffer { writable: true },
                ShaderStage::Compute,
                true
            ),
            Some(BufferAccess::StorageReadWriteCompute)
        );
        assert_eq!(
            Buffer::shader_access(DescriptorKind::Sampler, ShaderStage::Compute, false),
            None
        );
    }
}
