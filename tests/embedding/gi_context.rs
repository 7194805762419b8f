//! The GI context (`shine::embed`) driven by a host engine that rasterises its own G-buffer
//! with its own pipeline into its own images (examples/host_gbuffer/host.rs), validation on.

use super::host::{self, HostDevice, HostScene, Raster, Targets};
use glam::Mat4;
use shine::embed::{GiCamera, GiContext, GiContextDesc, GiDispatch, MaterialChannels};
use shine::gpu::{Device, vk};
use shine::graph::ExternalState;
use shine::passes::composite::Component;
use shine::study::metrics::image_error;
use shine::{CameraPose, FrameUpdate, Renderer, Settings};
use shine_scene::Scene;
use std::sync::atomic::Ordering;

/// Test image size.
pub const EXTENT: [u32; 2] = [64, 64];
/// Radians the camera turns per frame in the moving-camera tests.
const ORBIT: f32 = 0.04;

/// A host with the cornell box, its G-buffer pipeline and targets, and shine's device on it.
pub struct Bench {
    pub scene: Scene,
    host_scene: Option<HostScene>,
    raster: Option<Raster>,
    targets: Option<Targets>,
    device: Option<Device>,
    /// Last: dropped after every object above (the documented teardown order).
    pub host: HostDevice,
}

impl Bench {
    pub fn new(share_allocator: bool) -> Self {
        Self::with_device(share_allocator, |raw| raw)
    }

    /// A bench whose host draws the built-in scene `name`.
    pub fn for_scene(name: &str) -> Self {
        Self::build(false, name, |raw| raw)
    }

    /// A bench whose shine device is `wrap` of what the host lends.
    fn with_device(
        share_allocator: bool,
        wrap: impl FnOnce(shine::gpu::RawDevice) -> shine::gpu::RawDevice,
    ) -> Self {
        Self::build(share_allocator, "cornell-box", wrap)
    }

    /// A bench drawing the built-in `scene_name`, whose shine device is `wrap` of what the
    /// host lends.
    fn build(
        share_allocator: bool,
        scene_name: &str,
        wrap: impl FnOnce(shine::gpu::RawDevice) -> shine::gpu::RawDevice,
    ) -> Self {
        let host = HostDevice::new(true).expect("host device");
        assert!(
            host.validation || std::env::var_os("CI").is_none(),
            "CI needs the validation layer"
        );
        let scene = Scene::builtin(scene_name).expect("scene");
        let device = Device::from_raw(wrap(host.lend(share_allocator))).expect("shine device");
        Self {
            host_scene: Some(HostScene::new(&host, &scene).expect("host scene")),
            raster: Some(Raster::new(&host).expect("raster")),
            targets: Some(Targets::new(&host, EXTENT).expect("targets")),
            device: Some(device),
            scene,
            host,
        }
    }

    pub fn device(&self) -> &Device {
        self.device.as_ref().expect("device")
    }

    /// Rebuilds the host's geometry with the scene posed by `update` (its node overrides),
    /// as a host moving an instance does; the previous frame must have completed.
    pub fn pose(&mut self, update: &FrameUpdate) {
        let world = shine::gpu_scene::FrameState::evaluate(&self.scene, update)
            .pose
            .world;
        if let Some(old) = self.host_scene.take() {
            old.destroy(&self.host);
        }
        self.host_scene =
            Some(HostScene::posed(&self.host, &self.scene, &world).expect("host scene"));
    }

    /// The host's copy of the scene's geometry.
    pub fn host_scene(&self) -> &HostScene {
        self.host_scene.as_ref().expect("host scene")
    }

    pub fn targets(&self) -> &Targets {
        self.targets.as_ref().expect("targets")
    }

    /// A context for `technique` with the scene set.
    pub fn context(&self, technique: &str) -> GiContext {
        let mut gi =
            GiContext::new(self.device(), &exact_desc(EXTENT, technique)).expect("context");
        gi.set_scene(&self.scene, 0.0).expect("scene");
        gi
    }

    /// The camera of frame `k` (turned by `k · ORBIT`) and the previous frame's.
    pub fn camera(&self, k: u32) -> GiCamera {
        let (view, projection) = host::camera(&self.scene, EXTENT, k as f32 * ORBIT);
        let (previous_view, previous_projection) =
            host::camera(&self.scene, EXTENT, k.saturating_sub(1) as f32 * ORBIT);
        GiCamera {
            view,
            projection,
            jitter: [0.0; 2],
            previous_view,
            previous_projection,
        }
    }

    /// Records the host's G-buffer of frame `k` into `cb` and returns the dispatch of it.
    fn record_gbuffer(&self, cb: vk::CommandBuffer, k: u32) -> GiDispatch {
        self.record_gbuffer_from(cb, u64::from(k), self.camera(k))
    }

    /// Records the host's G-buffer seen from `camera` into `cb` and returns the dispatch of
    /// it as frame `frame_index`.
    pub fn record_gbuffer_from(
        &self,
        cb: vk::CommandBuffer,
        frame_index: u64,
        camera: GiCamera,
    ) -> GiDispatch {
        let t = self.targets();
        self.raster.as_ref().expect("raster").record(
            &self.host,
            cb,
            t,
            self.host_scene.as_ref().expect("scene"),
            camera.projection * camera.view,
        );
        t.dispatch(frame_index, camera)
    }

    /// Frames `frames` through `gi`, each in one host submission; the GI image of the last.
    pub fn run(&self, gi: &mut GiContext, frames: std::ops::Range<u32>) -> Vec<[f32; 3]> {
        for k in frames {
            let cb = self.host.begin().expect("begin");
            let dispatch = self.record_gbuffer(cb, k);
            gi.dispatch(cb, &dispatch).expect("dispatch");
            self.host.submit_and_wait(cb).expect("submit");
        }
        rgb(host::read_rgba16f(&self.host, &self.targets().gi, host::copy_source()).expect("read"))
    }

    /// Frame `k` through `gi` from the still camera of frame 0 (the scene's own), in one host
    /// submission; the GI image.
    pub fn run_still(&self, gi: &mut GiContext, k: u32) -> Vec<[f32; 3]> {
        let cb = self.host.begin().expect("begin");
        let dispatch = self.record_gbuffer_from(cb, u64::from(k), self.camera(0));
        gi.dispatch(cb, &dispatch).expect("dispatch");
        self.host.submit_and_wait(cb).expect("submit");
        rgb(host::read_rgba16f(&self.host, &self.targets().gi, host::copy_source()).expect("read"))
    }

    /// The full renderer's indirect light at frame `k`'s camera, after frames 0 to k - 1 at
    /// theirs (its history, like the context's, has seen them).
    fn full_renderer(&self, technique: &str, k: u32) -> Vec<[f32; 3]> {
        let mut renderer = Renderer::new(self.device()).expect("renderer");
        renderer.set_scene(&self.scene, 0.0).expect("scene");
        let projection = self.scene.cameras[0].projection;
        let mut settings = Settings {
            width: EXTENT[0],
            height: EXTENT[1],
            gi: technique.parse().expect("technique"),
            ..Settings::default()
        };
        settings.output.component = Component::Indirect;
        settings.output.exposure = 1.0;
        settings.hvl.shadow_rays = 0;
        settings.hvl.near_range = 0.0;
        let mut last = Vec::new();
        for frame in 0..=k {
            renderer
                .update(&FrameUpdate {
                    camera: Some(CameraPose {
                        world: self.camera(frame).view.inverse(),
                        projection,
                    }),
                    ..FrameUpdate::default()
                })
                .expect("update");
            last = rgb(renderer.render(&settings).expect("render").hdr.texels);
        }
        last
    }

    /// Zero validation messages so far (the host's messenger sees shine's calls too).
    pub fn assert_clean(&self) {
        assert_eq!(host::VALIDATION_MESSAGES.load(Ordering::Relaxed), 0);
    }
}

impl Drop for Bench {
    fn drop(&mut self) {
        // The documented teardown: the host's submissions are complete (each was waited
        // for), shine's device goes, then the host's own objects, then the host's device.
        self.device.take();
        if let Some(t) = self.targets.take() {
            t.destroy(&self.host);
        }
        if let Some(r) = self.raster.take() {
            r.destroy(&self.host);
        }
        if let Some(s) = self.host_scene.take() {
            s.destroy(&self.host);
        }
    }
}

pub fn rgb(texels: Vec<[f32; 4]>) -> Vec<[f32; 3]> {
    texels.into_iter().map(|t| [t[0], t[1], t[2]]).collect()
}

/// Relative RMSE and energy ratio of `image` against `truth` over every pixel.
pub fn error_of(image: &[[f32; 3]], truth: &[[f32; 3]]) -> (f64, f64) {
    let e = image_error(image, truth, &vec![true; truth.len()]).expect("signal");
    (e.relative_rmse, e.energy_ratio)
}

/// The context's output for a host G-buffer matches the full renderer's indirect light from
/// its own G-buffer, same scene and camera. They differ only in the G-buffer's encoding: the
/// host stores normals in 10-bit UNORM, albedo as 8-bit sRGB, and positions come back from
/// depth. Tolerance: relative RMSE ≤ 3 %, energy within 1 %.
#[test]
fn gi_context_matches_the_full_renderer() {
    let bench = Bench::new(false);
    for technique in ["hvl", "igi"] {
        let mut gi = bench.context(technique);
        let output = bench.run(&mut gi, 0..1);
        let truth = bench.full_renderer(technique, 0);
        let (relative_rmse, energy) = error_of(&output, &truth);
        println!("{technique}: relative RMSE {relative_rmse:.4}, energy {energy:.4}");
        assert!(
            relative_rmse <= 0.03,
            "{technique}: relative RMSE {relative_rmse}"
        );
        assert!((energy - 1.0).abs() <= 0.01, "{technique}: energy {energy}");
    }
    bench.assert_clean();
}

/// Five frames of a turning camera: every frame's output matches the full renderer's same
/// sequence at that camera (the indirect light's history reprojects through the camera motion
/// the context derives from the host's matrices, as the full renderer's through its own).
#[test]
fn moving_camera_frames_follow_the_camera() {
    let bench = Bench::new(false);
    let mut gi = bench.context("hvl");
    let mut previous: Option<Vec<[f32; 3]>> = None;
    for k in 0..5 {
        let output = bench.run(&mut gi, k..k + 1);
        let (relative_rmse, energy) = error_of(&output, &bench.full_renderer("hvl", k));
        println!("frame {k}: relative RMSE {relative_rmse:.4}, energy {energy:.4}");
        assert!(relative_rmse <= 0.05 && (energy - 1.0).abs() <= 0.02);
        if let Some(p) = &previous {
            assert_ne!(p, &output, "frame {k} did not change with the camera");
        }
        previous = Some(output);
    }
    bench.assert_clean();
}

/// A resize: the context takes images of the new size, and its output there matches a
/// context made at that size.
#[test]
fn resize_gives_what_a_new_context_gives() {
    let mut bench = Bench::new(false);
    let mut gi = bench.context("hvl");
    bench.run(&mut gi, 0..2);
    let small = [48, 40];
    let old = bench
        .targets
        .replace(Targets::new(&bench.host, small).expect("targets"));
    old.expect("targets").destroy(&bench.host);
    let resized_at = small;
    gi.resize(resized_at).expect("resize");
    assert_eq!(gi.display(), small);
    let dispatch_small = |gi: &mut GiContext, k: u32| {
        let cb = bench.host.begin().expect("begin");
        let mut d = bench.record_gbuffer(cb, k);
        d.camera = GiCamera::still(d.camera.view, d.camera.projection);
        gi.dispatch(cb, &d).expect("dispatch");
        bench.host.submit_and_wait(cb).expect("submit");
        rgb(
            host::read_rgba16f(&bench.host, &bench.targets().gi, host::copy_source())
                .expect("read"),
        )
    };
    let resized = dispatch_small(&mut gi, 2);
    let mut fresh = GiContext::new(bench.device(), &exact_desc(small, "hvl")).expect("context");
    fresh.set_scene(&bench.scene, 0.0).expect("scene");
    let made = dispatch_small(&mut fresh, 2);
    assert_eq!(resized.len(), (small[0] * small[1]) as usize);
    assert_eq!(resized, made);
    // A dispatch of the old size is refused, with a message naming both sizes.
    let cb = bench.host.begin().expect("begin");
    let mut d = bench.record_gbuffer(cb, 3);
    d.depth.extent = EXTENT;
    let error = gi.dispatch(cb, &d).expect_err("old size").to_string();
    assert!(
        error.contains("[64, 64]") && error.contains("[48, 40]"),
        "{error}"
    );
    bench.host.submit_and_wait(cb).expect("submit");
    bench.assert_clean();
}

/// Two contexts on one device, dispatched into one command buffer, give what each gives
/// alone.
#[test]
fn two_contexts_share_a_device() {
    let bench = Bench::new(false);
    let alone = |technique| {
        let mut gi = bench.context(technique);
        bench.run(&mut gi, 0..1)
    };
    let (hvl_alone, igi_alone) = (alone("hvl"), alone("igi"));
    let mut hvl = bench.context("hvl");
    let mut igi = bench.context("igi");
    let cb = bench.host.begin().expect("begin");
    let d = bench.record_gbuffer(cb, 0);
    hvl.dispatch(cb, &d).expect("hvl");
    let hvl_image = host::HostImage::new(
        &bench.host,
        "second gi",
        bench.targets().gi.format,
        EXTENT,
        vk::ImageUsageFlags::TRANSFER_DST
            | vk::ImageUsageFlags::TRANSFER_SRC
            | vk::ImageUsageFlags::SAMPLED,
    )
    .expect("image");
    // The second context reads the same G-buffer (left by the first in `sampled_after`) and
    // writes its own output.
    let read = |i: &host::HostImage| i.lend(host::sampled_after(), host::sampled_after());
    let t = bench.targets();
    let second = GiDispatch {
        depth: read(&t.depth),
        normals: read(&t.normal),
        albedo: read(&t.albedo),
        material: read(&t.material),
        diffuse: Some(hvl_image.lend(ExternalState::UNDEFINED, host::copy_source())),
        specular: None,
        ..d
    };
    igi.dispatch(cb, &second).expect("igi");
    bench.host.submit_and_wait(cb).expect("submit");
    let hvl_out = rgb(host::read_rgba16f(&bench.host, &t.gi, host::copy_source()).expect("read"));
    let igi_out =
        rgb(host::read_rgba16f(&bench.host, &hvl_image, host::copy_source()).expect("read"));
    hvl_image.destroy(&bench.host);
    assert_eq!(hvl_out, hvl_alone);
    assert_eq!(igi_out, igi_alone);
    bench.assert_clean();
}

/// shine allocates from the host's allocator when handed it, and gives every byte back.
#[test]
fn host_allocator_holds_shine_memory_until_teardown() {
    let bench = Bench::new(true);
    let host_only = bench
        .host
        .allocator()
        .lock()
        .expect("lock")
        .generate_report()
        .total_allocated_bytes;
    let mut gi = bench.context("hvl");
    bench.run(&mut gi, 0..2);
    let with_shine = bench
        .host
        .allocator()
        .lock()
        .expect("lock")
        .generate_report()
        .total_allocated_bytes;
    let shine_bytes = bench.device().memory_usage().allocated_bytes;
    assert!(shine_bytes > 0);
    assert!(
        with_shine >= host_only + shine_bytes,
        "host allocator {with_shine} B, host alone {host_only} B, shine {shine_bytes} B"
    );
    drop(gi);
    let mut bench = bench;
    bench.device.take();
    let after = bench
        .host
        .allocator()
        .lock()
        .expect("lock")
        .generate_report()
        .total_allocated_bytes;
    assert_eq!(
        after, host_only,
        "shine left memory in the host's allocator"
    );
}

/// Host matrices that are not invertible are refused before anything is recorded.
#[test]
fn bad_dispatches_are_refused() {
    let bench = Bench::new(false);
    let mut gi = bench.context("hvl");
    let cb = bench.host.begin().expect("begin");
    let good = bench.record_gbuffer(cb, 0);
    let cases = [
        GiDispatch {
            camera: GiCamera::still(Mat4::ZERO, good.camera.projection),
            ..good
        },
        GiDispatch {
            material_channels: MaterialChannels {
                roughness: 7,
                ..MaterialChannels::default()
            },
            ..good
        },
        GiDispatch {
            diffuse: Some(host::HostImage::lend(
                &bench.targets().depth,
                ExternalState::UNDEFINED,
                ExternalState::UNDEFINED,
            )),
            ..good
        },
        GiDispatch {
            diffuse: None,
            specular: None,
            ..good
        },
    ];
    for case in &cases {
        let error = gi.dispatch(cb, case).expect_err("refused").to_string();
        assert!(
            error.starts_with("GI dispatch:") || error.contains("GI dispatch"),
            "{error}"
        );
    }
    gi.dispatch(cb, &good).expect("good");
    let error = gi
        .dispatch(cb, &good)
        .expect_err("same frame twice")
        .to_string();
    assert!(error.contains("must increase"), "{error}");
    bench.host.submit_and_wait(cb).expect("submit");
    bench.assert_clean();
}

/// Queue submissions and waits made through the counting device of
/// [`dispatches_neither_submit_nor_wait`].
static SUBMITS: std::sync::atomic::AtomicU32 = std::sync::atomic::AtomicU32::new(0);
static WAITS: std::sync::atomic::AtomicU32 = std::sync::atomic::AtomicU32::new(0);
/// The real functions behind the counting ones.
static REAL: std::sync::OnceLock<(ash::DeviceFnV1_0, ash::DeviceFnV1_3)> =
    std::sync::OnceLock::new();

use shine::gpu::ash;

unsafe extern "system" fn count_submit(
    queue: vk::Queue,
    count: u32,
    submits: *const vk::SubmitInfo<'_>,
    fence: vk::Fence,
) -> vk::Result {
    SUBMITS.fetch_add(1, Ordering::SeqCst);
    // SAFETY: forwards the caller's arguments to the driver's function.
    unsafe { (REAL.get().expect("real").0.queue_submit)(queue, count, submits, fence) }
}

unsafe extern "system" fn count_submit2(
    queue: vk::Queue,
    count: u32,
    submits: *const vk::SubmitInfo2<'_>,
    fence: vk::Fence,
) -> vk::Result {
    SUBMITS.fetch_add(1, Ordering::SeqCst);
    // SAFETY: as above.
    unsafe { (REAL.get().expect("real").1.queue_submit2)(queue, count, submits, fence) }
}

unsafe extern "system" fn count_queue_wait(queue: vk::Queue) -> vk::Result {
    WAITS.fetch_add(1, Ordering::SeqCst);
    // SAFETY: as above.
    unsafe { (REAL.get().expect("real").0.queue_wait_idle)(queue) }
}

unsafe extern "system" fn count_device_wait(device: vk::Device) -> vk::Result {
    WAITS.fetch_add(1, Ordering::SeqCst);
    // SAFETY: as above.
    unsafe { (REAL.get().expect("real").0.device_wait_idle)(device) }
}

unsafe extern "system" fn count_fence_wait(
    device: vk::Device,
    count: u32,
    fences: *const vk::Fence,
    all: vk::Bool32,
    timeout: u64,
) -> vk::Result {
    WAITS.fetch_add(1, Ordering::SeqCst);
    // SAFETY: as above.
    unsafe { (REAL.get().expect("real").0.wait_for_fences)(device, count, fences, all, timeout) }
}

/// The host's device with every submit and wait entry point counted.
fn counting(mut raw: shine::gpu::RawDevice) -> shine::gpu::RawDevice {
    let d = &raw.device;
    let _ = REAL.set((d.fp_v1_0().clone(), d.fp_v1_3().clone()));
    let mut f10 = d.fp_v1_0().clone();
    f10.queue_submit = count_submit;
    f10.queue_wait_idle = count_queue_wait;
    f10.device_wait_idle = count_device_wait;
    f10.wait_for_fences = count_fence_wait;
    let mut f13 = d.fp_v1_3().clone();
    f13.queue_submit2 = count_submit2;
    raw.device = ash::Device::from_parts_1_3(
        d.handle(),
        f10,
        d.fp_v1_1().clone(),
        d.fp_v1_2().clone(),
        f13,
    );
    raw
}

/// Ten dispatches of a moving camera (the first one uploading the BRDF tables), then ten
/// full frames recorded with `Renderer::record`: shine submits nothing and waits for nothing;
/// the host submits every frame itself.
#[test]
fn dispatches_neither_submit_nor_wait() {
    let bench = Bench::with_device(false, counting);
    let mut gi = bench.context("hvl");
    let mut renderer = Renderer::new(bench.device()).expect("renderer");
    renderer.set_scene(&bench.scene, 0.0).expect("scene");
    for k in 0..10 {
        let cb = bench.host.begin().expect("begin");
        let dispatch = bench.record_gbuffer(cb, k);
        let before = (SUBMITS.load(Ordering::SeqCst), WAITS.load(Ordering::SeqCst));
        gi.dispatch(cb, &dispatch).expect("dispatch");
        let after = (SUBMITS.load(Ordering::SeqCst), WAITS.load(Ordering::SeqCst));
        assert_eq!(
            before, after,
            "dispatch {k}: (submits, waits) before and after"
        );
        bench.host.submit_and_wait(cb).expect("submit");
    }
    let settings = Settings {
        width: EXTENT[0],
        height: EXTENT[1],
        ..Settings::default()
    };
    for k in 0..10u32 {
        let cb = bench.host.begin().expect("begin");
        let before = (SUBMITS.load(Ordering::SeqCst), WAITS.load(Ordering::SeqCst));
        renderer
            .record(
                cb,
                u64::from(k),
                &bench
                    .targets()
                    .gi
                    .lend(ExternalState::UNDEFINED, host::copy_source()),
                &settings,
            )
            .expect("record");
        let after = (SUBMITS.load(Ordering::SeqCst), WAITS.load(Ordering::SeqCst));
        assert_eq!(
            before, after,
            "record {k}: (submits, waits) before and after"
        );
        bench.host.submit_and_wait(cb).expect("submit");
    }
    bench.assert_clean();
}

/// A host that did not enable synchronization2 gets an error naming it.
#[test]
fn missing_host_features_are_named() {
    let host = HostDevice::new(false).expect("host device");
    let mut raw = host.lend(false);
    raw.enabled = shine::gpu::EnabledFeatures::from_parts(
        vk::API_VERSION_1_3,
        &vk::PhysicalDeviceFeatures::default(),
        &vk::PhysicalDeviceVulkan13Features::default().dynamic_rendering(true),
        &[],
    );
    let error = Device::from_raw(raw).expect_err("refused").to_string();
    assert!(
        error.contains("synchronization2") && error.contains("not enabled by the host"),
        "{error}"
    );
    assert!(!error.contains("dynamicRendering"), "{error}");
}

/// The memory report's categories add up to every byte shine holds on the device, and each
/// category a HVL context needs is there.
#[test]
fn memory_report_accounts_for_every_byte() {
    let bench = Bench::new(false);
    // Amortised HVL keeps a history across frames.
    let mut desc = GiContextDesc::new(EXTENT, "hvl").expect("desc");
    desc.settings.hvl.slices = 4;
    let mut gi = GiContext::new(bench.device(), &desc).expect("context");
    gi.set_scene(&bench.scene, 0.0).expect("scene");
    bench.run(&mut gi, 0..3);
    let report = gi.memory_report();
    let usage = bench.device().memory_usage();
    println!("{report:?}, device {usage:?}");
    assert_eq!(report.total(), usage.allocated_bytes, "{report:?}");
    for (name, bytes) in [
        ("scene", report.scene),
        ("gi caches", report.gi_caches),
        ("frame data", report.frame_data),
        ("staging", report.staging),
        ("transients", report.transients),
        ("history", report.history),
    ] {
        assert!(bytes > 0, "{name} is empty: {report:?}");
    }
}

/// The documented teardown (host submissions complete → context → shine's device → the
/// host's images, pipeline and buffers → the host's device) leaves the validation layer
/// nothing to report: no object of shine's outlives its device.
#[test]
fn teardown_in_the_documented_order_is_clean() {
    {
        let bench = Bench::new(true);
        let mut gi = bench.context("igi");
        bench.run(&mut gi, 0..2);
        drop(gi);
        // `bench` drops shine's device, then the host's objects, then the host's device.
    }
    assert_eq!(host::VALIDATION_MESSAGES.load(Ordering::Relaxed), 0);
}

/// A context can move to a render thread; a device is shared between threads.
#[test]
fn contexts_are_send_and_devices_send_and_sync() {
    fn send<T: Send>() {}
    fn send_sync<T: Send + Sync>() {}
    send::<GiContext>();
    send_sync::<Device>();
}

/// The context's description for `technique` at `display`, with HVL's shadows traced one ray
/// per HVL and no traced near field: their noise follows the frame index and the G-buffer's
/// last bits, which these comparisons of two G-buffer paths and of resized contexts are not
/// about.
pub fn exact_desc(display: [u32; 2], technique: &str) -> GiContextDesc {
    let mut desc = GiContextDesc::new(display, technique).expect("desc");
    desc.settings.hvl.shadow_rays = 0;
    desc.settings.hvl.near_range = 0.0;
    desc
}

/// A smooth equirectangular test map (`w`×`h`, linear RGB): brighter towards +Y and +X.
fn test_map(w: u32, h: u32) -> Vec<[f32; 3]> {
    (0..h)
        .flat_map(|y| (0..w).map(move |x| (x, y)))
        .map(|(x, y)| {
            let theta = (y as f32 + 0.5) / h as f32 * std::f32::consts::PI;
            let a = std::f32::consts::TAU * ((x as f32 + 0.5) / w as f32 - 0.5);
            let d = glam::Vec3::new(theta.sin() * a.sin(), theta.cos(), -theta.sin() * a.cos());
            [
                1.0 + 0.6 * d.y + 0.3 * d.x,
                0.8 + 0.4 * d.y,
                0.6 + 0.2 * d.z * d.z,
            ]
        })
        .collect()
}

/// `technique`'s frame 0 lit by a host's environment map (the test map × 1.5, projected to
/// SH on the GPU), and the full renderer's with the same map as the scene's environment
/// (projected on the CPU): `(host, truth)`. For the proxies, a dispatch without any
/// environment is refused (they have nothing to shade with).
fn host_environment_frame(technique: &str) -> (Vec<[f32; 3]>, Vec<[f32; 3]>) {
    let (w, h) = (64, 32);
    let texels = test_map(w, h);
    let mut bench = Bench::new(false);
    let mut lit = bench.scene.clone();
    lit.environment = Some(shine_scene::environment::Environment {
        zenith: glam::Vec3::ZERO,
        horizon: glam::Vec3::ZERO,
        ground: glam::Vec3::ZERO,
        intensity: 1.5,
        map: Some(shine_scene::environment::EquirectMap {
            width: w,
            height: h,
            texels: std::sync::Arc::new(texels.clone()),
            uri: "test map".into(),
        }),
    });
    bench.scene.environment = None;
    let map = host::HostImage::new(
        &bench.host,
        "host environment",
        vk::Format::R32G32B32A32_SFLOAT,
        [w, h],
        vk::ImageUsageFlags::SAMPLED | vk::ImageUsageFlags::TRANSFER_DST,
    )
    .expect("map");
    let rgba: Vec<[f32; 4]> = texels.iter().map(|t| [t[0], t[1], t[2], 1.0]).collect();
    map.upload_rgba32f(&bench.host, &rgba).expect("upload");
    let mut gi = bench.context(technique);
    let cb = bench.host.begin().expect("begin");
    let mut d = bench.record_gbuffer(cb, 0);
    d.environment = Some(shine::embed::HostEnvironment {
        image: map.lend(host::sampled_after(), host::sampled_after()),
        intensity: 1.5,
    });
    gi.dispatch(cb, &d).expect("dispatch");
    bench.host.submit_and_wait(cb).expect("submit");
    let output = rgb(
        host::read_rgba16f(&bench.host, &bench.targets().gi, host::copy_source()).expect("read"),
    );
    map.destroy(&bench.host);
    if technique == "proxy" {
        let cb = bench.host.begin().expect("begin");
        let mut d = bench.record_gbuffer(cb, 1);
        d.environment = None;
        let error = gi.dispatch(cb, &d).expect_err("no environment").to_string();
        assert!(error.contains("environment"), "{error}");
        bench.host.submit_and_wait(cb).expect("submit");
    }
    let truth = {
        let scene = std::mem::replace(&mut bench.scene, lit);
        let truth = bench.full_renderer(technique, 0);
        bench.scene = scene;
        truth
    };
    bench.assert_clean();
    (output, truth)
}

/// The proxy technique lit by a host's environment map gives what the full renderer gives
/// with the same map as the scene's environment: relative RMSE ≤ 2 %, energy within 1 %.
#[test]
fn a_host_environment_map_lights_the_proxies() {
    let (output, truth) = host_environment_frame("proxy");
    let (relative_rmse, energy) = error_of(&output, &truth);
    println!("host environment: relative RMSE {relative_rmse:.4}, energy {energy:.4}");
    assert!(relative_rmse <= 0.02, "relative RMSE {relative_rmse}");
    assert!((energy - 1.0).abs() <= 0.01, "energy {energy}");
}

/// HVL and IGI frames take a host's environment map as their sky light (the `[sky]` pass, as
/// the full renderer lights them with the scene's environment): within 3 % relative RMSE and
/// 1 % of the energy of the full renderer's, whose sky adds light to the frame without it.
#[test]
fn a_host_environment_map_lights_the_sky_of_hvl_and_igi() {
    for technique in ["hvl", "igi"] {
        let (output, truth) = host_environment_frame(technique);
        let (relative_rmse, energy) = error_of(&output, &truth);
        let without_sky = Bench::new(false).full_renderer(technique, 0);
        let (_, sky_share) = error_of(&truth, &without_sky);
        println!(
            "{technique}: host environment relative RMSE {relative_rmse:.4}, energy {energy:.4}; \
             the sky adds {:.1} %",
            (sky_share - 1.0) * 100.0
        );
        assert!(
            sky_share > 1.02,
            "{technique}: the sky added nothing ({sky_share})"
        );
        assert!(
            relative_rmse <= 0.03,
            "{technique}: relative RMSE {relative_rmse}"
        );
        assert!((energy - 1.0).abs() <= 0.01, "{technique}: energy {energy}");
    }
}

/// `GiCamera::from_scene` gives the matrices of the scene's camera that the host bench
/// computes by hand (`host::camera` without a turn), and a still camera when both times are
/// the same; a missing camera is `None`.
#[test]
fn a_scene_camera_becomes_a_gi_camera() {
    let scene = Scene::builtin("cornell-box").expect("scene");
    let camera = GiCamera::from_scene(&scene, 0, 0.0, 0.0, EXTENT).expect("camera 0");
    let (view, projection) = host::camera(&scene, EXTENT, 0.0);
    assert!(camera.view.abs_diff_eq(view, 1e-5), "{camera:?}");
    assert!(
        camera.projection.abs_diff_eq(projection, 1e-5),
        "{camera:?}"
    );
    assert_eq!(camera, GiCamera::still(camera.view, camera.projection));
    assert!(GiCamera::from_scene(&scene, scene.cameras.len(), 0.0, 0.0, EXTENT).is_none());
}
