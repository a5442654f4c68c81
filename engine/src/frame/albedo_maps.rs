//! The scene's albedo maps on the GPU: one sRGB image with its mipmaps and one sampler per map
//! (meshes that share a map share them), and map 0, a white texel, for meshes without one. Lit
//! pipelines end their bindings with the mesh's map (`albedo_map.glsl`), pushed per draw.
use crate::backend::{Binding, Context, Edge, Format, Image, ImageDesc, ImageUsage, Sampler, SamplerDesc};
use crate::error::Result;
use crate::scene::albedo_map::{srgb_to_linear, AlbedoMap, Filter, Wrap};
use crate::scene::Scene;
use std::sync::Arc;

struct GpuAlbedoMap {
    image: Image,
    sampler: Sampler,
}

pub struct GpuAlbedoMaps {
    maps: Vec<GpuAlbedoMap>,
}

impl GpuAlbedoMaps {
    /// The maps of `scene`'s meshes and, per mesh in group order, the index of its map (0: the
    /// white texel).
    pub fn new(ctx: &Arc<Context>, scene: &Scene) -> Result<(GpuAlbedoMaps, Vec<usize>)> {
        let white = AlbedoMap {
            name: "white".into(),
            width: 1,
            height: 1,
            texels: vec![[255; 4]],
            wrap: [Wrap::Repeat; 2],
            filter: Filter { magnify_linear: false, minify_linear: false, mipmaps: None },
        };
        let mut maps = vec![upload(ctx, &white)?];
        let mut uploaded: Vec<*const AlbedoMap> = Vec::new();
        let mut indices = Vec::new();
        for mesh in scene.groups.iter().flat_map(|g| &g.meshes) {
            let Some(texturing) = &mesh.texturing else {
                indices.push(0);
                continue;
            };
            let key = Arc::as_ptr(&texturing.map);
            let index = match uploaded.iter().position(|m| *m == key) {
                Some(at) => at + 1,
                None => {
                    maps.push(upload(ctx, &texturing.map)?);
                    uploaded.push(key);
                    uploaded.len()
                }
            };
            indices.push(index);
        }
        Ok((GpuAlbedoMaps { maps }, indices))
    }

    /// Map `index` (of [`GpuAlbedoMaps::new`]'s list) for a lit pipeline's last binding.
    pub fn binding(&self, index: usize) -> Binding<'_> {
        let map = &self.maps[index];
        Binding::Sampled(&map.image, &map.sampler)
    }

    /// Device bytes of the maps' images.
    pub fn bytes(&self) -> u64 {
        self.maps.iter().map(|m| m.image.byte_size()).sum()
    }
}

fn upload(ctx: &Arc<Context>, map: &AlbedoMap) -> Result<GpuAlbedoMap> {
    let levels = if map.filter.mipmaps.is_some() { mipmaps(map) } else { vec![map.texels.clone()] };
    let name = format!("albedo_map.{}", map.name);
    let image = Image::new(
        ctx,
        &ImageDesc {
            name: &name,
            width: map.width,
            height: map.height,
            layers: 1,
            levels: levels.len() as u32,
            array: false,
            format: Format::RGBA8_SRGB,
            usage: ImageUsage::SAMPLED | ImageUsage::TRANSFER_DST,
        },
    )?;
    image.upload(&levels.iter().flatten().flatten().copied().collect::<Vec<u8>>())?;
    let edge = |wrap| match wrap {
        Wrap::Repeat => Edge::Repeat,
        Wrap::MirroredRepeat => Edge::Mirror,
        Wrap::ClampToEdge => Edge::Clamp,
    };
    let filter = map.filter;
    let desc = SamplerDesc {
        magnify_linear: filter.magnify_linear,
        minify_linear: filter.minify_linear,
        mipmaps: filter.mipmaps,
        u: edge(map.wrap[0]),
        v: edge(map.wrap[1]),
    };
    let sampler = Sampler::with_desc(ctx, &format!("{name}.sampler"), &desc)?;
    Ok(GpuAlbedoMap { image, sampler })
}

/// Every mipmap level of the map, level 0 first, down to 1×1, each side halved and rounded down
/// as Vulkan sizes levels: each texel the mean, in linear colour, of the 2×2 texels below it
/// (an odd side's last row or column is left out; a side of 1 repeats its texel), encoded as
/// sRGB again.
fn mipmaps(map: &AlbedoMap) -> Vec<Vec<[u8; 4]>> {
    let mut levels = vec![map.texels.clone()];
    let mut linear: Vec<[f32; 4]> = map
        .texels
        .iter()
        .map(|t| [srgb_to_linear(t[0]), srgb_to_linear(t[1]), srgb_to_linear(t[2]), f32::from(t[3]) / 255.0])
        .collect();
    let (mut width, mut height) = (map.width as usize, map.height as usize);
    while width > 1 || height > 1 {
        let (w, h) = ((width / 2).max(1), (height / 2).max(1));
        let mut next = Vec::with_capacity(w * h);
        for y in 0..h {
            for x in 0..w {
                let mut sum = [0.0f32; 4];
                for (dx, dy) in [(0, 0), (1, 0), (0, 1), (1, 1)] {
                    let (sx, sy) = ((2 * x + dx).min(width - 1), (2 * y + dy).min(height - 1));
                    let t = linear[sy * width + sx];
                    sum.iter_mut().zip(t).for_each(|(s, c)| *s += c / 4.0);
                }
                next.push(sum);
            }
        }
        levels.push(next.iter().map(encode).collect());
        (linear, width, height) = (next, w, h);
    }
    levels
}

fn encode(linear: &[f32; 4]) -> [u8; 4] {
    let byte = |c: f32| (c.clamp(0.0, 1.0) * 255.0).round() as u8;
    let srgb = |c: f32| byte(crate::imageio::srgb_oetf(c));
    [srgb(linear[0]), srgb(linear[1]), srgb(linear[2]), byte(linear[3])]
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Levels halve down to 1×1 (odd sides rounded down), each the linear mean of its 2×2 block:
    /// black and white average to linear 0.5, sRGB 188, not 128.
    #[test]
    fn mipmaps_average_in_linear_colour() {
        let texels = [[0, 0, 0, 255], [255, 255, 255, 255]].repeat(3);
        let map = AlbedoMap::new("t", 3, 2, texels, [Wrap::Repeat; 2], Filter::SMOOTH).unwrap();
        let levels = mipmaps(&map);
        assert_eq!(levels.iter().map(Vec::len).collect::<Vec<_>>(), vec![6, 1]);
        assert_eq!(levels[1][0], [188, 188, 188, 255]);
    }
}
