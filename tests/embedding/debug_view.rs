//! The debug output (`GiDispatch::debug`, `DebugView`): what the GI sees, drawn at the display
//! size. Each view against what it shows: the virtual lights' dots against a CPU projection of
//! the same lights built apart, the receivers against the G-buffer, AAF's samples against
//! their range; views a technique lacks refused; the diffuse output unchanged by it.

use super::common;
use super::gi_context::{Bench, EXTENT, exact_desc};
use super::host::{self, HostImage};
use glam::{Mat4, Vec3, Vec4};
use shine::embed::{DebugView, ExternalState, GiContext, GiContextDesc, GiDispatch};
use shine::frame::params::FrameParams;
use shine::gpu::{Sampler, vk};
use shine::gpu_scene::GpuScene;
use shine::graph::Executor;
use shine::passes::hvl::{Distribution, Hvl, cache_bytes, hvl_cache};
use shine::passes::{igi, rsm};

/// An RGBA16F host image of the bench's size that the debug view is blitted to and read from.
fn debug_image(bench: &Bench) -> HostImage {
    HostImage::new(
        &bench.host,
        "host debug",
        vk::Format::R16G16B16A16_SFLOAT,
        EXTENT,
        vk::ImageUsageFlags::TRANSFER_DST
            | vk::ImageUsageFlags::TRANSFER_SRC
            | vk::ImageUsageFlags::SAMPLED,
    )
    .expect("debug image")
}

/// A context of `desc` with the bench's scene.
fn context(bench: &Bench, desc: &GiContextDesc) -> GiContext {
    let mut gi = GiContext::new(bench.device(), desc).expect("context");
    gi.set_scene(&bench.scene, 0.0).expect("scene");
    gi
}

/// Frame `frame` of `gi` from the bench's still camera, with `view` into `debug` when given:
/// `(diffuse, debug)` read back.
fn dispatch(
    bench: &Bench,
    gi: &mut GiContext,
    frame: u64,
    debug: Option<(&HostImage, DebugView)>,
) -> (Vec<[f32; 4]>, Option<Vec<[f32; 4]>>) {
    let cb = bench.host.begin().expect("begin");
    let d = GiDispatch {
        debug: debug.map(|(image, _)| image.lend(ExternalState::UNDEFINED, host::copy_source())),
        debug_view: debug.map_or(DebugView::default(), |(_, view)| view),
        ..bench.record_gbuffer_from(cb, frame, bench.camera(0))
    };
    gi.dispatch(cb, &d).expect("dispatch");
    bench.host.submit_and_wait(cb).expect("submit");
    let read = |image: &HostImage| {
        host::read_rgba16f(&bench.host, image, host::copy_source()).expect("read")
    };
    (
        read(&bench.targets().gi),
        debug.map(|(image, _)| read(image)),
    )
}

/// The virtual lights of `technique` ("hvl" or "igi") as the context builds them from the same
/// scene at the same settings, rebuilt apart on shine's device: the primary light's (and every
/// other light's) RSM faces, then the HVL cache or IGI's VPLs, read back.
fn lights_built_apart(bench: &Bench, desc: &GiContextDesc) -> Vec<Hvl> {
    let device = bench.device();
    let mut settings = desc.settings.clone();
    [settings.width, settings.height] = EXTENT;
    let p = FrameParams::from_settings(&settings);
    let mut gpu = GpuScene::upload(device, &bench.scene, 0.0).expect("upload");
    let mut executor = Executor::new(device, 1).expect("executor");
    let sampler = Sampler::new(
        device,
        &vk::SamplerCreateInfo::default()
            .mag_filter(vk::Filter::LINEAR)
            .min_filter(vk::Filter::LINEAR),
    )
    .expect("sampler");
    let mut rg = executor.begin_frame();
    let handles = gpu.declare(&mut rg).expect("declare");
    let primary = gpu.primary_light().expect("a light");
    let faces = rsm::face_views(&gpu.state, primary, p.rsm_size);
    let rsms: Vec<rsm::Rsm> = faces
        .iter()
        .map(|face| face.render(&mut rg, &handles, sampler.raw()))
        .collect();
    let (records, count) = match (p.hvl, p.igi) {
        (Some(hvl), _) => {
            assert_eq!(hvl.distribution, Distribution::Flux, "every light's faces");
            (hvl_cache(&mut rg, &rsms, &hvl).expect("cache"), hvl.count)
        }
        (None, Some(igi)) => {
            assert_eq!(igi.distribution, Distribution::Flux, "every light's faces");
            (
                igi::vpls(&mut rg, &rsms, &igi).expect("vpls"),
                igi.vpl_count,
            )
        }
        _ => panic!("no virtual lights"),
    };
    let readback = common::transfer_storage(device, "lights readback", cache_bytes(count), None);
    let mut out = rg.import_gpu_buffer(&readback, ExternalState::UNDEFINED, common::read_by_copy());
    rg.copy_buffer("read lights", &records, &mut out);
    common::run_graph(device, &mut executor, rg);
    bytemuck::cast_slice(&device.read_buffer(&readback).expect("read")).to_vec()
}

/// Where `position` lands on the display through `view_proj` (pixels, y down), in front of
/// the camera.
fn project(view_proj: Mat4, position: Vec3) -> Option<[f32; 2]> {
    let clip = view_proj * position.extend(1.0);
    (clip.w > 0.0).then(|| {
        let ndc = [clip.x / clip.w, clip.y / clip.w];
        [0, 1].map(|a| (ndc[a] * 0.5 + 0.5) * EXTENT[a] as f32)
    })
}

/// HVL's and IGI's light points: every dot pixel (alpha 1) lies in the 3×3 dot of a light
/// the CPU projects from the records built apart (within 1 px of its centre pixel), with
/// that light's normalised flux as its colour (to RGBA16F rounding), and every light the CPU
/// projects into the image has a dot at its pixel. The RSM view of the same frame fills the
/// square output with finite flux, some of it lit.
#[test]
fn light_points_lie_where_the_lights_project() {
    let bench = Bench::new(false);
    let image = debug_image(&bench);
    let camera = bench.camera(0);
    let view_proj = camera.projection * camera.view;
    for technique in ["hvl", "igi"] {
        let desc = exact_desc(EXTENT, technique);
        let lights = lights_built_apart(&bench, &desc);
        let mut gi = context(&bench, &desc);
        let (_, dots) = dispatch(&bench, &mut gi, 0, Some((&image, DebugView::LightPoints)));
        let dots = dots.expect("debug");
        let projected: Vec<([f32; 2], Vec3)> = lights
            .iter()
            .filter(|l| l.is_valid())
            .filter_map(|l| {
                let flux = Vec3::from_slice(&l.flux).max(Vec3::ZERO);
                let at = project(view_proj, Vec3::from_slice(&l.position_radius))?;
                Some((at, flux / flux.max_element().max(1e-30)))
            })
            .collect();
        let [w, h] = EXTENT.map(|v| v as usize);
        let mut dot_pixels = 0;
        for (i, texel) in dots.iter().enumerate() {
            let (x, y) = ((i % w) as f32 + 0.5, (i / w) as f32 + 0.5);
            assert!(
                texel[3] == 0.0 || texel[3] == 1.0,
                "{technique}: alpha {}",
                texel[3]
            );
            if texel[3] == 0.0 {
                assert!(
                    texel[..3].iter().all(|&c| (0.0..0.5).contains(&c)),
                    "background"
                );
                continue;
            }
            dot_pixels += 1;
            let colour = Vec3::from_slice(&texel[..3]);
            let owner = projected.iter().find(|(at, c)| {
                (x - at[0]).abs() <= 1.5 + 1e-3
                    && (y - at[1]).abs() <= 1.5 + 1e-3
                    && (colour - *c).abs().max_element() <= 2e-3
            });
            assert!(
                owner.is_some(),
                "{technique}: dot pixel ({x}, {y}) colour {colour} is no light's"
            );
        }
        let mut inside = 0;
        for (at, _) in &projected {
            let [px, py] = at.map(|v| v.floor() as i64);
            if (0..w as i64).contains(&px) && (0..h as i64).contains(&py) {
                inside += 1;
                assert_eq!(
                    dots[py as usize * w + px as usize][3],
                    1.0,
                    "{technique}: no dot at the light projected to {at:?}"
                );
            }
        }
        println!(
            "{technique}: {} lights, {} valid, {inside} project into the image, {dot_pixels} dot \
             pixels",
            lights.len(),
            projected.len()
        );
        assert!(inside >= 16, "{technique}: only {inside} lights in view");
        let (_, rsm) = dispatch(&bench, &mut gi, 1, Some((&image, DebugView::Rsm)));
        let rsm = rsm.expect("debug");
        assert!(
            rsm.iter()
                .all(|t| t[3] == 1.0 && t.iter().all(|c| c.is_finite()))
        );
        let lit = rsm
            .iter()
            .filter(|t| t[..3].iter().any(|&c| c > 0.0))
            .count();
        println!("{technique}: RSM view, {lit} of {} pixels lit", rsm.len());
        assert!(
            lit > rsm.len() / 8,
            "{technique}: RSM view nearly dark: {lit}"
        );
    }
    image.destroy(&bench.host);
    bench.assert_clean();
}

/// The receivers views at `receiver_scale = 2`, normals and albedo: constant over each 2×2
/// block, and each block shows the normal and albedo of one and the same G-buffer sample of
/// the block (the receivers copy one sample; the views at scale 1 show the G-buffer itself).
#[test]
fn receivers_view_shows_one_sample_per_block() {
    let bench = Bench::new(false);
    let image = debug_image(&bench);
    let views = |scale: u32| {
        let mut desc = exact_desc(EXTENT, "hvl");
        desc.settings.receiver_scale = scale;
        let mut gi = context(&bench, &desc);
        [DebugView::ReceiverNormals, DebugView::ReceiverAlbedo]
            .into_iter()
            .enumerate()
            .map(|(k, view)| {
                dispatch(&bench, &mut gi, k as u64, Some((&image, view)))
                    .1
                    .expect("debug")
            })
            .collect::<Vec<_>>()
    };
    let (full, half) = (views(1), views(2));
    let [w, h] = EXTENT.map(|v| v as usize);
    let (mut edges, mut surfaces) = (0, 0);
    for by in (0..h).step_by(2) {
        for bx in (0..w).step_by(2) {
            let block: Vec<usize> = (0..4).map(|k| (by + k / 2) * w + bx + k % 2).collect();
            let shown = |i: usize| (half[0][i], half[1][i]);
            let sample = |i: usize| (full[0][i], full[1][i]);
            assert!(
                block.iter().all(|&i| shown(i) == shown(block[0])),
                "block ({bx}, {by}) is not constant"
            );
            let (normal, albedo) = shown(block[0]);
            if normal[3] == 0.0 {
                assert!(block.iter().all(|&i| sample(i).0[3] == 0.0), "background");
                assert_eq!((normal, albedo), ([0.0; 4], [0.0; 4]));
                continue;
            }
            surfaces += 1;
            if block.iter().any(|&i| sample(i) != sample(block[0])) {
                edges += 1;
            }
            assert!(
                block.iter().any(|&i| sample(i) == (normal, albedo)),
                "block ({bx}, {by}) shows {normal:?} {albedo:?}, no sample of its block"
            );
        }
    }
    println!("{surfaces} receiver blocks on surfaces, {edges} of them over differing samples");
    assert!(
        edges >= 20,
        "too few blocks where the choice matters: {edges}"
    );
    image.destroy(&bench.host);
    bench.assert_clean();
}

/// At 50 % internal resolution and `receiver_scale = 2` a receiver stands for 4×4 display
/// pixels: the view is constant over each such block and not over the whole image.
#[test]
fn receivers_view_at_half_internal_resolution_has_4x4_blocks() {
    let bench = Bench::new(false);
    let image = debug_image(&bench);
    let mut desc = exact_desc(EXTENT, "hvl");
    desc.settings.receiver_scale = 2;
    desc.internal_resolution = shine::embed::InternalResolution::Half;
    let mut gi = context(&bench, &desc);
    let shown = dispatch(
        &bench,
        &mut gi,
        0,
        Some((&image, DebugView::ReceiverNormals)),
    )
    .1
    .expect("debug");
    let w = EXTENT[0] as usize;
    let block = |i: usize| ((i / w) / 4) * (w / 4) + (i % w) / 4;
    let mut first = vec![None; (w / 4) * (EXTENT[1] as usize / 4)];
    for (i, texel) in shown.iter().enumerate() {
        let seen = first[block(i)].get_or_insert(*texel);
        assert_eq!(seen, texel, "pixel {i} differs from its 4×4 block");
    }
    let distinct = first.iter().filter(|b| b != &&first[0]).count();
    println!("{distinct} of {} blocks differ from the first", first.len());
    assert!(distinct > first.len() / 4);
    image.destroy(&bench.host);
    bench.assert_clean();
}

/// AAF's samples per pixel: every surface pixel's count (the view's alpha) within
/// `[spp_min, spp_max · μ]`, not all alike, and the heat colour of its place in that range;
/// the background 0.
#[test]
fn aaf_samples_view_stays_in_the_spp_range() {
    let bench = Bench::new(false);
    let image = debug_image(&bench);
    let desc = exact_desc(EXTENT, "aaf");
    let aaf = desc.settings.aaf;
    let range = [aaf.spp_min as f32, aaf.spp_upper()];
    let mut gi = context(&bench, &desc);
    let spp = dispatch(&bench, &mut gi, 0, Some((&image, DebugView::AafSamples)))
        .1
        .expect("debug");
    let counts: Vec<f32> = spp.iter().map(|t| t[3]).filter(|&n| n > 0.0).collect();
    let (least, most) = counts
        .iter()
        .fold((f32::MAX, 0.0f32), |(a, b), &n| (a.min(n), b.max(n)));
    println!(
        "{} surface pixels, samples per pixel {least}..{most} in {range:?}",
        counts.len()
    );
    assert!(counts.len() > spp.len() / 2, "too few surface pixels");
    assert!(
        least >= range[0] && most <= range[1],
        "{least}..{most} outside {range:?}"
    );
    assert!(most > least, "the samples per pixel are constant");
    for texel in &spp {
        if texel[3] == 0.0 {
            assert_eq!(texel, &[0.0; 4], "background");
            continue;
        }
        let t = (texel[3] - range[0]) / (range[1] - range[0]);
        let heat = [4.0 * t - 2.0, 2.0 - (4.0 * t - 2.0).abs(), 2.0 - 4.0 * t]
            .map(|c: f32| c.clamp(0.0, 1.0));
        let error = Vec4::from(*texel).truncate() - Vec3::from(heat);
        assert!(
            error.abs().max_element() <= 2e-3,
            "{texel:?} is not heat({t})"
        );
    }
    image.destroy(&bench.host);
    bench.assert_clean();
}

/// A view the technique does not have is refused at dispatch with a message naming it and
/// what it needs; so is a debug image of the wrong size.
#[test]
fn views_a_technique_lacks_are_refused() {
    let bench = Bench::new(false);
    let image = debug_image(&bench);
    let cases = [
        ("hvl", DebugView::AafSamples, "needs aaf"),
        ("igi", DebugView::ReceiverNormals, "receiver-resolution"),
        ("igi", DebugView::ReceiverAlbedo, "receiver-resolution"),
        ("aaf", DebugView::LightPoints, "virtual lights"),
        ("aaf", DebugView::Rsm, "virtual lights"),
    ];
    for (technique, view, needs) in cases {
        let mut gi = context(&bench, &exact_desc(EXTENT, technique));
        let cb = bench.host.begin().expect("begin");
        let d = GiDispatch {
            debug: Some(image.lend(ExternalState::UNDEFINED, host::copy_source())),
            debug_view: view,
            ..bench.record_gbuffer_from(cb, 0, bench.camera(0))
        };
        let error = gi.dispatch(cb, &d).expect_err("refused").to_string();
        println!("{technique}, {view:?}: {error}");
        assert!(
            error.contains(&format!("{view:?}")) && error.contains(needs),
            "{error}"
        );
        let mut wrong = image.lend(ExternalState::UNDEFINED, host::copy_source());
        wrong.extent = [32, 32];
        let d = GiDispatch {
            debug: Some(wrong),
            debug_view: DebugView::default(),
            ..d
        };
        let error = gi.dispatch(cb, &d).expect_err("refused").to_string();
        assert!(error.contains("debug image"), "{error}");
        bench.host.submit_and_wait(cb).expect("submit");
    }
    image.destroy(&bench.host);
    bench.assert_clean();
}

/// The debug output adds passes that only read: a context drawing every HVL view for three
/// frames writes the same diffuse output, bit for bit, as one without a debug image.
#[test]
fn the_debug_output_leaves_the_diffuse_output_unchanged() {
    let bench = Bench::new(false);
    let image = debug_image(&bench);
    let desc = exact_desc(EXTENT, "hvl");
    let (mut plain, mut debugged) = (context(&bench, &desc), context(&bench, &desc));
    let views = [
        DebugView::LightPoints,
        DebugView::ReceiverNormals,
        DebugView::Rsm,
    ];
    for (frame, view) in views.into_iter().enumerate() {
        let (without, _) = dispatch(&bench, &mut plain, frame as u64, None);
        let (with, debug) = dispatch(&bench, &mut debugged, frame as u64, Some((&image, view)));
        let bits = |image: &[[f32; 4]]| -> Vec<u32> {
            image.iter().flatten().map(|v| v.to_bits()).collect()
        };
        assert_eq!(bits(&with), bits(&without), "frame {frame}, {view:?}");
        assert!(debug.expect("debug").iter().flatten().any(|&c| c > 0.0));
        assert!(without.iter().flatten().any(|&c| c > 0.0));
    }
    image.destroy(&bench.host);
    bench.assert_clean();
}
