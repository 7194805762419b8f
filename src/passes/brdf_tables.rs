//! The receiver BRDF as SH tables (paper 003 §4.2, eq. 18), shared by the HVL gather and IGI's
//! SH resolve: Lambert plus GGX at [`GLOSSY_TABLES`] roughness nodes, the material weights
//! `kd`/`ks` of indirect light, and [`BrdfTables`], the tables kept on the device per band count.
//!
//! The GLSL twin is `shaders/include/brdf_table.glsl`.

use crate::gpu_scene::BUFFER_READ;
use crate::gpu_scene::upload_ring::UploadRing;
use glam::Vec3;
use shine_gpu::{Buffer, Device};
use shine_graph::{Handle, RenderGraph};
use shine_sh::ShError;
use shine_sh::brdf_table::{BrdfModel, BrdfTable, HemisphereSampling};

/// Number of glossy BRDF tables of the gather, at the roughness nodes of [`glossy_roughness`].
pub const GLOSSY_TABLES: u32 = 5;

/// Perceptual roughness of the first glossy table; the nodes are spaced evenly up to 1.
pub const GLOSSY_ROUGHNESS_MIN: f32 = 0.2;

/// The Fresnel index of refraction of the glossy tables (dielectrics; metals take their colour
/// from `ks`).
pub const GLOSSY_IOR: f32 = 1.5;

/// Perceptual roughness of glossy table `k` (GGX α = roughness², as the direct light).
pub fn glossy_roughness(k: u32) -> f32 {
    GLOSSY_ROUGHNESS_MIN + k as f32 * glossy_roughness_step()
}

/// Roughness between two glossy tables.
pub fn glossy_roughness_step() -> f32 {
    (1.0 - GLOSSY_ROUGHNESS_MIN) / (GLOSSY_TABLES - 1) as f32
}

/// The two glossy tables around `roughness` and the weight of the second: `(k, k + 1, t)`,
/// clamped to the nodes (the GLSL twin is `brdf_table_glossy_row` in
/// `shaders/include/brdf_table.glsl`).
pub fn glossy_blend(roughness: f32) -> (u32, u32, f32) {
    let x = ((roughness - GLOSSY_ROUGHNESS_MIN) / glossy_roughness_step())
        .clamp(0.0, (GLOSSY_TABLES - 1) as f32);
    let k0 = (x.floor() as u32).min(GLOSSY_TABLES - 1);
    let k1 = (k0 + 1).min(GLOSSY_TABLES - 1);
    (k0, k1, x - k0 as f32)
}

/// Diffuse and specular weights `(kd, ks)` of the metallic-roughness material for indirect
/// light (HVL and IGI; GLSL `brdf_indirect_weights`): Schlick's Fresnel F at the mirror
/// direction (v·h = n·v), `kd = (1 - F)(1 - metallic) albedo` (the direct pass's diffuse),
/// `ks = F` with `F0 = mix(0.04, albedo, metallic)`.
pub fn indirect_weights(albedo: Vec3, metallic: f32, n_dot_v: f32) -> (Vec3, Vec3) {
    let f0 = Vec3::splat(0.04).lerp(albedo, metallic);
    let ks = f0 + (Vec3::ONE - f0) * (1.0 - n_dot_v.clamp(0.0, 1.0)).powi(5);
    let kd = (Vec3::ONE - ks) * (1.0 - metallic) * albedo;
    (kd, ks)
}

/// The weight of a GGX table's glossy row for a material whose Fresnel is `ks` (GLSL
/// `brdf_table_fresnel_weight`): the tables hold the exact dielectric Fresnel of
/// [`GLOSSY_IOR`] at each direction's v·h; dividing `ks` by Schlick's F with F0 = 0.04 at
/// `n_dot_v` swaps it for the material's approximately (an n·v stand-in for v·h): 1 for
/// dielectrics, about albedo / 0.04 for metals at normal view.
pub fn table_fresnel_weight(ks: Vec3, n_dot_v: f32) -> Vec3 {
    ks / (0.04 + 0.96 * (1.0 - n_dot_v.clamp(0.0, 1.0)).powi(5))
}

/// The receiver BRDF SH tables of the full gather path (paper 003 §4.2, eq. 18): `F` of
/// Lambert (albedo 1, scaled by `kd` per receiver) and `F` of GGX at each roughness node
/// (scaled by `ks`).
#[derive(Debug, Clone, PartialEq)]
pub struct GatherBrdf {
    /// `F` of Lambert with albedo 1.
    pub lambert: BrdfTable,
    /// `F` of GGX at [`glossy_roughness`]`(k)`, k = 0..[`GLOSSY_TABLES`].
    pub glossy: Vec<BrdfTable>,
}

impl GatherBrdf {
    /// Tabulates every BRDF to `conv_bands` bands with the hemisphere quadrature `sampling`.
    pub fn build(conv_bands: u32, sampling: HemisphereSampling) -> Result<Self, ShError> {
        let bands = conv_bands as usize;
        let glossy = (0..GLOSSY_TABLES)
            .map(|k| {
                let r = glossy_roughness(k);
                let model = BrdfModel::Ggx {
                    alpha: r * r,
                    ior: GLOSSY_IOR,
                };
                BrdfTable::build_with(model, bands, sampling)
            })
            .collect::<Result<_, _>>()?;
        Ok(Self {
            lambert: BrdfTable::build_with(BrdfModel::Lambert { albedo: 1.0 }, bands, sampling)?,
            glossy,
        })
    }

    /// The glossy row `F(θ_o)` at `roughness`: the two nodes' rows blended linearly.
    pub fn glossy_f(&self, roughness: f32, theta_o: f32) -> Vec<f32> {
        let (k0, k1, t) = glossy_blend(roughness);
        let a = self.glossy[k0 as usize].lookup_f(theta_o);
        let b = self.glossy[k1 as usize].lookup_f(theta_o);
        a.iter()
            .zip(&b)
            .map(|(a, b)| a * (1.0 - t) + b * t)
            .collect()
    }

    /// The GPU buffer `brdf` of the gather: Lambert `F` rows then each glossy table's `F` rows
    /// (`(1 + GLOSSY_TABLES) × 90 × bands²` floats, the shine-sh table layout).
    pub fn gpu_data(&self) -> Vec<f32> {
        std::iter::once(&self.lambert)
            .chain(&self.glossy)
            .flat_map(|t| t.f().iter().copied())
            .collect()
    }

    /// Bytes of [`GatherBrdf::gpu_data`] at `conv_bands` bands.
    pub fn gpu_bytes(conv_bands: u32) -> u64 {
        u64::from(1 + GLOSSY_TABLES)
            * shine_sh::brdf_table::THETA_SAMPLES as u64
            * u64::from(conv_bands * conv_bands)
            * 4
    }
}

/// The [`GatherBrdf`] tables on the device, built once per convolution band count and kept
/// for the renderer's life (a few hundred KiB each). The first frame that needs a band count
/// uploads it with a transfer pass of its own (nothing waits).
pub struct BrdfTables {
    device: Device,
    tables: Vec<(u32, Buffer)>,
    ring: UploadRing,
}

impl BrdfTables {
    /// No tables yet.
    pub fn new(device: &Device) -> Self {
        Self {
            device: device.clone(),
            tables: Vec::new(),
            ring: UploadRing::new(device),
        }
    }

    /// Bytes of device memory: `(tables, staging)`.
    pub fn allocated_bytes(&self) -> (u64, u64) {
        (
            self.tables.iter().map(|(_, b)| b.allocated_bytes()).sum(),
            self.ring.allocated_bytes(),
        )
    }

    /// Forgets every table (a frame that uploaded one was dropped unrun).
    pub fn clear(&mut self) {
        self.tables.clear();
    }

    /// The tables at `bands` bands in `rg`: imported, or built and uploaded by this frame.
    pub fn import(
        &mut self,
        rg: &mut RenderGraph,
        bands: u32,
    ) -> Result<Handle<shine_graph::Buffer>, BrdfTablesError> {
        if let Some((_, buffer)) = self.tables.iter().find(|(b, _)| *b == bands) {
            return Ok(rg.import_gpu_buffer(buffer, BUFFER_READ, BUFFER_READ));
        }
        let tables = GatherBrdf::build(bands, HemisphereSampling::default())?;
        let data = tables.gpu_data();
        let buffer = Buffer::storage_for_uploads(
            &self.device,
            "brdf tables",
            std::mem::size_of_val(data.as_slice()) as u64,
        )?;
        let handle =
            self.ring
                .upload_once(rg, "brdf tables", &buffer, bytemuck::cast_slice(&data))?;
        self.tables.push((bands, buffer));
        Ok(handle)
    }
}

/// Why the BRDF tables could not be made.
#[derive(Debug, thiserror::Error)]
pub enum BrdfTablesError {
    /// Tabulating the BRDFs failed (a band count out of shine-sh's range).
    #[error("BRDF SH table: {0}")]
    Sh(#[from] ShError),
    /// Uploading them failed.
    #[error(transparent)]
    Gpu(#[from] shine_gpu::Error),
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn glossy_blend_clamps_and_hits_nodes() {
        assert_eq!(glossy_blend(0.0), (0, 1, 0.0));
        assert_eq!(
            glossy_blend(1.0),
            (GLOSSY_TABLES - 1, GLOSSY_TABLES - 1, 0.0)
        );
        let (k0, k1, t) = glossy_blend(glossy_roughness(2));
        assert!((k0 == 2 && t.abs() < 1e-5) || (k0 == 1 && k1 == 2 && (t - 1.0).abs() < 1e-5));
        let (k0, k1, t) = glossy_blend(0.5 * (glossy_roughness(1) + glossy_roughness(2)));
        assert_eq!((k0, k1), (1, 2));
        assert!((t - 0.5).abs() < 1e-5);
    }
}
