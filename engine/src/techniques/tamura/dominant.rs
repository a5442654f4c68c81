//! Dominant lights (beyond the paper): the few small, bright parts of an environment map (a sun,
//! studio lamps) that carry much of its energy. Three SH bands cannot hold the sharp terminator
//! such a light draws on a curved surface, nor its exact cosine on a flat one, and a region
//! holding it is a poor area light for eq. (13). So they are taken out of the map: the rest (the
//! residual) is lit as the paper does, and each dominant light per pixel, with an exact cosine
//! and a soft shadow from every group, its own included (`dominant_maps.rs`).
//!
//! A dominant light is a connected set of texels (8-neighbours, wrapping around in longitude)
//! that holds a texel brighter than [`SEED`] times the map's mean radiance and grows through
//! texels brighter than [`GROW`] times it; it is kept when it carries at least [`MIN_SHARE`] of
//! the map's energy and its energy spreads over at most [`MAX_RADIUS_DEG`] (a wider light's
//! penumbrae are what the regions' box filters do well). At most `max` are kept, the most
//! energetic first.
use crate::scene::EnvMap;
use crate::sh::{equirect_direction, equirect_texel_solid_angle};
use glam::DVec3;

/// Seed threshold, in multiples of the map's mean radiance (its energy over 4π).
pub const SEED: f64 = 100.0;
/// Growth threshold, in multiples of the mean radiance.
pub const GROW: f64 = 10.0;
/// Smallest share of the map's energy (luminance) a dominant light carries.
pub const MIN_SHARE: f64 = 0.01;
/// Largest angular radius of a dominant light, degrees (of the uniform disk its energy spreads
/// like).
pub const MAX_RADIUS_DEG: f64 = 8.0;
/// Most dominant lights a map may give.
pub const MAX_LIGHTS: usize = 8;

/// One dominant light, in the map's frame.
#[derive(Clone, Debug, PartialEq)]
pub struct DominantLight {
    /// Radiance integrated over its texels, per channel.
    pub energy: [f64; 3],
    /// Unit direction towards its energy-weighted centroid.
    pub direction: DVec3,
    /// Angular radius (radians) of the uniform disk whose energy spreads as the light's:
    /// sqrt(2·E\[θ²\]), θ the angle to `direction` weighted by luminance × solid angle.
    pub radius: f64,
    /// Texels it took from the map.
    pub texels: usize,
}

/// A map split into its dominant lights and the rest.
#[derive(Clone, Debug)]
pub struct Split {
    pub lights: Vec<DominantLight>,
    /// The map with the lights' texels set to black.
    pub residual: EnvMap,
}

fn luminance(c: [f32; 3]) -> f64 {
    0.2126 * f64::from(c[0]) + 0.7152 * f64::from(c[1]) + 0.0722 * f64::from(c[2])
}

/// Splits `map` into at most `max` dominant lights (0: none, the residual is the map) and the
/// residual.
pub fn split(map: &EnvMap, max: usize) -> Split {
    let (w, h) = (map.width() as usize, map.height() as usize);
    let pixels = map.pixels();
    let luma: Vec<f64> = pixels.iter().map(|&p| luminance(p)).collect();
    let solid_angle: Vec<f64> =
        (0..h).map(|y| equirect_texel_solid_angle(w as u32, h as u32, y as u32)).collect();
    let total: f64 = (0..w * h).map(|t| luma[t] * solid_angle[t / w]).sum();
    let mean = total / (4.0 * std::f64::consts::PI);
    if max == 0 || total <= 0.0 {
        return Split { lights: Vec::new(), residual: map.clone() };
    }
    let direction = |t: usize| {
        equirect_direction((t % w) as f64 / w as f64 + 0.5 / w as f64, ((t / w) as f64 + 0.5) / h as f64)
    };

    // Components grown from each seed, in scan order.
    let mut owner = vec![usize::MAX; w * h];
    let mut components: Vec<Vec<usize>> = Vec::new();
    for seed in 0..w * h {
        if luma[seed] <= SEED * mean || owner[seed] != usize::MAX {
            continue;
        }
        let id = components.len();
        let mut texels = vec![seed];
        owner[seed] = id;
        let mut next = 0;
        while next < texels.len() {
            let t = texels[next];
            next += 1;
            let (x, y) = ((t % w) as i64, (t / w) as i64);
            for (dx, dy) in [(-1, -1), (0, -1), (1, -1), (-1, 0), (1, 0), (-1, 1), (0, 1), (1, 1)] {
                let ny = y + dy;
                if !(0..h as i64).contains(&ny) {
                    continue;
                }
                let n = ny as usize * w + (x + dx).rem_euclid(w as i64) as usize;
                if owner[n] == usize::MAX && luma[n] > GROW * mean {
                    owner[n] = id;
                    texels.push(n);
                }
            }
        }
        components.push(texels);
    }

    let mut lights: Vec<(DominantLight, Vec<usize>)> = components
        .into_iter()
        .filter_map(|texels| {
            let mut energy = [0.0f64; 3];
            let (mut weight, mut centroid) = (0.0f64, DVec3::ZERO);
            for &t in &texels {
                let d_omega = solid_angle[t / w];
                for k in 0..3 {
                    energy[k] += f64::from(pixels[t][k]) * d_omega;
                }
                weight += luma[t] * d_omega;
                centroid += direction(t) * luma[t] * d_omega;
            }
            if weight < MIN_SHARE * total {
                return None;
            }
            let axis = centroid.normalize();
            let moment: f64 = texels
                .iter()
                .map(|&t| {
                    let theta = direction(t).dot(axis).clamp(-1.0, 1.0).acos();
                    luma[t] * solid_angle[t / w] * theta * theta
                })
                .sum::<f64>()
                / weight;
            let radius = (2.0 * moment).sqrt();
            (radius <= MAX_RADIUS_DEG.to_radians()).then(|| {
                let light = DominantLight { energy, direction: axis, radius, texels: texels.len() };
                (light, texels)
            })
        })
        .collect();
    let brightness = |l: &DominantLight| 0.2126 * l.energy[0] + 0.7152 * l.energy[1] + 0.0722 * l.energy[2];
    lights.sort_by(|a, b| brightness(&b.0).total_cmp(&brightness(&a.0)));
    lights.truncate(max);

    let mut residual = pixels.to_vec();
    for (_, texels) in &lights {
        for &t in texels {
            residual[t] = [0.0; 3];
        }
    }
    let residual = EnvMap::from_pixels(map.width(), map.height(), residual)
        .expect("the map's own shape and finite values, some set to 0");
    Split { lights: lights.into_iter().map(|(l, _)| l).collect(), residual }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::frame::regions::tests::map_energy;
    use crate::scene::SunMap;

    /// A 2° sun over a dim sky: one light, at the sun, of the sun's size and energy; the sky
    /// stays in the residual, and the energies add up to the map's.
    #[test]
    fn a_sun_over_a_sky_is_one_dominant_light() {
        let sun = SunMap { sky: [0.3, 0.4, 0.6], ground: [0.1; 3], ..SunMap::DEFAULT };
        let map = sun.map().unwrap();
        let split = split(&map, 4);
        assert_eq!(split.lights.len(), 1, "{:?}", split.lights);
        let light = &split.lights[0];
        assert!(light.direction.dot(sun.direction()) > 0.99995, "{:?}", light.direction);
        // The disk's texels' spread: within 10 % of the 2° radius (texels along the rim).
        assert!((light.radius.to_degrees() / 2.0 - 1.0).abs() < 0.1, "{}°", light.radius.to_degrees());
        let (whole, rest) = (map_energy(&map), map_energy(&split.residual));
        for k in 0..3 {
            let sum = rest[k] + light.energy[k];
            assert!((sum - whole[k]).abs() <= 1e-9 * whole[k], "{sum} against {}", whole[k]);
        }
        // Nothing of the sun is left: the residual's brightest texel is the sky's.
        let brightest = split.residual.pixels().iter().map(|p| p[2]).fold(0.0f32, f32::max);
        assert_eq!(brightest, 0.6);
    }

    /// No light brighter than the seed threshold, or none allowed: the residual is the map.
    #[test]
    fn a_uniform_sky_or_max_zero_gives_none() {
        let sky = EnvMap::constant([1.0; 3]);
        let none = split(&sky, 4);
        assert!(none.lights.is_empty());
        assert_eq!(none.residual, sky);
        let sun = SunMap::DEFAULT.map().unwrap();
        assert!(split(&sun, 0).lights.is_empty());
        assert_eq!(split(&sun, 0).residual, sun);
    }

    /// A light that wraps around the map's seam is one light; the most energetic come first,
    /// and `max` keeps that many.
    #[test]
    fn lights_across_the_seam_are_one_and_the_brightest_are_kept() {
        let (w, h) = (128u32, 64u32);
        let mut pixels = vec![[0.01f32; 3]; (w * h) as usize];
        for x in [126, 127, 0, 1] {
            pixels[(20 * w + x) as usize] = [6000.0; 3];
        }
        pixels[(40 * w + 30) as usize] = [20000.0; 3];
        pixels[(10 * w + 20) as usize] = [3000.0; 3];
        let map = EnvMap::from_pixels(w, h, pixels).unwrap();
        let all = split(&map, 8);
        assert_eq!(all.lights.len(), 3, "{:?}", all.lights);
        assert_eq!(all.lights.iter().map(|l| l.texels).collect::<Vec<_>>(), [4, 1, 1]);
        assert!(all.lights[1].direction.y < 0.0, "the single 20000 texel lies below the horizon");
        assert_eq!(split(&map, 2).lights.len(), 2);
    }
}
