//! Opening the files a user names (scene files, meshes, maps, images, probe lists, caches): only
//! regular files, and none larger than a limit for its kind, both checked before a byte is read,
//! so that a path to `/dev/zero` cannot fill memory nor a FIFO hang the caller. Every file Kage
//! and its command line read goes through [`open`], [`read`] or
//! [`read_prefix`].
use std::fs::{File, FileType};
use std::io::{Read, Write};
use std::path::Path;

/// The largest file of one kind that Kage reads; `kind` names it in the error.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Limit {
    pub kind: &'static str,
    pub bytes: u64,
}

/// Scene files, probe and point lists: 256 MiB, a thousand times the largest exported scene
/// file (the meshes live in OBJ files beside it).
pub const JSON: Limit = Limit { kind: "a JSON file", bytes: 256 << 20 };

/// Wavefront OBJ meshes: 1 GiB of text, some 15 million triangles with their normals.
pub const OBJ: Limit = Limit { kind: "an OBJ mesh", bytes: 1 << 30 };

/// Images and environment maps (.exr, .hdr): 2 GiB, above the largest image Kage reads
/// ([`crate::image_size::MAX_IMAGE_PIXELS`]) stored uncompressed as 32-bit float RGB.
pub const IMAGE: Limit = Limit { kind: "an image", bytes: 2 << 30 };

/// glTF files (.gltf, .glb, whose binary chunk holds the meshes and textures) and the buffer
/// files beside them: 2 GiB, as [`IMAGE`] (a buffer holds vertices or encoded images).
pub const GLTF: Limit = Limit { kind: "a glTF file or buffer", bytes: 2 << 30 };

/// Why a file was not read. The messages name no file: the caller's error does.
#[derive(Debug, thiserror::Error)]
pub enum ReadError {
    #[error("cannot read: {0}")]
    Io(#[from] std::io::Error),
    #[error("cannot read: it is {0}, not a regular file")]
    NotRegular(&'static str),
    #[error("cannot read: it has {bytes} bytes, more than the {} Kage reads from {}", limit.bytes, limit.kind)]
    TooLarge { bytes: u64, limit: Limit },
}

/// Opens `path` if it is a regular file (after following links) of at most `limit` bytes;
/// returns the file and its length.
pub fn open(path: &Path, limit: Limit) -> Result<(File, u64), ReadError> {
    let (file, bytes) = open_regular(path)?;
    if bytes > limit.bytes {
        return Err(ReadError::TooLarge { bytes, limit });
    }
    Ok((file, bytes))
}

/// Opens `path` if it is a regular file (after following links); returns it and its length.
fn open_regular(path: &Path) -> Result<(File, u64), ReadError> {
    // Checked before opening: opening a FIFO for reading blocks until a writer comes.
    let file_type = std::fs::metadata(path)?.file_type();
    if !file_type.is_file() {
        return Err(ReadError::NotRegular(kind_of(file_type)));
    }
    let file = File::open(path)?;
    let bytes = file.metadata()?.len();
    Ok((file, bytes))
}

/// The first `bytes` bytes of the regular file `path` (all of it where it is shorter): the
/// part of a file its reader declares it needs (a glTF buffer's `byteLength`), however large
/// the file is. The caller bounds `bytes`.
pub fn read_prefix(path: &Path, bytes: u64) -> Result<Vec<u8>, ReadError> {
    let (file, length) = open_regular(path)?;
    let mut data = Vec::with_capacity(bytes.min(length) as usize);
    file.take(bytes).read_to_end(&mut data)?;
    Ok(data)
}

/// The whole of `path`, checked as [`open`] does.
pub fn read(path: &Path, limit: Limit) -> Result<Vec<u8>, ReadError> {
    let (file, bytes) = open(path, limit)?;
    let mut data = Vec::with_capacity(bytes as usize);
    // `take`: a file that grows while it is read still stops at the limit.
    file.take(limit.bytes).read_to_end(&mut data)?;
    Ok(data)
}

/// Writes `bytes` to `path` so that every failure is reported and none leaves a partial file:
/// where `path` is (or links to) a regular file, or nothing yet, the bytes go to a temporary
/// file beside the final one, flushed to the disk and renamed over it (removed on failure);
/// where it is (or links to) something else, a device, they are written to it directly with
/// every write checked (`/dev/full` fails). A buffered writer dropped unflushed, as the image
/// crate's `save_buffer` does, loses the error of its last write.
pub fn write(path: &Path, bytes: &[u8]) -> std::io::Result<()> {
    // Through links: the file they name is replaced, not the link.
    let target = std::fs::canonicalize(path).unwrap_or_else(|_| path.to_path_buf());
    if std::fs::metadata(&target).is_ok_and(|m| !m.is_file()) {
        let mut file = std::fs::OpenOptions::new().write(true).open(&target)?;
        file.write_all(bytes)?;
        return file.flush();
    }
    let name = target.file_name().unwrap_or_default().to_string_lossy();
    let temporary = target.with_file_name(format!(".{name}.{}.partial", std::process::id()));
    let written = File::create(&temporary)
        .and_then(|mut file| file.write_all(bytes).and_then(|()| file.sync_all()))
        .and_then(|()| std::fs::rename(&temporary, &target));
    if written.is_err() {
        let _ = std::fs::remove_file(&temporary);
    }
    written
}

/// `bytes` without a leading UTF-8 byte order mark, which some editors write at the start of a
/// file and JSON forbids.
pub fn without_bom(bytes: &[u8]) -> &[u8] {
    bytes.strip_prefix(b"\xEF\xBB\xBF").unwrap_or(bytes)
}

#[cfg(unix)]
fn kind_of(file_type: FileType) -> &'static str {
    use std::os::unix::fs::FileTypeExt;
    let kinds = [
        (file_type.is_dir(), "a folder"),
        (file_type.is_fifo(), "a FIFO"),
        (file_type.is_char_device(), "a character device"),
        (file_type.is_block_device(), "a block device"),
        (file_type.is_socket(), "a socket"),
    ];
    kinds.into_iter().find(|(is, _)| *is).map_or("something else", |(_, kind)| kind)
}

#[cfg(not(unix))]
fn kind_of(file_type: FileType) -> &'static str {
    if file_type.is_dir() {
        "a folder"
    } else {
        "something else"
    }
}

/// `name` in this test process's own folder for `module`'s unit tests, made if missing.
#[cfg(test)]
pub(crate) fn scratch_path(module: &str, name: &str) -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!("kage-{module}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir.join(name)
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::PathBuf;
    use std::time::{Duration, Instant};

    fn scratch(name: &str) -> PathBuf {
        scratch_path("files", name)
    }

    #[test]
    fn devices_folders_and_fifos_are_refused_without_reading() {
        let fifo = scratch("fifo");
        let _ = std::fs::remove_file(&fifo);
        let made = std::process::Command::new("mkfifo").arg(&fifo).status().unwrap();
        assert!(made.success());
        let start = Instant::now();
        for (path, kind) in [
            (Path::new("/dev/zero"), "a character device"),
            (fifo.as_path(), "a FIFO"),
            (Path::new("/tmp"), "a folder"),
        ] {
            let message = read(path, OBJ).unwrap_err().to_string();
            assert!(message.contains(kind) && message.contains("not a regular file"), "{message}");
        }
        assert!(start.elapsed() < Duration::from_secs(5));
    }

    #[test]
    fn files_over_the_limit_are_refused_and_others_read() {
        let path = scratch("eleven");
        std::fs::write(&path, b"eleven byte").unwrap();
        assert_eq!(read(&path, Limit { kind: "a test file", bytes: 11 }).unwrap(), b"eleven byte");
        let err = read(&path, Limit { kind: "a test file", bytes: 10 }).unwrap_err();
        assert!(matches!(err, ReadError::TooLarge { bytes: 11, .. }), "{err}");
        assert!(err.to_string().contains("11 bytes, more than the 10 Kage reads from a test file"), "{err}");
    }
}
