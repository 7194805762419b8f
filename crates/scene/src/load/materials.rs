//! glTF metallic-roughness materials into [`Material`]s, their textures through the
//! [`TextureLoader`].

use super::accessor::Buffers;
use super::ctx::Ctx;
use super::textures::TextureLoader;
use crate::types::Material;

/// The materials of the file with their names, in file order.
pub(super) struct Materials {
    /// One per glTF material.
    pub(super) materials: Vec<Material>,
    /// The glTF name, or `material<i>`, parallel to `materials`.
    pub(super) names: Vec<String>,
}

impl Materials {
    /// Index the glTF default material gets when a primitive names none: one past the file's
    /// materials, where [`Materials::push_default`] puts it.
    pub(super) fn default_index(&self) -> u32 {
        self.materials.len() as u32
    }

    /// Appends the glTF default material (at [`Materials::default_index`]).
    pub(super) fn push_default(&mut self) {
        self.materials.push(Material::default());
        self.names.push("glTF default material".to_string());
    }
}

/// Loads every material of `doc`, decoding the textures they use.
pub(super) fn load_materials(
    ctx: &mut Ctx,
    buffers: &Buffers,
    textures: &mut TextureLoader,
    doc: &gltf::Document,
) -> Materials {
    let mut out = Materials {
        materials: Vec::new(),
        names: Vec::new(),
    };
    for (i, m) in doc.materials().enumerate() {
        out.materials
            .push(load_material(ctx, buffers, textures, &m));
        out.names.push(
            m.name()
                .map_or_else(|| format!("material{i}"), str::to_string),
        );
    }
    out
}

/// One material: factors made finite and clamped to their ranges, emissive strength
/// folded into the emissive factor, textures resolved to indices.
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
