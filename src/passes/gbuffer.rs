//! `gbuffer`: the scene rasterised from the camera into the G-buffer; the camera and light
//! views and the scene raster pipeline every raster pass shares (shadows, RSM).

use crate::gpu_scene::{FrameState, SceneHandles, Vertex};
use crate::shaders;
use glam::{Mat4, Vec3};
use shine_gpu::{Blend, DepthState, GraphicsPipelineDesc, VertexBufferLayout, vk};
use shine_graph::{ColorLoad, DepthLoad, Handle, Image, ImageDesc, RenderGraph};
use shine_scene::LightKind;

/// Push constants of `view.glsl` (112 bytes).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct ViewConstants {
    /// World to clip (Vulkan clip space: y down, depth 0..1).
    pub view_proj: [[f32; 4]; 4],
    /// Linear view depth of p is `dot(xyz, p) + w`.
    pub depth_plane: [f32; 4],
    /// Eye position (camera or light).
    pub eye: [f32; 4],
    /// RSM parameters (see view.glsl).
    pub params: [f32; 4],
}

/// A view of the scene: the camera or a light.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct View {
    /// World to view (right-handed, looking down -Z).
    pub view: Mat4,
    /// View to clip, Vulkan conventions.
    pub proj: Mat4,
    /// Eye position.
    pub eye: Vec3,
    /// Orthographic projection (directional light).
    pub orthographic: bool,
    /// Full vertical field of view in radians (perspective) or full width in metres (ortho).
    pub extent: f32,
}

impl View {
    /// Unit world direction the view looks along.
    pub fn forward(&self) -> Vec3 {
        self.view
            .inverse()
            .transform_vector3(Vec3::NEG_Z)
            .normalize_or(Vec3::NEG_Z)
    }

    /// World to clip.
    pub fn view_proj(&self) -> Mat4 {
        self.proj * self.view
    }

    /// Push constants for this view; `rsm` carries the RSM size and light index.
    pub fn constants(&self, rsm: Option<(u32, u32)>) -> ViewConstants {
        let row = self.view.row(2);
        let params = match rsm {
            Some((size, light)) => {
                let per_texel = if self.orthographic {
                    // Texel footprint area perpendicular to the light.
                    (self.extent / size as f32).powi(2)
                } else {
                    // Solid angle of a texel on the axis: (2 tan(fov/2) / S)^2.
                    (2.0 * (0.5 * self.extent).tan() / size as f32).powi(2)
                };
                [
                    per_texel,
                    f32::from(u8::from(self.orthographic)),
                    light as f32,
                    0.0,
                ]
            }
            None => [0.0; 4],
        };
        ViewConstants {
            view_proj: self.view_proj().to_cols_array_2d(),
            depth_plane: (-row).to_array(),
            eye: self.eye.extend(1.0).to_array(),
            params,
        }
    }
}

/// Vulkan clip space from a right-handed GL-style projection: y points down.
pub(crate) fn flip_y(mut proj: Mat4) -> Mat4 {
    proj.y_axis.y = -proj.y_axis.y;
    proj
}

/// The camera view of `frame` for a `width`×`height` image, its projection offset by the
/// frame's sub-pixel jitter.
pub fn camera_view(frame: &FrameState, width: u32, height: u32) -> View {
    jittered_camera_view(frame, width, height, frame.jitter)
}

/// The camera view of `frame` without its jitter (motion vectors compare these).
pub fn unjittered_camera_view(frame: &FrameState, width: u32, height: u32) -> View {
    jittered_camera_view(frame, width, height, [0.0; 2])
}

/// The camera view of `frame` offset by `[jx, jy]` pixels (TAA adds its own jitter to the
/// frame's).
pub fn jittered_camera_view(
    frame: &FrameState,
    width: u32,
    height: u32,
    [jx, jy]: [f32; 2],
) -> View {
    let aspect = width as f32 / height.max(1) as f32;
    let view = frame.camera_world.inverse();
    let eye = frame.camera_world.transform_point3(Vec3::ZERO);
    // A shift by (jx, jy) pixels is 2j / size in clip space (Vulkan clip y points down, as
    // image rows do).
    let jitter = Mat4::from_translation(Vec3::new(
        2.0 * jx / width.max(1) as f32,
        2.0 * jy / height.max(1) as f32,
        0.0,
    ));
    let (orthographic, extent) = match frame.projection {
        shine_scene::Projection::Perspective { yfov, .. } => (false, yfov),
        shine_scene::Projection::Orthographic { ymag, .. } => (true, 2.0 * ymag),
    };
    let mut view = View {
        view,
        proj: projection_matrix(&frame.projection, aspect),
        eye,
        orthographic,
        extent,
    };
    view.proj = jitter * view.proj;
    view
}

/// The view-to-clip matrix of a scene camera's `projection` for an image of `aspect` (width
/// over height), in Vulkan's clip conventions (y down, depth 0..1): the renderer's cameras
/// and the GI context's [`crate::embed::GiCamera::from_scene`] both use it.
pub(crate) fn projection_matrix(projection: &shine_scene::Projection, aspect: f32) -> Mat4 {
    flip_y(match *projection {
        shine_scene::Projection::Perspective {
            yfov, znear, zfar, ..
        } => match zfar {
            Some(far) => Mat4::perspective_rh(yfov, aspect, znear, far),
            None => Mat4::perspective_infinite_rh(yfov, aspect, znear),
        },
        shine_scene::Projection::Orthographic {
            ymag, znear, zfar, ..
        } => Mat4::orthographic_rh(-ymag * aspect, ymag * aspect, -ymag, ymag, znear, zfar),
    })
}

/// Steps per octave of a directional light's box radius: the radius is rounded up to a
/// multiple of 2^⌊log₂ r⌋ / RADIUS_STEPS (at most 1/16 larger than the scene's).
pub const RADIUS_STEPS: f32 = 16.0;

/// A directional light's orthographic box around a sphere (`center`, `radius`) for a map
/// `side` texels wide, made texel-stable as cascaded shadow maps stabilise theirs (issue 23):
/// the radius is rounded up to [`RADIUS_STEPS`] per octave and grown by one texel, and the
/// centre snapped, in the light's image plane (axis `dir`, `up`), to whole texels of the map.
/// Scene bounds that change a little (a moving object, a morph) then shift the map by whole
/// texels or not at all, instead of sliding every texel by a fraction, and the sphere stays
/// inside. Returns the box's centre and half-width.
pub fn stable_box(center: Vec3, radius: f32, dir: Vec3, up: Vec3, side: u32) -> (Vec3, f32) {
    let step = 2f32.powf(radius.log2().floor()) / RADIUS_STEPS;
    let rounded = (radius / step).ceil() * step;
    let side = side.max(2) as f32;
    // Half a texel of snap on either side: one texel of margin (2r' / side = texel).
    let radius = rounded * side / (side - 2.0);
    let texel = 2.0 * radius / side;
    let to_light = Mat4::look_to_rh(Vec3::ZERO, dir, up);
    let local = to_light.transform_point3(center);
    let snapped = Vec3::new(
        (local.x / texel).round() * texel,
        (local.y / texel).round() * texel,
        local.z,
    );
    (to_light.inverse().transform_point3(snapped), radius)
}

/// The primary light's view (the RSM and shadow map): a perspective frustum along a spot
/// light's axis covering its outer cone, an orthographic box around the scene for a
/// directional light (texel-stable for a map `side` texels wide: [`stable_box`]), or a frustum
/// from a point light towards the scene's centre.
pub fn light_view(frame: &FrameState, light_index: usize, side: u32) -> Option<View> {
    let light = frame.lights.get(light_index)?;
    let (lo, hi) = frame.bounds;
    let center = (lo + hi) * 0.5;
    let radius = ((hi - lo).length() * 0.5).max(1e-3);
    let up_for = |dir: Vec3| if dir.y.abs() > 0.99 { Vec3::Z } else { Vec3::Y };
    match light.light_kind()? {
        LightKind::Directional => {
            let dir = Vec3::from(light.direction).normalize_or(Vec3::NEG_Y);
            let (center, radius) = stable_box(center, radius, dir, up_for(dir), side);
            let eye = center - dir * radius * 2.0;
            Some(View {
                view: Mat4::look_to_rh(eye, dir, up_for(dir)),
                proj: flip_y(Mat4::orthographic_rh(
                    -radius,
                    radius,
                    -radius,
                    radius,
                    0.0,
                    radius * 4.0,
                )),
                eye,
                orthographic: true,
                extent: 2.0 * radius,
            })
        }
        kind => {
            let eye = Vec3::from(light.position);
            let (dir, fov) = if kind == LightKind::Spot {
                let dir = Vec3::from(light.direction).normalize_or(Vec3::NEG_Y);
                (dir, (2.0 * light.outer_cone_angle).clamp(0.1, 2.9))
            } else {
                let to_center = center - eye;
                let distance = to_center.length().max(1e-3);
                let fov = 2.0 * (radius / distance).min(1.0).asin().max(0.3);
                (to_center / distance, fov.min(2.9))
            };
            let far = (eye - center).length() + radius * 2.0;
            let near = (far * 1e-3).max(1e-3);
            Some(View {
                view: Mat4::look_to_rh(eye, dir, up_for(dir)),
                proj: flip_y(Mat4::perspective_rh(fov, 1.0, near, far)),
                eye,
                orthographic: false,
                extent: fov,
            })
        }
    }
}

/// The full-resolution G-buffer images (docs/frame.md).
#[derive(Clone, Copy, Debug)]
pub struct GBuffer {
    /// World position, w = linear view depth (0 on background).
    pub position: Handle<Image>,
    /// World shading normal.
    pub normal: Handle<Image>,
    /// Linear base colour.
    pub albedo: Handle<Image>,
    /// r = roughness, g = metallic.
    pub material: Handle<Image>,
    /// Emitted radiance.
    pub emissive: Handle<Image>,
    /// World geometric normal: the interpolated vertex normal before normal mapping, facing
    /// the camera (`gb_geometric_normal`, RGBA16F; paper 000's filter tests it).
    pub geometric_normal: Handle<Image>,
    /// Motion: texture coordinates now minus where the surface point was in the previous
    /// frame (RG16F; jitter excluded; zero on the background and on a scene's first frame).
    pub motion: Handle<Image>,
    /// Hardware depth.
    pub depth: Handle<Image>,
    /// Width and height.
    pub extent: [u32; 2],
}

impl GBuffer {
    /// The G-buffer's images of `extent`, new in `rg` (docs/frame.md lists their formats),
    /// for a pass to write.
    pub fn create(rg: &mut RenderGraph, extent: [u32; 2]) -> Self {
        let [w, h] = extent;
        let mut image = |name, format| rg.create_image(name, ImageDesc::new_2d(format, w, h));
        Self {
            position: image("gb_position", vk::Format::R32G32B32A32_SFLOAT),
            normal: image("gb_normal", vk::Format::R16G16B16A16_SFLOAT),
            albedo: image("gb_albedo", vk::Format::R8G8B8A8_UNORM),
            material: image("gb_material", vk::Format::R8G8B8A8_UNORM),
            emissive: image("gb_emissive", vk::Format::R16G16B16A16_SFLOAT),
            geometric_normal: image("gb_geometric_normal", vk::Format::R16G16B16A16_SFLOAT),
            motion: image("gb_motion", MOTION_FORMAT),
            depth: image("depth", vk::Format::D32_SFLOAT),
            extent,
        }
    }
}

/// Format of [`GBuffer::motion`].
pub const MOTION_FORMAT: vk::Format = vk::Format::R16G16_SFLOAT;

/// Both frames' unjittered world-to-clip matrices, as `gbuffer.vert` reads them (128 bytes).
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct MotionView {
    /// The previous frame's camera.
    pub previous: [[f32; 4]; 4],
    /// This frame's camera.
    pub current: [[f32; 4]; 4],
}

/// The pipeline of every scene raster pass: the flattened scene's vertices through
/// `gbuffer.vert` (`vertex`: its plain or motion variant), an optional fragment shader and
/// colour targets, depth tested and written.
pub(crate) fn scene_pipeline(
    vertex: &'static shine_gpu::ShaderDesc,
    fragment: Option<&'static shine_gpu::ShaderDesc>,
    colors: &[vk::Format],
    depth_bias: Option<(f32, f32)>,
) -> GraphicsPipelineDesc {
    GraphicsPipelineDesc {
        vertex,
        fragment,
        vertex_buffers: vec![VertexBufferLayout {
            stride: std::mem::size_of::<Vertex>() as u32,
            per_instance: false,
            attributes: vec![(0, 0), (1, 12), (2, 16), (3, 32), (4, 48)],
        }],
        topology: vk::PrimitiveTopology::TRIANGLE_LIST,
        cull_mode: vk::CullModeFlags::NONE,
        color_targets: colors.iter().map(|f| (*f, Blend::Replace)).collect(),
        depth: Some(DepthState {
            format: vk::Format::D32_SFLOAT,
            compare: vk::CompareOp::LESS_OR_EQUAL,
            write: true,
        }),
        depth_bias,
    }
}

/// Rasterises the scene from the camera into a new G-buffer; `motion_view` holds the
/// [`MotionView`] of the frame (the previous vertices are the scene's).
pub fn gbuffer(
    rg: &mut RenderGraph,
    scene: &SceneHandles,
    view: &View,
    motion_view: &Handle<shine_graph::Buffer>,
    extent: [u32; 2],
    sampler: vk::Sampler,
) -> GBuffer {
    let mut g = GBuffer::create(rg, extent);
    let pipeline = scene_pipeline(
        &shaders::GBUFFER_VERT_MOTION,
        Some(&shaders::GBUFFER_FRAG),
        &[
            vk::Format::R32G32B32A32_SFLOAT,
            vk::Format::R16G16B16A16_SFLOAT,
            vk::Format::R8G8B8A8_UNORM,
            vk::Format::R8G8B8A8_UNORM,
            vk::Format::R16G16B16A16_SFLOAT,
            vk::Format::R16G16B16A16_SFLOAT,
            MOTION_FORMAT,
        ],
        None,
    );
    rg.raster("gbuffer", pipeline)
        .color(&mut g.position, ColorLoad::Clear([0.0; 4]))
        .color(&mut g.normal, ColorLoad::Clear([0.0; 4]))
        .color(&mut g.albedo, ColorLoad::Clear([0.0; 4]))
        .color(&mut g.material, ColorLoad::Clear([0.0; 4]))
        .color(&mut g.emissive, ColorLoad::Clear([0.0; 4]))
        .color(&mut g.geometric_normal, ColorLoad::Clear([0.0; 4]))
        .color(&mut g.motion, ColorLoad::Clear([0.0; 4]))
        .depth(&mut g.depth, DepthLoad::Clear(1.0))
        .read("prev_vertices", &scene.prev_vertices)
        .read("motion_view", motion_view)
        .read("materials", &scene.materials)
        .read("srgb_textures", &scene.srgb_textures)
        .read("linear_textures", &scene.linear_textures)
        .sampler("texture_sampler", sampler)
        .vertex_buffer(&scene.vertices)
        .index_buffer(&scene.indices, vk::IndexType::UINT32)
        .push(&view.constants(None))
        .draw_indexed(scene.index_count, 1);
    g
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec2;

    /// Where `p` falls in texels of a `side`-wide map of the box (`center`, `radius`) seen along
    /// `dir`.
    fn texel_of(p: Vec3, (center, radius): (Vec3, f32), dir: Vec3, up: Vec3, side: f32) -> Vec2 {
        let local = Mat4::look_to_rh(Vec3::ZERO, dir, up).transform_point3(p - center);
        (Vec2::new(local.x, local.y) + radius) / (2.0 * radius) * side
    }

    /// Bounds that grow or move by a little (up to 2 mm in a 10 m scene) move a fixed world
    /// point by a whole number of texels of the map the box is made for, at every side, and
    /// its fraction within the texel stays; unsnapped, it slides by fractions.
    #[test]
    fn a_directional_box_moves_by_whole_texels() {
        let dir = Vec3::new(0.3, -1.0, 0.2).normalize();
        let up = Vec3::Y;
        let point = Vec3::new(1.234, 0.5, -2.345);
        let (c0, r0) = (Vec3::new(0.1, 1.5, -0.2), 4.9);
        let base = |side| stable_box(c0, r0, dir, up, side);
        let mut slid = 0.0f32;
        for k in 1..20 {
            let d = k as f32 * 1e-4;
            let (c, r) = (c0 + Vec3::new(d, -0.5 * d, 0.7 * d), r0 + 0.3 * d);
            for side in [256, 2048, 16384] {
                let moved = stable_box(c, r, dir, up, side);
                assert_eq!(moved.1, base(side).1, "radius {r}");
                let a = texel_of(point, base(side), dir, up, side as f32);
                let b = texel_of(point, moved, dir, up, side as f32);
                let shift = b - a;
                assert!(
                    (shift - shift.round()).abs().max_element() < 0.02,
                    "side {side}, step {k}: shift {shift}"
                );
                let unsnapped = texel_of(point, (c, r), dir, up, side as f32)
                    - texel_of(point, (c0, r0), dir, up, side as f32);
                slid = slid.max((unsnapped - unsnapped.round()).abs().max_element());
            }
        }
        // The test can tell: without the snap the point slides by fractions of a texel.
        assert!(slid > 0.1, "unsnapped slide {slid}");
    }

    /// The box still holds the scene's sphere: its half-width is at least the sphere's radius
    /// plus the centre's snap, and at most 1/16 and a texel larger.
    #[test]
    fn a_stable_box_holds_the_scene() {
        for side in [16u32, 256, 4096] {
            for r in [0.01f32, 0.7, 1.0, 3.3, 250.0] {
                let c = Vec3::new(r * 0.3, -r, 2.0 * r);
                let (center, radius) = stable_box(c, r, Vec3::NEG_Y, Vec3::Z, side);
                assert!(radius >= r + center.distance(c), "side {side}, r {r}");
                let most = r * (1.0 + 1.0 / RADIUS_STEPS) * side as f32 / (side as f32 - 2.0);
                assert!(radius <= most * 1.0001, "side {side}, r {r}: {radius}");
            }
        }
    }
}
