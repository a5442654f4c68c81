//! The exact irradiance of an environment map, E(n) = ∫ L(ω) max(n·ω, 0) dω, tabulated over
//! normals in a small equirectangular map (a CPU convolution, once per renderer).
//!
//! Why not 3-band SH: its clamped-cosine kernel rings (the band-2 truncation lets light from
//! below reach an up-facing normal), which under a map with a bright lower hemisphere leaves an
//! open floor several percent too bright; this table is exact but for its sampling.
//!
//! The table is node-centred in latitude: row k holds v = k/(H−1), so rows 0 and H−1 are the
//! poles themselves and a floor's normal (straight up) reads an exact value, not one from a
//! ring a few degrees off it. Column i holds u = i/W. The shader's lookup
//! (`irradiance_uv` in envmap.glsl) shifts its coordinates to these nodes.
use super::environment::GpuEnvironment;
use crate::backend::Context;
use crate::error::Result;
use crate::scene::EnvMap;
use crate::sh::equirect_direction;
use glam::DVec3;
use std::sync::Arc;

/// Columns of the table (longitude).
pub const WIDTH: u32 = 64;
/// Rows of the table, pole to pole inclusive.
pub const HEIGHT: u32 = 33;
/// The map is gathered into at most this many columns (and half as many rows) of bins before
/// the convolution: 2.8° bins, far finer than the cosine kernel's 180°.
pub const SOURCE_WIDTH: u32 = 128;

/// The map's bins, each as `Σ L ∫ω dω` over its texels, per channel. `∫ ω dω` over a texel
/// is taken in closed form: a bin wholly above a normal's horizon then adds exactly
/// `L · (n · ∫ω dω)` to its irradiance, so only the bins the horizon cuts carry an error (and
/// there the cosine is near 0). With the direction (sinθ sinφ, cosθ, −sinθ cosφ), the integral
/// over a texel is a row factor (∫ sin²θ dθ, ∫ cosθ sinθ dθ) times a column factor.
///
/// A map of fewer than `SOURCE_WIDTH / 2` rows is gathered as if each texel were `s` × `s`
/// sub-texels of its radiance, so that its bins are as small as a larger map's: a 2×1 map's
/// two hemispheres as two bins give no light to a normal their boundary contains.
fn bins(map: &EnvMap) -> Vec<[DVec3; 3]> {
    use std::f64::consts::PI;
    let s = (SOURCE_WIDTH / 2).div_ceil(map.height());
    let (w, h) = (map.width() * s, map.height() * s);
    let sin2 = |t: f64| t / 2.0 - (2.0 * t).sin() / 4.0;
    let rows: Vec<(f64, f64)> = (0..h)
        .map(|y| {
            let (t0, t1) = (PI * f64::from(y) / f64::from(h), PI * f64::from(y + 1) / f64::from(h));
            (sin2(t1) - sin2(t0), (t1.sin().powi(2) - t0.sin().powi(2)) / 2.0)
        })
        .collect();
    let columns: Vec<(f64, f64, f64)> = (0..w)
        .map(|x| {
            let (p0, p1) =
                (2.0 * PI * f64::from(x) / f64::from(w), 2.0 * PI * f64::from(x + 1) / f64::from(w));
            (p0.cos() - p1.cos(), p1 - p0, p1.sin() - p0.sin())
        })
        .collect();
    let (bw, bh) = (w.min(SOURCE_WIDTH), h.min(SOURCE_WIDTH / 2));
    let mut sums = vec![[DVec3::ZERO; 3]; (bw * bh) as usize];
    for (t, p) in map.pixels().iter().enumerate() {
        let (texel_x, texel_y) = (t as u32 % map.width(), t as u32 / map.width());
        for (x, y) in (0..s * s).map(|i| (texel_x * s + i % s, texel_y * s + i / s)) {
            let ((ss, cs), (sx, dphi, sz)) = (rows[y as usize], columns[x as usize]);
            let moment = DVec3::new(ss * sx, cs * dphi, -ss * sz);
            let bin = &mut sums[((y * bh / h) * bw + x * bw / w) as usize];
            for c in 0..3 {
                bin[c] += f64::from(p[c]) * moment;
            }
        }
    }
    sums
}

/// The irradiance table of `map`, [`WIDTH`]×[`HEIGHT`] RGB, row-major (see the module doc for
/// its nodes).
pub fn irradiance_table(map: &EnvMap) -> Vec<[f32; 3]> {
    let bins = bins(map);
    (0..WIDTH * HEIGHT)
        .map(|t| {
            let (i, k) = (t % WIDTH, t / WIDTH);
            let n = equirect_direction(f64::from(i) / f64::from(WIDTH), f64::from(k) / f64::from(HEIGHT - 1));
            let mut e = [0.0f64; 3];
            for bin in &bins {
                for c in 0..3 {
                    e[c] += n.dot(bin[c]).max(0.0);
                }
            }
            e.map(|v| v as f32)
        })
        .collect()
}

/// The table of `map` on the GPU, sampled bilinearly (wrapping in longitude, clamped at the
/// poles); for `None` (a pipeline that never reads it) one black texel, not worth computing.
pub fn gpu_irradiance(ctx: &Arc<Context>, map: Option<&EnvMap>) -> Result<GpuEnvironment> {
    match map {
        Some(map) => GpuEnvironment::table(ctx, "irradiance", WIDTH, HEIGHT, &irradiance_table(map)),
        None => GpuEnvironment::table(ctx, "irradiance.unused", 1, 1, &[[0.0; 3]]),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    fn at(table: &[[f32; 3]], i: u32, k: u32) -> [f32; 3] {
        table[(k * WIDTH + i) as usize]
    }

    #[test]
    fn a_constant_map_gives_pi_times_its_radiance_everywhere() {
        for p in irradiance_table(&EnvMap::constant([1.0, 0.5, 2.0])) {
            for (got, want) in p.iter().zip([PI, PI / 2.0, 2.0 * PI]) {
                // Exact for the bins wholly above the horizon; those it cuts (5.6° texels of
                // this small map) err where the cosine is near 0.
                assert!((f64::from(*got) / want - 1.0).abs() < 1e-3, "{got} against {want}");
            }
        }
    }

    /// Maps of a few texels: each texel gathered as sub-texels. Before, a 2×1 map's two bins
    /// left normals on their boundary unlit. Tolerance as above.
    #[test]
    fn tiny_constant_maps_give_pi_everywhere() {
        for (w, h) in [(2, 1), (4, 2), (16, 8)] {
            let map = EnvMap::from_pixels(w, h, vec![[1.0; 3]; (w * h) as usize]).unwrap();
            for p in irradiance_table(&map) {
                assert!((f64::from(p[0]) / PI - 1.0).abs() < 1e-3, "{w}x{h}: {} against π", p[0]);
            }
        }
    }

    #[test]
    fn a_linear_sky_gives_the_closed_form() {
        // L(ω) = 1 + ω_y has E(n) = π + (2π/3) n_y; 3-band SH holds it exactly too, so this
        // checks the table's nodes and directions, the poles included.
        let (w, h) = (256u32, 128u32);
        let pixels = (0..w * h)
            .map(|t| {
                let y = equirect_direction(0.5 / f64::from(w), (f64::from(t / w) + 0.5) / f64::from(h)).y;
                [(1.0 + y) as f32; 3]
            })
            .collect();
        let table = irradiance_table(&EnvMap::from_pixels(w, h, pixels).unwrap());
        for k in [0, 1, HEIGHT / 2, HEIGHT - 2, HEIGHT - 1] {
            let n_y = (PI * f64::from(k) / f64::from(HEIGHT - 1)).cos();
            let want = PI + 2.0 * PI / 3.0 * n_y;
            let got = f64::from(at(&table, 7, k)[0]);
            assert!((got / want - 1.0).abs() < 2e-3, "row {k}: {got} against {want}");
        }
    }

    #[test]
    fn light_from_below_never_reaches_an_up_facing_normal() {
        // The lower hemisphere bright, the upper black: E(up) is exactly 0, E(down) π.
        let (w, h) = (64u32, 32u32);
        let pixels = (0..w * h).map(|t| if t / w >= h / 2 { [1.0; 3] } else { [0.0; 3] }).collect();
        let table = irradiance_table(&EnvMap::from_pixels(w, h, pixels).unwrap());
        assert_eq!(at(&table, 0, 0), [0.0; 3]);
        let down = f64::from(at(&table, 0, HEIGHT - 1)[0]);
        assert!((down / PI - 1.0).abs() < 1e-3, "{down}");
    }
}
