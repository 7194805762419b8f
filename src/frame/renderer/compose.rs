//! The composition of a frame, in one place: the G-buffer, shadows and direct light of a full
//! frame, and the techniques' indirect light, which a full frame and a GI context (a host's
//! G-buffer, `crate::embed`) share.

use super::Renderer;
use super::sky_light;
use crate::frame::aaf::AafInputs;
use crate::frame::error::RenderError;
use crate::frame::hvl::HvlInputs;
use crate::frame::igi::IgiInputs;
use crate::frame::params::FrameParams;
use crate::frame::shadows::ShadowState;
use crate::gpu_scene::{SAMPLED_READ, SceneHandles};
use crate::passes::aaf::scene_size;
use crate::passes::composite::{self, Component, CompositeOutputs};
use crate::passes::cubes;
use crate::passes::debug_view::DebugSources;
use crate::passes::gbuffer::{self, GBuffer, View};
use crate::passes::gi_add::gi_add;
use crate::passes::hvl::{Distribution, near};
use crate::passes::sample_history::SampleSetup;
use crate::passes::traced_scene::TracedScene;
use crate::passes::{accumulate, direct, history, receivers, rsm, upsample};
use crate::passes::{denoise, specular};
use shine_graph::{Handle, Image, ImageDesc, RenderGraph, vk};

impl Renderer {
    /// Declares every pass of a frame: the G-buffer, shadows and direct light, the techniques'
    /// indirect light ([`Renderer::declare_indirect`]), and the composite. Returns the HDR and
    /// LDR images.
    pub(super) fn declare_frame(
        &mut self,
        rg: &mut RenderGraph,
        p: &FrameParams,
    ) -> Result<CompositeOutputs, RenderError> {
        let declared = self.declare_passes(rg, p);
        if declared.is_err() {
            self.forget_history();
        }
        declared
    }

    /// Starts every history over (a camera cut): the next frame carries nothing from earlier
    /// ones (previous vertices and camera, accumulation, amortised schedules, AAF's and the
    /// cube maps' histories). What was uploaded once (tables) stays.
    pub(crate) fn reset_history(&mut self) {
        self.restart_indirect();
        if let Some(scene) = self.scene.as_mut() {
            scene.gpu.forget_previous();
        }
        self.motion.reset();
        self.taa.reset();
        self.exposure.reset();
    }

    /// Starts the indirect light's histories over (a light cut): accumulation and the
    /// techniques' amortised caches, not the camera's (motion, TAA, exposure, previous
    /// vertices), which a change of light leaves valid.
    pub(super) fn restart_indirect(&mut self) {
        if let Some(scene) = self.scene.as_mut() {
            scene.proxy.reset();
            scene.cubes.reset();
        }
        self.accumulate.reset();
        self.hvl.reset();
        self.igi.reset();
        self.aaf.reset();
    }

    /// After a graph that is dropped unrun: what that frame meant to leave for the next one
    /// (previous vertices, camera, HVL history) or upload once (tables) was never written.
    pub(super) fn forget_history(&mut self) {
        self.reset_history();
        self.hvl.forget_uploads();
        self.igi.forget_uploads();
        if let Some(scene) = self.scene.as_mut() {
            scene.proxy.forget_uploads();
            scene.gpu.forget_uploads();
        }
    }

    /// The passes of [`Renderer::declare_frame`].
    fn declare_passes(
        &mut self,
        rg: &mut RenderGraph,
        output: &FrameParams,
    ) -> Result<CompositeOutputs, RenderError> {
        // Every pass before the composite renders at the supersampled size.
        let p = &output.at_render_extent();
        let textures = self.texture_sampler(p);
        let scene = self.scene.as_mut().ok_or(RenderError::NoScene)?;
        let handles = scene.gpu.declare(rg)?;
        let frame = &scene.gpu.state;
        let shadows = ShadowState::prepare(
            &self.device,
            self.shadows.take(),
            frame,
            p.shadow_size,
            p.shadow.pcf_radius,
        )?;
        let shadows = self.shadows.insert(shadows);
        let [width, height] = p.extent;
        // TAA: the camera's own jitter plus this frame's point of the Halton cycle.
        let jitter = match p.taa {
            Some(_) => {
                let [jx, jy] = accumulate::taa_jitter(rg.frame());
                [frame.jitter[0] + jx, frame.jitter[1] + jy]
            }
            None => frame.jitter,
        };
        let camera = gbuffer::jittered_camera_view(frame, width, height, jitter);
        let unjittered = gbuffer::unjittered_camera_view(frame, width, height).view_proj();
        let motion_view = self.motion.declare(rg, unjittered, p.extent)?;
        let g = gbuffer::gbuffer(rg, &handles, &camera, &motion_view, p.extent, textures);
        // Kept for the next frame (its previous normal and depth); the previous frame's is
        // the accumulation's disocclusion test.
        let geometry_then = history::gbuffer_history(rg, &g);
        let light_count = light_count(&scene.gpu.state)?;
        let atlas = shadows.declare(rg, &handles)?;
        let background = direct::Background {
            environment: rg.import_gpu_image(&scene.environment, SAMPLED_READ, SAMPLED_READ),
            sampler: self.environment_sampler.raw(),
        };
        let direct = direct::direct(
            rg,
            &g,
            &handles,
            light_count,
            &atlas,
            &camera,
            &background,
            p.shadow,
            self.nearest.raw(),
        );
        let direct = self
            .taa
            .apply(rg, p.taa, p.extent, Some(direct), &g, |_| geometry_then)?
            .unwrap_or(direct);
        let indirect = self
            .declare_indirect(rg, p, &handles, &g, &camera, None)?
            .summed(rg)?;
        let indirect = self
            .accumulate
            .apply(rg, p.history, p.extent, indirect, &g, |_| geometry_then)?;
        // `[output] component`: the composite sums its two inputs; one of them alone shows a part.
        // The position goes through an RGBA16F copy, the composite's input format.
        let position;
        let (first, second) = match (p.component, indirect.as_ref()) {
            (Component::Full, indirect) => (&direct, indirect),
            (Component::Direct, _) => (&direct, None),
            (Component::Normal, _) => (&g.normal, None),
            (Component::GeometricNormal, _) => (&g.geometric_normal, None),
            (Component::Position, _) => {
                let mut half = rg.create_image(
                    "position_half",
                    ImageDesc::new_2d(vk::Format::R16G16B16A16_SFLOAT, g.extent[0], g.extent[1]),
                );
                rg.blit_image("position_half", &g.position, &mut half, vk::Filter::NEAREST);
                position = half;
                (&position, None)
            }
            (Component::Indirect, Some(indirect)) => (indirect, None),
            (Component::Indirect, None) => {
                return Err(RenderError::Invalid(
                    "output.component = indirect needs a GI technique (this frame has none)".into(),
                ));
            }
        };
        let exposure = self
            .exposure
            .apply(rg, p.composite.auto_exposure, first, second);
        Ok(composite::composite(
            rg,
            first,
            second,
            exposure.as_ref(),
            output.extent,
            &p.composite,
        ))
    }

    /// The scene textures' sampler of `p`: trilinear (a level finer under TAA), or level 0
    /// without mipmaps.
    pub(super) fn texture_sampler(&self, p: &FrameParams) -> shine_gpu::vk::Sampler {
        match (p.mipmaps, p.taa.is_some()) {
            (true, false) => self.textures.raw(),
            (true, true) => self.textures_taa.raw(),
            (false, _) => self.textures_level0.raw(),
        }
    }

    /// The indirect light of the surfaces in `g`, seen from `camera`: each technique of `p`
    /// prepares its persistent state, then the primary light's RSM, the receiver-resolution
    /// techniques (HVL, proxies) and their upsample, and the full-resolution ones (IGI, AAF)
    /// are declared and summed. The proxies and the sky are lit by `host_sh` (an SH buffer,
    /// laid out as `EnvironmentSh::gpu_data`, at the proxies' order or the sky's
    /// `sky::BANDS`) when given, else by the scene's environment. Returns
    /// full-resolution outgoing indirect radiance (RGBA16F), or `None` when `p` has no
    /// technique.
    pub(super) fn declare_indirect(
        &mut self,
        rg: &mut RenderGraph,
        p: &FrameParams,
        handles: &SceneHandles,
        g: &GBuffer,
        camera: &View,
        host_sh: Option<Handle<shine_graph::Buffer>>,
    ) -> Result<Indirect, RenderError> {
        let textures = self.texture_sampler(p);
        let scene = self.scene.as_mut().ok_or(RenderError::NoScene)?;
        let frame = &scene.gpu.state;
        let receiver_extent = receivers::receiver_extent(p.extent, p.receiver_scale)?;
        let light_count = light_count(frame)?;
        let samples = SampleSetup {
            weight: p.sample_weight,
            lights: light_count.saturating_mul(crate::passes::hvl::flux::FACES_PER_LIGHT),
        };
        let hvl = p
            .hvl
            .map(|h| self.hvl.prepare(rg, h, receiver_extent, samples))
            .transpose()?;
        let igi = p
            .igi
            .map(|i| self.igi.prepare(rg, i, p.extent, samples))
            .transpose()?;
        let aaf = p
            .aaf
            .map(|a| self.aaf.prepare(rg, a, p.extent))
            .transpose()?;
        let proxy = p
            .proxy
            .as_ref()
            .map(|setup| {
                scene
                    .proxy
                    .prepare(rg, setup, &frame.pose.world, host_sh, receiver_extent)
            })
            .transpose()?;
        let cubes = match p.cubes {
            Some(params) => scene
                .cubes
                .prepare(
                    rg,
                    &frame.pose,
                    bytemuck::cast_slice(&frame.lights),
                    &params,
                )?
                .map(|inputs| (params, inputs)),
            None => None,
        };
        // What rays that meet the scene's surfaces read (the specular pass, the cubes' fill
        // and HVL's or IGI's near field): level-0 texture lookups, and the environment where
        // they escape, lighting the hits too when the scene has one.
        let near_field = p.near_field.filter(|_| hvl.is_some() || igi.is_some());
        let environment = (p.specular.is_some() || cubes.is_some() || near_field.is_some())
            .then(|| rg.import_gpu_image(&scene.environment, SAMPLED_READ, SAMPLED_READ));
        let traced = environment.as_ref().map(|environment| TracedScene {
            handles,
            bvh: &handles.trace,
            light_count,
            texture_sampler: self.textures_level0.raw(),
            environment,
            environment_sampler: self.environment_sampler.raw(),
            environment_lighting: scene.has_environment,
        });

        // HVL and IGI bounce light off RSM faces: placed by flux, every light's (the primary
        // light's first); on the paper's grid, the primary light's only (the first spot or
        // directional light). Without a light they add nothing.
        let every_light = p.hvl.is_some_and(|h| h.distribution == Distribution::Flux)
            || p.igi.is_some_and(|i| i.distribution == Distribution::Flux);
        let faces: Vec<rsm::FaceView> = match scene.gpu.primary_light() {
            Some(_) if hvl.is_none() && igi.is_none() => Vec::new(),
            Some(i) if every_light => rsm::face_views(frame, i, p.rsm_size),
            Some(i) => gbuffer::light_view(frame, i, p.rsm_size)
                .map(|view| {
                    vec![rsm::FaceView {
                        light: i as u32,
                        label: "rsm".to_owned(),
                        view,
                        size: p.rsm_size,
                    }]
                })
                .unwrap_or_default(),
            None => Vec::new(),
        };
        let rsm_faces: Vec<rsm::Rsm> = faces
            .iter()
            .map(|face| face.render(rg, handles, textures))
            .collect();
        let rsm = (!rsm_faces.is_empty()).then_some(rsm_faces.as_slice());
        // Receiver-resolution terms (HVL, proxies, the sky) share one receiver buffer and one
        // upsample; they are summed at receiver resolution first. The sky light is for frames
        // without proxies, in scenes with an environment.
        // A host's environment map (its SH in `host_sh`) lights the sky as the scene's does.
        let sky = p.sky.filter(|_| scene.has_environment || host_sh.is_some());
        let recv = if hvl.is_some()
            || proxy.is_some()
            || sky.is_some()
            || cubes.is_some()
            || near_field.is_some()
        {
            Some(receivers::receivers(rg, g, p.receiver_scale)?)
        } else {
            None
        };
        if rsm.is_none() {
            // No primary light: the HVL and IGI passes (and their history) are not in this
            // frame.
            self.hvl.reset();
            self.igi.reset();
        }
        // Sampled shadows draw new rays each frame a history averages: the indirect light's,
        // or the amortised gather's own.
        let near_radius = near_field.map_or(0.0, |n| n.range_fraction * scene_size(frame.bounds));
        let hvl_seed = match p.hvl {
            Some(h) if h.slices > 1 => rg.frame() as u32,
            _ => sky_light::history_seed(rg, p),
        };
        let hvl_low = match (hvl, rsm, &recv) {
            (Some(hvl), Some(rsm), Some(receivers)) => Some(hvl.declare(
                rg,
                &HvlInputs {
                    receivers,
                    rsm,
                    bvh: &handles.trace,
                    camera: camera.eye,
                    motion: &g.motion,
                    seed: hvl_seed,
                    near_radius,
                },
            )?),
            _ => None,
        };
        let proxy_low = match (proxy, &recv) {
            (Some(proxy), Some(receivers)) => {
                Some(proxy.declare(rg, receivers, camera.eye, &g.motion)?)
            }
            _ => None,
        };
        let (hvl_low, hvl_lights) = hvl_low.unzip();
        let hvl_low =
            sky_light::cavity_shaded(rg, p, frame.bounds, &handles.trace, recv.as_ref(), hvl_low)?;
        // HVL's or IGI's traced near field, where the gather or the VPLs left it out (after
        // the cavity shading: its rays are shadowed already). New rays each frame only when
        // the indirect light's history averages them (the amortised gather's resolve comes
        // before it). IGI's full-resolution light takes it through the receivers' upsample.
        let bounced = hvl_low.is_some() || (igi.is_some() && rsm.is_some());
        let near_light = match (near_field, &recv, &traced) {
            (Some(near), Some(receivers), Some(traced)) if bounced => Some(near::hvl_near(
                rg,
                receivers,
                traced,
                &near,
                near_radius,
                sky_light::history_seed(rg, p),
                camera,
                sky_light::light_filter(p, true),
            )?),
            _ => None,
        };
        let hvl_low = sum(rg, "hvl_near_add", hvl_low, near_light)?;
        let low = sum(rg, "gi_add", hvl_low, proxy_low)?;
        let sky_low = match (sky, &recv) {
            (Some(params), Some(receivers)) => Some(sky_light::sky_light(
                rg,
                p,
                &params,
                sky_light::SkySh {
                    host: host_sh,
                    scene: &mut scene.proxy,
                },
                &handles.trace,
                receivers,
                camera.eye,
            )?),
            _ => None,
        };
        let low = sum(rg, "sky_add", low, sky_low)?;
        // Paper 001's environment cubes light the dynamic objects' receivers instead.
        let low = match (cubes, &recv, &traced) {
            (Some((params, mut inputs)), Some(receivers), Some(traced)) => Some(cubes::cubes(
                rg,
                traced,
                &mut inputs,
                receivers,
                low.as_ref(),
                camera.eye,
                &params,
            )),
            _ => low,
        };
        let upsampled = match (low, &recv) {
            (Some(low), Some(recv)) => Some(upsample::upsample(rg, &low, recv, g, &p.upsample)?),
            _ => None,
        };
        // IGI runs at full resolution (its interleaving needs the pixel grid).
        let igi_full = match (igi, rsm) {
            (Some(igi), Some(rsm)) => Some(igi.declare(
                rg,
                &IgiInputs {
                    gbuffer: g,
                    rsm,
                    bvh: &handles.trace,
                    camera: camera.eye,
                    near_radius,
                },
            )?),
            _ => None,
        };
        let aaf_full = match aaf {
            Some(aaf) => Some(aaf.declare(
                rg,
                &AafInputs {
                    gbuffer: g,
                    scene: handles,
                    bvh: &handles.trace,
                    light_count,
                    bounds: frame.bounds,
                    camera,
                    // Ray hits read level 0 (no derivatives there, and lavapipe's
                    // anisotropic path is ~300× slower for explicit-LOD lookups).
                    texture_sampler: self.textures_level0.raw(),
                },
            )?),
            None => None,
        };
        let ((igi_full, igi_lights), (aaf_full, aaf_spp)) = (igi_full.unzip(), aaf_full.unzip());
        // `igi,proxy` and `aaf,proxy`: both full-resolution indirect terms summed (settings
        // allow at most one of hvl, igi and aaf).
        let full = igi_full.or(aaf_full);
        let techniques = sum(rg, "gi_add_full", upsampled, full)?;
        // The sharp part of the glossy lobes, which the techniques above leave out.
        // Filtered (`[denoise]`) in the lobe's footprint: one or two rays a pixel are grainy.
        let reflections = match (p.specular, &traced) {
            (Some(params), Some(traced)) => {
                let raw = specular::specular(
                    rg,
                    g,
                    traced,
                    camera.eye,
                    &params,
                    sky_light::history_seed(rg, p),
                    p.denoise.is_some(),
                )?;
                Some(match p.denoise {
                    Some(denoise) => {
                        denoise::specular(rg, g, &raw, camera, params.limit, &denoise)?
                    }
                    None => raw,
                })
            }
            _ => None,
        };
        Ok(Indirect {
            techniques,
            reflections,
            debug: DebugSources {
                receivers: recv,
                rsm_flux: rsm_faces.first().map(|face| face.flux),
                lights: hvl_lights.or(igi_lights),
                aaf: aaf_spp,
                indirect: techniques,
            },
        })
    }
}

/// A frame's indirect light in its two parts.
pub(super) struct Indirect {
    /// The GI techniques' light: diffuse, and the glossy lobes the SH terms carry (those
    /// rougher than `specular.limit`, faded in below it).
    pub techniques: Option<Handle<Image>>,
    /// The traced specular reflections of the smoother lobes (denoised), when they run.
    pub reflections: Option<Handle<Image>>,
    /// What the techniques declared that a GI context's debug view shows.
    pub debug: DebugSources,
}

impl Indirect {
    /// Both parts summed: the frame's whole indirect light.
    pub(super) fn summed(self, rg: &mut RenderGraph) -> Result<Option<Handle<Image>>, RenderError> {
        sum(rg, "specular_add", self.techniques, self.reflections)
    }
}

/// `a + b` (a `gi_add` pass called `name`) when both are there, else the one that is.
fn sum(
    rg: &mut RenderGraph,
    name: &str,
    a: Option<Handle<Image>>,
    b: Option<Handle<Image>>,
) -> Result<Option<Handle<Image>>, RenderError> {
    Ok(match (a, b) {
        (Some(a), Some(b)) => Some(gi_add(rg, name, &a, &b)?),
        (a, b) => a.or(b),
    })
}

/// The number of lights of `frame`, as the passes take it.
fn light_count(frame: &crate::gpu_scene::FrameState) -> Result<u32, RenderError> {
    u32::try_from(frame.lights.len()).map_err(|_| RenderError::Invalid("too many lights".into()))
}
