//! The lab's truths: the path-traced frame of the still time and of two fixed-seed
//! sequences under the moving light, cached on disk by scene, resolution, time and samples so
//! that a second lab run does not trace them again.
//!
//! The sequences turn the scene's primary light (its first spot or directional light, else its
//! first light) about the horizontal x axis through the scene's centre by
//! [`LabSetup::degrees_per_frame`] a frame: a spot sweeping, a sun turning, a point light
//! swinging along an arc. (About the vertical axis, a light above the centre pointing down,
//! as in the Cornell box, would not move at all.) The truth's flicker is measured noise-free
//! from the two seeds (issue 43): `mean(d2(A)²) − mean((d2(A) − d2(B))²) / 2` estimates the
//! squared second difference of the true light, since the two seeds' noises are independent.

use std::path::{Path, PathBuf};

use glam::{Quat, Vec3};
use shine_scene::{LightKind, Scene};

use super::{LabError, LabSetup};
use crate::capture::image_io::{HdrImage, read_exr, write_exr};
use crate::gpu::Device;
use crate::gpu_scene::FrameUpdate;
use crate::reference::{PathTracer, ReferenceParams};
use crate::study::temporal::{flicker, frames_mean};

/// Bumped when the truth's meaning changes (what is traced, how the light moves): cached
/// truths of another version are not read.
pub const TRUTH_VERSION: u32 = 3;

/// The seeds of the two truth sequences.
pub const SEQUENCE_SEEDS: [u32; 2] = [1, 2];

/// What the lab measures a scene against.
#[derive(Debug, Clone)]
pub struct Truths {
    /// The still frame (direct and indirect light; emissive surfaces light nothing).
    pub still: HdrImage,
    /// Each frame of the sequence, per seed.
    pub sequences: [Vec<HdrImage>; 2],
    /// The frames of the sequence: the scene at the lab's time with the primary light turned.
    pub updates: Vec<FrameUpdate>,
}

impl Truths {
    /// Each frame of the sequence as the mean of the two seeds (twice the samples): what the
    /// configurations' frames are judged against.
    pub fn sequence_mean(&self) -> Vec<HdrImage> {
        let [a, b] = &self.sequences;
        a.iter()
            .zip(b)
            .map(|(x, y)| HdrImage {
                width: x.width,
                height: x.height,
                texels: x
                    .texels
                    .iter()
                    .zip(&y.texels)
                    .map(|(p, q)| std::array::from_fn(|c| 0.5 * (p[c] + q[c])))
                    .collect(),
            })
            .collect()
    }

    /// The fixed-seed truth's flicker over every pixel (reported beside the noise-free one).
    pub fn flicker(&self) -> f64 {
        flicker(&self.sequences[0])
    }

    /// The truth's flicker with its noise taken out (see the module documentation), over every
    /// pixel; 0 when the sequence is shorter than 3 frames.
    pub fn noise_free_flicker(&self) -> f64 {
        noise_free_flicker(&self.sequences[0], &self.sequences[1])
    }
}

/// The index of the scene's primary light: its first spot or directional light, else its
/// first light.
pub fn primary_light(scene: &Scene) -> Option<usize> {
    let kind = |i: usize| scene.lights[i].light_kind();
    (0..scene.lights.len())
        .find(|&i| matches!(kind(i), Some(LightKind::Spot | LightKind::Directional)))
        .or((!scene.lights.is_empty()).then_some(0))
}

/// The sequence's frames: at the lab's time, the primary light turned by `k ×
/// degrees_per_frame` about the x axis through the centre of the scene's bounds.
pub fn sequence_updates(scene: &Scene, setup: &LabSetup) -> Vec<FrameUpdate> {
    let pose = scene.pose_at(setup.time);
    let lights = scene.lights_at(&pose.world);
    let bounds = scene.pose_bounds(&pose);
    let centre = 0.5 * (bounds.min + bounds.max);
    (0..setup.sequence_frames)
        .map(|k| {
            let mut update = FrameUpdate::at(setup.time);
            if let Some(i) = primary_light(scene)
                && let Some(light) = lights.get(i)
            {
                let turn = Quat::from_rotation_x((k as f32 * setup.degrees_per_frame).to_radians());
                let mut moved = *light;
                let p = Vec3::from_array(light.position) - centre;
                moved.position = (centre + turn * p).to_array();
                moved.direction = (turn * Vec3::from_array(light.direction)).to_array();
                update.lights.push((i, moved));
            }
            update
        })
        .collect()
}

/// `sqrt(mean(d2(A)²) − mean((d2(A) − d2(B))²)/2) / mean(A)`: the flicker of the light both
/// sequences estimate, without their independent noises (0 where the noise outweighs it).
pub fn noise_free_flicker(a: &[HdrImage], b: &[HdrImage]) -> f64 {
    if a.len() < 3 || a.len() != b.len() {
        return 0.0;
    }
    let (mut own, mut apart, mut n) = (0.0f64, 0.0f64, 0usize);
    for (wa, wb) in a.windows(3).zip(b.windows(3)) {
        for i in 0..wa[1].texels.len() {
            for c in 0..3 {
                let d2 = |w: &[HdrImage]| {
                    f64::from(w[2].texels[i][c] - 2.0 * w[1].texels[i][c] + w[0].texels[i][c])
                };
                let (da, db) = (d2(wa), d2(wb));
                own += da * da;
                apart += (da - db) * (da - db);
                n += 1;
            }
        }
    }
    let mean = frames_mean(a);
    ((own - apart / 2.0).max(0.0) / n.max(1) as f64).sqrt() / mean
}

/// The cache folder of one scene's truths under `setup`.
fn cache_folder(root: &Path, key: &str, setup: &LabSetup) -> PathBuf {
    let conditions = format!(
        "v{TRUTH_VERSION}-{}x{}-t{}-s{}-q{}x{}-d{}",
        setup.extent[0],
        setup.extent[1],
        setup.time,
        setup.truth_spp,
        setup.sequence_frames,
        setup.sequence_spp,
        setup.degrees_per_frame
    );
    root.join("lab-truth").join(key).join(conditions)
}

/// The truths of `scene` (named `key` in the cache) under `setup`: read from `cache` when it
/// holds them, else traced and written there. `traced` is told each frame traced.
pub fn truths(
    device: &Device,
    scene: &Scene,
    key: &str,
    setup: &LabSetup,
    cache: Option<&Path>,
    traced: &mut dyn FnMut(&str),
) -> Result<Truths, LabError> {
    let updates = sequence_updates(scene, setup);
    let folder = cache.map(|root| cache_folder(root, key, setup));
    let names: Vec<String> =
        std::iter::once("still.exr".to_owned())
            .chain(SEQUENCE_SEEDS.iter().flat_map(|s| {
                (0..setup.sequence_frames).map(move |k| format!("seed{s}-{k:03}.exr"))
            }))
            .collect();
    if let Some(folder) = &folder
        && names.iter().all(|n| folder.join(n).is_file())
    {
        let mut images = names
            .iter()
            .map(|n| read_exr(&folder.join(n)))
            .collect::<Result<Vec<_>, _>>()?
            .into_iter();
        let still = images.next().unwrap_or_else(|| empty(setup));
        let frames = setup.sequence_frames as usize;
        let first: Vec<HdrImage> = images.by_ref().take(frames).collect();
        let second: Vec<HdrImage> = images.collect();
        return Ok(Truths {
            still,
            sequences: [first, second],
            updates,
        });
    }
    let params = |seed: u32| ReferenceParams {
        width: setup.extent[0],
        height: setup.extent[1],
        jitter: false,
        emissive_lighting: false,
        seed,
        ..ReferenceParams::default()
    };
    let mut tracer = PathTracer::new(device, scene, setup.time, &params(0))?;
    tracer.update(&FrameUpdate::at(setup.time))?;
    tracer.accumulate(setup.truth_spp)?;
    let still = tracer.read()?.full;
    traced("still");
    let mut sequences: [Vec<HdrImage>; 2] = [Vec::new(), Vec::new()];
    for (seed, frames) in SEQUENCE_SEEDS.iter().zip(&mut sequences) {
        let mut tracer = PathTracer::new(device, scene, setup.time, &params(*seed))?;
        for update in &updates {
            tracer.update(update)?;
            tracer.accumulate(setup.sequence_spp)?;
            frames.push(tracer.read()?.full);
            traced(&format!("sequence seed {seed}"));
        }
    }
    if let Some(folder) = &folder {
        std::fs::create_dir_all(folder).map_err(|source| LabError::Io {
            path: folder.clone(),
            source,
        })?;
        let all = std::iter::once(&still).chain(sequences.iter().flatten());
        for (name, image) in names.iter().zip(all) {
            write_exr(&folder.join(name), image)?;
        }
    }
    Ok(Truths {
        still,
        sequences,
        updates,
    })
}

/// A black image of the setup's size.
fn empty(setup: &LabSetup) -> HdrImage {
    HdrImage {
        width: setup.extent[0],
        height: setup.extent[1],
        texels: vec![[0.0; 4]; (setup.extent[0] * setup.extent[1]) as usize],
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn frame(v: f32) -> HdrImage {
        HdrImage {
            width: 1,
            height: 1,
            texels: vec![[v, v, v, 1.0]],
        }
    }

    #[test]
    fn the_noise_of_two_seeds_is_taken_out() {
        // The true light ramps (no flicker); each seed adds its own noise.
        let a: Vec<HdrImage> = [1.0, 1.1, 1.2, 1.3, 1.4]
            .iter()
            .zip([0.05, -0.05, 0.05, -0.05, 0.05])
            .map(|(v, n)| frame(v + n))
            .collect();
        let b: Vec<HdrImage> = [1.0, 1.1, 1.2, 1.3, 1.4]
            .iter()
            .zip([-0.05, 0.05, 0.05, 0.05, -0.05])
            .map(|(v, n)| frame(v + n))
            .collect();
        assert!(flicker(&a) > 0.1);
        assert!(noise_free_flicker(&a, &b) < 0.5 * flicker(&a));
        // Without noise both agree, and a pop is seen by both.
        let pop: Vec<HdrImage> = [1.0, 1.0, 2.0, 1.0, 1.0]
            .iter()
            .map(|&v| frame(v))
            .collect();
        assert!((noise_free_flicker(&pop, &pop) - flicker(&pop)).abs() < 1e-12);
    }

    #[test]
    fn the_primary_light_turns_about_the_centre() {
        let scene = Scene::builtin("cornell-box").unwrap();
        let setup = LabSetup {
            sequence_frames: 3,
            degrees_per_frame: 90.0,
            ..LabSetup::default()
        };
        let updates = sequence_updates(&scene, &setup);
        assert_eq!(updates.len(), 3);
        let i = primary_light(&scene).unwrap();
        assert!(
            updates
                .iter()
                .all(|u| u.lights.len() == 1 && u.lights[0].0 == i)
        );
        // Frame 0 is the light as it is; frame 2 is turned by 180° about the x axis through
        // the centre: the same x, y and z mirrored about the centre.
        let p0 = Vec3::from_array(updates[0].lights[0].1.position);
        let p2 = Vec3::from_array(updates[2].lights[0].1.position);
        let pose = scene.pose_at(0.0);
        let b = scene.pose_bounds(&pose);
        let c = 0.5 * (b.min + b.max);
        assert!((p0.x - p2.x).abs() < 1e-4);
        let (d0, d2) = (p0 - c, p2 - c);
        assert!(
            (d0.y + d2.y).abs() < 1e-4 && (d0.z + d2.z).abs() < 1e-4,
            "{p0} {p2}"
        );
        assert!(d0.y.abs() > 0.1, "the light sits off the axis: it moves");
    }
}
