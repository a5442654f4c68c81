//! Instance, device, queue and allocator: the one object every other piece borrows.
use super::device::{self, has_extension, VALIDATION_LAYER};
use super::validation::{self, ValidationLog};
use crate::error::{Error, Result};
use ash::vk::{self, Handle};
use gpu_allocator::vulkan::{Allocator, AllocatorCreateDesc};
use std::ffi::{c_char, CString};
use std::mem::ManuallyDrop;
use std::sync::{Arc, Mutex, MutexGuard};

/// How to create a [`Context`].
#[derive(Clone, Debug, Default)]
pub struct ContextDesc {
    /// Turn on `VK_LAYER_KHRONOS_validation` and collect its messages (see
    /// [`Context::take_validation_messages`]). Missing layer is an error, not a silent downgrade.
    pub validation: bool,
    /// Pick the first device whose name contains this (case-insensitive). `None` reads the
    /// `KAGE_DEVICE` environment variable; unset, a discrete GPU is preferred.
    pub device: Option<String>,
}

/// A host's Vulkan objects for [`Context::adopt`]: Kage uses them and never destroys them.
///
/// The device must have been created with `VK_KHR_dynamic_rendering` and
/// `VK_KHR_push_descriptor` enabled and the features `dynamicRendering` and
/// `shaderStorageImageExtendedFormats` on, from an instance of API version 1.2 or later.
#[derive(Clone, Copy, Debug)]
pub struct HostVulkan {
    /// The `VkInstance`, `VkPhysicalDevice`, `VkDevice` and `VkQueue` handles' raw values, as
    /// a host's own Vulkan gives them.
    pub instance: u64,
    pub physical_device: u64,
    pub device: u64,
    /// A family with graphics and compute; `queue` belongs to it.
    pub queue_family: u32,
    pub queue: u64,
    /// Whether the instance has `VK_EXT_debug_utils` enabled (Kage then names and labels its
    /// objects and passes).
    pub debug_utils: bool,
}

/// The device's timestamp clock against the host's monotonic clock ([`Context::calibrate`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Calibration {
    /// The two clocks read together.
    pub device_ticks: u64,
    pub host_ns: u64,
    /// How far apart the two readings may be, in ns (the driver's bound).
    pub deviation_ns: u64,
    /// Nanoseconds per device tick.
    pub period_ns: f64,
}

impl Calibration {
    /// The host's monotonic time, in ns, at device timestamp `ticks`.
    pub fn host_ns_at(&self, ticks: u64) -> f64 {
        self.host_ns as f64 + (ticks as f64 - self.device_ticks as f64) * self.period_ns
    }
}

/// What `kage info` reports about the device.
#[derive(Clone, Debug)]
pub struct DeviceInfo {
    pub name: String,
    pub device_type: String,
    pub driver: String,
    pub api_version: String,
    /// Nanoseconds per timestamp tick; `None` when the queue cannot write timestamps.
    pub timestamp_period_ns: Option<f64>,
    /// `subPixelPrecisionBits`: the rasterizer places vertices to 1 / 2^bits of a pixel.
    pub sub_pixel_precision_bits: u32,
    /// `maxTexelBufferElements`: the most texels one texel buffer (the BVH's) may hold.
    pub max_texel_buffer_elements: u32,
    /// Every optional feature or extension Kage looks at, and whether it is there.
    pub features: Vec<(&'static str, bool)>,
}

impl DeviceInfo {
    /// Whether the device has the feature of that `features` name.
    pub fn has(&self, feature: &str) -> bool {
        self.features.iter().any(|(name, present)| *name == feature && *present)
    }
}

pub struct Context {
    _entry: ash::Entry,
    pub(crate) instance: ash::Instance,
    debug_instance: Option<ash::ext::debug_utils::Instance>,
    messenger: vk::DebugUtilsMessengerEXT,
    validation: Option<Box<ValidationLog>>,
    pub(crate) debug: Option<ash::ext::debug_utils::Device>,
    pub(crate) physical: vk::PhysicalDevice,
    pub(crate) device: ash::Device,
    pub(crate) dynamic_rendering: ash::khr::dynamic_rendering::Device,
    pub(crate) push_descriptor: ash::khr::push_descriptor::Device,
    /// Device and host clocks read together ([`Context::calibrate`]), where enabled.
    calibration: Option<ash::ext::calibrated_timestamps::Device>,
    queue: Mutex<vk::Queue>,
    /// The queue's family, for each recorder's command pool.
    pub(crate) queue_family: u32,
    allocator: ManuallyDrop<Mutex<Allocator>>,
    info: DeviceInfo,
    /// False for a host's device ([`Context::adopt`]): then the host destroys device and instance.
    owns_device: bool,
}

/// What both constructors hand to [`Context::assemble`].
struct Parts {
    entry: ash::Entry,
    instance: ash::Instance,
    debug_instance: Option<ash::ext::debug_utils::Instance>,
    messenger: vk::DebugUtilsMessengerEXT,
    validation: Option<Box<ValidationLog>>,
    debug_utils: bool,
    physical: vk::PhysicalDevice,
    device: ash::Device,
    queue_family: u32,
    queue: vk::Queue,
    info: DeviceInfo,
    owns_device: bool,
    /// Whether VK_EXT_calibrated_timestamps is enabled on the device.
    calibrated: bool,
}

impl Context {
    pub fn new(desc: &ContextDesc) -> Result<Arc<Context>> {
        // SAFETY: loading the system Vulkan loader; its initialisation has no preconditions.
        let entry = unsafe { ash::Entry::load() }.map_err(|e| Error::Loader(e.to_string()))?;

        // SAFETY: plain enumeration calls on a loaded entry.
        let layers = unsafe { entry.enumerate_instance_layer_properties() }
            .map_err(Error::vk("vkEnumerateInstanceLayerProperties"))?;
        if desc.validation && !layers.iter().any(|l| l.layer_name_as_c_str() == Ok(VALIDATION_LAYER)) {
            return Err(Error::Unsupported(
                "the validation layer VK_LAYER_KHRONOS_validation (Debian: vulkan-validationlayers)".into(),
            ));
        }
        // SAFETY: as above.
        let mut instance_exts = unsafe { entry.enumerate_instance_extension_properties(None) }
            .map_err(Error::vk("vkEnumerateInstanceExtensionProperties"))?;
        if desc.validation {
            // SAFETY: as above; the layer name is a valid C string.
            let from_layer = unsafe { entry.enumerate_instance_extension_properties(Some(VALIDATION_LAYER)) }
                .map_err(Error::vk("vkEnumerateInstanceExtensionProperties"))?;
            instance_exts.extend(from_layer);
        }
        let debug_utils = has_extension(&instance_exts, ash::ext::debug_utils::NAME);

        let app_name = c"kage";
        let app = vk::ApplicationInfo::default()
            .application_name(app_name)
            .engine_name(app_name)
            .api_version(vk::API_VERSION_1_3);
        let layer_ptrs: Vec<*const c_char> =
            if desc.validation { vec![VALIDATION_LAYER.as_ptr()] } else { vec![] };
        let ext_ptrs: Vec<*const c_char> =
            if debug_utils { vec![ash::ext::debug_utils::NAME.as_ptr()] } else { vec![] };
        let instance_info = vk::InstanceCreateInfo::default()
            .application_info(&app)
            .enabled_layer_names(&layer_ptrs)
            .enabled_extension_names(&ext_ptrs);
        // SAFETY: the create info points at locals that outlive the call.
        let instance =
            unsafe { entry.create_instance(&instance_info, None) }.map_err(Error::vk("vkCreateInstance"))?;

        // Declared before the guard so that it outlives the messenger the guard destroys.
        let validation = desc.validation.then(|| Box::new(ValidationLog::default()));
        // From here on a failure must undo what was created: the guard does it on drop.
        let mut guard = Guard { instance: instance.clone(), messenger: None, device: None };
        let (debug_instance, messenger) = match (&validation, debug_utils) {
            (Some(log), true) => {
                let loader = ash::ext::debug_utils::Instance::new(&entry, &instance);
                let info = vk::DebugUtilsMessengerCreateInfoEXT::default()
                    .message_severity(validation::SEVERITIES)
                    .message_type(
                        vk::DebugUtilsMessageTypeFlagsEXT::GENERAL
                            | vk::DebugUtilsMessageTypeFlagsEXT::VALIDATION
                            | vk::DebugUtilsMessageTypeFlagsEXT::PERFORMANCE,
                    )
                    .pfn_user_callback(Some(validation::callback))
                    .user_data(&**log as *const ValidationLog as *mut _);
                // SAFETY: the log is boxed, so its address is stable until the context drops,
                // and the context destroys the messenger first.
                let messenger = unsafe { loader.create_debug_utils_messenger(&info, None) }
                    .map_err(Error::vk("vkCreateDebugUtilsMessengerEXT"))?;
                guard.messenger = Some((loader.clone(), messenger));
                (Some(loader), messenger)
            }
            (Some(_), false) => {
                return Err(Error::Unsupported(
                    "VK_EXT_debug_utils, needed to collect validation messages".into(),
                ))
            }
            (None, _) => (None, vk::DebugUtilsMessengerEXT::null()),
        };

        let wanted = desc.device.clone().or_else(|| std::env::var("KAGE_DEVICE").ok());
        let (physical, queue_family) = device::pick(&instance, wanted.as_deref())?;
        let info = device::probe(&entry, &instance, physical, queue_family, debug_utils, &layers)?;

        let priorities = [1.0f32];
        let queue_info = [vk::DeviceQueueCreateInfo::default()
            .queue_family_index(queue_family)
            .queue_priorities(&priorities)];
        let mut device_ext_ptrs =
            vec![ash::khr::dynamic_rendering::NAME.as_ptr(), ash::khr::push_descriptor::NAME.as_ptr()];
        let calibrated = info.has(device::CALIBRATED_TIMESTAMPS);
        if calibrated {
            device_ext_ptrs.push(ash::ext::calibrated_timestamps::NAME.as_ptr());
        }
        let mut dynamic_rendering_features =
            vk::PhysicalDeviceDynamicRenderingFeatures::default().dynamic_rendering(true);
        let enabled = vk::PhysicalDeviceFeatures::default()
            .geometry_shader(info.has(device::GEOMETRY_SHADER))
            .fragment_stores_and_atomics(info.has(device::FRAGMENT_STORES))
            .shader_storage_image_extended_formats(true);
        let device_info = vk::DeviceCreateInfo::default()
            .queue_create_infos(&queue_info)
            .enabled_extension_names(&device_ext_ptrs)
            .enabled_features(&enabled)
            .push_next(&mut dynamic_rendering_features);
        // SAFETY: the create info points at locals that outlive the call.
        let device = unsafe { instance.create_device(physical, &device_info, None) }
            .map_err(Error::vk("vkCreateDevice"))?;
        guard.device = Some(device.clone());
        // SAFETY: queue 0 of a family requested above.
        let queue = unsafe { device.get_device_queue(queue_family, 0) };

        let ctx = Context::assemble(Parts {
            entry,
            instance,
            debug_instance,
            messenger,
            validation,
            debug_utils,
            physical,
            device,
            queue_family,
            queue,
            info,
            owns_device: true,
            calibrated,
        })?;
        std::mem::forget(guard);
        Ok(ctx)
    }

    /// Uses a host's instance, device and queue. Kage never destroys them: the host does, after
    /// the context and everything made from it are gone. Validation, if wanted, is the host's
    /// (its layers and messenger); [`Context::take_validation_messages`] stays empty.
    ///
    /// # Safety
    /// The handles must be valid, created as [`HostVulkan`] says and from the system Vulkan
    /// loader, and stay valid until the context drops. The host must not use `queue` while a
    /// Kage call runs (Vulkan requires queue access to be externally synchronized).
    pub unsafe fn adopt(host: &HostVulkan) -> Result<Arc<Context>> {
        // SAFETY: as in `new`. The host's handles came from the same system loader, which the
        // process has open already, so this finds the same library.
        let entry = unsafe { ash::Entry::load() }.map_err(|e| Error::Loader(e.to_string()))?;
        // SAFETY: plain enumeration on a loaded entry.
        let layers = unsafe { entry.enumerate_instance_layer_properties() }
            .map_err(Error::vk("vkEnumerateInstanceLayerProperties"))?;
        // SAFETY: the caller promises a valid instance from this loader.
        let instance =
            unsafe { ash::Instance::load(entry.static_fn(), vk::Instance::from_raw(host.instance)) };
        let info = device::probe(
            &entry,
            &instance,
            vk::PhysicalDevice::from_raw(host.physical_device),
            host.queue_family,
            host.debug_utils,
            &layers,
        )?;
        let device_handle = vk::Device::from_raw(host.device);
        // SAFETY: the caller promises a valid device of this instance.
        let device = unsafe { ash::Device::load(instance.fp_v1_0(), device_handle) };
        // A device created without an extension gives no entry points for it (Vulkan 1.3 and
        // Mesa): say which is missing rather than crash at the first draw.
        for (extension, function) in [
            (ash::khr::dynamic_rendering::NAME, c"vkCmdBeginRenderingKHR"),
            (ash::khr::push_descriptor::NAME, c"vkCmdPushDescriptorSetKHR"),
        ] {
            // SAFETY: a valid device and a NUL-terminated name.
            let found =
                unsafe { (instance.fp_v1_0().get_device_proc_addr)(device_handle, function.as_ptr()) };
            if found.is_none() {
                return Err(Error::Unsupported(format!(
                    "{} enabled on the host's device",
                    extension.to_string_lossy()
                )));
            }
        }
        // The host may not have enabled the calibration extension: only its entry point tells.
        // SAFETY: a valid device and a NUL-terminated name.
        let calibrated = info.has(device::CALIBRATED_TIMESTAMPS)
            && unsafe {
                (instance.fp_v1_0().get_device_proc_addr)(
                    device_handle,
                    c"vkGetCalibratedTimestampsEXT".as_ptr(),
                )
            }
            .is_some();
        Context::assemble(Parts {
            entry,
            instance,
            debug_instance: None,
            messenger: vk::DebugUtilsMessengerEXT::null(),
            validation: None,
            debug_utils: host.debug_utils,
            physical: vk::PhysicalDevice::from_raw(host.physical_device),
            device,
            queue_family: host.queue_family,
            queue: vk::Queue::from_raw(host.queue),
            info,
            owns_device: false,
            calibrated,
        })
    }

    /// The allocator and command pool on top of a device, then the context itself.
    fn assemble(parts: Parts) -> Result<Arc<Context>> {
        let Parts { entry, instance, device, physical, queue, queue_family, .. } = parts;
        let allocator = Allocator::new(&AllocatorCreateDesc {
            instance: instance.clone(),
            device: device.clone(),
            physical_device: physical,
            debug_settings: Default::default(),
            buffer_device_address: false,
            allocation_sizes: Default::default(),
        })
        .map_err(|e| Error::Allocation { name: "allocator".into(), message: e.to_string() })?;

        let ctx = Context {
            debug: parts.debug_utils.then(|| ash::ext::debug_utils::Device::new(&instance, &device)),
            dynamic_rendering: ash::khr::dynamic_rendering::Device::new(&instance, &device),
            push_descriptor: ash::khr::push_descriptor::Device::new(&instance, &device),
            calibration: parts
                .calibrated
                .then(|| ash::ext::calibrated_timestamps::Device::new(&instance, &device)),
            _entry: entry,
            instance,
            debug_instance: parts.debug_instance,
            messenger: parts.messenger,
            validation: parts.validation,
            physical,
            device,
            queue: Mutex::new(queue),
            queue_family,
            allocator: ManuallyDrop::new(Mutex::new(allocator)),
            info: parts.info,
            owns_device: parts.owns_device,
        };
        ctx.set_name(queue, "kage.queue");
        Ok(Arc::new(ctx))
    }

    /// The device's timestamp clock and the host's monotonic clock (CLOCK_MONOTONIC, which
    /// `std::time::Instant` reads on Linux) read together; `None` where the device cannot
    /// (`device::CALIBRATED_TIMESTAMPS`).
    pub fn calibrate(&self) -> Result<Option<Calibration>> {
        let Some(ext) = &self.calibration else { return Ok(None) };
        let infos = [
            vk::CalibratedTimestampInfoEXT::default().time_domain(vk::TimeDomainEXT::DEVICE),
            vk::CalibratedTimestampInfoEXT::default().time_domain(vk::TimeDomainEXT::CLOCK_MONOTONIC),
        ];
        // SAFETY: the extension is enabled on this device; the infos are well formed.
        let (stamps, deviation) = unsafe { ext.get_calibrated_timestamps(&infos) }
            .map_err(Error::vk("vkGetCalibratedTimestampsEXT"))?;
        let period_ns = self.info.timestamp_period_ns.unwrap_or(1.0);
        Ok(Some(Calibration {
            device_ticks: stamps[0],
            host_ns: stamps[1],
            deviation_ns: deviation,
            period_ns,
        }))
    }

    pub fn info(&self) -> &DeviceInfo {
        &self.info
    }

    pub fn device(&self) -> &ash::Device {
        &self.device
    }

    /// Whether validation is on for this context.
    pub fn validating(&self) -> bool {
        self.validation.is_some()
    }

    /// Every validation message of warning or error severity since the last call.
    pub fn take_validation_messages(&self) -> Vec<String> {
        self.validation.as_ref().map(|log| log.take()).unwrap_or_default()
    }

    /// Bytes of device memory held by Kage's live buffers and images right now (what a
    /// technique costs in memory is the difference across its creation).
    pub fn allocated_bytes(&self) -> u64 {
        self.allocator().generate_report().total_allocated_bytes
    }

    pub(crate) fn allocator(&self) -> MutexGuard<'_, Allocator> {
        self.allocator.lock().unwrap_or_else(|e| e.into_inner())
    }

    pub(crate) fn queue(&self) -> MutexGuard<'_, vk::Queue> {
        self.queue.lock().unwrap_or_else(|e| e.into_inner())
    }

    /// Gives a Vulkan object a debug name (no-op without VK_EXT_debug_utils).
    pub fn set_name<H: vk::Handle>(&self, handle: H, name: &str) {
        let Some(debug) = &self.debug else { return };
        let Ok(name) = CString::new(name.replace('\0', " ")) else {
            return;
        };
        let info = vk::DebugUtilsObjectNameInfoEXT::default().object_handle(handle).object_name(&name);
        // SAFETY: the handle belongs to this device; naming has no other effect.
        // A failure to name is not worth failing the caller for.
        let _ = unsafe { debug.set_debug_utils_object_name(&info) };
    }

    /// Waits until the device is idle (used before destroying shared resources).
    pub fn wait_idle(&self) -> Result<()> {
        let _queue = self.queue();
        // SAFETY: the queue lock is held, so no submission races with the wait.
        unsafe { self.device.device_wait_idle() }.map_err(Error::vk("vkDeviceWaitIdle"))
    }
}

impl Drop for Context {
    fn drop(&mut self) {
        // SAFETY: every resource holds an Arc<Context>, so none is alive here; waiting first
        // makes sure no submitted work still uses the pool. Kage submits to its one queue
        // only, so waiting for it is enough, and on a host's device waiting for the whole
        // device would also wait for (and race with) the host's own queues.
        unsafe {
            let _ = self.device.queue_wait_idle(*self.queue.get_mut().unwrap_or_else(|e| e.into_inner()));
        }
        // The allocator frees its memory blocks through the device: drop it before the device.
        // SAFETY: dropped exactly once, here.
        unsafe { ManuallyDrop::drop(&mut self.allocator) };
        if !self.owns_device {
            return;
        }
        // SAFETY: all children of the device and instance are gone.
        unsafe {
            self.device.destroy_device(None);
            if let Some(loader) = &self.debug_instance {
                loader.destroy_debug_utils_messenger(self.messenger, None);
            }
            self.instance.destroy_instance(None);
        }
    }
}

/// Undoes a partly built context when `Context::new` fails half way.
struct Guard {
    instance: ash::Instance,
    messenger: Option<(ash::ext::debug_utils::Instance, vk::DebugUtilsMessengerEXT)>,
    device: Option<ash::Device>,
}

impl Drop for Guard {
    fn drop(&mut self) {
        // SAFETY: only reached on an error path; nothing else owns these objects, and the
        // allocator (which frees through the device) was dropped before us or never made.
        unsafe {
            if let Some(device) = &self.device {
                device.destroy_device(None);
            }
            if let Some((loader, messenger)) = &self.messenger {
                loader.destroy_debug_utils_messenger(*messenger, None);
            }
            self.instance.destroy_instance(None);
        }
    }
}
