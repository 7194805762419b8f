//! The CPU side of a frame update, measured: evaluating a [`FrameUpdate`] (animation, world
//! matrices, lights, morph weights, joint matrices, bounds) on the built-in scenes; the whole
//! host side of a frame's update (`GpuScene::update` + `GpuScene::declare`: instance records,
//! the deformers' CPU refit, the top level, staging writes); and rebuilding the top-level BVH
//! over 10 to 10 000 instances (the scenes have tens; the larger counts show where a GPU
//! build would start to pay). Numbers go to docs/performance.md.
//!
//! ```text
//! cargo run --release --example update_cost
//! ```

use std::time::Instant;

use glam::{Mat4, Quat, Vec3};
use shine::gpu::{Device, DeviceDesc};
use shine::gpu_scene::bvh::{TopInstance, TopLevel};
use shine::gpu_scene::{FrameState, FrameUpdate, GpuScene};
use shine::graph::Executor;
use shine::profile::report::Stats;
use shine_scene::{Aabb, Scene};

/// Median over `runs` of `f`'s wall time, in microseconds (the profiler's [`Stats`]).
fn median_us(runs: usize, mut f: impl FnMut()) -> f64 {
    let ns: Vec<f64> = (0..runs)
        .map(|_| {
            let start = Instant::now();
            f();
            start.elapsed().as_secs_f64() * 1e9
        })
        .collect();
    Stats::from_ns(&ns).map_or(0.0, |s| s.median_ms * 1e3)
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    println!("FrameState::evaluate (CPU), median of 200:");
    for name in shine_scene::builtin::names() {
        let scene = Scene::builtin(name)?;
        let mut k = 0u32;
        let us = median_us(200, || {
            k += 1;
            std::hint::black_box(FrameState::evaluate(
                &scene,
                &FrameUpdate::at(k as f32 / 60.0),
            ));
        });
        println!("  {name:<12} {:>4} nodes  {us:>8.1} µs", scene.nodes.len());
    }
    println!("GpuScene::update + declare (host side of a frame's update), median of 100:");
    let device = Device::new(&DeviceDesc::from_env())?;
    let executor = Executor::new(&device, 2)?;
    for name in shine_scene::builtin::names() {
        let scene = Scene::builtin(name)?;
        let mut gpu = GpuScene::upload(&device, &scene, 0.0)?;
        let mut k = 0u32;
        let mut failed = None;
        let us = median_us(100, || {
            k += 1;
            let mut rg = executor.begin_frame();
            let result = gpu
                .update(&FrameUpdate::at(k as f32 / 60.0))
                .and_then(|()| gpu.declare(&mut rg).map(|_| ()));
            if let Err(e) = result {
                failed = Some(e);
            }
        });
        if let Some(e) = failed {
            return Err(e.into());
        }
        println!(
            "  {name:<12} {:>6} triangles  {us:>8.1} µs",
            scene.triangle_count()
        );
    }
    println!("TopLevel::build (CPU, binned SAH over instance boxes), median of 50:");
    let unit = Aabb {
        min: Vec3::splat(-0.5),
        max: Vec3::splat(0.5),
    };
    for n in [10usize, 100, 1000, 10_000] {
        let side = (n as f32).cbrt().ceil() as usize;
        let instances: Vec<TopInstance> = (0..n)
            .map(|i| {
                let p = Vec3::new(
                    (i % side) as f32,
                    ((i / side) % side) as f32,
                    (i / (side * side)) as f32,
                ) * 2.0;
                TopInstance {
                    world: Mat4::from_rotation_translation(Quat::from_rotation_y(i as f32), p),
                    root: 0,
                    bounds: unit,
                    triangle_base: 0,
                }
            })
            .collect();
        let us = median_us(50, || {
            std::hint::black_box(TopLevel::build(&instances));
        });
        println!("  {n:>6} instances  {us:>9.1} µs");
    }
    Ok(())
}
