//! A C++ host through the C API (examples/capi_host: its own instance, device, raster
//! G-buffer pipeline and images; built by its Makefile with the system compiler) against the
//! Rust host of examples/host_gbuffer through the Rust API: the same scene, camera, G-buffer
//! shaders and technique give the same indirect light, within 1e-3 relative RMSE (the C++
//! host registers its own vertex and index buffers; the Rust one hands over the built-in).
//! The C++ host also checks that a NaN camera, a too-small vertex buffer, a 60 % internal
//! resolution, a new shape for a rigid mesh and a NaN scene time are refused.

mod common;
#[path = "../../../examples/host_gbuffer/host/mod.rs"]
mod host;

use host::{HostDevice, HostScene, Raster, Targets};
use shine::embed::{Device, DispatchShape, GiCamera, GiContext, GiContextDesc};
use std::path::PathBuf;
use std::process::Command;
use std::sync::atomic::Ordering;

/// The compared image's size.
const EXTENT: [u32; 2] = [64, 64];
/// Frames each host records (a still camera: the history accumulates).
const FRAMES: u32 = 3;

/// The Rust host's indirect light after `FRAMES` frames (RGBA per pixel).
fn rust_host(scene_name: &str) -> Vec<[f32; 4]> {
    let host = HostDevice::new(true).expect("host device");
    let scene = shine::scene::Scene::builtin(scene_name).expect("scene");
    let host_scene = HostScene::new(&host, &scene).expect("host scene");
    let raster = Raster::new(&host).expect("raster");
    let targets = Targets::new(&host, EXTENT).expect("targets");
    let texels = {
        let device = Device::from_raw(host.lend(false)).expect("shine device");
        // The settings the C++ host passes as "key=value" strings.
        let mut desc = GiContextDesc::new(EXTENT, "hvl").expect("desc");
        desc.settings.hvl.shadow_rays = 0;
        desc.settings.hvl.near_range = 0.0;
        let mut gi = GiContext::new(&device, &desc).expect("context");
        gi.set_scene(&scene, 0.0).expect("set scene");
        gi.warm_up(DispatchShape::default()).expect("warm up");
        let camera = GiCamera::from_scene(&scene, 0, 0.0, 0.0, EXTENT).expect("camera");
        for k in 0..FRAMES {
            let cb = host.begin().expect("begin");
            raster.record(
                &host,
                cb,
                &targets,
                &host_scene,
                camera.projection * camera.view,
            );
            let dispatch = targets.dispatch(u64::from(k), camera);
            gi.dispatch(cb, &dispatch).expect("dispatch");
            host.submit_and_wait(cb).expect("submit");
        }
        host::read_rgba16f(&host, &targets.gi, host::copy_source()).expect("read back")
    };
    targets.destroy(&host);
    raster.destroy(&host);
    host_scene.destroy(&host);
    assert_eq!(host::VALIDATION_MESSAGES.load(Ordering::Relaxed), 0);
    texels
}

/// The C++ host's indirect light: built with `make`, run, its raw RGBA32F file read.
fn cpp_host(scene_name: &str) -> Vec<[f32; 4]> {
    let (include, lib) = (common::include_dir(), common::library_dir());
    let build = std::env::temp_dir().join(format!("shine-capi-host-{}", std::process::id()));
    let example = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../examples/capi_host");
    let made = Command::new("make")
        .arg("-C")
        .arg(&example)
        .arg(format!("SHINE_LIB={}", lib.display()))
        .arg(format!("SHINE_INCLUDE={}", include.display()))
        .arg(format!("OUT={}", build.display()))
        .output()
        .expect("run make");
    assert!(
        made.status.success(),
        "{}{}",
        String::from_utf8_lossy(&made.stdout),
        String::from_utf8_lossy(&made.stderr)
    );
    let raw = build.join("gi.raw");
    // The library just linked, first: cargo's own LD_LIBRARY_PATH may name an older copy
    // of it (target/<profile>, uplifted by an earlier `cargo build`) ahead of the rpath.
    let run = Command::new(build.join("capi_host"))
        .env("LD_LIBRARY_PATH", &lib)
        .arg(scene_name)
        .args([
            EXTENT[0].to_string(),
            EXTENT[1].to_string(),
            FRAMES.to_string(),
        ])
        .arg(&raw)
        .arg(&build)
        .output()
        .expect("run the C++ host");
    let stdout = String::from_utf8_lossy(&run.stdout);
    println!("{stdout}");
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    // The host's own bad-input checks ran (it exits 1 when one is not refused).
    assert!(stdout.contains("NaN camera refused"), "{stdout}");
    assert!(stdout.contains("too-small buffer refused"), "{stdout}");
    assert!(stdout.contains("60 % refused"), "{stdout}");
    assert!(
        stdout.contains("rigid mesh deformation refused"),
        "{stdout}"
    );
    assert!(stdout.contains("NaN time refused"), "{stdout}");
    let bytes = std::fs::read(&raw).expect("the C++ host's output");
    let _ = std::fs::remove_dir_all(&build);
    assert_eq!(bytes.len(), (EXTENT[0] * EXTENT[1] * 16) as usize);
    bytes
        .chunks_exact(16)
        .map(|t| {
            let f = |i: usize| f32::from_le_bytes([t[i], t[i + 1], t[i + 2], t[i + 3]]);
            [f(0), f(4), f(8), f(12)]
        })
        .collect()
}

#[test]
fn the_cpp_host_gets_the_rust_hosts_indirect_light() {
    let scene = "cornell-box";
    let truth = rust_host(scene);
    let cpp = cpp_host(&format!("builtin:{scene}"));
    let rgb = |t: &[[f32; 4]]| -> Vec<[f32; 3]> { t.iter().map(|p| [p[0], p[1], p[2]]).collect() };
    let (truth, cpp) = (rgb(&truth), rgb(&cpp));
    let mean =
        truth.iter().flatten().map(|&v| f64::from(v)).sum::<f64>() / (truth.len() * 3) as f64;
    let rmse = (truth
        .iter()
        .flatten()
        .zip(cpp.iter().flatten())
        .map(|(&a, &b)| (f64::from(a) - f64::from(b)).powi(2))
        .sum::<f64>()
        / (truth.len() * 3) as f64)
        .sqrt();
    println!("mean {mean:.5}, relative RMSE {:.2e}", rmse / mean);
    assert!(mean > 1e-3, "the Rust host's indirect light is black");
    assert!(rmse / mean <= 1e-3, "relative RMSE {}", rmse / mean);
}
