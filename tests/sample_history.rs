//! Each sample's own history (issue 43, item 2; `shaders/sample_history.comp`): the GPU pass
//! against its CPU twin (`shine::reference::sample_history`) over frames that exercise every
//! reset of the rule, with the validation layer reporting nothing; and on the flux cache of a
//! turning spot (the CPU twin of `hvl_flux`): a sample's filter keeps blending while its light
//! turns a little and starts over on each stated change.

mod common;

use std::collections::BTreeMap;

use common::spot_rsm::turned_spot;
use common::{assert_clean, device, read_by_copy, transfer_storage, uploaded_state};
use glam::{Vec3, Vec4};
use shine::gpu::Device;
use shine::graph::{Executor, ExternalState};
use shine::passes::hvl::{Distribution, Hvl, HvlParams, cache_bytes};
use shine::passes::sample_history::{
    DEFAULT_SAMPLE_WEIGHT, SAMPLE_FLUX_RATIO, SAMPLE_JUMP_RADII, SampleHistoryPush, sample_history,
};
use shine::reference::hvl_flux::build_flux_cache;
use shine::reference::sample_history::filter;

/// A valid record of identity (`light`, `index`).
fn record(light: u32, index: u32, position: Vec3, radius: f32, normal: Vec3, flux: Vec3) -> Hvl {
    let mut h: Hvl = bytemuck::Zeroable::zeroed();
    h.position_radius = position.extend(radius).to_array();
    h.normal_distance = normal.normalize().extend(2.0).to_array();
    h.flux = flux.extend(1.0).to_array();
    h.emission = [0.9, 0.5, 0.1, 0.0, 0.0];
    h.light = light;
    h.sample_index = index;
    h
}

/// Runs the pass on the GPU over `frames` (each a cache of the same count), one graph per frame
/// on one executor (the history persists between them); returns the filtered caches.
fn gpu_frames(device: &Device, frames: &[(Vec<Hvl>, SampleHistoryPush)]) -> Vec<Vec<Hvl>> {
    let mut executor = Executor::new(device, 1).unwrap();
    let mut out = Vec::new();
    for (cache, push) in frames {
        let bytes = cache_bytes(push.count);
        let upload = transfer_storage(
            device,
            "cache",
            bytes,
            Some(bytemuck::cast_slice(cache.as_slice())),
        );
        let readback = transfer_storage(device, "readback", bytes, None);
        let mut rg = executor.begin_frame();
        let mut records = rg.import_gpu_buffer(&upload, uploaded_state(), ExternalState::UNDEFINED);
        sample_history(&mut rg, "test samples", &mut records, push);
        let mut read = rg.import_gpu_buffer(&readback, ExternalState::UNDEFINED, read_by_copy());
        rg.copy_buffer("read", &records, &mut read);
        common::run_graph(device, &mut executor, rg);
        out.push(bytemuck::cast_slice(&device.read_buffer(&readback).unwrap()).to_vec());
    }
    out
}

/// The push constants' Rust mirror has the shader's size.
#[test]
fn push_constants_match_the_shader() {
    assert_eq!(
        shine::shaders::SAMPLE_HISTORY_COMP.push_constant_size as usize,
        std::mem::size_of::<SampleHistoryPush>()
    );
}

/// The GPU pass matches its twin over four frames of six records of two lights: a sample that
/// slides (blended), one that jumps further than its radius, one whose flux triples, one whose
/// normal turns by 126°, one missing the frame before, an empty slot; and a frame without history.
#[test]
fn the_pass_matches_its_cpu_twin_over_every_reset() {
    let device = device();
    let count = 6;
    let push = |has| SampleHistoryPush::new(count, 2, DEFAULT_SAMPLE_WEIGHT, has);
    let frame = |k: f32| -> Vec<Hvl> {
        let mut c = vec![
            record(
                0,
                0,
                Vec3::new(0.1 * k, 0.0, 0.0),
                0.5,
                Vec3::Y,
                Vec3::splat(1.0 + 0.1 * k),
            ),
            // Jumps 3 radii at frame 2.
            record(
                0,
                1,
                Vec3::new(if k >= 2.0 { 1.5 } else { 0.0 }, 1.0, 0.0),
                0.5,
                Vec3::Y,
                Vec3::ONE,
            ),
            // Flux ×3 at frame 2.
            record(
                1,
                0,
                Vec3::Z,
                0.5,
                Vec3::X,
                Vec3::splat(if k >= 2.0 { 3.0 } else { 1.0 }),
            ),
            // Normal turns 126° a frame: past SAMPLE_MIN_NORMAL_COS, starts over.
            record(
                1,
                1,
                Vec3::NEG_Z,
                0.5,
                Vec3::new((k * 2.2).cos(), (k * 2.2).sin(), 0.0),
                Vec3::ONE,
            ),
            // Absent at frame 1.
            record(
                1,
                2,
                Vec3::X,
                0.5,
                Vec3::Y,
                Vec3::new(0.2, 0.4, 0.6) * (1.0 + k),
            ),
            bytemuck::Zeroable::zeroed(),
        ];
        if k == 1.0 {
            c[4] = bytemuck::Zeroable::zeroed();
        }
        c
    };
    let frames: Vec<(Vec<Hvl>, SampleHistoryPush)> = (0..4)
        .map(|k| (frame(k as f32), push(k > 0 && k != 3)))
        .collect();
    let gpu = gpu_frames(&device, &frames);
    let mut previous = vec![bytemuck::Zeroable::zeroed(); (count * 2) as usize];
    // (frame, record) pairs the rule blends; every other record is this frame's as it is.
    let blends = [(1, 0), (2, 0)];
    for (k, ((cache, push), gpu)) in frames.iter().zip(&gpu).enumerate() {
        let mut cpu = cache.clone();
        previous = filter(&mut cpu, &previous, push);
        for (m, (g, c)) in gpu.iter().zip(&cpu).enumerate() {
            let fields = |h: &Hvl| -> Vec<f32> {
                h.flux.iter().chain(&h.normal_distance).copied().collect()
            };
            for (a, b) in fields(g).iter().zip(fields(c)) {
                assert!(
                    (a - b).abs() <= 1e-5,
                    "frame {k}, record {m}: GPU {g:?} against CPU {c:?}"
                );
            }
            assert_eq!(
                g.position_radius, c.position_radius,
                "frame {k}, record {m}"
            );
            assert_eq!(
                g != &cache[m],
                blends.contains(&(k, m)),
                "frame {k}, record {m}: blended or started over against the rule"
            );
        }
    }
    assert_clean(&device);
}

/// The flux cache (1024 samples) of tests/common's turned spot at `angle` scaled by `power`.
fn spot_cache(angle: f32, power: f32) -> Vec<Hvl> {
    let params = HvlParams {
        count: 1024,
        distribution: Distribution::Flux,
        ..HvlParams::default()
    };
    build_flux_cache(&[turned_spot(angle, power)], &params).expect("flux cache")
}

/// Records by identity.
fn by_id(cache: &[Hvl]) -> BTreeMap<(u32, u32), Hvl> {
    cache
        .iter()
        .filter(|h| h.is_valid())
        .map(|h| ((h.light, h.sample_index), *h))
        .collect()
}

/// A spot turning 0.1° a frame over 20 frames towards the wall: every sample continues (its filtered record
/// differs from the raw one wherever its flux or normal changed, and stays between the last
/// filtered and the raw), the samples that cross the crease from the floor to the wall turn
/// their normal over more than one frame; then the spot's power jumps (a stated change:
/// every sample starts over, its record is the raw one), and a sample moved further than
/// [`SAMPLE_JUMP_RADII`] radii starts over too.
#[test]
fn a_samples_temporal_filter_resets_on_a_stated_change() {
    let count = 1024;
    let push = |has| SampleHistoryPush::new(count, 1, DEFAULT_SAMPLE_WEIGHT, has);
    let mut previous = vec![bytemuck::Zeroable::zeroed(); count as usize];
    let mut last_filtered = BTreeMap::new();
    let mut crease_turns = 0;
    let step = 0.1f32.to_radians();
    for k in 0..20 {
        let raw = spot_cache(-0.3 + k as f32 * step, 1.0);
        let mut filtered = raw.clone();
        previous = filter(&mut filtered, &previous, &push(k > 0));
        let (raw_id, now) = (by_id(&raw), by_id(&filtered));
        if k > 0 {
            for (id, f) in &now {
                let r = raw_id[id];
                let Some(last): Option<&Hvl> = last_filtered.get(id) else {
                    continue;
                };
                let (n_f, n_r, n_l) = (
                    Vec4::from(f.normal_distance).truncate(),
                    Vec4::from(r.normal_distance).truncate(),
                    Vec4::from(last.normal_distance).truncate(),
                );
                // Half-way between the raw and the last filtered normal.
                if n_r.dot(n_l) < 0.999 {
                    let half = (n_r + n_l).normalize();
                    assert!(
                        n_f.dot(half) > 0.999,
                        "sample {id:?}: normal {n_f} not between {n_l} and {n_r}"
                    );
                    if n_r.dot(n_l) < 0.5 || n_f.dot(n_r) < 0.99 {
                        crease_turns += 1;
                    }
                }
                for c in 0..3 {
                    let (lo, hi) = (r.flux[c].min(last.flux[c]), r.flux[c].max(last.flux[c]));
                    assert!(
                        f.flux[c] >= lo - 1e-6 && f.flux[c] <= hi + 1e-6,
                        "sample {id:?}: flux outside its blend"
                    );
                }
            }
        }
        last_filtered = now;
    }
    assert!(
        crease_turns > 0,
        "no sample turned at the crease over more than one frame"
    );

    // The spot's power beyond SAMPLE_FLUX_RATIO: every sample starts over.
    let power = 1.5 * SAMPLE_FLUX_RATIO;
    let raw = spot_cache(-0.3 + 20.0 * step, power);
    let mut filtered = raw.clone();
    previous = filter(&mut filtered, &previous, &push(true));
    assert_eq!(
        filtered, raw,
        "a light beyond the ratio: every sample starts over"
    );

    // A sample moved by 1.5 radii starts over; one moved by half a radius blends.
    let mut moved = spot_cache(-0.3 + 20.0 * step, power);
    let r0 = moved[0].position_radius[3];
    moved[0].position_radius[0] += 1.5 * SAMPLE_JUMP_RADII * r0;
    moved[0].flux[0] *= 1.2;
    let r1 = moved[1].position_radius[3];
    moved[1].position_radius[0] += 0.5 * SAMPLE_JUMP_RADII * r1;
    moved[1].flux[0] *= 1.2;
    let raw = moved.clone();
    filter(&mut moved, &previous, &push(true));
    assert_eq!(moved[0], raw[0], "a jump of 1.5 radii starts over");
    assert_ne!(moved[1].flux, raw[1].flux, "a move of half a radius blends");
}
