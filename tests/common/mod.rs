//! Shared set-up of the GPU tests: a validated device that fails loudly when absent.

use shine::gpu::{Device, DeviceDesc, Validation};

/// Creates the test device with the validation layer (synchronization validation on).
///
/// Never skips: without a Vulkan device or, under `CI`, without the validation layer, the test
/// fails with the install command (DESIGN §8).
pub fn device() -> Device {
    let validation = if std::env::var_os("CI").is_some() {
        Validation::Required
    } else {
        Validation::IfAvailable
    };
    let desc = DeviceDesc {
        validation,
        ..DeviceDesc::from_env()
    };
    match Device::new(&desc) {
        Ok(device) => device,
        Err(e) => panic!(
            "GPU tests need a Vulkan 1.3 device and the validation layer: {e}\n\
             (Debian: apt-get install libvulkan1 mesa-vulkan-drivers vulkan-validationlayers)"
        ),
    }
}

/// Asserts that the validation layer and driver reported no error and no warning.
pub fn assert_clean(device: &Device) {
    if let Err(e) = device.wait_idle() {
        panic!("waiting for the device failed: {e}");
    }
    let counts = device.message_counts();
    assert_eq!(
        counts.problems(),
        0,
        "validation reported {} error(s) and {} warning(s):\n{}",
        counts.errors,
        counts.warnings,
        device.messages().join("\n")
    );
}
