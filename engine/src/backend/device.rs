//! Which physical device and queue family Kage uses, and what it offers: shared by a context
//! Kage creates and one adopted from a host.
use super::context::DeviceInfo;
use crate::error::{Error, Result};
use ash::vk;
use std::ffi::CStr;

pub(crate) const VALIDATION_LAYER: &CStr = c"VK_LAYER_KHRONOS_validation";

pub(crate) fn has_extension(list: &[vk::ExtensionProperties], name: &CStr) -> bool {
    list.iter().any(|e| e.extension_name_as_c_str() == Ok(name))
}

fn version_string(v: u32) -> String {
    format!("{}.{}.{}", vk::api_version_major(v), vk::api_version_minor(v), vk::api_version_patch(v))
}

/// Describes `physical` and its `queue_family`; fails when a feature Kage requires is missing.
/// `debug_utils`: whether the instance has VK_EXT_debug_utils; `layers`: the installed layers.
pub(crate) fn probe(
    entry: &ash::Entry,
    instance: &ash::Instance,
    physical: vk::PhysicalDevice,
    queue_family: u32,
    debug_utils: bool,
    layers: &[vk::LayerProperties],
) -> Result<DeviceInfo> {
    // SAFETY: valid physical device from this instance.
    let props = unsafe { instance.get_physical_device_properties(physical) };
    let name = props.device_name_as_c_str().unwrap_or(c"?").to_string_lossy().into_owned();
    if props.api_version < vk::API_VERSION_1_2 {
        return Err(Error::Unsupported(format!("Vulkan 1.2 on {name}")));
    }
    // SAFETY: as above.
    let device_exts = unsafe { instance.enumerate_device_extension_properties(physical) }
        .map_err(Error::vk("vkEnumerateDeviceExtensionProperties"))?;
    // SAFETY: as above.
    let families = unsafe { instance.get_physical_device_queue_family_properties(physical) };
    let family = families
        .get(queue_family as usize)
        .filter(|f| f.queue_flags.contains(vk::QueueFlags::GRAPHICS | vk::QueueFlags::COMPUTE))
        .ok_or_else(|| {
            Error::InvalidArgument(format!(
                "queue family {queue_family} of {name} is not a graphics and compute family"
            ))
        })?;
    // SAFETY: as above.
    let features = unsafe { instance.get_physical_device_features(physical) };
    let timestamps =
        props.limits.timestamp_compute_and_graphics == vk::TRUE && family.timestamp_valid_bits > 0;
    // SAFETY: as above.
    let rgba32f =
        unsafe { instance.get_physical_device_format_properties(physical, vk::Format::R32G32B32A32_SFLOAT) };
    let rgba32f_linear =
        rgba32f.optimal_tiling_features.contains(vk::FormatFeatureFlags::SAMPLED_IMAGE_FILTER_LINEAR);

    // Traces put device and host events on one timeline when the device reads both clocks
    // together.
    let calibrated = has_extension(&device_exts, ash::ext::calibrated_timestamps::NAME) && {
        let ext = ash::ext::calibrated_timestamps::Instance::new(entry, instance);
        // SAFETY: valid physical device of this instance, which has the extension.
        let domains =
            unsafe { ext.get_physical_device_calibrateable_time_domains(physical) }.unwrap_or_default();
        [vk::TimeDomainEXT::DEVICE, vk::TimeDomainEXT::CLOCK_MONOTONIC].iter().all(|d| domains.contains(d))
    };

    let mut driver = vk::PhysicalDeviceDriverProperties::default();
    let mut props2 = vk::PhysicalDeviceProperties2::default().push_next(&mut driver);
    // SAFETY: Vulkan 1.2 device (checked above); the chain is well formed.
    unsafe { instance.get_physical_device_properties2(physical, &mut props2) };
    let driver_text = format!(
        "{} ({})",
        driver.driver_name_as_c_str().unwrap_or(c"?").to_string_lossy(),
        driver.driver_info_as_c_str().unwrap_or(c"?").to_string_lossy()
    );

    let info = DeviceInfo {
        name,
        device_type: format!("{:?}", props.device_type),
        driver: driver_text,
        api_version: version_string(props.api_version),
        timestamp_period_ns: timestamps.then_some(props.limits.timestamp_period as f64),
        sub_pixel_precision_bits: props.limits.sub_pixel_precision_bits,
        max_texel_buffer_elements: props.limits.max_texel_buffer_elements,
        features: vec![
            (
                "VK_KHR_dynamic_rendering (required)",
                has_extension(&device_exts, ash::khr::dynamic_rendering::NAME),
            ),
            (
                "VK_KHR_push_descriptor (required)",
                has_extension(&device_exts, ash::khr::push_descriptor::NAME),
            ),
            ("RGBA32F linear filtering (required)", rgba32f_linear),
            ("timestamps on the graphics/compute queue (pass timings)", timestamps),
            (CALIBRATED_TIMESTAMPS, timestamps && calibrated),
            ("VK_EXT_debug_utils (object names, labels)", debug_utils),
            (
                "VK_LAYER_KHRONOS_validation (installed)",
                layers.iter().any(|l| l.layer_name_as_c_str() == Ok(VALIDATION_LAYER)),
            ),
            (
                "shaderStorageImageExtendedFormats (required)",
                features.shader_storage_image_extended_formats == vk::TRUE,
            ),
            ("shaderFloat64", features.shader_float64 == vk::TRUE),
            (GEOMETRY_SHADER, features.geometry_shader == vk::TRUE),
            (FRAGMENT_STORES, features.fragment_stores_and_atomics == vk::TRUE),
            (
                "ray query (not used: Kage casts rays through its own BVH)",
                has_extension(&device_exts, ash::khr::ray_query::NAME),
            ),
        ],
    };
    for (feature, present) in &info.features {
        if feature.ends_with("(required)") && !present {
            return Err(Error::Unsupported(format!("{feature} on {}", info.name)));
        }
    }
    Ok(info)
}

/// Reading the device's timestamp clock and the host's monotonic clock together
/// (`Context::calibrate`): traces then place passes and frames on one timeline. Enabled where
/// the device has it.
pub const CALIBRATED_TIMESTAMPS: &str =
    "VK_EXT_calibrated_timestamps, device and monotonic clocks (traces on one timeline)";

/// The feature that lets fragment shaders read gl_PrimitiveID (SPIR-V's Geometry capability):
/// the polygon IDs of adaptive shadow maps. Enabled where the device has it.
pub const GEOMETRY_SHADER: &str = "geometryShader (ASM polygon IDs: gl_PrimitiveID in fragment shaders)";

/// The feature that lets fragment shaders write storage buffers: the ASM lighting pass marks
/// the tiles it looks up for the page pool's LRU. Enabled where the device has it.
pub const FRAGMENT_STORES: &str = "fragmentStoresAndAtomics (ASM: the lighting marks the tiles it uses)";

/// Chooses a Vulkan 1.2+ device with a graphics+compute queue: by name when asked, otherwise
/// discrete GPU first, then integrated, virtual, CPU.
pub(crate) fn pick(instance: &ash::Instance, wanted: Option<&str>) -> Result<(vk::PhysicalDevice, u32)> {
    // SAFETY: plain enumeration on a valid instance.
    let devices =
        unsafe { instance.enumerate_physical_devices() }.map_err(Error::vk("vkEnumeratePhysicalDevices"))?;
    let mut candidates = Vec::new();
    let mut names = Vec::new();
    for physical in devices {
        // SAFETY: physical device from this instance.
        let props = unsafe { instance.get_physical_device_properties(physical) };
        let name = props.device_name_as_c_str().unwrap_or(c"?").to_string_lossy().into_owned();
        names.push(name.clone());
        if props.api_version < vk::API_VERSION_1_2 {
            continue;
        }
        // SAFETY: as above.
        let families = unsafe { instance.get_physical_device_queue_family_properties(physical) };
        let Some(family) = families
            .iter()
            .position(|f| f.queue_flags.contains(vk::QueueFlags::GRAPHICS | vk::QueueFlags::COMPUTE))
        else {
            continue;
        };
        let rank = match props.device_type {
            vk::PhysicalDeviceType::DISCRETE_GPU => 0,
            vk::PhysicalDeviceType::INTEGRATED_GPU => 1,
            vk::PhysicalDeviceType::VIRTUAL_GPU => 2,
            vk::PhysicalDeviceType::CPU => 3,
            _ => 4,
        };
        candidates.push((rank, name, physical, family as u32));
    }
    if let Some(wanted) = wanted {
        let needle = wanted.to_lowercase();
        return candidates
            .into_iter()
            .find(|c| c.1.to_lowercase().contains(&needle))
            .map(|c| (c.2, c.3))
            .ok_or_else(|| {
                Error::NoDevice(format!(
                    "no Vulkan 1.2 device named like {wanted:?}; devices: {}",
                    if names.is_empty() { "none".into() } else { names.join(", ") }
                ))
            });
    }
    candidates.sort_by_key(|c| c.0);
    candidates.into_iter().next().map(|c| (c.2, c.3)).ok_or_else(|| {
        Error::NoDevice(if names.is_empty() {
            "the loader found no device (Debian: install mesa-vulkan-drivers for lavapipe)".into()
        } else {
            format!("none of {} has Vulkan 1.2 and a graphics+compute queue", names.join(", "))
        })
    })
}
