//! The on-disk cache of a scene's [`TransferSet`]: one versioned binary file per geometry and
//! parameter set ([`CacheKey::file_name`]: scenes that share their geometry share the file),
//! checked field by field on load so that a stale or damaged file is reported with its reason
//! and rebuilt, never used.
//!
//! # File format (little-endian)
//! | offset | size | field |
//! |---|---|---|
//! | 0 | 8 | magic `KAGEPRT\0` |
//! | 8 | 4 | format version ([`FORMAT_VERSION`]) |
//! | 12 | 4 | SH bands |
//! | 16 | 4 | rays per vertex |
//! | 20 | 4 | mesh count M |
//! | 24 | 8 | vertex count V (all meshes) |
//! | 32 | 8 | seconds the precomputation took (f64) |
//! | 40 | 16 | geometry hash ([`geometry_hash`]) |
//! | 56 | 8 | FNV-1a 64 checksum of the coefficient bytes |
//! | 64 | 4 | visibility: 0 the vertex's group, 1 the whole scene at rest |
//! | 68 | 4 | seconds of those spent tracing rays (f32) |
//! | 72 | 12·M | per mesh: group index, mesh index, vertex count (u32 each) |
//! | 72 + 12·M | 4·V·bands² | coefficients (f32), mesh after mesh, vertex-major |
//!
//! The geometry hash covers what the transfer depends on: every mesh's positions, normals and
//! indices and which group it belongs to; with the whole scene's visibility, the group
//! transforms too (each group's own transfer is in object space, but what shadows it is where
//! the others stand). Not the albedo (the transfer leaves it out, see the module above).
//! [`FORMAT_VERSION`] changes whenever the layout or the meaning of the numbers does (the
//! estimator or its point set included), so a file from another Kage is rebuilt.
use std::fmt;
use std::io::Write as _;
use std::path::{Path, PathBuf};

use super::{mesh_layout, MeshTransfer, PrtParams, TransferSet, Visibility};
use crate::files::{self, ReadError};
use crate::scene::Scene;

pub const MAGIC: [u8; 8] = *b"KAGEPRT\0";
/// Version 1: Hammersley points with a per-vertex Cranley–Patterson shift, cosine-weighted.
/// Version 2: the visibility field.
/// Version 3: buried vertices filled from their neighbours (`prt::buried`).
pub const FORMAT_VERSION: u32 = 4;
/// File name extension of cache files.
pub const EXTENSION: &str = "kageprt";
const HEADER_BYTES: usize = 72;
const MESH_ENTRY_BYTES: usize = 12;

/// Why a cache file was not used.
#[derive(Clone, Debug, PartialEq)]
pub enum Stale {
    Missing,
    Unreadable(String),
    NotACacheFile,
    Version { found: u32 },
    Truncated { bytes: usize, expected: usize },
    TrailingBytes { bytes: usize, expected: usize },
    Bands { found: u32, wanted: u32 },
    Rays { found: u32, wanted: u32 },
    Visibility { found: u32, wanted: u32 },
    Geometry,
    Meshes(String),
    Checksum,
}

impl fmt::Display for Stale {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Stale::Missing => write!(f, "no cache file yet"),
            Stale::Unreadable(e) => write!(f, "the cache file cannot be read: {e}"),
            Stale::NotACacheFile => write!(f, "the file is not a Kage PRT cache (wrong magic)"),
            Stale::Version { found } => {
                write!(f, "it has format version {found}; this Kage writes version {FORMAT_VERSION}")
            }
            Stale::Truncated { bytes, expected } => {
                write!(f, "it is truncated: {bytes} bytes of {expected}")
            }
            Stale::TrailingBytes { bytes, expected } => {
                write!(f, "it has {bytes} bytes where its header says {expected}: extra data at the end")
            }
            Stale::Bands { found, wanted } => {
                write!(f, "it holds {found} SH bands; {wanted} were asked for")
            }
            Stale::Rays { found, wanted } => {
                write!(f, "it was made with {found} rays per vertex; {wanted} were asked for")
            }
            Stale::Visibility { found, wanted } => write!(
                f,
                "it holds visibility {} ({found}); {} ({wanted}) was asked for",
                visibility_name(*found),
                visibility_name(*wanted)
            ),
            Stale::Geometry => write!(f, "the scene's geometry changed since it was made"),
            Stale::Meshes(what) => write!(f, "its meshes do not match the scene: {what}"),
            Stale::Checksum => write!(f, "its coefficients are corrupt (checksum mismatch)"),
        }
    }
}

/// A failure to write a cache file.
#[derive(Debug, thiserror::Error)]
#[error("{action} {}: {source}", path.display())]
pub struct CacheWriteError {
    action: &'static str,
    path: PathBuf,
    source: std::io::Error,
}

/// What a cache file must match: the scene's geometry and the parameters.
#[derive(Clone, Debug, PartialEq)]
pub struct CacheKey {
    pub params: PrtParams,
    pub geometry: u128,
    /// (group, mesh, vertex count) of every mesh, in scene order.
    layout: Vec<(usize, usize, usize)>,
}

impl CacheKey {
    pub fn new(scene: &Scene, params: PrtParams) -> CacheKey {
        let mut geometry = geometry_hash(scene);
        if params.visibility == Visibility::Scene {
            let mut h = Fnv128(geometry);
            for group in &scene.groups {
                for v in group.transform.matrix().to_cols_array() {
                    h.write(&v.to_le_bytes());
                }
            }
            geometry = h.finish();
        }
        CacheKey { params, geometry, layout: mesh_layout(scene) }
    }

    /// The length of the file this key describes: the header, the mesh table, the coefficients.
    fn file_bytes(&self) -> usize {
        let vertices: usize = self.layout.iter().map(|m| m.2).sum();
        HEADER_BYTES + MESH_ENTRY_BYTES * self.layout.len() + 4 * self.params.coeffs() * vertices
    }

    /// `prt-<16 hex digits>.kageprt`: the digits hash what the transfer depends on and nothing
    /// else, [`CacheKey::geometry`] (the geometry hash, with the group transforms under the whole
    /// scene's visibility), the parameters and the format version. Never the scene's name or
    /// file: scene files around the same geometry (another camera, another name) share one file,
    /// and the name's length is fixed.
    pub fn file_name(&self) -> String {
        let mut h = Fnv64::new();
        h.write(&self.geometry.to_le_bytes());
        h.write(&self.params.bands.to_le_bytes());
        h.write(&self.params.rays.to_le_bytes());
        h.write(&visibility_code(self.params.visibility).to_le_bytes());
        h.write(&FORMAT_VERSION.to_le_bytes());
        format!("prt-{:016x}.{EXTENSION}", h.finish())
    }
}

/// The file's code of a visibility: its stable value.
fn visibility_code(visibility: Visibility) -> u32 {
    visibility as u32
}

fn visibility_name(code: u32) -> &'static str {
    match code {
        0 => "of each vertex's group",
        1 => "of the whole scene at rest",
        _ => "unknown",
    }
}

/// The cache folder when none is given: `$KAGE_CACHE_DIR`, else `$XDG_CACHE_HOME/kage`, else
/// `$HOME/.cache/kage`; `None` when none of them is set.
pub fn default_dir() -> Option<PathBuf> {
    let var = |name| std::env::var_os(name).filter(|v| !v.is_empty());
    if let Some(dir) = var("KAGE_CACHE_DIR") {
        return Some(PathBuf::from(dir));
    }
    if let Some(dir) = var("XDG_CACHE_HOME") {
        return Some(PathBuf::from(dir).join("kage"));
    }
    var("HOME").map(|home| PathBuf::from(home).join(".cache").join("kage"))
}

/// Hash of what the transfer depends on (see the module doc): 128-bit FNV-1a over every mesh's
/// vertex and index counts, position and normal bits and indices, group by group.
pub fn geometry_hash(scene: &Scene) -> u128 {
    let mut h = Fnv128::new();
    h.write(&(scene.groups.len() as u64).to_le_bytes());
    for group in &scene.groups {
        h.write(&(group.meshes.len() as u64).to_le_bytes());
        for mesh in &group.meshes {
            h.write(&(mesh.positions.len() as u64).to_le_bytes());
            h.write(&(mesh.indices.len() as u64).to_le_bytes());
            for v in mesh.positions.iter().chain(&mesh.normals).flatten() {
                h.write(&v.to_le_bytes());
            }
            for i in &mesh.indices {
                h.write(&i.to_le_bytes());
            }
        }
    }
    h.finish()
}

/// Reads the cache file at `path` if it matches `key` in every respect; otherwise says why not.
/// Reads no more than the key's file length (and only a regular file, see [`files`]).
pub fn load(path: &Path, key: &CacheKey) -> Result<TransferSet, Stale> {
    let expected = key.file_bytes();
    let limit = files::Limit { kind: "this PRT cache", bytes: expected as u64 };
    let bytes = match files::read(path, limit) {
        Ok(bytes) => bytes,
        Err(ReadError::Io(e)) if e.kind() == std::io::ErrorKind::NotFound => return Err(Stale::Missing),
        Err(ReadError::TooLarge { bytes, .. }) => {
            return Err(Stale::TrailingBytes { bytes: bytes as usize, expected })
        }
        Err(e) => return Err(Stale::Unreadable(e.to_string())),
    };
    parse(&bytes, key)
}

fn parse(bytes: &[u8], key: &CacheKey) -> Result<TransferSet, Stale> {
    if bytes.len() < MAGIC.len() || bytes[..MAGIC.len()] != MAGIC {
        return Err(Stale::NotACacheFile);
    }
    let truncated = |expected| Stale::Truncated { bytes: bytes.len(), expected };
    let mut r = Reader { bytes, at: 8 };
    let version = r.u32().ok_or(truncated(HEADER_BYTES))?;
    if version != FORMAT_VERSION {
        return Err(Stale::Version { found: version });
    }
    if bytes.len() < HEADER_BYTES {
        return Err(truncated(HEADER_BYTES));
    }
    // The header is complete from here on, so its reads cannot fail.
    let [bands, rays, mesh_count] = [r.u32(), r.u32(), r.u32()].map(Option::unwrap_or_default);
    let vertex_count = r.u64().unwrap_or_default();
    let seconds = f64::from_bits(r.u64().unwrap_or_default());
    let geometry = r.u128().unwrap_or_default();
    let checksum = r.u64().unwrap_or_default();
    let visibility = r.u32().unwrap_or_default();
    let traversal_seconds = f32::from_bits(r.u32().unwrap_or_default());

    if bands != key.params.bands {
        return Err(Stale::Bands { found: bands, wanted: key.params.bands });
    }
    if rays != key.params.rays {
        return Err(Stale::Rays { found: rays, wanted: key.params.rays });
    }
    let wanted = visibility_code(key.params.visibility);
    if visibility != wanted {
        return Err(Stale::Visibility { found: visibility, wanted });
    }
    if geometry != key.geometry {
        return Err(Stale::Geometry);
    }
    if mesh_count as usize != key.layout.len() {
        return Err(Stale::Meshes(format!(
            "{mesh_count} meshes in the file, {} in the scene",
            key.layout.len()
        )));
    }
    let scene_vertices: usize = key.layout.iter().map(|m| m.2).sum();
    if vertex_count != scene_vertices as u64 {
        return Err(Stale::Meshes(format!(
            "{vertex_count} vertices in the file, {scene_vertices} in the scene"
        )));
    }
    let coeffs = key.params.coeffs();
    let data_start = HEADER_BYTES + MESH_ENTRY_BYTES * key.layout.len();
    let expected = key.file_bytes();
    if bytes.len() < expected {
        return Err(truncated(expected));
    }
    if bytes.len() > expected {
        return Err(Stale::TrailingBytes { bytes: bytes.len(), expected });
    }
    for (at, &(group, mesh, vertices)) in key.layout.iter().enumerate() {
        let entry = [r.u32(), r.u32(), r.u32()].map(|v| v.unwrap_or_default() as usize);
        if entry != [group, mesh, vertices] {
            return Err(Stale::Meshes(format!(
                "mesh {at} is (group {}, mesh {}, {} vertices) in the file, \
                 (group {group}, mesh {mesh}, {vertices} vertices) in the scene",
                entry[0], entry[1], entry[2]
            )));
        }
    }
    let data = &bytes[data_start..];
    let mut h = Fnv64::new();
    h.write(data);
    if h.finish() != checksum {
        return Err(Stale::Checksum);
    }
    let mut floats = data.chunks_exact(4).map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]]));
    let meshes = key
        .layout
        .iter()
        .map(|&(group, mesh, vertices)| MeshTransfer {
            group,
            mesh,
            coefficients: floats.by_ref().take(vertices * coeffs).collect(),
        })
        .collect();
    Ok(TransferSet { params: key.params, seconds, traversal_seconds, meshes })
}

/// Writes `set` to `path` atomically (a temporary file in the same folder, then a rename), so a
/// crash or a concurrent reader never sees half a file. Creates the folder. Returns the bytes
/// written.
pub fn save(path: &Path, set: &TransferSet, key: &CacheKey) -> Result<u64, CacheWriteError> {
    let bytes = encode(set, key);
    if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir).map_err(fail("creating the cache folder", dir))?;
    }
    let mut tmp_name = path.file_name().unwrap_or_default().to_os_string();
    tmp_name.push(format!(".tmp-{}", std::process::id()));
    let tmp = path.with_file_name(tmp_name);
    let written = std::fs::File::create(&tmp).and_then(|mut file| {
        file.write_all(&bytes)?;
        file.sync_all()
    });
    if let Err(e) = written.and_then(|()| std::fs::rename(&tmp, path)) {
        let _ = std::fs::remove_file(&tmp);
        return Err(fail("writing the cache file", path)(e));
    }
    Ok(bytes.len() as u64)
}

fn fail(action: &'static str, path: &Path) -> impl FnOnce(std::io::Error) -> CacheWriteError {
    let path = path.to_path_buf();
    move |source| CacheWriteError { action, path, source }
}

fn encode(set: &TransferSet, key: &CacheKey) -> Vec<u8> {
    let mut data = Vec::with_capacity(set.data_bytes());
    for v in set.meshes.iter().flat_map(|m| &m.coefficients) {
        data.extend_from_slice(&v.to_le_bytes());
    }
    let mut checksum = Fnv64::new();
    checksum.write(&data);
    let mut out = Vec::with_capacity(HEADER_BYTES + 12 * set.meshes.len() + data.len());
    out.extend_from_slice(&MAGIC);
    for v in [FORMAT_VERSION, set.params.bands, set.params.rays, set.meshes.len() as u32] {
        out.extend_from_slice(&v.to_le_bytes());
    }
    out.extend_from_slice(&(set.vertex_count() as u64).to_le_bytes());
    out.extend_from_slice(&set.seconds.to_le_bytes());
    out.extend_from_slice(&key.geometry.to_le_bytes());
    out.extend_from_slice(&checksum.finish().to_le_bytes());
    out.extend_from_slice(&visibility_code(set.params.visibility).to_le_bytes());
    out.extend_from_slice(&set.traversal_seconds.to_le_bytes());
    let coeffs = set.params.coeffs().max(1);
    for m in &set.meshes {
        let vertices = m.coefficients.len() / coeffs;
        for v in [m.group, m.mesh, vertices] {
            out.extend_from_slice(&(v as u32).to_le_bytes());
        }
    }
    out.extend_from_slice(&data);
    out
}

struct Reader<'a> {
    bytes: &'a [u8],
    at: usize,
}

impl Reader<'_> {
    fn take<const N: usize>(&mut self) -> Option<[u8; N]> {
        let out = self.bytes.get(self.at..self.at + N)?.try_into().ok()?;
        self.at += N;
        Some(out)
    }
    fn u32(&mut self) -> Option<u32> {
        self.take().map(u32::from_le_bytes)
    }
    fn u64(&mut self) -> Option<u64> {
        self.take().map(u64::from_le_bytes)
    }
    fn u128(&mut self) -> Option<u128> {
        self.take().map(u128::from_le_bytes)
    }
}

/// FNV-1a: not cryptographic, but stale-file detection needs only that an accidental change
/// (an edited mesh, a flipped bit) changes the hash, and it needs no dependency.
struct Fnv128(u128);

impl Fnv128 {
    fn new() -> Self {
        Fnv128(0x6c62272e07bb014262b821756295c58d)
    }
    fn write(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.0 = (self.0 ^ u128::from(b)).wrapping_mul(0x0000000001000000000000000000013b);
        }
    }
    fn finish(&self) -> u128 {
        self.0
    }
}

/// 64-bit FNV-1a, for file names keyed by their contents (this cache's, the benchmarks' cached
/// references).
pub struct Fnv64(u64);

impl Fnv64 {
    pub fn new() -> Self {
        Fnv64(0xcbf29ce484222325)
    }
    pub fn write(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.0 = (self.0 ^ u64::from(b)).wrapping_mul(0x100000001b3);
        }
    }
    pub fn finish(&self) -> u64 {
        self.0
    }
}

impl Default for Fnv64 {
    fn default() -> Self {
        Fnv64::new()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fnv_matches_published_test_vectors() {
        let mut h = Fnv64::new();
        h.write(b"a");
        assert_eq!(h.finish(), 0xaf63dc4c8601ec8c);
        let mut h = Fnv128::new();
        h.write(b"a");
        assert_eq!(h.finish(), 0xd228cb696f1a8caf78912b704e4a8964);
    }

    #[test]
    fn file_names_are_keyed_by_what_the_transfer_depends_on() {
        let key = |geometry, bands, visibility| CacheKey {
            params: PrtParams { bands, rays: 64, visibility },
            geometry,
            layout: Vec::new(),
        };
        let name = key(7, 3, Visibility::Group).file_name();
        assert!(name.starts_with("prt-") && name.ends_with(".kageprt") && name.len() == 28, "{name}");
        assert_eq!(name, key(7, 3, Visibility::Group).file_name());
        for other in
            [key(8, 3, Visibility::Group), key(7, 4, Visibility::Group), key(7, 3, Visibility::Scene)]
        {
            assert_ne!(name, other.file_name());
        }
    }
}
