//! The proxy passes' push constants, inputs and outputs, and the functions that add them to a
//! frame's graph: `proxy_tiles`, `proxy_accumulate` and `proxy_shade`.

use glam::Vec3;

use crate::graph::{Buffer, BufferDesc, Handle, Image, RenderGraph};
use crate::passes::amortise;
use crate::passes::brdf_tables::{
    GLOSSY_ROUGHNESS_MIN, GLOSSY_TABLES, GatherBrdf, glossy_roughness_step,
};
use crate::passes::receivers::Receivers;
use crate::shaders;

use super::{
    Accumulation, GpuProxy, MAX_PROXIES, ProxyError, ProxyParams, ProxyTables, TABLE_ENTRIES,
};

/// Push constants of `shaders/proxy_accumulate.comp` (32 bytes).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct AccumulatePush {
    /// Receiver buffer size.
    pub extent: [u32; 2],
    /// Number of proxies.
    pub proxy_count: u32,
    /// Rows of each α table.
    pub table_entries: u32,
    /// [`ProxyTables::support_shadow`].
    pub support_shadow: f32,
    /// [`ProxyTables::support_indirect`] (the shadow one when indirect light is off).
    pub support_indirect: f32,
    /// 1: accumulate the indirect sums.
    pub indirect: u32,
    /// The receivers of this dispatch ([`ProxySlice::slice`]).
    pub slice: u32,
}

/// Push constants of `shaders/proxy_tiles.comp` (16 bytes).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct TilesPush {
    /// Receiver buffer size.
    pub extent: [u32; 2],
    /// Number of proxies.
    pub proxy_count: u32,
    /// The smaller of the two supports in [`AccumulatePush`].
    pub support: f32,
}

/// Side of a culling tile in receivers.
pub const TILE: u32 = 8;
/// Words of a tile's proxy mask (`MAX_PROXIES / 32`).
pub const TILE_WORDS: u32 = MAX_PROXIES / 32;

/// Push constants of `shaders/proxy_shade.comp` (48 bytes).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct ShadePush {
    /// xyz: camera position; w: the specular pass's roughness limit (0: none).
    pub camera: [f32; 4],
    /// Receiver buffer size.
    pub extent: [u32; 2],
    /// Roughness of the first glossy table, step between tables.
    pub roughness_nodes: [f32; 2],
    /// Number of glossy tables.
    pub glossy_tables: u32,
    /// The receivers of this dispatch ([`ProxySlice::slice`]).
    pub slice: u32,
    /// Padding.
    pub pad: [u32; 2],
}

/// Floats per receiver in the `proxy_sums` buffer: `bands²` (log-occlusion, or occlusion for
/// [`Accumulation::Product`]), then rgb `Σ I_i · H(N_p)` and `ω_p`.
pub fn sums_stride(bands: u32) -> usize {
    (bands * bands) as usize + 4
}

/// The GPU buffers the proxy passes read.
#[derive(Debug, Clone, Copy)]
pub struct ProxyInputs {
    /// [`GpuProxy`] records.
    pub proxies: Handle<Buffer>,
    /// How many records `proxies` holds (at most [`MAX_PROXIES`]).
    pub count: u32,
    /// [`ProxyTables::gpu_data`] at the parameters' band count.
    pub tables: Handle<Buffer>,
    /// [`EnvironmentSh::gpu_data`] at the parameters' band count.
    ///
    /// [`EnvironmentSh::gpu_data`]: crate::gpu_scene::environment_sh::EnvironmentSh::gpu_data
    pub environment: Handle<Buffer>,
    /// [`GatherBrdf::gpu_data`] at the parameters' band count: the shade pass's glossy
    /// receivers.
    pub brdf: Handle<Buffer>,
}

/// Which receivers one dispatch of the proxy passes shades: paper 001's amortised frames
/// (`proxy.slices`, [`crate::passes::amortise`]).
#[derive(Debug, Clone, Copy, Default)]
pub struct ProxySlice {
    /// 0: every receiver; 1 + k: the receiver at (k & 1, k >> 1) of every 2×2 cell;
    /// [`amortise::REGATHER_SLICE`]: the receivers `marks` marks with alpha −1.
    pub slice: u32,
    /// The proxy light after `proxy_regather_mask` (the regather reads its marks and writes
    /// into it); required by the regather slice.
    pub marks: Option<Handle<Image>>,
    /// The tile lists of the frame's first dispatch, which the regather reuses (`None`: built
    /// by this dispatch).
    pub masks: Option<Handle<Buffer>>,
}

/// The outputs of [`proxy_shade`].
#[derive(Debug, Clone, Copy)]
pub struct ProxyOutputs {
    /// `proxy_gi`: RGBA16F at receiver resolution, outgoing radiance (a = 0, 0 on background).
    pub radiance: Handle<Image>,
    /// `proxy_occlusion`: `bands²` floats per receiver, the occlusion vector `O_p` (at the
    /// receivers of the dispatch's slice only).
    pub occlusion: Handle<Buffer>,
}

fn check_inputs(
    receivers: &Receivers,
    inputs: &ProxyInputs,
    tables: &ProxyTables,
    params: &ProxyParams,
) -> Result<(), ProxyError> {
    let bands = params.check()?;
    if inputs.count > MAX_PROXIES {
        return Err(ProxyError::OutOfRange {
            name: "proxy count",
            value: f64::from(inputs.count),
            expected: format!("0..={MAX_PROXIES}"),
        });
    }
    let need = u64::from(inputs.count.max(1)) * std::mem::size_of::<GpuProxy>() as u64;
    let sizes = [
        ("proxies", inputs.proxies.desc().size, need),
        (
            "tables",
            inputs.tables.desc().size,
            (tables.gpu_data().len() * 4) as u64,
        ),
        (
            "environment",
            inputs.environment.desc().size,
            (6 * bands * bands * 4) as u64,
        ),
        (
            "brdf",
            inputs.brdf.desc().size,
            GatherBrdf::gpu_bytes(params.bands),
        ),
    ];
    for (name, actual, expected) in sizes {
        let ok = if name == "proxies" {
            actual >= expected
        } else {
            actual == expected
        };
        if !ok {
            return Err(ProxyError::Size {
                name,
                actual: format!("{actual} bytes"),
                expected: format!("{expected} bytes"),
            });
        }
    }
    if tables.log_occlusion.bands() != bands {
        return Err(ProxyError::Size {
            name: "tables",
            actual: format!("{} bands", tables.log_occlusion.bands()),
            expected: format!("{bands} bands"),
        });
    }
    let [w, h] = receivers.extent;
    if w == 0 || h == 0 {
        return Err(ProxyError::Size {
            name: "receivers",
            actual: format!("{w}×{h}"),
            expected: "a non-empty extent".into(),
        });
    }
    Ok(())
}

/// Adds the `proxy_accumulate` pass at every receiver: a new `proxy_sums` buffer
/// ([`sums_stride`] floats per receiver, row-major), returned.
pub fn proxy_accumulate(
    rg: &mut RenderGraph,
    receivers: &Receivers,
    inputs: &ProxyInputs,
    tables: &ProxyTables,
    params: &ProxyParams,
) -> Result<Handle<Buffer>, ProxyError> {
    let (sums, _) =
        proxy_accumulate_slice(rg, receivers, inputs, tables, params, ProxySlice::default())?;
    Ok(sums)
}

/// Adds `proxy_tiles` (for splatting, unless `slice` brings the frame's tile lists) and
/// `proxy_accumulate` (`proxy_reaccumulate` for the regather slice) at the receivers of
/// `slice`: returns a new `proxy_sums` buffer, valid at those receivers, and the tile lists.
pub fn proxy_accumulate_slice(
    rg: &mut RenderGraph,
    receivers: &Receivers,
    inputs: &ProxyInputs,
    tables: &ProxyTables,
    params: &ProxyParams,
    slice: ProxySlice,
) -> Result<(Handle<Buffer>, Option<Handle<Buffer>>), ProxyError> {
    check_inputs(receivers, inputs, tables, params)?;
    let marks = checked_marks(&slice)?;
    let shader = params.accumulate_shader()?;
    let [w, h] = receivers.extent;
    let support_indirect = if params.indirect {
        tables.support_indirect
    } else {
        tables.support_shadow
    };
    let masks = if params.accumulation != Accumulation::Splat {
        None
    } else if let Some(masks) = slice.masks {
        Some(masks)
    } else {
        let tiles = [w.div_ceil(TILE), h.div_ceil(TILE)];
        let bytes = u64::from(tiles[0]) * u64::from(tiles[1]) * u64::from(TILE_WORDS) * 4;
        let mut masks = rg.create_buffer("proxy_tile_masks", BufferDesc::new(bytes));
        rg.compute("proxy_tiles", &shaders::PROXY_TILES_COMP)
            .read("recv_position", &receivers.position)
            .read("proxies", &inputs.proxies)
            .write("tile_masks", &mut masks)
            .push(&TilesPush {
                extent: receivers.extent,
                proxy_count: inputs.count,
                support: tables.support_shadow.min(support_indirect),
            })
            .dispatch([tiles[0], tiles[1], 1]);
        Some(masks)
    };
    let bytes = u64::from(w) * u64::from(h) * sums_stride(params.bands) as u64 * 4;
    let mut sums = rg.create_buffer("proxy_sums", BufferDesc::new(bytes));
    let push = AccumulatePush {
        extent: receivers.extent,
        proxy_count: inputs.count,
        table_entries: TABLE_ENTRIES as u32,
        support_shadow: tables.support_shadow,
        support_indirect,
        indirect: u32::from(params.indirect),
        slice: slice.slice,
    };
    let name = if slice.slice == amortise::REGATHER_SLICE {
        "proxy_reaccumulate"
    } else {
        "proxy_accumulate"
    };
    let mut pass = rg.compute(name, shader);
    pass.read("recv_position", &receivers.position)
        .read("recv_normal", &receivers.normal)
        .read("proxies", &inputs.proxies)
        .read("tables", &inputs.tables)
        .read("environment", &inputs.environment);
    if let Some(masks) = &masks {
        pass.read("tile_masks", masks);
    }
    // Read only by the regather slice; any receiver-sized RGBA16F image fills the binding
    // of the others.
    pass.read("marks", marks.unwrap_or(&receivers.normal))
        .write("sums", &mut sums)
        .push(&push)
        .dispatch(amortise::slice_threads([w, h], slice.slice));
    Ok((sums, masks))
}

/// The marks of `slice`, after checking that the regather slice has them and no other slice
/// is out of range.
fn checked_marks(slice: &ProxySlice) -> Result<Option<&Handle<Image>>, ProxyError> {
    amortise::check_slice(slice.slice, slice.marks.is_some())?;
    Ok(slice.marks.as_ref())
}

/// Adds the `proxy_shade` pass over the sums of [`proxy_accumulate`] (`inputs.proxies` is not
/// read), the receivers seen from `camera` (their glossy lobes).
pub fn proxy_shade(
    rg: &mut RenderGraph,
    receivers: &Receivers,
    sums: &Handle<Buffer>,
    inputs: &ProxyInputs,
    tables: &ProxyTables,
    params: &ProxyParams,
    camera: Vec3,
) -> Result<ProxyOutputs, ProxyError> {
    let slice = ProxySlice::default();
    proxy_shade_slice(rg, receivers, sums, inputs, tables, params, camera, slice)
}

/// [`proxy_shade`] at the receivers of `slice` (`proxy_reshade` for the regather slice, which
/// writes into its marks; a new `proxy_gi` otherwise, valid at the slice's receivers).
#[allow(clippy::too_many_arguments)]
pub fn proxy_shade_slice(
    rg: &mut RenderGraph,
    receivers: &Receivers,
    sums: &Handle<Buffer>,
    inputs: &ProxyInputs,
    tables: &ProxyTables,
    params: &ProxyParams,
    camera: Vec3,
    slice: ProxySlice,
) -> Result<ProxyOutputs, ProxyError> {
    check_inputs(receivers, inputs, tables, params)?;
    let marks = checked_marks(&slice)?.copied();
    let shader = params.shade_shader()?;
    let table_bytes = (tables.gpu_data().len() * 4) as u64;
    if inputs.tables.desc().size != table_bytes {
        return Err(ProxyError::Size {
            name: "tables",
            actual: format!("{} bytes", inputs.tables.desc().size),
            expected: format!("{table_bytes} bytes"),
        });
    }
    let [w, h] = receivers.extent;
    let texels = u64::from(w) * u64::from(h);
    let need = texels * sums_stride(params.bands) as u64 * 4;
    if sums.desc().size != need {
        return Err(ProxyError::Size {
            name: "proxy_sums",
            actual: format!("{} bytes", sums.desc().size),
            expected: format!("{need} bytes"),
        });
    }
    let (mut radiance, name) = match marks {
        Some(marks) if slice.slice == amortise::REGATHER_SLICE => (marks, "proxy_reshade"),
        _ => (receivers.light_image(rg, "proxy_gi"), "proxy_shade"),
    };
    let coeffs = u64::from(params.bands * params.bands);
    let mut occlusion = rg.create_buffer("proxy_occlusion", BufferDesc::new(texels * coeffs * 4));
    let push = ShadePush {
        camera: camera.extend(params.specular_limit).to_array(),
        extent: receivers.extent,
        roughness_nodes: [GLOSSY_ROUGHNESS_MIN, glossy_roughness_step()],
        glossy_tables: GLOSSY_TABLES,
        slice: slice.slice,
        pad: [0; 2],
    };
    let mut pass = rg.compute(name, shader);
    pass.read("recv_position", &receivers.position)
        .read("recv_normal", &receivers.normal)
        .read("recv_albedo", &receivers.albedo)
        .read("recv_material", &receivers.material)
        .read("sums", sums)
        .read("environment", &inputs.environment)
        .read("brdf", &inputs.brdf);
    pass.read("tables", &inputs.tables)
        .write("occlusion", &mut occlusion)
        .write("proxy_gi", &mut radiance)
        .push(&push)
        .dispatch(amortise::slice_threads([w, h], slice.slice));
    Ok(ProxyOutputs {
        radiance,
        occlusion,
    })
}
