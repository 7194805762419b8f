//! The host's own geometry and lights: meshes registered from the host's `VkBuffer`s (read
//! back once, checked, decoded), instances placed by 3×4 transforms, and a light list, which
//! together become the scene the context lights (its BVH, RSMs and proxies are built from it as
//! from a glTF). Moving instances and changing lights afterwards is a per-frame `update`.

use crate::frame::RenderError;
use glam::{Mat4, Vec3, Vec4};
use shine_gpu::{Device, vk};
use shine_scene::{Aabb, Light, Material, Mesh, MorphTarget, Node, Primitive, Scene, Transform};

/// How a host mesh stores vertex positions.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PositionFormat {
    /// Three 32-bit floats (`R32G32B32_SFLOAT`).
    Float3,
    /// Four 16-bit floats, w ignored (`R16G16B16A16_SFLOAT`).
    Half4,
}

impl PositionFormat {
    /// Bytes one position takes.
    fn size(self) -> u64 {
        match self {
            PositionFormat::Float3 => 12,
            PositionFormat::Half4 => 8,
        }
    }
}

/// How a host mesh stores indices.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum IndexFormat {
    /// `VK_INDEX_TYPE_UINT16`.
    U16,
    /// `VK_INDEX_TYPE_UINT32`.
    U32,
}

/// A range of one of the host's buffers. Vulkan cannot tell shine a `VkBuffer`'s size, so
/// the host states it: a range that does not fit is refused instead of read out of bounds.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct HostBuffer {
    /// The buffer; needs `TRANSFER_SRC` usage, its contents complete on the device.
    pub buffer: vk::Buffer,
    /// Its size in bytes, as created.
    pub size: u64,
    /// Where the data starts.
    pub offset: u64,
}

/// What a mesh's surface is for the rays and RSMs that meet it (the G-buffer says what the
/// camera sees).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HostMaterial {
    /// Linear base colour.
    pub base_color: [f32; 3],
    /// Perceptual roughness.
    pub roughness: f32,
    /// Metalness.
    pub metallic: f32,
    /// Emitted radiance.
    pub emissive: [f32; 3],
    /// Whether both faces reflect (false: the back face is culled, glTF's default).
    pub double_sided: bool,
}

impl Default for HostMaterial {
    /// A grey, rough, single-sided dielectric.
    fn default() -> Self {
        Self {
            base_color: [0.5; 3],
            roughness: 1.0,
            metallic: 0.0,
            emissive: [0.0; 3],
            double_sided: false,
        }
    }
}

/// A triangle mesh in the host's buffers (`GiContext::register_mesh`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HostMesh {
    /// The vertices.
    pub vertices: HostBuffer,
    /// Bytes from one vertex to the next.
    pub vertex_stride: u32,
    /// Number of vertices.
    pub vertex_count: u32,
    /// Format of the position, at byte 0 of each vertex.
    pub position_format: PositionFormat,
    /// Byte offset of a float3 normal within each vertex; `None`: normals are computed
    /// (area-weighted over the triangles sharing a vertex).
    pub normal_offset: Option<u32>,
    /// The indices (a triangle list).
    pub indices: HostBuffer,
    /// Their format.
    pub index_format: IndexFormat,
    /// Number of indices (a multiple of 3).
    pub index_count: u32,
    /// The surface.
    pub material: HostMaterial,
    /// Whether the host changes the vertices every frame (skinning, cloth) and gives the new
    /// ones with `GiContext::deform_mesh`: its instances' hierarchies are then refitted every
    /// frame. `false`: a rigid mesh, whose hierarchy is built once.
    pub deformable: bool,
}

/// A registered mesh (`GiContext::register_mesh`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct MeshId(pub(crate) u32);

impl MeshId {
    /// The registration's number: 0 for a context's first mesh, then 1, 2 … (what the C
    /// API hands out).
    pub fn index(self) -> u32 {
        self.0
    }

    /// The id of registration number `index` (an unknown one is refused where it is used).
    pub fn from_index(index: u32) -> Self {
        Self(index)
    }
}

/// A mesh placed in the world: `transform` is the top three rows of the object-to-world
/// matrix (row-major, translation in the last column), as `VkTransformMatrixKHR`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HostInstance {
    /// The mesh.
    pub mesh: MeshId,
    /// Object to world, 3 rows of 4.
    pub transform: [[f32; 4]; 3],
}

/// A mesh registered with a context: what was read, and the host's last shape of it.
#[derive(Clone, Debug)]
pub(crate) struct Registered {
    /// The vertices and indices read at registration.
    pub primitive: Primitive,
    /// Its surface.
    pub material: HostMaterial,
    /// Whether it may be deformed ([`HostMesh::deformable`]).
    pub deformable: bool,
    /// The last shape given to [`deform`], as position and normal deltas from `primitive`'s
    /// (`None`: as registered).
    pub deltas: Option<(Vec<Vec3>, Vec<Vec3>)>,
}

/// The deltas of `positions` and `normals` (else area-weighted ones) from mesh `id`'s
/// registered vertices: its new shape, for [`Registered::deltas`]. Refused: a rigid mesh, a
/// count other than the registered one, a non-finite position, normal or delta.
pub(crate) fn deform(
    mesh: &Registered,
    id: u32,
    positions: &[[f32; 3]],
    normals: Option<&[[f32; 3]]>,
) -> Result<(Vec<Vec3>, Vec<Vec3>), RenderError> {
    let rest = &mesh.primitive;
    if !mesh.deformable {
        return Err(invalid(format!(
            "mesh {id} was registered rigid (HostMesh::deformable is false)"
        )));
    }
    let count = rest.positions.len();
    if positions.len() != count || normals.is_some_and(|n| n.len() != count) {
        return Err(invalid(format!(
            "mesh {id} has {count} vertices; {} positions and {} normals given",
            positions.len(),
            normals.map_or(0, <[_]>::len)
        )));
    }
    let finite = |v: &[f32; 3]| v.iter().all(|c| c.is_finite());
    let bad = positions
        .iter()
        .zip(0..)
        .chain(normals.unwrap_or_default().iter().zip(0..))
        .find(|(v, _)| !finite(v));
    if let Some((_, v)) = bad {
        return Err(invalid(format!("mesh {id}: vertex {v} is not finite")));
    }
    let positions: Vec<Vec3> = positions.iter().map(|p| Vec3::from_array(*p)).collect();
    let normals: Vec<Vec3> = match normals {
        Some(n) => n
            .iter()
            .map(|n| Vec3::from_array(*n).normalize_or(Vec3::Y))
            .collect(),
        None => area_weighted_normals(&positions, &rest.indices),
    };
    let delta = |new: &[Vec3], old: &[Vec3]| -> Vec<Vec3> {
        new.iter().zip(old).map(|(a, b)| *a - *b).collect()
    };
    let deltas = (
        delta(&positions, &rest.positions),
        delta(&normals, &rest.normals),
    );
    if !deltas.0.iter().all(|d| d.is_finite()) {
        return Err(invalid(format!(
            "mesh {id}: the new shape is too far from the registered one"
        )));
    }
    Ok(deltas)
}

fn invalid(message: String) -> RenderError {
    RenderError::Invalid(format!("host geometry: {message}"))
}

/// Reads `mesh` from the host's buffers (submits a copy and waits) into a primitive, refusing
/// ranges that overrun their buffers, indices past the vertices and non-finite positions.
pub(crate) fn read_mesh(device: &Device, mesh: &HostMesh) -> Result<Primitive, RenderError> {
    let stride = u64::from(mesh.vertex_stride);
    let count = u64::from(mesh.vertex_count);
    if mesh.vertex_count == 0 || mesh.index_count == 0 || !mesh.index_count.is_multiple_of(3) {
        return Err(invalid(format!(
            "{} vertices and {} indices: a triangle list needs vertices and a multiple of 3 \
             indices",
            mesh.vertex_count, mesh.index_count
        )));
    }
    let normal_end = mesh.normal_offset.map_or(0, |o| u64::from(o) + 12);
    if stride < mesh.position_format.size().max(normal_end) {
        return Err(invalid(format!(
            "vertex stride {stride} is smaller than the attributes it holds"
        )));
    }
    let vertex_bytes = (count - 1) * stride + mesh.position_format.size().max(normal_end);
    let index_size = match mesh.index_format {
        IndexFormat::U16 => 2,
        IndexFormat::U32 => 4,
    };
    let index_bytes = u64::from(mesh.index_count) * index_size;
    for (name, range, bytes) in [
        ("vertex", &mesh.vertices, vertex_bytes),
        ("index", &mesh.indices, index_bytes),
    ] {
        if range.buffer == vk::Buffer::null() {
            return Err(invalid(format!("the {name} buffer is null")));
        }
        if range
            .offset
            .checked_add(bytes)
            .is_none_or(|end| end > range.size)
        {
            return Err(invalid(format!(
                "the {name} buffer holds {} bytes; {bytes} from offset {} do not fit",
                range.size, range.offset
            )));
        }
    }
    let vertex_data =
        device.read_raw_buffer(mesh.vertices.buffer, mesh.vertices.offset, vertex_bytes)?;
    let index_data =
        device.read_raw_buffer(mesh.indices.buffer, mesh.indices.offset, index_bytes)?;
    let at = |v: usize, offset: usize, i: usize| -> f32 {
        let start = v * stride as usize + offset + 4 * i;
        f32::from_le_bytes([
            vertex_data[start],
            vertex_data[start + 1],
            vertex_data[start + 2],
            vertex_data[start + 3],
        ])
    };
    let half = |v: usize, i: usize| -> f32 {
        let start = v * stride as usize + 2 * i;
        half::f16::from_le_bytes([vertex_data[start], vertex_data[start + 1]]).to_f32()
    };
    let positions: Vec<Vec3> = (0..count as usize)
        .map(|v| match mesh.position_format {
            PositionFormat::Float3 => Vec3::new(at(v, 0, 0), at(v, 0, 1), at(v, 0, 2)),
            PositionFormat::Half4 => Vec3::new(half(v, 0), half(v, 1), half(v, 2)),
        })
        .collect();
    if let Some(v) = positions.iter().position(|p| !p.is_finite()) {
        return Err(invalid(format!("vertex {v} is not finite")));
    }
    let indices: Vec<u32> = index_data
        .chunks_exact(index_size as usize)
        .map(|b| match mesh.index_format {
            IndexFormat::U16 => u32::from(u16::from_le_bytes([b[0], b[1]])),
            IndexFormat::U32 => u32::from_le_bytes([b[0], b[1], b[2], b[3]]),
        })
        .collect();
    if let Some((i, index)) = indices
        .iter()
        .enumerate()
        .find(|(_, x)| **x >= mesh.vertex_count)
    {
        return Err(invalid(format!(
            "index {i} is {index}, past the mesh's {} vertices",
            mesh.vertex_count
        )));
    }
    let normals = match mesh.normal_offset {
        Some(o) => (0..count as usize)
            .map(|v| {
                let o = o as usize;
                Vec3::new(at(v, o, 0), at(v, o, 1), at(v, o, 2)).normalize_or(Vec3::Y)
            })
            .collect(),
        None => area_weighted_normals(&positions, &indices),
    };
    let mut bounds = Aabb::EMPTY;
    positions.iter().for_each(|&p| bounds.grow(p));
    Ok(Primitive {
        positions,
        normals,
        indices,
        bounds,
        ..Primitive::default()
    })
}

/// Vertex normals as the area-weighted sum of the faces around each vertex.
fn area_weighted_normals(positions: &[Vec3], indices: &[u32]) -> Vec<Vec3> {
    let mut normals = vec![Vec3::ZERO; positions.len()];
    for t in indices.chunks_exact(3) {
        let [a, b, c] = [t[0], t[1], t[2]].map(|i| i as usize);
        let n = (positions[b] - positions[a]).cross(positions[c] - positions[a]);
        for v in [a, b, c] {
            normals[v] += n;
        }
    }
    normals
        .into_iter()
        .map(|n| n.normalize_or(Vec3::Y))
        .collect()
}

/// The node transform of a host instance's 3×4 matrix, refusing non-finite, singular or
/// sheared ones (a scene node is translation, rotation and scale).
pub(crate) fn instance_transform(rows: &[[f32; 4]; 3]) -> Result<Transform, RenderError> {
    let m = Mat4::from_cols(
        Vec4::new(rows[0][0], rows[1][0], rows[2][0], 0.0),
        Vec4::new(rows[0][1], rows[1][1], rows[2][1], 0.0),
        Vec4::new(rows[0][2], rows[1][2], rows[2][2], 0.0),
        Vec4::new(rows[0][3], rows[1][3], rows[2][3], 1.0),
    );
    if !m.is_finite() || m.determinant().abs() < f32::MIN_POSITIVE {
        return Err(invalid(format!(
            "instance transform {rows:?} is not finite and invertible"
        )));
    }
    let (scale, rotation, translation) = m.to_scale_rotation_translation();
    let back = Mat4::from_scale_rotation_translation(scale, rotation, translation);
    let largest = m
        .abs()
        .to_cols_array()
        .iter()
        .fold(1.0f32, |a, &b| a.max(b));
    if !back.abs_diff_eq(m, 1e-4 * largest) {
        return Err(invalid(format!(
            "instance transform {rows:?} shears: give translation, rotation and scale"
        )));
    }
    Ok(Transform {
        translation,
        rotation,
        scale,
    })
}

/// The scene of `meshes` placed by `instances`, lit by `lights` (world space): one node per
/// instance, in order, each a root.
pub(crate) fn scene(
    meshes: &[Registered],
    instances: &[HostInstance],
    lights: &[Light],
) -> Result<Scene, RenderError> {
    let mut scene = Scene {
        source: "host geometry".into(),
        ..Scene::default()
    };
    for mesh in meshes {
        let material = &mesh.material;
        scene.materials.push(Material {
            base_color: [
                material.base_color[0],
                material.base_color[1],
                material.base_color[2],
                1.0,
            ],
            emissive: material.emissive,
            metallic: material.metallic,
            roughness: material.roughness,
            double_sided: u32::from(material.double_sided),
            ..Material::default()
        });
        scene
            .material_names
            .push(format!("host material {}", scene.meshes.len()));
        // A deformable mesh is one morph target at weight 1, whose deltas are the host's
        // last shape (GpuScene::set_morph_target rewrites them per frame).
        let count = mesh.primitive.positions.len();
        let targets = match (&mesh.deltas, mesh.deformable) {
            (Some((positions, normals)), true) => vec![MorphTarget {
                positions: positions.clone(),
                normals: normals.clone(),
            }],
            (None, true) => vec![MorphTarget {
                positions: vec![Vec3::ZERO; count],
                normals: vec![Vec3::ZERO; count],
            }],
            (_, false) => Vec::new(),
        };
        let weights = if mesh.deformable {
            vec![1.0]
        } else {
            Vec::new()
        };
        let mut bounds = mesh.primitive.bounds;
        if let Some((deltas, _)) = mesh.deltas.as_ref().filter(|_| mesh.deformable) {
            for (rest, delta) in mesh.primitive.positions.iter().zip(deltas) {
                bounds.grow(*rest + *delta);
            }
        }
        scene.meshes.push(Mesh {
            primitives: vec![Primitive {
                material: (scene.materials.len() - 1) as u32,
                targets,
                bounds,
                ..mesh.primitive.clone()
            }],
            weights,
            ..Mesh::default()
        });
    }
    for (i, instance) in instances.iter().enumerate() {
        let mesh = instance.mesh.0 as usize;
        if mesh >= meshes.len() {
            return Err(invalid(format!(
                "instance {i} names mesh {mesh}; {} are registered",
                meshes.len()
            )));
        }
        scene.roots.push(scene.nodes.len());
        scene.nodes.push(Node {
            name: format!("host instance {i}"),
            transform: instance_transform(&instance.transform)?,
            mesh: Some(mesh),
            ..Node::default()
        });
    }
    for (i, light) in lights.iter().enumerate() {
        let scalars = [
            light.intensity,
            light.range,
            light.inner_cone_angle,
            light.outer_cone_angle,
        ];
        let numbers = light
            .position
            .iter()
            .chain(&light.direction)
            .chain(&light.color);
        if !numbers.chain(&scalars).all(|v| v.is_finite()) || light.light_kind().is_none() {
            return Err(invalid(format!(
                "light {i} is not finite or of no known kind"
            )));
        }
        scene.lights.push(Light {
            node: u32::MAX,
            ..*light
        });
    }
    Ok(scene)
}
