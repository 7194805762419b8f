//! What a run's inputs are, as keys that compare across processes and machines: a part of a
//! sharded run names its scene by them, and the lab names its cached truths by them.

/// FNV-1a of `bytes`: names cache files after what they hold.
pub fn fnv1a(bytes: &[u8]) -> u64 {
    bytes.iter().fold(0xcbf2_9ce4_8422_2325, |h, &b| {
        (h ^ u64::from(b)).wrapping_mul(0x0100_0000_01b3)
    })
}

/// The key of a scene's truths: the built-in's name, or a hash of the file's bytes (so an
/// edited file is traced again); `None` when the file cannot be read.
pub fn scene_key(scene: &str) -> Option<String> {
    if scene.starts_with("builtin:") {
        return Some(scene.replace(':', "-"));
    }
    let bytes = std::fs::read(scene).ok()?;
    Some(format!("file-{:016x}", fnv1a(&bytes)))
}
