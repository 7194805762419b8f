//! Paper 003 (Harmonics Virtual Lights): geometric factor with the hemisphere-cap term
//! (eq. 21–22) and the HVL radius heuristics r1 (eq. 23) and r2 (eq. 24–26).

use glam::Vec3;

use crate::basis::unit_dir;
use crate::{Result, ShError, check_range};

/// Smoothstep `S(x) = 3x² - 2x³` on `[0, 1]` (paper 003 eq. 22).
#[inline]
fn smoothstep(x: f64) -> f64 {
    let x = x.clamp(0.0, 1.0);
    x * x * (3.0 - 2.0 * x)
}

/// Paper 003 eq. 22: `H(n_x, ω_j)`, the fraction of an HVL (a cap of half-angle `a`) that lies in
/// the receiver's hemisphere, from `cos_angle = n_x · ω_j` (`ω_j`: unit direction from the
/// receiver to the HVL centre).
///
/// `H = S((ā - clamp(acos(n_x·ω_j), a̲, ā)) / 2a)` with `ā = π/2 + a`, `S` the smoothstep.
/// **Deviation:** the text prints `a̲ = a - π/2`; with that the argument leaves `[0, 1]`.
/// Oat and Sander's cap-intersection approximation (2007) that eq. 22 specialises needs the lower bound at
/// full containment, `a̲ = π/2 - a` (then `ā - a̲ = 2a`), which we use. `a` is clamped to
/// `[0, π/2]`; `a = 0` degenerates to the step `acos(n_x·ω_j) < π/2`.
pub fn hemisphere_cap_fraction(cos_angle: f32, a: f32) -> f32 {
    let half_pi = std::f64::consts::FRAC_PI_2;
    let a = f64::from(a).clamp(0.0, half_pi);
    let theta = f64::from(cos_angle).clamp(-1.0, 1.0).acos();
    if a <= 1e-9 {
        return if theta < half_pi { 1.0 } else { 0.0 };
    }
    let upper = half_pi + a; // ā, eq. 22
    let lower = half_pi - a; // a̲ (see deviation note)
    smoothstep((upper - theta.clamp(lower, upper)) / (2.0 * a)) as f32
}

/// The half-angle `a` of the cap an HVL of radius `r` fills seen from a receiver at distance
/// `d` from its centre: `asin(r/d)` outside the sphere (the cap of eq. 20–22), and inside it
/// `π − (π/2)·d/r`, widening linearly from the hemisphere towards the centre at the surface
/// to the whole sphere at the centre.
///
/// **Deviation:** the paper does not say what a receiver inside an HVL sees. Taking the whole
/// sphere there (every direction meets the sphere's surface) makes the gathered light jump by
/// `2/(1 + cos θ)` at `d = r` (θ between the receiver's normal and the direction to the
/// centre): a visible seam at every HVL's rim. The ramp is continuous at `d = r` (asin 1 =
/// π/2) and at the centre (the whole sphere, the same for every direction to the centre), and
/// changes nothing for a receiver facing the centre (its clamped cosine sees πL either way).
pub fn cap_half_angle(distance: f32, radius: f32) -> Result<f32> {
    let d = check_range("distance", f64::from(distance), 0.0, f64::MAX, "≥ 0")?;
    let r = check_range("radius", f64::from(radius), 1e-30, f64::MAX, "> 0")?;
    let half_pi = std::f64::consts::FRAC_PI_2;
    Ok(if d >= r {
        (r / d).asin() as f32
    } else {
        (std::f64::consts::PI - half_pi * d / r) as f32
    })
}

/// The cap an HVL fills seen from a receiver, as the gather needs it: `(cos a, H)`, the cosine
/// of [`cap_half_angle`] and [`hemisphere_cap_fraction`] (eq. 22) at `cos_angle = n_x · ω_j`,
/// without trigonometry where none is needed. Outside the sphere `sin a = r/d`, so
/// `cos a = √(1 − (r/d)²)`; the cap lies wholly above the receiver's horizon (`H = 1`) when
/// `n_x · ω_j ≥ sin a` (θ ≤ π/2 − a) and wholly below it (`H = 0`) when `n_x · ω_j ≤ −sin a`.
/// Only caps across the horizon, and receivers inside the sphere, take the angles.
pub fn cap_terms(distance: f32, radius: f32, cos_angle: f32) -> Result<(f32, f32)> {
    let d = check_range("distance", f64::from(distance), 0.0, f64::MAX, "≥ 0")?;
    let r = check_range("radius", f64::from(radius), 1e-30, f64::MAX, "> 0")?;
    if d >= r {
        let s = r / d;
        let cos_a = (1.0 - s * s).max(0.0).sqrt() as f32;
        let c = f64::from(cos_angle);
        if c >= s {
            return Ok((cos_a, 1.0));
        }
        if c <= -s {
            return Ok((cos_a, 0.0));
        }
    }
    let a = cap_half_angle(distance, radius)?;
    Ok((
        f64::from(a).cos() as f32,
        hemisphere_cap_fraction(cos_angle, a),
    ))
}

/// Eq. 21 from its parts: `facing · H / (π r²)` (`facing = max(0, n_j · -ω_j)`, `H` of eq.
/// 22), as [`geometric_factor`] and the gather combine them.
pub fn geometric_factor_of(facing: f32, h: f32, radius: f32) -> f32 {
    (f64::from(facing) * f64::from(h) / (std::f64::consts::PI * f64::from(radius).powi(2))) as f32
}

/// Paper 003 eq. 21: `G_j(-ω_j) = max(0, n_j · -ω_j) H(n_x, ω_j) / (π r_j²)`.
///
/// * `to_hvl`: direction from the receiver `x` to the HVL centre (`ω_j`, normalised here),
/// * `hvl_normal`: `n_j`, `receiver_normal`: `n_x` (both normalised here),
/// * `radius`: `r_j > 0`, `half_angle`: `a`, the half-angle the HVL subtends at `x`.
pub fn geometric_factor(
    to_hvl: Vec3,
    hvl_normal: Vec3,
    receiver_normal: Vec3,
    radius: f32,
    half_angle: f32,
) -> Result<f32> {
    let w = unit_dir(to_hvl)?;
    let nj = unit_dir(hvl_normal)?;
    let nx = unit_dir(receiver_normal)?;
    check_range("HVL radius", f64::from(radius), 1e-30, f64::MAX, "> 0")?;
    let facing = (-nj.dot(w)).max(0.0);
    let h = hemisphere_cap_fraction(nx.dot(w) as f32, half_angle);
    Ok(geometric_factor_of(facing as f32, h, radius))
}

/// A neighbour of an HVL for heuristic r1: its world position `p_n` and distance `d_n` to the
/// primary light.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HvlNeighbour {
    /// World-space position `p_n`.
    pub position: Vec3,
    /// Distance `d_n` from the neighbour to its primary light.
    pub light_distance: f32,
}

/// Paper 003 eq. 23: `r1 = Σ w_n ‖p - p_n‖ / Σ w_n`, `w_n = 1 / (|d - d_n| + ε)` over the
/// (8-connected) neighbours in the HVL cache. The paper scales the result by a user constant
/// `k` in [1, 2]; the caller applies it. `ε > 0`; no neighbours is an error.
pub fn radius_r1(
    position: Vec3,
    light_distance: f32,
    neighbours: &[HvlNeighbour],
    epsilon: f32,
) -> Result<f32> {
    let eps = check_range("epsilon", f64::from(epsilon), 1e-30, f64::MAX, "> 0")?;
    if neighbours.is_empty() {
        return Err(ShError::OutOfRange {
            name: "neighbour count",
            value: 0.0,
            expected: "at least one neighbour",
        });
    }
    let (mut num, mut den) = (0.0f64, 0.0f64);
    for n in neighbours {
        let w = 1.0 / ((f64::from(light_distance) - f64::from(n.light_distance)).abs() + eps);
        num += w * f64::from(position.distance(n.position));
        den += w;
    }
    Ok((num / den) as f32)
}

/// Paper 003 eq. 24: `γ = sqrt(2) λ / sqrt(M)`, the angle between diagonal neighbours of a square
/// RSM of field of view `λ` (radians) holding `M` HVLs.
pub fn diagonal_angle(fov: f32, hvl_count: u32) -> Result<f32> {
    let l = check_range(
        "RSM field of view",
        f64::from(fov),
        0.0,
        std::f64::consts::PI,
        "0..=π radians",
    )?;
    if hvl_count == 0 {
        return Err(ShError::OutOfRange {
            name: "HVL count",
            value: 0.0,
            expected: "≥ 1",
        });
    }
    Ok((std::f64::consts::SQRT_2 * l / f64::from(hvl_count).sqrt()) as f32)
}

/// Paper 003 eq. 25: `r2 = d tan(γ)` (exact form), `d`: distance HVL–primary light.
pub fn radius_r2_exact(light_distance: f32, fov: f32, hvl_count: u32) -> Result<f32> {
    let g = f64::from(diagonal_angle(fov, hvl_count)?);
    Ok((f64::from(light_distance) * g.tan()) as f32)
}

/// Paper 003 eq. 26: `r2 ≈ d (γ + γ³/3)`, the Taylor form used on the GPU (error < 0.01 of
/// `tan` for `γ ≲ 0.58`, i.e. `λ/√M ≲ 0.2`). The user scale `k` (1–2) is applied by the caller.
pub fn radius_r2(light_distance: f32, fov: f32, hvl_count: u32) -> Result<f32> {
    let g = f64::from(diagonal_angle(fov, hvl_count)?);
    Ok((f64::from(light_distance) * (g + g * g * g / 3.0)) as f32)
}

/// Eq. 24–25 for an orthographic RSM (a directional light) of width `width` across: its
/// footprint is the same at every distance, so `d λ` becomes `W` and the small-angle form of
/// `tan` gives `r2 = √2 W / √M`. Not in paper 003 (its RSMs are perspective); shine's extension.
pub fn radius_r2_orthographic(width: f32, hvl_count: u32) -> Result<f32> {
    if !(width.is_finite() && width > 0.0) {
        return Err(ShError::OutOfRange {
            name: "RSM width",
            value: f64::from(width),
            expected: "finite, > 0",
        });
    }
    if hvl_count == 0 {
        return Err(ShError::OutOfRange {
            name: "HVL count",
            value: 0.0,
            expected: "≥ 1",
        });
    }
    Ok((std::f64::consts::SQRT_2 * f64::from(width) / f64::from(hvl_count).sqrt()) as f32)
}

/// The near-field correction of an HVL of radius `r` seen from distance `d` (shine's, not in
/// paper 003): the ratio of what a Lambertian disc of area πr² sends to what eq. 20–22's
/// sphere sends.
/// - Outside the sphere (d ≥ r), the sphere's cap gives the point-light irradiance `Φ/(π d²)`
///   up to its surface, twice the disc's on-axis `Φ/(π (r² + d²))` at d = r. The factor is
///   `d²/(d² + r²)`.
/// - Inside, the cap is the whole sphere, about `Φ/(π r²)`. The factor is `r²/(d² + r²)`:
///   1 at the centre.
///
/// The two forms meet at 1/2 at d = r, and the factor tends to 1 far away. It brings HVL's
/// energy on the cornell box from 1.12 to 1.02 of the truth, but darkens the animated scene
/// (docs/quality.md), so `hvl.falloff` defaults to the sphere. GLSL twin `hvl_disc_falloff`
/// in `sh.glsl`.
pub fn disc_falloff(distance: f32, radius: f32) -> f32 {
    let (d2, r2) = (distance * distance, radius * radius);
    if distance >= radius {
        d2 / (d2 + r2)
    } else {
        r2 / (d2 + r2)
    }
}

/// The share of a sender point's light at `distance` from a receiver that the HVL gather keeps
/// when the near field within `range` (R) is traced (shine's extension, `hvl.near_range`):
/// `S((d − R) / R)` with the smoothstep `S`, 0 up to R, 1 from 2R on; 1 everywhere when R is
/// 0. The near-field pass takes `1 −` this at each ray hit, so the two shares sum to one for
/// every sender point (Kollig and Keller's split with a smooth boundary). GLSL twin
/// `hvl_far_weight` in `hvl_near.glsl`.
pub fn far_weight(distance: f32, range: f32) -> f32 {
    if range > 0.0 {
        smoothstep(f64::from((distance - range) / range)) as f32
    } else {
        1.0
    }
}

/// Smallest cosine of incidence [`rsm_texel_area`] divides by: a texel lit at grazing
/// incidence (beyond about 84°) counts as lit at 84°, so its patch and the radius taken from
/// it stay finite.
pub const MIN_INCIDENCE_COS: f32 = 0.1;

/// How an RSM was projected, as [`rsm_texel_area`] needs it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum RsmFootprint {
    /// A perspective RSM of square field of view `fov` (radians).
    Perspective {
        /// Field of view λ.
        fov: f32,
    },
    /// An orthographic RSM `width` metres across.
    Orthographic {
        /// Width W.
        width: f32,
    },
}

/// World area of the surface patch one texel of an `size`² RSM covers.
///
/// - Perspective: the texel's solid angle `(2 tan(λ/2) / S)² cos³α` (α from the view's axis,
///   `cos_axis`) times `d²` (`light_distance`).
/// - Orthographic: `(W / S)²`.
///
/// Both are divided by the obliquity `max(cos θ_i, MIN_INCIDENCE_COS)`, θ_i being the angle
/// between the surface normal and the direction to the light. The RSM's flux is the power
/// through the texel, so flux / area is the reflected exitance. Shine's extension, for
/// [`radius_spacing`]; the GLSL twin is `hvl_rsm_texel_area` in `sh.glsl`.
pub fn rsm_texel_area(
    footprint: RsmFootprint,
    size: u32,
    light_distance: f32,
    cos_axis: f32,
    cos_incidence: f32,
) -> f32 {
    let s = size.max(1) as f32;
    let perpendicular = match footprint {
        RsmFootprint::Perspective { fov } => {
            let side = 2.0 * (0.5 * fov).tan() / s;
            let c = cos_axis.clamp(0.0, 1.0);
            side * side * c * c * c * light_distance * light_distance
        }
        RsmFootprint::Orthographic { width } => (width / s) * (width / s),
    };
    perpendicular / cos_incidence.max(MIN_INCIDENCE_COS)
}

/// The r2 heuristic (eq. 24–25) generalised to HVLs placed with density proportional to the
/// reflected flux: `√2 s`, where `s = √(A Φ / (M w))` is the local spacing.
///
/// - M HVLs share the total flux weight Φ (`total_weight`) equally, one per Φ/M of flux.
/// - On a texel of area A (`texel_area`) and flux weight w (`texel_weight`), that puts one
///   HVL on every `A Φ / (M w)` of surface.
/// - √2 s is the diagonal spacing, as γ = √2 λ / √M of eq. 24 is for a regular grid.
///
/// The user scale k multiplies the result. Shine's extension: paper 003 spreads HVLs
/// uniformly over the RSM. GLSL twin: `hvl_radius_spacing` in `sh.glsl`.
pub fn radius_spacing(
    texel_area: f32,
    texel_weight: f32,
    total_weight: f32,
    hvl_count: u32,
) -> f32 {
    let spacing_squared = texel_area * total_weight / (hvl_count.max(1) as f32 * texel_weight);
    std::f32::consts::SQRT_2 * spacing_squared.sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::quadrature::SphereQuadrature;
    use glam::DVec3;

    /// The cap half-angle is asin(r/d) outside, π/2 on the rim from both sides, π at the
    /// centre, and falls monotonically with distance.
    #[test]
    fn cap_half_angle_is_continuous_at_the_rim() {
        let r = 0.7;
        let a = |d: f32| cap_half_angle(d, r).unwrap();
        assert!((a(2.0 * r) - std::f32::consts::FRAC_PI_6).abs() < 1e-6);
        assert!((a(r) - std::f32::consts::FRAC_PI_2).abs() < 1e-6);
        assert!((a(r * (1.0 - 1e-4)) - a(r * (1.0 + 1e-4))).abs() < 0.02);
        assert!((a(0.0) - std::f32::consts::PI).abs() < 1e-6);
        let samples: Vec<f32> = (0..=400).map(|i| a(i as f32 * 0.01)).collect();
        assert!(samples.windows(2).all(|w| w[1] <= w[0]));
        assert!(cap_half_angle(1.0, 0.0).is_err());
        assert!(cap_half_angle(-1.0, 0.5).is_err());
    }

    /// The shortcut of `cap_terms` gives what the angles give, inside and outside the sphere,
    /// for caps above, across and below the horizon (and at their edges).
    #[test]
    fn cap_terms_match_the_half_angle_and_the_fraction() {
        let r = 0.4f32;
        for i in 0..=60 {
            let d = r * (0.05 + 0.1 * i as f32);
            let s = (r / d).min(1.0);
            for c in [
                -1.0,
                -0.7,
                -s,
                -0.5 * s,
                0.0,
                0.3 * s,
                s,
                0.999 * s,
                0.6,
                1.0,
            ] {
                let (cos_a, h) = cap_terms(d, r, c).unwrap();
                let a = cap_half_angle(d, r).unwrap();
                let want = (a.cos(), hemisphere_cap_fraction(c, a));
                assert!(
                    (cos_a - want.0).abs() < 1e-6 && (h - want.1).abs() < 1e-5,
                    "d {d} cos {c}: {:?} vs {want:?}",
                    (cos_a, h)
                );
            }
        }
        assert!(cap_terms(1.0, 0.0, 0.5).is_err());
    }

    /// Exact fraction of a cap (half-angle `a` around direction at angle `theta` from the normal)
    /// that lies above the horizon, by quadrature over the cap.
    fn exact_fraction(theta: f64, a: f64) -> f64 {
        let axis = DVec3::new(theta.sin(), 0.0, theta.cos());
        let q = SphereQuadrature::cap(axis, a.cos(), 200, 400);
        let total = q.integrate(|_| 1.0);
        q.integrate(|s| if s.z >= 0.0 { 1.0 } else { 0.0 }) / total
    }

    #[test]
    fn cap_term_against_exact_overlap() {
        let mut worst = 0.0f64;
        for &a in &[0.05f64, 0.2, 0.5, 1.0] {
            for i in 0..=30 {
                let theta = std::f64::consts::PI * i as f64 / 30.0;
                let h = f64::from(hemisphere_cap_fraction(theta.cos() as f32, a as f32));
                let e = exact_fraction(theta, a);
                worst = worst.max((h - e).abs());
            }
        }
        // Oat's smoothstep is an approximation: measured worst 0.058 over these cases.
        assert!(worst < 0.07, "worst {worst}");
        assert_eq!(hemisphere_cap_fraction(1.0, 0.3), 1.0);
        assert_eq!(hemisphere_cap_fraction(-1.0, 0.3), 0.0);
        assert!((hemisphere_cap_fraction(0.0, 0.3) - 0.5).abs() < 1e-6);
    }

    #[test]
    fn geometric_factor_cases() {
        // HVL facing the receiver, above it.
        let g = geometric_factor(Vec3::Z, -Vec3::Z, Vec3::Z, 0.5, 0.1).unwrap();
        assert!((g - 1.0 / (std::f32::consts::PI * 0.25)).abs() < 1e-5);
        // HVL turned away.
        assert_eq!(
            geometric_factor(Vec3::Z, Vec3::Z, Vec3::Z, 0.5, 0.1),
            Ok(0.0)
        );
        assert!(geometric_factor(Vec3::Z, Vec3::Z, Vec3::Z, 0.0, 0.1).is_err());
    }

    #[test]
    fn radius_heuristics() {
        let n = [
            HvlNeighbour {
                position: Vec3::new(1.0, 0.0, 0.0),
                light_distance: 2.0,
            },
            HvlNeighbour {
                position: Vec3::new(0.0, 3.0, 0.0),
                light_distance: 5.0,
            },
        ];
        // weights 1/(0+1) and 1/(3+1): (1·1 + 0.25·3) / 1.25 = 1.4
        assert!((radius_r1(Vec3::ZERO, 2.0, &n, 1.0).unwrap() - 1.4).abs() < 1e-6);
        assert!(radius_r1(Vec3::ZERO, 2.0, &[], 1.0).is_err());
        // Eq. 26 within 0.01 of eq. 25 where the paper says so (λ/√M ≤ 0.2).
        let fov = std::f32::consts::FRAC_PI_2;
        for m in [64u32, 400, 10_000] {
            let exact = radius_r2_exact(1.0, fov, m).unwrap();
            let approx = radius_r2(1.0, fov, m).unwrap();
            assert!((exact - approx).abs() < 0.01, "M={m}: {exact} vs {approx}");
        }
        assert!(diagonal_angle(1.0, 0).is_err());
    }

    /// Uniform flux over an RSM facing a plane: the spacing radius is r2 (eq. 24–26) for a
    /// narrow perspective RSM and √2 W / √M for an orthographic one; a patch lit at 60° is
    /// twice as large, and grazing light stops at MIN_INCIDENCE_COS.
    #[test]
    fn spacing_radius_of_uniform_flux_is_r2() {
        let (size, m, d) = (512u32, 400u32, 2.0f32);
        let texels = (size * size) as f32;
        let fov = 0.3f32;
        let area = rsm_texel_area(RsmFootprint::Perspective { fov }, size, d, 1.0, 1.0);
        let r = radius_spacing(area, 0.5, 0.5 * texels, m);
        let r2 = radius_r2(d, fov, m).unwrap();
        assert!((r / r2 - 1.0).abs() < 0.01, "{r} vs r2 {r2}");
        let width = 4.0f32;
        let ortho = RsmFootprint::Orthographic { width };
        let area = rsm_texel_area(ortho, size, d, 1.0, 1.0);
        let r = radius_spacing(area, 0.5, 0.5 * texels, m);
        let expected = radius_r2_orthographic(width, m).unwrap();
        assert!((r / expected - 1.0).abs() < 1e-5, "{r} vs {expected}");
        let tilted = rsm_texel_area(ortho, size, d, 1.0, 0.5);
        assert!((tilted / area - 2.0).abs() < 1e-5);
        let grazing = rsm_texel_area(ortho, size, d, 1.0, 0.0);
        assert!((grazing / area - 1.0 / MIN_INCIDENCE_COS).abs() < 1e-3);
        // Off the axis a perspective texel shrinks as cos³α.
        let fov = RsmFootprint::Perspective { fov: 1.0 };
        let on_axis = rsm_texel_area(fov, size, d, 1.0, 1.0);
        let off_axis = rsm_texel_area(fov, size, d, 0.5, 1.0);
        assert!((off_axis / on_axis - 0.125).abs() < 1e-6);
    }

    /// Continuous at the rim (1/2 from both sides), 1 at the centre, towards 1 far away.
    #[test]
    fn disc_falloff_is_continuous() {
        let r = 0.3;
        assert!((disc_falloff(r * (1.0 - 1e-6), r) - 0.5).abs() < 1e-5);
        assert!((disc_falloff(r, r) - 0.5).abs() < 1e-6);
        assert_eq!(disc_falloff(0.0, r), 1.0);
        assert!(disc_falloff(1000.0 * r, r) > 0.9999);
        // d = 2r: the disc's Φ/(π 5r²) over the sphere's Φ/(π 4r²).
        assert!((disc_falloff(2.0 * r, r) - 0.8).abs() < 1e-6);
    }
}
