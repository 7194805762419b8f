//! Errors of the graph: [`GraphError`] for declaration and compilation, [`ExecuteError`] for
//! running a frame on a device (which wraps the former).

/// A render graph that cannot be compiled, and why.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum GraphError {
    /// A pass reads a transient resource version that no pass writes.
    #[error("pass `{pass}` reads `{resource}` version {version}, which no pass writes")]
    ReadOfUnwritten {
        /// The reading pass.
        pass: String,
        /// The resource.
        resource: String,
        /// The version read.
        version: u32,
    },
    /// A pass writes an imported resource that was imported read-only.
    #[error("pass `{pass}` writes `{resource}`, which was imported read-only")]
    WriteToReadOnly {
        /// The writing pass.
        pass: String,
        /// The resource.
        resource: String,
    },
    /// The passes' dependencies form a cycle (a pass reads an old version that a later
    /// write would overwrite, while that write must come first).
    #[error("the passes form a dependency cycle: {}", passes.join(" -> "))]
    Cycle {
        /// The passes that could not be ordered.
        passes: Vec<String>,
    },
    /// A pass writes through a handle that is not the newest version of the resource.
    #[error(
        "pass `{pass}` writes `{resource}` through version {version}, but version {latest} exists: write the newest handle"
    )]
    StaleWrite {
        /// The writing pass.
        pass: String,
        /// The resource.
        resource: String,
        /// The version of the handle used.
        version: u32,
        /// The newest version.
        latest: u32,
    },
    /// A handle that does not belong to this graph.
    #[error("resource {resource} does not belong to this graph")]
    UnknownResource {
        /// The foreign id.
        resource: crate::ResourceId,
    },
    /// An imported resource lacks a usage flag one of its accesses needs.
    #[error(
        "pass `{pass}` uses `{resource}` as {access}, which needs usage {needed}, but it was imported with {available}"
    )]
    UsageMismatch {
        /// The pass.
        pass: String,
        /// The resource.
        resource: String,
        /// The access, in words.
        access: String,
        /// The usage needed, in words.
        needed: String,
        /// The usage the import declared, in words.
        available: String,
    },
    /// One pass uses an image in two ways that need different layouts.
    #[error("pass `{pass}` uses `{resource}` in layouts {first} and {second} at once")]
    LayoutConflict {
        /// The pass.
        pass: String,
        /// The image.
        resource: String,
        /// One layout, in words.
        first: String,
        /// The other layout, in words.
        second: String,
    },
    /// A pass that does not run every frame writes a transient, whose contents would be lost on
    /// the frames it skips.
    #[error(
        "pass `{pass}` runs every {period} frames but writes the transient `{resource}`: make it temporal"
    )]
    PeriodicPassWritesTransient {
        /// The pass.
        pass: String,
        /// The transient resource.
        resource: String,
        /// The pass's period.
        period: u32,
    },
    /// A pass's update rate has period zero.
    #[error("pass `{pass}` has an update period of 0 frames")]
    ZeroPeriod {
        /// The pass.
        pass: String,
    },
    /// Two passes have the same name.
    #[error("two passes are named `{pass}`")]
    DuplicatePassName {
        /// The name.
        pass: String,
    },
    /// A resource description that cannot be created.
    #[error("resource `{resource}` cannot be created: {problem}")]
    InvalidDescription {
        /// The resource.
        resource: String,
        /// What is wrong.
        problem: &'static str,
    },
    /// An access of the wrong kind (a buffer access on an image or the reverse).
    #[error("pass `{pass}` uses `{resource}` with an access for the other kind of resource")]
    KindMismatch {
        /// The pass.
        pass: String,
        /// The resource.
        resource: String,
    },
    /// A shader binding that does not exist or does not fit the resource given to it.
    #[error("pass `{pass}`, binding `{binding}`: {message}")]
    Binding {
        /// The pass.
        pass: String,
        /// The binding name.
        binding: String,
        /// What is wrong.
        message: String,
    },
}

/// Why a frame could not be executed.
#[derive(Debug, thiserror::Error)]
pub enum ExecuteError {
    /// The graph does not compile.
    #[error(transparent)]
    Graph(#[from] GraphError),
    /// A Vulkan operation failed.
    #[error(transparent)]
    Gpu(#[from] shine_gpu::Error),
    /// An imported resource was declared without its Vulkan object.
    #[error(
        "imported resource `{0}` has no Vulkan object: import it with import_vk_* or import_gpu_*"
    )]
    MissingObject(String),
    /// A raster pass's area does not lie inside its attachments.
    #[error(
        "raster pass `{pass}`: area {width}×{height} at ({x}, {y}) is outside its {attachment_width}×{attachment_height} attachments"
    )]
    RenderArea {
        /// The pass.
        pass: String,
        /// Area origin x.
        x: u32,
        /// Area origin y.
        y: u32,
        /// Area width.
        width: u32,
        /// Area height.
        height: u32,
        /// Attachment width.
        attachment_width: u32,
        /// Attachment height.
        attachment_height: u32,
    },
}
