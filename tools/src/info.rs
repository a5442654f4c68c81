//! `kage info`: what the device offers, feature by feature.
use crate::args::GpuArgs;
use anyhow::Result;

pub fn run(args: &GpuArgs) -> Result<()> {
    let ctx = args.context()?;
    let info = ctx.info();
    println!("device:         {} ({})", info.name, info.device_type);
    println!("driver:         {}", info.driver);
    println!("Vulkan:         {}", info.api_version);
    match info.timestamp_period_ns {
        Some(period) => println!("timestamps:     {period} ns per tick"),
        None => println!("timestamps:     not available (pass timings will be missing)"),
    }
    let bits = info.sub_pixel_precision_bits;
    println!(
        "sub-pixel:      {bits} bits (vertices placed to 1/{} px; the edge ties of `kage compare --edges`)",
        1u64 << bits
    );
    println!("features Kage uses:");
    for (name, present) in &info.features {
        println!("  [{}] {name}", if *present { "x" } else { " " });
    }
    args.finish(&ctx)
}
