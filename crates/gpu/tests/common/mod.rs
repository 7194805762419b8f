//! What the shine-gpu tests share: a device with the validation layer (required in CI).

use shine_gpu::{Device, DeviceDesc, Validation};

/// A Vulkan 1.3 device (lavapipe in CI) with the validation layer: required when `CI` is set,
/// else when installed.
pub fn device() -> Device {
    let validation = if std::env::var_os("CI").is_some() {
        Validation::Required
    } else {
        Validation::IfAvailable
    };
    Device::new(&DeviceDesc {
        validation,
        ..DeviceDesc::from_env()
    })
    .unwrap_or_else(|e| panic!("GPU tests need a Vulkan 1.3 device: {e}"))
}
