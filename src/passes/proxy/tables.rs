//! The α tables of the proxy accumulation (paper 002 §4.1) and the SH exponential's and
//! tensor's tables beside them, as one GPU buffer.

use shine_sh::exp_log::ShExp;
use shine_sh::sphere_blocker::AlphaTable;

use super::{Accumulation, ExpMethod, ProxyError, ProxyParams, TABLE_ENTRIES};

/// The α tables of the accumulation (GPU buffer `tables`): clamped log-occlusion, clamped
/// visibility, unclamped visibility, each [`TABLE_ENTRIES`] rows of `bands` floats, then the
/// OL exponential's table of shine-sh (step, `a`, `b`; read by the OL shading variant).
#[derive(Debug, Clone, PartialEq)]
pub struct ProxyTables {
    /// `O^log(α)` smoothly clamped with the shadow expansion factor.
    pub log_occlusion: AlphaTable,
    /// `V(α)` smoothly clamped with the indirect expansion factor.
    pub visibility: AlphaTable,
    /// `V(α)` unclamped (brute-force product).
    pub visibility_full: AlphaTable,
    /// Largest α at which `log_occlusion` is exactly 0 (its rows up to it are all zero).
    pub support_shadow: f32,
    /// Largest α at which `visibility` is exactly 0.
    pub support_indirect: f32,
    /// [`shine_sh::exp_log::OlTable`] of the band count: step, `a` samples, `b` samples.
    pub ol: Vec<f32>,
    /// [`shine_sh::glsl_tables::tensor_pairs`] of the band count: the entry count, packed
    /// `ijk` (as floats, exact below 2²⁴), then values.
    pub tensor: Vec<f32>,
}

/// The largest α such that every row of `table` at or below it is all zeros.
fn support(table: &AlphaTable) -> f32 {
    let n = table.bands();
    let zero_rows = table
        .data()
        .chunks_exact(n)
        .take_while(|row| row.iter().all(|&x| x == 0.0))
        .count();
    if zero_rows == 0 {
        0.0
    } else {
        (zero_rows - 1) as f32 / (table.entries() - 1) as f32
    }
}

impl ProxyTables {
    /// Builds the tables for `bands` bands and the shadow / indirect expansion factors η
    /// (§4.1: 15 for order 4, 10 for order 3).
    pub fn build(bands: u32, eta_shadow: f32, eta_indirect: f32) -> Result<Self, ProxyError> {
        let bands = ProxyParams {
            bands,
            accumulation: Accumulation::Splat,
            exp: ExpMethod::Hyb,
            indirect: true,
            specular_limit: 0.0,
        }
        .check()?;
        let mut log_occlusion = AlphaTable::log_visibility(bands, TABLE_ENTRIES)?;
        log_occlusion.smooth_clamp(eta_shadow)?;
        let mut visibility = AlphaTable::visibility(bands, TABLE_ENTRIES)?;
        visibility.smooth_clamp(eta_indirect)?;
        let visibility_full = AlphaTable::visibility(bands, TABLE_ENTRIES)?;
        let exp = ShExp::new(bands)?;
        let (a, b) = exp.ol_table().samples();
        let ol = std::iter::once(exp.ol_table().step())
            .chain(a.iter().copied())
            .chain(b.iter().copied())
            .map(|x| x as f32)
            .collect();
        let (ijk, values) = shine_sh::glsl_tables::tensor_pairs(bands)?;
        let tensor = std::iter::once(ijk.len() as f32)
            .chain(ijk.iter().map(|&x| x as f32))
            .chain(values)
            .collect();
        Ok(Self {
            ol,
            tensor,
            support_shadow: support(&log_occlusion),
            support_indirect: support(&visibility),
            log_occlusion,
            visibility,
            visibility_full,
        })
    }

    /// The GPU buffer `tables`.
    pub fn gpu_data(&self) -> Vec<f32> {
        [
            self.log_occlusion.data(),
            self.visibility.data(),
            self.visibility_full.data(),
            &self.ol,
            &self.tensor,
        ]
        .concat()
    }

    /// Float offset of the OL table in [`ProxyTables::gpu_data`].
    pub fn ol_offset(&self) -> usize {
        3 * TABLE_ENTRIES * self.log_occlusion.bands()
    }
}
