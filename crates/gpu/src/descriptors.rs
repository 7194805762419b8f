//! Descriptor sets allocated per submission and written by binding NAME from the reflection.
//!
//! An arena hands out sets from pools it grows on demand; [`DescriptorArena::reset`] frees all
//! of them at once when the GPU is done with the command buffer that used them.

use crate::device::Device;
use crate::error::{Error, Result, VkContext};
use crate::memory::{Buffer, Image, Sampler};
use crate::pipeline::PipelineLayout;
use crate::shader::DescriptorKind;
use ash::vk;

/// Sets per pool; pools are added when one runs out.
const SETS_PER_POOL: u32 = 256;
/// Descriptors of each type per pool.
const DESCRIPTORS_PER_TYPE: u32 = 1024;

/// What a binding points at, as raw handles (the render graph binds resources it aliases).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Descriptor {
    /// A buffer range (uniform or storage).
    Buffer {
        /// The buffer.
        buffer: vk::Buffer,
        /// Start of the range in bytes.
        offset: u64,
        /// Length in bytes, or `vk::WHOLE_SIZE`.
        range: u64,
    },
    /// An image view in a layout (sampled or storage).
    Image {
        /// The view.
        view: vk::ImageView,
        /// Layout the image is in while the shader reads it.
        layout: vk::ImageLayout,
    },
    /// A sampler.
    Sampler(vk::Sampler),
}

impl From<&Buffer> for Descriptor {
    fn from(buffer: &Buffer) -> Self {
        Self::Buffer {
            buffer: buffer.raw(),
            offset: 0,
            range: vk::WHOLE_SIZE,
        }
    }
}

impl From<&Sampler> for Descriptor {
    fn from(sampler: &Sampler) -> Self {
        Self::Sampler(sampler.raw())
    }
}

impl Descriptor {
    /// A storage image in `GENERAL` layout.
    pub fn storage_image(image: &Image) -> Self {
        Self::Image {
            view: image.view(),
            layout: vk::ImageLayout::GENERAL,
        }
    }

    /// A sampled image in `SHADER_READ_ONLY_OPTIMAL` layout.
    pub fn sampled_image(image: &Image) -> Self {
        Self::Image {
            view: image.view(),
            layout: vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL,
        }
    }

    fn fits(&self, kind: DescriptorKind) -> bool {
        matches!(
            (self, kind),
            (
                Self::Buffer { .. },
                DescriptorKind::UniformBuffer | DescriptorKind::StorageBuffer { .. }
            ) | (
                Self::Image { .. },
                DescriptorKind::SampledImage | DescriptorKind::StorageImage { .. }
            ) | (Self::Sampler(_), DescriptorKind::Sampler)
        )
    }
}

/// Growable descriptor pools, reset wholesale.
pub struct DescriptorArena {
    raw: ash::Device,
    /// Keeps the device alive; `None` inside the device's own command contexts, which the
    /// device destroys itself (a clone there would be a reference cycle).
    _keep_alive: Option<Device>,
    pools: Vec<vk::DescriptorPool>,
    current: usize,
}

impl DescriptorArena {
    /// An empty arena; the first pool is made on first use.
    pub fn new(device: &Device) -> Self {
        Self {
            raw: device.raw().clone(),
            _keep_alive: Some(device.clone()),
            pools: Vec::new(),
            current: 0,
        }
    }

    /// An arena owned by a command context of the device itself.
    pub(crate) fn detached(raw: &ash::Device) -> Self {
        Self {
            raw: raw.clone(),
            _keep_alive: None,
            pools: Vec::new(),
            current: 0,
        }
    }

    /// Frees every set handed out. The GPU must be done with them.
    pub fn reset(&mut self) -> Result<()> {
        for pool in &self.pools {
            // SAFETY: the caller guarantees no pending command buffer uses these sets.
            unsafe {
                self.raw
                    .reset_descriptor_pool(*pool, vk::DescriptorPoolResetFlags::empty())
            }
            .ctx("resetting a descriptor pool")?;
        }
        self.current = 0;
        Ok(())
    }

    fn new_pool(&self) -> Result<vk::DescriptorPool> {
        let sizes = [
            vk::DescriptorType::UNIFORM_BUFFER,
            vk::DescriptorType::STORAGE_BUFFER,
            vk::DescriptorType::SAMPLED_IMAGE,
            vk::DescriptorType::STORAGE_IMAGE,
            vk::DescriptorType::SAMPLER,
        ]
        .map(|ty| vk::DescriptorPoolSize {
            ty,
            descriptor_count: DESCRIPTORS_PER_TYPE,
        });
        let info = vk::DescriptorPoolCreateInfo::default()
            .max_sets(SETS_PER_POOL)
            .pool_sizes(&sizes);
        // SAFETY: valid create info on a live device.
        unsafe { self.raw.create_descriptor_pool(&info, None) }.ctx("creating a descriptor pool")
    }

    fn allocate(&mut self, layout: vk::DescriptorSetLayout) -> Result<vk::DescriptorSet> {
        loop {
            let fresh = self.current == self.pools.len();
            if fresh {
                let pool = self.new_pool()?;
                self.pools.push(pool);
            }
            let layouts = [layout];
            let info = vk::DescriptorSetAllocateInfo::default()
                .descriptor_pool(self.pools[self.current])
                .set_layouts(&layouts);
            // SAFETY: the pool and layout belong to this device.
            match unsafe { self.raw.allocate_descriptor_sets(&info) } {
                Ok(sets) => {
                    return sets.first().copied().ok_or_else(|| {
                        Error::InvalidUsage("the driver returned no descriptor set".into())
                    });
                }
                Err(vk::Result::ERROR_OUT_OF_POOL_MEMORY | vk::Result::ERROR_FRAGMENTED_POOL)
                    if !fresh =>
                {
                    self.current += 1;
                }
                Err(e) => {
                    return Err(Error::vk(
                        format!(
                            "allocating a descriptor set (a pool holds {SETS_PER_POOL} sets and \
                             {DESCRIPTORS_PER_TYPE} descriptors of each type)"
                        ),
                        e,
                    ));
                }
            }
        }
    }

    /// Allocates and writes every set of `layout` from `resources` (matched by binding name)
    /// and binds them. Every reflected binding must be given exactly once.
    pub fn bind(
        &mut self,
        cb: vk::CommandBuffer,
        bind_point: vk::PipelineBindPoint,
        layout: &PipelineLayout,
        resources: &[(&str, Descriptor)],
    ) -> Result<()> {
        let error = |message: String| Error::Binding {
            pipeline: layout.name.clone(),
            message,
        };
        for (name, _) in resources {
            if !layout.bindings.iter().any(|b| b.desc.name == *name) {
                let known: Vec<_> = layout.bindings.iter().map(|b| b.desc.name).collect();
                return Err(error(format!(
                    "no binding named `{name}` (the shader has: {})",
                    known.join(", ")
                )));
            }
        }
        let mut sets = Vec::with_capacity(layout.set_layouts.len());
        for (set_index, set_layout) in layout.set_layouts.iter().enumerate() {
            let set = self.allocate(*set_layout)?;
            let mut buffer_infos = Vec::new();
            let mut image_infos = Vec::new();
            let mut targets = Vec::new();
            for b in layout
                .bindings
                .iter()
                .filter(|b| b.desc.set == set_index as u32)
            {
                let given: Vec<_> = resources
                    .iter()
                    .filter(|(n, _)| *n == b.desc.name)
                    .map(|(_, d)| *d)
                    .collect();
                if given.len() != b.desc.count as usize {
                    return Err(error(format!(
                        "binding `{}` needs {} descriptor(s), got {}",
                        b.desc.name,
                        b.desc.count,
                        given.len()
                    )));
                }
                for d in &given {
                    if !d.fits(b.desc.kind) {
                        return Err(error(format!(
                            "binding `{}` is a {:?}, got {d:?}",
                            b.desc.name, b.desc.kind
                        )));
                    }
                    match *d {
                        Descriptor::Buffer {
                            buffer,
                            offset,
                            range,
                        } => buffer_infos.push(vk::DescriptorBufferInfo {
                            buffer,
                            offset,
                            range,
                        }),
                        Descriptor::Image { view, layout } => {
                            image_infos.push(vk::DescriptorImageInfo {
                                sampler: vk::Sampler::null(),
                                image_view: view,
                                image_layout: layout,
                            })
                        }
                        Descriptor::Sampler(sampler) => image_infos.push(vk::DescriptorImageInfo {
                            sampler,
                            image_view: vk::ImageView::null(),
                            image_layout: vk::ImageLayout::UNDEFINED,
                        }),
                    }
                }
                let is_buffer = matches!(given.first(), Some(Descriptor::Buffer { .. }));
                targets.push((b, is_buffer));
            }
            // Build the writes after the info vectors stopped growing (they are borrowed).
            let mut writes = Vec::with_capacity(targets.len());
            let (mut next_buffer, mut next_image) = (0, 0);
            for (b, is_buffer) in targets {
                let count = b.desc.count as usize;
                let write = vk::WriteDescriptorSet::default()
                    .dst_set(set)
                    .dst_binding(b.desc.binding)
                    .descriptor_type(b.desc.kind.vk());
                writes.push(if is_buffer {
                    next_buffer += count;
                    write.buffer_info(&buffer_infos[next_buffer - count..next_buffer])
                } else {
                    next_image += count;
                    write.image_info(&image_infos[next_image - count..next_image])
                });
            }
            // SAFETY: every write targets a binding of `set` with a matching descriptor type.
            unsafe { self.raw.update_descriptor_sets(&writes, &[]) };
            sets.push(set);
        }
        if !sets.is_empty() {
            // SAFETY: the sets match the pipeline layout; `cb` is recording.
            unsafe {
                self.raw
                    .cmd_bind_descriptor_sets(cb, bind_point, layout.raw, 0, &sets, &[])
            };
        }
        Ok(())
    }
}

impl Drop for DescriptorArena {
    fn drop(&mut self) {
        for pool in self.pools.drain(..) {
            match &self._keep_alive {
                // Destroyed once the frames that bound its sets have completed.
                Some(device) => device.defer(crate::retire::Garbage::DescriptorPool(pool)),
                // SAFETY: inside the device's own command contexts, which it destroys only
                // once their submissions completed.
                None => unsafe { self.raw.destroy_descriptor_pool(pool, None) },
            }
        }
    }
}
