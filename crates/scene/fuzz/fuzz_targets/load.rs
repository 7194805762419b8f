//! Fuzzes the glTF loader: any bytes, as .gltf JSON or .glb, must give a scene or an error.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let _ = shine_scene::load_slice(data, None, "fuzz input");
});
