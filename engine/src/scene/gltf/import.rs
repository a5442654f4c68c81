//! A glTF file's document, buffers and encoded images, every byte read through [`files`]: the
//! file itself within [`files::GLTF`], each buffer's file only as far as its declared
//! `byteLength` (itself within [`files::GLTF`]), each image's file within [`files::IMAGE`], and
//! only regular files (a URI naming `/dev/zero` or a FIFO is refused, not read). The gltf
//! crate's own `import` reads whatever a URI names, whole.
//!
//! The document's indices are checked before the crate's validation runs: it indexes the
//! accessor of a primitive's POSITION unchecked (a panic on `"POSITION": 99`).
use crate::files;
use std::path::{Path, PathBuf};

/// What [`import`] reads: the document, each buffer's bytes (at least its `byteLength`, padded
/// to 4 as the crate's readers expect) and each image's encoded bytes (PNG or JPEG).
pub struct Import {
    pub document: gltf::Document,
    pub buffers: Vec<gltf::buffer::Data>,
    pub images: Vec<Vec<u8>>,
}

/// Reads the glTF (or GLB) file at `path` with its buffers and images. Errors name the
/// element and its URI; the caller names `path`.
pub fn import(path: &Path) -> Result<Import, String> {
    let bytes = files::read(path, files::GLTF).map_err(|e| e.to_string())?;
    let gltf::Gltf { document, blob } = gltf::Gltf::from_slice_without_validation(&bytes)
        .map_err(|e| format!("not a glTF 2.0 file Kage can read: {e}"))?;
    check_attribute_indices(document.as_json())?;
    validate(document.as_json())?;
    let folder = path.parent().unwrap_or(Path::new(""));
    let mut blob = blob;
    let mut buffers = Vec::new();
    for buffer in document.buffers() {
        let what = |uri: Option<&str>| match uri {
            Some(uri) => format!("buffer {} (\"{}\")", buffer.index(), super::super::clip(uri)),
            None => format!("buffer {} (the GLB file's binary chunk)", buffer.index()),
        };
        let declared = buffer.length() as u64;
        let (mut data, uri) = match buffer.source() {
            gltf::buffer::Source::Bin => {
                (blob.take().ok_or_else(|| format!("{}: the file has no binary chunk", what(None)))?, None)
            }
            gltf::buffer::Source::Uri(uri) => {
                if declared > files::GLTF.bytes {
                    return Err(format!(
                        "{}: its byteLength {declared} is more than the {} bytes Kage reads from {}",
                        what(Some(uri)),
                        files::GLTF.bytes,
                        files::GLTF.kind
                    ));
                }
                let data = match resolve(folder, uri).map_err(|e| format!("{}: {e}", what(Some(uri))))? {
                    Source::Data(data) => data,
                    Source::File(file) => files::read_prefix(&file, declared)
                        .map_err(|e| file_error(&format!("buffer {}", buffer.index()), uri, &file, e))?,
                };
                (data, Some(uri))
            }
        };
        if (data.len() as u64) < declared {
            return Err(format!("{}: {} bytes, fewer than its byteLength {declared}", what(uri), data.len()));
        }
        data.resize(data.len().next_multiple_of(4), 0);
        buffers.push(gltf::buffer::Data(data));
    }
    let mut images = Vec::new();
    for image in document.images() {
        let what = format!("image {}", image.index());
        let encoded = match image.source() {
            gltf::image::Source::Uri { uri, .. } => {
                let what = format!("{what} (\"{}\")", super::super::clip(uri));
                match resolve(folder, uri).map_err(|e| format!("{what}: {e}"))? {
                    Source::Data(data) => data,
                    Source::File(file) => files::read(&file, files::IMAGE)
                        .map_err(|e| file_error(&format!("image {}", image.index()), uri, &file, e))?,
                }
            }
            gltf::image::Source::View { view, .. } => {
                let data = &buffers[view.buffer().index()].0;
                let range = view.offset().checked_add(view.length()).map(|end| view.offset()..end);
                range.and_then(|range| data.get(range)).map(<[u8]>::to_vec).ok_or_else(|| {
                    format!("{what}: its buffer view {} lies beyond its buffer", view.index())
                })?
            }
        };
        images.push(encoded);
    }
    Ok(Import { document, buffers, images })
}

/// A buffer's or image's file that was not read: `buffer 0's file "a.bin" (/path/a.bin): cannot
/// read: ...`, its URI as written and the path it resolved to.
fn file_error(what: &str, uri: &str, file: &Path, error: files::ReadError) -> String {
    format!("{what}'s file \"{}\" ({}): {error}", super::super::clip(uri), file.display())
}

/// Where a URI's bytes are.
enum Source {
    /// A `data:` URI's, decoded (no larger than the URI, which the file's limit bounds).
    Data(Vec<u8>),
    /// A file's: a path relative to the glTF file's folder (percent-decoded), or a `file:` URI.
    File(PathBuf),
}

fn resolve(folder: &Path, uri: &str) -> Result<Source, String> {
    if let Some(rest) = uri.strip_prefix("data:") {
        let (_, encoded) =
            rest.split_once(";base64,").ok_or("a data URI without \";base64,\", which Kage does not read")?;
        let data = base64::decode(encoded).map_err(|e| format!("its base64 data does not decode: {e}"))?;
        return Ok(Source::Data(data));
    }
    if let Some(rest) = uri.strip_prefix("file://").or_else(|| uri.strip_prefix("file:")) {
        return Ok(Source::File(PathBuf::from(rest)));
    }
    if uri.contains(':') {
        return Err("a URI scheme Kage does not read (only relative paths, file: and data:)".into());
    }
    let decoded = urlencoding::decode(uri).map_err(|e| format!("its percent-encoding is not UTF-8: {e}"))?;
    Ok(Source::File(folder.join(&*decoded)))
}

/// Every primitive's attribute accessors exist (the crate's validation indexes POSITION's
/// unchecked and panics past the end).
fn check_attribute_indices(root: &gltf::json::Root) -> Result<(), String> {
    let count = root.accessors.len();
    for (m, mesh) in root.meshes.iter().enumerate() {
        for (p, primitive) in mesh.primitives.iter().enumerate() {
            for (semantic, accessor) in &primitive.attributes {
                if accessor.value() >= count {
                    let semantic = match semantic {
                        gltf::json::validation::Checked::Valid(s) => s.to_string(),
                        gltf::json::validation::Checked::Invalid => "an unknown attribute".into(),
                    };
                    return Err(format!(
                        "mesh {m} primitive {p}: its {semantic} accessor {} does not exist (the file has {count} accessors)",
                        accessor.value()
                    ));
                }
            }
        }
    }
    Ok(())
}

/// The crate's validation of the document (indices in range, required fields, enums), its
/// first problems named by their JSON path.
fn validate(root: &gltf::json::Root) -> Result<(), String> {
    use gltf::json::validation::Validate;
    let mut errors = Vec::new();
    root.validate(root, gltf::json::Path::new, &mut |path, error| {
        errors.push(format!("{}: {error}", path()))
    });
    if errors.is_empty() {
        return Ok(());
    }
    let more = if errors.len() > 4 { format!(" (and {} more)", errors.len() - 4) } else { String::new() };
    errors.truncate(4);
    Err(format!("not a valid glTF 2.0 file: {}{more}", errors.join("; ")))
}
