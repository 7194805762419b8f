//! `shine info`: the selected device, its driver and Vulkan version, and every feature the
//! engine requires or uses when present.

use super::CliError;
use shine::gpu::{Device, DeviceDesc, vk};

/// Arguments of `shine info`.
#[derive(clap::Args, Debug)]
pub struct InfoArgs {
    /// Device index or name substring (overrides SHINE_DEVICE).
    #[arg(long)]
    device: Option<String>,
}

/// Prints the report; fails with a clear message when no usable device exists.
pub fn run(args: &InfoArgs) -> Result<(), CliError> {
    let adapters = Device::enumerate()?;
    println!("Vulkan devices:");
    if adapters.is_empty() {
        println!("  (none)");
    }
    for a in &adapters {
        let usable = if a.missing.is_empty() {
            "usable".to_string()
        } else {
            format!("lacks {}", a.missing.join(", "))
        };
        println!(
            "  {}: {} ({}) — {usable}",
            a.index,
            a.name,
            device_type(a.device_type)
        );
    }
    let mut desc = DeviceDesc::from_env();
    if args.device.is_some() {
        desc.selector.clone_from(&args.device);
    }
    let device = Device::new(&desc)?;
    let info = device.info();
    println!();
    println!(
        "Selected: {} ({})",
        info.name,
        device_type(info.device_type)
    );
    println!("Driver:   {}", info.driver);
    println!("Vulkan:   {}", info.api_version);
    println!(
        "Timestamps: {} valid bits, {} ns per tick",
        info.timestamp_valid_bits, info.timestamp_period_ns
    );
    println!(
        "Limits:   {} B push constants, {} MiB per storage buffer, subgroup size {}",
        info.max_push_constants_size,
        info.max_storage_buffer_range / (1024 * 1024),
        info.subgroup_size
    );
    println!(
        "Validation layer: {}",
        if info.validation {
            "on"
        } else {
            "off (SHINE_VALIDATION=1 to enable)"
        }
    );
    println!();
    println!(
        "{:<30} {:<9} {:<8} used for",
        "feature", "needed", "present"
    );
    for f in &info.features {
        println!(
            "{:<30} {:<9} {:<8} {}",
            f.name,
            if f.required { "required" } else { "optional" },
            if f.present { "yes" } else { "no" },
            f.purpose
        );
    }
    Ok(())
}

fn device_type(t: vk::PhysicalDeviceType) -> &'static str {
    match t {
        vk::PhysicalDeviceType::DISCRETE_GPU => "discrete GPU",
        vk::PhysicalDeviceType::INTEGRATED_GPU => "integrated GPU",
        vk::PhysicalDeviceType::VIRTUAL_GPU => "virtual GPU",
        vk::PhysicalDeviceType::CPU => "CPU",
        _ => "other",
    }
}
