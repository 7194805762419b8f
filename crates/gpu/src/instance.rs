//! Creating the Vulkan instance and choosing a physical device for a headless [`Device`], and
//! the guards that destroy what was created when device creation fails part-way.
//!
//! [`Device`]: crate::Device

use crate::error::{Error, Result};
use crate::features::Support;
use crate::validation::{self, MessageLog};
use ash::vk;
use std::ffi::CStr;

/// The Khronos validation layer's name.
pub(crate) const VALIDATION_LAYER: &CStr = c"VK_LAYER_KHRONOS_validation";

/// A physical device as listed by [`Device::enumerate`](crate::Device::enumerate).
#[derive(Clone, Debug)]
pub struct Adapter {
    /// Index used by `SHINE_DEVICE=<index>`.
    pub index: usize,
    /// Device name.
    pub name: String,
    /// Device type.
    pub device_type: vk::PhysicalDeviceType,
    /// Requirements it does not meet (empty when usable).
    pub missing: Vec<String>,
}

/// Objects shine created and must destroy (absent for a wrapped host device).
pub(crate) struct Owned {
    pub(crate) debug_instance:
        Option<(ash::ext::debug_utils::Instance, vk::DebugUtilsMessengerEXT)>,
}

/// The debug-utils messenger that counts validation messages into `log`.
pub(crate) fn messenger_info(log: &MessageLog) -> vk::DebugUtilsMessengerCreateInfoEXT<'static> {
    vk::DebugUtilsMessengerCreateInfoEXT::default()
        .message_severity(validation::severities())
        .message_type(validation::message_types())
        .pfn_user_callback(Some(validation::callback))
        .user_data(log as *const MessageLog as *mut std::ffi::c_void)
}

/// A Vulkan 1.3 instance, with the validation layer and debug utils when asked for.
pub(crate) fn create_instance(
    entry: &ash::Entry,
    validation: bool,
    debug_utils: bool,
    log: Option<&MessageLog>,
) -> Result<ash::Instance> {
    let app = vk::ApplicationInfo::default()
        .application_name(c"shine")
        .engine_name(c"shine")
        .api_version(vk::API_VERSION_1_3);
    let layers = if validation {
        vec![VALIDATION_LAYER.as_ptr()]
    } else {
        vec![]
    };
    let mut extensions = Vec::new();
    if debug_utils {
        extensions.push(ash::ext::debug_utils::NAME.as_ptr());
    }
    if validation {
        extensions.push(ash::ext::validation_features::NAME.as_ptr());
    }
    let enables = [vk::ValidationFeatureEnableEXT::SYNCHRONIZATION_VALIDATION];
    let mut features = vk::ValidationFeaturesEXT::default().enabled_validation_features(&enables);
    let mut messenger = log.map(messenger_info);
    let mut info = vk::InstanceCreateInfo::default()
        .application_info(&app)
        .enabled_layer_names(&layers)
        .enabled_extension_names(&extensions);
    if validation {
        info = info.push_next(&mut features);
    }
    if let Some(messenger) = messenger.as_mut() {
        info = info.push_next(messenger);
    }
    // SAFETY: every pointer in `info` outlives this call.
    unsafe { entry.create_instance(&info, None) }.map_err(|result| match result {
        vk::Result::ERROR_INCOMPATIBLE_DRIVER => Error::NoDevice {
            detail: " (the loader found no Vulkan driver)".into(),
        },
        other => Error::vk("creating the Vulkan instance", other),
    })
}

/// The device name a physical device reports.
pub(crate) fn physical_name(instance: &ash::Instance, physical: vk::PhysicalDevice) -> String {
    // SAFETY: the physical device belongs to the instance.
    let properties = unsafe { instance.get_physical_device_properties(physical) };
    properties.device_name_as_c_str().map_or_else(
        |_| "unnamed device".into(),
        |n| n.to_string_lossy().into_owned(),
    )
}

/// Every physical device with what it lacks of shine's requirements.
pub(crate) fn list_adapters(
    instance: &ash::Instance,
) -> Result<Vec<(Adapter, vk::PhysicalDevice)>> {
    // SAFETY: the instance is alive.
    let physicals = match unsafe { instance.enumerate_physical_devices() } {
        Ok(list) => list,
        Err(vk::Result::ERROR_INITIALIZATION_FAILED) => Vec::new(),
        Err(e) => return Err(Error::vk("enumerating physical devices", e)),
    };
    Ok(physicals
        .into_iter()
        .enumerate()
        .map(|(index, physical)| {
            // SAFETY: enumerated from this instance.
            let properties = unsafe { instance.get_physical_device_properties(physical) };
            let adapter = Adapter {
                index,
                name: physical_name(instance, physical),
                device_type: properties.device_type,
                missing: Support::query(instance, physical).missing(),
            };
            (adapter, physical)
        })
        .collect())
}

/// Preference of a device type: discrete before integrated before virtual before CPU.
fn type_rank(t: vk::PhysicalDeviceType) -> u32 {
    match t {
        vk::PhysicalDeviceType::DISCRETE_GPU => 0,
        vk::PhysicalDeviceType::INTEGRATED_GPU => 1,
        vk::PhysicalDeviceType::VIRTUAL_GPU => 2,
        vk::PhysicalDeviceType::CPU => 3,
        _ => 4,
    }
}

/// The adapter `selector` names (`SHINE_DEVICE`: an index or a name substring), or the
/// most preferred usable one.
pub(crate) fn choose<'a>(
    adapters: &'a [(Adapter, vk::PhysicalDevice)],
    selector: Option<&str>,
) -> Result<(&'a Adapter, vk::PhysicalDevice)> {
    if adapters.is_empty() {
        return Err(Error::NoDevice {
            detail: String::new(),
        });
    }
    if let Some(selector) = selector {
        let wanted = selector.to_lowercase();
        let found = match selector.parse::<usize>() {
            Ok(index) => adapters.iter().find(|(a, _)| a.index == index),
            Err(_) => adapters
                .iter()
                .find(|(a, _)| a.name.to_lowercase().contains(&wanted)),
        };
        return found
            .map(|(a, p)| (a, *p))
            .ok_or_else(|| Error::DeviceNotFound {
                selector: selector.to_string(),
                available: adapters
                    .iter()
                    .map(|(a, _)| format!("{}: {}", a.index, a.name))
                    .collect::<Vec<_>>()
                    .join(", "),
            });
    }
    let usable = adapters
        .iter()
        .filter(|(a, _)| a.missing.is_empty())
        .min_by_key(|(a, _)| (type_rank(a.device_type), a.index));
    match usable {
        Some((a, p)) => Ok((a, *p)),
        // No device meets the requirements: report the best one's shortfall.
        None => {
            let (a, _) = adapters
                .iter()
                .min_by_key(|(a, _)| (type_rank(a.device_type), a.index))
                .ok_or_else(|| Error::NoDevice {
                    detail: String::new(),
                })?;
            Err(Error::MissingFeatures {
                device: a.name.clone(),
                missing: a.missing.clone(),
            })
        }
    }
}

/// Destroys the messenger and the instance shine created.
pub(crate) fn destroy_owned(instance: &ash::Instance, owned: Owned) {
    if let Some((loader, messenger)) = owned.debug_instance {
        // SAFETY: created by shine on this instance.
        unsafe { loader.destroy_debug_utils_messenger(messenger, None) };
    }
    // SAFETY: created by shine; every child object is gone.
    unsafe { instance.destroy_instance(None) };
}

/// Destroys a freshly created instance if device creation fails part-way.
pub(crate) struct InstanceGuard(pub(crate) Option<ash::Instance>);

impl InstanceGuard {
    pub(crate) fn get(&self) -> &ash::Instance {
        // The option is only emptied by `release`, which consumes the guard.
        match &self.0 {
            Some(instance) => instance,
            None => unreachable!("InstanceGuard used after release"),
        }
    }

    pub(crate) fn release(mut self) -> ash::Instance {
        match self.0.take() {
            Some(instance) => instance,
            None => unreachable!("InstanceGuard released twice"),
        }
    }
}

impl Drop for InstanceGuard {
    fn drop(&mut self) {
        if let Some(instance) = self.0.take() {
            // SAFETY: no child objects remain (the messenger guard runs first).
            unsafe { instance.destroy_instance(None) };
        }
    }
}

/// Destroys the messenger if device creation fails part-way (before the instance guard runs).
pub(crate) struct OwnedGuard {
    pub(crate) owned: Option<Owned>,
}

impl Drop for OwnedGuard {
    fn drop(&mut self) {
        if let Some(Owned {
            debug_instance: Some((loader, messenger)),
        }) = self.owned.take()
        {
            // SAFETY: created by shine on the instance, which outlives this guard.
            unsafe { loader.destroy_debug_utils_messenger(messenger, None) };
        }
    }
}
