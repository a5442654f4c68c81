//! Rendered images to and from disk. The format follows the file name: `.png` is for looking
//! at (tonemapped, sRGB, 8-bit), `.exr` is for measuring (linear radiance, 32-bit float, so that
//! tests can compare renders without a tonemapper in the way).
use std::io::{BufReader, Seek};
use std::path::{Path, PathBuf};

use exr::prelude::{ReadChannels, ReadLayers};

use crate::files::{self, ReadError};
use crate::image_size::{Declared, SizeError};

#[derive(Debug, thiserror::Error)]
pub enum ImageIoError {
    #[error(
        "{}: unsupported image format {}; Kage writes .png (tonemapped sRGB) and .exr (linear float)",
        path.display(),
        path.extension().map_or("(no extension)".into(), |e| format!("\".{}\"", e.to_string_lossy()))
    )]
    UnsupportedExtension { path: PathBuf },
    #[error(
        "{}: a {width}×{height} image needs a non-zero size and width × height pixels, but has {pixels}",
        path.display()
    )]
    Size { path: PathBuf, width: u32, height: u32, pixels: usize },
    #[error("{}: pixel ({x}, {y}) is NaN or infinite", path.display())]
    NonFinite { path: PathBuf, x: u32, y: u32 },
    #[error("{}: exposure {exposure} is not a finite, non-negative number", path.display())]
    Exposure { path: PathBuf, exposure: f32 },
    // The causes are printed in the message rather than chained as `source`, so that the
    // reason reaches the user whichever way the error is printed.
    #[error("{}: PNG failed: {error}", path.display())]
    Png { path: PathBuf, error: image::ImageError },
    #[error("{}: cannot write: {error}", path.display())]
    Write { path: PathBuf, error: std::io::Error },
    #[error("{}: OpenEXR failed: {error}", path.display())]
    Exr { path: PathBuf, error: exr::error::Error },
    #[error("{}: {error}", path.display())]
    Read { path: PathBuf, error: ReadError },
    #[error("{}: {error}", path.display())]
    DeclaredSize { path: PathBuf, error: SizeError },
}

impl ImageIoError {
    /// Whether the caller's values are at fault (a format or an exposure Kage does not write),
    /// not a file.
    pub fn by_caller(&self) -> bool {
        matches!(self, ImageIoError::UnsupportedExtension { .. } | ImageIoError::Exposure { .. })
    }
}

/// Linear RGBA radiance, row-major, row 0 at the top.
#[derive(Clone, Debug, PartialEq)]
pub struct RgbaF32Image {
    pub width: u32,
    pub height: u32,
    pub pixels: Vec<[f32; 4]>,
}

impl RgbaF32Image {
    /// Checks the invariants both writers rely on; `path` only names the file in the error.
    fn validate(&self, path: &Path) -> Result<(), ImageIoError> {
        let expected = (self.width as usize).checked_mul(self.height as usize);
        if self.width == 0 || self.height == 0 || expected != Some(self.pixels.len()) {
            return Err(ImageIoError::Size {
                path: path.to_owned(),
                width: self.width,
                height: self.height,
                pixels: self.pixels.len(),
            });
        }
        check_finite(path, self.width, &self.pixels)
    }
}

fn check_finite(path: &Path, width: u32, pixels: &[[f32; 4]]) -> Result<(), ImageIoError> {
    match pixels.iter().position(|p| !p.iter().all(|v| v.is_finite())) {
        None => Ok(()),
        Some(i) => Err(ImageIoError::NonFinite {
            path: path.to_owned(),
            x: (i % width as usize) as u32,
            y: (i / width as usize) as u32,
        }),
    }
}

enum Format {
    Png,
    Exr,
}

fn format_of(path: &Path) -> Option<Format> {
    let ext = path.extension()?.to_str()?;
    if ext.eq_ignore_ascii_case("png") {
        Some(Format::Png)
    } else if ext.eq_ignore_ascii_case("exr") {
        Some(Format::Exr)
    } else {
        None
    }
}

/// Writes `image` in the format named by `path`'s extension (case-insensitive):
/// - `.png`: each channel multiplied by `exposure`, tonemapped and sRGB-encoded by
///   [`tonemap_srgb8`], 8-bit RGB;
/// - `.exr`: the linear radiance as 32-bit float RGBA (alpha: coverage, 0 where a local-light
///   reference shows no surface); `exposure` is ignored, the file holds what was rendered.
///
/// PNG drops alpha. NaN or infinite pixels are refused rather than written, since they
/// mean the render went wrong.
pub fn write(path: impl AsRef<Path>, image: &RgbaF32Image, exposure: f32) -> Result<(), ImageIoError> {
    let path = path.as_ref();
    let format =
        format_of(path).ok_or_else(|| ImageIoError::UnsupportedExtension { path: path.to_owned() })?;
    image.validate(path)?;
    match format {
        Format::Png => write_png(path, image, exposure),
        Format::Exr => write_exr(path, image),
    }
}

fn write_png(path: &Path, image: &RgbaF32Image, exposure: f32) -> Result<(), ImageIoError> {
    if !(exposure.is_finite() && exposure >= 0.0) {
        return Err(ImageIoError::Exposure { path: path.to_owned(), exposure });
    }
    let bytes: Vec<u8> =
        image.pixels.iter().flat_map(|&[r, g, b, _]| tonemap_srgb8([r, g, b], exposure)).collect();
    write_rgb8_png(path, &bytes, image.width, image.height)
}

/// Writes 8-bit sRGB triples as a PNG file: encoded in memory, then written by
/// [`files::write`], so that a full disk or a device that refuses the bytes is an error and
/// leaves no truncated file.
pub fn write_rgb8_png(path: &Path, rgb: &[u8], width: u32, height: u32) -> Result<(), ImageIoError> {
    let mut png = Vec::new();
    image::ImageEncoder::write_image(
        image::codecs::png::PngEncoder::new(&mut png),
        rgb,
        width,
        height,
        image::ExtendedColorType::Rgb8,
    )
    .map_err(|error| ImageIoError::Png { path: path.to_owned(), error })?;
    files::write(path, &png).map_err(|error| ImageIoError::Write { path: path.to_owned(), error })
}

fn write_exr(path: &Path, image: &RgbaF32Image) -> Result<(), ImageIoError> {
    let width = image.width as usize;
    exr::prelude::write_rgba_file(path, width, image.height as usize, |x, y| {
        let [r, g, b, a] = image.pixels[y * width + x];
        (r, g, b, a)
    })
    .map_err(|error| ImageIoError::Exr { path: path.to_owned(), error })
}

/// Reads the first RGB or RGBA layer of an OpenEXR file, half or float, as linear f32 (alpha 1
/// where the file has none). NaN or infinite pixels are an error, as they are on writing. The
/// file must be a regular file within [`files::IMAGE`], and the size its header declares within
/// what [`Declared::check`] allows, before any pixel is allocated.
pub fn read_exr(path: impl AsRef<Path>) -> Result<RgbaF32Image, ImageIoError> {
    let path = path.as_ref();
    let exr_error = |error| ImageIoError::Exr { path: path.to_owned(), error };
    let (file, bytes) = files::open(path, files::IMAGE)
        .map_err(|error| ImageIoError::Read { path: path.to_owned(), error })?;
    let mut reader = BufReader::new(file);
    Declared::exr(&mut reader)
        .map_err(exr_error)?
        .check(bytes)
        .map_err(|error| ImageIoError::DeclaredSize { path: path.to_owned(), error })?;
    reader.rewind().map_err(|e| exr_error(e.into()))?;
    let image = exr::prelude::read()
        .no_deep_data()
        .largest_resolution_level()
        .rgba_channels(
            |size, _| (size.width(), vec![[0.0f32, 0.0, 0.0, 1.0]; size.area()]),
            |(width, pixels): &mut (usize, Vec<[f32; 4]>), pos, (r, g, b, a): (f32, f32, f32, f32)| {
                pixels[pos.y() * *width + pos.x()] = [r, g, b, a];
            },
        )
        .first_valid_layer()
        .all_attributes()
        .from_buffered(reader)
        .map_err(exr_error)?;
    let size = image.layer_data.size;
    let pixels = image.layer_data.channel_data.pixels.1;
    // OpenEXR keeps its data window in i32s, so both sides fit a u32.
    let (width, height) = (size.width() as u32, size.height() as u32);
    let image = RgbaF32Image { width, height, pixels };
    image.validate(path)?;
    Ok(image)
}

/// Linear radiance to display bytes: multiply by `exposure`, apply the ACES filmic fit
/// (Narkowicz 2015) per channel, encode with the sRGB transfer function, round to 8 bits.
/// Negative and NaN inputs give 0.
pub fn tonemap_srgb8(rgb: [f32; 3], exposure: f32) -> [u8; 3] {
    rgb.map(|v| {
        let encoded = srgb_oetf(aces_narkowicz(v * exposure));
        // `as u8` saturates and sends NaN to 0.
        (encoded * 255.0).round() as u8
    })
}

/// The mid-grey a picture's log-average luminance is exposed to by [`auto_exposure`]
/// (Reinhard et al. 2002's "key" of a normal scene).
pub const AUTO_EXPOSURE_KEY: f32 = 0.18;

/// An exposure that makes any picture readable, whatever its units (a light of 54,351 cd and a
/// sky of radiance 1 alike): [`AUTO_EXPOSURE_KEY`] over the image's log-average luminance
/// exp(mean ln(10⁻⁴ + L)), L the Rec. 709 luminance of each finite pixel (the 10⁻⁴ keeps
/// black pixels from sending the mean to −∞). A black image gets 1.
pub fn auto_exposure(image: &RgbaF32Image) -> f32 {
    const DELTA: f64 = 1e-4;
    let luminances = image.pixels.iter().map(|&[r, g, b, _]| 0.2126 * r + 0.7152 * g + 0.0722 * b);
    let (sum, count) = luminances
        .filter(|l| l.is_finite() && *l >= 0.0)
        .fold((0.0f64, 0usize), |(sum, n), l| (sum + (DELTA + f64::from(l)).ln(), n + 1));
    let average = if count == 0 { DELTA } else { (sum / count as f64).exp() };
    if average <= 2.0 * DELTA {
        return 1.0;
    }
    (f64::from(AUTO_EXPOSURE_KEY) / average) as f32
}

/// Narkowicz's rational fit of the ACES RRT + ODT, clamped to [0, 1]. It is monotonic on
/// [0, ∞) and overshoots 1 (towards 2.51/2.43), hence the output clamp. It reaches 1 at
/// x ≈ 7.24, so capping the input at 100 changes no result but keeps x² from overflowing to
/// ∞/∞ = NaN for huge radiance.
fn aces_narkowicz(x: f32) -> f32 {
    let x = x.clamp(0.0, 100.0);
    let (a, b, c, d, e) = (2.51, 0.03, 2.43, 0.59, 0.14);
    ((x * (a * x + b)) / (x * (c * x + d) + e)).clamp(0.0, 1.0)
}

/// The exact piecewise sRGB encoding (IEC 61966-2-1), not the 1/2.2 power approximation.
pub fn srgb_oetf(x: f32) -> f32 {
    if x <= 0.0031308 {
        12.92 * x
    } else {
        1.055 * x.powf(1.0 / 2.4) - 0.055
    }
}

/// Its inverse: an sRGB-encoded value in [0, 1] back to linear (texture colours).
pub fn srgb_eotf(x: f32) -> f32 {
    if x <= 0.04045 {
        x / 12.92
    } else {
        ((x + 0.055) / 1.055).powf(2.4)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A uniform picture of luminance L is exposed to the key: 0.18 / (L + 10⁻⁴); one 1000×
    /// brighter takes a 1000× smaller exposure (units do not matter); black keeps 1, and NaN or
    /// negative pixels are left out of the average.
    #[test]
    fn auto_exposure_brings_the_log_average_to_the_key() {
        let uniform = |value: f32, extra: Vec<[f32; 4]>| {
            let mut pixels = vec![[value; 4]; 64];
            pixels.extend(extra);
            RgbaF32Image { width: pixels.len() as u32, height: 1, pixels }
        };
        let dim = auto_exposure(&uniform(0.5, Vec::new()));
        assert!((dim - AUTO_EXPOSURE_KEY / 0.5001).abs() < 1e-5, "{dim}");
        let bright = auto_exposure(&uniform(500.0, vec![[f32::NAN; 4], [-1.0; 4]]));
        assert!((dim / bright / 1000.0 - 1.0).abs() < 1e-3, "{dim} {bright}");
        assert_eq!(auto_exposure(&uniform(0.0, Vec::new())), 1.0);
    }

    fn scratch(name: &str) -> PathBuf {
        crate::files::scratch_path("imageio", name)
    }

    fn sample_image(width: u32, height: u32) -> RgbaF32Image {
        let pixels = (0..width * height)
            .map(|i| {
                let t = i as f32;
                // Values that are not exactly representable in half, to catch a lossy path; an
                // alpha of 0, 0.5 or 1 (coverage), which EXR keeps.
                [t * 0.123_456_7, 1.0 / (t + 3.0), (t * 0.7).sin().abs() * 1e3, (i % 3) as f32 * 0.5]
            })
            .collect();
        RgbaF32Image { width, height, pixels }
    }

    #[test]
    fn srgb_eotf_inverts_the_encoding() {
        for x in [0.0, 0.001, 0.0031308, 0.2, 0.5, 1.0] {
            assert!((srgb_eotf(srgb_oetf(x)) - x).abs() < 1e-6, "{x}");
        }
    }

    #[test]
    fn srgb_oetf_endpoints_and_knee() {
        assert_eq!(srgb_oetf(0.0), 0.0);
        assert!((srgb_oetf(1.0) - 1.0).abs() < 1e-6);
        assert_eq!((srgb_oetf(1.0) * 255.0).round() as u8, 255);
        assert_eq!((srgb_oetf(0.0) * 255.0).round() as u8, 0);
        // The two pieces meet at the knee.
        let k = 0.0031308f32;
        assert!((12.92 * k - (1.055 * k.powf(1.0 / 2.4) - 0.055)).abs() < 1e-6);
        // Mid grey (18 %) encodes to about 118.
        assert_eq!((srgb_oetf(0.18) * 255.0).round() as u8, 118);
    }

    #[test]
    fn tonemap_is_monotonic_and_bounded() {
        assert_eq!(tonemap_srgb8([0.0; 3], 1.0), [0; 3]);
        assert_eq!(tonemap_srgb8([-1.0, f32::NAN, 1e30], 1.0), [0, 0, 255]);
        let mut prev_curve = 0.0;
        let mut prev_byte = 0;
        for i in 0..10_000 {
            let x = i as f32 * 1e-3;
            let curve = aces_narkowicz(x);
            assert!(curve >= prev_curve, "curve decreases at {x}");
            let byte = tonemap_srgb8([x; 3], 1.0)[0];
            assert!(byte >= prev_byte, "bytes decrease at {x}");
            (prev_curve, prev_byte) = (curve, byte);
        }
        assert_eq!(prev_byte, 255);
        // Exposure scales the input.
        assert_eq!(tonemap_srgb8([0.25; 3], 2.0), tonemap_srgb8([0.5; 3], 1.0));
    }

    #[test]
    fn exr_round_trip_is_bit_exact() {
        let path = scratch("round-trip.exr");
        let image = sample_image(37, 11);
        write(&path, &image, 123.0).unwrap();
        let back = read_exr(&path).unwrap();
        assert_eq!((back.width, back.height), (37, 11));
        for (a, b) in image.pixels.iter().zip(&back.pixels) {
            for ch in 0..4 {
                assert_eq!(a[ch].to_bits(), b[ch].to_bits());
            }
        }
    }

    #[test]
    fn png_has_the_right_size_and_tonemapped_pixels() {
        let path = scratch("size.PNG");
        let image = sample_image(13, 7);
        write(&path, &image, 0.5).unwrap();
        let back = image::open(&path).unwrap().to_rgb8();
        assert_eq!(back.dimensions(), (13, 7));
        let [r, g, b, _] = image.pixels[2 * 13 + 5];
        assert_eq!(back.get_pixel(5, 2).0, tonemap_srgb8([r, g, b], 0.5));
    }

    #[test]
    fn unsupported_extension_names_the_path() {
        for name in ["out.jpg", "out"] {
            let path = scratch(name);
            let err = write(&path, &sample_image(2, 1), 1.0).unwrap_err();
            assert!(matches!(err, ImageIoError::UnsupportedExtension { .. }));
            let message = err.to_string();
            assert!(message.contains(&path.display().to_string()), "{message}");
            assert!(message.contains(".png") && message.contains(".exr"), "{message}");
        }
    }

    #[test]
    fn bad_images_are_refused() {
        let path = scratch("bad.exr");
        let mut image = sample_image(4, 4);
        image.pixels.pop();
        assert!(matches!(write(&path, &image, 1.0), Err(ImageIoError::Size { .. })));
        let empty = RgbaF32Image { width: 0, height: 0, pixels: vec![] };
        assert!(matches!(write(&path, &empty, 1.0), Err(ImageIoError::Size { .. })));
        let mut image = sample_image(4, 4);
        image.pixels[9][2] = f32::INFINITY;
        let err = write(&path, &image, 1.0).unwrap_err();
        assert!(matches!(err, ImageIoError::NonFinite { x: 1, y: 2, .. }), "{err}");
        let png = scratch("bad-exposure.png");
        let err = write(&png, &sample_image(2, 2), f32::NAN).unwrap_err();
        assert!(matches!(err, ImageIoError::Exposure { .. }), "{err}");
    }

    #[test]
    fn reading_a_missing_or_corrupt_exr_is_an_error() {
        let missing = scratch("missing.exr");
        let err = read_exr(&missing).unwrap_err();
        assert!(err.to_string().contains(&missing.display().to_string()), "{err}");
        let corrupt = scratch("corrupt.exr");
        std::fs::write(&corrupt, b"not an exr").unwrap();
        assert!(matches!(read_exr(&corrupt), Err(ImageIoError::Exr { .. })));
    }
}
