//! Typed, versioned resource handles.
//!
//! A handle names one version of one resource. Reading takes `&Handle`; writing takes
//! `&mut Handle` and advances it to the version the write produces, so the order of a
//! read-after-write is explicit in the code that declares the passes.

use std::fmt;
use std::marker::PhantomData;

use crate::access::{AnyAccess, BufferAccess, ImageAccess};
use crate::resource::{BufferDesc, ImageDesc};
use shine_gpu::{DescriptorKind, ShaderStage};

/// Index of a resource in its graph.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, serde::Serialize)]
pub struct ResourceId(pub u32);

impl fmt::Display for ResourceId {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "r{}", self.0)
    }
}

/// Marker type of image handles.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Image {}

/// Marker type of buffer handles.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Buffer {}

/// A kind of graph resource: [`Image`] or [`Buffer`].
pub trait ResourceType: Copy + 'static {
    /// Its description type.
    type Desc: Copy + fmt::Debug + PartialEq + Eq + std::hash::Hash;
    /// The ways a pass can use it.
    type Access: Copy + fmt::Debug;
    /// The access as an [`AnyAccess`].
    fn any_access(access: Self::Access) -> AnyAccess;
    /// The access a shader binding of `kind` in `stage` makes (`write`: through a writable
    /// storage binding), or `None` when this kind of resource cannot be bound there.
    fn shader_access(kind: DescriptorKind, stage: ShaderStage, write: bool)
    -> Option<Self::Access>;
}

impl ResourceType for Image {
    type Desc = ImageDesc;
    type Access = ImageAccess;
    fn any_access(access: ImageAccess) -> AnyAccess {
        AnyAccess::Image(access)
    }
    fn shader_access(kind: DescriptorKind, stage: ShaderStage, write: bool) -> Option<ImageAccess> {
        use DescriptorKind as K;
        use ShaderStage as S;
        Some(match (kind, stage, write) {
            (K::SampledImage, S::Compute, false) => ImageAccess::SampledCompute,
            (K::SampledImage, S::Vertex, false) => ImageAccess::SampledVertex,
            (K::SampledImage, S::Fragment, false) => ImageAccess::SampledFragment,
            (K::StorageImage { writable: false }, S::Compute, false) => {
                ImageAccess::StorageReadCompute
            }
            (K::StorageImage { writable: true }, S::Compute, true) => {
                ImageAccess::StorageReadWriteCompute
            }
            _ => return None,
        })
    }
}

impl ResourceType for Buffer {
    type Desc = BufferDesc;
    type Access = BufferAccess;
    fn any_access(access: BufferAccess) -> AnyAccess {
        AnyAccess::Buffer(access)
    }
    fn shader_access(
        kind: DescriptorKind,
        stage: ShaderStage,
        write: bool,
    ) -> Option<BufferAccess> {
        use DescriptorKind as K;
        use ShaderStage as S;
        Some(match (kind, stage, write) {
            (K::UniformBuffer, S::Compute, false) => BufferAccess::UniformCompute,
            (K::UniformBuffer, S::Vertex, false) => BufferAccess::UniformVertex,
            (K::UniformBuffer, S::Fragment, false) => BufferAccess::UniformFragment,
            (K::StorageBuffer { writable: false }, S::Compute, false) => {
                BufferAccess::StorageReadCompute
            }
            (K::StorageBuffer { writable: false }, S::Vertex, false) => {
                BufferAccess::StorageReadVertex
            }
            (K::StorageBuffer { writable: false }, S::Fragment, false) => {
                BufferAccess::StorageReadFragment
            }
            (K::StorageBuffer { writable: true }, S::Compute, true) => {
                BufferAccess::StorageReadWriteCompute
            }
            _ => return None,
        })
    }
}

/// One version of one graph resource of type `R`.
///
/// Handles are `Copy`: a copy kept from before a write still names the older version, and a
/// pass that reads it is ordered before the write (or the graph reports a cycle).
pub struct Handle<R: ResourceType> {
    pub(crate) id: ResourceId,
    pub(crate) version: u32,
    pub(crate) desc: R::Desc,
    pub(crate) marker: PhantomData<R>,
}

impl<R: ResourceType> Handle<R> {
    pub(crate) fn new(id: ResourceId, desc: R::Desc) -> Self {
        Self {
            id,
            version: 0,
            desc,
            marker: PhantomData,
        }
    }

    /// The resource this handle names.
    pub fn id(&self) -> ResourceId {
        self.id
    }

    /// The version it names: 0 is the contents on entry, each write adds one.
    pub fn version(&self) -> u32 {
        self.version
    }

    /// The resource's description.
    pub fn desc(&self) -> &R::Desc {
        &self.desc
    }
}

impl<R: ResourceType> Clone for Handle<R> {
    fn clone(&self) -> Self {
        *self
    }
}

impl<R: ResourceType> Copy for Handle<R> {}

impl<R: ResourceType> fmt::Debug for Handle<R> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}v{} {:?}", self.id, self.version, self.desc)
    }
}

impl<R: ResourceType> PartialEq for Handle<R> {
    fn eq(&self, other: &Self) -> bool {
        self.id == other.id && self.version == other.version
    }
}

impl<R: ResourceType> Eq for Handle<R> {}
