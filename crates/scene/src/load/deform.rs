//! The deformation attributes of one primitive: `JOINTS_0` and `WEIGHTS_0` (glTF 2.0 §3.7.3.3)
//! and morph targets (§3.7.2.2), checked to have one row per vertex and usable values.

use glam::{Vec3, Vec4};
use gltf::accessor::{DataType, Dimensions};

use super::accessor::Buffers;
use super::ctx::{Ctx, finite_rows};
use crate::error::Result;
use crate::types::MorphTarget;

/// Per-vertex joints and weights of a skinned primitive; both empty when it is not skinned.
pub(super) struct SkinAttributes {
    /// `JOINTS_0`.
    pub(super) joints: Vec<[u32; 4]>,
    /// `WEIGHTS_0`, normalised to sum to 1.
    pub(super) weights: Vec<Vec4>,
}

/// The accessor's rows as flat floats, checked to have `vertex_count` rows; the error names
/// `what` (an attribute) of `element`.
fn rows(
    ctx: &Ctx,
    buffers: &Buffers,
    acc: &gltf::Accessor<'_>,
    dims: Dimensions,
    vertex_count: usize,
    (element, what): (&str, &str),
) -> Result<Vec<f32>> {
    let values = buffers
        .read_rows(acc, dims)
        .map_err(|m| ctx.invalid(format!("{element} {what} (accessors[{}])", acc.index()), m))?;
    let len = values.len() / dims.multiplicity();
    if len != vertex_count {
        return Err(ctx.invalid(
            format!("{element} {what}"),
            format!("has {len} elements but POSITION has {vertex_count}"),
        ));
    }
    Ok(values)
}

/// `JOINTS_0` (unsigned byte or short VEC4) and `WEIGHTS_0` (float, or normalised unsigned
/// byte or short VEC4): both or neither. Weights must be finite and non-negative with a
/// positive sum; they are divided by their sum. Joint indices are checked against the skin
/// later, when the node using the mesh is known.
pub(super) fn skin_attributes(
    ctx: &Ctx,
    buffers: &Buffers,
    prim: &gltf::Primitive<'_>,
    element: &str,
    vertex_count: usize,
) -> Result<SkinAttributes> {
    let joints = prim.get(&gltf::Semantic::Joints(0));
    let weights = prim.get(&gltf::Semantic::Weights(0));
    let (joints, weights) = match (joints, weights) {
        (None, None) => {
            return Ok(SkinAttributes {
                joints: Vec::new(),
                weights: Vec::new(),
            });
        }
        (Some(j), Some(w)) => (j, w),
        (Some(_), None) => {
            return Err(ctx.invalid(
                element,
                "has JOINTS_0 but no WEIGHTS_0; skinning needs both",
            ));
        }
        (None, Some(_)) => {
            return Err(ctx.invalid(
                element,
                "has WEIGHTS_0 but no JOINTS_0; skinning needs both",
            ));
        }
    };
    if !matches!(joints.data_type(), DataType::U8 | DataType::U16) || joints.normalized() {
        return Err(ctx.invalid(
            format!("{element} JOINTS_0 (accessors[{}])", joints.index()),
            format!(
                "must be unsigned byte or short, not {:?}{}",
                joints.data_type(),
                if joints.normalized() {
                    " normalized"
                } else {
                    ""
                }
            ),
        ));
    }
    let float_or_normalized = match weights.data_type() {
        DataType::F32 => true,
        DataType::U8 | DataType::U16 => weights.normalized(),
        _ => false,
    };
    if !float_or_normalized {
        return Err(ctx.invalid(
            format!("{element} WEIGHTS_0 (accessors[{}])", weights.index()),
            format!(
                "must be float or normalized unsigned byte or short, not {:?}",
                weights.data_type()
            ),
        ));
    }
    let at = (element, "JOINTS_0");
    let j = rows(ctx, buffers, &joints, Dimensions::Vec4, vertex_count, at)?;
    let at = (element, "WEIGHTS_0");
    let w = rows(ctx, buffers, &weights, Dimensions::Vec4, vertex_count, at)?;
    let w = finite_rows(ctx, element, "WEIGHTS_0", &w, 4, |c| {
        Vec4::new(c[0], c[1], c[2], c[3])
    })?;
    let mut normalised = Vec::with_capacity(w.len());
    for (i, v) in w.iter().enumerate() {
        let sum = v.x + v.y + v.z + v.w;
        if v.min_element() < 0.0 || sum <= 0.0 {
            return Err(ctx.invalid(
                format!("{element} WEIGHTS_0"),
                format!(
                    "element {i} ({v}) has a negative weight or all four zero; weights must be non-negative with a positive sum"
                ),
            ));
        }
        normalised.push(*v / sum);
    }
    Ok(SkinAttributes {
        joints: j
            .chunks_exact(4)
            .map(|c| [c[0] as u32, c[1] as u32, c[2] as u32, c[3] as u32])
            .collect(),
        weights: normalised,
    })
}

/// The primitive's morph targets: finite POSITION and NORMAL deltas (either may be absent:
/// zeros for positions, empty for normals), one per vertex. Tangent deltas are ignored with
/// a warning.
pub(super) fn morph_targets(
    ctx: &mut Ctx,
    buffers: &Buffers,
    prim: &gltf::Primitive<'_>,
    element: &str,
    vertex_count: usize,
) -> Result<Vec<MorphTarget>> {
    let mut out = Vec::new();
    let mut tangents = false;
    for (k, target) in prim.morph_targets().enumerate() {
        let read = |acc: Option<gltf::Accessor<'_>>, what: &str| -> Result<Vec<Vec3>> {
            let Some(acc) = acc else {
                return Ok(Vec::new());
            };
            let what = format!("targets[{k}] {what}");
            let at = (element, what.as_str());
            let v = rows(ctx, buffers, &acc, Dimensions::Vec3, vertex_count, at)?;
            finite_rows(ctx, element, &what, &v, 3, |c| Vec3::new(c[0], c[1], c[2]))
        };
        let mut positions = read(target.positions(), "POSITION")?;
        let normals = read(target.normals(), "NORMAL")?;
        if positions.is_empty() {
            positions = vec![Vec3::ZERO; vertex_count];
        }
        tangents |= target.tangents().is_some();
        out.push(MorphTarget { positions, normals });
    }
    if tangents {
        ctx.warn(
            element,
            "has morph target TANGENT deltas; shine ignores them (tangents follow the base shape)",
        );
    }
    Ok(out)
}
