//! The separate specular output: with `GiDispatch::specular` the traced reflections go there
//! and the techniques' light to `diffuse`; the two add up to the single-output frame.

use super::gi_context::{Bench, EXTENT, exact_desc, rgb};
use super::host::{self, HostImage};
use super::truth::{error_of, error_over, truth};
use shine::embed::{DispatchShape, ExternalState, GiContext, GiDispatch};
use shine::gpu::vk;

/// One frame of `builtin:metals` (frame 0 of a fresh, warmed context without history) with
/// or without a specular image: `(diffuse, specular)` read back.
fn frame(bench: &Bench, specular: Option<&HostImage>) -> (Vec<[f32; 3]>, Option<Vec<[f32; 3]>>) {
    let mut desc = exact_desc(EXTENT, "hvl");
    desc.settings.history.max_frames = 1;
    let mut gi = GiContext::new(bench.device(), &desc).expect("context");
    gi.set_scene(&bench.scene, 0.0).expect("scene");
    gi.warm_up(DispatchShape {
        specular: specular.is_some(),
        ..DispatchShape::default()
    })
    .expect("warm up");
    let cb = bench.host.begin().expect("begin");
    let dispatch = GiDispatch {
        specular: specular.map(|s| s.lend(ExternalState::UNDEFINED, host::copy_source())),
        ..bench.record_gbuffer_from(cb, 0, bench.camera(0))
    };
    gi.dispatch(cb, &dispatch).expect("dispatch");
    bench.host.submit_and_wait(cb).expect("submit");
    let read = |image: &HostImage| {
        rgb(host::read_rgba16f(&bench.host, image, host::copy_source()).expect("read"))
    };
    (read(&bench.targets().gi), specular.map(read))
}

/// The host's specular output image (RGBA16F, display size).
fn specular_image(bench: &Bench) -> HostImage {
    HostImage::new(
        &bench.host,
        "host specular",
        vk::Format::R16G16B16A16_SFLOAT,
        EXTENT,
        vk::ImageUsageFlags::TRANSFER_DST
            | vk::ImageUsageFlags::TRANSFER_SRC
            | vk::ImageUsageFlags::SAMPLED,
    )
    .expect("specular image")
}

/// Metals: the specular image carries the sharp reflections (a real share of the light: the
/// chrome and silver spheres), the diffuse image the rest, and their sum is the
/// single-output frame to RGBA16F rounding (relative RMSE ≤ 2e-3). The traced part is not
/// accumulated either way here (`history.frames = 1`).
#[test]
fn diffuse_and_specular_outputs_add_up_to_the_whole_indirect_light() {
    let bench = Bench::for_scene("metals");
    let specular = specular_image(&bench);
    let (whole, _) = frame(&bench, None);
    let (diffuse, split) = frame(&bench, Some(&specular));
    let split = split.expect("specular read back");
    let total = |img: &[[f32; 3]]| img.iter().flatten().map(|&v| f64::from(v)).sum::<f64>();
    let share = total(&split) / total(&whole);
    let sum: Vec<[f32; 3]> = diffuse
        .iter()
        .zip(&split)
        .map(|(d, s)| [d[0] + s[0], d[1] + s[1], d[2] + s[2]])
        .collect();
    let (relative_rmse, energy) = super::gi_context::error_of(&sum, &whole);
    println!(
        "specular share {share:.3}, diffuse + specular against the whole: relative RMSE \
         {relative_rmse:.2e}, energy {energy:.5}"
    );
    assert!(share > 0.02, "the specular output is nearly empty: {share}");
    assert!(relative_rmse <= 2e-3, "relative RMSE {relative_rmse}");
    assert!((energy - 1.0).abs() <= 1e-3, "energy {energy}");
    specular.destroy(&bench.host);
    bench.assert_clean();
}

/// Bound on the specular output's relative RMSE where its truth converged (measured 0.295 at
/// 64²: one frame, two rays per pixel, denoised; issue 47 measured 0.20–0.67 on a rough gold
/// sphere for the same one-sample traced specular).
const SPECULAR_RMSE: f64 = 0.35;
/// Bound on its energy ratio's distance from 1 there (measured 0.949).
const SPECULAR_ENERGY: f64 = 0.08;

/// The specular output against its own truth: the path tracer with the camera's surface
/// reflecting through its GGX lobe alone, by the traced share at the context's
/// `specular.limit` (`ReferenceParams::primary_specular`), 8 × 128 spp with its noise taken
/// out. One frame at one sample per pixel (`--ssaa 1`'s case), no history. Reported over every
/// pixel, over the pixels the truth lights (the smooth metals) and over those where the truth
/// converged (a few stay fireflies: a glossy path that finds a surface next to a point light);
/// bounded there, and at least 90 % of the lit pixels must have converged.
#[test]
fn the_specular_output_matches_its_path_traced_truth() {
    let bench = Bench::for_scene("metals");
    let specular = specular_image(&bench);
    let (_, output) = frame(&bench, Some(&specular));
    let output = output.expect("specular read back");
    let limit = exact_desc(EXTENT, "hvl").settings.specular.limit;
    let truth = truth(&bench, Some(limit));
    let mean = truth.mean();
    let noise = truth.pixel_noise().expect("chunks");
    let lit: Vec<bool> = mean.iter().map(|t| t.iter().sum::<f32>() > 0.0).collect();
    // Converged: the truth's standard error below a quarter of its value (the few pixels
    // where a glossy path found a light's near surface stay fireflies at 1024 spp).
    let converged: Vec<bool> = mean
        .iter()
        .zip(&noise)
        .zip(&lit)
        .map(|((t, n), &l)| l && n.sqrt() < 0.25 * f64::from(t.iter().sum::<f32>() / 3.0))
        .collect();
    let count = |mask: &[bool]| mask.iter().filter(|&&m| m).count();
    let (every, energy) = error_of(&output, &truth);
    let (region, region_energy) = error_over(&output, &truth, &lit);
    let (settled, settled_energy) = error_over(&output, &truth, &converged);
    println!(
        "specular output against its truth: every pixel relative RMSE {every:.3} (energy \
         {energy:.3}); the {} lit pixels {region:.3} (energy {region_energy:.3}); the {} \
         where the truth converged {settled:.3} (energy {settled_energy:.3})",
        count(&lit),
        count(&converged)
    );
    assert!(
        count(&converged) * 10 >= count(&lit) * 9,
        "the truth converged on too few pixels"
    );
    assert!(settled <= SPECULAR_RMSE, "relative RMSE {settled}");
    assert!(
        (settled_energy - 1.0).abs() <= SPECULAR_ENERGY,
        "energy {settled_energy}"
    );
    specular.destroy(&bench.host);
    bench.assert_clean();
}
