//! `rsm`: the reflective shadow map of the primary light (Dachsbacher and Stamminger 2005), the
//! source of the HVLs (paper 003) and of IGI's VPLs (paper 000); docs/frame.md, "Reflective
//! shadow map", fixes its formats and units.

use glam::Vec3;
use shine_graph::{ColorLoad, DepthLoad, Handle, Image, ImageDesc, RenderGraph};

use super::gbuffer::{View, light_view, scene_pipeline};
use super::shadows::{CUBE_FACES, cube_face};
use crate::gpu::vk;
use crate::gpu_scene::{FrameState, SceneHandles};
use crate::shaders;
use shine_scene::LightKind;

/// Default RSM side: 512² texels serve 400 HVLs with room to spare.
pub const DEFAULT_SIZE: u32 = 512;

/// RSM sides S in texels (S×S per primary light).
pub const SIZE: std::ops::RangeInclusive<u32> = 16..=4096;

/// The reflective shadow map of one primary light (docs/frame.md, "Reflective shadow map").
#[derive(Debug, Clone, Copy)]
pub struct Rsm {
    /// `rsm_position`, RGBA32F: xyz world position, w = 1 (0 where empty).
    pub position: Handle<Image>,
    /// `rsm_normal`, RGBA16F: xyz unit world normal.
    pub normal: Handle<Image>,
    /// `rsm_flux`, RGBA32F: rgb reflected flux Φ of the texel (W).
    pub flux: Handle<Image>,
    /// Position of the primary light (perspective) or the RSM's eye (orthographic).
    pub light_position: Vec3,
    /// Unit axis of the RSM's view (the light's direction for a directional light).
    pub light_direction: Vec3,
    /// How the RSM was projected.
    pub projection: RsmProjection,
    /// Side S of the RSM in texels.
    pub size: u32,
    /// The index in the scene of the light this face belongs to.
    pub light: u32,
}

/// The projection of an RSM: it decides the r2 heuristic and the distance `d_j` to the light.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum RsmProjection {
    /// A point or spot light's square frustum of full field of view λ (radians, eq. 24).
    Perspective {
        /// λ.
        fov: f32,
    },
    /// A directional light's box of width W (metres) across.
    Orthographic {
        /// W.
        width: f32,
    },
}

/// Rasterises the scene from light `light` through `view` (perspective or orthographic) into a
/// new `size`² reflective shadow map (docs/frame.md); its pass and images are named after
/// `label` (`rsm`: the primary light's).
pub fn rsm(
    rg: &mut RenderGraph,
    scene: &SceneHandles,
    view: View,
    light: u32,
    size: u32,
    sampler: vk::Sampler,
    label: &str,
) -> Rsm {
    let image = |rg: &mut RenderGraph, name: &str, format| {
        rg.create_image(
            &format!("{label}_{name}"),
            ImageDesc::new_2d(format, size, size),
        )
    };
    let mut depth = image(rg, "depth", vk::Format::D32_SFLOAT);
    let mut r = Rsm {
        position: image(rg, "position", vk::Format::R32G32B32A32_SFLOAT),
        normal: image(rg, "normal", vk::Format::R16G16B16A16_SFLOAT),
        flux: image(rg, "flux", vk::Format::R32G32B32A32_SFLOAT),
        light_position: view.eye,
        light_direction: view.forward(),
        projection: if view.orthographic {
            RsmProjection::Orthographic { width: view.extent }
        } else {
            RsmProjection::Perspective { fov: view.extent }
        },
        size,
        light,
    };
    let pipeline = scene_pipeline(
        &shaders::GBUFFER_VERT_PLAIN,
        Some(&shaders::RSM_FRAG),
        &[
            vk::Format::R32G32B32A32_SFLOAT,
            vk::Format::R16G16B16A16_SFLOAT,
            vk::Format::R32G32B32A32_SFLOAT,
        ],
        None,
    );
    rg.raster(label, pipeline)
        .color(&mut r.position, ColorLoad::Clear([0.0; 4]))
        .color(&mut r.normal, ColorLoad::Clear([0.0; 4]))
        .color(&mut r.flux, ColorLoad::Clear([0.0; 4]))
        .depth(&mut depth, DepthLoad::Clear(1.0))
        .read("materials", &scene.materials)
        .read("srgb_textures", &scene.srgb_textures)
        .read("linear_textures", &scene.linear_textures)
        .read("lights", &scene.lights)
        .sampler("texture_sampler", sampler)
        .vertex_buffer(&scene.vertices)
        .index_buffer(&scene.indices, vk::IndexType::UINT32)
        .push(&view.constants(Some((size, light))))
        .draw_indexed(scene.index_count, 1);
    r
}

/// One RSM face to render: which light, through which view, at which side.
#[derive(Debug, Clone)]
pub struct FaceView {
    /// Index of the light in the scene.
    pub light: u32,
    /// Name of its pass and prefix of its images: `rsm` for the primary light, `rsm light I`
    /// for light I, a cube face's axis after it.
    pub label: String,
    /// The light's view.
    pub view: View,
    /// Side of the face in texels.
    pub size: u32,
}

impl FaceView {
    /// Rasterises this face ([`rsm`]).
    pub fn render(&self, rg: &mut RenderGraph, scene: &SceneHandles, sampler: vk::Sampler) -> Rsm {
        rsm(
            rg,
            scene,
            self.view,
            self.light,
            self.size,
            sampler,
            &self.label,
        )
    }
}

/// The faces whose RSMs feed the flux distribution: every light of `frame`, the primary light
/// (`primary`) first. A spot or directional light has one face of side `size`, as the
/// primary's RSM. A point light has six cube faces of exactly 90° and side `size / 2` (at
/// least [`SIZE`]'s minimum): they tile the sphere without overlap, so no flux is counted twice,
/// and the six hold 1.5× the texels of one spot's RSM.
pub fn face_views(frame: &FrameState, primary: usize, size: u32) -> Vec<FaceView> {
    let mut order: Vec<usize> = (0..frame.lights.len()).collect();
    if primary < order.len() {
        order.remove(primary);
        order.insert(0, primary);
    }
    let cube_side = (size / 2).max(*SIZE.start());
    let mut faces = Vec::new();
    for i in order {
        let light = &frame.lights[i];
        // The primary light's passes keep the name `rsm` (profiles, docs/frame.md).
        let label = if i == primary {
            "rsm".to_owned()
        } else {
            format!("rsm light {i}")
        };
        match light.light_kind() {
            Some(LightKind::Point) => {
                let eye = Vec3::from(light.position);
                for (axis, up, name) in CUBE_FACES {
                    let view = cube_face(frame, eye, axis, up, 1.0);
                    faces.push(FaceView {
                        light: i as u32,
                        label: format!("{label} {name}"),
                        view,
                        size: cube_side,
                    });
                }
            }
            Some(_) => {
                if let Some(view) = light_view(frame, i, size) {
                    faces.push(FaceView {
                        light: i as u32,
                        label: label.clone(),
                        view,
                        size,
                    });
                }
            }
            None => {}
        }
    }
    faces
}
