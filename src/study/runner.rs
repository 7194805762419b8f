//! The study's renderer: the G-buffer and the AAF passes of one scene on the render graph
//! directly (not through [`crate::Renderer`], which reads back only the composited frame), with
//! the per-pixel buffers the study needs read back and each pass timed on the host.

use std::time::Instant;

use shine_gpu::{Buffer, BufferDesc, Device, MemoryLocation, Sampler, vk};
use shine_graph::{Executor, ExternalState};
use shine_scene::Scene;

use super::metrics::{self, ImageError};
use super::{Progress, StudyError};
use crate::frame::RenderError;
use crate::frame::motion::MotionState;
use crate::gpu_scene::GpuScene;
use crate::passes::aaf::{self, AafParams, AafScene};
use crate::passes::gbuffer::{self, View};

/// The names of the AAF passes, in frame order (their host times make AAF's frame).
pub const AAF_PASSES: [&str; 5] = [
    "aaf_sample_first",
    "aaf_beta",
    "aaf_sample_second",
    "aaf_filter_x",
    "aaf_filter_y",
];

/// One AAF frame read back: per pixel, row-major.
#[derive(Debug, Clone)]
pub struct AafFrame {
    /// The indirect light (`kd` × filtered irradiance / π), linear RGB.
    pub indirect: Vec<[f32; 3]>,
    /// Samples taken (0: background).
    pub samples: Vec<f32>,
    /// Filter width β in world units (0: no filter).
    pub beta: Vec<f32>,
    /// Host time of every pass of the frame, in milliseconds, in the order they ran (each
    /// pass submitted alone: `Executor::execute_serialized`).
    pub passes: Vec<(String, f64)>,
    /// Host time of the whole frame's submissions (graph compilation and readback included).
    pub wall_ms: f64,
}

impl AafFrame {
    /// Milliseconds spent in the passes whose names are in `names`.
    pub fn time_ms(&self, names: &[&str]) -> f64 {
        self.passes
            .iter()
            .filter(|(name, _)| names.contains(&name.as_str()))
            .map(|(_, ms)| ms)
            .sum()
    }

    /// Milliseconds of the AAF passes ([`AAF_PASSES`]) of this frame.
    pub fn aaf_ms(&self) -> f64 {
        self.time_ms(&AAF_PASSES)
    }
}

/// The buffers a frame's outputs are copied into (kept for the runner's life).
struct Readback {
    indirect: Buffer,
    sums: Buffer,
    widths: Buffer,
    position: Buffer,
}

/// Renders the AAF passes of one scene, at one size, over and over with different parameters.
pub struct AafRunner {
    device: Device,
    executor: Executor,
    scene: GpuScene,
    motion: MotionState,
    sampler: Sampler,
    extent: [u32; 2],
    camera: View,
    readback: Readback,
    /// Linear view depth of every pixel (0: background), from the first frame.
    depth: Option<Vec<f32>>,
}

impl AafRunner {
    /// Uploads `scene` at time `t` for frames of `extent` pixels.
    pub fn new(
        device: &Device,
        scene: &Scene,
        t: f32,
        extent: [u32; 2],
    ) -> Result<Self, StudyError> {
        let gpu = GpuScene::upload(device, scene, t).map_err(RenderError::from)?;
        let sampler = Sampler::new(
            device,
            &vk::SamplerCreateInfo::default()
                .mag_filter(vk::Filter::LINEAR)
                .min_filter(vk::Filter::LINEAR)
                .address_mode_u(vk::SamplerAddressMode::REPEAT)
                .address_mode_v(vk::SamplerAddressMode::REPEAT)
                .address_mode_w(vk::SamplerAddressMode::CLAMP_TO_EDGE)
                .max_lod(0.0),
        )
        .map_err(RenderError::from)?;
        let pixels = u64::from(extent[0]) * u64::from(extent[1]);
        let buffer = |name, bytes_per_pixel: u64| {
            Buffer::new(
                device,
                &BufferDesc {
                    name,
                    size: pixels * bytes_per_pixel,
                    usage: vk::BufferUsageFlags::TRANSFER_DST | vk::BufferUsageFlags::TRANSFER_SRC,
                    location: MemoryLocation::GpuOnly,
                },
            )
            .map_err(RenderError::from)
        };
        let readback = Readback {
            indirect: buffer("study indirect", 8)?,
            sums: buffer("study sums", crate::passes::aaf::SUMS_BYTES)?,
            widths: buffer("study widths", 8)?,
            position: buffer("study position", 16)?,
        };
        let camera = gbuffer::camera_view(&gpu.state, extent[0], extent[1]);
        Ok(Self {
            device: device.clone(),
            executor: Executor::new(device, 1).map_err(RenderError::from)?,
            scene: gpu,
            motion: MotionState::new(device)?,
            sampler,
            extent,
            camera,
            readback,
            depth: None,
        })
    }

    /// Width and height of the frames.
    pub fn extent(&self) -> [u32; 2] {
        self.extent
    }

    /// The world-space size of a pixel at linear depth `z` is `z · f[0] + f[1]`
    /// ([`aaf::footprint`]).
    pub fn footprint(&self) -> [f32; 2] {
        aaf::footprint(&self.camera, self.extent[1])
    }

    /// Linear view depth of every pixel (0: background); `None` before the first frame.
    pub fn depth(&self) -> Option<&[f32]> {
        self.depth.as_deref()
    }

    /// Renders the G-buffer and the AAF passes with `params`, each pass submitted alone and
    /// timed on the host, and reads the indirect light, the sample counts and β back.
    pub fn render(&mut self, params: &AafParams) -> Result<AafFrame, StudyError> {
        let start = Instant::now();
        let [w, h] = self.extent;
        let mut rg = self.executor.begin_frame();
        let handles = self.scene.declare(&mut rg).map_err(RenderError::from)?;
        // A still camera: no motion.
        let motion_view = self
            .motion
            .declare(&mut rg, self.camera.view_proj(), self.extent)?;
        let g = gbuffer::gbuffer(
            &mut rg,
            &handles,
            &self.camera,
            &motion_view,
            self.extent,
            self.sampler.raw(),
        );
        let light_count = u32::try_from(self.scene.state.lights.len())
            .map_err(|_| StudyError::Invalid("too many lights".into()))?;
        let scene = AafScene {
            handles: &handles,
            bvh: &handles.trace,
            light_count,
            size: aaf::scene_size(self.scene.state.bounds),
            texture_sampler: self.sampler.raw(),
        };
        let out = aaf::aaf(&mut rg, &g, &scene, &self.camera, params).map_err(RenderError::from)?;
        let read_by_copy = ExternalState::new(
            vk::PipelineStageFlags2::COPY,
            vk::AccessFlags2::TRANSFER_READ,
            vk::ImageLayout::UNDEFINED,
        );
        let rb = &self.readback;
        let mut import =
            |buffer: &Buffer| rg.import_gpu_buffer(buffer, ExternalState::UNDEFINED, read_by_copy);
        let (mut indirect, mut sums, mut widths, mut position) = (
            import(&rb.indirect),
            import(&rb.sums),
            import(&rb.widths),
            import(&rb.position),
        );
        rg.copy_image_to_buffer("study read indirect", &out.indirect, &mut indirect);
        rg.copy_buffer("study read sums", &out.sums, &mut sums);
        rg.copy_buffer("study read widths", &out.widths, &mut widths);
        if self.depth.is_none() {
            rg.copy_image_to_buffer("study read position", &g.position, &mut position);
        }
        let (_, timings) = self
            .executor
            .execute_serialized(rg)
            .map_err(RenderError::from)?;
        let passes = timings
            .into_iter()
            .map(|t| (t.name, (t.end_ns - t.begin_ns) / 1e6))
            .collect();

        let pixels = w as usize * h as usize;
        let read = |buffer: &Buffer| -> Result<Vec<u8>, StudyError> {
            let bytes = self.device.read_buffer(buffer).map_err(RenderError::from)?;
            Ok(bytes)
        };
        let halves: Vec<u16> = bytemuck::pod_collect_to_vec(&read(&rb.indirect)?);
        let sums: Vec<[f32; 4]> = bytemuck::pod_collect_to_vec(&read(&rb.sums)?);
        let widths: Vec<[f32; 2]> = bytemuck::pod_collect_to_vec(&read(&rb.widths)?);
        if halves.len() != pixels * 4
            || sums.len() != pixels * crate::passes::aaf::SUMS_STRIDE as usize
            || widths.len() != pixels
        {
            return Err(StudyError::Invalid(format!(
                "readback of a {w}×{h} frame has the wrong size"
            )));
        }
        if self.depth.is_none() {
            let position: Vec<[f32; 4]> = bytemuck::pod_collect_to_vec(&read(&rb.position)?);
            self.depth = Some(position.iter().map(|p| p[3]).collect());
        }
        Ok(AafFrame {
            indirect: halves
                .chunks_exact(4)
                .map(|t| [f16_to_f32(t[0]), f16_to_f32(t[1]), f16_to_f32(t[2])])
                .collect(),
            samples: sums
                .iter()
                .step_by(crate::passes::aaf::SUMS_STRIDE as usize)
                .map(|s| s[3])
                .collect(),
            beta: widths.iter().map(|f| f[0]).collect(),
            passes,
            wall_ms: start.elapsed().as_secs_f64() * 1e3,
        })
    }
}

/// A curve point's renders, before the report's definitions are applied.
pub(super) struct Measured {
    /// Average samples per non-background pixel.
    pub spp: f64,
    /// The error against the truth (MSE and energy averaged over the renders).
    pub error: ImageError,
    /// The least time over the renders, ms.
    pub time_ms: f64,
    /// The last render.
    pub last: AafFrame,
}

/// The truth a render is measured against.
pub(super) struct Target<'a> {
    /// The truth image.
    pub truth: &'a [[f32; 3]],
    /// Non-background pixels.
    pub mask: &'a [bool],
    /// The truth's mean over the mask and channels.
    pub mean: f64,
}

/// The runner with the study's seed sequence: every render gets the next seed.
pub(super) struct Bench {
    /// The renderer.
    pub runner: AafRunner,
    /// The last seed used.
    pub seed: u32,
    /// Renders per measurement.
    pub repeats: u32,
}

impl Bench {
    /// Renders `params` with the next seed.
    pub fn render(&mut self, params: AafParams) -> Result<AafFrame, StudyError> {
        self.seed = self.seed.wrapping_add(1);
        self.runner.render(&AafParams {
            seed: self.seed,
            ..params
        })
    }

    /// Renders `params` `repeats` times: the mean MSE, energy ratio and spp, and the least
    /// `time` over the renders.
    pub fn measure(
        &mut self,
        params: AafParams,
        target: &Target<'_>,
        time: &dyn Fn(&AafFrame) -> f64,
        what: &str,
        progress: &mut dyn Progress,
    ) -> Result<Measured, StudyError> {
        let (mut mse, mut energy, mut spp, mut time_ms) = (0.0, 0.0, 0.0, f64::INFINITY);
        let mut last = None;
        for _ in 0..self.repeats {
            let frame = self.render(params)?;
            let error = metrics::image_error(&frame.indirect, target.truth, target.mask)
                .ok_or_else(|| {
                    StudyError::NothingToMeasure("the truth is black on every pixel".into())
                })?;
            mse += error.mse;
            energy += error.energy_ratio;
            spp += metrics::mean_samples(&frame.samples, target.mask);
            time_ms = time_ms.min(time(&frame));
            last = Some(frame);
            progress.advance(1, what);
        }
        let last = last.ok_or_else(|| StudyError::Invalid("no render".into()))?;
        let r = f64::from(self.repeats);
        let mse = mse / r;
        Ok(Measured {
            spp: spp / r,
            error: ImageError {
                mse,
                relative_rmse: mse.sqrt() / target.mean,
                energy_ratio: energy / r,
            },
            time_ms,
            last,
        })
    }
}

/// IEEE half bits → f32 (exact; what an RGBA16F readback holds).
pub fn f16_to_f32(h: u16) -> f32 {
    let sign = if h & 0x8000 != 0 { -1.0 } else { 1.0 };
    let exponent = i32::from((h >> 10) & 0x1f);
    let mantissa = f32::from(h & 0x3ff);
    match exponent {
        0 => sign * mantissa * 2f32.powi(-24),
        31 if mantissa == 0.0 => sign * f32::INFINITY,
        31 => f32::NAN,
        _ => sign * (1.0 + mantissa / 1024.0) * 2f32.powi(exponent - 15),
    }
}

#[cfg(test)]
mod tests {
    use super::f16_to_f32;

    #[test]
    fn halves_decode() {
        assert_eq!(f16_to_f32(0x3c00), 1.0);
        assert_eq!(f16_to_f32(0xc000), -2.0);
        assert_eq!(f16_to_f32(0x0001), 2f32.powi(-24));
        assert_eq!(f16_to_f32(0x7bff), 65504.0);
        assert!(f16_to_f32(0x7c00).is_infinite());
        assert!(f16_to_f32(0x7e00).is_nan());
    }
}
