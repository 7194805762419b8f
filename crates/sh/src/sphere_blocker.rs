//! Paper 002: canonical ZH tables of a sphere blocker as functions of `α = sin θ`, their smooth
//! clamping (§4.1), and the self-shadowing replacement rules for receivers near a proxy.
//!
//! A sphere seen from `p` under half-angle `θ` (`sin θ = r/d`, eq. 1) with its centre on +z
//! covers the cap `s_z ≥ cos θ`. Two tables are tabulated at `α_i = i/(N-1)`:
//!
//! * [`AlphaTable::log_visibility`]: `O^log(α)`, the SH log of the environment visibility
//!   `1 - cap` ([`crate::exp_log::ShExp::log`], computed on the `m = 0` block with the whole
//!   matrix's eigenvalue floor), for shadow accumulation;
//! * [`AlphaTable::visibility`]: `V(α)`, the cap itself (paper 003 eq. 14), for indirect
//!   accumulation (paper 002 §5).
//!
//! Rows are `bands` ZH coefficients; `data()[i * bands + l]`. Rotate a row to the proxy
//! direction with [`crate::zonal::rotate_zh`] (paper 002 eq. 8).

use glam::Vec3;

use crate::exp_log::zonal_log;
use crate::product::TripleProduct;
use crate::zonal::cap_zh_f64;
use crate::{Result, ShError, check_bands, check_range};

const SQRT_4PI: f64 = 3.544_907_701_811_032;

/// A table of ZH vectors sampled uniformly in `α = sin θ ∈ [0, 1]`.
#[derive(Debug, Clone, PartialEq)]
pub struct AlphaTable {
    bands: usize,
    entries: usize,
    data: Vec<f32>,
}

fn check_entries(entries: usize) -> Result<usize> {
    if (2..=65_536).contains(&entries) {
        Ok(entries)
    } else {
        Err(ShError::OutOfRange {
            name: "table entries",
            value: entries as f64,
            expected: "2..=65536",
        })
    }
}

impl AlphaTable {
    fn alpha_of(i: usize, entries: usize) -> f64 {
        i as f64 / (entries - 1) as f64
    }

    /// Log-visibility table `O^log(α)` (bands `1..=MAX_PRODUCT_BANDS`, `entries ≥ 2`).
    pub fn log_visibility(bands: usize, entries: usize) -> Result<Self> {
        let tensor = TripleProduct::new(bands)?;
        let entries = check_entries(entries)?;
        let mut data = Vec::with_capacity(bands * entries);
        let mut cap = vec![0.0; bands];
        for i in 0..entries {
            let a = Self::alpha_of(i, entries);
            cap_zh_f64((1.0 - a * a).max(0.0).sqrt(), bands, &mut cap)?;
            let g: Vec<f64> = cap
                .iter()
                .enumerate()
                .map(|(l, &c)| if l == 0 { SQRT_4PI - c } else { -c })
                .collect();
            data.extend(zonal_log(&tensor, &g).into_iter().map(|x| x as f32));
        }
        Ok(Self {
            bands,
            entries,
            data,
        })
    }

    /// Visibility table `V(α)`: the cap of half-angle `asin α` (bands `1..=MAX_BANDS`).
    pub fn visibility(bands: usize, entries: usize) -> Result<Self> {
        check_bands(bands)?;
        let entries = check_entries(entries)?;
        let mut data = Vec::with_capacity(bands * entries);
        let mut cap = vec![0.0; bands];
        for i in 0..entries {
            let a = Self::alpha_of(i, entries);
            cap_zh_f64((1.0 - a * a).max(0.0).sqrt(), bands, &mut cap)?;
            data.extend(cap.iter().map(|&x| x as f32));
        }
        Ok(Self {
            bands,
            entries,
            data,
        })
    }

    /// Paper 002 §4.1 smooth clamping for the radius expansion factor `η > 1` (15 for order-4
    /// shadows, 10 for order-3 indirect): proxies subtending less than `α_c = 1/η` are outside
    /// their sphere of influence and must fade to zero without a jump.
    ///
    /// Our rule (the paper only says "the 4 entries around 1/η are weighted smoothly to 0"): with
    /// `i_c = floor(α_c (N-1))`, entries `i_c-1 ..= i_c+2` are multiplied by `S((k+1)/5)`,
    /// `k = 0..3` (0.104, 0.352, 0.648, 0.896; `S` = smoothstep), entries below `i_c-1` are zeroed,
    /// entries above are unchanged.
    pub fn smooth_clamp(&mut self, eta: f32) -> Result<()> {
        let eta = check_range("expansion factor η", f64::from(eta), 1.0, 1e6, "1..=1e6")?;
        let ic = ((self.entries - 1) as f64 / eta).floor() as i64;
        for i in 0..self.entries {
            let k = i as i64 - (ic - 1);
            let w = if k < 0 {
                0.0
            } else if k > 3 {
                1.0
            } else {
                let x = (k as f64 + 1.0) / 5.0;
                x * x * (3.0 - 2.0 * x)
            };
            for c in &mut self.data[i * self.bands..(i + 1) * self.bands] {
                *c = (f64::from(*c) * w) as f32;
            }
        }
        Ok(())
    }

    /// Band count of each row.
    pub fn bands(&self) -> usize {
        self.bands
    }

    /// Number of rows `N`.
    pub fn entries(&self) -> usize {
        self.entries
    }

    /// Row-major data, `entries × bands` floats (GPU layout: an R32F image `bands × N`, sampled
    /// at `v = α` with texel-centre addressing `(α (N-1) + 0.5)/N`).
    pub fn data(&self) -> &[f32] {
        &self.data
    }

    /// The ZH vector at `α` (clamped to `[0, 1]`), linearly interpolated.
    pub fn lookup(&self, alpha: f32) -> Vec<f32> {
        let a = if alpha.is_finite() {
            f64::from(alpha).clamp(0.0, 1.0)
        } else {
            0.0
        };
        let x = a * (self.entries - 1) as f64;
        let i0 = (x.floor() as usize).min(self.entries - 2);
        let t = (x - i0 as f64) as f32;
        let n = self.bands;
        (0..n)
            .map(|l| self.data[i0 * n + l] * (1.0 - t) + self.data[(i0 + 1) * n + l] * t)
            .collect()
    }
}

/// The outcome of the self-shadowing rules for one proxy and one receiver.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum BlockerSubstitute {
    /// The proxy casts no shadow on this receiver.
    Skip,
    /// Use this sphere (possibly the original) for the receiver.
    Use {
        /// Centre of the sphere to accumulate.
        center: Vec3,
        /// Its radius.
        radius: f32,
    },
}

/// Self-shadowing replacement rules for a proxy `(center, radius)` seen from receiver `p` with
/// unit normal `n` (after Ren et al. 2006 §5, which paper 002 §3 refers to). With
/// `h = (c - p)·n` the height of the centre above the tangent plane:
///
/// 1. `h + r ≤ 0`: the sphere is entirely below the tangent plane → [`BlockerSubstitute::Skip`].
/// 2. `p` inside the sphere and `h ≤ 0` → `Skip` (the receiver is buried in its own proxy).
/// 3. `|h| < r` (the sphere pokes through the plane): replace it by the sphere spanning from the
///    plane to the top of the original, `c' = c + (r-h)/2 n`, `r' = (r+h)/2`; `p` is outside it.
///    When `h < 0` we scale `r'` by `t^(-h/r)`, `t = clamp((ρ - c_r)/c_r, 0, 1)`, `ρ` the distance
///    from `p` to the centre's foot on the plane and `c_r = sqrt(r² - h²)` the radius of the
///    sphere's footprint on the plane. This fade is our own: it is 1 at `h = 0` (continuous with
///    the `h > 0` case) and 0 when `p` reaches the footprint (continuous with rule 2).
/// 4. Otherwise the sphere is used unchanged.
pub fn self_shadow_substitute(
    p: Vec3,
    n: Vec3,
    center: Vec3,
    radius: f32,
) -> Result<BlockerSubstitute> {
    let n = crate::basis::unit_dir(n)?;
    let r = check_range("proxy radius", f64::from(radius), 0.0, f64::MAX, "≥ 0")?;
    let c = center.as_dvec3();
    let p = p.as_dvec3();
    let h = (c - p).dot(n);
    let d = (c - p).length();
    if h + r <= 0.0 || (d < r && h <= 0.0) {
        return Ok(BlockerSubstitute::Skip);
    }
    if h >= r {
        return Ok(BlockerSubstitute::Use { center, radius });
    }
    let new_center = c + n * (0.5 * (r - h));
    let mut new_radius = 0.5 * (r + h);
    if h < 0.0 {
        let foot = c - n * h;
        let rho = (foot - p).length();
        let cr = (r * r - h * h).max(0.0).sqrt();
        let t = if cr > 0.0 {
            ((rho - cr) / cr).clamp(0.0, 1.0)
        } else {
            1.0
        };
        let fade = if t <= 0.0 { 0.0 } else { t.powf(-h / r) };
        new_radius *= fade;
        if new_radius <= 0.0 {
            return Ok(BlockerSubstitute::Skip);
        }
    }
    Ok(BlockerSubstitute::Use {
        center: new_center.as_vec3(),
        radius: new_radius as f32,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::exp_log::ShExp;
    use crate::zonal::cap_zh;

    #[test]
    fn log_table_matches_sh_log_and_exponentiates_back() {
        let bands = 4;
        let table = AlphaTable::log_visibility(bands, 65).unwrap();
        let sx = ShExp::new(bands).unwrap();
        // 56 and 64 (61°, 90°) clamp eigenvalues: the table's ε (from every m block) must be
        // the full log's (from the whole matrix)
        for &i in &[8usize, 20, 40, 56, 64] {
            let alpha = i as f32 / 64.0;
            let zh = table.lookup(alpha);
            // full-SH log of the same blocker (ZH expanded on +z)
            let cap = cap_zh(alpha.asin(), bands).unwrap();
            let mut v = vec![0.0f32; 16];
            for l in 0..bands {
                v[crate::index(l, 0)] = -cap[l];
            }
            v[0] += SQRT_4PI as f32;
            let log = sx.log(&v).unwrap();
            for l in 0..bands {
                assert!(
                    (log[crate::index(l, 0)] - zh[l]).abs() < 1e-4,
                    "α={alpha} l={l}"
                );
            }
            if i > 40 {
                continue;
            }
            let mut full = vec![0.0f32; 16];
            for l in 0..bands {
                full[crate::index(l, 0)] = zh[l];
            }
            let back = sx.exp_exact(&full).unwrap();
            for (b, x) in back.iter().zip(&v) {
                assert!((b - x).abs() < 1e-3);
            }
        }
        assert!(table.data()[..bands].iter().all(|&x| x.abs() < 1e-6));
    }

    #[test]
    fn smooth_clamp_fades_to_zero() {
        let mut t = AlphaTable::visibility(3, 101).unwrap();
        let before = t.clone();
        t.smooth_clamp(10.0).unwrap(); // α_c = 0.1 → i_c = 10; ramp over rows 9..=12
        assert!(t.lookup(0.08).iter().all(|&x| x == 0.0));
        assert_eq!(t.lookup(0.5), before.lookup(0.5));
        let r = |i: usize| t.data()[i * 3] / before.data()[i * 3];
        assert!((r(9) - 0.104).abs() < 1e-3 && (r(12) - 0.896).abs() < 1e-3);
        assert!(r(10) < r(11));
        assert!(t.smooth_clamp(0.5).is_err());
    }

    #[test]
    fn self_shadow_rules() {
        let p = Vec3::ZERO;
        let n = Vec3::Y;
        // rule 1
        assert_eq!(
            self_shadow_substitute(p, n, Vec3::new(3.0, -2.0, 0.0), 1.0),
            Ok(BlockerSubstitute::Skip)
        );
        // rule 2
        assert_eq!(
            self_shadow_substitute(p, n, Vec3::new(0.1, -0.2, 0.0), 1.0),
            Ok(BlockerSubstitute::Skip)
        );
        // rule 4
        let c = Vec3::new(1.0, 2.0, 0.0);
        assert_eq!(
            self_shadow_substitute(p, n, c, 1.0),
            Ok(BlockerSubstitute::Use {
                center: c,
                radius: 1.0
            })
        );
        // rule 3, centre above: sphere spans plane..top, p outside it
        match self_shadow_substitute(p, n, Vec3::new(0.0, 0.5, 0.0), 1.0).unwrap() {
            BlockerSubstitute::Use { center, radius } => {
                assert!((radius - 0.75).abs() < 1e-6);
                assert!((center - Vec3::new(0.0, 0.75, 0.0)).length() < 1e-6);
                assert!(center.length() >= radius - 1e-6);
            }
            BlockerSubstitute::Skip => panic!("expected a substitute"),
        }
        // rule 3 continuity at h = 0 and towards the footprint
        let above = self_shadow_substitute(p, n, Vec3::new(3.0, 1e-4, 0.0), 1.0).unwrap();
        let below = self_shadow_substitute(p, n, Vec3::new(3.0, -1e-4, 0.0), 1.0).unwrap();
        if let (
            BlockerSubstitute::Use { radius: a, .. },
            BlockerSubstitute::Use { radius: b, .. },
        ) = (above, below)
        {
            assert!((a - b).abs() < 1e-3);
        } else {
            panic!("expected substitutes");
        }
        let near = self_shadow_substitute(p, n, Vec3::new(0.87, -0.5, 0.0), 1.0).unwrap();
        if let BlockerSubstitute::Use { radius, .. } = near {
            assert!(radius < 0.02, "{radius}");
        }
    }
}
