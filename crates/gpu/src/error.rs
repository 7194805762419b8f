//! Errors of the device layer: every Vulkan failure becomes a value with context.

use ash::vk;

/// Result alias for the device layer.
pub type Result<T, E = Error> = std::result::Result<T, E>;

/// Everything that can go wrong in shine-gpu.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// The Vulkan loader (libvulkan) could not be loaded.
    #[error(
        "cannot load the Vulkan loader: {0}. Install it (Debian: `apt-get install libvulkan1 mesa-vulkan-drivers`)"
    )]
    Loader(#[from] ash::LoadingError),

    /// A Vulkan call failed.
    #[error("{context}: {result}{hint}", hint = hint(*.result))]
    Vulkan {
        /// What the engine was doing.
        context: String,
        /// The Vulkan result code.
        result: vk::Result,
    },

    /// No physical device supports Vulkan 1.3 with a graphics+compute queue.
    #[error(
        "no Vulkan device found{detail}. On a machine without a GPU install lavapipe (Debian: `apt-get install mesa-vulkan-drivers`)"
    )]
    NoDevice {
        /// What was found instead, if anything.
        detail: String,
    },

    /// `SHINE_DEVICE` (or the requested selector) matched no device.
    #[error("no Vulkan device matches `{selector}`; available: {available}")]
    DeviceNotFound {
        /// The index or name substring asked for.
        selector: String,
        /// The devices that exist, as `index: name`.
        available: String,
    },

    /// The chosen device lacks what the engine needs.
    #[error("device `{device}` lacks what shine needs: {}", .missing.join(", "))]
    MissingFeatures {
        /// Device name.
        device: String,
        /// Every missing requirement, named as in the Vulkan spec.
        missing: Vec<String>,
    },

    /// Validation was required but the Khronos layer is not installed.
    #[error(
        "validation requested but VK_LAYER_KHRONOS_validation is not installed (Debian: `apt-get install vulkan-validationlayers`)"
    )]
    ValidationUnavailable,

    /// gpu-allocator failed.
    #[error("memory allocation failed for `{name}`: {source}")]
    Allocation {
        /// Name of the resource being allocated.
        name: String,
        /// The allocator's error.
        source: gpu_allocator::AllocationError,
    },

    /// A resource does not fit what it is used for (size, usage, mapping).
    #[error("{0}")]
    InvalidUsage(String),

    /// A pipeline was bound with resources that do not match its reflected bindings.
    #[error("pipeline `{pipeline}`: {message}")]
    Binding {
        /// Shader or pipeline name.
        pipeline: String,
        /// What does not match.
        message: String,
    },
}

impl Error {
    /// Wraps a Vulkan result code with what was being done.
    pub fn vk(context: impl Into<String>, result: vk::Result) -> Self {
        Self::Vulkan {
            context: context.into(),
            result,
        }
    }

    /// True when the device was lost: the caller must recreate it.
    pub fn is_device_lost(&self) -> bool {
        matches!(
            self,
            Self::Vulkan {
                result: vk::Result::ERROR_DEVICE_LOST,
                ..
            }
        )
    }
}

fn hint(result: vk::Result) -> &'static str {
    match result {
        vk::Result::ERROR_DEVICE_LOST => " (the device was lost: recreate it)",
        vk::Result::ERROR_OUT_OF_DEVICE_MEMORY => {
            " (out of GPU memory: lower the resolution or counts)"
        }
        vk::Result::ERROR_OUT_OF_HOST_MEMORY => " (out of host memory)",
        vk::Result::ERROR_FEATURE_NOT_PRESENT | vk::Result::ERROR_EXTENSION_NOT_PRESENT => {
            " (run `shine info` to see what the device offers)"
        }
        vk::Result::ERROR_LAYER_NOT_PRESENT => " (install vulkan-validationlayers)",
        _ => "",
    }
}

/// Adds context to a raw Vulkan result.
pub(crate) trait VkContext<T> {
    /// Maps the error with a description of the call.
    fn ctx(self, context: &str) -> Result<T>;
}

impl<T> VkContext<T> for std::result::Result<T, vk::Result> {
    fn ctx(self, context: &str) -> Result<T> {
        self.map_err(|r| Error::vk(context, r))
    }
}
