//! CPU twin of `accumulate` (src/passes/accumulate.rs, shaders/accumulate.comp): the indirect
//! light's reprojection, disocclusion test, variance clip, blend and filter state (Holt's trend,
//! the innovations' variance), pixel for pixel.

use glam::{Vec2, Vec3, Vec4};

use crate::capture::tonemap::luminance;
use crate::passes::accumulate::{
    ACCUMULATE_CHANGE, ACCUMULATE_MIN_LUMINANCE, ACCUMULATE_MIN_WEIGHT, AccumulateParams,
    TAA_MIN_INVERSE, TAA_MOVING_FRAMES, TAA_STILL_PIXELS,
};
use crate::passes::amortise::same_surface;
use crate::reference::denoise::HALF_MAX;

/// The images `accumulate` reads, row-major, all of one extent.
pub struct AccumulateInputs<'a> {
    /// Image size.
    pub extent: [u32; 2],
    /// This frame's indirect light (rgb).
    pub current: &'a [Vec3],
    /// G-buffer positions (w: linear depth, 0 on the background).
    pub position: &'a [Vec4],
    /// G-buffer geometric normals (what `gbuffer history` keeps).
    pub normal: &'a [Vec3],
    /// Motion (uv now minus uv then).
    pub motion: &'a [Vec2],
    /// The previous frame's (normal, linear depth).
    pub history_geometry: &'a [Vec4],
    /// The previous frame's accumulated light (alpha: history length).
    pub history_light: &'a [Vec4],
    /// The previous frame's filter state (rgb: trend, alpha: the innovations' variance).
    pub history_state: &'a [Vec4],
    /// Whether the history holds the previous frame.
    pub has_history: bool,
}

/// TAA's blend space x / (1 + luma(x)) (`to_blend` in the shader); the indirect light's is
/// linear.
fn to_blend(x: Vec3, params: &AccumulateParams) -> Vec3 {
    if params.geometry {
        x
    } else {
        x / (1.0 + luminance(x))
    }
}

/// The inverse of [`to_blend`] (`from_blend`).
fn from_blend(x: Vec3, params: &AccumulateParams) -> Vec3 {
    if params.geometry {
        x
    } else {
        x / (1.0 - luminance(x)).max(TAA_MIN_INVERSE)
    }
}

/// TAA's disocclusion test (`taa_same_surface` in the shader): whether history geometry `g`
/// shows the surface a pixel at `depth` with normal `n` shows now, the background (depth 0)
/// included.
fn taa_same_surface(depth: f32, n: Vec3, g: Vec4) -> bool {
    if g.w == 0.0 {
        depth == 0.0
    } else {
        depth > 0.0 && same_surface(depth, n, g.w, g.truncate())
    }
}

/// TAA's test where nothing moves (`taa_seen_nearby`): whether `g` shows a surface some pixel
/// of (x, y)'s 3×3 neighbourhood shows now.
fn taa_seen_nearby(inp: &AccumulateInputs<'_>, x: i32, y: i32, g: Vec4) -> bool {
    let [w, h] = inp.extent;
    (-1..=1)
        .flat_map(|dy| (-1..=1).map(move |dx| (x + dx, y + dy)))
        .filter(|&(qx, qy)| qx >= 0 && qy >= 0 && qx < w as i32 && qy < h as i32)
        .any(|(qx, qy)| {
            let i = (qy * w as i32 + qx) as usize;
            taa_same_surface(inp.position[i].w, inp.normal[i].normalize(), g)
        })
}

/// What the pass writes, row-major: the accumulated light (alpha: history length) and the
/// filter state (rgb: trend, alpha: the innovations' variance).
pub struct Accumulated {
    /// The accumulated light.
    pub light: Vec<Vec4>,
    /// The next frame's filter state.
    pub state: Vec<Vec4>,
}

/// The accumulated light and filter state, as the pass writes them.
pub fn accumulate_cpu(inp: &AccumulateInputs<'_>, params: &AccumulateParams) -> Accumulated {
    let [w, h] = inp.extent;
    let inside = |x: i32, y: i32| x >= 0 && y >= 0 && x < w as i32 && y < h as i32;
    let at = |x: i32, y: i32| (y * w as i32 + x) as usize;
    let mut out = vec![Vec4::ZERO; (w * h) as usize];
    let mut state = vec![Vec4::ZERO; (w * h) as usize];
    for y in 0..h as i32 {
        for x in 0..w as i32 {
            let i = at(x, y);
            let radiance = inp.current[i];
            let light = to_blend(radiance, params);
            let depth = inp.position[i].w;
            let background = params.geometry && depth == 0.0;
            if background || !inp.has_history {
                out[i] = radiance.extend(if background { 0.0 } else { 1.0 });
                continue;
            }
            let n = inp.normal[i].normalize();
            let uv = Vec2::new((x as f32 + 0.5) / w as f32, (y as f32 + 0.5) / h as f32);
            let size = Vec2::new(w as f32, h as f32);
            let then = (uv - inp.motion[i]) * size - 0.5;
            let still = !params.geometry
                && (-1..=1)
                    .flat_map(|dy| (-1..=1).map(move |dx| (x + dx, y + dy)))
                    .filter(|&(qx, qy)| inside(qx, qy))
                    .all(|(qx, qy)| (inp.motion[at(qx, qy)] * size).length() < TAA_STILL_PIXELS);
            let base = then.floor();
            let f = then - base;
            let (mut history, mut filter_state, mut weight) = (Vec4::ZERO, Vec4::ZERO, 0.0f32);
            for j in 0..2 {
                for k in 0..2 {
                    let (qx, qy) = (base.x as i32 + k, base.y as i32 + j);
                    if !inside(qx, qy) {
                        continue;
                    }
                    let g = inp.history_geometry[at(qx, qy)];
                    let valid = if params.geometry {
                        same_surface(depth, n, g.w, g.truncate())
                    } else {
                        taa_same_surface(depth, n, g) || (still && taa_seen_nearby(inp, x, y, g))
                    };
                    if !valid {
                        continue;
                    }
                    let wx = if k == 0 { 1.0 - f.x } else { f.x };
                    let wy = if j == 0 { 1.0 - f.y } else { f.y };
                    let h = inp.history_light[at(qx, qy)];
                    history += wx * wy * to_blend(h.truncate(), params).extend(h.w);
                    filter_state += wx * wy * inp.history_state[at(qx, qy)];
                    weight += wx * wy;
                }
            }
            if weight < ACCUMULATE_MIN_WEIGHT {
                out[i] = radiance.extend(1.0);
                continue;
            }
            history /= weight;
            filter_state /= weight;
            // Holt's filter where the view holds still; elsewhere the plain history.
            let view_still = (inp.motion[i] * size).length() < TAA_STILL_PIXELS;
            let still_indirect = params.geometry && view_still;
            // Holt's forecast: the level moved on by its trend.
            let level = history.truncate();
            let trend = if still_indirect && params.trend > 0.0 {
                filter_state.truncate()
            } else {
                Vec3::ZERO
            };
            let noise = if still_indirect { filter_state.w } else { 0.0 };
            let forecast = (level + trend).max(Vec3::ZERO);
            let mut past = forecast;
            let mut restarted = false;
            if params.clip > 0.0 {
                let (mut sum, mut sum2, mut count) = (Vec3::ZERO, Vec3::ZERO, 0.0f32);
                for dy in -1..=1 {
                    for dx in -1..=1 {
                        let (qx, qy) = (x + dx, y + dy);
                        if !inside(qx, qy) || (params.geometry && inp.position[at(qx, qy)].w == 0.0)
                        {
                            continue;
                        }
                        let c = to_blend(inp.current[at(qx, qy)], params);
                        sum += c;
                        sum2 += c * c;
                        count += 1.0;
                    }
                }
                let mean = sum / count;
                let variance = (sum2 / count - mean * mean).max(Vec3::ZERO);
                let mut sigma = Vec3::new(variance.x.sqrt(), variance.y.sqrt(), variance.z.sqrt());
                if still_indirect && params.temporal {
                    let spread = mean / luminance(mean).max(ACCUMULATE_MIN_LUMINANCE);
                    sigma = sigma.max(noise.max(0.0).sqrt() * spread);
                }
                let lo = light.min(mean - params.clip * sigma);
                let hi = light.max(mean + params.clip * sigma);
                let clipped = past.clamp(lo, hi);
                let moved = luminance((past - clipped).abs());
                if still_indirect
                    && moved > ACCUMULATE_CHANGE * luminance(clipped).max(luminance(light))
                {
                    history.w = 0.0;
                    restarted = true;
                }
                past = clipped;
            }
            let longest = if params.geometry || still {
                params.max_frames
            } else {
                params.max_frames.min(TAA_MOVING_FRAMES)
            };
            let frames = (history.w + 1.0).min(longest as f32);
            let blended = past.lerp(light, 1.0 / frames);
            out[i] = from_blend(blended, params).extend(frames);
            if still_indirect && !restarted {
                let innovation = luminance(radiance) - luminance(forecast);
                let next = trend
                    .lerp(blended - level, params.trend)
                    .extend(noise + (innovation * innovation - noise) / frames);
                state[i] = next.clamp(Vec4::splat(-HALF_MAX), Vec4::splat(HALF_MAX));
            }
        }
    }
    Accumulated { light: out, state }
}
