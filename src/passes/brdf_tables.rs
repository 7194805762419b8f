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

/// Scale of the fit of the cosine-averaged Schlick factor ([`diffuse_fresnel_factor`]).
pub const DIFFUSE_FRESNEL_SCALE: f32 = 0.0279;

/// Exponent of the fit of the cosine-averaged Schlick factor ([`diffuse_fresnel_factor`]).
pub const DIFFUSE_FRESNEL_POWER: f32 = 2.55;

/// `E_l[(1 − v·h)⁵]` over light directions l cosine-distributed about the normal: the Schlick
/// factor that the diffuse lobe `(1 − F(v·h)) albedo / π` of the direct pass averages to
/// under light from the whole hemisphere. Fitted as `0.0279 (1 − n·v)^2.55`, within 0.001 of
/// the integral for every n·v (`tests::diffuse_fresnel_fit`). It stays below 0.03 even at
/// grazing view, where `(1 − n·v)⁵` approaches 1: most light directions put h far from v.
pub fn diffuse_fresnel_factor(n_dot_v: f32) -> f32 {
    DIFFUSE_FRESNEL_SCALE * (1.0 - n_dot_v.clamp(0.0, 1.0)).powf(DIFFUSE_FRESNEL_POWER)
}

/// GGX α of a perceptual roughness, `roughness²` kept away from a delta lobe (≥ 10⁻³; GLSL
/// `brdf_alpha`).
pub fn alpha(roughness: f32) -> f32 {
    (roughness * roughness).max(1e-3)
}

/// Diffuse and specular weights `(kd, ks)` of the metallic-roughness material for indirect
/// light (HVL, IGI, AAF; GLSL `brdf_indirect_weights`), with `F0 = mix(0.04, albedo,
/// metallic)`:
/// - `ks = F0 + (1 − F0)(1 − n·v)⁵`: Schlick's Fresnel at the mirror direction (v·h = n·v),
///   where the glossy lobe peaks.
/// - `kd = (1 − F_d)(1 − metallic) albedo`, with `F_d = F0 + (1 − F0) diffuse_fresnel_factor(n·v)`:
///   the direct pass's `(1 − F(v·h))` averaged over the hemisphere of light directions.
///
/// Taking the mirror direction's F for the diffuse weight as well (shine's first version)
/// removed up to 65% of the diffuse light at grazing view: IGI's side walls in the cornell box
/// sat at 0.75–0.83 of the truth (docs/quality.md).
pub fn indirect_weights(albedo: Vec3, metallic: f32, n_dot_v: f32) -> (Vec3, Vec3) {
    let f0 = Vec3::splat(0.04).lerp(albedo, metallic);
    let ks = f0 + (Vec3::ONE - f0) * (1.0 - n_dot_v.clamp(0.0, 1.0)).powi(5);
    let f_diffuse = f0 + (Vec3::ONE - f0) * diffuse_fresnel_factor(n_dot_v);
    let kd = (Vec3::ONE - f_diffuse) * (1.0 - metallic) * albedo;
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
    /// The owner's tables' name (their buffers and upload pass), unique in a frame.
    name: &'static str,
    tables: Vec<(u32, Buffer)>,
    ring: UploadRing,
}

impl BrdfTables {
    /// No tables yet; `name` names their buffers and upload passes, and must differ between
    /// the owners whose tables one frame may upload (`hvl brdf tables`, …).
    pub fn new(device: &Device, name: &'static str) -> Self {
        Self {
            device: device.clone(),
            name,
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
            self.name,
            std::mem::size_of_val(data.as_slice()) as u64,
        )?;
        let handle = self
            .ring
            .upload_once(rg, self.name, &buffer, bytemuck::cast_slice(&data))?;
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

    /// The fit against the integral `E_l[(1 − v·h)⁵]` over cosine-distributed l, by a
    /// 256 × 256 midpoint rule in (cos² θ, φ) (cosine-weighted: uniform in cos² θ).
    #[test]
    fn diffuse_fresnel_fit() {
        let n = 256;
        for nv in [1.0f64, 0.9, 0.7, 0.5, 0.3, 0.2, 0.1, 0.05, 0.01] {
            let v = glam::DVec3::new((1.0 - nv * nv).sqrt(), 0.0, nv);
            let mut sum = 0.0;
            for i in 0..n {
                let u = (i as f64 + 0.5) / n as f64;
                let (r, z) = (u.sqrt(), (1.0 - u).sqrt());
                for j in 0..n {
                    let phi = std::f64::consts::TAU * (j as f64 + 0.5) / n as f64;
                    let l = glam::DVec3::new(r * phi.cos(), r * phi.sin(), z);
                    let h = (l + v).normalize();
                    sum += (1.0 - v.dot(h)).powi(5);
                }
            }
            let integral = sum / (n * n) as f64;
            let fit = f64::from(diffuse_fresnel_factor(nv as f32));
            assert!(
                (fit - integral).abs() < 1e-3,
                "n·v {nv}: fit {fit} vs {integral}"
            );
        }
        // The diffuse weight at grazing view keeps most of the albedo (it lost 65% before).
        let (kd, _) = indirect_weights(Vec3::ONE, 0.0, 0.1);
        assert!(kd.x > 0.93, "{kd}");
    }

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
