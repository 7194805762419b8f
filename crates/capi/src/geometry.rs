//! `shine_context_register_mesh`, `shine_context_set_instances` and
//! `shine_context_move_instances`: the host's own buffers and light list, as the Rust
//! `GiContext` calls of the same names take them.

use crate::error::{Failure, ShineResult, call};
use crate::handles::{self, ShineContext, lock};
use shine::embed::{
    GiContext, HostBuffer, HostInstance, HostMaterial, HostMesh, IndexFormat, Light, LightKind,
    MeshId, PositionFormat,
};
use shine::gpu::vk::{self, Handle};

/// `ShineHostMesh::version` of this header.
pub const SHINE_HOST_MESH_VERSION: u32 = 2;
/// `ShineHostMesh::position_format`: three 32-bit floats.
pub const SHINE_POSITION_FLOAT3: u32 = 0;
/// `ShineHostMesh::position_format`: four 16-bit floats (w ignored).
pub const SHINE_POSITION_HALF4: u32 = 1;
/// `ShineHostMesh::index_format`: 16-bit indices.
pub const SHINE_INDEX_UINT16: u32 = 0;
/// `ShineHostMesh::index_format`: 32-bit indices.
pub const SHINE_INDEX_UINT32: u32 = 1;
/// `ShineLight::kind`: a directional light (lux).
pub const SHINE_LIGHT_DIRECTIONAL: u32 = 0;
/// `ShineLight::kind`: a point light (candela).
pub const SHINE_LIGHT_POINT: u32 = 1;
/// `ShineLight::kind`: a spot light (candela).
pub const SHINE_LIGHT_SPOT: u32 = 2;

/// A range of one of the host's buffers; `size` is the buffer's size as created (Vulkan
/// cannot tell shine), every range is checked against it.
#[repr(C)]
#[derive(Clone, Copy)]
pub struct ShineHostBuffer {
    /// `VkBuffer`, with `TRANSFER_SRC` usage.
    pub buffer: u64,
    /// Its size in bytes.
    pub size: u64,
    /// Where the data starts.
    pub offset: u64,
}

/// What rays and RSMs see of a mesh.
#[repr(C)]
#[derive(Clone, Copy)]
pub struct ShineHostMaterial {
    /// Linear base colour.
    pub base_color: [f32; 3],
    /// Perceptual roughness.
    pub roughness: f32,
    /// Metalness.
    pub metallic: f32,
    /// Emitted radiance.
    pub emissive: [f32; 3],
    /// Nonzero: both faces reflect.
    pub double_sided: u32,
}

/// A triangle mesh in the host's buffers.
#[repr(C)]
pub struct ShineHostMesh {
    /// `SHINE_HOST_MESH_VERSION`.
    pub version: u32,
    /// The vertices.
    pub vertices: ShineHostBuffer,
    /// Bytes from one vertex to the next.
    pub vertex_stride: u32,
    /// Number of vertices.
    pub vertex_count: u32,
    /// `SHINE_POSITION_FLOAT3` or `SHINE_POSITION_HALF4`, at byte 0 of each vertex.
    pub position_format: u32,
    /// Byte offset of a float3 normal in each vertex, or −1 (computed from the triangles).
    pub normal_offset: i32,
    /// The indices (a triangle list).
    pub indices: ShineHostBuffer,
    /// `SHINE_INDEX_UINT16` or `SHINE_INDEX_UINT32`.
    pub index_format: u32,
    /// Number of indices, a multiple of 3.
    pub index_count: u32,
    /// The surface.
    pub material: ShineHostMaterial,
    /// Nonzero: the host changes the vertices every frame and gives them with
    /// `shine_context_deform_mesh` (version 2).
    pub deformable: u32,
}

/// A registered mesh placed in the world: the top three rows of its object-to-world matrix,
/// row-major, as `VkTransformMatrixKHR`.
#[repr(C)]
#[derive(Clone, Copy)]
pub struct ShineHostInstance {
    /// What `shine_context_register_mesh` returned.
    pub mesh: u32,
    /// Object to world, 3 rows of 4.
    pub transform: [[f32; 4]; 3],
}

/// A light in world space.
#[repr(C)]
#[derive(Clone, Copy)]
pub struct ShineLight {
    /// `SHINE_LIGHT_DIRECTIONAL`, `SHINE_LIGHT_POINT` or `SHINE_LIGHT_SPOT`.
    pub kind: u32,
    /// Position (point and spot lights).
    pub position: [f32; 3],
    /// Unit direction the light shines along (directional and spot lights).
    pub direction: [f32; 3],
    /// Linear RGB colour.
    pub color: [f32; 3],
    /// Candela (point, spot) or lux (directional).
    pub intensity: f32,
    /// Metres beyond which the light is zero; 0: infinite.
    pub range: f32,
    /// Spot inner cone half-angle, radians.
    pub inner_cone_angle: f32,
    /// Spot outer cone half-angle, radians.
    pub outer_cone_angle: f32,
}

/// Registers a mesh from the host's buffers (reads them back once: submits a copy on the
/// device's queue and waits) and writes its number to `out_mesh`.
///
/// # Safety
/// `mesh` is null or valid; `out_mesh` is null or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn shine_context_register_mesh(
    context: ShineContext,
    mesh: *const ShineHostMesh,
    out_mesh: *mut u32,
) -> ShineResult {
    call(|| {
        let context = handles::context(context)?;
        // SAFETY: the caller's promise.
        let (mesh, out) = unsafe { (mesh.as_ref(), out_mesh.as_mut()) };
        let (mesh, out) = mesh
            .zip(out)
            .ok_or_else(|| Failure::invalid("mesh and out_mesh must not be null"))?;
        if mesh.version != SHINE_HOST_MESH_VERSION {
            return Err(Failure::new(
                ShineResult::ErrorVersionMismatch,
                format!(
                    "ShineHostMesh version {} (this library reads version \
                     {SHINE_HOST_MESH_VERSION})",
                    mesh.version
                ),
            ));
        }
        let rust = HostMesh {
            vertices: buffer(mesh.vertices),
            vertex_stride: mesh.vertex_stride,
            vertex_count: mesh.vertex_count,
            position_format: match mesh.position_format {
                SHINE_POSITION_FLOAT3 => PositionFormat::Float3,
                SHINE_POSITION_HALF4 => PositionFormat::Half4,
                other => return Err(Failure::invalid(format!("position_format {other}"))),
            },
            normal_offset: u32::try_from(mesh.normal_offset).ok(),
            indices: buffer(mesh.indices),
            index_format: match mesh.index_format {
                SHINE_INDEX_UINT16 => IndexFormat::U16,
                SHINE_INDEX_UINT32 => IndexFormat::U32,
                other => return Err(Failure::invalid(format!("index_format {other}"))),
            },
            index_count: mesh.index_count,
            material: HostMaterial {
                base_color: mesh.material.base_color,
                roughness: mesh.material.roughness,
                metallic: mesh.material.metallic,
                emissive: mesh.material.emissive,
                double_sided: mesh.material.double_sided != 0,
            },
            deformable: mesh.deformable != 0,
        };
        *out = lock(&context).register_mesh(&rust)?.index();
        Ok(())
    })
}

/// Gives deformable mesh `mesh`'s new shape from host memory: `vertex_count` positions (3
/// floats each, mesh space) and, unless null, as many normals. CPU only, per frame; the next
/// dispatch uploads it.
///
/// # Safety
/// `positions` holds `3 · vertex_count` floats; `normals` is null or holds as many.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn shine_context_deform_mesh(
    context: ShineContext,
    mesh: u32,
    positions: *const f32,
    normals: *const f32,
    vertex_count: u32,
) -> ShineResult {
    call(|| {
        let context = handles::context(context)?;
        if positions.is_null() {
            return Err(Failure::invalid("positions must not be null"));
        }
        // SAFETY: the caller's promise: 3 · vertex_count floats each.
        let positions = unsafe { slice(positions.cast::<[f32; 3]>(), vertex_count, "positions") }?;
        // SAFETY: as above.
        let normals = (!normals.is_null())
            .then(|| unsafe { slice(normals.cast::<[f32; 3]>(), vertex_count, "normals") })
            .transpose()?;
        Ok(lock(&context).deform_mesh(MeshId::from_index(mesh), positions, normals)?)
    })
}

/// Places registered meshes and sets the light list: builds the scene (uploads and waits).
///
/// # Safety
/// `instances` holds `instance_count` instances and `lights` `light_count` lights (either may
/// be null when its count is 0).
#[unsafe(no_mangle)]
pub unsafe extern "C" fn shine_context_set_instances(
    context: ShineContext,
    instances: *const ShineHostInstance,
    instance_count: u32,
    lights: *const ShineLight,
    light_count: u32,
) -> ShineResult {
    // SAFETY: the caller's promise.
    unsafe {
        with_world(
            context,
            instances,
            instance_count,
            lights,
            light_count,
            |gi, i, l| gi.set_instances(i, l),
        )
    }
}

/// Moves the instances of the last `shine_context_set_instances` (same meshes, same order)
/// and replaces its lights (as many): CPU only, per frame.
///
/// # Safety
/// As `shine_context_set_instances`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn shine_context_move_instances(
    context: ShineContext,
    instances: *const ShineHostInstance,
    instance_count: u32,
    lights: *const ShineLight,
    light_count: u32,
) -> ShineResult {
    // SAFETY: the caller's promise.
    unsafe {
        with_world(
            context,
            instances,
            instance_count,
            lights,
            light_count,
            |gi, i, l| gi.move_instances(i, l),
        )
    }
}

/// Runs `f` on the context with the C arrays as Rust instances and lights.
///
/// # Safety
/// The arrays hold their counts (or are null with a count of 0).
unsafe fn with_world(
    context: ShineContext,
    instances: *const ShineHostInstance,
    instance_count: u32,
    lights: *const ShineLight,
    light_count: u32,
    f: impl FnOnce(&mut GiContext, &[HostInstance], &[Light]) -> Result<(), shine::RenderError>,
) -> ShineResult {
    call(|| {
        let context = handles::context(context)?;
        // SAFETY: the caller's promise.
        let (instances, lights) = unsafe { world(instances, instance_count, lights, light_count) }?;
        Ok(f(&mut lock(&context), &instances, &lights)?)
    })
}

/// The Rust range of a C one.
fn buffer(b: ShineHostBuffer) -> HostBuffer {
    HostBuffer {
        buffer: vk::Buffer::from_raw(b.buffer),
        size: b.size,
        offset: b.offset,
    }
}

/// The Rust instances and lights of C arrays.
///
/// # Safety
/// The arrays hold their counts (or are null with a count of 0).
unsafe fn world(
    instances: *const ShineHostInstance,
    instance_count: u32,
    lights: *const ShineLight,
    light_count: u32,
) -> Result<(Vec<HostInstance>, Vec<Light>), Failure> {
    // SAFETY: the caller's promise.
    let instances = unsafe { slice(instances, instance_count, "instances") }?;
    // SAFETY: as above.
    let lights = unsafe { slice(lights, light_count, "lights") }?;
    let instances = instances
        .iter()
        .map(|i| HostInstance {
            mesh: MeshId::from_index(i.mesh),
            transform: i.transform,
        })
        .collect();
    let lights = lights
        .iter()
        .enumerate()
        .map(|(i, l)| {
            let kind = match l.kind {
                SHINE_LIGHT_DIRECTIONAL => LightKind::Directional,
                SHINE_LIGHT_POINT => LightKind::Point,
                SHINE_LIGHT_SPOT => LightKind::Spot,
                other => return Err(Failure::invalid(format!("light {i}: kind {other}"))),
            };
            Ok(Light {
                position: l.position,
                kind: kind as u32,
                direction: l.direction,
                range: l.range,
                color: l.color,
                intensity: l.intensity,
                inner_cone_angle: l.inner_cone_angle,
                outer_cone_angle: l.outer_cone_angle,
                node: u32::MAX,
                _pad: 0,
            })
        })
        .collect::<Result<_, _>>()?;
    Ok((instances, lights))
}

/// `count` elements at `p`, or none when `count` is 0.
///
/// # Safety
/// `p` holds `count` elements when `count` > 0.
unsafe fn slice<'a, T>(p: *const T, count: u32, name: &str) -> Result<&'a [T], Failure> {
    match (count, p.is_null()) {
        (0, _) => Ok(&[]),
        (_, true) => Err(Failure::invalid(format!(
            "{name} is null with a count of {count}"
        ))),
        // SAFETY: the caller's promise.
        (n, false) => Ok(unsafe { std::slice::from_raw_parts(p, n as usize) }),
    }
}
