//! `kage env ...`: environment-map utilities.
use anyhow::{Context as _, Result};
use clap::Subcommand;
use kage::scene::SunMap;
use std::path::PathBuf;

#[derive(Subcommand)]
pub enum EnvCommand {
    /// Write a synthetic sun map (EXR, 32-bit float): a round sun of uniform radiance, alone or
    /// over a uniform sky and ground. The sun sits at (cos e·sin a, sin e, −cos e·cos a) for
    /// elevation e and azimuth a: azimuth 0 is −Z, 90 is +X.
    ///
    /// kage env sun [--elevation DEG] [--azimuth DEG] [--radius DEG] [--radiance R,G,B] [--sky
    /// R,G,B] [--ground R,G,B] [--width W] --out MAP.exr: a synthetic sun map (equirectangular,
    /// W×W/2, 32-bit float EXR): a disk of uniform radiance at (cos e·sin a, sin e, −cos e·cos a),
    /// alone or over a uniform sky and ground (the test maps of tests/assets/sun/ come from
    /// `scripts/test-maps.sh`)
    Sun {
        /// Degrees above the horizon, -90 to 90.
        #[arg(long, default_value_t = SunMap::DEFAULT.elevation_deg, allow_hyphen_values = true)]
        elevation: f64,
        /// Degrees from −Z towards +X.
        #[arg(long, default_value_t = SunMap::DEFAULT.azimuth_deg, allow_hyphen_values = true)]
        azimuth: f64,
        /// Angular radius of the sun's disk, degrees.
        #[arg(long, default_value_t = SunMap::DEFAULT.radius_deg)]
        radius: f64,
        /// The sun's radiance, r,g,b.
        #[arg(long, value_parser = crate::args::parse_xyz::<f32>, default_value = "2000,2000,2000")]
        radiance: [f32; 3],
        /// Radiance of the rest of the upper hemisphere, r,g,b.
        #[arg(long, value_parser = crate::args::parse_xyz::<f32>, default_value = "0,0,0")]
        sky: [f32; 3],
        /// Radiance of the lower hemisphere, r,g,b.
        #[arg(long, value_parser = crate::args::parse_xyz::<f32>, default_value = "0,0,0")]
        ground: [f32; 3],
        /// Map width in texels (the height is half).
        #[arg(long, default_value_t = SunMap::DEFAULT.width)]
        width: u32,
        /// Output file (.exr).
        #[arg(long)]
        out: PathBuf,
    },
}

pub fn run(command: &EnvCommand) -> Result<()> {
    match command {
        EnvCommand::Sun { elevation, azimuth, radius, radiance, sky, ground, width, out } => {
            let sun = SunMap {
                width: *width,
                elevation_deg: *elevation,
                azimuth_deg: *azimuth,
                radius_deg: *radius,
                radiance: *radiance,
                sky: *sky,
                ground: *ground,
            };
            let map = sun.map()?;
            map.write_exr(out).with_context(|| format!("writing {}", out.display()))?;
            println!("wrote {} ({}x{})", out.display(), map.width(), map.height());
            Ok(())
        }
    }
}
