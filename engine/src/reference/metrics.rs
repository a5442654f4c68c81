//! Image error metrics between a render and a reference, and a false-colour picture of where
//! they differ. Used by `kage compare`, the tests and the benchmarks.
//!
//! Every metric is taken over all pixels and the three colour channels together (alpha is
//! ignored): each pixel contributes three absolute errors |a − b|. The shadow mismatch alone
//! reads the reference's alpha: it leaves out the pixels where a local-light reference shows
//! no surface (alpha 0), whose background only a raster render draws.
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
    /// Pixels lit in one image and shadowed in the other, edge ties and pixels with no surface
    /// apart.
    pub differing: usize,
    /// Pixels where the reference shows no surface (alpha 0): not compared.
    pub no_surface: usize,
    /// Pixels lit in one image only that are edge ties ([`EdgeTies`]): not in `differing`.
    pub at_edges: usize,
    /// Of those, pixels the render lights and the reference shadows (light leaks).
    pub lit_in_render_only: usize,
    /// The luminance that separates lit from shadowed.
    pub threshold: f64,
}

/// Default relative threshold of [`shadow_mismatch`]: 10⁻⁴ of the brightest reference pixel
/// (a lit point at 100 times the brightest point's distance, or at grazing light, still counts).
pub const SHADOW_THRESHOLD: f64 = 1e-4;

/// Where a local-light reference cannot say lit or shadowed more precisely than a rasterizer:
/// per pixel, the lowest and highest luminance the reference takes at the pixel centre and
/// with its primary ray moved by 1 / 2^`bits` px (the device's `subPixelPrecisionBits`, the
/// precision to which the rasterizer places vertices) to each side along x and y. Where that
/// range straddles the lit threshold, an edge (a silhouette, a shadow's edge, a spot's cone,
/// light grazing a face) passes closer to the pixel centre than a rasterizer can place it, so
/// a raster render's state there is a tie, whatever its shadow technique: [`shadow_mismatch`]
/// counts such pixels apart.
#[derive(Clone, Debug, PartialEq)]
pub struct EdgeTies {
    pub width: u32,
    pub height: u32,
    pub bits: u32,
    /// Row-major, row 0 at the top: [lowest, highest] luminance.
    pub ranges: Vec<[f32; 2]>,
}

impl EdgeTies {
    /// As `kage reference --edges` writes them: R the lowest, G the highest luminance, B `bits`.
    pub fn to_image(&self) -> RgbaF32Image {
        let bits = self.bits as f32;
        let pixels = self.ranges.iter().map(|&[low, high]| [low, high, bits, 1.0]).collect();
        RgbaF32Image { width: self.width, height: self.height, pixels }
    }

    /// Reads what [`EdgeTies::to_image`] wrote; anything else is an error naming the problem.
    pub fn from_image(image: &RgbaF32Image) -> Result<EdgeTies> {
        let bits = image.pixels.first().map_or(0.0, |p| p[2]);
        let ordered = image.pixels.iter().all(|p| p[0] <= p[1] && p[2] == bits);
        if !(ordered && (1.0..=16.0).contains(&bits) && bits.fract() == 0.0) {
            return Err(Error::InvalidArgument(
                "not an edge-tie image of `kage reference --light local --edges` (R <= G per pixel, B the bits, 1 to 16)"
                    .into(),
            ));
        }
        let ranges = image.pixels.iter().map(|p| [p[0], p[1]]).collect();
        Ok(EdgeTies { width: image.width, height: image.height, bits: bits as u32, ranges })
    }

    /// Whether each pixel, row-major, is a tie at the luminance `threshold` (the lit threshold
    /// [`ShadowMismatch::threshold`]).
    pub fn ties(&self, threshold: f64) -> impl Iterator<Item = bool> + '_ {
        self.ranges.iter().map(move |&[low, high]| f64::from(low) <= threshold && f64::from(high) > threshold)
    }
}

/// The lit/shadowed disagreement of `a` against the reference `b`; `relative_threshold` in
/// (0, 1) (see [`ShadowMismatch`]); with `edges` (of the same reference), edge ties apart.
pub fn shadow_mismatch(
    a: &RgbaF32Image,
    b: &RgbaF32Image,
    relative_threshold: f64,
    edges: Option<&EdgeTies>,
) -> Result<ShadowMismatch> {
    check_sizes(a, b)?;
    let threshold = lit_threshold(b, relative_threshold)?;
    let (mut differing, mut at_edges, mut lit_in_render_only, mut no_surface) = (0, 0, 0, 0);
    for (((lit_a, lit_b), tie), surface) in lit_states(a, threshold)
        .zip(lit_states(b, threshold))
        .zip(ties(a, edges, threshold)?)
        .zip(surfaces(b))
    {
        if !surface {
            no_surface += 1;
            continue;
        }
        let counted = lit_a != lit_b && !tie;
        differing += usize::from(counted);
        at_edges += usize::from(lit_a != lit_b && tie);
        lit_in_render_only += usize::from(counted && lit_a);
    }
    Ok(ShadowMismatch {
        fraction: differing as f64 / a.pixels.len() as f64,
        differing,
        no_surface,
        at_edges,
        lit_in_render_only,
        threshold,
    })
}

/// Per pixel of the reference, row-major, whether it shows a surface (alpha above 0).
fn surfaces(reference: &RgbaF32Image) -> impl Iterator<Item = bool> + '_ {
    reference.pixels.iter().map(|p| p[3] > 0.0)
}

/// Per pixel of `image`, whether it is an edge tie (never without `edges`).
fn ties<'a>(
    image: &RgbaF32Image,
    edges: Option<&'a EdgeTies>,
    threshold: f64,
) -> Result<Box<dyn Iterator<Item = bool> + 'a>> {
    let Some(edges) = edges else { return Ok(Box::new(std::iter::repeat(false))) };
    if (edges.width, edges.height) != (image.width, image.height) {
        return Err(Error::InvalidArgument(format!(
            "edge ties of {}x{} for images of {}x{}: take them from the same reference",
            edges.width, edges.height, image.width, image.height
        )));
    }
    Ok(Box::new(edges.ties(threshold)))
}

/// The luminance above which a pixel counts as lit: `relative_threshold` in (0, 1) times the
/// reference's brightest pixel.
fn lit_threshold(reference: &RgbaF32Image, relative_threshold: f64) -> Result<f64> {
    if !(relative_threshold > 0.0 && relative_threshold < 1.0) {
        return Err(Error::InvalidArgument(format!(
            "shadow threshold {relative_threshold} must be between 0 and 1 (a fraction of the reference's brightest pixel)"
        )));
    }
    let brightest = reference.pixels.iter().map(pixel_luminance).fold(0.0, f64::max);
    Ok(relative_threshold * brightest)
}

fn pixel_luminance(p: &[f32; 4]) -> f64 {
    f64::from(luminance([p[0], p[1], p[2]]))
}

/// Lit (true) or shadowed per pixel, row-major.
fn lit_states(image: &RgbaF32Image, threshold: f64) -> impl Iterator<Item = bool> + '_ {
    image.pixels.iter().map(move |p| pixel_luminance(p) > threshold)
}

/// Pixels whose lit/shadowed state changes from one frame to the next (temporal stability):
/// in a render and in its reference over the same two cameras. Each frame is classified as
/// [`shadow_mismatch`] classifies it, against that frame's reference. Where the camera moves, the
/// reference's shadow edges move across the screen too; the render's flips that the reference
/// does not make are the instability (shimmering edges, shadows popping as they are refined).
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct ShadowFlips {
    /// Pixels whose state changes in the render.
    pub render: usize,
    /// Pixels whose state changes in the reference.
    pub reference: usize,
    /// Pixels whose state changes in the render but not in the reference.
    pub spurious: usize,
    /// `spurious` / all pixels.
    pub fraction: f64,
}

/// The flips of `render` from frame 0 to frame 1 against those of `reference` (see
/// [`ShadowFlips`]); `relative_threshold` as for [`shadow_mismatch`]. All four images must have
/// one size.
pub fn shadow_flips(
    render: [&RgbaF32Image; 2],
    reference: [&RgbaF32Image; 2],
    relative_threshold: f64,
) -> Result<ShadowFlips> {
    check_sizes(render[0], reference[0])?;
    check_sizes(render[1], reference[1])?;
    check_sizes(render[0], render[1])?;
    let states = |k: usize| -> Result<(Vec<bool>, Vec<bool>)> {
        let threshold = lit_threshold(reference[k], relative_threshold)?;
        Ok((lit_states(render[k], threshold).collect(), lit_states(reference[k], threshold).collect()))
    };
    let ((render_0, reference_0), (render_1, reference_1)) = (states(0)?, states(1)?);
    let (mut flips, mut reference_flips, mut spurious) = (0, 0, 0);
    for i in 0..render_0.len() {
        let (a, b) = (render_0[i] != render_1[i], reference_0[i] != reference_1[i]);
        flips += usize::from(a);
        reference_flips += usize::from(b);
        spurious += usize::from(a && !b);
    }
    Ok(ShadowFlips {
        render: flips,
        reference: reference_flips,
        spurious,
        fraction: spurious as f64 / render_0.len() as f64,
    })
}

/// Frames until an error stops falling once the camera has stopped (`errors[0]` the frame it
/// stopped at): the first frame k from which no later frame's error is below `errors[k]` −
/// `tolerance`. `None` when the last frame was still more than `tolerance` below an earlier
/// one (the error was still falling when the series ended) or the series is empty.
pub fn frames_to_converge(errors: &[f64], tolerance: f64) -> Option<usize> {
    // The lowest error from each frame on, to the end.
    let mut lowest_after = vec![f64::INFINITY; errors.len()];
    for k in (0..errors.len().saturating_sub(1)).rev() {
        lowest_after[k] = lowest_after[k + 1].min(errors[k + 1]);
    }
    let k = (0..errors.len()).find(|&k| lowest_after[k] >= errors[k] - tolerance)?;
    (k + 1 < errors.len() || k == 0).then_some(k)
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
        .map(|(pa, pb)| (pixel_luminance(pa) - pixel_luminance(pb)).abs())
        .collect();
    let mut sorted = errors.clone();
    sorted.sort_by(f64::total_cmp);
    let p99 = percentile(&sorted, 0.99);
    let scale = if p99 > 0.0 { p99 } else { sorted.last().copied().unwrap_or(0.0) };
    let rgb = errors.iter().flat_map(|&e| viridis(if scale > 0.0 { e / scale } else { 0.0 })).collect();
    Ok(DiffImage { width: a.width, height: a.height, rgb, scale })
}

/// Where `a` and the reference `b` disagree on lit and shadowed (as [`shadow_mismatch`]
/// counts): red where only `a` is lit (a leak), blue where only `b` is, yellow where they
/// disagree on an edge tie, light grey where both are lit, dark grey where both are shadowed
/// and black where the reference shows no surface. `scale` is the luminance threshold.
pub fn shadow_mismatch_image(
    a: &RgbaF32Image,
    b: &RgbaF32Image,
    relative_threshold: f64,
    edges: Option<&EdgeTies>,
) -> Result<DiffImage> {
    check_sizes(a, b)?;
    let threshold = lit_threshold(b, relative_threshold)?;
    let rgb = lit_states(a, threshold)
        .zip(lit_states(b, threshold))
        .zip(ties(a, edges, threshold)?)
        .zip(surfaces(b))
        .flat_map(|(states, surface)| match (states, surface) {
            (_, false) => [0, 0, 0],
            (((true, false), true) | ((false, true), true), _) => [240, 210, 40],
            (((true, false), false), _) => [230, 40, 40],
            (((false, true), false), _) => [40, 110, 255],
            (((true, true), _), _) => [170, 170, 170],
            (((false, false), _), _) => [50, 50, 50],
        })
        .collect();
    Ok(DiffImage { width: a.width, height: a.height, rgb, scale: threshold })
}

impl DiffImage {
    pub fn write_png(&self, path: &Path) -> Result<()> {
        crate::imageio::write_rgb8_png(path, &self.rgb, self.width, self.height).map_err(Error::Image)
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
        let m = shadow_mismatch(&render, &reference, 0.25, None).unwrap();
        assert_eq!(m.threshold, 0.5);
        assert_eq!((m.differing, m.lit_in_render_only), (2, 1));
        assert_eq!(m.fraction, 0.25);
        // Any two images that agree on every pixel's state, whatever the values, match.
        let brighter = image(4, 2, &[0.0, 4.0, 3.0, 2.0, 0.0, 0.0, 0.1, 0.0]);
        assert_eq!(shadow_mismatch(&brighter, &reference, 0.25, None).unwrap().differing, 0);
        for bad in [0.0, 1.0, -1.0, f64::NAN] {
            let err = shadow_mismatch(&render, &reference, bad, None).unwrap_err().to_string();
            assert!(err.contains("between 0 and 1"), "{bad}: {err}");
        }
        assert!(shadow_mismatch(&image(2, 1, &[0.0; 2]), &reference, 0.25, None).is_err());
        // The picture of the same: a colour per pixel for each pair of states, counted alike.
        let picture = shadow_mismatch_image(&render, &reference, 0.25, None).unwrap();
        let colours: Vec<&[u8]> = picture.rgb.chunks(3).collect();
        let (red, blue) = ([230, 40, 40], [40, 110, 255]);
        assert_eq!((colours[0], colours[2]), (&red[..], &blue[..]));
        assert_eq!(colours.iter().filter(|c| **c == red || **c == blue).count(), m.differing);
        assert_eq!((colours[1], colours[4]), (&[170u8, 170, 170][..], &[50u8, 50, 50][..]));
        assert_eq!((picture.width, picture.height, picture.scale), (4, 2, 0.5));
    }

    /// A local reference's sky (alpha 0, black) against a render's environment there (lit):
    /// left out of the count and black in the picture, whatever the render shows.
    #[test]
    fn pixels_where_the_reference_shows_no_surface_are_left_out() {
        let mut reference = image(4, 1, &[0.0, 2.0, 0.0, 0.0]);
        let render = image(4, 1, &[0.9, 2.0, 0.9, 0.0]);
        assert_eq!(shadow_mismatch(&render, &reference, 0.25, None).unwrap().differing, 2);
        reference.pixels[0][3] = 0.0;
        let m = shadow_mismatch(&render, &reference, 0.25, None).unwrap();
        assert_eq!((m.differing, m.no_surface, m.lit_in_render_only), (1, 1, 1));
        assert_eq!(m.fraction, 0.25);
        let picture = shadow_mismatch_image(&render, &reference, 0.25, None).unwrap();
        assert_eq!((&picture.rgb[0..3], &picture.rgb[6..9]), (&[0u8, 0, 0][..], &[230u8, 40, 40][..]));
    }

    #[test]
    fn edge_ties_are_counted_apart() {
        // As above; pixel 0's reference range straddles the threshold 0.5 (a tie), pixel 2's
        // does not (0.55 to 0.6: lit wherever the ray moves), pixel 3's range is a tie but
        // both images agree there.
        let reference = image(4, 2, &[0.0, 2.0, 0.6, 0.9, 0.0, 0.0, 0.4, 0.0]);
        let render = image(4, 2, &[0.7, 1.5, 0.0, 0.9, 0.0, 0.0, 0.5, 0.0]);
        let mut ranges = reference.pixels.iter().map(|p| [p[0], p[0]]).collect::<Vec<_>>();
        (ranges[0], ranges[2], ranges[3]) = ([0.0, 0.8], [0.55, 0.6], [0.3, 0.9]);
        let edges = EdgeTies { width: 4, height: 2, bits: 8, ranges };
        let m = shadow_mismatch(&render, &reference, 0.25, Some(&edges)).unwrap();
        assert_eq!((m.differing, m.at_edges, m.lit_in_render_only), (1, 1, 0));
        assert_eq!(m.fraction, 0.125);
        let picture = shadow_mismatch_image(&render, &reference, 0.25, Some(&edges)).unwrap();
        assert_eq!(&picture.rgb[0..3], &[240, 210, 40]);
        assert_eq!(EdgeTies::from_image(&edges.to_image()).unwrap(), edges);
        let other = EdgeTies { width: 2, height: 1, bits: 8, ranges: vec![[0.0, 0.0]; 2] };
        assert!(shadow_mismatch(&render, &reference, 0.25, Some(&other)).is_err());
        assert!(EdgeTies::from_image(&render).is_err(), "an ordinary image is no edge-tie image");
    }

    #[test]
    fn shadow_flips_count_the_render_flips_the_reference_does_not_make() {
        // Both references have brightest 2.0: lit above 0.5 at the threshold 0.25.
        let reference_0 = image(4, 1, &[2.0, 2.0, 0.0, 0.0]);
        let reference_1 = image(4, 1, &[2.0, 0.0, 0.0, 2.0]);
        // Pixel 1 flips in both (an edge moving with the camera); pixel 2 flips in the render
        // only (popping); pixel 3 flips in the reference only (the render lags).
        let render_0 = image(4, 1, &[1.0, 1.0, 0.0, 0.0]);
        let render_1 = image(4, 1, &[1.0, 0.0, 0.9, 0.0]);
        let f = shadow_flips([&render_0, &render_1], [&reference_0, &reference_1], 0.25).unwrap();
        assert_eq!((f.render, f.reference, f.spurious), (2, 2, 1));
        assert_eq!(f.fraction, 0.25);
        // Each frame has its own threshold: a frame twice as bright overall flips nothing.
        let brighter = image(4, 1, &[4.0, 4.0, 0.0, 0.0]);
        let f = shadow_flips([&render_0, &brighter], [&reference_0, &brighter], 0.25).unwrap();
        assert_eq!((f.render, f.spurious), (0, 0));
        let small = image(2, 1, &[0.0; 2]);
        assert!(shadow_flips([&render_0, &small], [&reference_0, &reference_1], 0.25).is_err());
        assert!(shadow_flips([&render_0, &render_1], [&reference_0, &reference_1], 0.0).is_err());
    }

    #[test]
    fn convergence_is_the_frame_after_which_the_error_no_longer_falls() {
        // A constant error (a conventional map at rest) has converged when the camera stops.
        assert_eq!(frames_to_converge(&[0.02; 5], 1e-4), Some(0));
        // Refinement: falls for three frames, then stays within the tolerance.
        let refining = [0.05, 0.03, 0.021, 0.0205, 0.0207, 0.0204];
        assert_eq!(frames_to_converge(&refining, 1e-3), Some(2));
        assert_eq!(frames_to_converge(&refining, 1e-5), None, "still falling by more than 1e-5");
        // A later drop counts even after a plateau: not converged before it.
        assert_eq!(frames_to_converge(&[0.05, 0.05, 0.05, 0.01, 0.01], 1e-3), Some(3));
        // A rise does not reset convergence.
        assert_eq!(frames_to_converge(&[0.04, 0.02, 0.03, 0.025], 1e-3), Some(1));
        // Still falling at the end, or nothing to judge.
        assert_eq!(frames_to_converge(&[0.05, 0.04, 0.03], 1e-3), None);
        assert_eq!(frames_to_converge(&[], 1e-3), None);
        assert_eq!(frames_to_converge(&[0.3], 1e-3), Some(0));
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
