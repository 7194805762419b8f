//! The plain data a scene is made of: geometry, materials, textures, lights, cameras and the
//! node hierarchy, in glTF conventions (docs/architecture.md, "Conventions": right-handed, +Y up, metres,
//! KHR_lights_punctual units).
//!
//! A leaf module: it depends on no other module of the crate, so [`crate::animation`],
//! [`crate::proxies`] and the scene itself can all use these types without depending on
//! each other.

use bytemuck::{Pod, Zeroable};
use glam::{Mat4, Quat, Vec2, Vec3, Vec4};

/// An axis-aligned bounding box. An empty box has `min > max`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Aabb {
    /// Smallest corner.
    pub min: Vec3,
    /// Largest corner.
    pub max: Vec3,
}

impl Default for Aabb {
    /// The empty box.
    fn default() -> Self {
        Aabb::EMPTY
    }
}

impl Aabb {
    /// The empty box (grows from nothing).
    pub const EMPTY: Aabb = Aabb {
        min: Vec3::splat(f32::INFINITY),
        max: Vec3::splat(f32::NEG_INFINITY),
    };

    /// Whether the box contains no point.
    pub fn is_empty(&self) -> bool {
        self.min.x > self.max.x || self.min.y > self.max.y || self.min.z > self.max.z
    }

    /// Grows the box to contain `p`.
    pub fn grow(&mut self, p: Vec3) {
        self.min = self.min.min(p);
        self.max = self.max.max(p);
    }

    /// The union of two boxes.
    pub fn union(&self, other: &Aabb) -> Aabb {
        Aabb {
            min: self.min.min(other.min),
            max: self.max.max(other.max),
        }
    }

    /// Centre of the box.
    pub fn center(&self) -> Vec3 {
        (self.min + self.max) * 0.5
    }

    /// Edge lengths of the box (zero for an empty box).
    pub fn extent(&self) -> Vec3 {
        (self.max - self.min).max(Vec3::ZERO)
    }

    /// Surface area (zero for an empty box).
    pub fn area(&self) -> f32 {
        let e = self.extent();
        2.0 * (e.x * e.y + e.y * e.z + e.z * e.x)
    }

    /// The box of this box's eight corners transformed by `m`.
    pub fn transformed(&self, m: &Mat4) -> Aabb {
        let mut out = Aabb::EMPTY;
        if self.is_empty() {
            return out;
        }
        for i in 0..8 {
            let c = Vec3::new(
                if i & 1 == 0 { self.min.x } else { self.max.x },
                if i & 2 == 0 { self.min.y } else { self.max.y },
                if i & 4 == 0 { self.min.z } else { self.max.z },
            );
            out.grow(m.transform_point3(c));
        }
        out
    }
}

/// A node's local transform as translation, rotation and scale (glTF TRS order: `T * R * S`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Transform {
    /// Translation in metres.
    pub translation: Vec3,
    /// Unit rotation quaternion.
    pub rotation: Quat,
    /// Scale per axis.
    pub scale: Vec3,
}

impl Default for Transform {
    /// The identity: no translation, no rotation, unit scale.
    fn default() -> Self {
        Transform {
            translation: Vec3::ZERO,
            rotation: Quat::IDENTITY,
            scale: Vec3::ONE,
        }
    }
}

impl Transform {
    /// The transform as a matrix.
    pub fn matrix(&self) -> Mat4 {
        Mat4::from_scale_rotation_translation(self.scale, self.rotation, self.translation)
    }
}

/// A node of the scene hierarchy.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Node {
    /// The glTF name, or `node<i>`.
    pub name: String,
    /// Parent node index, `None` for a root of the scene.
    pub parent: Option<usize>,
    /// Child node indices.
    pub children: Vec<usize>,
    /// Local transform at rest (before animation).
    pub transform: Transform,
    /// The mesh this node instances.
    pub mesh: Option<usize>,
    /// Index into [`Scene::cameras`](crate::Scene::cameras) of the camera on this node.
    pub camera: Option<usize>,
    /// Indices into [`Scene::lights`](crate::Scene::lights) of the lights on this node.
    pub lights: Vec<usize>,
    /// Index into [`Scene::skins`](crate::Scene::skins) of the skin deforming this node's
    /// mesh. A skinned mesh is placed by its joints alone: the node's own transform is
    /// ignored (glTF 2.0 §3.7.3).
    pub skin: Option<usize>,
    /// Morph weights overriding [`Mesh::weights`] for this node (glTF 2.0 §3.7.2.2), as
    /// many as the mesh has morph targets.
    pub weights: Option<Vec<f32>>,
}

/// A skin (glTF 2.0 §3.7.3): the joints a skinned mesh follows.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Skin {
    /// The glTF name, or `skin<i>`.
    pub name: String,
    /// Node indices of the joints; `JOINTS_0` values index this list.
    pub joints: Vec<usize>,
    /// One inverse bind matrix per joint (mesh space to the joint's space at bind time);
    /// the identity when the file gives none.
    pub inverse_bind: Vec<Mat4>,
}

/// One morph target of a primitive (glTF 2.0 §3.7.2.2): displacements added to the base
/// attributes, scaled by the target's weight.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct MorphTarget {
    /// Position deltas, one per vertex.
    pub positions: Vec<Vec3>,
    /// Normal deltas, one per vertex; empty when the file has none.
    pub normals: Vec<Vec3>,
}

/// One drawable piece of a mesh: one glTF primitive with one material, as indexed triangles.
///
/// All vertex arrays have the same length. Normals are unit length; tangents are unit `xyz`
/// with the bitangent sign in `w`, glTF convention. When the file has none they are generated:
/// MikkTSpace for normal-mapped materials, an arbitrary perpendicular otherwise.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Primitive {
    /// Positions in the node's local space (metres).
    pub positions: Vec<Vec3>,
    /// Unit normals.
    pub normals: Vec<Vec3>,
    /// Tangents: unit `xyz`, handedness `w` = ±1.
    pub tangents: Vec<Vec4>,
    /// First texture coordinate set (zero when the file has none).
    pub uvs: Vec<Vec2>,
    /// Triangle list indices into the vertex arrays.
    pub indices: Vec<u32>,
    /// Index into [`Scene::materials`](crate::Scene::materials).
    pub material: u32,
    /// Bounds of the positions (the base shape, in bind pose).
    pub bounds: Aabb,
    /// `JOINTS_0`: per vertex, four indices into the joint list of the node's skin; empty
    /// when the primitive is not skinned.
    pub joints: Vec<[u32; 4]>,
    /// `WEIGHTS_0`: per vertex, the weights of the four joints, non-negative and summing to
    /// 1; empty when the primitive is not skinned.
    pub weights: Vec<Vec4>,
    /// Morph targets; every primitive of a mesh has the same number.
    pub targets: Vec<MorphTarget>,
}

impl Primitive {
    /// Number of triangles.
    pub fn triangle_count(&self) -> usize {
        self.indices.len() / 3
    }

    /// Whether the primitive carries joints and weights.
    pub fn is_skinned(&self) -> bool {
        !self.joints.is_empty()
    }
}

/// A mesh: a list of primitives sharing a node transform.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Mesh {
    /// The glTF name, or `mesh<i>`.
    pub name: String,
    /// The primitives (one per material).
    pub primitives: Vec<Primitive>,
    /// Default morph weights, one per morph target (zeros when the file gives none).
    pub weights: Vec<f32>,
}

impl Mesh {
    /// Number of morph targets (the most over its primitives, which glTF requires equal).
    pub fn target_count(&self) -> usize {
        self.primitives
            .iter()
            .map(|p| p.targets.len())
            .max()
            .unwrap_or(0)
    }

    /// Bounds of all primitives in mesh space (base shapes, bind pose).
    pub fn bounds(&self) -> Aabb {
        self.primitives
            .iter()
            .fold(Aabb::EMPTY, |b, p| b.union(&p.bounds))
    }
}

/// No texture, in the texture index fields of [`Material`].
pub const NO_TEXTURE: u32 = u32::MAX;

/// A metallic-roughness material, laid out for a GPU buffer (std430-compatible, 80 bytes).
///
/// Texture fields index [`Scene::textures`](crate::Scene::textures) or hold [`NO_TEXTURE`].
/// All textures use UV set 0.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Pod, Zeroable)]
pub struct Material {
    /// Linear base colour and alpha.
    pub base_color: [f32; 4],
    /// Emitted radiance: linear emissive factor already multiplied by
    /// KHR_materials_emissive_strength.
    pub emissive: [f32; 3],
    /// Metalness factor, 0..1.
    pub metallic: f32,
    /// Perceptual roughness factor, 0..1.
    pub roughness: f32,
    /// Scale of the normal map's xy.
    pub normal_scale: f32,
    /// Alpha cutoff for `alpha_mode == 1` (mask); 0.5 by default.
    pub alpha_cutoff: f32,
    /// 0 opaque, 1 mask, 2 blend.
    pub alpha_mode: u32,
    /// Base colour texture (sRGB).
    pub base_color_texture: u32,
    /// Metallic (B) and roughness (G) texture (linear).
    pub metallic_roughness_texture: u32,
    /// Tangent-space normal map (linear).
    pub normal_texture: u32,
    /// Emissive texture (sRGB).
    pub emissive_texture: u32,
    /// 1 when the material is double sided.
    pub double_sided: u32,
    /// Padding to a multiple of 16 bytes.
    pub _pad: [u32; 3],
}

impl Material {
    /// Whether any of its texture fields names a texture.
    pub fn has_textures(&self) -> bool {
        [
            self.base_color_texture,
            self.metallic_roughness_texture,
            self.normal_texture,
            self.emissive_texture,
        ]
        .iter()
        .any(|&t| t != NO_TEXTURE)
    }
}

impl Default for Material {
    /// The glTF default material (glTF 2.0 §3.9.6): white, metallic 1, roughness 1, opaque.
    fn default() -> Self {
        Material {
            base_color: [1.0; 4],
            emissive: [0.0; 3],
            metallic: 1.0,
            roughness: 1.0,
            normal_scale: 1.0,
            alpha_cutoff: 0.5,
            alpha_mode: 0,
            base_color_texture: NO_TEXTURE,
            metallic_roughness_texture: NO_TEXTURE,
            normal_texture: NO_TEXTURE,
            emissive_texture: NO_TEXTURE,
            double_sided: 0,
            _pad: [0; 3],
        }
    }
}

/// A decoded texture image: tightly packed RGBA8 rows, top row first.
#[derive(Clone, Debug, PartialEq)]
pub struct Texture {
    /// The image's name or URI, for messages and debugging.
    pub name: String,
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// Whether the RGB channels are sRGB-encoded colour (base colour, emissive) rather than
    /// linear data (normals, metallic-roughness). Upload as `R8G8B8A8_SRGB` when set.
    pub srgb: bool,
    /// `width * height * 4` bytes.
    pub rgba8: Vec<u8>,
}

/// The kind of a light, as stored in [`Light::kind`].
#[repr(u32)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LightKind {
    /// Directional light, intensity in lux.
    Directional = 0,
    /// Point light, intensity in candela.
    Point = 1,
    /// Spot light, intensity in candela.
    Spot = 2,
}

/// A punctual light in world space, laid out for a GPU buffer (64 bytes).
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Pod, Zeroable)]
pub struct Light {
    /// World-space position (unused for directional lights).
    pub position: [f32; 3],
    /// A [`LightKind`] as `u32`.
    pub kind: u32,
    /// World-space unit direction the light shines along (the node's -Z).
    pub direction: [f32; 3],
    /// Range in metres beyond which the light is zero; 0 means infinite.
    pub range: f32,
    /// Linear RGB colour.
    pub color: [f32; 3],
    /// Candela (point, spot) or lux (directional).
    pub intensity: f32,
    /// Spot inner cone half-angle in radians (0 for other kinds).
    pub inner_cone_angle: f32,
    /// Spot outer cone half-angle in radians (0 for other kinds).
    pub outer_cone_angle: f32,
    /// Node carrying the light, or `u32::MAX` for a default light added by the loader.
    pub node: u32,
    /// Padding to a multiple of 16 bytes.
    pub _pad: u32,
}

impl Light {
    /// The light's kind, `None` if `kind` holds an unknown value.
    pub fn light_kind(&self) -> Option<LightKind> {
        match self.kind {
            0 => Some(LightKind::Directional),
            1 => Some(LightKind::Point),
            2 => Some(LightKind::Spot),
            _ => None,
        }
    }
}

/// A camera projection.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Projection {
    /// Perspective projection.
    Perspective {
        /// Vertical field of view in radians.
        yfov: f32,
        /// Aspect ratio (width / height); `None` means use the viewport's.
        aspect_ratio: Option<f32>,
        /// Near plane distance.
        znear: f32,
        /// Far plane distance; `None` means infinite.
        zfar: Option<f32>,
    },
    /// Orthographic projection.
    Orthographic {
        /// Half width of the view volume.
        xmag: f32,
        /// Half height of the view volume.
        ymag: f32,
        /// Near plane distance.
        znear: f32,
        /// Far plane distance.
        zfar: f32,
    },
}

impl Projection {
    /// Whether the projection can be rendered: perspective with a field of view in (0, π), a
    /// positive near plane, and a positive finite aspect ratio and a finite far plane beyond the
    /// near one when given; orthographic with finite non-zero magnifications and a non-negative
    /// near plane before a finite far plane.
    pub fn is_valid(&self) -> bool {
        match *self {
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
        }
    }
}

/// A camera. It looks along its local -Z with +Y up, as in glTF.
#[derive(Clone, Debug, PartialEq)]
pub struct Camera {
    /// The glTF name, or a description of the default camera.
    pub name: String,
    /// The projection.
    pub projection: Projection,
    /// Camera-to-world matrix at rest.
    pub world: Mat4,
    /// Node carrying the camera (it follows the node's animation); `None` for the default camera.
    pub node: Option<usize>,
}

/// One mesh placed in the world: what a draw call or a BVH instance needs (80 bytes).
///
/// Deformation (skins, morph targets) is not in here: see [`crate::Pose`] and
/// [`crate::Scene::instance_vertices`].
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Pod, Zeroable)]
pub struct Instance {
    /// Object-to-world matrix, column major.
    pub world: [[f32; 4]; 4],
    /// Index into [`Scene::meshes`](crate::Scene::meshes).
    pub mesh: u32,
    /// Index into [`Scene::nodes`](crate::Scene::nodes).
    pub node: u32,
    /// Index into [`Scene::skins`](crate::Scene::skins), or [`NO_SKIN`]. A skinned
    /// instance's `world` is the identity: its vertices are placed by the joint matrices
    /// alone (glTF 2.0 §3.7.3).
    pub skin: u32,
    /// Padding to a multiple of 16 bytes.
    pub _pad: u32,
}

/// No skin, in [`Instance::skin`].
pub const NO_SKIN: u32 = u32::MAX;

#[cfg(test)]
mod tests {
    use super::*;

    /// The default material has no texture; any one texture field makes one.
    #[test]
    fn has_textures_sees_every_texture_field() {
        assert!(!Material::default().has_textures());
        let with = |set: fn(&mut Material)| {
            let mut m = Material::default();
            set(&mut m);
            m.has_textures()
        };
        assert!(with(|m| m.base_color_texture = 0));
        assert!(with(|m| m.metallic_roughness_texture = 3));
        assert!(with(|m| m.normal_texture = 1));
        assert!(with(|m| m.emissive_texture = 2));
    }
}
