//! The objects behind the C API's handles. A handle is a number (drawn from a counter that
//! never repeats) cast to an opaque pointer type: looking it up can tell a null, destroyed,
//! never-made or wrong-kind handle from a live one without touching freed memory.
//!
//! The handle types keep C's `_T` spelling (`typedef struct ShineDevice_T *ShineDevice`).
#![allow(non_camel_case_types)]

use crate::error::{Failure, ShineResult};
use shine::embed::{Device, GiContext};
use std::collections::BTreeMap;
use std::sync::{Arc, Mutex, MutexGuard};

/// What a `ShineDevice` points to (never dereferenced).
pub struct ShineDevice_T {
    _opaque: [u8; 0],
}

/// What a `ShineScene` points to (never dereferenced).
pub struct ShineScene_T {
    _opaque: [u8; 0],
}

/// What a `ShineContext` points to (never dereferenced).
pub struct ShineContext_T {
    _opaque: [u8; 0],
}

/// A device lent by the host.
pub type ShineDevice = *mut ShineDevice_T;
/// A scene loaded from glTF or a built-in.
pub type ShineScene = *mut ShineScene_T;
/// A GI context.
pub type ShineContext = *mut ShineContext_T;

/// A loaded scene and the last flattening handed out (its arrays stay valid until the next).
pub(crate) struct SceneObject {
    pub scene: shine::scene::Scene,
    pub flat: shine::scene::FlatScene,
    pub draws: Vec<crate::types::ShineDraw>,
}

/// What a handle names.
enum Object {
    Device(Device),
    Scene(Arc<Mutex<SceneObject>>),
    Context(Arc<Mutex<GiContext>>),
}

impl Object {
    fn kind(&self) -> &'static str {
        match self {
            Object::Device(_) => "a device",
            Object::Scene(_) => "a scene",
            Object::Context(_) => "a context",
        }
    }
}

/// Every live object by handle number.
struct Registry {
    next: u64,
    objects: BTreeMap<u64, Object>,
}

static REGISTRY: Mutex<Registry> = Mutex::new(Registry {
    next: 1,
    objects: BTreeMap::new(),
});

fn registry() -> MutexGuard<'static, Registry> {
    REGISTRY
        .lock()
        .unwrap_or_else(std::sync::PoisonError::into_inner)
}

/// Registers `object` under a new number.
fn insert(object: Object) -> u64 {
    let mut r = registry();
    let id = r.next;
    r.next += 1;
    r.objects.insert(id, object);
    id
}

/// The number of a handle of `kind`, or the failure a null one gets.
fn number<T>(handle: *mut T, kind: &str) -> Result<u64, Failure> {
    if handle.is_null() {
        return Err(Failure::new(
            ShineResult::ErrorNullHandle,
            format!("{kind} handle is null"),
        ));
    }
    Ok(handle as usize as u64)
}

/// The failure of a handle that names nothing, or something else.
fn stale(id: u64, kind: &str, found: Option<&Object>) -> Failure {
    let what = match found {
        Some(o) => format!("it names {}", o.kind()),
        None => "it was destroyed or never made".into(),
    };
    Failure::new(
        ShineResult::ErrorStaleHandle,
        format!("{kind} handle {id:#x} is not a live {kind}: {what}"),
    )
}

/// A new device handle.
pub(crate) fn add_device(device: Device) -> *mut ShineDevice_T {
    insert(Object::Device(device)) as usize as *mut ShineDevice_T
}

/// A new scene handle.
pub(crate) fn add_scene(scene: SceneObject) -> *mut ShineScene_T {
    insert(Object::Scene(Arc::new(Mutex::new(scene)))) as usize as *mut ShineScene_T
}

/// A new context handle.
pub(crate) fn add_context(context: GiContext) -> *mut ShineContext_T {
    insert(Object::Context(Arc::new(Mutex::new(context)))) as usize as *mut ShineContext_T
}

/// The device behind `handle`.
pub(crate) fn device(handle: *mut ShineDevice_T) -> Result<Device, Failure> {
    let id = number(handle, "device")?;
    match registry().objects.get(&id) {
        Some(Object::Device(d)) => Ok(d.clone()),
        other => Err(stale(id, "device", other)),
    }
}

/// The scene behind `handle`.
pub(crate) fn scene(handle: *mut ShineScene_T) -> Result<Arc<Mutex<SceneObject>>, Failure> {
    let id = number(handle, "scene")?;
    match registry().objects.get(&id) {
        Some(Object::Scene(s)) => Ok(Arc::clone(s)),
        other => Err(stale(id, "scene", other)),
    }
}

/// The context behind `handle`.
pub(crate) fn context(handle: *mut ShineContext_T) -> Result<Arc<Mutex<GiContext>>, Failure> {
    let id = number(handle, "context")?;
    match registry().objects.get(&id) {
        Some(Object::Context(c)) => Ok(Arc::clone(c)),
        other => Err(stale(id, "context", other)),
    }
}

/// Removes the object of `kind` behind `handle` (a context is dropped once no call on
/// another thread still holds it).
pub(crate) fn remove<T>(handle: *mut T, kind: &'static str) -> Result<(), Failure> {
    let id = number(handle, kind)?;
    let mut r = registry();
    let matches = r
        .objects
        .get(&id)
        .is_some_and(|o| o.kind().strip_prefix("a ").is_some_and(|k| k == kind));
    if !matches {
        return Err(stale(id, kind, r.objects.get(&id)));
    }
    let object = r.objects.remove(&id);
    drop(r);
    drop(object);
    Ok(())
}

/// Locks `mutex`, recovering from a panic on another thread (the call that panicked already
/// reported an internal error).
pub(crate) fn lock<T>(mutex: &Mutex<T>) -> MutexGuard<'_, T> {
    mutex
        .lock()
        .unwrap_or_else(std::sync::PoisonError::into_inner)
}
