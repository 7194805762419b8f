//! Checks on the document as a whole before anything is decoded: attribute accessor
//! references, required and used extensions, and the buffers' bytes.

use std::path::Path;

use gltf::json::validation::Checked;

use super::accessor::Buffers;
use super::ctx::Ctx;
use super::{SUPPORTED_EXTENSIONS, uri};
use crate::error::Result;

/// Fails on a primitive attribute naming an accessor that does not exist.
///
/// gltf-json 1.4's validation indexes `accessors` by a primitive's POSITION index without a
/// bounds check (a panic on bad input), so this runs on the raw JSON before validation.
pub(super) fn check_attribute_accessors(ctx: &Ctx, root: &gltf::json::Root) -> Result<()> {
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
pub(super) fn semantic_name(s: &gltf::Semantic) -> String {
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

/// Rejects a file requiring an extension outside [`SUPPORTED_EXTENSIONS`] and warns about
/// each unsupported extension it merely uses.
pub(super) fn check_extensions(ctx: &mut Ctx, doc: &gltf::Document) -> Result<()> {
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
    Ok(())
}

/// The bytes of every buffer: the GLB binary chunk or a URI resolved against `base`,
/// checked to hold at least the length each buffer declares.
pub(super) fn load_buffers(
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
