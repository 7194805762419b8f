//! The glTF 2.0 loader: `.gltf` (+ `.bin`, images, data URIs) and `.glb` into a [`Scene`].
//!
//! Bad input never panics: structural problems (malformed JSON or GLB, references to
//! elements that do not exist, buffers too short for their accessors, out-of-range vertex
//! indices, NaN or infinite positions, node cycles, unsupported required extensions) are an
//! [`Error`] naming the file and the element. Problems the scene survives are warnings in
//! [`Scene::warnings`]: a missing or undecodable image (the material keeps its factors),
//! non-triangle primitives (skipped), skins and morph targets (ignored), and the defaults
//! below.
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
mod geometry;
pub(crate) mod uri;

use std::collections::HashMap;
use std::path::Path;

use glam::{Mat4, Quat, Vec2, Vec3, Vec4};
use gltf::accessor::Dimensions;
use gltf::json::validation::Checked;
use gltf::mesh::Mode;

use crate::animation::{Animation, Channel, Interpolation, Property};
use crate::environment::{self, Environment};
use crate::error::{Error, Result};
use crate::proxies::{self, NodeProxies, ProxySource};
use crate::scene::Scene;
use crate::types::{
    Aabb, Camera, Light, LightKind, Material, Mesh, NO_TEXTURE, Node, Primitive, Projection,
    Texture, Transform,
};
use accessor::Buffers;
pub(crate) use geometry::VertexData;

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
    let mut ctx = Ctx {
        file: name,
        warnings: Vec::new(),
    };
    // gltf-json 1.4's validation indexes `accessors` by a primitive's POSITION index without a
    // bounds check (a panic on bad input), so attribute references are checked here first.
    check_attribute_accessors(&ctx, parsed.document.as_json())?;
    let document = gltf::Document::from_json(parsed.document.into_json()).map_err(gltf_error)?;
    let blob = parsed.blob;
    let doc = &document;

    for ext in doc.extensions_required() {
        if !SUPPORTED_EXTENSIONS.contains(&ext) {
            return Err(ctx.invalid(
                "extensionsRequired",
                format!(
                    "requires extension {ext}, which shine does not support (supported: {})",
                    SUPPORTED_EXTENSIONS.join(", ")
                ),
            ));
        }
    }

    for ext in doc.extensions_used() {
        if !SUPPORTED_EXTENSIONS.contains(&ext) {
            ctx.warn(
                "extensionsUsed",
                format!("extension {ext} is not supported and is ignored"),
            );
        }
    }
    let buffers = load_buffers(&ctx, doc, blob.as_deref(), base_dir)?;
    let mut textures = TextureLoader {
        root: doc.as_json(),
        base_dir,
        images: HashMap::new(),
        textures: Vec::new(),
        keys: HashMap::new(),
    };
    let mut materials = Vec::new();
    let mut material_names = Vec::new();
    for m in doc.materials() {
        materials.push(load_material(&mut ctx, &buffers, &mut textures, &m));
        material_names.push(m.name().map_or_else(
            || format!("material{}", materials.len() - 1),
            str::to_string,
        ));
    }
    let default_material = materials.len() as u32;
    let mut uses_default = false;

    // Primitives are independent: decode them (and generate normals and tangents) on all
    // cores, then gather results, warnings and the first error in file order.
    let mut jobs = Vec::new();
    let mut meshes = Vec::new();
    for mesh in doc.meshes() {
        let mesh_name = mesh
            .name()
            .map_or_else(|| format!("mesh{}", mesh.index()), str::to_string);
        for prim in mesh.primitives() {
            let element = format!(
                "meshes[{}] {:?} primitives[{}]",
                mesh.index(),
                mesh_name,
                prim.index()
            );
            let material = prim
                .material()
                .index()
                .map_or(default_material, |i| i as u32);
            uses_default |= material == default_material;
            let normal_mapped = materials
                .get(material as usize)
                .is_some_and(|m| m.normal_texture != NO_TEXTURE);
            jobs.push(PrimitiveJob {
                mesh: meshes.len(),
                prim,
                element,
                material,
                normal_mapped,
            });
        }
        meshes.push(Mesh {
            name: mesh_name,
            primitives: Vec::new(),
        });
    }
    for (job, (result, warnings)) in jobs.iter().zip(load_primitives(name, &buffers, &jobs)) {
        ctx.warnings.extend(warnings);
        if let (Some(p), Some(mesh)) = (result?, meshes.get_mut(job.mesh)) {
            mesh.primitives.push(p);
        }
    }
    if uses_default {
        materials.push(Material::default());
        material_names.push("glTF default material".to_string());
    }

    let (nodes, roots) = load_nodes(&mut ctx, doc)?;
    let mut scene = Scene {
        source: name.to_string(),
        nodes,
        roots,
        meshes,
        materials,
        material_names,
        textures: textures.textures,
        ..Scene::default()
    };
    scene.animations = load_animations(&mut ctx, &buffers, doc)?;
    let world = scene.rest_world_transforms();
    load_lights(&mut ctx, doc, &mut scene, &world)?;
    load_cameras(&ctx, doc, &mut scene, &world)?;

    if let Some(raw) = &doc.as_json().extras {
        let v: serde_json::Value = serde_json::from_str(raw.get())
            .map_err(|e| ctx.invalid("extras", format!("not JSON: {e}")))?;
        if let Some(env) = v.get(environment::EXTRAS_KEY) {
            let fetch = |uri: &str| uri::fetch(uri, base_dir);
            scene.environment = Some(
                Environment::from_json(env, &fetch)
                    .map_err(|m| ctx.invalid(format!("extras.{}", environment::EXTRAS_KEY), m))?,
            );
        }
    }

    scene.proxies = load_proxies(&ctx, doc, &scene)?;
    add_defaults(&mut ctx, &mut scene, &world);
    scene.warnings = ctx.warnings;
    Ok(scene)
}

fn check_attribute_accessors(ctx: &Ctx, root: &gltf::json::Root) -> Result<()> {
    for (m, mesh) in root.meshes.iter().enumerate() {
        for (p, prim) in mesh.primitives.iter().enumerate() {
            for (semantic, index) in &prim.attributes {
                if index.value() >= root.accessors.len() {
                    let semantic = match semantic {
                        Checked::Valid(s) => semantic_name(s),
                        Checked::Invalid => "(invalid semantic)".to_string(),
                    };
                    return Err(ctx.invalid(
                        format!("meshes[{m}].primitives[{p}].attributes.{semantic}"),
                        format!(
                            "accessor {} does not exist ({} accessors)",
                            index.value(),
                            root.accessors.len()
                        ),
                    ));
                }
            }
        }
    }
    Ok(())
}

/// The glTF spelling of an attribute semantic (`POSITION`, `TEXCOORD_0`, ...).
fn semantic_name(s: &gltf::Semantic) -> String {
    match s {
        gltf::Semantic::Positions => "POSITION".to_string(),
        gltf::Semantic::Normals => "NORMAL".to_string(),
        gltf::Semantic::Tangents => "TANGENT".to_string(),
        gltf::Semantic::Colors(i) => format!("COLOR_{i}"),
        gltf::Semantic::TexCoords(i) => format!("TEXCOORD_{i}"),
        gltf::Semantic::Joints(i) => format!("JOINTS_{i}"),
        gltf::Semantic::Weights(i) => format!("WEIGHTS_{i}"),
        gltf::Semantic::Extras(name) => format!("_{name}"),
    }
}

/// Loading context: the file name for messages and the warnings so far.
struct Ctx<'a> {
    file: &'a str,
    warnings: Vec<String>,
}

impl Ctx<'_> {
    fn invalid(&self, element: impl Into<String>, message: impl Into<String>) -> Error {
        Error::Invalid {
            file: self.file.to_string(),
            element: element.into(),
            message: message.into(),
        }
    }

    fn warn(&mut self, element: impl std::fmt::Display, message: impl std::fmt::Display) {
        self.warnings
            .push(format!("{}: {element}: {message}", self.file));
    }
}

fn load_buffers(
    ctx: &Ctx,
    doc: &gltf::Document,
    blob: Option<&[u8]>,
    base: Option<&Path>,
) -> Result<Buffers> {
    let mut data = Vec::new();
    for b in doc.buffers() {
        let element = format!("buffers[{}]", b.index());
        let bytes = match b.source() {
            gltf::buffer::Source::Bin => blob.map(<[u8]>::to_vec).ok_or_else(|| {
                ctx.invalid(
                    &element,
                    "refers to the GLB binary chunk, but the file has none",
                )
            })?,
            gltf::buffer::Source::Uri(uri) => uri::fetch(uri, base)
                .map_err(|m| ctx.invalid(format!("{element} (uri {uri:?})"), m))?,
        };
        if bytes.len() < b.length() {
            return Err(ctx.invalid(
                &element,
                format!(
                    "declares {} bytes but only {} are present (truncated file?)",
                    b.length(),
                    bytes.len()
                ),
            ));
        }
        data.push(bytes);
    }
    Ok(Buffers { data })
}

/// Decodes images on first use and makes one [`Texture`] per (image, colour space).
struct TextureLoader<'a> {
    root: &'a gltf::json::Root,
    base_dir: Option<&'a Path>,
    /// Decoded RGBA8 per image index (`None`: failed, already warned).
    images: HashMap<usize, Option<Texture>>,
    textures: Vec<Texture>,
    keys: HashMap<(usize, bool), u32>,
}

impl TextureLoader<'_> {
    fn texture(
        &mut self,
        ctx: &mut Ctx,
        buffers: &Buffers,
        info: &gltf::texture::Texture<'_>,
        srgb: bool,
        element: &str,
    ) -> u32 {
        let image = info.source();
        let index = image.index();
        if let Some(&t) = self.keys.get(&(index, srgb)) {
            return t;
        }
        if !self.images.contains_key(&index) {
            let decoded = self.decode(buffers, &image);
            if let Err(m) = &decoded {
                ctx.warn(
                    format!("{element} -> images[{index}]"),
                    format!("{m}; the material uses its factors without this texture"),
                );
            }
            self.images.insert(index, decoded.ok());
        }
        let Some(Some(decoded)) = self.images.get(&index) else {
            return NO_TEXTURE;
        };
        let t = self.textures.len() as u32;
        self.textures.push(Texture {
            srgb,
            ..decoded.clone()
        });
        self.keys.insert((index, srgb), t);
        t
    }

    /// The image decoded to RGBA8 (`srgb` is set per use by the caller).
    fn decode(&self, buffers: &Buffers, image: &gltf::image::Image<'_>) -> Result<Texture, String> {
        // From the JSON: gltf 1.4's `Image::source` unwraps a missing mimeType or uri.
        let index = image.index();
        let json = self.root;
        let def = json.images.get(index).ok_or("the image does not exist")?;
        let default_name = || def.name.clone().unwrap_or_else(|| format!("image{index}"));
        let (bytes, name) = match (&def.buffer_view, &def.uri) {
            (Some(view), _) => {
                let v = json
                    .buffer_views
                    .get(view.value())
                    .ok_or("its bufferView does not exist")?;
                let buffer = buffers
                    .data
                    .get(v.buffer.value())
                    .ok_or("its buffer is missing")?;
                let start = v.byte_offset.map_or(0, |o| o.0 as usize);
                let end = start
                    .checked_add(v.byte_length.0 as usize)
                    .ok_or("bufferView range overflows")?;
                let bytes = buffer.get(start..end).ok_or_else(|| {
                    format!(
                        "bufferViews[{}] runs past the end of its buffer",
                        view.value()
                    )
                })?;
                (bytes.to_vec(), default_name())
            }
            (None, Some(uri)) => {
                let name = if uri.starts_with("data:") {
                    default_name()
                } else {
                    uri.clone()
                };
                (uri::fetch(uri, self.base_dir)?, name)
            }
            (None, None) => return Err("the image has neither a uri nor a bufferView".to_string()),
        };
        let decoded = image::ImageReader::new(std::io::Cursor::new(bytes))
            .with_guessed_format()
            .map_err(|e| format!("cannot read image: {e}"))?
            .decode()
            .map_err(|e| format!("cannot decode image: {e}"))?;
        let rgba = decoded.to_rgba8();
        if rgba.width() == 0 || rgba.height() == 0 {
            return Err("image is 0 pixels wide or high".to_string());
        }
        Ok(Texture {
            name,
            width: rgba.width(),
            height: rgba.height(),
            srgb: false,
            rgba8: rgba.into_raw(),
        })
    }
}

fn load_material(
    ctx: &mut Ctx,
    buffers: &Buffers,
    tex: &mut TextureLoader,
    m: &gltf::Material<'_>,
) -> Material {
    let index = m.index().unwrap_or(0);
    let element = format!("materials[{index}] {:?}", m.name().unwrap_or(""));
    let pbr = m.pbr_metallic_roughness();
    let mut out = Material::default();
    let finite_or = |x: f32, d: f32| if x.is_finite() { x } else { d };
    out.base_color = pbr.base_color_factor().map(|x| finite_or(x, 1.0));
    out.metallic = finite_or(pbr.metallic_factor(), 1.0).clamp(0.0, 1.0);
    out.roughness = finite_or(pbr.roughness_factor(), 1.0).clamp(0.0, 1.0);
    let strength = finite_or(m.emissive_strength().unwrap_or(1.0), 1.0).max(0.0);
    out.emissive = m
        .emissive_factor()
        .map(|x| finite_or(x, 0.0).max(0.0) * strength);
    out.alpha_cutoff = m.alpha_cutoff().unwrap_or(0.5);
    out.alpha_mode = match m.alpha_mode() {
        gltf::material::AlphaMode::Opaque => 0,
        gltf::material::AlphaMode::Mask => 1,
        gltf::material::AlphaMode::Blend => 2,
    };
    out.double_sided = u32::from(m.double_sided());
    let check_info = |ctx: &mut Ctx, what: &str, tex_coord: u32| {
        if tex_coord != 0 {
            ctx.warn(
                format!("{element} {what}"),
                format!("uses TEXCOORD_{tex_coord}; shine reads UV0 for all textures"),
            );
        }
    };
    if let Some(info) = pbr.base_color_texture() {
        check_info(ctx, "baseColorTexture", info.tex_coord());
        out.base_color_texture = tex.texture(ctx, buffers, &info.texture(), true, &element);
    }
    if let Some(info) = pbr.metallic_roughness_texture() {
        check_info(ctx, "metallicRoughnessTexture", info.tex_coord());
        out.metallic_roughness_texture =
            tex.texture(ctx, buffers, &info.texture(), false, &element);
    }
    if let Some(info) = m.normal_texture() {
        check_info(ctx, "normalTexture", info.tex_coord());
        out.normal_scale = finite_or(info.scale(), 1.0);
        out.normal_texture = tex.texture(ctx, buffers, &info.texture(), false, &element);
    }
    if let Some(info) = m.emissive_texture() {
        check_info(ctx, "emissiveTexture", info.tex_coord());
        out.emissive_texture = tex.texture(ctx, buffers, &info.texture(), true, &element);
    }
    out
}

/// A loaded primitive (or `None`: skipped with a warning) and the warnings met.
type PrimitiveResult = (Result<Option<Primitive>>, Vec<String>);

/// One primitive to load, with what it needs to know about its mesh and material.
struct PrimitiveJob<'d> {
    mesh: usize,
    prim: gltf::Primitive<'d>,
    element: String,
    material: u32,
    normal_mapped: bool,
}

/// Loads every job, on up to `available_parallelism` threads; results in job order, each
/// with its warnings.
fn load_primitives(
    file: &str,
    buffers: &Buffers,
    jobs: &[PrimitiveJob<'_>],
) -> Vec<PrimitiveResult> {
    let run = |job: &PrimitiveJob<'_>| {
        let mut ctx = Ctx {
            file,
            warnings: Vec::new(),
        };
        let result = load_primitive(
            &mut ctx,
            buffers,
            &job.prim,
            &job.element,
            job.material,
            job.normal_mapped,
        );
        (result, ctx.warnings)
    };
    let threads = std::thread::available_parallelism()
        .map_or(1, |n| n.get())
        .min(jobs.len());
    if threads <= 1 {
        return jobs.iter().map(run).collect();
    }
    let next = std::sync::atomic::AtomicUsize::new(0);
    let mut done: Vec<(usize, PrimitiveResult)> = std::thread::scope(|scope| {
        let workers: Vec<_> = (0..threads)
            .map(|_| {
                scope.spawn(|| {
                    let mut out = Vec::new();
                    loop {
                        let i = next.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
                        let Some(job) = jobs.get(i) else { break };
                        out.push((i, run(job)));
                    }
                    out
                })
            })
            .collect();
        // A worker only panics if loading panicked, which the loader must never do; its
        // jobs are then reported as failed rather than lost silently.
        workers
            .into_iter()
            .flat_map(|w| w.join().unwrap_or_default())
            .collect()
    });
    done.sort_by_key(|(i, _)| *i);
    let mut out: Vec<PrimitiveResult> = Vec::with_capacity(jobs.len());
    let mut results = done.into_iter().peekable();
    for (i, job) in jobs.iter().enumerate() {
        match results.next_if(|(k, _)| *k == i) {
            Some((_, r)) => out.push(r),
            None => out.push((
                Err(Error::Invalid {
                    file: file.to_string(),
                    element: job.element.clone(),
                    message: "loading this primitive failed unexpectedly".to_string(),
                }),
                Vec::new(),
            )),
        }
    }
    out
}

/// Converts rows of floats into vectors, failing on NaN or infinity.
fn finite_rows<T>(
    ctx: &Ctx,
    element: &str,
    what: &str,
    values: &[f32],
    dims: usize,
    make: impl Fn(&[f32]) -> T,
) -> Result<Vec<T>> {
    if let Some(bad) = values.iter().position(|x| !x.is_finite()) {
        return Err(ctx.invalid(
            format!("{element} {what}"),
            format!(
                "element {} has a NaN or infinite component ({})",
                bad / dims.max(1),
                values.get(bad).copied().unwrap_or(0.0)
            ),
        ));
    }
    Ok(values.chunks_exact(dims).map(make).collect())
}

fn load_primitive(
    ctx: &mut Ctx,
    buffers: &Buffers,
    prim: &gltf::Primitive<'_>,
    element: &str,
    material: u32,
    normal_mapped: bool,
) -> Result<Option<Primitive>> {
    let mode = prim.mode();
    if !matches!(
        mode,
        Mode::Triangles | Mode::TriangleStrip | Mode::TriangleFan
    ) {
        ctx.warn(
            element,
            format!("mode {mode:?} is not triangles; the primitive is skipped"),
        );
        return Ok(None);
    }
    let read =
        |ctx: &Ctx, semantic: gltf::Semantic, dims: Dimensions| -> Result<Option<Vec<f32>>> {
            match prim.get(&semantic) {
                None => Ok(None),
                Some(acc) => buffers.read_rows(&acc, dims).map(Some).map_err(|m| {
                    ctx.invalid(
                        format!(
                            "{element} {} (accessors[{}])",
                            semantic_name(&semantic),
                            acc.index()
                        ),
                        m,
                    )
                }),
            }
        };
    let Some(pos) = read(ctx, gltf::Semantic::Positions, Dimensions::Vec3)? else {
        ctx.warn(
            element,
            "has no POSITION attribute; the primitive is skipped",
        );
        return Ok(None);
    };
    let positions = finite_rows(ctx, element, "POSITION", &pos, 3, |c| {
        Vec3::new(c[0], c[1], c[2])
    })?;
    let n = positions.len();
    let count_check = |ctx: &Ctx, what: &str, len: usize| -> Result<()> {
        if len == n {
            Ok(())
        } else {
            Err(ctx.invalid(
                format!("{element} {what}"),
                format!("has {len} elements but POSITION has {n}"),
            ))
        }
    };
    let raw_indices = match prim.indices() {
        Some(acc) => buffers.read_indices(&acc).map_err(|m| {
            ctx.invalid(format!("{element} indices (accessors[{}])", acc.index()), m)
        })?,
        None => (0..n as u32).collect(),
    };
    if let Some((k, &v)) = raw_indices
        .iter()
        .enumerate()
        .find(|&(_, &v)| v as usize >= n)
    {
        return Err(ctx.invalid(
            format!("{element} indices"),
            format!("index {k} has value {v}, out of range for {n} vertices"),
        ));
    }
    let mut indices = match mode {
        Mode::TriangleStrip => (0..raw_indices.len().saturating_sub(2))
            .flat_map(|i| {
                let w = raw_indices.get(i..i + 3).unwrap_or(&[0, 0, 0]);
                if i % 2 == 0 {
                    [w[0], w[1], w[2]]
                } else {
                    [w[1], w[0], w[2]]
                }
            })
            .collect(),
        Mode::TriangleFan => (1..raw_indices.len().saturating_sub(1))
            .flat_map(|i| {
                let first = raw_indices.first().copied().unwrap_or(0);
                let w = raw_indices.get(i..i + 2).unwrap_or(&[0, 0]);
                [first, w[0], w[1]]
            })
            .collect(),
        _ => raw_indices,
    };
    if indices.len() % 3 != 0 {
        ctx.warn(
            format!("{element} indices"),
            format!(
                "{} indices is not a multiple of 3; the last partial triangle is dropped",
                indices.len()
            ),
        );
        indices.truncate(indices.len() / 3 * 3);
    }

    let normals = match read(ctx, gltf::Semantic::Normals, Dimensions::Vec3)? {
        Some(v) => {
            count_check(ctx, "NORMAL", v.len() / 3)?;
            let raw = finite_rows(ctx, element, "NORMAL", &v, 3, |c| {
                Vec3::new(c[0], c[1], c[2])
            })?;
            let generated = raw
                .iter()
                .any(|x| x.length_squared() < 1e-12)
                .then(|| geometry::smooth_normals(&positions, &indices));
            raw.iter()
                .enumerate()
                .map(|(i, x)| {
                    x.try_normalize()
                        .or_else(|| generated.as_ref().and_then(|g| g.get(i).copied()))
                        .unwrap_or(Vec3::Y)
                })
                .collect()
        }
        None => geometry::smooth_normals(&positions, &indices),
    };
    let uvs = match read(ctx, gltf::Semantic::TexCoords(0), Dimensions::Vec2)? {
        Some(v) => {
            count_check(ctx, "TEXCOORD_0", v.len() / 2)?;
            Some(finite_rows(ctx, element, "TEXCOORD_0", &v, 2, |c| {
                Vec2::new(c[0], c[1])
            })?)
        }
        None => None,
    };
    let tangents = match read(ctx, gltf::Semantic::Tangents, Dimensions::Vec4)? {
        Some(v) => {
            count_check(ctx, "TANGENT", v.len() / 4)?;
            let raw = finite_rows(ctx, element, "TANGENT", &v, 4, |c| {
                Vec4::new(c[0], c[1], c[2], c[3])
            })?;
            Some(
                raw.iter()
                    .zip(&normals)
                    .map(|(t, n)| match t.truncate().try_normalize() {
                        Some(d) => d.extend(if t.w < 0.0 { -1.0 } else { 1.0 }),
                        None => geometry::any_tangent(*n),
                    })
                    .collect(),
            )
        }
        None => None,
    };
    if prim.morph_targets().next().is_some() {
        ctx.warn(
            element,
            "has morph targets; shine ignores them and uses the base shape",
        );
    }
    let has_uvs = uvs.is_some();
    let mut v = VertexData {
        positions,
        normals,
        uvs: uvs.unwrap_or_else(|| vec![Vec2::ZERO; n]),
        indices,
    };
    let tangents = match tangents {
        Some(t) => t,
        // Tangents only matter under a normal map; elsewhere a perpendicular will do and
        // MikkTSpace's cost (about 2.5 s per million triangles) is not paid.
        None if has_uvs && normal_mapped => geometry::mikktspace_tangents(&mut v),
        None => v
            .normals
            .iter()
            .map(|n| geometry::any_tangent(*n))
            .collect(),
    };
    let bounds = v.positions.iter().fold(Aabb::EMPTY, |mut b, p| {
        b.grow(*p);
        b
    });
    Ok(Some(Primitive {
        positions: v.positions,
        normals: v.normals,
        tangents,
        uvs: v.uvs,
        indices: v.indices,
        material,
        bounds,
    }))
}

/// MikkTSpace tangents for `v`, splitting vertices where tangents disagree.
pub(crate) fn tangents_for(v: &mut VertexData) -> Vec<Vec4> {
    geometry::mikktspace_tangents(v)
}

fn load_nodes(ctx: &mut Ctx, doc: &gltf::Document) -> Result<(Vec<Node>, Vec<usize>)> {
    let mut nodes = Vec::new();
    for node in doc.nodes() {
        let name = node
            .name()
            .map_or_else(|| format!("node{}", node.index()), str::to_string);
        let element = format!("nodes[{}] {name:?}", node.index());
        let (t, r, s) = node.transform().decomposed();
        let transform = Transform {
            translation: Vec3::from(t),
            rotation: Quat::from_array(r),
            scale: Vec3::from(s),
        };
        if !(transform.translation.is_finite()
            && transform.rotation.is_finite()
            && transform.scale.is_finite())
        {
            return Err(ctx.invalid(&element, "transform has NaN or infinite values (or a matrix that is not translation·rotation·scale)"));
        }
        let transform = Transform {
            rotation: if transform.rotation.length_squared() > 1e-12 {
                transform.rotation.normalize()
            } else {
                ctx.warn(&element, "rotation is a zero quaternion; identity is used");
                Quat::IDENTITY
            },
            ..transform
        };
        if node.skin().is_some() {
            ctx.warn(
                &element,
                "is skinned; skinning is not supported yet, the mesh is drawn in its bind pose",
            );
        }
        nodes.push(Node {
            name,
            parent: None,
            children: node.children().map(|c| c.index()).collect(),
            transform,
            mesh: node.mesh().map(|m| m.index()),
            camera: None,
            lights: Vec::new(),
        });
    }
    for i in 0..nodes.len() {
        let children = nodes.get(i).map(|n| n.children.clone()).unwrap_or_default();
        for c in children {
            let Some(child) = nodes.get_mut(c) else {
                return Err(ctx.invalid(
                    format!("nodes[{i}].children"),
                    format!("node {c} does not exist"),
                ));
            };
            if child.parent.is_some() || c == i {
                return Err(ctx.invalid(
                    format!("nodes[{c}] {:?}", child.name),
                    "has more than one parent or is its own ancestor; the node hierarchy must be a forest",
                ));
            }
            child.parent = Some(i);
        }
    }
    // Every chain of parents must end at a root (no cycles).
    for (i, node) in nodes.iter().enumerate() {
        let mut p = node.parent;
        let mut steps = 0;
        while let Some(j) = p {
            steps += 1;
            if steps > nodes.len() {
                return Err(ctx.invalid(
                    format!("nodes[{i}] {:?}", node.name),
                    "is part of a cycle in the node hierarchy",
                ));
            }
            p = nodes.get(j).and_then(|n| n.parent);
        }
    }
    let roots: Vec<usize> = match doc.default_scene().or_else(|| doc.scenes().next()) {
        Some(scene) => {
            let roots: Vec<usize> = scene.nodes().map(|n| n.index()).collect();
            if let Some(&bad) = roots
                .iter()
                .find(|&&r| nodes.get(r).is_some_and(|n| n.parent.is_some()))
            {
                return Err(ctx.invalid(
                    format!("scenes[{}].nodes", scene.index()),
                    format!("node {bad} is listed as a root but has a parent"),
                ));
            }
            roots
        }
        None => {
            if !nodes.is_empty() {
                ctx.warn(
                    "scenes",
                    "the file has no scene; every parentless node is shown",
                );
            }
            (0..nodes.len())
                .filter(|&i| nodes.get(i).is_some_and(|n| n.parent.is_none()))
                .collect()
        }
    };
    Ok((nodes, roots))
}

fn load_animations(
    ctx: &mut Ctx,
    buffers: &Buffers,
    doc: &gltf::Document,
) -> Result<Vec<Animation>> {
    let mut out = Vec::new();
    // Read from the JSON: gltf 1.4's animation wrappers unwrap the target path and node,
    // which its validation does not check.
    let json = doc.as_json();
    for (ai, anim) in json.animations.iter().enumerate() {
        let name = anim
            .name
            .clone()
            .unwrap_or_else(|| format!("animation{ai}"));
        let mut channels = Vec::new();
        for (ci, ch) in anim.channels.iter().enumerate() {
            let element = format!("animations[{ai}] {name:?} channels[{ci}]");
            use gltf::json::animation::{Interpolation as I, Property as P};
            let property = match &ch.target.path {
                Checked::Valid(P::Translation) => Property::Translation,
                Checked::Valid(P::Rotation) => Property::Rotation,
                Checked::Valid(P::Scale) => Property::Scale,
                Checked::Valid(P::MorphTargetWeights) => {
                    ctx.warn(
                        &element,
                        "animates morph target weights, which shine ignores",
                    );
                    continue;
                }
                Checked::Invalid => return Err(ctx.invalid(&element, "unknown target path")),
            };
            let node = ch.target.node.value();
            if node >= json.nodes.len() {
                return Err(ctx.invalid(&element, format!("target node {node} does not exist")));
            }
            let sampler = anim.samplers.get(ch.sampler.value()).ok_or_else(|| {
                ctx.invalid(
                    &element,
                    format!("sampler {} does not exist", ch.sampler.value()),
                )
            })?;
            let interpolation = match &sampler.interpolation {
                Checked::Valid(I::Step) => Interpolation::Step,
                Checked::Valid(I::Linear) => Interpolation::Linear,
                Checked::Valid(I::CubicSpline) => Interpolation::CubicSpline,
                Checked::Invalid => return Err(ctx.invalid(&element, "unknown interpolation")),
            };
            let accessor = |index: usize, what: &str| {
                doc.accessors().nth(index).ok_or_else(|| {
                    ctx.invalid(&element, format!("{what} accessor {index} does not exist"))
                })
            };
            let input = accessor(sampler.input.value(), "input")?;
            let output = accessor(sampler.output.value(), "output")?;
            let times = buffers.read_rows(&input, Dimensions::Scalar).map_err(|m| {
                ctx.invalid(format!("{element} input (accessors[{}])", input.index()), m)
            })?;
            if times.is_empty()
                || times.iter().any(|t| !t.is_finite())
                || times.windows(2).any(|w| w[1] <= w[0])
            {
                return Err(ctx.invalid(
                    &element,
                    "key times must be finite, strictly increasing and at least one",
                ));
            }
            let dims = if property == Property::Rotation { 4 } else { 3 };
            let (values, got) = buffers.read_f32(&output).map_err(|m| {
                ctx.invalid(
                    format!("{element} output (accessors[{}])", output.index()),
                    m,
                )
            })?;
            if got != dims {
                return Err(ctx.invalid(
                    &element,
                    format!("output has {got} components per key, expected {dims}"),
                ));
            }
            let per_key = if interpolation == Interpolation::CubicSpline {
                3
            } else {
                1
            };
            if values.len() / dims != times.len() * per_key {
                return Err(ctx.invalid(
                    &element,
                    format!(
                        "{} output values for {} keys (expected {} per key)",
                        values.len() / dims,
                        times.len(),
                        per_key
                    ),
                ));
            }
            let values = finite_rows(ctx, &element, "output", &values, dims, |c| {
                Vec4::new(c[0], c[1], c[2], c.get(3).copied().unwrap_or(0.0))
            })?;
            channels.push(Channel {
                node,
                property,
                interpolation,
                times,
                values,
            });
        }
        out.push(Animation { name, channels });
    }
    Ok(out)
}

fn load_lights(
    ctx: &mut Ctx,
    doc: &gltf::Document,
    scene: &mut Scene,
    world: &[Mat4],
) -> Result<()> {
    let json = doc.as_json();
    let defs = json
        .extensions
        .as_ref()
        .and_then(|e| e.khr_lights_punctual.as_ref())
        .map(|l| l.lights.as_slice())
        .unwrap_or(&[]);
    let shown = scene.shown_nodes();
    for (i, node) in json.nodes.iter().enumerate() {
        let Some(light_ref) = node
            .extensions
            .as_ref()
            .and_then(|e| e.khr_lights_punctual.as_ref())
        else {
            continue;
        };
        if !shown.get(i).copied().unwrap_or(false) {
            continue;
        }
        let li = light_ref.light.value();
        let element = format!("nodes[{i}] KHR_lights_punctual.light {li}");
        let def = defs
            .get(li)
            .ok_or_else(|| ctx.invalid(&element, "the light does not exist"))?;
        use gltf::json::extensions::scene::khr_lights_punctual::Type;
        let (kind, inner, outer) = match &def.type_ {
            Checked::Valid(Type::Directional) => (LightKind::Directional, 0.0, 0.0),
            Checked::Valid(Type::Point) => (LightKind::Point, 0.0, 0.0),
            Checked::Valid(Type::Spot) => {
                let spot = def.spot.as_ref().ok_or_else(|| {
                    ctx.invalid(&element, "spot light without \"spot\" cone angles")
                })?;
                (
                    LightKind::Spot,
                    spot.inner_cone_angle,
                    spot.outer_cone_angle,
                )
            }
            Checked::Invalid => return Err(ctx.invalid(&element, "unknown light type")),
        };
        let values = [def.intensity, inner, outer, def.range.unwrap_or(0.0)];
        if values.iter().any(|x| !x.is_finite() || *x < 0.0)
            || def.color.iter().any(|x| !x.is_finite() || *x < 0.0)
        {
            return Err(ctx.invalid(
                &element,
                "intensity, colour, range and cone angles must be finite and non-negative",
            ));
        }
        if kind == LightKind::Spot
            && !(inner < outer && outer <= std::f32::consts::FRAC_PI_2 + 1e-6)
        {
            ctx.warn(&element, format!("spot cone angles inner {inner} / outer {outer} should satisfy inner < outer <= π/2"));
        }
        let w = world.get(i).copied().unwrap_or(Mat4::IDENTITY);
        let index = scene.lights.len();
        scene.lights.push(Light {
            position: w.transform_point3(Vec3::ZERO).to_array(),
            kind: kind as u32,
            direction: w
                .transform_vector3(Vec3::NEG_Z)
                .normalize_or(Vec3::NEG_Z)
                .to_array(),
            range: def.range.unwrap_or(0.0),
            color: def.color,
            intensity: def.intensity,
            inner_cone_angle: inner,
            outer_cone_angle: outer.min(std::f32::consts::FRAC_PI_2),
            node: i as u32,
            _pad: 0,
        });
        if let Some(n) = scene.nodes.get_mut(i) {
            n.lights.push(index);
        }
    }
    Ok(())
}

fn load_cameras(ctx: &Ctx, doc: &gltf::Document, scene: &mut Scene, world: &[Mat4]) -> Result<()> {
    let shown = scene.shown_nodes();
    for node in doc.nodes() {
        let Some(cam) = node.camera() else { continue };
        if !shown.get(node.index()).copied().unwrap_or(false) {
            continue;
        }
        let element = format!(
            "cameras[{}] {:?} (on nodes[{}])",
            cam.index(),
            cam.name().unwrap_or(""),
            node.index()
        );
        let projection = match cam.projection() {
            gltf::camera::Projection::Perspective(p) => Projection::Perspective {
                yfov: p.yfov(),
                aspect_ratio: p.aspect_ratio(),
                znear: p.znear(),
                zfar: p.zfar(),
            },
            gltf::camera::Projection::Orthographic(o) => Projection::Orthographic {
                xmag: o.xmag(),
                ymag: o.ymag(),
                znear: o.znear(),
                zfar: o.zfar(),
            },
        };
        let ok = match projection {
            Projection::Perspective {
                yfov,
                aspect_ratio,
                znear,
                zfar,
            } => {
                yfov > 0.0
                    && yfov < std::f32::consts::PI
                    && znear > 0.0
                    && aspect_ratio.is_none_or(|a| a > 0.0 && a.is_finite())
                    && zfar.is_none_or(|f| f > znear && f.is_finite())
            }
            Projection::Orthographic {
                xmag,
                ymag,
                znear,
                zfar,
            } => {
                xmag.is_finite()
                    && ymag.is_finite()
                    && xmag != 0.0
                    && ymag != 0.0
                    && znear >= 0.0
                    && zfar > znear
                    && zfar.is_finite()
            }
        };
        if !ok {
            return Err(ctx.invalid(&element, format!("invalid projection {projection:?}")));
        }
        let index = scene.cameras.len();
        scene.cameras.push(Camera {
            name: cam
                .name()
                .map_or_else(|| format!("camera{}", cam.index()), str::to_string),
            projection,
            world: world.get(node.index()).copied().unwrap_or(Mat4::IDENTITY),
            node: Some(node.index()),
        });
        if let Some(n) = scene.nodes.get_mut(node.index()) {
            n.camera = Some(index);
        }
    }
    Ok(())
}

fn load_proxies(ctx: &Ctx, doc: &gltf::Document, scene: &Scene) -> Result<Vec<NodeProxies>> {
    let mut out = Vec::new();
    let shown = scene.shown_nodes();
    for node in doc.nodes() {
        let i = node.index();
        if !shown.get(i).copied().unwrap_or(false) {
            continue;
        }
        let explicit = match node.extras() {
            Some(raw) => {
                let element = format!("nodes[{i}] {:?} extras", node.name().unwrap_or(""));
                let v: serde_json::Value = serde_json::from_str(raw.get())
                    .map_err(|e| ctx.invalid(&element, format!("not JSON: {e}")))?;
                match v.get(proxies::EXTRAS_KEY) {
                    Some(p) => Some(proxies::from_json(p).map_err(|m| {
                        ctx.invalid(format!("{element}.{}", proxies::EXTRAS_KEY), m)
                    })?),
                    None => None,
                }
            }
            None => None,
        };
        if let Some(spheres) = explicit {
            out.push(NodeProxies {
                node: i,
                spheres,
                source: ProxySource::Explicit,
            });
            continue;
        }
        let Some(mesh) = node.mesh().and_then(|m| scene.meshes.get(m.index())) else {
            continue;
        };
        if scene.is_animated(i) {
            let fit = proxies::fit(mesh, proxies::DEFAULT_PROXY_COUNT);
            out.push(NodeProxies {
                node: i,
                spheres: fit.spheres,
                source: ProxySource::Fitted(fit.error),
            });
        }
    }
    Ok(out)
}

fn add_defaults(ctx: &mut Ctx, scene: &mut Scene, world: &[Mat4]) {
    if scene.cameras.is_empty() {
        let bounds = scene.bounds(world);
        let (center, radius) = if bounds.is_empty() {
            (Vec3::ZERO, 1.0)
        } else {
            (bounds.center(), (bounds.extent().length() * 0.5).max(1e-3))
        };
        let distance = radius / (DEFAULT_YFOV * 0.5).sin();
        let eye = center + Vec3::Z * distance;
        ctx.warn("cameras", format!("the scene has no camera; using a default camera at {eye} looking down -Z at {center}"));
        scene.cameras.push(Camera {
            name: "default camera (framing the scene bounds)".to_string(),
            projection: Projection::Perspective {
                yfov: DEFAULT_YFOV,
                aspect_ratio: None,
                znear: (distance - radius).max(distance * 1e-3),
                zfar: Some(distance + radius * 2.0),
            },
            world: Mat4::from_translation(eye),
            node: None,
        });
    }
    if scene.lights.is_empty() && scene.environment.is_none() {
        ctx.warn(
            "KHR_lights_punctual",
            format!("the scene has no light and no environment; adding a default directional sun of {DEFAULT_SUN_LUX} lux along {DEFAULT_SUN_DIRECTION}"),
        );
        scene.lights.push(Light {
            position: [0.0; 3],
            kind: LightKind::Directional as u32,
            direction: DEFAULT_SUN_DIRECTION.to_array(),
            range: 0.0,
            color: [1.0; 3],
            intensity: DEFAULT_SUN_LUX,
            inner_cone_angle: 0.0,
            outer_cone_angle: 0.0,
            node: u32::MAX,
            _pad: 0,
        });
    }
}
