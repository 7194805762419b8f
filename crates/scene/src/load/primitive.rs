//! One glTF primitive into a [`Primitive`]: attributes read and checked (deformation ones in
//! [`super::deform`]), strips and fans triangulated, missing normals and tangents generated.

use glam::{Vec2, Vec3, Vec4};
use gltf::accessor::Dimensions;
use gltf::mesh::Mode;

use super::accessor::Buffers;
use super::ctx::{Ctx, finite_rows};
use super::deform::{self, SkinAttributes};
use super::document::semantic_name;
use super::geometry::{self, VertexData};
use crate::error::Result;
use crate::types::{Aabb, MorphTarget, Primitive};

/// Loads one primitive named `element` in messages; `None` when it is skipped (not
/// triangles, or no POSITION) with a warning.
pub(super) fn load_primitive(
    ctx: &mut Ctx,
    buffers: &Buffers,
    prim: &gltf::Primitive<'_>,
    element: &str,
    material: u32,
    normal_mapped: bool,
) -> Result<Option<Primitive>> {
    let mode = prim.mode();
    if !matches!(
        mode,
        Mode::Triangles | Mode::TriangleStrip | Mode::TriangleFan
    ) {
        ctx.warn(
            element,
            format!("mode {mode:?} is not triangles; the primitive is skipped"),
        );
        return Ok(None);
    }
    let reader = Reader {
        buffers,
        prim,
        element,
    };
    let Some(positions) = reader.positions(ctx)? else {
        return Ok(None);
    };
    let n = positions.len();
    let indices = reader.triangle_indices(ctx, mode, n)?;
    let normals = reader.normals(ctx, &positions, &indices)?;
    let uvs = reader.uvs(ctx, n)?;
    let tangents = reader.tangents(ctx, &normals)?;
    let mut skin = deform::skin_attributes(ctx, buffers, prim, element, n)?;
    let mut targets = deform::morph_targets(ctx, buffers, prim, element, n)?;
    let has_uvs = uvs.is_some();
    let mut v = VertexData {
        positions,
        normals,
        uvs: uvs.unwrap_or_else(|| vec![Vec2::ZERO; n]),
        indices,
    };
    let tangents = match tangents {
        Some(t) => t,
        None => {
            let (tangents, origins) = generated_tangents(&mut v, has_uvs && normal_mapped);
            copy_split_vertices(&origins, &mut skin, &mut targets);
            tangents
        }
    };
    Ok(Some(finish(v, tangents, material, skin, targets)))
}

/// Appends, for each vertex split off by MikkTSpace, a copy of its origin's joints,
/// weights and morph deltas, so every per-vertex array keeps the vertex count.
fn copy_split_vertices(origins: &[u32], skin: &mut SkinAttributes, targets: &mut [MorphTarget]) {
    fn copy<T: Copy>(v: &mut Vec<T>, origins: &[u32]) {
        if v.is_empty() {
            return;
        }
        for &o in origins {
            if let Some(&x) = v.get(o as usize) {
                v.push(x);
            }
        }
    }
    copy(&mut skin.joints, origins);
    copy(&mut skin.weights, origins);
    for t in targets {
        copy(&mut t.positions, origins);
        copy(&mut t.normals, origins);
    }
}

/// Reads one primitive's accessors, naming the primitive and attribute in errors.
struct Reader<'a, 'd> {
    buffers: &'a Buffers,
    prim: &'a gltf::Primitive<'d>,
    element: &'a str,
}

impl Reader<'_, '_> {
    /// The attribute's rows as flat floats, `None` when the primitive lacks it.
    fn attribute(
        &self,
        ctx: &Ctx,
        semantic: gltf::Semantic,
        dims: Dimensions,
    ) -> Result<Option<Vec<f32>>> {
        match self.prim.get(&semantic) {
            None => Ok(None),
            Some(acc) => self.buffers.read_rows(&acc, dims).map(Some).map_err(|m| {
                ctx.invalid(
                    format!(
                        "{} {} (accessors[{}])",
                        self.element,
                        semantic_name(&semantic),
                        acc.index()
                    ),
                    m,
                )
            }),
        }
    }

    /// Finite positions; `None` (with a warning) when the primitive has no POSITION.
    fn positions(&self, ctx: &mut Ctx) -> Result<Option<Vec<Vec3>>> {
        let Some(pos) = self.attribute(ctx, gltf::Semantic::Positions, Dimensions::Vec3)? else {
            ctx.warn(
                self.element,
                "has no POSITION attribute; the primitive is skipped",
            );
            return Ok(None);
        };
        finite_rows(ctx, self.element, "POSITION", &pos, 3, |c| {
            Vec3::new(c[0], c[1], c[2])
        })
        .map(Some)
    }

    /// A per-vertex attribute as rows made by `make`, checked to have `vertex_count` rows of
    /// finite floats; `None` when the primitive lacks it.
    fn per_vertex<T>(
        &self,
        ctx: &Ctx,
        semantic: gltf::Semantic,
        dims: Dimensions,
        vertex_count: usize,
        make: impl Fn(&[f32]) -> T,
    ) -> Result<Option<Vec<T>>> {
        let what = semantic_name(&semantic);
        let Some(values) = self.attribute(ctx, semantic, dims)? else {
            return Ok(None);
        };
        let width = dims.multiplicity();
        let len = values.len() / width;
        if len != vertex_count {
            return Err(ctx.invalid(
                format!("{} {what}", self.element),
                format!("has {len} elements but POSITION has {vertex_count}"),
            ));
        }
        finite_rows(ctx, self.element, &what, &values, width, make).map(Some)
    }

    /// Unit normals: the file's (see [`unit_normals`]), else smooth normals over `indices`.
    fn normals(&self, ctx: &Ctx, positions: &[Vec3], indices: &[u32]) -> Result<Vec<Vec3>> {
        let raw = self.per_vertex(
            ctx,
            gltf::Semantic::Normals,
            Dimensions::Vec3,
            positions.len(),
            |c| Vec3::new(c[0], c[1], c[2]),
        )?;
        Ok(match raw {
            Some(raw) => unit_normals(&raw, positions, indices),
            None => geometry::smooth_normals(positions, indices),
        })
    }

    /// The first texture coordinate set, `None` when the primitive has none.
    fn uvs(&self, ctx: &Ctx, vertex_count: usize) -> Result<Option<Vec<Vec2>>> {
        self.per_vertex(
            ctx,
            gltf::Semantic::TexCoords(0),
            Dimensions::Vec2,
            vertex_count,
            |c| Vec2::new(c[0], c[1]),
        )
    }

    /// The file's tangents made unit (see [`unit_tangents`]), `None` when it has none.
    fn tangents(&self, ctx: &Ctx, normals: &[Vec3]) -> Result<Option<Vec<Vec4>>> {
        let raw = self.per_vertex(
            ctx,
            gltf::Semantic::Tangents,
            Dimensions::Vec4,
            normals.len(),
            |c| Vec4::new(c[0], c[1], c[2], c[3]),
        )?;
        Ok(raw.map(|raw| unit_tangents(&raw, normals)))
    }

    /// The primitive's indices (or `0..vertex_count` without an index accessor), checked to
    /// be in range and turned into a triangle list; a trailing partial triangle is dropped
    /// with a warning.
    fn triangle_indices(&self, ctx: &mut Ctx, mode: Mode, vertex_count: usize) -> Result<Vec<u32>> {
        let element = self.element;
        let raw = match self.prim.indices() {
            Some(acc) => self.buffers.read_indices(&acc).map_err(|m| {
                ctx.invalid(format!("{element} indices (accessors[{}])", acc.index()), m)
            })?,
            None => (0..vertex_count as u32).collect(),
        };
        if let Some((k, &v)) = raw
            .iter()
            .enumerate()
            .find(|&(_, &v)| v as usize >= vertex_count)
        {
            return Err(ctx.invalid(
                format!("{element} indices"),
                format!("index {k} has value {v}, out of range for {vertex_count} vertices"),
            ));
        }
        let mut indices = triangle_list(mode, raw);
        if !indices.len().is_multiple_of(3) {
            ctx.warn(
                format!("{element} indices"),
                format!(
                    "{} indices is not a multiple of 3; the last partial triangle is dropped",
                    indices.len()
                ),
            );
            indices.truncate(indices.len() / 3 * 3);
        }
        Ok(indices)
    }
}

/// Indices of `mode` (triangles, strip or fan) as a triangle list, strips keeping their
/// winding by swapping the first two corners of every odd triangle.
fn triangle_list(mode: Mode, raw: Vec<u32>) -> Vec<u32> {
    match mode {
        Mode::TriangleStrip => (0..raw.len().saturating_sub(2))
            .flat_map(|i| {
                let w = raw.get(i..i + 3).unwrap_or(&[0, 0, 0]);
                if i % 2 == 0 {
                    [w[0], w[1], w[2]]
                } else {
                    [w[1], w[0], w[2]]
                }
            })
            .collect(),
        Mode::TriangleFan => (1..raw.len().saturating_sub(1))
            .flat_map(|i| {
                let first = raw.first().copied().unwrap_or(0);
                let w = raw.get(i..i + 2).unwrap_or(&[0, 0]);
                [first, w[0], w[1]]
            })
            .collect(),
        _ => raw,
    }
}

/// The file's normals normalised; a zero normal takes the smooth normal of its vertex (or
/// +Y when that is zero too).
fn unit_normals(raw: &[Vec3], positions: &[Vec3], indices: &[u32]) -> Vec<Vec3> {
    let generated = raw
        .iter()
        .any(|x| x.length_squared() < 1e-12)
        .then(|| geometry::smooth_normals(positions, indices));
    raw.iter()
        .enumerate()
        .map(|(i, x)| {
            x.try_normalize()
                .or_else(|| generated.as_ref().and_then(|g| g.get(i).copied()))
                .unwrap_or(Vec3::Y)
        })
        .collect()
}

/// The file's tangents with unit `xyz` and handedness ±1; a zero tangent is replaced by any
/// perpendicular to its normal.
fn unit_tangents(raw: &[Vec4], normals: &[Vec3]) -> Vec<Vec4> {
    raw.iter()
        .zip(normals)
        .map(|(t, n)| match t.truncate().try_normalize() {
            Some(d) => d.extend(if t.w < 0.0 { -1.0 } else { 1.0 }),
            None => geometry::any_tangent(*n),
        })
        .collect()
}

/// Tangents for a primitive whose file has none: MikkTSpace when `mikktspace` (the
/// primitive has UVs and a normal map), any perpendicular to the normal otherwise. Also
/// returns the origins of the vertices MikkTSpace split off (see
/// [`geometry::mikktspace_tangents`]).
///
/// Tangents only matter under a normal map; elsewhere a perpendicular will do and
/// MikkTSpace's cost (about 2.5 s per million triangles) is not paid.
fn generated_tangents(v: &mut VertexData, mikktspace: bool) -> (Vec<Vec4>, Vec<u32>) {
    if mikktspace {
        geometry::mikktspace_tangents(v)
    } else {
        let tangents = v
            .normals
            .iter()
            .map(|n| geometry::any_tangent(*n))
            .collect();
        (tangents, Vec::new())
    }
}

/// The finished primitive with the bounds of its positions.
fn finish(
    v: VertexData,
    tangents: Vec<Vec4>,
    material: u32,
    skin: SkinAttributes,
    targets: Vec<MorphTarget>,
) -> Primitive {
    let bounds = v.positions.iter().fold(Aabb::EMPTY, |mut b, p| {
        b.grow(*p);
        b
    });
    Primitive {
        positions: v.positions,
        normals: v.normals,
        tangents,
        uvs: v.uvs,
        indices: v.indices,
        material,
        bounds,
        joints: skin.joints,
        weights: skin.weights,
        targets,
    }
}
