//! shine-scene: everything the engine needs to know about a scene, as plain data. No GPU.
//!
//! - [`load()`] / [`load_slice`]: glTF 2.0 (`.gltf` + `.bin`, `.glb`, data URIs) into a [`Scene`]
//!   of flat arrays: meshes (with skinning attributes and morph targets), skins, instances,
//!   materials, RGBA8 textures, lights, cameras, animations, environment, proxy spheres, and
//!   the warnings met on the way.
//! - [`builtin`]: the procedural scenes `cornell-box`, `spheres`, `room` and `animated`,
//!   written as GLB by [`builtin::export`].
//! - [`bvh`]: a binned-SAH bounding volume hierarchy over all triangles, flattened for the
//!   GPU and refittable after animation.
//! - [`proxies`]: proxy spheres for dynamic objects (paper 002).
//! - [`animation`]: node and morph weight animation evaluated at any time.
//! - [`Pose`]: everything time-dependent at one instant (node matrices, morph weights, joint
//!   matrices; [`Scene::pose_at`], or [`Scene::pose`] for a host animating nodes itself),
//!   and [`Scene::instance_vertices`], the CPU reference of morphing and skinning that a GPU
//!   deformation pass is tested against.
#![cfg_attr(not(test), deny(clippy::unwrap_used, clippy::expect_used))]

pub mod animation;
pub mod builtin;
pub mod bvh;
pub mod environment;
mod error;
mod flat;
pub mod glb_writer;
mod load;
mod pose;
pub mod proxies;
mod scene;
mod types;

pub use error::{Error, Result};
pub use flat::{FlatDraw, FlatScene};
pub use load::{
    DEFAULT_SUN_DIRECTION, DEFAULT_SUN_LUX, DEFAULT_YFOV, SUPPORTED_EXTENSIONS, load, load_slice,
};
pub use pose::{DeformedVertices, Pose, skin_matrix};
pub use scene::Scene;
pub use types::{
    Aabb, Camera, Instance, Light, LightKind, Material, Mesh, MorphTarget, NO_SKIN, NO_TEXTURE,
    Node, Primitive, Projection, Skin, Texture, Transform,
};
