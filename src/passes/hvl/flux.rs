//! The flux distribution's passes ([`Distribution::Flux`](super::Distribution::Flux)):
//! `hvl_flux_rows` and `hvl_flux_marginal` per RSM face, `hvl_flux_budget`, then
//! `hvl_cache` per face (`shaders/hvl_flux.comp`; CPU twin [`crate::reference::hvl_flux`]).
//! Each RSM face (a point light has six) owns a progressive sample sequence whose members keep
//! their identity from frame to frame (issue 43; the shader's header tells how).

use glam::Vec3;

use super::{HvlError, HvlParams, encode_projection};
use crate::graph::{Buffer, BufferDesc, Handle, RenderGraph};
use crate::passes::rsm::Rsm;
use crate::passes::shadows::CUBE_FACES;
use crate::shaders;

/// Push constants of `shaders/hvl_flux.comp` (every stage), 80 bytes.
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
    /// The face's light: its first row in the global row order.
    pub light_row_offset: u32,
    /// The face's light: its rows (the sum of its faces' sides).
    pub light_rows: u32,
    /// The face's light: its place k in the light order.
    pub light_order: u32,
    /// The face's light: its index in the scene (the samples' identity).
    pub light_id: u32,
    /// N: lights.
    pub light_count: u32,
}

/// Most RSM faces of one light (a point light's cube): the sequences' identities leave this
/// many per light.
pub const FACES_PER_LIGHT: u32 = CUBE_FACES.len() as u32;

/// The identity of the sample sequence of face `face` (its place among its light's faces) of
/// scene light `light`: `light · FACES_PER_LIGHT + face`. Each face owns a sequence: one over
/// a point light's six faces ran from one face's last row into the next face's first, so a
/// sample could step across the room when flux moved between faces (issue 43).
pub fn sequence_id(light: u32, face: u32) -> u32 {
    light * FACES_PER_LIGHT + face
}

/// The sequence identities of a face list given each face's scene light in order (a point
/// light's cube faces consecutive): each face's [`sequence_id`] of its light and its place
/// among that light's faces.
pub fn sequence_ids(lights: impl IntoIterator<Item = u32>) -> Vec<u32> {
    let mut last: Option<u32> = None;
    let mut within = 0;
    lights
        .into_iter()
        .map(|light| {
            within = if last == Some(light) { within + 1 } else { 0 };
            last = Some(light);
            sequence_id(light, within)
        })
        .collect()
}

/// Largest `cdf` buffer, bytes: the storage-buffer range every Vulkan device allows (2²⁷).
pub const MAX_CDF_BYTES: u64 = 1 << 27;

/// Bytes of the `cdf` buffer for faces of these sides and `lights` lights: T running sums,
/// R row totals and their R running sums, then the light table (4 floats and 4 per light).
pub fn cdf_bytes(sides: impl IntoIterator<Item = u32>, lights: usize) -> u64 {
    let (texels, rows) = sides.into_iter().fold((0u64, 0u64), |(t, r), s| {
        (t + u64::from(s) * u64::from(s), r + u64::from(s))
    });
    4 * (texels + 2 * rows + 4 * (lights as u64 + 1))
}

/// One face's sample sequence (the shader's "light"): its identity ([`sequence_id`]), its
/// face (whose place in the face list is the sequence's in the order), and its rows in the
/// global row order.
struct LightRun {
    id: u32,
    face: usize,
    row_offset: u32,
    rows: u32,
}

/// The faces' sequences, one per face in order (a point light's six cube faces are
/// consecutive, faces 0–5 of its light): the twin's [`light_faces`](crate::reference::hvl_flux::light_faces).
fn light_runs(faces: &[Rsm]) -> Vec<LightRun> {
    let ids = sequence_ids(faces.iter().map(|face| face.light));
    let mut row = 0;
    let mut runs = Vec::with_capacity(faces.len());
    for (f, (face, id)) in faces.iter().zip(ids).enumerate() {
        runs.push(LightRun {
            id,
            face: f,
            row_offset: row,
            rows: face.size,
        });
        row += face.size;
    }
    runs
}

/// Adds the flux distribution's passes over `faces` (the primary light's first), writing
/// `params.count` records into `hvls`.
pub(super) fn flux_cache(
    rg: &mut RenderGraph,
    faces: &[Rsm],
    params: &HvlParams,
    hvls: &mut Handle<Buffer>,
) -> Result<(), HvlError> {
    let runs = light_runs(faces);
    let bytes = cdf_bytes(faces.iter().map(|f| f.size), runs.len());
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
    for (run, face) in runs.iter().map(|run| (run, &faces[run.face])) {
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
            light_row_offset: run.row_offset,
            light_rows: run.rows,
            light_order: run.face as u32,
            light_id: run.id,
            light_count: runs.len() as u32,
        });
        texel_offset += face.size * face.size;
        row_offset += face.size;
    }
    let mut cdf = rg.create_buffer("hvl_flux_cdf", BufferDesc::new(bytes));
    // Slots no light keeps stay empty records.
    rg.fill_buffer("hvl_cache_clear", hvls, 0);
    for (f, (face, push)) in faces.iter().zip(&pushes).enumerate() {
        rg.compute(&face_name("hvl_flux_rows", f), &shaders::HVL_FLUX_COMP_ROWS)
            .read("rsm_position", &face.position)
            .read("rsm_flux", &face.flux)
            .write("cdf", &mut cdf)
            .push(push)
            .dispatch([face.size, 1, 1]);
    }
    for run in &runs {
        rg.compute(
            &face_name("hvl_flux_marginal", run.face),
            &shaders::HVL_FLUX_COMP_MARGINAL,
        )
        .write("cdf", &mut cdf)
        .push(&pushes[run.face])
        .dispatch([1, 1, 1]);
    }
    rg.compute("hvl_flux_budget", &shaders::HVL_FLUX_COMP_BUDGET)
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

/// A pass's name for face (or light) `f`: `base` for the primary light's (the name the
/// profiles and the grid distribution use), `base f` for the others.
fn face_name(base: &str, f: usize) -> String {
    if f == 0 {
        base.to_owned()
    } else {
        format!("{base} {f}")
    }
}
