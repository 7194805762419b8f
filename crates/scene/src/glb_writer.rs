//! A small glTF 2.0 writer: JSON built with serde_json plus one binary buffer, written as a
//! `.glb` (header, JSON chunk padded with spaces, BIN chunk padded with zeros).
//!
//! Output is deterministic: serde_json orders object keys, and every array is appended in
//! call order.
//!
//! Besides static meshes it writes what animated scenes need: skins with inverse bind
//! matrices ([`GlbWriter::skin`]), skinned and morphing primitives
//! ([`GlbWriter::deforming_mesh`]: `JOINTS_0`, `WEIGHTS_0`, morph targets, default mesh
//! weights) and animation keys of any kind ([`GlbWriter::keys`], `SCALAR` for weights).

use glam::{Mat4, Vec2, Vec3, Vec4};
use serde_json::{Map, Value, json};

use crate::builtin::shapes::MeshData;
use crate::error::{Error, Result};
use crate::types::MorphTarget;

const ARRAY_BUFFER: u32 = 34962;
const ELEMENT_ARRAY_BUFFER: u32 = 34963;
const FLOAT: u32 = 5126;
const UNSIGNED_INT: u32 = 5125;
const UNSIGNED_SHORT: u32 = 5123;
const UNSIGNED_BYTE: u32 = 5121;

/// One primitive for [`GlbWriter::deforming_mesh`]: geometry and material, plus skinning
/// and morph data (each empty when unused).
#[derive(Clone, Copy, Debug)]
pub struct DeformingPrimitive<'a> {
    /// Positions, normals, UVs and indices (the base shape, in bind pose).
    pub geometry: &'a MeshData,
    /// Material index.
    pub material: usize,
    /// `JOINTS_0`, one per vertex (written as unsigned bytes when every index fits, else
    /// unsigned shorts); empty when not skinned.
    pub joints: &'a [[u32; 4]],
    /// `WEIGHTS_0`, one per vertex, summing to 1 (floats); empty when not skinned.
    pub weights: &'a [Vec4],
    /// Morph targets (POSITION deltas with bounds, NORMAL deltas when present).
    pub targets: &'a [MorphTarget],
}

/// Builds a glTF document and serialises it as GLB.
#[derive(Debug, Default)]
pub struct GlbWriter {
    root: Map<String, Value>,
    bin: Vec<u8>,
    lights: Vec<Value>,
    extensions_used: Vec<String>,
}

impl GlbWriter {
    /// An empty document.
    pub fn new() -> GlbWriter {
        GlbWriter::default()
    }

    /// Appends `value` to the top-level array `key` and returns its index.
    pub fn push(&mut self, key: &str, value: Value) -> usize {
        let entry = self
            .root
            .entry(key)
            .or_insert_with(|| Value::Array(Vec::new()));
        match entry {
            Value::Array(a) => {
                a.push(value);
                a.len() - 1
            }
            other => {
                *other = Value::Array(vec![value]);
                0
            }
        }
    }

    /// Adds the scene (the default one) with these root nodes.
    pub fn scene(&mut self, name: &str, roots: &[usize]) {
        let index = self.push("scenes", json!({"name": name, "nodes": roots}));
        self.root.insert("scene".to_string(), json!(index));
    }

    /// Records an extension in `extensionsUsed` (once).
    pub fn use_extension(&mut self, name: &str) {
        if !self.extensions_used.iter().any(|e| e == name) {
            self.extensions_used.push(name.to_string());
        }
    }

    /// Sets the root `extras` object.
    pub fn set_extras(&mut self, extras: Value) {
        self.root.insert("extras".to_string(), extras);
    }

    /// Appends bytes to the binary buffer (4-byte aligned) as a buffer view.
    pub fn buffer_view(&mut self, bytes: &[u8], target: Option<u32>) -> usize {
        while !self.bin.len().is_multiple_of(4) {
            self.bin.push(0);
        }
        let offset = self.bin.len();
        self.bin.extend_from_slice(bytes);
        let mut view = json!({"buffer": 0, "byteOffset": offset, "byteLength": bytes.len()});
        if let (Some(t), Some(obj)) = (target, view.as_object_mut()) {
            obj.insert("target".to_string(), json!(t));
        }
        self.push("bufferViews", view)
    }

    fn float_accessor(
        &mut self,
        floats: &[f32],
        kind: &str,
        dims: usize,
        target: Option<u32>,
        bounds: bool,
    ) -> usize {
        let view = self.buffer_view(bytemuck::cast_slice(floats), target);
        let count = floats.len() / dims;
        let mut acc =
            json!({"bufferView": view, "componentType": FLOAT, "count": count, "type": kind});
        if bounds && count > 0 {
            let mut min = vec![f32::INFINITY; dims];
            let mut max = vec![f32::NEG_INFINITY; dims];
            for row in floats.chunks_exact(dims) {
                for ((lo, hi), x) in min.iter_mut().zip(max.iter_mut()).zip(row) {
                    *lo = lo.min(*x);
                    *hi = hi.max(*x);
                }
            }
            if let Some(obj) = acc.as_object_mut() {
                obj.insert("min".to_string(), json!(min));
                obj.insert("max".to_string(), json!(max));
            }
        }
        self.push("accessors", acc)
    }

    /// A VEC3 float vertex accessor; `bounds` adds min/max (required for POSITION).
    pub fn vec3(&mut self, data: &[Vec3], bounds: bool) -> usize {
        self.float_accessor(
            bytemuck::cast_slice(data),
            "VEC3",
            3,
            Some(ARRAY_BUFFER),
            bounds,
        )
    }

    /// A VEC2 float vertex accessor.
    pub fn vec2(&mut self, data: &[Vec2]) -> usize {
        self.float_accessor(
            bytemuck::cast_slice(data),
            "VEC2",
            2,
            Some(ARRAY_BUFFER),
            false,
        )
    }

    /// A VEC4 float vertex accessor.
    pub fn vec4(&mut self, data: &[Vec4]) -> usize {
        self.float_accessor(
            bytemuck::cast_slice(data),
            "VEC4",
            4,
            Some(ARRAY_BUFFER),
            false,
        )
    }

    /// Animation sampler data: `times` (SCALAR with min/max) and values of `kind` ("VEC3",
    /// "VEC4", or "SCALAR" for morph weights: one float per target per value). Returns
    /// `(input, output)` accessor indices.
    pub fn keys(&mut self, times: &[f32], values: &[f32], kind: &str) -> (usize, usize) {
        let dims = match kind {
            "VEC4" => 4,
            "SCALAR" => 1,
            _ => 3,
        };
        let input = self.float_accessor(times, "SCALAR", 1, None, true);
        let output = self.float_accessor(values, kind, dims, None, false);
        (input, output)
    }

    /// Triangle indices: u16 when every index fits, else u32.
    pub fn indices(&mut self, indices: &[u32]) -> usize {
        let (view, component) = if indices.iter().all(|&i| i < u32::from(u16::MAX)) {
            let short: Vec<u16> = indices.iter().map(|&i| i as u16).collect();
            (
                self.buffer_view(bytemuck::cast_slice(&short), Some(ELEMENT_ARRAY_BUFFER)),
                UNSIGNED_SHORT,
            )
        } else {
            (
                self.buffer_view(bytemuck::cast_slice(indices), Some(ELEMENT_ARRAY_BUFFER)),
                UNSIGNED_INT,
            )
        };
        self.push("accessors", json!({"bufferView": view, "componentType": component, "count": indices.len(), "type": "SCALAR"}))
    }

    /// A skin: `joints` (node indices) with one inverse bind matrix each, and the skeleton
    /// root node when given. Returns the skin index for a node's `skin`.
    pub fn skin(
        &mut self,
        name: &str,
        joints: &[usize],
        inverse_bind: &[Mat4],
        skeleton: Option<usize>,
    ) -> usize {
        let floats: Vec<f32> = inverse_bind
            .iter()
            .flat_map(|m| m.to_cols_array())
            .collect();
        let ibm = self.float_accessor(&floats, "MAT4", 16, None, false);
        let mut skin = json!({"name": name, "joints": joints, "inverseBindMatrices": ibm});
        if let (Some(root), Some(obj)) = (skeleton, skin.as_object_mut()) {
            obj.insert("skeleton".to_string(), json!(root));
        }
        self.push("skins", skin)
    }

    /// `JOINTS_0` as unsigned bytes when every index is below 256, else unsigned shorts;
    /// `None` when an index does not fit a short.
    fn joints(&mut self, joints: &[[u32; 4]]) -> Option<usize> {
        let max = joints.iter().flatten().copied().max().unwrap_or(0);
        let (view, component) = if max < 256 {
            let bytes: Vec<u8> = joints.iter().flatten().map(|&j| j as u8).collect();
            (self.buffer_view(&bytes, Some(ARRAY_BUFFER)), UNSIGNED_BYTE)
        } else if max < 65536 {
            let shorts: Vec<u16> = joints.iter().flatten().map(|&j| j as u16).collect();
            (
                self.buffer_view(bytemuck::cast_slice(&shorts), Some(ARRAY_BUFFER)),
                UNSIGNED_SHORT,
            )
        } else {
            return None;
        };
        Some(self.push(
            "accessors",
            json!({"bufferView": view, "componentType": component, "count": joints.len(), "type": "VEC4"}),
        ))
    }

    /// A mesh whose primitives may be skinned and morphing, with default morph `weights`
    /// (written when not empty). Fails on a joint index that does not fit an unsigned short.
    pub fn deforming_mesh(
        &mut self,
        name: &str,
        parts: &[DeformingPrimitive<'_>],
        weights: &[f32],
    ) -> Result<usize> {
        let mut primitives = Vec::new();
        for (k, part) in parts.iter().enumerate() {
            let mut prim = self.primitive(part.geometry, part.material, None);
            if !part.joints.is_empty() {
                let joints = self.joints(part.joints).ok_or_else(|| Error::Invalid {
                    file: "glTF writer".to_string(),
                    element: format!("mesh {name:?} primitives[{k}] JOINTS_0"),
                    message: "a joint index does not fit an unsigned short".to_string(),
                })?;
                let w = self.vec4(part.weights);
                prim["attributes"]["JOINTS_0"] = json!(joints);
                prim["attributes"]["WEIGHTS_0"] = json!(w);
            }
            let mut targets = Vec::new();
            for t in part.targets {
                let mut target = Map::new();
                target.insert("POSITION".to_string(), json!(self.vec3(&t.positions, true)));
                if !t.normals.is_empty() {
                    target.insert("NORMAL".to_string(), json!(self.vec3(&t.normals, false)));
                }
                targets.push(Value::Object(target));
            }
            if !targets.is_empty() {
                prim["targets"] = Value::Array(targets);
            }
            primitives.push(prim);
        }
        let mut mesh = json!({"name": name, "primitives": primitives});
        if !weights.is_empty() {
            mesh["weights"] = json!(weights);
        }
        Ok(self.push("meshes", mesh))
    }

    /// One primitive's JSON: POSITION, NORMAL, TEXCOORD_0, TANGENT when given, indices,
    /// material, triangle mode.
    fn primitive(&mut self, m: &MeshData, material: usize, tangents: Option<&[Vec4]>) -> Value {
        let mut attributes = Map::new();
        attributes.insert("POSITION".to_string(), json!(self.vec3(&m.positions, true)));
        attributes.insert("NORMAL".to_string(), json!(self.vec3(&m.normals, false)));
        attributes.insert("TEXCOORD_0".to_string(), json!(self.vec2(&m.uvs)));
        if let Some(t) = tangents {
            attributes.insert("TANGENT".to_string(), json!(self.vec4(t)));
        }
        let indices = self.indices(&m.indices);
        json!({"attributes": attributes, "indices": indices, "material": material, "mode": 4})
    }

    /// A mesh with one primitive per `(geometry, material)`; writes POSITION, NORMAL,
    /// TEXCOORD_0 and indices. Tangents are left to the loader's MikkTSpace.
    pub fn mesh(&mut self, name: &str, parts: &[(&MeshData, usize)]) -> usize {
        let parts: Vec<(&MeshData, usize, bool)> =
            parts.iter().map(|&(m, mat)| (m, mat, false)).collect();
        self.mesh_parts(name, &parts)
    }

    /// Like [`GlbWriter::mesh`], with a flag per primitive to also write MikkTSpace TANGENTs
    /// (for normal-mapped materials, so the file carries its tangent space).
    pub fn mesh_parts(&mut self, name: &str, parts: &[(&MeshData, usize, bool)]) -> usize {
        let mut primitives = Vec::new();
        for &(m, material, with_tangents) in parts {
            let (m, tangents) = if with_tangents {
                let t = m.clone().into_mesh(name, 0);
                let p = t.primitives.into_iter().next().unwrap_or_default();
                (
                    MeshData {
                        positions: p.positions,
                        normals: p.normals,
                        uvs: p.uvs,
                        indices: p.indices,
                    },
                    Some(p.tangents),
                )
            } else {
                (m.clone(), None)
            };
            let prim = self.primitive(&m, material, tangents.as_deref());
            primitives.push(prim);
        }
        self.push("meshes", json!({"name": name, "primitives": primitives}))
    }

    /// An embedded PNG image with a texture (repeat wrapping, trilinear filtering).
    pub fn png_texture(&mut self, name: &str, png: &[u8]) -> usize {
        let view = self.buffer_view(png, None);
        let image = self.push(
            "images",
            json!({"name": name, "bufferView": view, "mimeType": "image/png"}),
        );
        if self.root.get("samplers").is_none() {
            self.push(
                "samplers",
                json!({"magFilter": 9729, "minFilter": 9987, "wrapS": 10497, "wrapT": 10497}),
            );
        }
        self.push(
            "textures",
            json!({"name": name, "sampler": 0, "source": image}),
        )
    }

    /// A KHR_lights_punctual light; returns its index for a node's extension.
    pub fn light(&mut self, light: Value) -> usize {
        self.use_extension("KHR_lights_punctual");
        self.lights.push(light);
        self.lights.len() - 1
    }

    /// The root JSON object; `uri` is the buffer's URI (`None` for the GLB binary chunk).
    fn root_json(&self, uri: Option<String>) -> Value {
        let mut root = self.root.clone();
        root.insert(
            "asset".to_string(),
            json!({"version": "2.0", "generator": "shine-scene built-in scene writer"}),
        );
        if !self.lights.is_empty() {
            root.insert(
                "extensions".to_string(),
                json!({"KHR_lights_punctual": {"lights": self.lights}}),
            );
        }
        if !self.extensions_used.is_empty() {
            root.insert("extensionsUsed".to_string(), json!(self.extensions_used));
        }
        if !self.bin.is_empty() {
            let mut buffer = json!({"byteLength": self.bin.len()});
            if let (Some(uri), Some(obj)) = (uri, buffer.as_object_mut()) {
                obj.insert("uri".to_string(), json!(uri));
            }
            root.insert("buffers".to_string(), json!([buffer]));
        }
        Value::Object(root)
    }

    /// The document as `.gltf` JSON text plus the bytes of its one buffer. With
    /// `Some(file_name)` the JSON refers to the buffer as that file (write the bytes next to
    /// it); with `None` the buffer is embedded as a base64 `data:` URI.
    pub fn to_gltf(&self, buffer_file: Option<&str>) -> (String, Vec<u8>) {
        let uri = match buffer_file {
            Some(f) => f.to_string(),
            None => format!(
                "data:application/octet-stream;base64,{}",
                crate::load::uri::base64_encode(&self.bin)
            ),
        };
        (self.root_json(Some(uri)).to_string(), self.bin.clone())
    }

    /// The document as GLB bytes.
    pub fn to_glb(&self) -> Vec<u8> {
        let mut json_bytes = self.root_json(None).to_string().into_bytes();
        while !json_bytes.len().is_multiple_of(4) {
            json_bytes.push(b' ');
        }
        let mut bin = self.bin.clone();
        while !bin.len().is_multiple_of(4) {
            bin.push(0);
        }
        let bin_chunk = if bin.is_empty() { 0 } else { 8 + bin.len() };
        let total = 12 + 8 + json_bytes.len() + bin_chunk;
        let mut out = Vec::with_capacity(total);
        out.extend_from_slice(b"glTF");
        out.extend_from_slice(&2u32.to_le_bytes());
        out.extend_from_slice(&(total as u32).to_le_bytes());
        out.extend_from_slice(&(json_bytes.len() as u32).to_le_bytes());
        out.extend_from_slice(b"JSON");
        out.extend_from_slice(&json_bytes);
        if !bin.is_empty() {
            out.extend_from_slice(&(bin.len() as u32).to_le_bytes());
            out.extend_from_slice(b"BIN\0");
            out.extend_from_slice(&bin);
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn glb_layout_is_aligned_and_parses() {
        let mut w = GlbWriter::new();
        let mut quad = MeshData::default();
        quad.quad(
            [Vec3::ZERO, Vec3::X, Vec3::new(1.0, 1.0, 0.0), Vec3::Y],
            Vec2::ONE,
        );
        let mesh = w.mesh("quad", &[(&quad, 0)]);
        w.push("materials", json!({"name": "white"}));
        let node = w.push("nodes", json!({"mesh": mesh}));
        w.scene("test", &[node]);
        let glb = w.to_glb();
        assert_eq!(&glb[0..4], b"glTF");
        assert_eq!(
            u32::from_le_bytes(glb[8..12].try_into().unwrap()) as usize,
            glb.len()
        );
        assert_eq!(glb.len() % 4, 0);
        let g = gltf::Gltf::from_slice(&glb).unwrap();
        assert_eq!(g.document.meshes().count(), 1);
        assert!(g.blob.is_some());
    }
}
