//! The environment light: an equirectangular map of linear RGB radiance.
//!
//! Mapping (shared with every shader that samples the map): a unit direction (x, y, z) sits at
//! u = atan2(x, −z) / 2π wrapped into [0, 1) and v = acos(y) / π. So −Z is u = 0, +X is u = ¼,
//! +Z is u = ½, −X is u = ¾; +Y is v = 0 (row 0, the top row) and −Y is v = 1. Pixel (i, j) covers
//! u in [i, i + 1) / width and v in [j, j + 1) / height; its centre is at ((i + ½) / width,
//! (j + ½) / height).
use std::f32::consts::{PI, TAU};
use std::io::Cursor;
use std::path::Path;

use exr::prelude::{self as exrp, ReadChannels, ReadLayers, WritableImage};
use glam::{Vec2, Vec3};

use super::SceneError;
use crate::files;
use crate::image_size::{Declared, SizeError, MAX_IMAGE_PIXELS};

#[derive(Debug, Clone)]
pub struct EnvMap {
    width: u32,
    height: u32,
    pixels: Vec<[f32; 3]>,
    clamped_negative: usize,
}

/// Maps are equal when they hold the same radiance; how much clamping it took to get there is
/// a note about the source, so a map written out and read back still compares equal.
impl PartialEq for EnvMap {
    fn eq(&self, other: &EnvMap) -> bool {
        (self.width, self.height) == (other.width, other.height) && self.pixels == other.pixels
    }
}

/// Size of [`EnvMap::constant`] maps: big enough that per-pixel solid angles are smooth, small
/// enough to cost nothing.
const CONSTANT_WIDTH: u32 = 64;

impl EnvMap {
    /// Checks the size ([`EnvMap::check_size`]) and that every value is finite; negative values are
    /// clamped to 0 and counted (see [`EnvMap::clamped_negative`]).
    pub fn from_pixels(width: u32, height: u32, pixels: Vec<[f32; 3]>) -> Result<EnvMap, SceneError> {
        EnvMap::check_size(width, height)?;
        let expected = width as usize * height as usize;
        if pixels.len() != expected {
            return Err(SceneError::invalid(format!(
                "environment map of {width}x{height} needs {expected} pixels, got {}",
                pixels.len()
            )));
        }
        check_radiance(width, &pixels)?;
        // Lossy encodings (the DWA-compressed originals of the bundled maps) leave slightly
        // negative values; radiance cannot be negative, so they are clamped and counted.
        let mut pixels = pixels;
        let mut clamped_negative = 0;
        for c in pixels.iter_mut().flatten().filter(|c| **c < 0.0) {
            *c = 0.0;
            clamped_negative += 1;
        }
        Ok(EnvMap { width, height, pixels, clamped_negative })
    }

    /// Checks a map's shape before its pixels are allocated: not empty, 2:1, and at most
    /// [`MAX_IMAGE_PIXELS`] (16384x8192, the widest map a device image holds).
    pub fn check_size(width: u32, height: u32) -> Result<(), SceneError> {
        if width == 0 || height == 0 {
            return Err(SceneError::invalid(format!("environment map is empty ({width}x{height})")));
        }
        if u64::from(width) != 2 * u64::from(height) {
            return Err(SceneError::invalid(format!(
                "environment map is {width}x{height}, but an equirectangular map must be 2:1 (width = 2 x height)"
            )));
        }
        if u64::from(width) * u64::from(height) > MAX_IMAGE_PIXELS {
            return Err(SceneError::invalid(format!(
                "environment map is {width}x{height}, more than the {MAX_IMAGE_PIXELS} pixels (16384x8192) \
                 Kage takes"
            )));
        }
        Ok(())
    }

    /// A small map of one radiance in every direction.
    pub fn constant(rgb: [f32; 3]) -> EnvMap {
        let (width, height) = (CONSTANT_WIDTH, CONSTANT_WIDTH / 2);
        EnvMap { width, height, pixels: vec![rgb; (width * height) as usize], clamped_negative: 0 }
    }

    /// Reads `.exr` (RGB or RGBA, any sample type and compression `exr` supports) or Radiance
    /// `.hdr`, chosen by extension, from a regular file within [`files::IMAGE`].
    pub fn load(path: &Path) -> Result<EnvMap, SceneError> {
        let extension = path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase);
        let decode = match extension.as_deref() {
            Some("exr") => EnvMap::from_exr_bytes,
            Some("hdr") => EnvMap::from_hdr_bytes,
            _ => {
                return Err(SceneError::in_file(
                    path,
                    "unsupported environment map format; use OpenEXR (.exr) or Radiance HDR (.hdr)",
                ))
            }
        };
        let bytes = files::read(path, files::IMAGE).map_err(|e| SceneError::in_file(path, e.to_string()))?;
        decode(&bytes).map_err(|e| SceneError::in_file(path, e.problem()))
    }

    /// Decodes an OpenEXR file held in memory (its first layer with R, G and B channels); the
    /// size its header declares is checked ([`Declared::check`]) before a pixel is allocated.
    pub fn from_exr_bytes(bytes: &[u8]) -> Result<EnvMap, SceneError> {
        Declared::exr(Cursor::new(bytes)).map_err(not_exr)?.check(bytes.len() as u64).map_err(size_error)?;
        let image = exrp::read()
            .no_deep_data()
            .largest_resolution_level()
            .rgba_channels(
                |size, _| (size.width(), vec![[0.0f32; 3]; size.area()]),
                |(width, pixels): &mut (usize, Vec<[f32; 3]>), at, (r, g, b, _a): (f32, f32, f32, f32)| {
                    pixels[at.y() * *width + at.x()] = [r, g, b];
                },
            )
            .first_valid_layer()
            .all_attributes()
            .from_buffered(Cursor::new(bytes))
            .map_err(not_exr)?;
        let layer = image.layer_data;
        let (width, height) = (layer.size.width(), layer.size.height());
        EnvMap::from_pixels(dimension(width)?, dimension(height)?, layer.channel_data.pixels.1)
    }

    /// Decodes a Radiance RGBE (.hdr) file held in memory, its declared size checked as
    /// [`EnvMap::from_exr_bytes`] does.
    pub fn from_hdr_bytes(bytes: &[u8]) -> Result<EnvMap, SceneError> {
        Declared::hdr(bytes).map_err(not_hdr)?.check(bytes.len() as u64).map_err(size_error)?;
        let image = image::load_from_memory_with_format(bytes, image::ImageFormat::Hdr)
            .map_err(not_hdr)?
            .into_rgb32f();
        let (width, height) = image.dimensions();
        let pixels = image.pixels().map(|p| p.0).collect();
        EnvMap::from_pixels(width, height, pixels)
    }

    /// Writes the map as OpenEXR, RGB, 32-bit float, ZIP compressed: lossless, so reading it back
    /// gives the same pixels bit for bit.
    pub fn write_exr(&self, path: &Path) -> Result<(), SceneError> {
        let width = self.width as usize;
        let channels = exrp::SpecificChannels::rgb(|exrp::Vec2(x, y): exrp::Vec2<usize>| {
            let [r, g, b] = self.pixels[y * width + x];
            (r, g, b)
        });
        let layer = exrp::Layer::new(
            (width, self.height as usize),
            exrp::LayerAttributes::default(),
            exrp::Encoding::SMALL_LOSSLESS,
            channels,
        );
        exrp::Image::from_layer(layer)
            .write()
            .to_file(path)
            .map_err(|e| SceneError::in_file(path, format!("cannot write OpenEXR: {e}")))
    }

    /// Multiplies every pixel by `factor` (finite, >= 0); the products must stay within
    /// [`MAX_RADIANCE`].
    pub fn scaled(mut self, factor: f32) -> Result<EnvMap, SceneError> {
        if !(factor.is_finite() && factor >= 0.0) {
            return Err(SceneError::invalid(format!(
                "environment intensity must be finite and >= 0, got {factor}"
            )));
        }
        for p in &mut self.pixels {
            *p = p.map(|c| c * factor);
        }
        check_radiance(self.width, &self.pixels)
            .map_err(|e| SceneError::invalid(format!("environment intensity {factor}: {e}")))?;
        Ok(self)
    }

    /// How many negative channel values the source held (clamped to 0 on load).
    pub fn clamped_negative(&self) -> usize {
        self.clamped_negative
    }

    pub fn width(&self) -> u32 {
        self.width
    }

    pub fn height(&self) -> u32 {
        self.height
    }

    /// Row-major, row 0 at the top (+Y).
    pub fn pixels(&self) -> &[[f32; 3]] {
        &self.pixels
    }
}

/// The largest radiance a texel may hold. Every technique integrates the map in 32-bit floats
/// (SH projection: Σ L dω ≤ 4π L; irradiance π times that), and at 1e38 a bright map's sums
/// overflow to infinity and the picture turns NaN without a word; 1e30 keeps eight orders of
/// magnitude of headroom and is still 21 above the brightest real sun in a bundled map (~3.5e4).
pub const MAX_RADIANCE: f32 = 1e30;

/// Every channel finite and at most [`MAX_RADIANCE`]; the error names the first texel that is not.
fn check_radiance(width: u32, pixels: &[[f32; 3]]) -> Result<(), SceneError> {
    let Some(index) = pixels.iter().position(|p| p.iter().any(|c| !(c.is_finite() && *c <= MAX_RADIANCE)))
    else {
        return Ok(());
    };
    let (x, y) = (index % width as usize, index / width as usize);
    let p = pixels[index];
    let problem = if p.iter().all(|c| c.is_finite()) {
        format!("exceeds the largest radiance Kage integrates ({MAX_RADIANCE:e})")
    } else {
        "is NaN or infinite; radiance must be finite".into()
    };
    Err(SceneError::invalid(format!("environment map pixel ({x}, {y}) {problem}: {p:?}")))
}

fn not_exr(error: exr::error::Error) -> SceneError {
    SceneError::invalid(format!("not a readable OpenEXR RGB image: {error}"))
}

fn not_hdr(error: image::ImageError) -> SceneError {
    SceneError::invalid(format!("not a readable Radiance HDR image: {error}"))
}

fn size_error(error: SizeError) -> SceneError {
    SceneError::invalid(error.to_string())
}

fn dimension(size: usize) -> Result<u32, SceneError> {
    u32::try_from(size)
        .map_err(|_| SceneError::invalid(format!("environment map dimension {size} is too large")))
}

/// Where a direction lands in an equirectangular map (see the module documentation).
/// `d` need not be normalized but must not be zero.
pub fn direction_to_uv(d: Vec3) -> Vec2 {
    let d = d.normalize();
    let u = d.x.atan2(-d.z) / TAU;
    // rem_euclid of a tiny negative number rounds up to exactly 1.0, which is outside [0, 1).
    let u = u.rem_euclid(1.0);
    let u = if u >= 1.0 { 0.0 } else { u };
    let v = d.y.clamp(-1.0, 1.0).acos() / PI;
    Vec2::new(u, v)
}

/// The unit direction at a point of an equirectangular map; the inverse of [`direction_to_uv`].
pub fn uv_to_direction(uv: Vec2) -> Vec3 {
    let phi = uv.x * TAU;
    let theta = uv.y * PI;
    let (sin_theta, cos_theta) = theta.sin_cos();
    let (sin_phi, cos_phi) = phi.sin_cos();
    Vec3::new(sin_theta * sin_phi, cos_theta, -sin_theta * cos_phi)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: Vec2, b: Vec2) -> bool {
        (a - b).abs().max_element() < 1e-6
    }

    #[test]
    fn axes_land_where_the_convention_says() {
        assert!(close(direction_to_uv(Vec3::NEG_Z), Vec2::new(0.0, 0.5)));
        assert!(close(direction_to_uv(Vec3::X), Vec2::new(0.25, 0.5)));
        assert!(close(direction_to_uv(Vec3::Z), Vec2::new(0.5, 0.5)));
        assert!(close(direction_to_uv(Vec3::NEG_X), Vec2::new(0.75, 0.5)));
        assert!(direction_to_uv(Vec3::Y).y.abs() < 1e-6);
        assert!((direction_to_uv(Vec3::NEG_Y).y - 1.0).abs() < 1e-6);
    }

    #[test]
    fn u_stays_in_the_half_open_unit_interval() {
        for d in [Vec3::new(-1e-30, 0.0, -1.0), Vec3::new(-1e-7, 0.3, -1.0), Vec3::new(0.0, 1.0, 0.0)] {
            let u = direction_to_uv(d).x;
            assert!((0.0..1.0).contains(&u), "{d} -> u = {u}");
        }
    }

    #[test]
    fn directions_round_trip_through_pixel_centres() {
        let (width, height) = (16, 8);
        for j in 0..height {
            for i in 0..width {
                let uv = Vec2::new((i as f32 + 0.5) / width as f32, (j as f32 + 0.5) / height as f32);
                let d = uv_to_direction(uv);
                assert!((d.length() - 1.0).abs() < 1e-6);
                assert!(close(direction_to_uv(d), uv), "pixel ({i}, {j})");
            }
        }
    }

    #[test]
    fn from_pixels_checks_shape_and_values() {
        assert!(EnvMap::from_pixels(4, 2, vec![[1.0; 3]; 8]).is_ok());
        assert!(EnvMap::from_pixels(0, 0, vec![]).is_err());
        assert!(EnvMap::from_pixels(4, 4, vec![[1.0; 3]; 16]).unwrap_err().to_string().contains("2:1"));
        // Refused by its size alone, before a host allocates its pixels.
        assert!(EnvMap::check_size(16384, 8192).is_ok());
        let huge = EnvMap::check_size(32768, 16384).unwrap_err().to_string();
        assert!(huge.contains("32768x16384") && huge.contains("16384x8192"), "{huge}");
        assert!(EnvMap::from_pixels(4, 2, vec![[1.0; 3]; 7]).is_err());
        let mut pixels = vec![[1.0; 3]; 8];
        pixels[6] = [1.0, f32::NAN, 1.0];
        let message = EnvMap::from_pixels(4, 2, pixels.clone()).unwrap_err().to_string();
        assert!(message.contains("(2, 1)") && message.contains("NaN"), "{message}");
        pixels[6] = [1.0, -0.5, -0.25];
        let clamped = EnvMap::from_pixels(4, 2, pixels).unwrap();
        assert_eq!((clamped.pixels()[6], clamped.clamped_negative()), ([1.0, 0.0, 0.0], 2));
    }

    #[test]
    fn constant_map_is_two_to_one_and_uniform() {
        let map = EnvMap::constant([0.5, 1.0, 2.0]);
        assert_eq!(map.width(), 2 * map.height());
        assert!(map.pixels().iter().all(|p| *p == [0.5, 1.0, 2.0]));
    }
}
