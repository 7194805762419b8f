//! The glTF 2.0 loader: `.gltf` (+ `.bin`, images, data URIs) and `.glb` into a [`Scene`].
//!
//! Bad input never panics: structural problems (malformed JSON or GLB, references to
//! elements that do not exist, buffers too short for their accessors, out-of-range vertex
//! indices, NaN or infinite positions, node cycles, unsupported required extensions) are an
//! [`Error`] naming the file and the element. Problems the scene survives are warnings in
//! [`Scene::warnings`]: a missing or undecodable image (the material keeps its factors),
//! non-triangle primitives (skipped), morph target tangent deltas (ignored), a mesh with
//! joints on a node without a skin or the reverse (drawn rigid), and the defaults below.
//!
//! Skins and morph targets are loaded (glTF 2.0 §3.7.2.2, §3.7.3): joints, inverse bind
//! matrices (one per joint), `JOINTS_0` (unsigned byte or short), `WEIGHTS_0` (float or
//! normalised unsigned byte or short, divided by their sum), POSITION and NORMAL deltas,
//! mesh and node weights, and weight animation channels. Bad skinning data is an error: an
//! empty joint list, a joint that is not a node, a `JOINTS_0` value outside the skin, a
//! negative, NaN or infinite weight or four zero weights, an inverse bind count that is not
//! the joint count, `JOINTS_0` without `WEIGHTS_0` or the reverse, weight counts that do not
//! match the morph targets.
//!
//! Defaults:
//! - no camera: a perspective camera ([`DEFAULT_YFOV`]) on the +Z side of the scene bounds,
//!   looking at their centre down -Z, far enough to frame them; a warning is recorded.
//! - no punctual light and no environment: a directional "sun" of [`DEFAULT_SUN_LUX`] lux,
//!   white, shining along [`DEFAULT_SUN_DIRECTION`]; a warning is recorded. A scene with an
//!   environment (see [`crate::environment`]) and no punctual light is lit by the environment
//!   alone, without a warning.
//! - missing normals: smooth (area-weighted) normals over shared vertex indices.
//! - missing tangents: MikkTSpace tangents (from UV0) when the primitive's material has a
//!   normal map; otherwise (no normal map, or no UV0) any unit vector perpendicular to the
//!   normal, as tangents then only need to be well-formed.
//! - missing material: the glTF default material (appended last in [`Scene::materials`]).

mod accessor;
mod animations;
mod cameras;
mod ctx;
mod defaults;
mod deform;
mod document;
mod extras;
mod geometry;
mod lights;
mod materials;
mod meshes;
mod nodes;
mod primitive;
mod skins;
mod textures;
pub(crate) mod uri;

use std::path::Path;

use glam::{Vec3, Vec4};

use crate::error::{Error, Result};
use crate::scene::Scene;
use ctx::Ctx;
pub(crate) use geometry::VertexData;
use textures::TextureLoader;

/// Direction the default sun shines along (world space, unit).
pub const DEFAULT_SUN_DIRECTION: Vec3 = Vec3::new(-0.408_248_3, -0.816_496_6, -0.408_248_3);
/// Illuminance of the default sun, in lux.
pub const DEFAULT_SUN_LUX: f32 = 3.0;
/// Vertical field of view of the default camera, in radians (45°).
pub const DEFAULT_YFOV: f32 = std::f32::consts::FRAC_PI_4;

/// glTF extensions the loader understands; a file *requiring* any other is rejected.
pub const SUPPORTED_EXTENSIONS: &[&str] =
    &["KHR_lights_punctual", "KHR_materials_emissive_strength"];

/// Loads a `.gltf` or `.glb` file. Relative URIs resolve against the file's directory.
pub fn load(path: impl AsRef<Path>) -> Result<Scene> {
    let path = path.as_ref();
    let bytes = std::fs::read(path).map_err(|source| Error::Read {
        path: path.to_path_buf(),
        source,
    })?;
    load_slice(&bytes, path.parent(), &path.display().to_string())
}

/// Loads glTF JSON or GLB bytes. `base_dir` resolves relative URIs (`None`: only embedded
/// and data-URI resources are allowed); `name` names the data in messages.
pub fn load_slice(bytes: &[u8], base_dir: Option<&Path>, name: &str) -> Result<Scene> {
    let gltf_error = |source| Error::Gltf {
        file: name.to_string(),
        source,
    };
    let parsed = gltf::Gltf::from_slice_without_validation(bytes).map_err(gltf_error)?;
    let mut ctx = Ctx::new(name);
    document::check_attribute_accessors(&ctx, parsed.document.as_json())?;
    let gltf_doc = gltf::Document::from_json(parsed.document.into_json()).map_err(gltf_error)?;
    let doc = &gltf_doc;
    document::check_extensions(&mut ctx, doc)?;
    let buffers = document::load_buffers(&ctx, doc, parsed.blob.as_deref(), base_dir)?;

    let mut textures = TextureLoader::new(doc.as_json(), base_dir);
    let mut materials = materials::load_materials(&mut ctx, &buffers, &mut textures, doc);
    let default_material = materials.default_index();
    let meshes = meshes::load_meshes(
        &mut ctx,
        &buffers,
        doc,
        &materials.materials,
        default_material,
    )?;
    if meshes.uses_default_material {
        materials.push_default();
    }

    let (nodes, roots) = nodes::load_nodes(&mut ctx, doc)?;
    let mut scene = Scene {
        source: name.to_string(),
        nodes,
        roots,
        meshes: meshes.meshes,
        skins: skins::load_skins(&ctx, &buffers, doc)?,
        materials: materials.materials,
        material_names: materials.names,
        textures: textures.into_textures(),
        ..Scene::default()
    };
    skins::check_nodes(&mut ctx, &mut scene)?;
    scene.animations = animations::load_animations(&ctx, &buffers, doc)?;
    let world = scene.rest_world_transforms();
    lights::load_lights(&mut ctx, doc, &mut scene, &world)?;
    cameras::load_cameras(&ctx, doc, &mut scene, &world)?;
    scene.environment = extras::load_environment(&ctx, doc, base_dir)?;
    scene.proxies = extras::load_proxies(&ctx, doc, &scene)?;
    defaults::add_defaults(&mut ctx, &mut scene, &world);
    scene.warnings = ctx.warnings;
    Ok(scene)
}

/// MikkTSpace tangents for `v`, splitting vertices where tangents disagree.
pub(crate) fn tangents_for(v: &mut VertexData) -> Vec<Vec4> {
    geometry::mikktspace_tangents(v).0
}
