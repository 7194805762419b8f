//! The Vulkan device: created headless by shine, or wrapping a host engine's handles.
//!
//! A [`Device`] is a cheap, clonable handle. Resources keep it alive; their destruction is
//! deferred until every submission that may have used them has completed ([`crate::retire`]).

use crate::error::{Error, Result, VkContext};
use crate::features::{EnabledFeatures, FeatureStatus, Support};
use crate::instance::{
    Adapter, InstanceGuard, Owned, OwnedGuard, VALIDATION_LAYER, choose, create_instance,
    destroy_owned, list_adapters, messenger_info, physical_name,
};
use crate::pipeline_cache::PipelineCache;
use crate::retire::Tracker;
use crate::validation::{MessageCounts, MessageLog, Validation};
use ash::vk;
use gpu_allocator::vulkan::{Allocator, AllocatorCreateDesc};
use std::mem::ManuallyDrop;
use std::sync::{Arc, Mutex, MutexGuard};

/// How to create a headless device.
#[derive(Clone, Debug, Default)]
pub struct DeviceDesc {
    /// Validation layer policy.
    pub validation: Validation,
    /// Index (from `shine info`) or case-insensitive name substring; `None` picks by type
    /// (discrete > integrated > virtual > CPU).
    pub selector: Option<String>,
    /// A previous run's [`Device::pipeline_cache_data`] to seed the pipeline cache with
    /// (empty: start cold; data from another driver or device is ignored by the driver).
    pub pipeline_cache_data: Vec<u8>,
}

impl DeviceDesc {
    /// Reads `SHINE_VALIDATION` and `SHINE_DEVICE`.
    pub fn from_env() -> Self {
        Self {
            validation: Validation::from_env(),
            selector: std::env::var("SHINE_DEVICE").ok().filter(|s| !s.is_empty()),
            pipeline_cache_data: Vec::new(),
        }
    }
}

/// A host engine's Vulkan objects, lent to shine (see [`Device::from_raw`]).
pub struct RawDevice {
    /// The host's loader entry.
    pub entry: ash::Entry,
    /// The host's instance.
    pub instance: ash::Instance,
    /// The physical device the host's device was created on.
    pub physical_device: vk::PhysicalDevice,
    /// The host's logical device, created with [`crate::REQUIREMENTS`] enabled.
    pub device: ash::Device,
    /// Queue family of `queue`; must support graphics, compute and timestamps.
    pub queue_family_index: u32,
    /// A queue shine may submit to. The host must not submit to it concurrently with shine.
    pub queue: vk::Queue,
    /// Whether the host enabled VK_EXT_debug_utils on the instance (labels, names). Must be
    /// false unless it really is enabled: its functions are called when true.
    pub debug_utils: bool,
    /// What the host enabled when it created `device`: checked against
    /// [`Device::requirements`] (`EnabledFeatures::required()` when the host enabled exactly
    /// shine's needs).
    pub enabled: EnabledFeatures,
    /// The host's allocator, made on `device`, for shine to allocate from and free into;
    /// `None`: shine makes its own. Shine frees all of its allocations before it drops its
    /// reference.
    pub allocator: Option<Arc<Mutex<Allocator>>>,
    /// The host's pipeline cache, which every pipeline shine creates goes through (the host
    /// saves it with `vkGetPipelineCacheData` and destroys it after shine's device is gone);
    /// `vk::PipelineCache::null()`: shine makes its own.
    pub pipeline_cache: vk::PipelineCache,
}

/// Facts about the device, for `shine info` and for sizing work.
#[derive(Clone, Debug)]
pub struct DeviceInfo {
    /// Device name.
    pub name: String,
    /// Discrete, integrated, CPU …
    pub device_type: vk::PhysicalDeviceType,
    /// Driver name and version string.
    pub driver: String,
    /// Device's Vulkan API version as `major.minor.patch`.
    pub api_version: String,
    /// Nanoseconds per timestamp tick.
    pub timestamp_period_ns: f32,
    /// Valid bits of timestamps on the queue.
    pub timestamp_valid_bits: u32,
    /// Maximum push-constant bytes.
    pub max_push_constants_size: u32,
    /// Maximum bytes of one storage-buffer binding.
    pub max_storage_buffer_range: u32,
    /// Subgroup size (information only: shaders never use subgroups).
    pub subgroup_size: u32,
    /// Whether the validation layer is active.
    pub validation: bool,
    /// Feature report: required and optional features and whether present.
    pub features: Vec<FeatureStatus>,
    /// Largest sampler anisotropy usable: the device's limit where shine enabled
    /// `samplerAnisotropy`, 1 (none) without it or on a host's device, whose enabled features
    /// shine does not know.
    pub max_anisotropy: f32,
}

pub(crate) struct Inner {
    pub(crate) entry: ash::Entry,
    pub(crate) instance: ash::Instance,
    pub(crate) physical: vk::PhysicalDevice,
    pub(crate) raw: ash::Device,
    pub(crate) queue: Mutex<vk::Queue>,
    pub(crate) queue_family: u32,
    pub(crate) debug_utils: Option<ash::ext::debug_utils::Device>,
    pub(crate) allocator: ManuallyDrop<Arc<Mutex<Allocator>>>,
    /// Bytes and allocations shine holds (the allocator may be the host's, with its own).
    pub(crate) usage: Mutex<(u64, usize)>,
    pub(crate) tracker: Mutex<Tracker>,
    pub(crate) info: DeviceInfo,
    pub(crate) limits: vk::PhysicalDeviceLimits,
    pub(crate) pipeline_cache: PipelineCache,
    owned: Option<Owned>,
    log: Arc<MessageLog>,
}

/// The engine's handle to a Vulkan device. Clone freely.
#[derive(Clone)]
pub struct Device {
    pub(crate) inner: Arc<Inner>,
}

impl std::fmt::Debug for Device {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Device")
            .field("name", &self.inner.info.name)
            .finish_non_exhaustive()
    }
}

impl Device {
    /// What a host must enable to wrap its device (docs/architecture.md, "Device layer").
    pub fn requirements() -> crate::Requirements {
        crate::REQUIREMENTS
    }

    /// Lists the physical devices the loader sees and whether each is usable.
    pub fn enumerate() -> Result<Vec<Adapter>> {
        // SAFETY: loading the system loader; ash checks the library exports.
        let entry = unsafe { ash::Entry::load() }?;
        let instance = create_instance(&entry, false, false, None)?;
        let result = list_adapters(&instance);
        // SAFETY: no child objects were created from this instance.
        unsafe { instance.destroy_instance(None) };
        result.map(|list| list.into_iter().map(|(adapter, _)| adapter).collect())
    }

    /// Creates a headless device (no surface, no window).
    pub fn new(desc: &DeviceDesc) -> Result<Self> {
        // SAFETY: loading the system loader; ash checks the library exports.
        let entry = unsafe { ash::Entry::load() }?;
        // SAFETY: plain queries on a loaded entry.
        let layers = unsafe { entry.enumerate_instance_layer_properties() }
            .ctx("enumerating instance layers")?;
        let have_layer = layers
            .iter()
            .any(|l| l.layer_name_as_c_str().is_ok_and(|n| n == VALIDATION_LAYER));
        let use_layer = match desc.validation {
            Validation::Off => false,
            Validation::IfAvailable => have_layer,
            Validation::Required if have_layer => true,
            Validation::Required => return Err(Error::ValidationUnavailable),
        };
        // SAFETY: as above.
        let extensions = unsafe { entry.enumerate_instance_extension_properties(None) }
            .ctx("enumerating instance extensions")?;
        let have_debug_utils = extensions.iter().any(|e| {
            e.extension_name_as_c_str()
                .is_ok_and(|n| n == ash::ext::debug_utils::NAME)
        });

        let log = Arc::new(MessageLog::default());
        let instance = create_instance(
            &entry,
            use_layer,
            have_debug_utils,
            have_debug_utils.then_some(&*log),
        )?;
        let guard = InstanceGuard(Some(instance));
        let instance_ref = guard.get();

        let debug_instance = if have_debug_utils {
            let loader = ash::ext::debug_utils::Instance::new(&entry, instance_ref);
            let info = messenger_info(&log);
            // SAFETY: the instance enables debug utils; `log` outlives the messenger (Inner).
            let messenger = unsafe { loader.create_debug_utils_messenger(&info, None) }
                .ctx("creating the debug messenger")?;
            Some((loader, messenger))
        } else {
            None
        };
        let owned = Owned { debug_instance };
        let mut owned_guard = OwnedGuard { owned: Some(owned) };

        let adapters = list_adapters(instance_ref)?;
        let (adapter, physical) = choose(&adapters, desc.selector.as_deref())?;
        let support = Support::query(instance_ref, physical);
        if !adapter.missing.is_empty() {
            return Err(Error::MissingFeatures {
                device: adapter.name.clone(),
                missing: adapter.missing.clone(),
            });
        }
        let queue_family = support.queue_family.ok_or_else(|| Error::MissingFeatures {
            device: adapter.name.clone(),
            missing: vec!["a queue family with GRAPHICS and COMPUTE".into()],
        })?;

        let priorities = [1.0f32];
        let queue_info = [vk::DeviceQueueCreateInfo::default()
            .queue_family_index(queue_family)
            .queue_priorities(&priorities)];
        let core = support.enabled_core();
        let mut f12 = vk::PhysicalDeviceVulkan12Features::default()
            .host_query_reset(support.host_query_reset)
            .scalar_block_layout(support.scalar_block_layout)
            .shader_float16(support.shader_float16);
        let mut f13 = crate::REQUIREMENTS
            .enable_vulkan13(vk::PhysicalDeviceVulkan13Features::default())
            .maintenance4(support.maintenance4);
        let mut f2 = vk::PhysicalDeviceFeatures2::default()
            .features(core)
            .push_next(&mut f12)
            .push_next(&mut f13);
        let device_info = vk::DeviceCreateInfo::default()
            .queue_create_infos(&queue_info)
            .push_next(&mut f2);
        // SAFETY: the physical device belongs to this instance; every enabled feature was
        // reported as supported.
        let raw = unsafe { instance_ref.create_device(physical, &device_info, None) }
            .ctx("creating the logical device")?;
        // SAFETY: queue 0 of the family was requested above.
        let queue = unsafe { raw.get_device_queue(queue_family, 0) };

        let instance = guard.release();
        let owned = owned_guard.owned.take();
        Self::assemble(
            Parts {
                entry,
                instance,
                physical,
                raw,
                queue,
                queue_family,
                debug_utils: have_debug_utils,
                validation: use_layer,
                allocator: None,
                anisotropy: false,
                pipeline_cache: vk::PipelineCache::null(),
                pipeline_cache_data: &desc.pipeline_cache_data,
            },
            owned,
            log,
        )
    }

    /// Wraps a host engine's instance, device and queue without owning them: shine never
    /// destroys host objects. The host must have enabled [`Device::requirements`] and keep the
    /// objects alive until every shine object made from this device is dropped.
    pub fn from_raw(raw: RawDevice) -> Result<Self> {
        let support = Support::query(&raw.instance, raw.physical_device);
        let mut missing = support.missing();
        missing.extend(raw.enabled.missing());
        if support.queue_family.is_some() {
            // SAFETY: the host's physical device belongs to the host's instance.
            let families = unsafe {
                raw.instance
                    .get_physical_device_queue_family_properties(raw.physical_device)
            };
            match families.get(raw.queue_family_index as usize) {
                Some(f)
                    if f.timestamp_valid_bits > 0
                        && f.queue_flags
                            .contains(vk::QueueFlags::GRAPHICS | vk::QueueFlags::COMPUTE) => {}
                _ => missing.push(format!(
                    "queue family {} with GRAPHICS, COMPUTE and timestamps",
                    raw.queue_family_index
                )),
            }
        }
        if !missing.is_empty() {
            return Err(Error::MissingFeatures {
                device: physical_name(&raw.instance, raw.physical_device),
                missing,
            });
        }
        Self::assemble(
            Parts {
                entry: raw.entry,
                instance: raw.instance,
                physical: raw.physical_device,
                raw: raw.device,
                queue: raw.queue,
                queue_family: raw.queue_family_index,
                debug_utils: raw.debug_utils,
                validation: false,
                allocator: raw.allocator,
                anisotropy: raw.enabled.features.sampler_anisotropy == vk::TRUE,
                pipeline_cache: raw.pipeline_cache,
                pipeline_cache_data: &[],
            },
            None,
            Arc::new(MessageLog::default()),
        )
    }

    fn assemble(parts: Parts<'_>, owned: Option<Owned>, log: Arc<MessageLog>) -> Result<Self> {
        let is_owned = owned.is_some();
        let cleanup = |parts: &Parts<'_>| {
            if is_owned {
                // SAFETY: created above by shine, no child objects exist yet.
                unsafe { parts.raw.destroy_device(None) };
            }
        };
        let allocator = match parts.allocator.clone().map_or_else(
            || {
                Allocator::new(&AllocatorCreateDesc {
                    instance: parts.instance.clone(),
                    device: parts.raw.clone(),
                    physical_device: parts.physical,
                    debug_settings: Default::default(),
                    buffer_device_address: false,
                    allocation_sizes: Default::default(),
                })
                .map(|a| Arc::new(Mutex::new(a)))
            },
            Ok,
        ) {
            Ok(a) => a,
            Err(source) => {
                cleanup(&parts);
                if let Some(owned) = owned {
                    destroy_owned(&parts.instance, owned);
                }
                return Err(Error::Allocation {
                    name: "allocator".into(),
                    source,
                });
            }
        };
        let pipeline_cache =
            match PipelineCache::new(&parts.raw, parts.pipeline_cache, parts.pipeline_cache_data) {
                Ok(cache) => cache,
                Err(e) => {
                    drop(allocator);
                    cleanup(&parts);
                    if let Some(owned) = owned {
                        destroy_owned(&parts.instance, owned);
                    }
                    return Err(e);
                }
            };
        let support = Support::query(&parts.instance, parts.physical);
        // SAFETY: the physical device belongs to the instance.
        let families = unsafe {
            parts
                .instance
                .get_physical_device_queue_family_properties(parts.physical)
        };
        // SAFETY: as above.
        let properties = unsafe {
            parts
                .instance
                .get_physical_device_properties(parts.physical)
        };
        let mut driver = vk::PhysicalDeviceDriverProperties::default();
        let mut subgroup = vk::PhysicalDeviceSubgroupProperties::default();
        let mut p2 = vk::PhysicalDeviceProperties2::default()
            .push_next(&mut driver)
            .push_next(&mut subgroup);
        // SAFETY: both chained structs are core in Vulkan 1.2+, which was checked.
        unsafe {
            parts
                .instance
                .get_physical_device_properties2(parts.physical, &mut p2)
        };
        let info = DeviceInfo {
            name: physical_name(&parts.instance, parts.physical),
            device_type: properties.device_type,
            driver: format!(
                "{} {}",
                driver
                    .driver_name_as_c_str()
                    .map_or("?".into(), |s| s.to_string_lossy()),
                driver
                    .driver_info_as_c_str()
                    .map_or("".into(), |s| s.to_string_lossy())
            )
            .trim()
            .to_string(),
            api_version: format!(
                "{}.{}.{}",
                vk::api_version_major(properties.api_version),
                vk::api_version_minor(properties.api_version),
                vk::api_version_patch(properties.api_version)
            ),
            timestamp_period_ns: properties.limits.timestamp_period,
            timestamp_valid_bits: families
                .get(parts.queue_family as usize)
                .map_or(0, |f| f.timestamp_valid_bits),
            max_push_constants_size: properties.limits.max_push_constants_size,
            max_storage_buffer_range: properties.limits.max_storage_buffer_range,
            subgroup_size: subgroup.subgroup_size,
            validation: parts.validation,
            features: support.report(),
            max_anisotropy: if (owned.is_some()
                && support.enabled_core().sampler_anisotropy == vk::TRUE)
                || parts.anisotropy
            {
                properties.limits.max_sampler_anisotropy
            } else {
                1.0
            },
        };
        let debug_utils = parts
            .debug_utils
            .then(|| ash::ext::debug_utils::Device::new(&parts.instance, &parts.raw));
        Ok(Self {
            inner: Arc::new(Inner {
                entry: parts.entry,
                instance: parts.instance,
                physical: parts.physical,
                raw: parts.raw,
                queue: Mutex::new(parts.queue),
                queue_family: parts.queue_family,
                debug_utils,
                allocator: ManuallyDrop::new(allocator),
                usage: Mutex::new((0, 0)),
                tracker: Mutex::new(Tracker::default()),
                info,
                limits: properties.limits,
                pipeline_cache,
                owned,
                log,
            }),
        })
    }

    /// The ash device, for what shine-gpu has no wrapper for.
    pub fn raw(&self) -> &ash::Device {
        &self.inner.raw
    }

    /// The ash instance.
    pub fn instance(&self) -> &ash::Instance {
        &self.inner.instance
    }

    /// The loader entry.
    pub fn entry(&self) -> &ash::Entry {
        &self.inner.entry
    }

    /// The physical device.
    pub fn physical_device(&self) -> vk::PhysicalDevice {
        self.inner.physical
    }

    /// Queue family index of the queue shine submits to.
    pub fn queue_family(&self) -> u32 {
        self.inner.queue_family
    }

    /// Device facts and the feature report.
    pub fn info(&self) -> &DeviceInfo {
        &self.inner.info
    }

    /// Device limits.
    pub fn limits(&self) -> &vk::PhysicalDeviceLimits {
        &self.inner.limits
    }

    /// Validation and driver messages received so far.
    pub fn message_counts(&self) -> MessageCounts {
        self.inner.log.counts()
    }

    /// Texts of the first error and warning messages (for test failure reports).
    pub fn messages(&self) -> Vec<String> {
        self.inner.log.messages()
    }

    /// Waits until the device is idle, then frees everything awaiting destruction.
    pub fn wait_idle(&self) -> Result<()> {
        {
            let queue = lock(&self.inner.queue);
            // SAFETY: the queue is externally synchronised by the lock.
            unsafe { self.inner.raw.queue_wait_idle(*queue) }.ctx("waiting for the queue")?;
        }
        self.retire()
    }

    /// Gives a Vulkan object a name visible in RenderDoc / Nsight / validation messages.
    pub fn set_name<H: vk::Handle>(&self, handle: H, name: &str) {
        let Some(debug) = &self.inner.debug_utils else {
            return;
        };
        let Ok(name) = std::ffi::CString::new(name) else {
            return;
        };
        let info = vk::DebugUtilsObjectNameInfoEXT::default()
            .object_handle(handle)
            .object_name(&name);
        // SAFETY: the handle belongs to this device; naming is best effort.
        let _ = unsafe { debug.set_debug_utils_object_name(&info) };
    }
}

struct Parts<'a> {
    entry: ash::Entry,
    instance: ash::Instance,
    physical: vk::PhysicalDevice,
    raw: ash::Device,
    queue: vk::Queue,
    queue_family: u32,
    debug_utils: bool,
    validation: bool,
    /// A host's allocator to share.
    allocator: Option<Arc<Mutex<Allocator>>>,
    /// Whether the host enabled samplerAnisotropy.
    anisotropy: bool,
    /// The host's pipeline cache, or null.
    pipeline_cache: vk::PipelineCache,
    /// What to seed shine's own pipeline cache with.
    pipeline_cache_data: &'a [u8],
}

/// Locks a mutex, recovering the data if a panicking thread poisoned it.
pub(crate) fn lock<T>(mutex: &Mutex<T>) -> MutexGuard<'_, T> {
    mutex
        .lock()
        .unwrap_or_else(std::sync::PoisonError::into_inner)
}

impl Drop for Inner {
    fn drop(&mut self) {
        if self.owned.is_some() {
            // SAFETY: shine owns the device and every queue on it.
            let _ = unsafe { self.raw.device_wait_idle() };
        } else {
            // A host device: its other queues are not ours to synchronise; ours is enough,
            // since shine submits only to it.
            let queue = self
                .queue
                .get_mut()
                .unwrap_or_else(std::sync::PoisonError::into_inner);
            // SAFETY: the queue is externally synchronised through `&mut self`.
            let _ = unsafe { self.raw.queue_wait_idle(*queue) };
        }
        {
            let tracker = self
                .tracker
                .get_mut()
                .unwrap_or_else(std::sync::PoisonError::into_inner);
            let mut allocator = lock(&self.allocator);
            tracker.destroy_all(&self.raw, &mut allocator);
        }
        self.pipeline_cache.destroy(&self.raw);
        // SAFETY: dropped exactly once, before the device it allocates from (the last
        // reference frees shine's own allocator; a host's lives on in the host).
        unsafe { ManuallyDrop::drop(&mut self.allocator) };
        if let Some(owned) = self.owned.take() {
            // SAFETY: the device was created by shine and every child object is destroyed.
            unsafe { self.raw.destroy_device(None) };
            destroy_owned(&self.instance, owned);
        }
    }
}
