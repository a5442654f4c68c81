//! Albedo maps: a texture a mesh's albedo is multiplied by, per pixel, in every technique and in
//! the reference (glTF's `baseColorTexture`, OBJ's `map_Kd`).
//!
//! Conventions (glTF's): texture coordinate (0, 0) is the top-left corner of the image's first
//! row, u runs along the rows and v down the columns; texel (i, j) has its centre at
//! ((i + ½) / width, (j + ½) / height). Texels are sRGB-encoded 8-bit colour, decoded to linear
//! before filtering; alpha is not used. OBJ's v runs up, so the OBJ reader turns it (v ↦ 1 − v).
//! The PRT transfer stays free of albedo: a map changes the picture, never the precomputation.
use super::SceneError;
use crate::files;
use std::path::Path;
use std::sync::Arc;

/// The largest side of an albedo map, in texels: 16384, the side of the largest 2D image many
/// Vulkan devices take (lavapipe's among them), 1 GiB of RGBA8 with its mipmaps.
pub const MAX_ALBEDO_MAP_SIDE: u32 = 16384;

/// What a texture coordinate outside [0, 1] reads (glTF sampler wrapS / wrapT).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Wrap {
    Repeat,
    MirroredRepeat,
    ClampToEdge,
}

/// How texels are filtered: magnified (`linear` or nearest), minified (`linear` or nearest)
/// and between mipmap levels (`Some(linear)`; `None` reads level 0 only).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Filter {
    pub magnify_linear: bool,
    pub minify_linear: bool,
    pub mipmaps: Option<bool>,
}

impl Filter {
    /// glTF's default where a sampler leaves a filter unset: linear, with linear mipmaps.
    pub const SMOOTH: Filter = Filter { magnify_linear: true, minify_linear: true, mipmaps: Some(true) };
}

/// An 8-bit sRGB image sampled across a mesh through its texture coordinates.
#[derive(Debug, Clone, PartialEq)]
pub struct AlbedoMap {
    /// Where it came from, for messages and debug names (`"image 0"`, a file name).
    pub name: String,
    pub width: u32,
    pub height: u32,
    /// Row after row from the top, RGBA; A is kept for the upload's layout and not used.
    pub texels: Vec<[u8; 4]>,
    /// Along u, then v.
    pub wrap: [Wrap; 2],
    pub filter: Filter,
}

impl AlbedoMap {
    /// Checks the size (1 ..= [`MAX_ALBEDO_MAP_SIDE`] per side) and the texel count.
    pub fn new(
        name: impl Into<String>,
        width: u32,
        height: u32,
        texels: Vec<[u8; 4]>,
        wrap: [Wrap; 2],
        filter: Filter,
    ) -> Result<AlbedoMap, SceneError> {
        let name = name.into();
        let sides = 1..=MAX_ALBEDO_MAP_SIDE;
        if !sides.contains(&width) || !sides.contains(&height) {
            return Err(SceneError::invalid(format!(
                "albedo map {name} is {width}x{height} texels; each side must be 1 to {MAX_ALBEDO_MAP_SIDE}"
            )));
        }
        if texels.len() as u64 != u64::from(width) * u64::from(height) {
            return Err(SceneError::invalid(format!(
                "albedo map {name}: {} texels for {width}x{height}",
                texels.len()
            )));
        }
        Ok(AlbedoMap { name, width, height, texels, wrap, filter })
    }

    /// Reads a PNG or JPEG file (a regular file within [`files::IMAGE`], each side at most
    /// [`MAX_ALBEDO_MAP_SIDE`]) as a map that repeats and filters smoothly (OBJ's `map_Kd` has
    /// no sampler). Errors name `path`.
    pub fn read(path: &Path) -> Result<AlbedoMap, SceneError> {
        let fail = |problem: String| SceneError::in_file(path, problem);
        let bytes = files::read(path, files::IMAGE).map_err(|e| fail(e.to_string()))?;
        let (width, height, texels) = decode(&bytes).map_err(fail)?;
        let name = path.file_name().unwrap_or_default().to_string_lossy().into_owned();
        AlbedoMap::new(name, width, height, texels, [Wrap::Repeat; 2], Filter::SMOOTH)
            .map_err(|e| fail(e.problem().to_owned()))
    }

    /// Its texels as a PNG file's bytes (RGBA, 8 bits).
    pub fn png(&self) -> Vec<u8> {
        let mut bytes = Vec::new();
        let encoder = image::codecs::png::PngEncoder::new(&mut bytes);
        image::ImageEncoder::write_image(
            encoder,
            self.texels.as_flattened(),
            self.width,
            self.height,
            image::ExtendedColorType::Rgba8,
        )
        .expect("encoding to memory fails only on a size the map's own checks refuse");
        bytes
    }
}

/// A PNG or JPEG file's bytes as 8-bit RGBA texels (16-bit channels rounded, grey spread to
/// RGB), each side at most [`MAX_ALBEDO_MAP_SIDE`], checked in the header before decoding.
pub fn decode(bytes: &[u8]) -> Result<(u32, u32, Vec<[u8; 4]>), String> {
    let mut reader = image::ImageReader::new(std::io::Cursor::new(bytes))
        .with_guessed_format()
        .map_err(|e| format!("cannot read: {e}"))?;
    let mut limits = image::Limits::default();
    (limits.max_image_width, limits.max_image_height) =
        (Some(MAX_ALBEDO_MAP_SIDE), Some(MAX_ALBEDO_MAP_SIDE));
    reader.limits(limits);
    let image = reader.decode().map_err(|e| format!("not a PNG or JPEG image Kage can read: {e}"))?;
    let rgba = image.to_rgba8();
    let (width, height) = rgba.dimensions();
    Ok((width, height, rgba.pixels().map(|p| p.0).collect()))
}

/// sRGB decoding of one 8-bit channel (the curve `imageio` decodes with).
pub fn srgb_to_linear(c: u8) -> f32 {
    crate::imageio::srgb_eotf(f32::from(c) / 255.0)
}

/// A mesh's albedo map and its texture coordinates, one per position.
#[derive(Debug, Clone, PartialEq)]
pub struct Texturing {
    pub map: Arc<AlbedoMap>,
    pub uvs: Vec<[f32; 2]>,
}
