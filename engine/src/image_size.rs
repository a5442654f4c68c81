//! An image's size as its header declares it, checked before a pixel is allocated: a file of a
//! few bytes that claims 65536 × 32768 pixels must be an error, not a 24 GiB allocation that
//! aborts the process.
use std::io::{Cursor, Read};

/// The most pixels Kage reads from one image: a 16384 × 8192 environment map, the largest sun
/// map `kage env sun` writes and the widest map a 16384-texel device image (lavapipe's and
/// current GPUs' limit) holds. Renders (at most [`crate::frame::MAX_SIZE`]² pixels) fit in it.
/// As 32-bit float RGBA that is 2 GiB.
pub const MAX_IMAGE_PIXELS: u64 = 16384 * 8192;

/// What is wrong with a declared size. The messages name no file: the caller's error does.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum SizeError {
    #[error(
        "its header declares {width}x{height} pixels, more than the {MAX_IMAGE_PIXELS} pixels \
         (16384x8192) Kage reads from an image"
    )]
    TooLarge { width: u64, height: u64 },
    #[error(
        "its header declares {width}x{height} pixels, which take at least {needed} bytes, but the \
         file has {bytes}: it is truncated or its header is wrong"
    )]
    BeyondFile { width: u64, height: u64, needed: u64, bytes: u64 },
}

/// An image's size from its header, and the fewest bytes a file holding that many pixels has.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Declared {
    pub width: u64,
    pub height: u64,
    pub min_bytes: u64,
}

impl Declared {
    /// Reads an OpenEXR file's headers (not its pixels). The size is its largest part's; each
    /// block of pixels takes at least 16 bytes (its 8-byte entry in the offset table, its
    /// position and its length), whatever the compression.
    pub fn exr(read: impl Read) -> exr::error::Result<Declared> {
        let meta = exr::meta::MetaData::read_from_buffered(read, false)?;
        let size = meta.headers.iter().map(|h| h.layer_size).max_by_key(|s| s.area()).unwrap_or_default();
        let blocks: u64 = meta.headers.iter().map(|h| h.chunk_count as u64).sum();
        Ok(Declared {
            width: size.width() as u64,
            height: size.height() as u64,
            min_bytes: blocks.saturating_mul(16),
        })
    }

    /// Reads a Radiance HDR file's header. Each row takes at least 4 bytes: a pixel, or the
    /// marker of a run-length encoded row.
    pub fn hdr(bytes: &[u8]) -> image::ImageResult<Declared> {
        let reader = image::ImageReader::with_format(Cursor::new(bytes), image::ImageFormat::Hdr);
        let (width, height) = reader.into_dimensions()?;
        let (width, height) = (u64::from(width), u64::from(height));
        Ok(Declared { width, height, min_bytes: 4 * height })
    }

    /// Within [`MAX_IMAGE_PIXELS`], and no more than a file of `bytes` bytes can hold.
    pub fn check(&self, bytes: u64) -> Result<(), SizeError> {
        let Declared { width, height, min_bytes: needed } = *self;
        if width.saturating_mul(height) > MAX_IMAGE_PIXELS {
            return Err(SizeError::TooLarge { width, height });
        }
        if needed > bytes {
            return Err(SizeError::BeyondFile { width, height, needed, bytes });
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes_within_the_limit_and_the_file_pass() {
        let at_limit = Declared { width: 16384, height: 8192, min_bytes: 100 };
        assert_eq!(at_limit.check(100), Ok(()));
        let wider = Declared { width: 16385, ..at_limit };
        assert_eq!(wider.check(100), Err(SizeError::TooLarge { width: 16385, height: 8192 }));
        let overflowing = Declared { width: u64::MAX, height: u64::MAX, min_bytes: 0 };
        assert!(matches!(overflowing.check(0), Err(SizeError::TooLarge { .. })));
        assert_eq!(
            at_limit.check(99),
            Err(SizeError::BeyondFile { width: 16384, height: 8192, needed: 100, bytes: 99 })
        );
    }

    #[test]
    fn a_radiance_header_gives_its_size_and_rows() {
        let header = b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 32768 +X 65536\n";
        let declared = Declared::hdr(header).unwrap();
        assert_eq!(declared, Declared { width: 65536, height: 32768, min_bytes: 4 * 32768 });
        let message = declared.check(header.len() as u64).unwrap_err().to_string();
        assert!(message.contains("65536x32768") && message.contains("16384x8192"), "{message}");
    }
}
