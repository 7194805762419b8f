//! Resource descriptions: plain `Copy + Hash + Eq` values that say what a graph resource is.

use shine_gpu::vk;

/// Description of an image resource. The graph derives the usage flags from the accesses.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct ImageDesc {
    /// Texel format.
    pub format: vk::Format,
    /// Dimensionality (1D, 2D or 3D).
    pub image_type: vk::ImageType,
    /// Size in texels; `depth` is 1 for 1D and 2D images.
    pub extent: vk::Extent3D,
    /// Number of mip levels (at least 1).
    pub mips: u32,
    /// Number of array layers (at least 1).
    pub layers: u32,
    /// Samples per texel (`TYPE_1` unless multisampled).
    pub samples: vk::SampleCountFlags,
}

impl ImageDesc {
    /// A single-mip, single-layer, single-sample 2D image.
    pub fn new_2d(format: vk::Format, width: u32, height: u32) -> Self {
        Self {
            format,
            image_type: vk::ImageType::TYPE_2D,
            extent: vk::Extent3D {
                width,
                height,
                depth: 1,
            },
            mips: 1,
            layers: 1,
            samples: vk::SampleCountFlags::TYPE_1,
        }
    }

    /// A single-mip, single-sample 3D image.
    pub fn new_3d(format: vk::Format, width: u32, height: u32, depth: u32) -> Self {
        Self {
            image_type: vk::ImageType::TYPE_3D,
            extent: vk::Extent3D {
                width,
                height,
                depth,
            },
            ..Self::new_2d(format, width, height)
        }
    }

    /// The same description with `mips` mip levels.
    pub fn with_mips(self, mips: u32) -> Self {
        Self { mips, ..self }
    }

    /// The same description with `layers` array layers.
    pub fn with_layers(self, layers: u32) -> Self {
        Self { layers, ..self }
    }

    /// The aspects of the format: depth and/or stencil for depth formats, colour otherwise.
    pub fn aspect(&self) -> vk::ImageAspectFlags {
        shine_gpu::format_aspect(self.format)
    }

    /// The whole image as a subresource range (every mip and layer of every aspect).
    pub fn full_range(&self) -> vk::ImageSubresourceRange {
        vk::ImageSubresourceRange {
            aspect_mask: self.aspect(),
            base_mip_level: 0,
            level_count: self.mips,
            base_array_layer: 0,
            layer_count: self.layers,
        }
    }

    /// Why this description cannot be created, if it cannot.
    pub(crate) fn problem(&self) -> Option<&'static str> {
        let e = self.extent;
        if e.width == 0 || e.height == 0 || e.depth == 0 {
            Some("an extent is zero")
        } else if self.mips == 0 || self.layers == 0 {
            Some("zero mip levels or layers")
        } else if self.format == vk::Format::UNDEFINED {
            Some("the format is UNDEFINED")
        } else {
            None
        }
    }
}

/// Description of a buffer resource. The graph derives the usage flags from the accesses.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct BufferDesc {
    /// Size in bytes.
    pub size: u64,
}

impl BufferDesc {
    /// A buffer of `size` bytes.
    pub fn new(size: u64) -> Self {
        Self { size }
    }

    /// Why this description cannot be created, if it cannot.
    pub(crate) fn problem(&self) -> Option<&'static str> {
        (self.size == 0).then_some("the size is zero")
    }
}

/// Either kind of resource description.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum AnyDesc {
    /// An image.
    Image(ImageDesc),
    /// A buffer.
    Buffer(BufferDesc),
}

impl From<ImageDesc> for AnyDesc {
    fn from(desc: ImageDesc) -> Self {
        AnyDesc::Image(desc)
    }
}

impl From<BufferDesc> for AnyDesc {
    fn from(desc: BufferDesc) -> Self {
        AnyDesc::Buffer(desc)
    }
}

impl AnyDesc {
    /// Why this description cannot be created, if it cannot.
    pub(crate) fn problem(&self) -> Option<&'static str> {
        match self {
            AnyDesc::Image(d) => d.problem(),
            AnyDesc::Buffer(d) => d.problem(),
        }
    }
}

/// Where a resource lives and who owns it.
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub(crate) enum Lifetime {
    /// Created by the graph for one frame; its memory may alias other transients.
    Transient,
    /// Owned by the caller; the graph is told its state on entry and leaves it in the state asked.
    Imported(ImportInfo),
    /// Kept by the graph across frames under a key (history buffers, amortised caches).
    Temporal(String),
}

/// The synchronization state of a resource outside the graph: the last (or next) use's stage and
/// access masks and, for images, the layout.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct ExternalState {
    /// Pipeline stages of the outside use.
    pub stage: vk::PipelineStageFlags2,
    /// Memory accesses of the outside use.
    pub access: vk::AccessFlags2,
    /// Image layout (ignored for buffers).
    pub layout: vk::ImageLayout,
}

impl ExternalState {
    /// No outside use, undefined contents: the state of a freshly created resource.
    pub const UNDEFINED: Self = Self {
        stage: vk::PipelineStageFlags2::NONE,
        access: vk::AccessFlags2::NONE,
        layout: vk::ImageLayout::UNDEFINED,
    };

    /// A state with the given masks and layout.
    pub const fn new(
        stage: vk::PipelineStageFlags2,
        access: vk::AccessFlags2,
        layout: vk::ImageLayout,
    ) -> Self {
        Self {
            stage,
            access,
            layout,
        }
    }
}

/// How an imported image enters and leaves the graph.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct ImageImport {
    /// State of the last use before the graph (a write access mask means its contents are
    /// being produced there and must be waited for).
    pub initial: ExternalState,
    /// State the graph must leave it in: its layout, and the stage/access of the caller's next
    /// use. An UNDEFINED layout leaves it in the layout of its last use in the graph.
    pub final_state: ExternalState,
    /// Usage flags it was created with; an access needing more is an error.
    pub usage: vk::ImageUsageFlags,
    /// Whether passes may only read it.
    pub read_only: bool,
}

/// How an imported buffer enters and leaves the graph.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct BufferImport {
    /// State of the last use before the graph (the layout is ignored).
    pub initial: ExternalState,
    /// Stage/access of the caller's next use after the graph (the layout is ignored).
    pub final_state: ExternalState,
    /// Usage flags it was created with; an access needing more is an error.
    pub usage: vk::BufferUsageFlags,
    /// Whether passes may only read it.
    pub read_only: bool,
}

/// An import of either kind, with the usage as raw bits.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub(crate) struct ImportInfo {
    pub initial: ExternalState,
    pub final_state: ExternalState,
    pub usage: u32,
    pub read_only: bool,
}

impl From<ImageImport> for ImportInfo {
    fn from(i: ImageImport) -> Self {
        Self {
            initial: i.initial,
            final_state: i.final_state,
            usage: i.usage.as_raw(),
            read_only: i.read_only,
        }
    }
}

impl From<BufferImport> for ImportInfo {
    fn from(i: BufferImport) -> Self {
        let strip = |s: ExternalState| ExternalState {
            layout: vk::ImageLayout::UNDEFINED,
            ..s
        };
        Self {
            initial: strip(i.initial),
            final_state: strip(i.final_state),
            usage: i.usage.as_raw(),
            read_only: i.read_only,
        }
    }
}
