//! `shine_device_create` / `shine_device_destroy`: the host's Vulkan objects wrapped as a
//! [`shine::embed::Device`] (`Device::from_raw`), with what the host enabled read from the
//! `VkDeviceCreateInfo` it used.

use crate::error::{Failure, ShineResult, call};
use crate::handles::{self, ShineDevice};
use crate::types::{SHINE_DEVICE_DESC_VERSION, ShineDeviceDesc};
use shine::embed::{Device, EnabledFeatures, RawDevice};
use shine::gpu::ash;
use shine::gpu::vk::{self, Handle};
use std::ffi::{CStr, c_void};

/// Most structures a `VkDeviceCreateInfo`'s `pNext` chain may hold before it is taken for a
/// loop.
const MAX_CHAIN: usize = 64;

/// Wraps the host's device for shine and writes its handle to `out`. Fails, naming what is
/// missing, when the device lacks what shine needs; `out` is then left null.
///
/// # Safety
/// `desc` is null or points to a valid `ShineDeviceDesc` whose Vulkan handles are live and
/// whose `device_create_info` points to the `VkDeviceCreateInfo` used; `out` is null or
/// writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn shine_device_create(
    desc: *const ShineDeviceDesc,
    out: *mut ShineDevice,
) -> ShineResult {
    call(|| {
        // SAFETY: the caller's promise.
        let (desc, out) = unsafe { (desc.as_ref(), out.as_mut()) };
        let (desc, out) = desc
            .zip(out)
            .ok_or_else(|| Failure::invalid("desc and out must not be null"))?;
        *out = std::ptr::null_mut();
        if desc.version != SHINE_DEVICE_DESC_VERSION {
            return Err(Failure::new(
                ShineResult::ErrorVersionMismatch,
                format!(
                    "ShineDeviceDesc version {} (this library reads version {SHINE_DEVICE_DESC_VERSION})",
                    desc.version
                ),
            ));
        }
        let get_instance_proc_addr = desc
            .get_instance_proc_addr
            .ok_or_else(|| Failure::invalid("get_instance_proc_addr is null"))?;
        for (name, null) in [
            ("instance", desc.instance.is_null()),
            ("physical_device", desc.physical_device.is_null()),
            ("device", desc.device.is_null()),
            ("queue", desc.queue.is_null()),
            ("device_create_info", desc.device_create_info.is_null()),
        ] {
            if null {
                return Err(Failure::invalid(format!("ShineDeviceDesc::{name} is null")));
            }
        }
        // SAFETY: the same function with Vulkan's handle type (a pointer, like ours).
        let pfn: vk::PFN_vkGetInstanceProcAddr = unsafe {
            std::mem::transmute::<
                unsafe extern "system" fn(
                    *mut c_void,
                    *const std::ffi::c_char,
                ) -> vk::PFN_vkVoidFunction,
                vk::PFN_vkGetInstanceProcAddr,
            >(get_instance_proc_addr)
        };
        // SAFETY: the loader's vkGetInstanceProcAddr (the caller's promise), alive while the
        // host's instance is.
        let entry = unsafe {
            ash::Entry::from_static_fn(ash::StaticFn {
                get_instance_proc_addr: pfn,
            })
        };
        let instance_handle = vk::Instance::from_raw(desc.instance as u64);
        // SAFETY: a live instance of this loader (the caller's promise).
        let instance = unsafe { ash::Instance::load(entry.static_fn(), instance_handle) };
        // SAFETY: a live device of that instance.
        let device = unsafe {
            ash::Device::load(instance.fp_v1_0(), vk::Device::from_raw(desc.device as u64))
        };
        // SAFETY: the caller's promise about `device_create_info`.
        let enabled = unsafe { enabled_features(desc.device_create_info, desc.api_version) }?;
        let device = Device::from_raw(RawDevice {
            entry,
            instance,
            physical_device: vk::PhysicalDevice::from_raw(desc.physical_device as u64),
            device,
            queue_family_index: desc.queue_family_index,
            queue: vk::Queue::from_raw(desc.queue as u64),
            debug_utils: desc.debug_utils != 0,
            enabled,
            allocator: None,
            pipeline_cache: vk::PipelineCache::from_raw(desc.pipeline_cache),
        })?;
        *out = handles::add_device(device);
        Ok(())
    })
}

/// What a `VkDeviceCreateInfo` enabled: its core features (directly or through
/// `VkPhysicalDeviceFeatures2`), synchronization2 and dynamicRendering (the Vulkan 1.3 struct
/// or their own), and its extensions.
///
/// # Safety
/// `info` points to a valid `VkDeviceCreateInfo` and its chain.
unsafe fn enabled_features(
    info: *const c_void,
    api_version: u32,
) -> Result<EnabledFeatures, Failure> {
    // SAFETY: the caller's promise.
    let info = unsafe { &*info.cast::<vk::DeviceCreateInfo<'_>>() };
    if info.s_type != vk::StructureType::DEVICE_CREATE_INFO {
        return Err(Failure::invalid(format!(
            "device_create_info has sType {:?}, not VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO",
            info.s_type
        )));
    }
    let mut features = if info.p_enabled_features.is_null() {
        vk::PhysicalDeviceFeatures::default()
    } else {
        // SAFETY: as above.
        unsafe { *info.p_enabled_features }
    };
    let mut v13 = vk::PhysicalDeviceVulkan13Features::default();
    let mut next = info.p_next.cast::<vk::BaseInStructure<'_>>();
    for _ in 0..MAX_CHAIN {
        // SAFETY: every link of a valid chain starts with sType and pNext.
        let Some(link) = (unsafe { next.as_ref() }) else {
            break;
        };
        let here = std::ptr::from_ref(link).cast::<c_void>();
        // SAFETY: each cast follows the structure's own sType.
        unsafe {
            match link.s_type {
                vk::StructureType::PHYSICAL_DEVICE_FEATURES_2 => {
                    features = (*here.cast::<vk::PhysicalDeviceFeatures2<'_>>()).features;
                }
                vk::StructureType::PHYSICAL_DEVICE_VULKAN_1_3_FEATURES => {
                    let f = &*here.cast::<vk::PhysicalDeviceVulkan13Features<'_>>();
                    v13.synchronization2 |= f.synchronization2;
                    v13.dynamic_rendering |= f.dynamic_rendering;
                }
                vk::StructureType::PHYSICAL_DEVICE_SYNCHRONIZATION_2_FEATURES => {
                    let f = &*here.cast::<vk::PhysicalDeviceSynchronization2Features<'_>>();
                    v13.synchronization2 |= f.synchronization2;
                }
                vk::StructureType::PHYSICAL_DEVICE_DYNAMIC_RENDERING_FEATURES => {
                    let f = &*here.cast::<vk::PhysicalDeviceDynamicRenderingFeatures<'_>>();
                    v13.dynamic_rendering |= f.dynamic_rendering;
                }
                _ => {}
            }
        }
        next = link.p_next;
    }
    let count = info.enabled_extension_count as usize;
    let names: Vec<&CStr> = if count == 0 || info.pp_enabled_extension_names.is_null() {
        Vec::new()
    } else {
        // SAFETY: `count` valid, NUL-terminated names.
        unsafe { std::slice::from_raw_parts(info.pp_enabled_extension_names, count) }
            .iter()
            .filter(|p| !p.is_null())
            // SAFETY: as above.
            .map(|p| unsafe { CStr::from_ptr(*p) })
            .collect()
    };
    Ok(EnabledFeatures::from_parts(
        api_version,
        &features,
        &v13,
        &names,
    ))
}

/// Releases the device handle. Contexts made on it keep what they need until they are
/// destroyed; the host's Vulkan objects are never destroyed by shine.
///
/// # Safety
/// `device` is any value (null and stale handles are refused).
#[unsafe(no_mangle)]
pub unsafe extern "C" fn shine_device_destroy(device: ShineDevice) -> ShineResult {
    call(|| handles::remove(device, "device"))
}

/// The device behind a handle, for the other entry points.
pub(crate) fn lookup(device: ShineDevice) -> Result<Device, Failure> {
    handles::device(device)
}
