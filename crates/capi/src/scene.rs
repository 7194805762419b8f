//! Scenes for C hosts: loaded from glTF (or a built-in), flattened for the host's rasteriser,
//! and their cameras, so a C host draws the same geometry the context lights.

use crate::error::{Failure, ShineResult, call};
use crate::geometry::ShineLight;
use crate::handles::{self, SceneObject, ShineScene, lock};
use crate::types::{ShineDraw, ShineGeometry};
use shine::embed::GiCamera;
use std::ffi::{CStr, c_char};

/// Loads a glTF file (`.gltf`, `.glb`) or a built-in scene (`builtin:cornell-box`, …) and
/// writes its handle to `out` (null on failure).
///
/// # Safety
/// `path` is null or a NUL-terminated string; `out` is null or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn shine_scene_load(
    path: *const c_char,
    out: *mut ShineScene,
) -> ShineResult {
    call(|| {
        // SAFETY: the caller's promise.
        let out = unsafe { out.as_mut() }.ok_or_else(|| Failure::invalid("out is null"))?;
        *out = std::ptr::null_mut();
        // SAFETY: as above.
        let path = unsafe { string(path, "path") }?;
        let scene = match path.strip_prefix("builtin:") {
            Some(name) => shine::scene::Scene::builtin(name),
            None => shine::scene::load(std::path::Path::new(&path)),
        }
        .map_err(|e| Failure::new(ShineResult::ErrorScene, e.to_string()))?;
        *out = handles::add_scene(SceneObject {
            scene,
            flat: Default::default(),
            draws: Vec::new(),
        });
        Ok(())
    })
}

/// Flattens the scene posed at time `t` into world-space arrays (`ShineGeometry`), which stay
/// valid until the scene's next flattening or its destruction.
///
/// # Safety
/// `out` is null or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn shine_scene_flatten(
    scene: ShineScene,
    t: f32,
    out: *mut ShineGeometry,
) -> ShineResult {
    call(|| {
        let object = handles::scene(scene)?;
        // SAFETY: the caller's promise.
        let out = unsafe { out.as_mut() }.ok_or_else(|| Failure::invalid("out is null"))?;
        if !t.is_finite() {
            return Err(Failure::invalid(format!("time {t} is not finite")));
        }
        let mut guard = lock(&object);
        let o = &mut *guard;
        o.flat = o.scene.flatten_at(t);
        let materials = &o.scene.materials;
        o.draws = o
            .flat
            .draws
            .iter()
            .map(|d| {
                let material = d.material.and_then(|m| materials.get(m));
                ShineDraw {
                    first_index: d.first_index,
                    index_count: d.index_count,
                    base_color: d.base_color,
                    roughness: d.roughness,
                    metallic: d.metallic,
                    emissive: material.map_or([0.0; 3], |m| m.emissive),
                    double_sided: material.map_or(0, |m| m.double_sided),
                }
            })
            .collect();
        let count = |n: usize, what: &str| {
            u32::try_from(n).map_err(|_| Failure::invalid(format!("{n} {what}: too many")))
        };
        *out = ShineGeometry {
            vertex_count: count(o.flat.vertices.len(), "vertices")?,
            vertices: o.flat.vertices.as_ptr().cast(),
            index_count: count(o.flat.indices.len(), "indices")?,
            indices: o.flat.indices.as_ptr(),
            draw_count: count(o.draws.len(), "draws")?,
            draws: o.draws.as_ptr(),
        };
        Ok(())
    })
}

/// Camera `index` of the scene at time `t` for a `width`×`height` image: column-major world
/// to view and unjittered Vulkan projection, as shine's renderer computes them.
///
/// # Safety
/// `view` and `projection` are null or point to 16 writable floats each.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn shine_scene_camera(
    scene: ShineScene,
    index: u32,
    t: f32,
    width: u32,
    height: u32,
    view: *mut f32,
    projection: *mut f32,
) -> ShineResult {
    call(|| {
        let object = handles::scene(scene)?;
        if view.is_null() || projection.is_null() {
            return Err(Failure::invalid("view and projection must not be null"));
        }
        if width == 0 || height == 0 || !t.is_finite() {
            return Err(Failure::invalid(format!(
                "camera of a {width}x{height} image at time {t}"
            )));
        }
        let o = lock(&object);
        let camera = GiCamera::from_scene(&o.scene, index as usize, t, t, [width, height])
            .ok_or_else(|| {
                Failure::invalid(format!(
                    "camera {index}: the scene has {}",
                    o.scene.cameras.len()
                ))
            })?;
        // SAFETY: 16 writable floats each (the caller's promise).
        unsafe {
            std::ptr::copy_nonoverlapping(camera.view.to_cols_array().as_ptr(), view, 16);
            std::ptr::copy_nonoverlapping(
                camera.projection.to_cols_array().as_ptr(),
                projection,
                16,
            );
        }
        Ok(())
    })
}

/// The scene's lights at time `t`, in world space: writes up to `capacity` of them to `out`
/// (which may be null when `capacity` is 0) and their total number to `count`, as Vulkan's
/// enumerations do.
///
/// # Safety
/// `out` holds `capacity` writable lights; `count` is null or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn shine_scene_lights(
    scene: ShineScene,
    t: f32,
    out: *mut ShineLight,
    capacity: u32,
    count: *mut u32,
) -> ShineResult {
    call(|| {
        let object = handles::scene(scene)?;
        // SAFETY: the caller's promise.
        let count = unsafe { count.as_mut() }.ok_or_else(|| Failure::invalid("count is null"))?;
        if !t.is_finite() {
            return Err(Failure::invalid(format!("time {t} is not finite")));
        }
        if capacity > 0 && out.is_null() {
            return Err(Failure::invalid("out is null with a nonzero capacity"));
        }
        let o = lock(&object);
        let lights = o.scene.lights_at(&o.scene.world_transforms_at(t));
        *count = u32::try_from(lights.len()).map_err(|_| Failure::invalid("too many lights"))?;
        for (i, l) in lights.iter().take(capacity as usize).enumerate() {
            let light = ShineLight {
                kind: l.kind,
                position: l.position,
                direction: l.direction,
                color: l.color,
                intensity: l.intensity,
                range: l.range,
                inner_cone_angle: l.inner_cone_angle,
                outer_cone_angle: l.outer_cone_angle,
            };
            // SAFETY: `i` < `capacity` (the caller's promise).
            unsafe { out.add(i).write(light) };
        }
        Ok(())
    })
}

/// Releases the scene (contexts it was set on keep their own copy on the device).
///
/// # Safety
/// `scene` is any value (null and stale handles are refused).
#[unsafe(no_mangle)]
pub unsafe extern "C" fn shine_scene_destroy(scene: ShineScene) -> ShineResult {
    call(|| handles::remove(scene, "scene"))
}

/// The UTF-8 string at `p`, or the failure a null or non-UTF-8 `name` gets.
///
/// # Safety
/// `p` is null or NUL-terminated.
pub(crate) unsafe fn string(p: *const c_char, name: &str) -> Result<String, Failure> {
    if p.is_null() {
        return Err(Failure::invalid(format!("{name} is null")));
    }
    // SAFETY: the caller's promise.
    unsafe { CStr::from_ptr(p) }
        .to_str()
        .map(str::to_owned)
        .map_err(|_| Failure::invalid(format!("{name} is not UTF-8")))
}
