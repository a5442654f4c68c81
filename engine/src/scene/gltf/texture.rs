//! A glTF material's `baseColorTexture` as an albedo map: its image (PNG or JPEG, decoded into
//! 8-bit RGBA as an OBJ's map is), its sampler's wrap and filter modes, its texture coordinate set and
//! its `KHR_texture_transform` baked into the coordinates.
use super::super::albedo_map::{AlbedoMap, Filter, Texturing, Wrap};
use gltf::texture::{MagFilter, MinFilter, WrappingMode};
use std::collections::HashMap;
use std::sync::Arc;

/// The albedo maps read so far, by (image, sampler): primitives that share a texture share
/// one map (and one GPU image).
pub struct AlbedoMaps<'a> {
    /// Each image's encoded bytes, decoded when a texture first uses it.
    images: &'a [Vec<u8>],
    read: HashMap<(usize, Option<usize>), Arc<AlbedoMap>>,
}

impl<'a> AlbedoMaps<'a> {
    pub fn new(images: &'a [Vec<u8>]) -> AlbedoMaps<'a> {
        AlbedoMaps { images, read: HashMap::new() }
    }

    /// The base colour texture of `primitive`'s material with its texture coordinates (`count`
    /// of them, one per position, `tex_coords(set)` reads a set), or `None` where the material
    /// has none.
    pub fn texturing(
        &mut self,
        primitive: &gltf::Primitive,
        tex_coords: impl Fn(u32) -> Option<Vec<[f32; 2]>>,
        count: usize,
    ) -> Result<Option<Texturing>, String> {
        let Some(info) = primitive.material().pbr_metallic_roughness().base_color_texture() else {
            return Ok(None);
        };
        let transform = info.texture_transform();
        let set = transform.as_ref().and_then(|t| t.tex_coord()).unwrap_or(info.tex_coord());
        let uvs = tex_coords(set)
            .ok_or_else(|| format!("its base colour texture reads TEXCOORD_{set}, which it does not have"))?;
        if uvs.len() != count {
            return Err(format!("TEXCOORD_{set} has {} coordinates for {count} positions", uvs.len()));
        }
        let uvs = match transform {
            Some(t) => {
                let ([ox, oy], [sx, sy], (sin, cos)) = (t.offset(), t.scale(), t.rotation().sin_cos());
                uvs.into_iter()
                    .map(|[u, v]| [cos * sx * u + sin * sy * v + ox, -sin * sx * u + cos * sy * v + oy])
                    .collect()
            }
            None => uvs,
        };
        let texture = info.texture();
        let key = (texture.source().index(), texture.sampler().index());
        let map = match self.read.get(&key) {
            Some(map) => map.clone(),
            None => {
                let map = Arc::new(self.map(&texture)?);
                self.read.insert(key, map.clone());
                map
            }
        };
        Ok(Some(Texturing { map, uvs }))
    }

    fn map(&self, texture: &gltf::Texture) -> Result<AlbedoMap, String> {
        let index = texture.source().index();
        let name = texture.source().name().map_or_else(|| format!("image {index}"), str::to_owned);
        let image = self.images.get(index).ok_or_else(|| format!("its base colour {name} is missing"))?;
        let (width, height, texels) =
            super::super::albedo_map::decode(image).map_err(|e| format!("its base colour {name}: {e}"))?;
        let sampler = texture.sampler();
        let wrap = |mode| match mode {
            WrappingMode::Repeat => Wrap::Repeat,
            WrappingMode::MirroredRepeat => Wrap::MirroredRepeat,
            WrappingMode::ClampToEdge => Wrap::ClampToEdge,
        };
        let filter = Filter {
            magnify_linear: sampler.mag_filter() != Some(MagFilter::Nearest),
            minify_linear: !matches!(
                sampler.min_filter(),
                Some(MinFilter::Nearest | MinFilter::NearestMipmapNearest | MinFilter::NearestMipmapLinear)
            ),
            mipmaps: match sampler.min_filter() {
                Some(MinFilter::Nearest | MinFilter::Linear) => None,
                Some(MinFilter::NearestMipmapNearest | MinFilter::LinearMipmapNearest) => Some(false),
                _ => Some(true),
            },
        };
        AlbedoMap::new(name, width, height, texels, [wrap(sampler.wrap_s()), wrap(sampler.wrap_t())], filter)
            .map_err(|e| e.to_string())
    }
}
