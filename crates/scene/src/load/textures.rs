//! Texture images: decoded to RGBA8 on first use, one [`Texture`] per (image, colour space)
//! pair. A missing or undecodable image is a warning; the material keeps its factors.

use std::collections::HashMap;
use std::path::Path;

use super::accessor::Buffers;
use super::ctx::Ctx;
use super::uri;
use crate::types::{NO_TEXTURE, Texture};

/// Decodes images on first use and makes one [`Texture`] per (image, colour space).
pub(super) struct TextureLoader<'a> {
    root: &'a gltf::json::Root,
    base_dir: Option<&'a Path>,
    /// Decoded RGBA8 per image index (`None`: failed, already warned).
    images: HashMap<usize, Option<Texture>>,
    textures: Vec<Texture>,
    keys: HashMap<(usize, bool), u32>,
}

impl<'a> TextureLoader<'a> {
    /// A loader for the images of `root`, resolving relative URIs against `base_dir`.
    pub(super) fn new(root: &'a gltf::json::Root, base_dir: Option<&'a Path>) -> Self {
        TextureLoader {
            root,
            base_dir,
            images: HashMap::new(),
            textures: Vec::new(),
            keys: HashMap::new(),
        }
    }
}

impl TextureLoader<'_> {
    /// Index of the texture for `info`'s image in colour space `srgb`, decoding the image on
    /// first use; [`NO_TEXTURE`] (with a warning naming `element`) when it cannot be decoded.
    pub(super) fn texture(
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

    /// The textures made so far, in index order.
    pub(super) fn into_textures(self) -> Vec<Texture> {
        self.textures
    }

    /// The image decoded to RGBA8 (`srgb` is set per use by the caller).
    fn decode(&self, buffers: &Buffers, image: &gltf::image::Image<'_>) -> Result<Texture, String> {
        let (bytes, name) = self.image_bytes(buffers, image.index())?;
        decode_rgba8(bytes, name)
    }

    /// The encoded bytes of image `index` and its name for messages.
    ///
    /// Read from the JSON: gltf 1.4's `Image::source` unwraps a missing mimeType or uri.
    fn image_bytes(&self, buffers: &Buffers, index: usize) -> Result<(Vec<u8>, String), String> {
        let json = self.root;
        let def = json.images.get(index).ok_or("the image does not exist")?;
        let default_name = || def.name.clone().unwrap_or_else(|| format!("image{index}"));
        match (&def.buffer_view, &def.uri) {
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
                Ok((bytes.to_vec(), default_name()))
            }
            (None, Some(uri)) => {
                let name = if uri.starts_with("data:") {
                    default_name()
                } else {
                    uri.clone()
                };
                Ok((uri::fetch(uri, self.base_dir)?, name))
            }
            (None, None) => Err("the image has neither a uri nor a bufferView".to_string()),
        }
    }
}

/// Decodes encoded image bytes (any format the `image` crate guesses) into a linear RGBA8
/// [`Texture`] named `name`.
fn decode_rgba8(bytes: Vec<u8>, name: String) -> Result<Texture, String> {
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
