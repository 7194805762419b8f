//! Built-in procedural scenes, generated in code (no third-party models) and written as GLB.
//!
//! - `cornell-box`: the classic Cornell box (dimensions and colours of the Cornell data), in
//!   metres, with the ceiling lamp as a downward spot light plus an emissive patch.
//! - `spheres`: a ground plane and four animated objects lit by a procedural sky stored in
//!   the root `extras` (see [`crate::environment`]); each object carries explicit proxy
//!   spheres in its `extras` (paper 002).
//! - `room`: a textured multi-material room with normal-mapped tiles, glossy metal and
//!   plastic, and two lights (point and spot) (papers 000 and 003).
//! - `animated`: a room with a large window and a sky, a skinned figure walking across it
//!   (proxy spheres on its bones), a morphing curtain, a sweeping spot light and a dim lamp,
//!   all moving for 16 s (issue 15).
//! - `marbles`: 96 balls of six materials (gold, chrome, clay, plastics) on a wide ground
//!   under a low sun and an evening sky, each with its proxy sphere; a scene nothing was tuned
//!   on, and the one the proxies' neighbour lists are measured on (issue 18).
//! - `motion-sweep`, `motion-orbit`, `motion-sun`, `motion-crossing`, `motion-dolly`: one
//!   static room with one thing moving in each (a spot's sweep, a point light's orbit, a sun's
//!   turn, a box crossing a fixed spot's beam, the camera), for the temporal studies (issue 43;
//!   `motions`).
//! - `metals`: four metal spheres (chrome, silver, gold, copper; roughness 0.03 to 0.5) in a
//!   closed matte room under a warm spot and a cool point light, for measuring a specular
//!   denoiser at one sample per pixel; nothing was tuned on it (`metals`).
//!
//! `assets/<name>.glb` holds the exported files; a test checks they equal what [`build`]
//! produces now.

mod animated;
mod cornell_box;
mod marbles;
mod metals;
mod motions;
mod room;
pub mod shapes;
mod spheres;
mod textures;
mod tracks;
mod walker;

use std::io::Write;
use std::path::Path;

use crate::error::{Error, Result};
use crate::scene::Scene;

/// Names of the built-in scenes.
pub fn names() -> &'static [&'static str] {
    &[
        "cornell-box",
        "spheres",
        "room",
        "animated",
        "marbles",
        motions::NAMES[0],
        motions::NAMES[1],
        motions::NAMES[2],
        motions::NAMES[3],
        motions::NAMES[4],
        "metals",
    ]
}

/// The built-in scene `name` as GLB bytes.
pub fn build(name: &str) -> Result<Vec<u8>> {
    match name {
        "cornell-box" => Ok(cornell_box::build()),
        "spheres" => Ok(spheres::build()),
        "room" => Ok(room::build()),
        "animated" => animated::build(),
        "marbles" => Ok(marbles::build()),
        "metals" => Ok(metals::build()),
        _ => motions::build(name).ok_or_else(|| Error::UnknownBuiltin {
            name: name.to_string(),
            known: names().join(", "),
        }),
    }
}

/// The built-in scene `name`, loaded through the same loader as files.
pub fn scene(name: &str) -> Result<Scene> {
    let glb = build(name)?;
    let mut scene = crate::load_slice(&glb, None, &format!("built-in scene {name}"))?;
    scene.source = format!("builtin:{name}");
    Ok(scene)
}

/// Writes the built-in scene `name` to `path` as GLB, atomically: the bytes go to a
/// temporary file in the same directory, which is then renamed over `path`, so a reader
/// never sees a half-written file.
pub fn export(name: &str, path: impl AsRef<Path>) -> Result<()> {
    let glb = build(name)?;
    write_atomically(path.as_ref(), &glb)
}

/// Writes `bytes` to `path` through a temporary file in the same directory and a rename.
pub fn write_atomically(path: &Path, bytes: &[u8]) -> Result<()> {
    let err = |source: std::io::Error| Error::Write {
        path: path.to_path_buf(),
        source,
    };
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
        _ => std::path::PathBuf::from("."),
    };
    let file_name = path
        .file_name()
        .map(|f| f.to_string_lossy().into_owned())
        .unwrap_or_else(|| "scene".to_string());
    let tmp = dir.join(format!(".{file_name}.{}.tmp", std::process::id()));
    let result = (|| {
        let mut f = std::fs::File::create(&tmp)?;
        f.write_all(bytes)?;
        f.sync_all()?;
        std::fs::rename(&tmp, path)
    })();
    if result.is_err() {
        // Best effort: the temporary file must not linger; the original error is reported.
        let _ = std::fs::remove_file(&tmp);
    }
    result.map_err(err)
}

impl Scene {
    /// The built-in scene `name` (see [`names`]).
    pub fn builtin(name: &str) -> Result<Scene> {
        scene(name)
    }
}
