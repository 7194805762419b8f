//! CPU twin of `accumulate` (src/passes/accumulate.rs, shaders/accumulate.comp): the indirect
//! light's reprojection, disocclusion test, variance clip and blend, pixel for pixel.

use glam::{Vec2, Vec3, Vec4};

use crate::passes::accumulate::{ACCUMULATE_MIN_WEIGHT, AccumulateParams};
use crate::passes::hvl::resolve::same_surface;

/// The images `accumulate` reads, row-major, all of one extent.
pub struct AccumulateInputs<'a> {
    /// Image size.
    pub extent: [u32; 2],
    /// This frame's indirect light (rgb).
    pub current: &'a [Vec3],
    /// G-buffer positions (w: linear depth, 0 on the background).
    pub position: &'a [Vec4],
    /// G-buffer normals.
    pub normal: &'a [Vec3],
    /// Motion (uv now minus uv then).
    pub motion: &'a [Vec2],
    /// The previous frame's (normal, linear depth).
    pub history_geometry: &'a [Vec4],
    /// The previous frame's accumulated light (alpha: history length).
    pub history_light: &'a [Vec4],
    /// Whether the history holds the previous frame.
    pub has_history: bool,
}

/// The accumulated light (alpha: history length), as the pass writes it.
pub fn accumulate_cpu(inp: &AccumulateInputs<'_>, params: &AccumulateParams) -> Vec<Vec4> {
    let [w, h] = inp.extent;
    let inside = |x: i32, y: i32| x >= 0 && y >= 0 && x < w as i32 && y < h as i32;
    let at = |x: i32, y: i32| (y * w as i32 + x) as usize;
    let mut out = vec![Vec4::ZERO; (w * h) as usize];
    for y in 0..h as i32 {
        for x in 0..w as i32 {
            let i = at(x, y);
            let light = inp.current[i];
            let depth = inp.position[i].w;
            if depth == 0.0 || !inp.has_history {
                out[i] = light.extend(if depth == 0.0 { 0.0 } else { 1.0 });
                continue;
            }
            let n = inp.normal[i].normalize();
            let uv = Vec2::new((x as f32 + 0.5) / w as f32, (y as f32 + 0.5) / h as f32);
            let then = (uv - inp.motion[i]) * Vec2::new(w as f32, h as f32) - 0.5;
            let base = then.floor();
            let f = then - base;
            let (mut history, mut weight) = (Vec4::ZERO, 0.0f32);
            for j in 0..2 {
                for k in 0..2 {
                    let (qx, qy) = (base.x as i32 + k, base.y as i32 + j);
                    if !inside(qx, qy) {
                        continue;
                    }
                    let g = inp.history_geometry[at(qx, qy)];
                    if !same_surface(depth, n, g.w, g.truncate()) {
                        continue;
                    }
                    let wx = if k == 0 { 1.0 - f.x } else { f.x };
                    let wy = if j == 0 { 1.0 - f.y } else { f.y };
                    history += wx * wy * inp.history_light[at(qx, qy)];
                    weight += wx * wy;
                }
            }
            if weight < ACCUMULATE_MIN_WEIGHT {
                out[i] = light.extend(1.0);
                continue;
            }
            history /= weight;
            let mut past = history.truncate();
            if params.clip > 0.0 {
                let (mut sum, mut sum2, mut count) = (Vec3::ZERO, Vec3::ZERO, 0.0f32);
                for dy in -1..=1 {
                    for dx in -1..=1 {
                        let (qx, qy) = (x + dx, y + dy);
                        if !inside(qx, qy) || inp.position[at(qx, qy)].w == 0.0 {
                            continue;
                        }
                        let c = inp.current[at(qx, qy)];
                        sum += c;
                        sum2 += c * c;
                        count += 1.0;
                    }
                }
                let mean = sum / count;
                let variance = (sum2 / count - mean * mean).max(Vec3::ZERO);
                let sigma = Vec3::new(variance.x.sqrt(), variance.y.sqrt(), variance.z.sqrt());
                let lo = light.min(mean - params.clip * sigma);
                let hi = light.max(mean + params.clip * sigma);
                past = past.clamp(lo, hi);
            }
            let frames = (history.w + 1.0).min(params.max_frames as f32);
            out[i] = past.lerp(light, 1.0 / frames).extend(frames);
        }
    }
    out
}
