//! shine-scene: everything the engine needs to know about a scene, as plain data. No GPU.
