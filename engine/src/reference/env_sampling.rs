//! Importance sampling of the environment map: a piecewise-constant distribution over its
//! texels as an alias table (Walker 1977, built by Vose's method), built here on the CPU and
//! uploaded as a texel buffer; `shaders-glsl/include/reference.glsl` samples it the same way.
//! A draw costs one read whatever the map's size, where a search of CDFs took a dozen: the
//! reference's resampling draws 16 candidates per sample (BENCHMARKS.md).
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
    /// Per texel, row by row: the chance out of 2^32 that a draw of its slot yields its alias
    /// instead of itself, and the alias.
    alias: Vec<[u32; 2]>,
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
        // In f64, so that a 4k × 2k map of tiny values keeps its shape.
        let weights: Vec<f64> = luminance
            .iter()
            .enumerate()
            .map(|(t, &y)| f64::from(y) * equirect_texel_solid_angle(width, height, (t / w) as u32))
            .collect();
        let total: f64 = weights.iter().sum();
        EnvDistribution { width, height, luminance, alias: alias_table(&weights), total: total as f32 }
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

    /// The alias table as the GPU reads it (reference.glsl): per texel its chance and alias,
    /// up to a whole texel buffer texel of four words.
    pub fn alias_words(&self) -> Vec<u32> {
        let mut words: Vec<u32> = self.alias.iter().flatten().copied().collect();
        words.resize(words.len().div_ceil(4) * 4, 0);
        words
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

    /// A direction drawn from uniform words `next()` as reference.glsl draws it (the slot,
    /// the alias's chance, then where in the texel); `None` for a black map.
    pub fn sample(&self, mut next: impl FnMut() -> u32) -> Option<EnvSample> {
        if !self.has_energy() {
            return None;
        }
        let slot = below(&mut next, self.width * self.height);
        let [chance, alias] = self.alias[slot as usize];
        let t = if next() < chance { alias } else { slot };
        let (i, j) = (t % self.width, t / self.width);
        let unit = |word: u32| (word >> 8) as f32 / (1u32 << 24) as f32;
        let (v_in, u_in) = (unit(next()), unit(next()));
        let h = self.height as f32;
        let (cos0, cos1) = ((PI * j as f32 / h).cos(), (PI * (j + 1) as f32 / h).cos());
        let cos_theta = cos0 + (cos1 - cos0) * v_in;
        let sin_theta = (1.0 - cos_theta * cos_theta).max(0.0).sqrt();
        let phi = TAU * (i as f32 + u_in) / self.width as f32;
        let texel = [i, j];
        Some(EnvSample {
            direction: Vec3::new(sin_theta * phi.sin(), cos_theta, -sin_theta * phi.cos()),
            texel,
            pdf: self.texel_pdf(texel),
        })
    }
}

/// Uniform in [0, n) from uniform words, unbiased (Lemire 2019: the high word of a word times
/// n, drawn again where the low word lies in the 2^32 mod n values that favour some results);
/// sampling.glsl's `rng_below`.
fn below(next: &mut impl FnMut() -> u32, n: u32) -> u32 {
    let reject = n.wrapping_neg() % n;
    loop {
        let product = u64::from(next()) * u64::from(n);
        if product as u32 >= reject {
            return (product >> 32) as u32;
        }
    }
}

/// The alias table of non-negative `weights` (Vose 1991): slot k yields k with probability
/// p_k and its alias otherwise, p_k and the aliases chosen so that each index comes out in
/// proportion to its weight over a uniform slot. Stored as the alias's chance in 2^32
/// (rounded; 0 for p = 1). A slot of weight 0 left over by rounding goes to the heaviest
/// index, so that a texel of no light is never drawn (save with chance 2^-32 per slot). All
/// weights 0: each slot itself (the table is then never read).
fn alias_table(weights: &[f64]) -> Vec<[u32; 2]> {
    let n = weights.len();
    let total: f64 = weights.iter().sum();
    let mut table: Vec<[u32; 2]> = (0..n as u32).map(|k| [0, k]).collect();
    if total <= 0.0 {
        return table;
    }
    let mut scaled: Vec<f64> = weights.iter().map(|w| w * n as f64 / total).collect();
    let (mut small, mut large): (Vec<usize>, Vec<usize>) = (0..n).partition(|&k| scaled[k] < 1.0);
    let chance = |p: f64| ((1.0 - p) * 4_294_967_296.0).round().min(f64::from(u32::MAX)) as u32;
    while let (Some(&s), Some(&l)) = (small.last(), large.last()) {
        small.pop();
        table[s] = [chance(scaled[s]), l as u32];
        scaled[l] -= 1.0 - scaled[s];
        if scaled[l] < 1.0 {
            large.pop();
            small.push(l);
        }
    }
    let heaviest = (0..n).max_by(|&a, &b| weights[a].total_cmp(&weights[b])).unwrap_or(0) as u32;
    for k in small.into_iter().chain(large) {
        table[k] = if weights[k] > 0.0 { [0, k as u32] } else { [u32::MAX, heaviest] };
    }
    table
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

    /// A tiny deterministic generator of uniform words (SplitMix64), so the test needs no
    /// dependency.
    fn words(seed: u64) -> impl FnMut() -> u32 {
        let mut state = seed;
        move || {
            state = state.wrapping_add(0x9e37_79b9_7f4a_7c15);
            let mut z = state;
            z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
            z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
            ((z ^ (z >> 31)) >> 32) as u32
        }
    }

    /// What a uniform slot yields, exactly: each index's probability from the table, against
    /// its weight over the total. The table rounds each chance to 2^-32, so over n slots an
    /// index is off by at most n 2^-32 / n = 2^-32 (plus f64 rounding).
    #[test]
    fn the_alias_table_yields_each_texel_in_proportion_to_its_weight() {
        let map = uneven_map();
        let dist = EnvDistribution::new(&map);
        let n = dist.alias.len();
        let mut yielded = vec![0.0f64; n];
        for (k, &[chance, alias]) in dist.alias.iter().enumerate() {
            let to_alias = f64::from(chance) / 4_294_967_296.0;
            yielded[k] += (1.0 - to_alias) / n as f64;
            yielded[alias as usize] += to_alias / n as f64;
        }
        for (t, &p) in yielded.iter().enumerate() {
            let j = t as u32 / map.width();
            let expected = f64::from(dist.luminance[t])
                * equirect_texel_solid_angle(map.width(), map.height(), j)
                / f64::from(dist.total);
            // The total is kept in f32: its rounding scales every texel alike.
            assert!(
                (p - expected).abs() <= 2f64.powi(-32) + 1e-7 * expected,
                "texel {t}: {p} against {expected}"
            );
        }
        // Black texels: never their own slot's outcome, nor an alias.
        let black = (12 * map.width()) as usize;
        assert!(dist.alias[black..].iter().all(|&[chance, _]| chance == u32::MAX));
        assert!(dist.alias.iter().all(|&[_, alias]| (alias as usize) < black));
        // Weights that no f64 sum leaves exact: a slot is never both short and over one.
        let uneven: Vec<f64> = (0..1000).map(|k| ((k * 7919) % 1013) as f64 * 0.1 + 1e-3).collect();
        let total: f64 = uneven.iter().sum();
        let mut yielded = vec![0.0f64; uneven.len()];
        for (k, &[chance, alias]) in alias_table(&uneven).iter().enumerate() {
            let to_alias = f64::from(chance) / 4_294_967_296.0;
            yielded[k] += (1.0 - to_alias) / 1000.0;
            yielded[alias as usize] += to_alias / 1000.0;
        }
        for (k, p) in yielded.iter().enumerate() {
            assert!((p - uneven[k] / total).abs() < 1e-9, "{k}: {p} against {}", uneven[k] / total);
        }
    }

    #[test]
    fn below_is_uniform_and_in_range() {
        let mut next = words(3);
        for n in [1u32, 3, 7, 1 << 27, u32::MAX] {
            assert!((0..1000).all(|_| below(&mut next, n) < n));
        }
        // The rejection, where it matters: for n = 3 · 2^30 the high word alone is 0.75 r
        // rounded down, which for r = 4m + d (d = 0..3) is 3m + 0, 0, 1, 2: residue 0 mod 3
        // half the time. The low word is d / 4 of 2^32, below 2^32 mod n = 2^30 for d = 0
        // alone, which is drawn again: the residues come out a third each.
        let n = 3u32 << 30;
        let draws = 300_000;
        let thirds = (0..draws).fold([0u32; 3], |mut c, _| {
            c[(below(&mut next, n) % 3) as usize] += 1;
            c
        });
        let expected = f64::from(draws) / 3.0;
        for c in thirds {
            assert!((f64::from(c) - expected).abs() < 5.0 * (expected * 2.0 / 3.0).sqrt(), "{thirds:?}");
        }
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
        let mut next = words(7);
        let n = 200_000;
        let mut counts = vec![0u32; (map.width() * map.height()) as usize];
        for _ in 0..n {
            let s = dist.sample(&mut next).unwrap();
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
        assert!(dist.sample(words(1)).is_none());
        assert_eq!(dist.pdf(Vec3::Y), 0.0);
        assert!(dist.alias.iter().enumerate().all(|(k, &e)| e == [0, k as u32]));
    }
}
