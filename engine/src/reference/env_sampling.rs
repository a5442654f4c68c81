//! Importance sampling of the environment map: a piecewise-constant 2D distribution over its
//! texels (marginal CDF over rows, one conditional CDF per row), built here on the CPU and
//! uploaded as two storage buffers; `shaders-glsl/include/sampling.glsl` samples it the same way.
//!
//! The lighting integral treats the map as constant over each texel (nearest lookup), which is
//! exactly the function the SH projection integrates. Texel t is chosen with probability
//! Y_t Ω_t / Σ Y Ω (Y: Rec. 709 luminance, Ω: the texel's exact solid angle), then a direction
//! uniform in solid angle inside it (u uniform, cos θ uniform between the row's edges). So the
//! pdf in solid angle is Y_t / Σ Y Ω everywhere in the texel: proportional to the luminance, with
//! no 1 / sin θ factor to blow up at the poles.
use crate::scene::{direction_to_uv, EnvMap};
use crate::sh::equirect_texel_solid_angle;
use glam::Vec3;
use std::f32::consts::{PI, TAU};

/// Rec. 709 / sRGB luminance of linear RGB.
pub fn luminance(rgb: [f32; 3]) -> f32 {
    0.2126 * rgb[0] + 0.7152 * rgb[1] + 0.0722 * rgb[2]
}

pub struct EnvDistribution {
    width: u32,
    height: u32,
    luminance: Vec<f32>,
    /// `height + 1` entries: P(row < j), from exactly 0 to exactly 1.
    marginal_cdf: Vec<f32>,
    /// `height` runs of `width + 1` entries: P(column < i | row j), from 0 to exactly 1.
    conditional_cdf: Vec<f32>,
    /// Σ Y Ω over the sphere; 0 for a black map.
    total: f32,
}

/// One direction drawn from the distribution.
#[derive(Clone, Copy, Debug)]
pub struct EnvSample {
    pub direction: Vec3,
    pub texel: [u32; 2],
    /// Probability density per unit solid angle.
    pub pdf: f32,
}

impl EnvDistribution {
    pub fn new(map: &EnvMap) -> EnvDistribution {
        let (width, height) = (map.width(), map.height());
        let w = width as usize;
        let luminance: Vec<f32> = map.pixels().iter().map(|&p| luminance(p)).collect();
        let mut conditional_cdf = Vec::with_capacity(height as usize * (w + 1));
        let mut row_weights = Vec::with_capacity(height as usize);
        for (j, row) in luminance.chunks_exact(w).enumerate() {
            // Sums in f64 so that a 4k-wide row of tiny values keeps its shape.
            let row_sum: f64 = row.iter().map(|&y| f64::from(y)).sum();
            row_weights.push(row_sum * equirect_texel_solid_angle(width, height, j as u32));
            conditional_cdf.extend(cdf(row.iter().map(|&y| f64::from(y)), w));
        }
        let total: f64 = row_weights.iter().sum();
        let marginal_cdf = cdf(row_weights.iter().copied(), height as usize);
        EnvDistribution { width, height, luminance, marginal_cdf, conditional_cdf, total: total as f32 }
    }

    /// False for a map that is black everywhere: there is nothing to importance-sample, and the
    /// reference falls back to cosine sampling alone (which then gives exactly 0, no NaN).
    pub fn has_energy(&self) -> bool {
        self.total > 0.0
    }

    /// Σ Y Ω: turns a texel's luminance into its pdf per unit solid angle.
    pub fn total(&self) -> f32 {
        self.total
    }

    pub fn marginal_cdf(&self) -> &[f32] {
        &self.marginal_cdf
    }

    /// The marginal CDF as the GPU reads it (reference.glsl): its entries' bits, up to a
    /// whole texel of four words, then its guide (per cell of u, the range where the search
    /// for u ends).
    pub fn marginal_words(&self) -> Vec<u32> {
        gpu_words(&self.marginal_cdf, guide(&self.marginal_cdf))
    }

    /// The conditional CDFs as the GPU reads them: all their entries' bits, up to a whole
    /// texel, then each row's guide in row order.
    pub fn conditional_words(&self) -> Vec<u32> {
        let runs = self.conditional_cdf.chunks_exact(self.width as usize + 1);
        gpu_words(&self.conditional_cdf, runs.flat_map(guide).collect())
    }

    pub fn conditional_cdf(&self) -> &[f32] {
        &self.conditional_cdf
    }

    /// The pdf per unit solid angle of drawing `direction` (0 for a black map).
    pub fn pdf(&self, direction: Vec3) -> f32 {
        self.texel_pdf(self.texel_of(direction))
    }

    fn texel_pdf(&self, [i, j]: [u32; 2]) -> f32 {
        if !self.has_energy() {
            return 0.0;
        }
        self.luminance[(j * self.width + i) as usize] / self.total
    }

    /// The texel a direction falls in (nearest lookup, as the lighting does).
    pub fn texel_of(&self, direction: Vec3) -> [u32; 2] {
        let uv = direction_to_uv(direction);
        [
            ((uv.x * self.width as f32) as u32).min(self.width - 1),
            ((uv.y * self.height as f32) as u32).min(self.height - 1),
        ]
    }

    /// Maps two uniform numbers in [0, 1) to a direction; `None` for a black map.
    pub fn sample(&self, u1: f32, u2: f32) -> Option<EnvSample> {
        if !self.has_energy() {
            return None;
        }
        let (j, v_in) = pick(&self.marginal_cdf, u1);
        let w = self.width as usize;
        let row = &self.conditional_cdf[j * (w + 1)..(j + 1) * (w + 1)];
        let (i, u_in) = pick(row, u2);
        let h = self.height as f32;
        let (cos0, cos1) = ((PI * j as f32 / h).cos(), (PI * (j + 1) as f32 / h).cos());
        let cos_theta = cos0 + (cos1 - cos0) * v_in;
        let sin_theta = (1.0 - cos_theta * cos_theta).max(0.0).sqrt();
        let phi = TAU * (i as f32 + u_in) / self.width as f32;
        let texel = [i as u32, j as u32];
        Some(EnvSample {
            direction: Vec3::new(sin_theta * phi.sin(), cos_theta, -sin_theta * phi.cos()),
            texel,
            pdf: self.texel_pdf(texel),
        })
    }
}

/// The `n + 1` CDF entries of `n` non-negative weights; uniform when they are all 0, so that
/// every run stays monotone and defined.
fn cdf(weights: impl Iterator<Item = f64>, n: usize) -> Vec<f32> {
    let mut sums = Vec::with_capacity(n + 1);
    sums.push(0.0f64);
    for w in weights {
        sums.push(sums.last().copied().unwrap_or(0.0) + w);
    }
    let total = sums[n];
    let mut cdf: Vec<f32> = if total > 0.0 {
        sums.iter().map(|s| (s / total) as f32).collect()
    } else {
        (0..=n).map(|k| k as f32 / n as f32).collect()
    };
    // Exactly 1, so that a uniform number below 1 always lands in some interval.
    cdf[n] = 1.0;
    cdf
}

/// How far beyond its cell of u a [`guide`] entry looks: far more than the f32 rounding of
/// u · n on the GPU moves u (2^-24 of it), far less than a cell of a 16k-wide map.
const GUIDE_MARGIN: f64 = 1e-6;

/// Where the search for the first entry of `cdf` (n + 1 entries) greater than u can end, for u
/// in each of n equal cells of [0, 1), cell g = ⌊u n⌋: a word per cell, the first entry greater
/// than the cell's least u | the first greater than its greatest << 16 (each widened by
/// [`GUIDE_MARGIN`]; a map is at most 16,384 texels wide, `EnvMap::check_size`, so an index
/// fits 16 bits). The answer is monotone in u, so it lies between them, and a search of that
/// range alone ends where the whole one does: the same samples in a read or two, where a
/// binary search of a 1k-wide row takes ten.
fn guide(cdf: &[f32]) -> Vec<u32> {
    let n = cdf.len() - 1;
    let first_above = |u: f64| cdf.partition_point(|&c| f64::from(c) <= u).min(n) as u32;
    let cell = |g: usize| g as f64 / n as f64;
    (0..n)
        .map(|g| first_above(cell(g) - GUIDE_MARGIN) | first_above(cell(g + 1) + GUIDE_MARGIN) << 16)
        .collect()
}

/// A CDF's bits up to a whole texel of four words, then its guide, up to a whole texel.
fn gpu_words(cdf: &[f32], guide: Vec<u32>) -> Vec<u32> {
    let mut words: Vec<u32> = cdf.iter().map(|c| c.to_bits()).collect();
    words.resize(words.len().div_ceil(4) * 4, 0);
    words.extend(guide);
    words.resize(words.len().div_ceil(4) * 4, 0);
    words
}

/// The interval k with cdf[k] <= u < cdf[k + 1] (never an empty one), and where u lies in it.
fn pick(cdf: &[f32], u: f32) -> (usize, f32) {
    let n = cdf.len() - 1;
    // The first entry greater than u, minus one: skips zero-width intervals.
    let k = cdf.partition_point(|&c| c <= u).clamp(1, n) - 1;
    let width = cdf[k + 1] - cdf[k];
    let within = if width > 0.0 { ((u - cdf[k]) / width).clamp(0.0, 1.0) } else { 0.5 };
    (k, within)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A map with a bright spot, a dark band and black texels, so that every branch is taken.
    fn uneven_map() -> EnvMap {
        let (w, h) = (32u32, 16u32);
        let pixels = (0..w * h)
            .map(|t| {
                let (i, j) = (t % w, t / w);
                if j == 3 && i == 7 {
                    [50.0, 40.0, 30.0]
                } else if j >= 12 {
                    [0.0; 3]
                } else {
                    [0.1 + i as f32 * 0.01, 0.2, 0.3]
                }
            })
            .collect();
        EnvMap::from_pixels(w, h, pixels).unwrap()
    }

    /// A tiny deterministic generator (SplitMix64), so the test needs no dependency.
    fn uniforms(seed: u64) -> impl FnMut() -> f32 {
        let mut state = seed;
        move || {
            state = state.wrapping_add(0x9e37_79b9_7f4a_7c15);
            let mut z = state;
            z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
            z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
            ((z ^ (z >> 31)) >> 40) as f32 / (1u64 << 24) as f32
        }
    }

    /// reference.glsl's search through the guide, on the words the GPU reads (`entries` CDF
    /// entries, runs of n + 1), in run `run`: the cell of u as f32 arithmetic gives it, then a
    /// binary search between the cell's two indices.
    fn guided_pick(words: &[u32], entries: usize, run: usize, n: usize, u: f32) -> usize {
        let g = ((u * n as f32) as usize).min(n - 1);
        let range = words[entries.div_ceil(4) * 4 + run * n + g] as usize;
        let (mut lo, mut hi) = (range & 0xffff, range >> 16);
        while lo < hi {
            let mid = (lo + hi) / 2;
            if f32::from_bits(words[run * (n + 1) + mid]) <= u {
                lo = mid + 1;
            } else {
                hi = mid;
            }
        }
        lo.clamp(1, n) - 1
    }

    #[test]
    fn the_guided_search_picks_what_the_whole_search_picks() {
        let dist = EnvDistribution::new(&uneven_map());
        let (w, h) = (dist.width as usize, dist.height as usize);
        let (marginal, conditional) = (dist.marginal_words(), dist.conditional_words());
        let mut next = uniforms(11);
        // Random u, the cells' edges and their neighbours in f32, the largest u below 1.
        let mut us: Vec<f32> = (0..20_000).map(|_| next()).collect();
        for n in [w, h] {
            for g in 0..=n {
                let edge = g as f32 / n as f32;
                us.extend(
                    [edge.next_down(), edge, edge.next_up()].into_iter().filter(|u| (0.0..1.0).contains(u)),
                );
            }
        }
        us.push(1.0f32.next_down());
        for &u in &us {
            assert_eq!(
                guided_pick(&marginal, h + 1, 0, h, u),
                pick(dist.marginal_cdf(), u).0,
                "row at u = {u}"
            );
            for j in [0, 3, 7, 12, 15] {
                let row = &dist.conditional_cdf()[j * (w + 1)..(j + 1) * (w + 1)];
                let column = guided_pick(&conditional, h * (w + 1), j, w, u);
                assert_eq!(column, pick(row, u).0, "row {j}, u = {u}");
            }
        }
    }

    #[test]
    fn cdfs_are_monotone_and_end_at_one() {
        let dist = EnvDistribution::new(&uneven_map());
        let check = |run: &[f32]| {
            assert_eq!(run[0], 0.0);
            assert_eq!(*run.last().unwrap(), 1.0);
            assert!(run.windows(2).all(|p| p[0] <= p[1]), "{run:?}");
        };
        check(dist.marginal_cdf());
        assert_eq!(dist.marginal_cdf().len(), 17);
        assert_eq!(dist.conditional_cdf().len(), 16 * 33);
        dist.conditional_cdf().chunks_exact(33).for_each(check);
    }

    #[test]
    fn pdf_integrates_to_one_over_the_sphere() {
        let map = uneven_map();
        let dist = EnvDistribution::new(&map);
        // The pdf is constant over each texel, so the texel-centre sum is the exact integral;
        // what remains is f32 rounding.
        let mut integral = 0.0f64;
        for j in 0..map.height() {
            for i in 0..map.width() {
                let uv = glam::Vec2::new(
                    (i as f32 + 0.5) / map.width() as f32,
                    (j as f32 + 0.5) / map.height() as f32,
                );
                let pdf = dist.pdf(crate::scene::uv_to_direction(uv));
                integral += f64::from(pdf) * equirect_texel_solid_angle(map.width(), map.height(), j);
            }
        }
        assert!((integral - 1.0).abs() < 1e-5, "{integral}");
    }

    #[test]
    fn samples_follow_the_pdf() {
        let map = uneven_map();
        let dist = EnvDistribution::new(&map);
        let mut next = uniforms(7);
        let n = 200_000;
        let mut counts = vec![0u32; (map.width() * map.height()) as usize];
        for _ in 0..n {
            let s = dist.sample(next(), next()).unwrap();
            assert!((s.direction.length() - 1.0).abs() < 1e-5);
            // The direction lands in the texel it was drawn from (or on its edge).
            let back = dist.texel_of(s.direction);
            assert!(
                back[0].abs_diff(s.texel[0]) <= 1 && back[1].abs_diff(s.texel[1]) <= 1,
                "{s:?} -> {back:?}"
            );
            assert!(s.pdf > 0.0);
            counts[(s.texel[1] * map.width() + s.texel[0]) as usize] += 1;
        }
        for j in 0..map.height() {
            let omega = equirect_texel_solid_angle(map.width(), map.height(), j);
            for i in 0..map.width() {
                let t = (j * map.width() + i) as usize;
                let p = f64::from(dist.texel_pdf([i, j])) * omega;
                let expected = p * n as f64;
                // Binomial counts: 5 standard deviations, plus one count for tiny texels.
                let bound = 5.0 * (expected * (1.0 - p)).sqrt() + 1.0;
                assert!(
                    (f64::from(counts[t]) - expected).abs() <= bound,
                    "texel ({i}, {j}): {} drawn, {expected:.1} expected",
                    counts[t]
                );
            }
        }
        // Black texels are never drawn.
        assert!(counts[(12 * map.width()) as usize..].iter().all(|&c| c == 0));
    }

    #[test]
    fn constant_map_gives_the_uniform_sphere_pdf() {
        let dist = EnvDistribution::new(&EnvMap::constant([0.5, 1.0, 2.0]));
        for d in [Vec3::Y, Vec3::NEG_Y, Vec3::X, Vec3::new(0.3, -0.4, 0.5)] {
            let pdf = dist.pdf(d);
            assert!((pdf - 1.0 / (4.0 * PI)).abs() < 1e-5 / (4.0 * PI), "{d}: {pdf}");
        }
    }

    #[test]
    fn black_map_has_no_energy_and_no_nan() {
        let dist = EnvDistribution::new(&EnvMap::constant([0.0; 3]));
        assert!(!dist.has_energy());
        assert!(dist.sample(0.3, 0.7).is_none());
        assert_eq!(dist.pdf(Vec3::Y), 0.0);
        let finite = |run: &[f32]| run.iter().all(|c| c.is_finite());
        assert!(finite(dist.marginal_cdf()) && finite(dist.conditional_cdf()));
        assert!(dist.marginal_cdf().windows(2).all(|p| p[0] <= p[1]));
    }
}
