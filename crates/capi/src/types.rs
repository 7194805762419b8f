//! The C API's plain types: Vulkan handles and enums as the header's own types, and the
//! versioned descriptor structs.

use std::ffi::{c_char, c_void};

/// `VkInstance`.
pub type ShineVkInstance = *mut c_void;
/// `VkPhysicalDevice`.
pub type ShineVkPhysicalDevice = *mut c_void;
/// `VkDevice`.
pub type ShineVkDevice = *mut c_void;
/// `VkQueue`.
pub type ShineVkQueue = *mut c_void;
/// `VkCommandBuffer`.
pub type ShineVkCommandBuffer = *mut c_void;
/// `VkImage`.
pub type ShineVkImage = u64;
/// `VkImageView`.
pub type ShineVkImageView = u64;
/// `VkPipelineCache`.
pub type ShineVkPipelineCache = u64;
/// `PFN_vkVoidFunction`.
pub type ShinePfnVoidFunction = Option<unsafe extern "system" fn()>;
/// `PFN_vkGetInstanceProcAddr`: how shine loads every Vulkan function it calls.
pub type ShinePfnGetInstanceProcAddr =
    Option<unsafe extern "system" fn(ShineVkInstance, *const c_char) -> ShinePfnVoidFunction>;

/// `ShineDeviceDesc::version` of this header.
pub const SHINE_DEVICE_DESC_VERSION: u32 = 1;
/// `ShineContextDesc::version` of this header.
pub const SHINE_CONTEXT_DESC_VERSION: u32 = 2;
/// `ShineDispatchDesc::version` of this header.
pub const SHINE_DISPATCH_DESC_VERSION: u32 = 2;

/// `ShineDispatchDesc::debug_view`: the receivers' normals (needs hvl or proxy).
pub const SHINE_DEBUG_RECEIVER_NORMALS: u32 = 0;
/// The receivers' albedo (needs hvl or proxy).
pub const SHINE_DEBUG_RECEIVER_ALBEDO: u32 = 1;
/// The primary light's reflective shadow map (needs hvl or igi).
pub const SHINE_DEBUG_RSM: u32 = 2;
/// The virtual lights as dots over the dimmed indirect light (needs hvl or igi).
pub const SHINE_DEBUG_LIGHT_POINTS: u32 = 3;
/// AAF's samples per pixel as a heat map (needs aaf).
pub const SHINE_DEBUG_AAF_SAMPLES: u32 = 4;

/// The host's Vulkan objects, lent to shine (`shine_device_create`). The host keeps them
/// alive until the device and every context made on it are destroyed.
#[repr(C)]
pub struct ShineDeviceDesc {
    /// `SHINE_DEVICE_DESC_VERSION`.
    pub version: u32,
    /// The loader's `vkGetInstanceProcAddr`.
    pub get_instance_proc_addr: ShinePfnGetInstanceProcAddr,
    /// The host's instance.
    pub instance: ShineVkInstance,
    /// The physical device `device` was made on.
    pub physical_device: ShineVkPhysicalDevice,
    /// The host's device.
    pub device: ShineVkDevice,
    /// The family of `queue`: graphics, compute and timestamps.
    pub queue_family_index: u32,
    /// A queue shine may submit to at load time (`shine_context_set_scene`,
    /// `shine_context_warm_up`); never during dispatches.
    pub queue: ShineVkQueue,
    /// The `VkDeviceCreateInfo` `device` was created with: shine reads the features (core,
    /// `VkPhysicalDeviceFeatures2`, `VkPhysicalDeviceVulkan13Features`) and extensions it
    /// enabled, and names what is missing. Read during `shine_device_create` only.
    pub device_create_info: *const c_void,
    /// `VkApplicationInfo::apiVersion` of the instance.
    pub api_version: u32,
    /// Nonzero when the instance enabled `VK_EXT_debug_utils` (shine then names and labels
    /// its work).
    pub debug_utils: u32,
    /// The host's pipeline cache (saved by the host), or 0: shine makes its own.
    pub pipeline_cache: ShineVkPipelineCache,
}

/// How a context is made (`shine_context_create`).
#[repr(C)]
pub struct ShineContextDesc {
    /// `SHINE_CONTEXT_DESC_VERSION`.
    pub version: u32,
    /// Width of the host's G-buffer and of the output.
    pub width: u32,
    /// Height of the host's G-buffer and of the output.
    pub height: u32,
    /// How many frames the host records ahead of the GPU (at least 1; 0 is refused).
    pub frames_in_flight: u32,
    /// The technique(s): "hvl", "igi", "aaf", "hvl,proxy" …
    pub technique: *const c_char,
    /// `settings_count` settings as "key=value" (`shine settings` lists them), or null.
    pub settings: *const *const c_char,
    /// How many strings `settings` holds.
    pub settings_count: u32,
    /// The share of each display side the light is computed at, in per cent: 100, 75, 50 or
    /// 25 (0 means 100); the outputs are upsampled to the display (version 2).
    pub internal_percent: u32,
}

/// Layout, stages and accesses of an image's use (Vulkan's `VkImageLayout`,
/// `VkPipelineStageFlags2`, `VkAccessFlags2`).
#[repr(C)]
#[derive(Clone, Copy)]
pub struct ShineImageState {
    /// `VkPipelineStageFlags2`.
    pub stage: u64,
    /// `VkAccessFlags2`.
    pub access: u64,
    /// `VkImageLayout`.
    pub layout: i32,
}

/// One of the host's images: 2D, one mip and layer.
#[repr(C)]
#[derive(Clone, Copy)]
pub struct ShineImage {
    /// The image.
    pub image: ShineVkImage,
    /// A view of all of it (inputs are sampled through it; 0 for an image only blitted to).
    pub view: ShineVkImageView,
    /// `VkFormat`.
    pub format: i32,
    /// Its width, exactly.
    pub width: u32,
    /// Its height, exactly.
    pub height: u32,
    /// `VkImageUsageFlags` it was created with.
    pub usage: u32,
    /// The host's last use before the dispatch.
    pub before: ShineImageState,
    /// The host's next use: the dispatch leaves the image so.
    pub after: ShineImageState,
}

/// The host's camera, column-major 4×4 matrices: world to view (right-handed, looking down
/// −Z) and the unjittered Vulkan projection (y down, depth 0..1), now and the previous frame.
#[repr(C)]
#[derive(Clone, Copy)]
pub struct ShineCamera {
    /// World to view.
    pub view: [f32; 16],
    /// View to clip, unjittered.
    pub projection: [f32; 16],
    /// The previous frame's world to view.
    pub previous_view: [f32; 16],
    /// The previous frame's view to clip.
    pub previous_projection: [f32; 16],
    /// The sub-pixel offset the G-buffer was rasterised with (x right, y down).
    pub jitter: [f32; 2],
}

/// One frame's inputs and output (`shine_context_dispatch`); docs/embedding.md has each
/// field's formats and encodings.
#[repr(C)]
pub struct ShineDispatchDesc {
    /// `SHINE_DISPATCH_DESC_VERSION`.
    pub version: u32,
    /// Strictly increasing; frame `frame_index − frames_in_flight` has completed.
    pub frame_index: u64,
    /// The camera the G-buffer was rasterised with.
    pub camera: ShineCamera,
    /// Depth (D32_SFLOAT, D24_UNORM_S8_UINT, X8_D24_UNORM_PACK32; depth-only view).
    pub depth: ShineImage,
    /// Nonzero for reversed Z (empty pixels hold 0).
    pub depth_reversed: u32,
    /// World-space normals: `n = normalize(texel.xyz · normal_mul + normal_add)`.
    pub normals: ShineImage,
    /// Scale of the normals' decoding (2 for UNORM, 1 for signed formats).
    pub normal_mul: f32,
    /// Offset of the normals' decoding (−1 for UNORM, 0 for signed formats).
    pub normal_add: f32,
    /// Linear base colour.
    pub albedo: ShineImage,
    /// Roughness and metallic.
    pub material: ShineImage,
    /// The channel (0..3) of `material` holding roughness.
    pub roughness_channel: u32,
    /// The channel holding metallic, or −1 (dielectric everywhere).
    pub metallic_channel: i32,
    /// Nonzero when the roughness channel holds α = roughness².
    pub roughness_squared: u32,
    /// Motion vectors, or null.
    pub motion: *const ShineImage,
    /// shine's motion (uv now − uv then) is `texel.xy · motion_scale`.
    pub motion_scale: [f32; 2],
    /// An equirectangular environment map (float format), or null.
    pub environment: *const ShineImage,
    /// Multiplier on the environment's radiance.
    pub environment_intensity: f32,
    /// Output, or null: the indirect light of the GI techniques (diffuse, and glossy lobes
    /// rougher than `specular.limit`), accumulated over frames; with no `specular` output,
    /// the traced reflections too. RGBA16F, `TRANSFER_DST`.
    pub diffuse: *const ShineImage,
    /// Output, or null: the traced reflections of the smoother lobes, denoised in space, not
    /// accumulated. RGBA16F, `TRANSFER_DST`. At least one of `diffuse` and `specular` is
    /// given.
    pub specular: *const ShineImage,
    /// Output, or null: what the GI sees (`debug_view`), display size, the formats of
    /// `diffuse` (version 2).
    pub debug: *const ShineImage,
    /// Which view `debug` shows: a `SHINE_DEBUG_*` (version 2).
    pub debug_view: u32,
}

/// What the host's dispatches will bring (`shine_context_warm_up`).
#[repr(C)]
pub struct ShineDispatchShape {
    /// Nonzero: dispatches bring motion vectors.
    pub motion: u32,
    /// Nonzero: dispatches bring an environment map.
    pub environment: u32,
    /// Nonzero: dispatches ask for a separate specular output.
    pub specular: u32,
}

/// One primitive of a flattened scene.
#[repr(C)]
#[derive(Clone, Copy)]
pub struct ShineDraw {
    /// First index in `ShineGeometry::indices`.
    pub first_index: u32,
    /// Number of indices.
    pub index_count: u32,
    /// Linear base colour.
    pub base_color: [f32; 3],
    /// Perceptual roughness.
    pub roughness: f32,
    /// Metalness.
    pub metallic: f32,
    /// Emitted radiance.
    pub emissive: [f32; 3],
    /// Nonzero: both faces reflect.
    pub double_sided: u32,
}

/// A scene's meshes in world space (`shine_scene_flatten`); the arrays belong to the scene
/// and stay valid until its next flattening or its destruction.
#[repr(C)]
pub struct ShineGeometry {
    /// Number of vertices.
    pub vertex_count: u32,
    /// 6 floats per vertex: world position xyz, world normal xyz.
    pub vertices: *const f32,
    /// Number of indices (a triangle list).
    pub index_count: u32,
    /// The indices.
    pub indices: *const u32,
    /// Number of draws.
    pub draw_count: u32,
    /// One draw per primitive.
    pub draws: *const ShineDraw,
}
