//! What the engine needs from a device, what it can use when present, and the check of both.
//!
//! The baseline is Vulkan 1.3 core with synchronization2, dynamic rendering and timestamps:
//! what Mesa 22.3 lavapipe offers (docs/architecture.md, "Device layer"). Everything else is optional and reported.

use ash::vk;
use std::ffi::CStr;

/// What a host engine must enable on its device before wrapping it with
/// [`Device::from_raw`](crate::Device::from_raw).
#[derive(Clone, Debug)]
pub struct Requirements {
    /// Minimum instance and device API version.
    pub api_version: u32,
    /// Device extensions that must be enabled (none beyond core 1.3 today).
    pub device_extensions: &'static [&'static CStr],
    /// Vulkan 1.3 core features that must be enabled.
    pub vulkan13_features: &'static [&'static str],
    /// What the queue handed to shine must support.
    pub queue: &'static str,
}

impl Requirements {
    /// Sets every required Vulkan 1.3 feature on a host's feature struct.
    pub fn enable_vulkan13<'a>(
        &self,
        features: vk::PhysicalDeviceVulkan13Features<'a>,
    ) -> vk::PhysicalDeviceVulkan13Features<'a> {
        features.synchronization2(true).dynamic_rendering(true)
    }
}

/// The engine's requirements (see [`Requirements`]).
pub const REQUIREMENTS: Requirements = Requirements {
    api_version: vk::API_VERSION_1_3,
    device_extensions: &[],
    vulkan13_features: &["synchronization2", "dynamicRendering"],
    queue: "one queue family with GRAPHICS and COMPUTE and timestampValidBits > 0",
};

/// One line of the feature report: a feature the engine requires or can use.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct FeatureStatus {
    /// Name as in the Vulkan spec.
    pub name: &'static str,
    /// What shine uses it for.
    pub purpose: &'static str,
    /// Whether the engine cannot run without it.
    pub required: bool,
    /// Whether the device offers it.
    pub present: bool,
}

/// Support of a physical device, queried once.
#[derive(Clone, Debug)]
pub(crate) struct Support {
    pub api_version: u32,
    pub queue_family: Option<u32>,
    pub timestamp_valid_bits: u32,
    pub features: vk::PhysicalDeviceFeatures,
    pub synchronization2: bool,
    pub dynamic_rendering: bool,
    pub maintenance4: bool,
    pub host_query_reset: bool,
    pub scalar_block_layout: bool,
    pub shader_float16: bool,
    pub descriptor_indexing: bool,
    pub ray_query: bool,
    pub float_atomics: bool,
}

const RAY_QUERY: &CStr = c"VK_KHR_ray_query";
const FLOAT_ATOMICS: &CStr = c"VK_EXT_shader_atomic_float";

impl Support {
    /// Queries a physical device.
    pub(crate) fn query(instance: &ash::Instance, physical: vk::PhysicalDevice) -> Self {
        // SAFETY: `physical` was enumerated from `instance`, which is alive.
        let properties = unsafe { instance.get_physical_device_properties(physical) };
        // SAFETY: as above.
        let families = unsafe { instance.get_physical_device_queue_family_properties(physical) };
        let wanted = vk::QueueFlags::GRAPHICS | vk::QueueFlags::COMPUTE;
        let queue_family = families
            .iter()
            .position(|f| f.queue_flags.contains(wanted))
            .map(|i| i as u32);
        let timestamp_valid_bits = queue_family
            .and_then(|i| families.get(i as usize))
            .map_or(0, |f| f.timestamp_valid_bits);

        // SAFETY: as above.
        let extensions =
            unsafe { instance.enumerate_device_extension_properties(physical) }.unwrap_or_default();
        let has_extension = |name: &CStr| {
            extensions
                .iter()
                .any(|e| e.extension_name_as_c_str().is_ok_and(|n| n == name))
        };

        let mut f12 = vk::PhysicalDeviceVulkan12Features::default();
        let mut f13 = vk::PhysicalDeviceVulkan13Features::default();
        let api_version = properties.api_version;
        let (features, f12, f13) = if api_version >= vk::API_VERSION_1_2 {
            let mut f2 = vk::PhysicalDeviceFeatures2::default()
                .push_next(&mut f12)
                .push_next(&mut f13);
            // SAFETY: the chain holds structs the device's API version knows.
            unsafe { instance.get_physical_device_features2(physical, &mut f2) };
            let core = f2.features;
            (core, f12, f13)
        } else {
            // SAFETY: as above.
            let core = unsafe { instance.get_physical_device_features(physical) };
            (core, f12, f13)
        };
        let is_13 = api_version >= vk::API_VERSION_1_3;
        Self {
            api_version,
            queue_family,
            timestamp_valid_bits,
            features,
            synchronization2: is_13 && f13.synchronization2 == vk::TRUE,
            dynamic_rendering: is_13 && f13.dynamic_rendering == vk::TRUE,
            maintenance4: is_13 && f13.maintenance4 == vk::TRUE,
            host_query_reset: f12.host_query_reset == vk::TRUE,
            scalar_block_layout: f12.scalar_block_layout == vk::TRUE,
            shader_float16: f12.shader_float16 == vk::TRUE,
            descriptor_indexing: f12.descriptor_indexing == vk::TRUE
                && f12.runtime_descriptor_array == vk::TRUE,
            ray_query: has_extension(RAY_QUERY),
            float_atomics: has_extension(FLOAT_ATOMICS),
        }
    }

    /// Every requirement the device does not meet, named as in the spec.
    pub(crate) fn missing(&self) -> Vec<String> {
        let mut missing = Vec::new();
        if self.api_version < vk::API_VERSION_1_3 {
            missing.push(format!(
                "Vulkan 1.3 (device offers {}.{})",
                vk::api_version_major(self.api_version),
                vk::api_version_minor(self.api_version)
            ));
        }
        if self.queue_family.is_none() {
            missing.push("a queue family with GRAPHICS and COMPUTE".into());
        } else if self.timestamp_valid_bits == 0 {
            missing.push("timestamps (timestampValidBits is 0 on the queue)".into());
        }
        if !self.synchronization2 {
            missing.push("synchronization2 (Vulkan 1.3 feature)".into());
        }
        if !self.dynamic_rendering {
            missing.push("dynamicRendering (Vulkan 1.3 feature)".into());
        }
        missing
    }

    /// The report printed by `shine info`.
    pub(crate) fn report(&self) -> Vec<FeatureStatus> {
        let f = &self.features;
        let line = |name, purpose, required, present| FeatureStatus {
            name,
            purpose,
            required,
            present,
        };
        vec![
            line(
                "Vulkan 1.3",
                "baseline API",
                true,
                self.api_version >= vk::API_VERSION_1_3,
            ),
            line(
                "synchronization2",
                "render-graph barriers",
                true,
                self.synchronization2,
            ),
            line(
                "dynamicRendering",
                "raster passes without render passes",
                true,
                self.dynamic_rendering,
            ),
            line(
                "timestamps",
                "per-pass GPU timing",
                true,
                self.timestamp_valid_bits > 0,
            ),
            line(
                "fragmentStoresAndAtomics",
                "splatting passes writing buffers",
                false,
                f.fragment_stores_and_atomics == vk::TRUE,
            ),
            line(
                "vertexPipelineStoresAndAtomics",
                "vertex-stage buffer writes",
                false,
                f.vertex_pipeline_stores_and_atomics == vk::TRUE,
            ),
            line(
                "samplerAnisotropy",
                "texture filtering",
                false,
                f.sampler_anisotropy == vk::TRUE,
            ),
            line(
                "shaderInt64",
                "64-bit integers in shaders",
                false,
                f.shader_int64 == vk::TRUE,
            ),
            line(
                "shaderFloat64",
                "64-bit floats in shaders",
                false,
                f.shader_float64 == vk::TRUE,
            ),
            line(
                "shaderFloat16",
                "half-precision arithmetic",
                false,
                self.shader_float16,
            ),
            line(
                "scalarBlockLayout",
                "tightly packed buffers",
                false,
                self.scalar_block_layout,
            ),
            line(
                "hostQueryReset",
                "query reset from the host",
                false,
                self.host_query_reset,
            ),
            line(
                "maintenance4",
                "LocalSizeId SPIR-V",
                false,
                self.maintenance4,
            ),
            line(
                "descriptorIndexing",
                "bindless (never required)",
                false,
                self.descriptor_indexing,
            ),
            line(
                "VK_KHR_ray_query",
                "hardware ray queries (never required)",
                false,
                self.ray_query,
            ),
            line(
                "VK_EXT_shader_atomic_float",
                "float atomics (never required)",
                false,
                self.float_atomics,
            ),
        ]
    }

    /// Core features the engine enables when present.
    pub(crate) fn enabled_core(&self) -> vk::PhysicalDeviceFeatures {
        let f = &self.features;
        vk::PhysicalDeviceFeatures::default()
            .fragment_stores_and_atomics(f.fragment_stores_and_atomics == vk::TRUE)
            .vertex_pipeline_stores_and_atomics(f.vertex_pipeline_stores_and_atomics == vk::TRUE)
            .sampler_anisotropy(f.sampler_anisotropy == vk::TRUE)
            .shader_int64(f.shader_int64 == vk::TRUE)
            .shader_float64(f.shader_float64 == vk::TRUE)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn lavapipe_like() -> Support {
        Support {
            api_version: vk::make_api_version(0, 1, 3, 230),
            queue_family: Some(0),
            timestamp_valid_bits: 64,
            features: vk::PhysicalDeviceFeatures::default(),
            synchronization2: true,
            dynamic_rendering: true,
            maintenance4: true,
            host_query_reset: true,
            scalar_block_layout: true,
            shader_float16: true,
            descriptor_indexing: false,
            ray_query: false,
            float_atomics: false,
        }
    }

    #[test]
    fn a_complete_device_misses_nothing() {
        assert!(lavapipe_like().missing().is_empty());
    }

    #[test]
    fn every_shortfall_is_named() {
        let old = Support {
            api_version: vk::make_api_version(0, 1, 2, 0),
            timestamp_valid_bits: 0,
            synchronization2: false,
            dynamic_rendering: false,
            ..lavapipe_like()
        };
        assert_eq!(
            old.missing(),
            [
                "Vulkan 1.3 (device offers 1.2)",
                "timestamps (timestampValidBits is 0 on the queue)",
                "synchronization2 (Vulkan 1.3 feature)",
                "dynamicRendering (Vulkan 1.3 feature)",
            ]
        );
        let no_queue = Support {
            queue_family: None,
            ..lavapipe_like()
        };
        assert_eq!(
            no_queue.missing(),
            ["a queue family with GRAPHICS and COMPUTE"]
        );
    }

    #[test]
    fn optional_features_never_block() {
        let report = lavapipe_like().report();
        let ray_query = report
            .iter()
            .find(|f| f.name == "VK_KHR_ray_query")
            .map(|f| (f.required, f.present));
        assert_eq!(ray_query, Some((false, false)));
        assert!(report.iter().filter(|f| f.required).all(|f| f.present));
    }
}

/// What a host enabled when it created the device it lends shine ([`crate::RawDevice`]):
/// `Device::from_raw` checks it against [`REQUIREMENTS`], since a physical device that offers
/// a feature says nothing about whether the host turned it on.
#[derive(Clone, Debug)]
pub struct EnabledFeatures {
    /// The API version the host's instance asked for.
    pub api_version: u32,
    /// Core features enabled (`VkPhysicalDeviceFeatures`).
    pub features: vk::PhysicalDeviceFeatures,
    /// `synchronization2` of `VkPhysicalDeviceVulkan13Features`.
    pub synchronization2: bool,
    /// `dynamicRendering` of `VkPhysicalDeviceVulkan13Features`.
    pub dynamic_rendering: bool,
    /// Device extensions enabled.
    pub extensions: Vec<std::ffi::CString>,
}

impl EnabledFeatures {
    /// Exactly what [`REQUIREMENTS`] asks for: what a host that enables only shine's needs
    /// passes.
    pub fn required() -> Self {
        Self {
            api_version: REQUIREMENTS.api_version,
            features: vk::PhysicalDeviceFeatures::default(),
            synchronization2: true,
            dynamic_rendering: true,
            extensions: REQUIREMENTS
                .device_extensions
                .iter()
                .map(|e| (*e).to_owned())
                .collect(),
        }
    }

    /// What the host put in its `VkDeviceCreateInfo`: its API version, core features, the
    /// Vulkan 1.3 feature struct it chained and its extension names.
    pub fn from_parts(
        api_version: u32,
        features: &vk::PhysicalDeviceFeatures,
        vulkan13: &vk::PhysicalDeviceVulkan13Features<'_>,
        extensions: &[&CStr],
    ) -> Self {
        Self {
            api_version,
            features: *features,
            synchronization2: vulkan13.synchronization2 == vk::TRUE,
            dynamic_rendering: vulkan13.dynamic_rendering == vk::TRUE,
            extensions: extensions.iter().map(|e| (*e).to_owned()).collect(),
        }
    }

    /// Every requirement the host did not enable, named as in the spec.
    pub(crate) fn missing(&self) -> Vec<String> {
        let mut missing = Vec::new();
        if self.api_version < REQUIREMENTS.api_version {
            missing.push(format!(
                "Vulkan {}.{} (the host asked for {}.{})",
                vk::api_version_major(REQUIREMENTS.api_version),
                vk::api_version_minor(REQUIREMENTS.api_version),
                vk::api_version_major(self.api_version),
                vk::api_version_minor(self.api_version)
            ));
        }
        for (name, on) in [
            ("synchronization2", self.synchronization2),
            ("dynamicRendering", self.dynamic_rendering),
        ] {
            if !on {
                missing.push(format!(
                    "{name} (Vulkan 1.3 feature): not enabled by the host"
                ));
            }
        }
        for e in REQUIREMENTS.device_extensions {
            if !self.extensions.iter().any(|x| x.as_c_str() == *e) {
                missing.push(format!(
                    "{} (device extension): not enabled by the host",
                    e.to_string_lossy()
                ));
            }
        }
        missing
    }
}
