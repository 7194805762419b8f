//! `shadow`: a depth map for every light of the scene, each rendered into one tile of a single
//! shadow atlas that the direct pass samples (docs/frame.md, "Shadow atlas").
//!
//! Decisions:
//! * **One atlas.** lavapipe indexes arrays of textures only with constants, so every map is a
//!   square tile of one D32 image: a spot light has one tile (its outer cone), a directional
//!   light one (an orthographic box around the scene), a point light six (cube faces +x, -x,
//!   +y, -y, +z, -z). A spot wider than [`WIDE_SPOT_HALF_ANGLE`] has six faces too, at half
//!   the side and four to a tile: one perspective map over its whole cone spreads its texels
//!   thin (the Cornell box's 90° lamp had stair-stepped shadows at 1080p). Each tile is one
//!   raster pass restricted to its rectangle ([`shine_graph::RasterPass::area`]), so clears
//!   and draws never touch the other tiles.
//! * **Tile size** is the `shadow.size` setting for every tile; when the atlas would exceed the
//!   device's largest 2D image the tiles are halved until it fits (with a warning).
//! * **Cube faces overlap.** A point-light face covers slightly more than 90° (its central 90°
//!   leaves a margin of PCF radius + 2 texels of the final tile on each side, at most a quarter
//!   of the tile), so the PCF kernel of a receiver whose major axis picked the face stays on the
//!   face's valid depth.

use super::gbuffer::{View, flip_y, light_view, scene_pipeline};
use crate::gpu_scene::{FrameState, SceneHandles};
use crate::shaders;
use glam::{Mat4, Vec3};
use shine_gpu::{GraphicsPipelineDesc, vk};
use shine_graph::{DepthLoad, Handle, Image, ImageDesc, RenderGraph};
use shine_scene::LightKind;

/// Shadow-map tile sides in texels (`shadow.size`).
pub const TILE_SIZE: std::ops::RangeInclusive<u32> = 64..=16384;

/// Default shadow-map tile side in texels.
pub const DEFAULT_TILE_SIZE: u32 = 2048;

/// Outer cone half-angle (radians) beyond which a spot light is shadowed through six cube
/// faces of half the slot's side. One map's texel near its axis is 2 tan(outer) / side, a half
/// face's about 4 / side: the faces are finer beyond tan(outer) = 2 (63.4°). At the Cornell
/// lamp's 90° (the single map's fov clamped to 166°) they are 4× finer.
pub const WIDE_SPOT_HALF_ANGLE: f32 = 1.107_148_8; // atan(2)

/// Default PCF radius in texels (a 3×3 kernel).
pub const DEFAULT_FILTER_RADIUS: f32 = 1.5;

/// Percentage-closer filter radii in texels (`shadow.filter_radius`; 0: one hard tap).
pub const FILTER_RADIUS: std::ops::RangeInclusive<f32> = 0.0..=16.0;

/// Smallest tile the atlas shrinks to before refusing (texels).
pub const MIN_TILE: u32 = 16;

/// Cube faces of a point light, in the order of its tiles: the axis each looks along and its
/// up vector (the direct pass picks the face by the receiver's major axis, in this order).
pub const CUBE_FACES: [(Vec3, Vec3, &str); 6] = [
    (Vec3::X, Vec3::Y, "+x"),
    (Vec3::NEG_X, Vec3::Y, "-x"),
    (Vec3::Y, Vec3::Z, "+y"),
    (Vec3::NEG_Y, Vec3::Z, "-y"),
    (Vec3::Z, Vec3::Y, "+z"),
    (Vec3::NEG_Z, Vec3::Y, "-z"),
];

/// One shadow view as the direct pass reads it (std430, 96 bytes; `ShadowView` of
/// `shaders/direct.comp`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct ShadowViewRecord {
    /// World to the view's clip space.
    pub view_proj: [[f32; 4]; 4],
    /// xy: the tile's origin in atlas uv; zw: its size in atlas uv.
    pub tile: [f32; 4],
    /// x: texel size in metres at 1 m from the light (perspective) or absolute (orthographic);
    /// y: 1 for orthographic; zw: 0.
    pub params: [f32; 4],
}

/// Which views shadow one light (std430, 16 bytes; `LightShadow` of `shaders/direct.comp`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct LightShadowRecord {
    /// Index of the light's first view.
    pub first_view: u32,
    /// Number of views: 0 (unshadowed), 1 (spot, directional) or 6 (point, wide spot).
    pub view_count: u32,
    /// Padding.
    pub pad: [u32; 2],
}

/// Where every light's shadow views lie in the atlas.
#[derive(Clone, Debug, PartialEq)]
pub struct ShadowLayout {
    /// Side of a slot of the atlas's grid in texels: a spot's or directional light's tile, a
    /// point light's face; a wide spot's face is half of it ([`WIDE_SPOT_HALF_ANGLE`]).
    pub tile: u32,
    /// Slots per atlas row.
    pub columns: u32,
    /// Slot rows.
    pub rows: u32,
    /// Every view: the light it belongs to, its pass name and its view.
    pub views: Vec<(u32, String, View)>,
    /// Every view's tile: texel origin and side.
    pub tiles: Vec<([u32; 2], u32)>,
    /// Per view, whether the scene is drawn into it: a wide spot's face that lies wholly
    /// outside its cone is only cleared (the direct pass may pick it, for points the spot
    /// does not light).
    pub drawn: Vec<bool>,
    /// Per light of the scene, in light order.
    pub lights: Vec<LightShadowRecord>,
    /// Set when the tiles had to shrink below the asked size.
    pub warning: Option<String>,
}

/// Why the shadow atlas cannot be laid out.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error(
    "{views} shadow views do not fit a {max_dimension}² atlas even with {MIN_TILE}² tiles: the scene has too many lights"
)]
pub struct ShadowLayoutError {
    /// Views asked for.
    pub views: usize,
    /// The device's largest 2D image side.
    pub max_dimension: u32,
}

/// How a light's views fill the atlas's slots.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Slots {
    /// No shadow (a light of unknown kind).
    None,
    /// One view in one slot (a spot or directional light).
    One,
    /// Six cube faces in six slots (a point light).
    Cube,
    /// Six cube faces at half the slot's side, four to a slot (a spot wider than
    /// [`WIDE_SPOT_HALF_ANGLE`], where half-size faces are already finer than one map over
    /// its cone).
    HalfCube,
}

impl Slots {
    fn of(light: &shine_scene::Light) -> Self {
        match light.light_kind() {
            Some(LightKind::Point) => Self::Cube,
            Some(LightKind::Spot) if light.outer_cone_angle > WIDE_SPOT_HALF_ANGLE => {
                Self::HalfCube
            }
            Some(_) => Self::One,
            None => Self::None,
        }
    }

    fn count(self) -> u32 {
        match self {
            Self::None => 0,
            Self::One => 1,
            Self::Cube => 6,
            Self::HalfCube => 2,
        }
    }
}

/// The half-angle tangent of a cube face of `side` texels whose central 90° leaves a margin of
/// `pcf_radius` + 2 texels (at most a quarter of the side) on each side.
fn face_tan_half(side: u32, pcf_radius: u32) -> f32 {
    let margin = ((pcf_radius + 2) as f32).min(side as f32 / 4.0);
    side as f32 / (side as f32 - 2.0 * margin)
}

impl ShadowLayout {
    /// The views of every light of `frame` in slots of `tile` texels (smaller if the atlas
    /// would exceed `max_dimension`), with a margin of `pcf_radius` + 2 texels around each
    /// cube face.
    pub fn new(
        frame: &FrameState,
        tile: u32,
        pcf_radius: u32,
        max_dimension: u32,
    ) -> Result<Self, ShadowLayoutError> {
        let slots: Vec<Slots> = frame.lights.iter().map(Slots::of).collect();
        let total: u32 = slots.iter().map(|s| s.count()).sum();
        let n = total.max(1);
        let columns = (f64::from(n).sqrt().ceil()) as u32;
        let rows = n.div_ceil(columns);
        let mut side = tile;
        while u64::from(columns.max(rows)) * u64::from(side) > u64::from(max_dimension) {
            side /= 2;
            if side < MIN_TILE {
                return Err(ShadowLayoutError {
                    views: total as usize,
                    max_dimension,
                });
            }
        }
        let slot_origin = |k: u32| [(k % columns) * side, (k / columns) * side];
        let mut views = Vec::with_capacity(6 * frame.lights.len());
        let mut tiles = Vec::with_capacity(6 * frame.lights.len());
        let mut drawn = Vec::with_capacity(6 * frame.lights.len());
        let mut lights = Vec::with_capacity(frame.lights.len());
        let mut slot = 0u32;
        for (i, (light, kind)) in frame.lights.iter().zip(&slots).enumerate() {
            let first_view = views.len() as u32;
            let index = i as u32;
            let eye = Vec3::from(light.position);
            match kind {
                Slots::Cube | Slots::HalfCube => {
                    let half = *kind == Slots::HalfCube;
                    let face_side = if half { side / 2 } else { side };
                    let tan_half = face_tan_half(face_side, pcf_radius);
                    // The face's frustum lies within this angle of its axis (its corners).
                    let face_half_angle = (std::f32::consts::SQRT_2 * tan_half).atan();
                    let spot = Vec3::from(light.direction).normalize_or(Vec3::NEG_Y);
                    for (f, (axis, up, face)) in CUBE_FACES.into_iter().enumerate() {
                        let f = f as u32;
                        let origin = if half {
                            let [x, y] = slot_origin(slot + f / 4);
                            [x + (f % 2) * face_side, y + (f % 4 / 2) * face_side]
                        } else {
                            slot_origin(slot + f)
                        };
                        let view = cube_face(frame, eye, axis, up, tan_half);
                        views.push((index, format!("shadow light {i} {face}"), view));
                        tiles.push((origin, face_side));
                        let apart = axis.dot(spot).clamp(-1.0, 1.0).acos();
                        drawn.push(!half || apart < light.outer_cone_angle + face_half_angle);
                    }
                }
                Slots::One => {
                    if let Some(view) = light_view(frame, i, side) {
                        views.push((index, format!("shadow light {i}"), view));
                        tiles.push((slot_origin(slot), side));
                        drawn.push(true);
                    }
                }
                Slots::None => {}
            }
            slot += kind.count();
            lights.push(LightShadowRecord {
                first_view,
                view_count: views.len() as u32 - first_view,
                pad: [0; 2],
            });
        }
        let warning = (side != tile).then(|| {
            format!(
                "{} shadow views at {tile}² do not fit a {max_dimension}² image: shadow tiles shrunk to {side}²",
                views.len()
            )
        });
        Ok(Self {
            warning,
            tile: side,
            columns,
            rows,
            views,
            tiles,
            drawn,
            lights,
        })
    }

    /// Width and height of the atlas in texels.
    pub fn atlas_extent(&self) -> [u32; 2] {
        [self.columns * self.tile, self.rows * self.tile]
    }

    /// The views as the direct pass reads them (at least one record, so the buffer exists).
    pub fn view_records(&self) -> Vec<ShadowViewRecord> {
        let [w, h] = self.atlas_extent();
        let mut records: Vec<ShadowViewRecord> = self
            .views
            .iter()
            .zip(&self.tiles)
            .map(|((_, _, view), ([x, y], side))| {
                let texel = if view.orthographic {
                    view.extent / *side as f32
                } else {
                    2.0 * (0.5 * view.extent).tan() / *side as f32
                };
                ShadowViewRecord {
                    view_proj: view.view_proj().to_cols_array_2d(),
                    tile: [
                        *x as f32 / w as f32,
                        *y as f32 / h as f32,
                        *side as f32 / w as f32,
                        *side as f32 / h as f32,
                    ],
                    params: [texel, f32::from(u8::from(view.orthographic)), 0.0, 0.0],
                }
            })
            .collect();
        if records.is_empty() {
            records.push(ShadowViewRecord::default());
        }
        records
    }

    /// The per-light records (at least one, so the buffer exists).
    pub fn light_records(&self) -> Vec<LightShadowRecord> {
        let mut records = self.lights.clone();
        if records.is_empty() {
            records.push(LightShadowRecord::default());
        }
        records
    }
}

/// One cube face of a point light at `eye` looking along `axis`: a square frustum whose
/// half-angle tangent is `tan_half` (1 = exactly 90°), reaching past the scene's far side.
pub(crate) fn cube_face(
    frame: &FrameState,
    eye: Vec3,
    axis: Vec3,
    up: Vec3,
    tan_half: f32,
) -> View {
    let (lo, hi) = frame.bounds;
    let center = (lo + hi) * 0.5;
    let radius = ((hi - lo).length() * 0.5).max(1e-3);
    let far = (eye - center).length() + radius * 2.0;
    let near = (far * 1e-3).max(1e-3);
    let fov = 2.0 * tan_half.atan();
    View {
        view: Mat4::look_to_rh(eye, axis, up),
        proj: flip_y(Mat4::perspective_rh(fov, 1.0, near, far)),
        eye,
        orthographic: false,
        extent: fov,
    }
}

/// The shadow atlas of a frame and the buffers describing it.
#[derive(Clone, Copy, Debug)]
pub struct ShadowAtlas {
    /// D32 depth, the tiles of [`ShadowLayout`].
    pub depth: Handle<Image>,
    /// [`ShadowViewRecord`]s.
    pub views: Handle<shine_graph::Buffer>,
    /// [`LightShadowRecord`]s, one per light.
    pub lights: Handle<shine_graph::Buffer>,
    /// Atlas width and height.
    pub extent: [u32; 2],
    /// Number of views rendered (0: nothing is shadowed).
    pub view_count: u32,
}

/// Rasterises the scene's depth from every view of `layout` into its tile of a new atlas.
/// `views` and `lights` hold [`ShadowLayout::view_records`] and
/// [`ShadowLayout::light_records`].
pub fn shadow_atlas(
    rg: &mut RenderGraph,
    scene: &SceneHandles,
    layout: &ShadowLayout,
    views: Handle<shine_graph::Buffer>,
    lights: Handle<shine_graph::Buffer>,
) -> ShadowAtlas {
    let extent = layout.atlas_extent();
    let mut depth = rg.create_image(
        "shadow_atlas",
        ImageDesc::new_2d(vk::Format::D32_SFLOAT, extent[0], extent[1]),
    );
    if layout.views.is_empty() {
        // Nothing casts a shadow: the atlas is one cleared tile the direct pass never reads.
        rg.raster("shadow clear", shadow_pipeline())
            .depth(&mut depth, DepthLoad::Clear(1.0))
            .push(&super::gbuffer::ViewConstants::default());
    }
    let views_and_tiles = layout.views.iter().zip(&layout.tiles).zip(&layout.drawn);
    for (((_, name, view), (origin, side)), drawn) in views_and_tiles {
        if !drawn {
            rg.raster(&format!("{name} clear"), shadow_pipeline())
                .depth(&mut depth, DepthLoad::Clear(1.0))
                .area(*origin, [*side, *side])
                .push(&super::gbuffer::ViewConstants::default());
            continue;
        }
        rg.raster(name, shadow_pipeline())
            .depth(&mut depth, DepthLoad::Clear(1.0))
            .area(*origin, [*side, *side])
            .vertex_buffer(&scene.vertices)
            .index_buffer(&scene.indices, vk::IndexType::UINT32)
            .push(&view.constants(None))
            .draw_indexed(scene.index_count, 1);
    }
    ShadowAtlas {
        depth,
        views,
        lights,
        extent,
        view_count: layout.views.len() as u32,
    }
}

/// Depth-only scene pipeline with a slope-scaled bias against acne (constant in depth units,
/// slope factor); the direct pass adds a normal offset on top.
fn shadow_pipeline() -> GraphicsPipelineDesc {
    scene_pipeline(&shaders::GBUFFER_VERT_PLAIN, None, &[], Some((1.0, 1.5)))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::gpu_scene::{FrameState, FrameUpdate};

    /// The Cornell lamp (a spot of 90° half-angle pointing down) gets six half-size faces in
    /// two slots, four to the first; its +y face, wholly above the cone, is only cleared.
    #[test]
    fn a_wide_spot_has_half_size_faces_and_skips_the_one_outside_its_cone() {
        let scene = shine_scene::Scene::builtin("cornell-box").expect("builtin");
        let frame = FrameState::evaluate(&scene, &FrameUpdate::default());
        let layout = ShadowLayout::new(&frame, 512, 1, 16384).expect("layout");
        assert_eq!(layout.lights[0].view_count, 6);
        assert_eq!((layout.columns, layout.rows), (2, 1));
        let names: Vec<&str> = layout.views.iter().map(|(_, n, _)| n.as_str()).collect();
        assert_eq!(names[2], "shadow light 0 +y");
        assert_eq!(layout.drawn, [true, true, false, true, true, true]);
        let origins: Vec<[u32; 2]> = layout.tiles.iter().map(|(o, _)| *o).collect();
        assert_eq!(
            origins,
            [[0, 0], [256, 0], [0, 256], [256, 256], [512, 0], [768, 0]]
        );
        assert!(layout.tiles.iter().all(|(_, side)| *side == 256));
    }
}
