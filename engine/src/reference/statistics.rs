//! The per-pixel (or per-point) statistics the reference shaders accumulate, read back: the
//! mean of the samples and the standard error of that mean.
use crate::backend::{Buffer, BufferDesc, BufferUsage, Context, MemoryLocation};
use crate::error::{Error, Result};
use crate::layouts::ReferenceAccum;
use std::sync::Arc;

/// The sample count after a batch of `spp` more per `item` (pixel, point): a batch of none, or
/// a count past u32, is an error naming both.
pub fn samples_after(samples: u32, spp: u32, item: &str) -> Result<u32> {
    if spp == 0 {
        return Err(Error::InvalidArgument(format!("a batch needs at least one sample per {item}")));
    }
    samples.checked_add(spp).ok_or_else(|| {
        Error::InvalidArgument(format!("{samples} + {spp} samples per {item} overflow the sample counter"))
    })
}

/// A GPU array of [`ReferenceAccum`], one per pixel or point.
pub fn accum_buffer(ctx: &Arc<Context>, name: &str, items: usize) -> Result<Buffer> {
    Buffer::new(
        ctx,
        &BufferDesc {
            name,
            size: (items * size_of::<ReferenceAccum>()) as u64,
            usage: BufferUsage::STORAGE | BufferUsage::TRANSFER_SRC,
            location: MemoryLocation::GpuOnly,
        },
    )
}

/// Means and standard errors per item, RGB.
#[derive(Clone, Debug)]
pub struct Statistics {
    pub samples: u32,
    pub mean: Vec<[f32; 3]>,
    /// sqrt(s² / n) per channel with the unbiased sample variance s²; `None` below two samples.
    pub standard_error: Option<Vec<[f32; 3]>>,
    /// The local-light reference's lowest and highest luminance per pixel at the edge-tie
    /// offsets ([`super::EdgeTies`]); zeros from the other modes.
    pub luminance_range: Vec<[f32; 2]>,
    /// The local-light reference's coverage per pixel: 1 where its primary ray meets a surface,
    /// 0 where it shows none; the other modes' first sums of squares, no coverage.
    pub local_coverage: Vec<f32>,
}

impl Statistics {
    /// Reads `buffer` (after the batches that filled it) holding `samples` samples per item.
    pub fn read(buffer: &Buffer, samples: u32) -> Result<Statistics> {
        let bytes = buffer.read()?;
        let floats: Vec<f32> =
            bytes.chunks_exact(4).map(|c| f32::from_ne_bytes([c[0], c[1], c[2], c[3]])).collect();
        let items = floats.chunks_exact(8);
        let mean = items.clone().map(|a| [a[0], a[1], a[2]]).collect();
        let luminance_range = items.clone().map(|a| [a[3], a[7]]).collect();
        let local_coverage = items.clone().map(|a| a[4]).collect();
        let standard_error = (samples >= 2).then(|| {
            let n = f64::from(samples);
            items
                .map(|a| [a[4], a[5], a[6]].map(|m2| (f64::from(m2.max(0.0)) / (n - 1.0) / n).sqrt() as f32))
                .collect()
        });
        Ok(Statistics { samples, mean, standard_error, luminance_range, local_coverage })
    }

    /// The noise left in the estimate, relative: the RMS over items and channels of the standard
    /// errors, divided by the mean over items and channels. It predicts the relative RMSE
    /// (`kage compare`) against the converged image. `None` below two samples or for a black
    /// result.
    pub fn relative_standard_error(&self) -> Option<f64> {
        let errors = self.standard_error.as_ref()?;
        let n = (self.mean.len() * 3) as f64;
        let mean: f64 = self.mean.iter().flatten().map(|&v| f64::from(v)).sum::<f64>() / n;
        let square: f64 = errors.iter().flatten().map(|&e| f64::from(e) * f64::from(e)).sum::<f64>() / n;
        (mean > 0.0).then(|| square.sqrt() / mean)
    }
}
