//! The flux distribution's passes ([`Distribution::Flux`](super::Distribution::Flux)):
//! `hvl_flux_rows` per RSM face, `hvl_flux_marginal`, then `hvl_cache` per face
//! (`shaders/hvl_flux.comp`; CPU twin [`crate::reference::hvl_flux`]).

use glam::Vec3;

use super::{HvlError, HvlParams, encode_projection};
use crate::graph::{Buffer, BufferDesc, Handle, RenderGraph};
use crate::passes::rsm::Rsm;
use crate::shaders;

/// Push constants of `shaders/hvl_flux.comp` (every stage), 64 bytes.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct FluxPush {
    /// xyz: the face's light position (perspective) or RSM eye (orthographic); w: its field of
    /// view λ (radians) or width W (metres).
    pub light_position_extent: [f32; 4],
    /// xyz: unit axis of the face's view; w: 1 for orthographic, 0 for perspective.
    pub light_direction_ortho: [f32; 4],
    /// The face's side S_f.
    pub face_size: u32,
    /// Index of the face's first running sum in the `cdf` buffer.
    pub texel_offset: u32,
    /// The face's first row in the global row order.
    pub row_offset: u32,
    /// R: rows of every face.
    pub rows_total: u32,
    /// T: texels of every face.
    pub texels_total: u32,
    /// HVL count M.
    pub count: u32,
    /// User radius scale k.
    pub radius_scale: f32,
    /// Padding.
    pub pad: u32,
}

/// Largest `cdf` buffer, bytes: the storage-buffer range every Vulkan device allows (2²⁷).
pub const MAX_CDF_BYTES: u64 = 1 << 27;

/// Bytes of the `cdf` buffer for faces of these sides: T running sums, then R row totals and
/// their R running sums.
pub fn cdf_bytes(sides: impl IntoIterator<Item = u32>) -> u64 {
    let (texels, rows) = sides.into_iter().fold((0u64, 0u64), |(t, r), s| {
        (t + u64::from(s) * u64::from(s), r + u64::from(s))
    });
    4 * (texels + 2 * rows)
}

/// Adds the flux distribution's passes over `faces` (the primary light's first), writing
/// `params.count` records into `hvls`.
pub(super) fn flux_cache(
    rg: &mut RenderGraph,
    faces: &[Rsm],
    params: &HvlParams,
    hvls: &mut Handle<Buffer>,
) -> Result<(), HvlError> {
    let bytes = cdf_bytes(faces.iter().map(|f| f.size));
    if bytes > MAX_CDF_BYTES {
        return Err(HvlError::Size {
            name: "hvl_flux_cdf",
            actual: format!("{bytes} bytes for {} RSM faces", faces.len()),
            expected: format!("at most {MAX_CDF_BYTES} bytes (lower rsm.size)"),
        });
    }
    let rows_total: u32 = faces.iter().map(|f| f.size).sum();
    let texels_total: u32 = faces.iter().map(|f| f.size * f.size).sum();
    let mut pushes = Vec::with_capacity(faces.len());
    let (mut texel_offset, mut row_offset) = (0, 0);
    for face in faces {
        let (extent, ortho) = encode_projection(face.projection);
        pushes.push(FluxPush {
            light_position_extent: face.light_position.extend(extent).to_array(),
            light_direction_ortho: face
                .light_direction
                .normalize_or(Vec3::NEG_Y)
                .extend(ortho)
                .to_array(),
            face_size: face.size,
            texel_offset,
            row_offset,
            rows_total,
            texels_total,
            count: params.count,
            radius_scale: params.radius_scale,
            pad: 0,
        });
        texel_offset += face.size * face.size;
        row_offset += face.size;
    }
    let mut cdf = rg.create_buffer("hvl_flux_cdf", BufferDesc::new(bytes));
    for (f, (face, push)) in faces.iter().zip(&pushes).enumerate() {
        rg.compute(&face_name("hvl_flux_rows", f), &shaders::HVL_FLUX_COMP_ROWS)
            .read("rsm_position", &face.position)
            .read("rsm_flux", &face.flux)
            .write("cdf", &mut cdf)
            .push(push)
            .dispatch([face.size, 1, 1]);
    }
    rg.compute("hvl_flux_marginal", &shaders::HVL_FLUX_COMP_MARGINAL)
        .write("cdf", &mut cdf)
        .push(&pushes[0])
        .dispatch([1, 1, 1]);
    for (f, (face, push)) in faces.iter().zip(&pushes).enumerate() {
        rg.compute(&face_name("hvl_cache", f), &shaders::HVL_FLUX_COMP_BUILD)
            .read("rsm_position", &face.position)
            .read("rsm_normal", &face.normal)
            .read("rsm_flux", &face.flux)
            .read("cdf", &cdf)
            .write("hvls", hvls)
            .push(push)
            .dispatch([params.count, 1, 1]);
    }
    Ok(())
}

/// A pass's name for face `f`: `base` for the primary light's face (the name the profiles
/// and the grid distribution use), `base f` for the others.
fn face_name(base: &str, f: usize) -> String {
    if f == 0 {
        base.to_owned()
    } else {
        format!("{base} {f}")
    }
}
