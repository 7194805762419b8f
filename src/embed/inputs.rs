//! What a host hands a [`super::GiContext`] each frame: its camera, its G-buffer images with
//! their encodings, and the image the indirect light goes to (docs/embedding.md).

use crate::frame::RenderError;
use crate::frame::renderer::HostTarget;
use crate::passes::debug_view::DebugView;
use crate::passes::gbuffer::{View, flip_y, projection_matrix};
use crate::passes::host_gbuffer::{HostFrame, NO_CHANNEL};
use glam::{Mat4, Vec3};
use shine_gpu::vk;
use shine_scene::Scene;

/// The host's camera this frame and the previous one. Projections follow Vulkan clip
/// conventions (y down, depth 0..1, standard or reversed Z as [`DepthConvention`] says) and
/// are given without jitter; `jitter` is the sub-pixel offset the host rasterised with.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GiCamera {
    /// World to view (right-handed, looking down −Z).
    pub view: Mat4,
    /// View to clip, unjittered.
    pub projection: Mat4,
    /// The offset in pixels the G-buffer was rasterised with (x right, y down; 0 without TAA).
    pub jitter: [f32; 2],
    /// The previous frame's world to view (the current one on a first frame).
    pub previous_view: Mat4,
    /// The previous frame's view to clip, unjittered.
    pub previous_projection: Mat4,
}

impl GiCamera {
    /// A camera that has not moved since the previous frame.
    pub fn still(view: Mat4, projection: Mat4) -> Self {
        Self {
            view,
            projection,
            jitter: [0.0; 2],
            previous_view: view,
            previous_projection: projection,
        }
    }

    /// A perspective camera at `eye` looking at `target` (+Y up) with vertical field of view
    /// `yfov` (radians) and the given aspect and clip planes, in shine's conventions: what a
    /// host without matrices of its own (the tests, the example) passes.
    pub fn look_at(eye: Vec3, target: Vec3, yfov: f32, aspect: f32, near: f32, far: f32) -> Self {
        Self::still(
            Mat4::look_at_rh(eye, target, Vec3::Y),
            flip_y(Mat4::perspective_rh(yfov, aspect, near, far)),
        )
    }

    /// Camera `index` of `scene` at time `t`, and at `previous_t` as the previous frame's, for
    /// an image of `extent`: the matrices shine's own renderer uses for that camera. `None`
    /// when the scene has no such camera.
    pub fn from_scene(
        scene: &Scene,
        index: usize,
        t: f32,
        previous_t: f32,
        extent: [u32; 2],
    ) -> Option<Self> {
        let camera = scene.cameras.get(index)?;
        let aspect = extent[0] as f32 / extent[1].max(1) as f32;
        let projection = projection_matrix(&camera.projection, aspect);
        let view_at = |t: f32| {
            scene
                .camera_world(index, &scene.pose_at(t).world)
                .map(|world| world.inverse())
        };
        Some(Self {
            view: view_at(t)?,
            projection,
            jitter: [0.0; 2],
            previous_view: view_at(previous_t)?,
            previous_projection: projection,
        })
    }

    /// The camera position (the view matrix's origin).
    pub fn position(&self) -> Vec3 {
        self.view.inverse().transform_point3(Vec3::ZERO)
    }

    /// The projection with the jitter applied, for an image of `extent`.
    fn jittered_projection(&self, extent: [u32; 2]) -> Mat4 {
        let [jx, jy] = self.jitter;
        Mat4::from_translation(Vec3::new(
            2.0 * jx / extent[0].max(1) as f32,
            2.0 * jy / extent[1].max(1) as f32,
            0.0,
        )) * self.projection
    }

    /// The view the passes read (eye, orthographic or not, field of view) for `extent`.
    pub(crate) fn view_for(&self, extent: [u32; 2]) -> View {
        let orthographic = self.projection.w_axis.w == 1.0 && self.projection.z_axis.w == 0.0;
        let y_scale = self.projection.y_axis.y.abs().max(f32::MIN_POSITIVE);
        View {
            view: self.view,
            proj: self.jittered_projection(extent),
            eye: self.position(),
            orthographic,
            extent: if orthographic {
                2.0 / y_scale
            } else {
                2.0 * (1.0 / y_scale).atan()
            },
        }
    }

    /// Checks that every matrix is finite and invertible.
    fn validate(&self) -> Result<(), RenderError> {
        let matrices = [
            ("view", self.view),
            ("projection", self.projection),
            ("previous view", self.previous_view),
            ("previous projection", self.previous_projection),
        ];
        for (name, m) in matrices {
            if !m.is_finite() || m.determinant().abs() < f32::MIN_POSITIVE {
                return Err(invalid(format!(
                    "camera {name} is not finite and invertible"
                )));
            }
        }
        if !self.jitter.iter().all(|j| j.is_finite()) {
            return Err(invalid("camera jitter is not finite".into()));
        }
        Ok(())
    }
}

/// Which depth an empty (background) pixel holds.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum DepthConvention {
    /// Near 0, far 1, cleared to 1.
    #[default]
    Standard,
    /// Reversed Z: near 1, far 0, cleared to 0.
    Reversed,
}

/// How the host stores world-space normals: `n = normalize(texel.xyz · mul + add)`, as
/// FidelityFX's `normalsUnpackMul`/`normalsUnpackAdd`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NormalEncoding {
    /// Scale applied to the texel.
    pub mul: f32,
    /// Offset added after the scale.
    pub add: f32,
}

impl NormalEncoding {
    /// Signed formats (RGBA16F, RGBA16_SNORM …): the texel is the normal.
    pub const SIGNED: Self = Self { mul: 1.0, add: 0.0 };
    /// Unsigned normalised formats (RGBA8_UNORM, A2B10G10R10_UNORM …): `n = 2·texel − 1`.
    pub const UNORM: Self = Self {
        mul: 2.0,
        add: -1.0,
    };
}

/// Where roughness and metallic sit in the host's material image.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct MaterialChannels {
    /// The channel (0 = r … 3 = a) holding roughness.
    pub roughness: u32,
    /// The channel holding metallic; `None`: dielectric everywhere.
    pub metallic: Option<u32>,
    /// Whether the channel holds α = roughness² (GGX alpha) rather than perceptual roughness.
    pub roughness_squared: bool,
}

impl Default for MaterialChannels {
    /// glTF's metallic-roughness convention in the first two channels: r = perceptual
    /// roughness, g = metallic.
    fn default() -> Self {
        Self {
            roughness: 0,
            metallic: Some(1),
            roughness_squared: false,
        }
    }
}

/// The host's motion vectors and how to read them: shine's motion (texture coordinates now
/// minus then) is `texel.xy · scale`. Vectors pointing from now to then in texture
/// coordinates take `[-1, -1]`; in pixels, `[-1/width, -1/height]`.
#[derive(Clone, Copy, Debug)]
pub struct HostMotion {
    /// The image (display size, sampled).
    pub image: HostTarget,
    /// Per-axis scale to shine's convention.
    pub scale: [f32; 2],
}

/// The host's environment map: an equirectangular radiance image (any size; linear RGB, a
/// float format; u = atan2(d.x, −d.z)/2π + ½ across, v = acos(d.y)/π down, shine-scene's
/// convention) times `intensity`. Projected to SH on the GPU every dispatch (for a 256×128 map
/// at 4 bands, about 2 M multiply-adds); it lights the proxy technique in place of the
/// scene's environment.
#[derive(Clone, Copy, Debug)]
pub struct HostEnvironment {
    /// The image (sampled).
    pub image: HostTarget,
    /// Multiplier on its radiance.
    pub intensity: f32,
}

/// One frame of a [`super::GiContext`]: what the host recorded before and where the result
/// goes. Every image is display-sized, 2D, one mip and layer; inputs need `SAMPLED` and are
/// only read; each carries the state of the host's last use (`before`) and the one the
/// context leaves it in (`after`).
#[derive(Clone, Copy, Debug)]
pub struct GiDispatch {
    /// The host's frame number: strictly increasing from dispatch to dispatch. The host
    /// promises that frame `frame_index − frames_in_flight` has completed on the GPU.
    pub frame_index: u64,
    /// The camera the G-buffer was rasterised with.
    pub camera: GiCamera,
    /// Depth (D32_SFLOAT, D24_UNORM_S8_UINT or X8_D24_UNORM_PACK32), through a depth-only
    /// view.
    pub depth: HostTarget,
    /// Which depth an empty pixel holds.
    pub depth_convention: DepthConvention,
    /// World-space normals.
    pub normals: HostTarget,
    /// How `normals` are encoded.
    pub normal_encoding: NormalEncoding,
    /// Linear base colour in rgb (an sRGB format is decoded by the sampler).
    pub albedo: HostTarget,
    /// Roughness and metallic.
    pub material: HostTarget,
    /// Where roughness and metallic are in `material`.
    pub material_channels: MaterialChannels,
    /// Motion vectors; `None`: the camera's motion alone (objects that move reproject
    /// wrongly, and amortised techniques lag on them).
    pub motion: Option<HostMotion>,
    /// The environment map; `None`: the scene's environment (if any).
    pub environment: Option<HostEnvironment>,
    /// Output: the indirect radiance the GI techniques carry (diffuse, and the glossy lobes
    /// rougher than `specular.limit`), accumulated over frames; with no `specular` output,
    /// the traced reflections too. RGBA16F (or another float format a blit can write),
    /// `TRANSFER_DST`. `None`: not computed.
    pub diffuse: Option<HostTarget>,
    /// Output: the traced specular reflections of the lobes smoother than `specular.limit`
    /// (faded in below it), denoised in space and not accumulated over frames; the same
    /// formats as `diffuse`. `None`: they go into `diffuse` (when `specular.enabled`).
    pub specular: Option<HostTarget>,
    /// Output for debugging: what the GI sees, as `debug_view` says, drawn at the display size
    /// (docs/embedding.md "Debug view"); the same formats as `diffuse`. `None`: nothing of it
    /// is declared, and the frame is the same without it.
    pub debug: Option<HostTarget>,
    /// What `debug` shows. A view the context's technique does not have is refused. Chosen per
    /// dispatch, not on the context: a host flips between views (a debug menu) without a new
    /// context, and a frame budget may change the technique at `set_scene`, so only a
    /// dispatch knows what runs. Not used without `debug`.
    pub debug_view: DebugView,
}

/// Depth formats a dispatch reads.
const DEPTH_FORMATS: [vk::Format; 3] = [
    vk::Format::D32_SFLOAT,
    vk::Format::D24_UNORM_S8_UINT,
    vk::Format::X8_D24_UNORM_PACK32,
];

impl GiDispatch {
    /// Checks the dispatch against the context's `display` size: sizes, formats, usages,
    /// channels and the camera.
    pub(crate) fn validate(&self, display: [u32; 2]) -> Result<(), RenderError> {
        self.camera.validate()?;
        let mut inputs = vec![
            ("depth", &self.depth),
            ("normals", &self.normals),
            ("albedo", &self.albedo),
            ("material", &self.material),
        ];
        if let Some(motion) = &self.motion {
            inputs.push(("motion", &motion.image));
            if !motion.scale.iter().all(|s| s.is_finite()) {
                return Err(invalid("motion scale is not finite".into()));
            }
        }
        for (name, image) in inputs {
            check_extent(name, image, display)?;
            if !image.usage.contains(vk::ImageUsageFlags::SAMPLED) {
                return Err(invalid(format!("{name} image needs SAMPLED usage")));
            }
        }
        if !DEPTH_FORMATS.contains(&self.depth.format) {
            return Err(invalid(format!(
                "depth format {:?} is not one of {DEPTH_FORMATS:?}",
                self.depth.format
            )));
        }
        let channels = self.material_channels;
        if channels.roughness > 3 || channels.metallic.is_some_and(|c| c > 3) {
            return Err(invalid("material channels are 0 (r) to 3 (a)".into()));
        }
        if ![self.normal_encoding.mul, self.normal_encoding.add]
            .iter()
            .all(|v| v.is_finite())
        {
            return Err(invalid("normal encoding is not finite".into()));
        }
        if let Some(env) = &self.environment {
            if !env.image.usage.contains(vk::ImageUsageFlags::SAMPLED) {
                return Err(invalid("environment image needs SAMPLED usage".into()));
            }
            if env.image.extent.contains(&0) {
                return Err(invalid("environment image is empty".into()));
            }
            if !(env.intensity.is_finite() && env.intensity >= 0.0) {
                return Err(invalid(format!(
                    "environment intensity {} is not a finite number ≥ 0",
                    env.intensity
                )));
            }
        }
        let outputs = [("diffuse", &self.diffuse), ("specular", &self.specular)];
        if outputs.iter().all(|(_, o)| o.is_none()) {
            return Err(invalid(
                "the dispatch has no output: give diffuse, specular or both".into(),
            ));
        }
        for (name, output) in outputs.into_iter().chain([("debug", &self.debug)]) {
            let Some(output) = output else { continue };
            check_extent(name, output, display)?;
            if !output.usage.contains(vk::ImageUsageFlags::TRANSFER_DST) {
                return Err(invalid(format!("{name} output needs TRANSFER_DST usage")));
            }
            if shine_gpu::format_aspect(output.format) != vk::ImageAspectFlags::COLOR {
                return Err(invalid(format!(
                    "{name} output format {:?} is not a colour format",
                    output.format
                )));
            }
        }
        Ok(())
    }

    /// The constants of `host_gbuffer.comp` for this dispatch at `display` size.
    pub(crate) fn host_frame(&self, display: [u32; 2]) -> HostFrame {
        let c = &self.camera;
        let jittered = c.jittered_projection(display) * c.view;
        let row = c.view.row(2);
        let channels = self.material_channels;
        HostFrame {
            inverse_view_proj: jittered.inverse().to_cols_array_2d(),
            view_proj: (c.projection * c.view).to_cols_array_2d(),
            previous_view_proj: (c.previous_projection * c.previous_view).to_cols_array_2d(),
            depth_plane: (-row).to_array(),
            eye: c.position().extend(1.0).to_array(),
            normal_unpack: [self.normal_encoding.mul, self.normal_encoding.add, 0.0, 0.0],
            params: [
                match self.depth_convention {
                    DepthConvention::Standard => 1.0,
                    DepthConvention::Reversed => 0.0,
                },
                self.motion.map_or(0.0, |m| m.scale[0]),
                self.motion.map_or(0.0, |m| m.scale[1]),
                f32::from(u8::from(channels.roughness_squared)),
            ],
            channels: [
                channels.roughness,
                channels.metallic.unwrap_or(NO_CHANNEL),
                u32::from(self.motion.is_some()),
                0,
            ],
            extent: [display[0], display[1], 0, 0],
        }
    }
}

/// An error naming a bad input.
fn invalid(message: String) -> RenderError {
    RenderError::Invalid(format!("GI dispatch: {message}"))
}

/// Checks that `image` is `display` sized.
fn check_extent(name: &str, image: &HostTarget, display: [u32; 2]) -> Result<(), RenderError> {
    if image.extent != display {
        return Err(invalid(format!(
            "{name} image is {:?}, the context's display size is {display:?}",
            image.extent
        )));
    }
    Ok(())
}
