//! Image error metrics between a render and a reference, and a false-colour picture of where
//! they differ. Used by `kage compare`, the tests and the benchmarks.
//!
//! Every metric is taken over all pixels and the three colour channels together (alpha is
//! ignored): each pixel contributes three absolute errors |a − b|.
use super::env_sampling::luminance;
use crate::error::{Error, Result};
use crate::imageio::RgbaF32Image;
use std::path::Path;

#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct ImageMetrics {
    /// sqrt(mean of (a − b)²).
    pub rmse: f64,
    /// `rmse` divided by the mean of the reference `b` (∞ when that mean is 0 and rmse is not).
    pub relative_rmse: f64,
    /// Mean of |a − b|.
    pub mean_abs_error: f64,
    /// The 99th percentile of |a − b| (nearest rank: the smallest value that at least 99 % of
    /// the errors do not exceed).
    pub p99_abs_error: f64,
    pub max_abs_error: f64,
    /// Mean of `b` over pixels and channels.
    pub reference_mean: f64,
}

fn check_sizes(a: &RgbaF32Image, b: &RgbaF32Image) -> Result<()> {
    if (a.width, a.height) != (b.width, b.height) {
        return Err(Error::InvalidArgument(format!(
            "images differ in size: {}x{} vs {}x{}; compare renders of the same size",
            a.width, a.height, b.width, b.height
        )));
    }
    if a.pixels.is_empty() {
        return Err(Error::InvalidArgument("images are empty".into()));
    }
    Ok(())
}

/// The metrics of `a` against the reference `b`; images of different sizes are an error.
pub fn compare(a: &RgbaF32Image, b: &RgbaF32Image) -> Result<ImageMetrics> {
    check_sizes(a, b)?;
    let mut errors: Vec<f64> = Vec::with_capacity(a.pixels.len() * 3);
    let (mut sq, mut abs, mut reference) = (0.0f64, 0.0f64, 0.0f64);
    for (pa, pb) in a.pixels.iter().zip(&b.pixels) {
        for k in 0..3 {
            let e = (f64::from(pa[k]) - f64::from(pb[k])).abs();
            sq += e * e;
            abs += e;
            reference += f64::from(pb[k]);
            errors.push(e);
        }
    }
    let n = errors.len() as f64;
    let rmse = (sq / n).sqrt();
    let reference_mean = reference / n;
    errors.sort_by(f64::total_cmp);
    Ok(ImageMetrics {
        rmse,
        relative_rmse: if rmse == 0.0 { 0.0 } else { rmse / reference_mean },
        mean_abs_error: abs / n,
        p99_abs_error: percentile(&errors, 0.99),
        max_abs_error: errors.last().copied().unwrap_or(0.0),
        reference_mean,
    })
}

/// Nearest-rank percentile of sorted, non-empty values.
fn percentile(sorted: &[f64], q: f64) -> f64 {
    let rank = (q * sorted.len() as f64).ceil() as usize;
    sorted[rank.clamp(1, sorted.len()) - 1]
}

/// How many pixels a render shadows differently from the reference (`kage reference --light
/// local`): a pixel counts as lit when its luminance exceeds `threshold` × the reference's
/// largest luminance, else as shadowed. Meant for renders by local lights alone (the shadowmap
/// and ASM techniques) against the local-light reference: there a shadowed pixel is exactly
/// black, so any positive threshold far below the smallest lit value separates the two states.
/// With several lights "lit" means "receives direct light from at least one".
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct ShadowMismatch {
    /// `differing` / all pixels.
    pub fraction: f64,
    /// Pixels lit in one image and shadowed in the other.
    pub differing: usize,
    /// Of those, pixels the render lights and the reference shadows (light leaks).
    pub lit_in_render_only: usize,
    /// The luminance that separates lit from shadowed.
    pub threshold: f64,
}

/// Default relative threshold of [`shadow_mismatch`]: 10⁻⁴ of the brightest reference pixel
/// (a lit point at 100 times the brightest point's distance, or at grazing light, still counts).
pub const SHADOW_THRESHOLD: f64 = 1e-4;

/// The lit/shadowed disagreement of `a` against the reference `b`; `relative_threshold` in
/// (0, 1) (see [`ShadowMismatch`]).
pub fn shadow_mismatch(
    a: &RgbaF32Image,
    b: &RgbaF32Image,
    relative_threshold: f64,
) -> Result<ShadowMismatch> {
    check_sizes(a, b)?;
    if !(relative_threshold > 0.0 && relative_threshold < 1.0) {
        return Err(Error::InvalidArgument(format!(
            "shadow threshold {relative_threshold} must be between 0 and 1 (a fraction of the reference's brightest pixel)"
        )));
    }
    let y = |p: &[f32; 4]| f64::from(luminance([p[0], p[1], p[2]]));
    let threshold = relative_threshold * b.pixels.iter().map(y).fold(0.0, f64::max);
    let (mut differing, mut lit_in_render_only) = (0, 0);
    for (pa, pb) in a.pixels.iter().zip(&b.pixels) {
        let (lit_a, lit_b) = (y(pa) > threshold, y(pb) > threshold);
        differing += usize::from(lit_a != lit_b);
        lit_in_render_only += usize::from(lit_a && !lit_b);
    }
    Ok(ShadowMismatch {
        fraction: differing as f64 / a.pixels.len() as f64,
        differing,
        lit_in_render_only,
        threshold,
    })
}

/// The false-colour difference picture: per pixel |Y(a) − Y(b)| (luminance), divided by
/// `scale` and mapped through viridis (dark blue 0 → yellow at `scale` and above).
pub struct DiffImage {
    pub width: u32,
    pub height: u32,
    /// 8-bit sRGB, row-major, row 0 at the top.
    pub rgb: Vec<u8>,
    /// The luminance error shown as full yellow: the 99th percentile of the per-pixel
    /// luminance errors (the maximum if that is 0), so a few outliers do not wash it out.
    pub scale: f64,
}

pub fn diff_image(a: &RgbaF32Image, b: &RgbaF32Image) -> Result<DiffImage> {
    check_sizes(a, b)?;
    let errors: Vec<f64> = a
        .pixels
        .iter()
        .zip(&b.pixels)
        .map(|(pa, pb)| {
            let y = |p: &[f32; 4]| f64::from(luminance([p[0], p[1], p[2]]));
            (y(pa) - y(pb)).abs()
        })
        .collect();
    let mut sorted = errors.clone();
    sorted.sort_by(f64::total_cmp);
    let p99 = percentile(&sorted, 0.99);
    let scale = if p99 > 0.0 { p99 } else { sorted.last().copied().unwrap_or(0.0) };
    let rgb = errors.iter().flat_map(|&e| viridis(if scale > 0.0 { e / scale } else { 0.0 })).collect();
    Ok(DiffImage { width: a.width, height: a.height, rgb, scale })
}

impl DiffImage {
    pub fn write_png(&self, path: &Path) -> Result<()> {
        image::save_buffer_with_format(
            path,
            &self.rgb,
            self.width,
            self.height,
            image::ExtendedColorType::Rgb8,
            image::ImageFormat::Png,
        )
        .map_err(|e| Error::InvalidArgument(format!("{}: cannot write PNG: {e}", path.display())))
    }
}

/// Viridis (matplotlib's perceptually uniform map), as 9 sRGB stops interpolated linearly;
/// `t` is clamped to [0, 1].
fn viridis(t: f64) -> [u8; 3] {
    const STOPS: [[f64; 3]; 9] = [
        [68.0, 1.0, 84.0],
        [71.0, 44.0, 122.0],
        [59.0, 81.0, 139.0],
        [44.0, 113.0, 142.0],
        [33.0, 144.0, 141.0],
        [39.0, 173.0, 129.0],
        [92.0, 200.0, 99.0],
        [170.0, 220.0, 50.0],
        [253.0, 231.0, 37.0],
    ];
    let x = t.clamp(0.0, 1.0) * (STOPS.len() - 1) as f64;
    let k = (x.floor() as usize).min(STOPS.len() - 2);
    let f = x - k as f64;
    std::array::from_fn(|c| (STOPS[k][c] + (STOPS[k + 1][c] - STOPS[k][c]) * f).round() as u8)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn image(width: u32, height: u32, values: &[f32]) -> RgbaF32Image {
        RgbaF32Image { width, height, pixels: values.iter().map(|&v| [v, v, v, 1.0]).collect() }
    }

    #[test]
    fn metrics_of_hand_made_images_are_exact() {
        // Errors per pixel 0, 1, 2, 3 on every channel; reference mean 2.
        let a = image(2, 2, &[1.0, 3.0, 0.0, 5.0]);
        let b = image(2, 2, &[1.0, 2.0, 2.0, 2.0]);
        let m = compare(&a, &b).unwrap();
        assert_eq!(m.rmse, (14.0f64 / 4.0).sqrt());
        assert_eq!(m.reference_mean, 1.75);
        assert_eq!(m.relative_rmse, (14.0f64 / 4.0).sqrt() / 1.75);
        assert_eq!(m.mean_abs_error, 1.5);
        // 12 errors; nearest rank ceil(0.99 * 12) = 12: the largest.
        assert_eq!(m.p99_abs_error, 3.0);
        assert_eq!(m.max_abs_error, 3.0);
        let same = compare(&b, &b).unwrap();
        assert_eq!((same.rmse, same.relative_rmse, same.max_abs_error), (0.0, 0.0, 0.0));
    }

    #[test]
    fn shadow_mismatch_counts_pixels_whose_lit_state_differs() {
        // Reference: brightest 2.0, so the threshold at 0.25 is 0.5; lit pixels 1, 2 and 3.
        let reference = image(4, 2, &[0.0, 2.0, 0.6, 0.9, 0.0, 0.0, 0.4, 0.0]);
        // Pixel 0 leaks light, pixel 2 is shadowed wrongly, pixel 6 stays under the threshold.
        let render = image(4, 2, &[0.7, 1.5, 0.0, 0.9, 0.0, 0.0, 0.5, 0.0]);
        let m = shadow_mismatch(&render, &reference, 0.25).unwrap();
        assert_eq!(m.threshold, 0.5);
        assert_eq!((m.differing, m.lit_in_render_only), (2, 1));
        assert_eq!(m.fraction, 0.25);
        // Any two images that agree on every pixel's state, whatever the values, match.
        let brighter = image(4, 2, &[0.0, 4.0, 3.0, 2.0, 0.0, 0.0, 0.1, 0.0]);
        assert_eq!(shadow_mismatch(&brighter, &reference, 0.25).unwrap().differing, 0);
        for bad in [0.0, 1.0, -1.0, f64::NAN] {
            let err = shadow_mismatch(&render, &reference, bad).unwrap_err().to_string();
            assert!(err.contains("between 0 and 1"), "{bad}: {err}");
        }
        assert!(shadow_mismatch(&image(2, 1, &[0.0; 2]), &reference, 0.25).is_err());
    }

    #[test]
    fn percentile_takes_the_nearest_rank() {
        let values: Vec<f64> = (1..=200).map(f64::from).collect();
        assert_eq!(percentile(&values, 0.99), 198.0);
        assert_eq!(percentile(&[5.0], 0.99), 5.0);
    }

    #[test]
    fn size_mismatch_is_an_error_naming_both_sizes() {
        let err = compare(&image(2, 1, &[0.0; 2]), &image(1, 2, &[0.0; 2])).unwrap_err();
        assert!(err.to_string().contains("2x1 vs 1x2"), "{err}");
        assert!(diff_image(&image(2, 1, &[0.0; 2]), &image(1, 1, &[0.0])).is_err());
    }

    #[test]
    fn diff_image_scales_to_the_99th_percentile() {
        let a = image(2, 1, &[1.0, 0.5]);
        let b = image(2, 1, &[0.0, 0.0]);
        let d = diff_image(&a, &b).unwrap();
        // Two pixels: the 99th percentile is the larger error; luminance weights sum to 1.
        assert!((d.scale - 1.0).abs() < 1e-6);
        assert_eq!(&d.rgb[..3], &[253, 231, 37]);
        assert_eq!(&d.rgb[3..], &viridis(0.5));
        assert_eq!(viridis(0.0), [68, 1, 84]);
        let zero = diff_image(&b, &b).unwrap();
        assert_eq!((zero.scale, &zero.rgb[..3]), (0.0, &[68u8, 1, 84][..]));
    }
}
