//! The environment split into q regions acting as area lights (eqs. (8)–(9)), in the manner of
//! Kollig & Keller 2003: Voronoi regions on the sphere whose sites are placed by the map's
//! energy, so that bright parts (a sun) get many small regions and dim sky a few large ones.
//!
//! The sites come from Lloyd relaxation on a downsampled copy of the map, starting from
//! stratified samples of the same weight, which is half the texel's share of the energy
//! (luminance × solid angle) and half its share of the sphere: energy alone would pile every site
//! onto a small sun and leave the sky to one region. Then every texel of the full map goes to its
//! nearest site; a site left without texels (more sites than a sun has texels) moves to the texel
//! its region serves worst. Each region reports:
//! - `energy` B_i = Σ L·dΩ over its texels (RGB), so the regions' energies add up to the map's;
//! - `direction` ω_i, the radiance-weighted centroid (the site when the region is black);
//! - `solid_angle` Ω_i, which sets the width of the box filter (eq. (13)).
//!
//! Regions live in the map's own frame: when the light turns, their directions turn with it and
//! nothing is recomputed, so a rotating light never makes regions pop.
use crate::error::{Error, Result};
use crate::scene::EnvMap;
use crate::sh::{equirect_direction, equirect_texel_solid_angle};
use glam::DVec3;

/// One region of the environment, an area light.
#[derive(Clone, Debug, PartialEq)]
pub struct Region {
    /// B_i: radiance integrated over the region's solid angle, per channel.
    pub energy: [f64; 3],
    /// ω_i: unit radiance-weighted centroid direction, in the map's frame.
    pub direction: DVec3,
    /// Ω_i in steradians.
    pub solid_angle: f64,
    /// The solid angle its energy spreads over: 2π·E\[θ²\], θ the angle to `direction` weighted
    /// by luminance × solid angle, which is πr² for a uniform disk of angular radius r; the
    /// geometric `solid_angle` for a black region. A sun in a large region of black sky is a
    /// small light: its shadows are sharp however large the region is.
    pub spread: f64,
}

/// The decomposition of one map.
#[derive(Clone, Debug)]
pub struct Regions {
    pub regions: Vec<Region>,
    /// Region index of every texel of the map (row-major), for pictures and tests.
    pub texel_region: Vec<u32>,
}

/// Most regions a decomposition may have: each costs an occlusion layer per group pair.
pub const MAX_REGIONS: usize = 256;

/// Texel rows of the copy the sites are relaxed on: fine enough to resolve a sun a few texels
/// wide in a 1024×512 map once it is box-averaged, coarse enough to iterate in milliseconds.
const RELAX_ROWS: u32 = 64;
const LLOYD_ITERATIONS: usize = 24;

fn luminance(c: [f64; 3]) -> f64 {
    0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2]
}

/// A texel direction and its weight.
struct Sample {
    dir: DVec3,
    energy: f64,
}

/// Box-downsamples the map so that it has `RELAX_ROWS` rows (or keeps it when smaller) and
/// returns each texel's direction and site-placement weight (see the module doc).
fn relaxation_samples(map: &EnvMap) -> Vec<Sample> {
    let factor = (map.height() / RELAX_ROWS).max(1);
    let (w, h) = (map.width() / factor, map.height() / factor);
    let mut samples = Vec::with_capacity((w * h) as usize);
    for y in 0..h {
        let solid_angle = equirect_texel_solid_angle(w, h, y);
        for x in 0..w {
            let mut sum = [0.0f64; 3];
            for dy in 0..factor {
                for dx in 0..factor {
                    let p = map.pixels()[((y * factor + dy) * map.width() + x * factor + dx) as usize];
                    for k in 0..3 {
                        sum[k] += p[k] as f64;
                    }
                }
            }
            let n = (factor * factor) as f64;
            samples.push(Sample {
                dir: equirect_direction((x as f64 + 0.5) / w as f64, (y as f64 + 0.5) / h as f64),
                energy: luminance(sum.map(|c| c / n)) * solid_angle,
            });
        }
    }
    let total: f64 = samples.iter().map(|s| s.energy).sum();
    let area = 4.0 * std::f64::consts::PI;
    for (s, y) in samples.iter_mut().zip((0..h).flat_map(|y| (0..w).map(move |_| y))) {
        let share = if total > 0.0 { s.energy / total } else { 0.0 };
        s.energy = 0.5 * share + 0.5 * equirect_texel_solid_angle(w, h, y) / area;
    }
    samples
}

fn nearest(sites: &[DVec3], dir: DVec3) -> usize {
    let mut best = (0, f64::NEG_INFINITY);
    for (i, s) in sites.iter().enumerate() {
        let d = s.dot(dir);
        if d > best.1 {
            best = (i, d);
        }
    }
    best.0
}

/// Sites at stratified positions (i + ½)/q of the weights' cumulative sum.
fn initial_sites(samples: &[Sample], q: usize) -> Vec<DVec3> {
    let sum: f64 = samples.iter().map(|s| s.energy).sum();
    let mut sites = Vec::with_capacity(q);
    let mut acc = 0.0;
    let mut next = 0;
    for s in samples {
        acc += s.energy;
        while next < q && acc >= (next as f64 + 0.5) / q as f64 * sum {
            sites.push(s.dir);
            next += 1;
        }
    }
    while sites.len() < q {
        sites.push(samples[samples.len() - 1].dir);
    }
    sites
}

/// Energy-weighted Lloyd relaxation. A site that loses every texel (two sites started on the
/// same bright texel) moves to the highest-energy texel of the busiest region, so none is wasted.
fn relax(samples: &[Sample], mut sites: Vec<DVec3>) -> Vec<DVec3> {
    let q = sites.len();
    for _ in 0..LLOYD_ITERATIONS {
        let mut centroid = vec![DVec3::ZERO; q];
        let mut energy = vec![0.0f64; q];
        let mut owner = Vec::with_capacity(samples.len());
        for s in samples {
            let i = nearest(&sites, s.dir);
            owner.push(i);
            centroid[i] += s.dir * s.energy;
            energy[i] += s.energy;
        }
        for i in 0..q {
            if centroid[i].length_squared() > 0.0 {
                sites[i] = centroid[i].normalize();
            } else {
                let busiest = (0..q).max_by(|&a, &b| energy[a].total_cmp(&energy[b])).unwrap_or(0);
                let brightest = samples
                    .iter()
                    .zip(&owner)
                    .filter(|(_, &o)| o == busiest)
                    .max_by(|a, b| a.0.energy.total_cmp(&b.0.energy));
                if let Some((s, _)) = brightest {
                    sites[i] = s.dir;
                }
            }
        }
    }
    sites
}

/// Assigns every texel (direction, solid angle, radiance) to its nearest site. While a site has
/// no texel, it moves to the texel farthest (in angle, weighted by solid angle) from the site
/// that holds it, which is where another region helps most; [`Regions::new`] asks for no more
/// sites than there are texels, so this ends after a few rounds.
fn assign_without_empty_regions(
    texels: &[(DVec3, f64, [f64; 3])],
    mut sites: Vec<DVec3>,
) -> (Vec<DVec3>, Vec<u32>) {
    loop {
        let owner: Vec<u32> = texels.iter().map(|t| nearest(&sites, t.0) as u32).collect();
        let mut count = vec![0usize; sites.len()];
        for &o in &owner {
            count[o as usize] += 1;
        }
        let Some(empty) = count.iter().position(|&c| c == 0) else {
            return (sites, owner);
        };
        let farthest = texels
            .iter()
            .zip(&owner)
            .map(|(t, &o)| (t.0, (1.0 - t.0.dot(sites[o as usize])) * t.1))
            .max_by(|a, b| a.1.total_cmp(&b.1));
        match farthest {
            Some((dir, _)) => sites[empty] = dir,
            None => return (sites, owner),
        }
    }
}

impl Regions {
    /// Splits `map` into `q` regions (1 ≤ q ≤ [`MAX_REGIONS`]).
    pub fn new(map: &EnvMap, q: usize) -> Result<Regions> {
        if !(1..=MAX_REGIONS).contains(&q) {
            return Err(Error::InvalidArgument(format!("regions: q = {q}, must be 1 to {MAX_REGIONS}")));
        }
        // Every region needs a texel of its own (a 2x1 map cannot be split in 64).
        let texel_count = map.width() as usize * map.height() as usize;
        if q > texel_count {
            return Err(Error::InvalidArgument(format!(
                "regions: q = {q} regions need at least {q} texels, but the {}x{} environment map has {texel_count}",
                map.width(),
                map.height()
            )));
        }
        let samples = relaxation_samples(map);
        let (w, h) = (map.width(), map.height());
        let texels: Vec<(DVec3, f64, [f64; 3])> = (0..w * h)
            .map(|t| {
                let (x, y) = (t % w, t / w);
                let dir = equirect_direction((x as f64 + 0.5) / w as f64, (y as f64 + 0.5) / h as f64);
                (dir, equirect_texel_solid_angle(w, h, y), map.pixels()[t as usize].map(f64::from))
            })
            .collect();
        let (sites, texel_region) =
            assign_without_empty_regions(&texels, relax(&samples, initial_sites(&samples, q)));

        let mut energy = vec![[0.0f64; 3]; q];
        let mut weighted_dir = vec![DVec3::ZERO; q];
        let mut solid_angle = vec![0.0f64; q];
        for (&(dir, d_omega, l), &i) in texels.iter().zip(&texel_region) {
            let i = i as usize;
            for k in 0..3 {
                energy[i][k] += l[k] * d_omega;
            }
            weighted_dir[i] += dir * luminance(l) * d_omega;
            solid_angle[i] += d_omega;
        }
        let directions: Vec<DVec3> =
            (0..q)
                .map(|i| {
                    if weighted_dir[i].length_squared() > 0.0 {
                        weighted_dir[i].normalize()
                    } else {
                        sites[i]
                    }
                })
                .collect();
        let mut moment = vec![0.0f64; q];
        let mut weight = vec![0.0f64; q];
        for (&(dir, d_omega, l), &i) in texels.iter().zip(&texel_region) {
            let (i, w) = (i as usize, luminance(l) * d_omega);
            let theta = dir.dot(directions[i]).clamp(-1.0, 1.0).acos();
            moment[i] += w * theta * theta;
            weight[i] += w;
        }
        let regions = (0..q)
            .map(|i| Region {
                energy: energy[i],
                direction: directions[i],
                solid_angle: solid_angle[i],
                spread: if weight[i] > 0.0 {
                    2.0 * std::f64::consts::PI * moment[i] / weight[i]
                } else {
                    solid_angle[i]
                },
            })
            .collect();
        Ok(Regions { regions, texel_region })
    }

    /// Σ B_i: the map's total energy per channel.
    pub fn total_energy(&self) -> [f64; 3] {
        std::array::from_fn(|k| self.regions.iter().map(|r| r.energy[k]).sum())
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use std::f64::consts::PI;

    /// Σ L dΩ over the map's texels, per channel.
    pub(crate) fn map_energy(map: &EnvMap) -> [f64; 3] {
        let mut total = [0.0; 3];
        for (t, p) in map.pixels().iter().enumerate() {
            let d_omega = equirect_texel_solid_angle(map.width(), map.height(), t as u32 / map.width());
            for k in 0..3 {
                total[k] += p[k] as f64 * d_omega;
            }
        }
        total
    }

    /// A dim sky with one small, very bright sun: the hard case of the method.
    fn sun_map() -> EnvMap {
        let (w, h) = (256u32, 128u32);
        let pixels = (0..w * h)
            .map(|t| {
                let (x, y) = (t % w, t / w);
                if (60..63).contains(&x) && (30..33).contains(&y) {
                    [30000.0, 28000.0, 25000.0]
                } else if y < h / 2 {
                    [0.4, 0.6, 1.0]
                } else {
                    [0.2, 0.18, 0.15]
                }
            })
            .collect();
        EnvMap::from_pixels(w, h, pixels).unwrap()
    }

    #[test]
    fn energies_add_up_to_the_map_and_solid_angles_to_the_sphere() {
        let map = sun_map();
        for q in [1, 4, 32, 64] {
            let regions = Regions::new(&map, q).unwrap();
            assert_eq!(regions.regions.len(), q);
            let (total, expected) = (regions.total_energy(), map_energy(&map));
            for k in 0..3 {
                // The same f64 terms summed in another grouping: equal to rounding.
                assert!(
                    (total[k] - expected[k]).abs() <= 1e-12 * expected[k],
                    "q = {q}: {total:?} vs {expected:?}"
                );
            }
            let omega: f64 = regions.regions.iter().map(|r| r.solid_angle).sum();
            assert!((omega - 4.0 * PI).abs() < 1e-9, "q = {q}: {omega}");
            assert!(regions.regions.iter().all(|r| r.solid_angle > 0.0), "q = {q}: an empty region");
        }
    }

    #[test]
    fn the_sun_gets_small_regions_and_its_direction() {
        let map = sun_map();
        let regions = Regions::new(&map, 32).unwrap();
        let sun = equirect_direction(61.5 / 256.0, 31.5 / 128.0);
        let brightest = regions.regions.iter().max_by(|a, b| a.energy[0].total_cmp(&b.energy[0])).unwrap();
        assert!(brightest.direction.dot(sun) > 0.999, "{:?}", brightest.direction);
        let mean_solid_angle = 4.0 * PI / 32.0;
        assert!(
            brightest.solid_angle < 0.25 * mean_solid_angle,
            "sun region is {} sr",
            brightest.solid_angle
        );
    }

    #[test]
    fn texels_belong_to_the_nearest_site_region_and_q_is_checked() {
        let regions = Regions::new(&EnvMap::constant([1.0; 3]), 8).unwrap();
        // A constant map: the regions share the sphere roughly evenly.
        for r in &regions.regions {
            assert!(r.solid_angle > 0.5 * 4.0 * PI / 8.0 && r.solid_angle < 2.0 * 4.0 * PI / 8.0, "{r:?}");
        }
        assert_eq!(regions.texel_region.len(), 64 * 32);
        assert!(Regions::new(&EnvMap::constant([1.0; 3]), 0).is_err());
        assert!(Regions::new(&EnvMap::constant([1.0; 3]), MAX_REGIONS + 1).is_err());
    }

    #[test]
    fn a_black_map_still_tiles_the_sphere() {
        let regions = Regions::new(&EnvMap::constant([0.0; 3]), 4).unwrap();
        let omega: f64 = regions.regions.iter().map(|r| r.solid_angle).sum();
        assert!((omega - 4.0 * PI).abs() < 1e-9);
        assert!(regions.regions.iter().all(|r| r.direction.is_finite() && r.energy == [0.0; 3]));
    }
}
