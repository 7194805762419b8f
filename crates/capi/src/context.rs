//! `shine_context_*`: the GI context's life and frames, each a thin wrapper of the Rust
//! [`GiContext`] call of the same name.

use crate::device;
use crate::error::{Failure, ShineResult, call};
use crate::handles::{self, ShineContext, ShineDevice, ShineScene, lock};
use crate::scene::string;
use crate::types::{
    SHINE_CONTEXT_DESC_VERSION, SHINE_DEBUG_AAF_SAMPLES, SHINE_DEBUG_LIGHT_POINTS,
    SHINE_DEBUG_RECEIVER_ALBEDO, SHINE_DEBUG_RECEIVER_NORMALS, SHINE_DEBUG_RSM,
    SHINE_DISPATCH_DESC_VERSION, ShineCamera, ShineContextDesc, ShineDispatchDesc,
    ShineDispatchShape, ShineImage, ShineImageState, ShineVkCommandBuffer,
};
use glam::Mat4;
use shine::embed::{
    DebugView, DepthConvention, DispatchShape, ExternalState, FrameUpdate, GiCamera, GiContext,
    GiContextDesc, GiDispatch, HostEnvironment, HostMotion, HostTarget, InternalResolution,
    MaterialChannels, NormalEncoding,
};
use shine::gpu::vk::{self, Handle};

/// Makes a context on `device` and writes its handle to `out` (null on failure).
///
/// # Safety
/// `desc` is null or a valid `ShineContextDesc` (its strings NUL-terminated); `out` is null or
/// writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn shine_context_create(
    device: ShineDevice,
    desc: *const ShineContextDesc,
    out: *mut ShineContext,
) -> ShineResult {
    call(|| {
        let device = device::lookup(device)?;
        // SAFETY: the caller's promise.
        let (desc, out) = unsafe { (desc.as_ref(), out.as_mut()) };
        let (desc, out) = desc
            .zip(out)
            .ok_or_else(|| Failure::invalid("desc and out must not be null"))?;
        *out = std::ptr::null_mut();
        if desc.version != SHINE_CONTEXT_DESC_VERSION {
            return Err(Failure::new(
                ShineResult::ErrorVersionMismatch,
                format!(
                    "ShineContextDesc version {} (this library reads version \
                     {SHINE_CONTEXT_DESC_VERSION})",
                    desc.version
                ),
            ));
        }
        // SAFETY: the caller's promise.
        let technique = unsafe { string(desc.technique, "technique") }?;
        let mut rust = GiContextDesc::new([desc.width, desc.height], &technique)?;
        if desc.frames_in_flight == 0 {
            return Err(Failure::invalid("frames_in_flight must be at least 1"));
        }
        rust.frames_in_flight = desc.frames_in_flight as usize;
        rust.internal_resolution = match desc.internal_percent {
            0 => InternalResolution::Full,
            percent => InternalResolution::from_percent(percent)?,
        };
        if desc.settings_count > 0 && desc.settings.is_null() {
            return Err(Failure::invalid(
                "settings is null with a nonzero settings_count",
            ));
        }
        for i in 0..desc.settings_count as usize {
            // SAFETY: `settings_count` strings (the caller's promise).
            let setting = unsafe { string(*desc.settings.add(i), "a setting") }?;
            let (key, value) = setting
                .split_once('=')
                .ok_or_else(|| Failure::invalid(format!("setting `{setting}` is not key=value")))?;
            rust.settings
                .set(key.trim(), value.trim())
                .map_err(|e| Failure::invalid(format!("setting `{setting}`: {e}")))?;
        }
        *out = handles::add_context(GiContext::new(&device, &rust)?);
        Ok(())
    })
}

/// Hands the context `scene` posed at time `t` (uploads and waits: a load-time call).
///
/// # Safety
/// Handles may be any value (null and stale ones are refused).
#[unsafe(no_mangle)]
pub unsafe extern "C" fn shine_context_set_scene(
    context: ShineContext,
    scene: ShineScene,
    t: f32,
) -> ShineResult {
    call(|| {
        let context = handles::context(context)?;
        let scene = handles::scene(scene)?;
        let scene = lock(&scene);
        Ok(lock(&context).set_scene(&scene.scene, t)?)
    })
}

/// Builds everything the host's frames need before the first (no first-dispatch hitch):
/// submits placeholder frames on the device's queue and waits. `shape` null: neither motion
/// nor an environment.
///
/// # Safety
/// `shape` is null or valid.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn shine_context_warm_up(
    context: ShineContext,
    shape: *const ShineDispatchShape,
) -> ShineResult {
    call(|| {
        let context = handles::context(context)?;
        // SAFETY: the caller's promise.
        let shape = unsafe { shape.as_ref() }.map_or(DispatchShape::default(), |s| DispatchShape {
            motion: s.motion != 0,
            environment: s.environment != 0,
            specular: s.specular != 0,
        });
        Ok(lock(&context).warm_up(shape)?)
    })
}

/// Starts every history over (a camera cut): the next dispatch is computed as a first frame.
///
/// # Safety
/// `context` may be any value (null and stale handles are refused).
#[unsafe(no_mangle)]
pub unsafe extern "C" fn shine_context_reset_history(context: ShineContext) -> ShineResult {
    call(|| {
        let context = handles::context(context)?;
        lock(&context).reset_history();
        Ok(())
    })
}

/// Sets the scene's clock for the next dispatch: every animation of a loaded scene (nodes,
/// lights, morph weights, skins) is evaluated at `time` seconds (`GiContext::update` with
/// `FrameUpdate::at(time)`). It replaces the whole frame state: on a world of registered
/// meshes it puts the instances and lights back where `shine_context_set_instances` put them,
/// so such a host moves things with `shine_context_move_instances` instead. CPU only, per
/// frame. A non-finite time is refused.
///
/// # Safety
/// `context` may be any value (null and stale handles are refused).
#[unsafe(no_mangle)]
pub unsafe extern "C" fn shine_context_set_time(context: ShineContext, time: f32) -> ShineResult {
    call(|| {
        let context = handles::context(context)?;
        Ok(lock(&context).update(&FrameUpdate::at(time))?)
    })
}

/// Records one frame into `command_buffer` (recording, outside a render pass): never submits
/// or waits. After an error nothing usable was recorded: do not submit the command buffer.
///
/// # Safety
/// `command_buffer` is a command buffer of the context's device in the recording state;
/// `desc` is null or valid, its images live until the submission completes.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn shine_context_dispatch(
    context: ShineContext,
    command_buffer: ShineVkCommandBuffer,
    desc: *const ShineDispatchDesc,
) -> ShineResult {
    call(|| {
        let context = handles::context(context)?;
        if command_buffer.is_null() {
            return Err(Failure::invalid("command_buffer is null"));
        }
        // SAFETY: the caller's promise.
        let desc = unsafe { desc.as_ref() }.ok_or_else(|| Failure::invalid("desc is null"))?;
        // SAFETY: as above.
        let dispatch = unsafe { dispatch(desc) }?;
        let cb = vk::CommandBuffer::from_raw(command_buffer as u64);
        Ok(lock(&context).dispatch(cb, &dispatch)?)
    })
}

/// Destroys the context. The host's submissions that used it must have completed.
///
/// # Safety
/// `context` may be any value (null and stale handles are refused).
#[unsafe(no_mangle)]
pub unsafe extern "C" fn shine_context_destroy(context: ShineContext) -> ShineResult {
    call(|| handles::remove(context, "context"))
}

/// The Rust dispatch of a C one.
///
/// # Safety
/// `motion`, `environment`, `diffuse` and `specular` are null or valid.
unsafe fn dispatch(d: &ShineDispatchDesc) -> Result<GiDispatch, Failure> {
    if d.version != SHINE_DISPATCH_DESC_VERSION {
        return Err(Failure::new(
            ShineResult::ErrorVersionMismatch,
            format!(
                "ShineDispatchDesc version {} (this library reads version \
                 {SHINE_DISPATCH_DESC_VERSION})",
                d.version
            ),
        ));
    }
    let channel = |c: i32| u32::try_from(c).ok();
    if d.metallic_channel < -1 {
        return Err(Failure::invalid(format!(
            "metallic_channel {} is neither −1 nor a channel",
            d.metallic_channel
        )));
    }
    // SAFETY: the caller's promise.
    let (motion, environment, diffuse, specular, debug) = unsafe {
        (
            d.motion.as_ref(),
            d.environment.as_ref(),
            d.diffuse.as_ref(),
            d.specular.as_ref(),
            d.debug.as_ref(),
        )
    };
    let debug_view = match d.debug_view {
        SHINE_DEBUG_RECEIVER_NORMALS => DebugView::ReceiverNormals,
        SHINE_DEBUG_RECEIVER_ALBEDO => DebugView::ReceiverAlbedo,
        SHINE_DEBUG_RSM => DebugView::Rsm,
        SHINE_DEBUG_LIGHT_POINTS => DebugView::LightPoints,
        SHINE_DEBUG_AAF_SAMPLES => DebugView::AafSamples,
        other => return Err(Failure::invalid(format!("debug_view {other}"))),
    };
    Ok(GiDispatch {
        frame_index: d.frame_index,
        camera: camera(&d.camera),
        depth: target(&d.depth),
        depth_convention: if d.depth_reversed != 0 {
            DepthConvention::Reversed
        } else {
            DepthConvention::Standard
        },
        normals: target(&d.normals),
        normal_encoding: NormalEncoding {
            mul: d.normal_mul,
            add: d.normal_add,
        },
        albedo: target(&d.albedo),
        material: target(&d.material),
        material_channels: MaterialChannels {
            roughness: d.roughness_channel,
            metallic: channel(d.metallic_channel),
            roughness_squared: d.roughness_squared != 0,
        },
        motion: motion.map(|m| HostMotion {
            image: target(m),
            scale: d.motion_scale,
        }),
        environment: environment.map(|e| HostEnvironment {
            image: target(e),
            intensity: d.environment_intensity,
        }),
        diffuse: diffuse.map(target),
        specular: specular.map(target),
        debug: debug.map(target),
        debug_view,
    })
}

/// The Rust camera of a C one.
fn camera(c: &ShineCamera) -> GiCamera {
    GiCamera {
        view: Mat4::from_cols_array(&c.view),
        projection: Mat4::from_cols_array(&c.projection),
        jitter: c.jitter,
        previous_view: Mat4::from_cols_array(&c.previous_view),
        previous_projection: Mat4::from_cols_array(&c.previous_projection),
    }
}

/// The Rust image of a C one.
fn target(i: &ShineImage) -> HostTarget {
    HostTarget {
        image: vk::Image::from_raw(i.image),
        view: vk::ImageView::from_raw(i.view),
        format: vk::Format::from_raw(i.format),
        extent: [i.width, i.height],
        usage: vk::ImageUsageFlags::from_raw(i.usage),
        before: state(i.before),
        after: state(i.after),
    }
}

/// The Rust image state of a C one.
fn state(s: ShineImageState) -> ExternalState {
    ExternalState::new(
        vk::PipelineStageFlags2::from_raw(s.stage),
        vk::AccessFlags2::from_raw(s.access),
        vk::ImageLayout::from_raw(s.layout),
    )
}

/// Device memory a context holds, by category, in bytes (`shine_context_memory_report`).
#[repr(C)]
pub struct ShineMemoryReport {
    /// Geometry, materials, textures, lights, the BVH.
    pub scene: u64,
    /// The techniques' persistent tables and caches.
    pub gi_caches: u64,
    /// Per-frame records kept on the device.
    pub frame_data: u64,
    /// Host-visible staging rings.
    pub staging: u64,
    /// The render graph's aliased transient heaps.
    pub transients: u64,
    /// Histories and temporal images kept across frames.
    pub history: u64,
    /// Objects waiting for the GPU to finish with them.
    pub pending_release: u64,
}

/// Changes the display size after a swapchain resize: the next dispatch takes images of
/// `width`×`height`; histories start over. Nothing waits (warm up again to avoid the next
/// frame building its plan and memory).
///
/// # Safety
/// `context` may be any value (null and stale handles are refused).
#[unsafe(no_mangle)]
pub unsafe extern "C" fn shine_context_resize(
    context: ShineContext,
    width: u32,
    height: u32,
) -> ShineResult {
    call(|| {
        let context = handles::context(context)?;
        Ok(lock(&context).resize([width, height])?)
    })
}

/// Writes the device memory the context holds, by category, to `out`.
///
/// # Safety
/// `out` is null or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn shine_context_memory_report(
    context: ShineContext,
    out: *mut ShineMemoryReport,
) -> ShineResult {
    call(|| {
        let context = handles::context(context)?;
        // SAFETY: the caller's promise.
        let out = unsafe { out.as_mut() }.ok_or_else(|| Failure::invalid("out is null"))?;
        let r = lock(&context).memory_report();
        *out = ShineMemoryReport {
            scene: r.scene,
            gi_caches: r.gi_caches,
            frame_data: r.frame_data,
            staging: r.staging,
            transients: r.transients,
            history: r.history,
            pending_release: r.pending_release,
        };
        Ok(())
    })
}
