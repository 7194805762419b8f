//! Tiny environment cubes (issue 18, item 3; paper 001, "Environment maps"): the `cubes_fill`,
//! `cubes_smooth` and `cubes_shade` passes (`shaders/cubes.comp`).
//!
//! Paper 001 gives each object a small cube map of the light around it, [`SIDE`]² texels a
//! face ("the ideal size … 6×6×6"), painted with the sky and the objects around, smoothed by a
//! cosine-weighted sum over the hemisphere of each texel, and read as a directional table of
//! incoming light. shine builds one per dynamic object (a node with proxies) and lights the
//! object's receivers from it, in place of the frame's technique: a cheap indirect mode for
//! objects that move, compared with the per-pixel proxy gather (docs/quality.md).
//!
//! # Decisions
//!
//! * **Filled by rays.** The paper paints each object as z-buffered pixels; a ray through the
//!   BVH per texel sample ([`SAMPLES`], 2×2 strata) is the same nearest-surface test over the
//!   whole scene, static geometry included. Rays leave from the centre of the object's
//!   bounding sphere, start where they exit the object's proxy spheres that hold that centre,
//!   and jump past every own proxy that holds a later hit: the object does not see itself (a
//!   floor inside a proxy that pokes through it is skipped too; the spheres are grown by only
//!   0.1%, so an object resting on a floor still sees it). A hit sends what its surface
//!   reflects of the one-bounce light (next-event estimation to the punctual lights, one
//!   cosine ray to the environment), the light the path tracer counts; an escaped ray sees the
//!   environment. Seeds are fixed per texel, so a still scene gives the same cube every frame.
//! * **Smoothing** as published (`Σ L max(0, n·d) / Σ max(0, n·d)` over every texel), or
//!   weighted by each texel's solid angle ([`CubeLookup`] and `solid_angle`; the texels of a
//!   6×6 face span solid angles 3.3× apart, corners smallest).
//! * **Lookup**: the smoothed texel holding the normal (the paper's), or the smoothing sum at
//!   the normal itself (216 multiply-adds, no facets or seams at 6×6).
//! * **Which receivers**: those inside one of the object's proxy spheres (1% margin). The
//!   G-buffer has no object id, and a host's G-buffer (a GI context) would not either.
//! * **Amortised** (paper 001: "update one object at the time"; issue 18, item 1): with
//!   `cubes.slices = k` a frame refreshes every k-th cube in turn, and at once every cube whose
//!   object moved since its last refresh, every cube a moving object is near enough to be seen
//!   in ([`NEIGHBOUR_ALPHA`]), and all of them when a light changes
//!   (`crate::frame::cubes`). The others keep their texels from earlier frames.
//! * **Diffuse only**: the receivers get `kd · L̄`; the traced specular pass still adds the
//!   sharp part of their glossy lobes, the rough part is left out.

use serde::{Deserialize, Serialize};

use crate::declare::Settings;
use crate::graph::{Buffer, Handle, Image, RenderGraph};
use crate::passes::receivers::Receivers;
use crate::passes::traced_scene::TracedScene;
use crate::shaders;

/// Texels along a cube face's side: paper 001's "ideal size" of 6×6×6.
pub const SIDE: u32 = 6;
/// Texels of a cube.
pub const TEXELS: u32 = 6 * SIDE * SIDE;
/// Rays per texel of the fill (2×2 strata).
pub const SAMPLES: u32 = 4;
/// A cube is refreshed when an object that moved this frame subtends at least this sin of a
/// half-angle from its centre (`r / d`; 11.5°, about two 6×6 texels' worth of solid angle):
/// smaller, it moves the cube's smoothed light by a few percent of its own at most. On
/// `marbles` 0.1 refreshed 58% of the cubes per frame at `slices = 4`, 0.2 refreshes 40%, at
/// the same error and flicker (docs/quality.md).
pub const NEIGHBOUR_ALPHA: f32 = 0.2;
/// Default `cubes.slices`: every cube refreshed every frame.
pub const SLICES: u32 = 1;
/// `cubes.slices` the settings take.
pub const SLICES_RANGE: std::ops::RangeInclusive<u32> = 1..=16;

crate::choice::named_choice! {
    /// How a receiver reads its object's cube.
    pub enum CubeLookup ("environment cube lookup") {
        /// The smoothed texel that holds the normal (paper 001).
        Texel = "texel",
        /// The smoothing sum evaluated at the normal itself.
        Normal = "normal",
    }
}

/// `[cubes]`: one 6×6×6 cube of incoming light per dynamic object (a node with proxies),
/// filled by rays and smoothed as paper 001 does; the object's receivers take their indirect
/// light from it instead of from the frame's technique (issue 18). The cube passes'
/// parameters, each declared once.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, Settings)]
#[serde(default, deny_unknown_fields)]
pub struct CubeParams {
    /// Light the dynamic objects from their cubes (the frame declares the passes only then).
    #[setting(default = false, affects = both)]
    pub enabled: bool,
    /// How a receiver reads its cube: `normal` (the smoothing sum at the normal) or `texel`
    /// (the smoothed texel holding the normal, the paper's).
    #[setting(default = CubeLookup::Normal, affects = quality)]
    pub lookup: CubeLookup,
    /// Weight the smoothing by each texel's solid angle (false: the paper's plain sum).
    #[setting(default = true, affects = quality)]
    pub solid_angle: bool,
    /// Write 1 at the receivers the cubes light and 0 elsewhere, instead of light (see with
    /// `output.component = indirect`; the mask of the cube study's per-object error).
    #[setting(default = false, affects = output)]
    pub mask: bool,
    /// Refresh one cube in `slices` per frame, in turn, plus at once those of objects that
    /// move (and their neighbours) and all of them when a light changes (paper 001: "update
    /// one object at the time"; `crate::frame::cubes`).
    #[setting(default = SLICES, range = SLICES_RANGE, affects = both)]
    pub slices: u32,
}

/// One cube as the fill reads it (32 bytes).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct GpuCube {
    /// Centre xyz and radius w of the object's bounding sphere.
    pub sphere: [f32; 4],
    /// x: the first of the object's [`GpuCubeSphere`]s, y: their count; z, w: 0.
    pub spheres: [u32; 4],
}

/// One proxy sphere with the cube of its object (32 bytes).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct GpuCubeSphere {
    /// Centre xyz and radius w.
    pub sphere: [f32; 4],
    /// x: the index of the object's cube (as a float); y, z, w: 0.
    pub cube: [f32; 4],
}

/// Push constants of `shaders/cubes.comp` (48 bytes).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct CubesPush {
    /// Fill: cube count, light count, 1 when the environment lights the hits. Smooth: cube
    /// count. Shade: receiver extent, sphere count, 1 with a light input.
    pub frame: [u32; 4],
    /// Shade: the camera position.
    pub camera: [f32; 4],
    /// y: look up at the normal (shade); z: solid-angle weights (fill); w: write the mask
    /// (shade).
    pub config: [u32; 4],
}

/// The cubes of one frame: their records, the proxy spheres naming their receivers, the
/// cubes to refresh, and the texels they keep between frames.
pub struct CubeInputs {
    /// [`GpuCube`] per dynamic object.
    pub cubes: Handle<Buffer>,
    /// [`GpuCubeSphere`] per proxy sphere.
    pub spheres: Handle<Buffer>,
    /// Spheres in `spheres`.
    pub sphere_count: u32,
    /// The indices (u32) of the cubes this frame fills and smooths.
    pub refresh: Handle<Buffer>,
    /// Cubes in `refresh` (0: the fill and smooth passes are left out).
    pub refresh_count: u32,
    /// [`TEXELS`] × vec4 per cube: radiance times its smoothing weight, and the weight.
    pub radiance: Handle<Buffer>,
    /// [`TEXELS`] × vec4 per cube: the smoothed `L̄` of each texel.
    pub smoothed: Handle<Buffer>,
}

/// Adds `cubes_fill` and `cubes_smooth` over the cubes `inputs` refreshes (none: neither
/// pass), then `cubes_shade`: the receivers inside the cubes' objects lit from them, `light`
/// (the technique's RGBA16F light at receiver resolution, if any) kept elsewhere. Returns the
/// result (RGBA16F at receiver resolution).
pub fn cubes(
    rg: &mut RenderGraph,
    scene: &TracedScene<'_>,
    inputs: &mut CubeInputs,
    receivers: &Receivers,
    light: Option<&Handle<Image>>,
    camera: glam::Vec3,
    params: &CubeParams,
) -> Handle<Image> {
    let config = [
        0,
        u32::from(params.lookup == CubeLookup::Normal),
        u32::from(params.solid_angle),
        u32::from(params.mask),
    ];
    if inputs.refresh_count > 0 {
        fill_and_smooth(rg, scene, inputs, config);
    }
    let [w, h] = receivers.extent;
    let mut out = receivers.light_image(rg, "cube_light");
    let mut pass = rg.compute("cubes_shade", &shaders::CUBES_COMP_SHADE);
    pass.read("radiance", &inputs.radiance)
        .read("smoothed", &inputs.smoothed)
        .read("recv_position", &receivers.position)
        .read("recv_normal", &receivers.normal)
        .read("recv_albedo", &receivers.albedo)
        .read("recv_material", &receivers.material)
        .read("spheres", &inputs.spheres);
    // Without a technique's light the input binding reads the receivers' normals, unused.
    pass.read("light", light.unwrap_or(&receivers.normal));
    pass.write("shaded", &mut out)
        .push(&CubesPush {
            frame: [w, h, inputs.sphere_count, u32::from(light.is_some())],
            camera: camera.extend(0.0).to_array(),
            config,
        })
        .dispatch([w, h, 1]);
    out
}

/// `cubes_fill` and `cubes_smooth` over the refreshed cubes of `inputs`.
fn fill_and_smooth(
    rg: &mut RenderGraph,
    scene: &TracedScene<'_>,
    inputs: &mut CubeInputs,
    config: [u32; 4],
) {
    let mut pass = rg.compute("cubes_fill", &shaders::CUBES_COMP_FILL);
    scene.bind(&mut pass);
    pass.read("cubes", &inputs.cubes)
        .read("spheres", &inputs.spheres)
        .read("refresh", &inputs.refresh)
        .write("radiance", &mut inputs.radiance)
        .push(&CubesPush {
            frame: [
                inputs.refresh_count,
                scene.light_count,
                u32::from(scene.environment_lighting),
                0,
            ],
            camera: [0.0; 4],
            config,
        })
        .dispatch([TEXELS, inputs.refresh_count, 1]);
    rg.compute("cubes_smooth", &shaders::CUBES_COMP_SMOOTH)
        .read("radiance", &inputs.radiance)
        .read("refresh", &inputs.refresh)
        .write("smoothed", &mut inputs.smoothed)
        .push(&CubesPush {
            frame: [inputs.refresh_count, 0, 0, 0],
            camera: [0.0; 4],
            config,
        })
        .dispatch([TEXELS, inputs.refresh_count, 1]);
}

/// The direction through face coordinates `(u, v)` ∈ [-1, 1]² of `face` (not normalised):
/// `cube_face_direction` of `shaders/include/cube.glsl`.
pub fn face_direction(face: u32, u: f32, v: f32) -> glam::Vec3 {
    use glam::Vec3;
    match face {
        0 => Vec3::new(1.0, -v, -u),
        1 => Vec3::new(-1.0, -v, u),
        2 => Vec3::new(u, 1.0, v),
        3 => Vec3::new(u, -1.0, -v),
        4 => Vec3::new(u, -v, 1.0),
        _ => Vec3::new(-u, -v, -1.0),
    }
}

/// The unit direction through texel `t` at sub-texel position `s` ∈ [0, 1]² (0.5: the centre):
/// `cube_texel_direction`.
pub fn texel_direction(t: u32, s: [f32; 2]) -> glam::Vec3 {
    let face = t / (SIDE * SIDE);
    let (row, column) = ((t / SIDE) % SIDE, t % SIDE);
    let step = 2.0 / SIDE as f32;
    let u = (column as f32 + s[0]) * step - 1.0;
    let v = (row as f32 + s[1]) * step - 1.0;
    face_direction(face, u, v).normalize()
}

/// The texel whose square holds direction `d` (any length > 0): `cube_texel_of`.
pub fn texel_of(d: glam::Vec3) -> u32 {
    let a = d.abs();
    let (face, u, v) = if a.x >= a.y && a.x >= a.z {
        if d.x > 0.0 {
            (0, -d.z / a.x, -d.y / a.x)
        } else {
            (1, d.z / a.x, -d.y / a.x)
        }
    } else if a.y >= a.z {
        if d.y > 0.0 {
            (2, d.x / a.y, d.z / a.y)
        } else {
            (3, d.x / a.y, -d.z / a.y)
        }
    } else if d.z > 0.0 {
        (4, d.x / a.z, -d.y / a.z)
    } else {
        (5, -d.x / a.z, -d.y / a.z)
    };
    let cell = |x: f32| ((x + 1.0) * 0.5 * SIDE as f32).clamp(0.0, SIDE as f32 - 0.5) as u32;
    face * SIDE * SIDE + cell(v) * SIDE + cell(u)
}

/// The solid angle of texel `t`: `cube_texel_solid_angle`.
pub fn texel_solid_angle(t: u32) -> f32 {
    let (row, column) = ((t / SIDE) % SIDE, t % SIDE);
    let step = 2.0 / SIDE as f32;
    let (lo_x, lo_y) = (column as f32 * step - 1.0, row as f32 * step - 1.0);
    let (hi_x, hi_y) = (lo_x + step, lo_y + step);
    let a = |x: f32, y: f32| (x * y).atan2((x * x + y * y + 1.0).sqrt());
    a(hi_x, hi_y) - a(lo_x, hi_y) - a(hi_x, lo_y) + a(lo_x, lo_y)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn texels_tile_the_sphere() {
        let total: f32 = (0..TEXELS).map(texel_solid_angle).sum();
        assert!((total - 4.0 * std::f32::consts::PI).abs() < 1e-4, "{total}");
        let (min, max) = (0..TEXELS)
            .map(texel_solid_angle)
            .fold((f32::MAX, 0.0f32), |(a, b), w| (a.min(w), b.max(w)));
        // a 6×6 face: the centre texels 3.3 times the corners
        assert!(max / min > 3.2 && max / min < 3.4, "{min} {max}");
    }

    #[test]
    fn texel_of_inverts_texel_direction() {
        for t in 0..TEXELS {
            for s in [
                [0.5, 0.5],
                [0.05, 0.05],
                [0.95, 0.05],
                [0.05, 0.95],
                [0.95, 0.95],
            ] {
                assert_eq!(texel_of(texel_direction(t, s) * 3.0), t, "{t} {s:?}");
            }
        }
    }

    #[test]
    fn every_texel_direction_lies_on_its_face() {
        for t in 0..TEXELS {
            let d = texel_direction(t, [0.5, 0.5]);
            let face = t / (SIDE * SIDE);
            let axis = (face / 2) as usize;
            let sign = if face.is_multiple_of(2) { 1.0 } else { -1.0 };
            let a = d.abs().to_array();
            assert!(a[axis] >= a[(axis + 1) % 3] && a[axis] >= a[(axis + 2) % 3]);
            assert!(d.to_array()[axis] * sign > 0.0);
        }
    }
}
