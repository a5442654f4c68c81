//! The environment map on the GPU, or a table over directions laid out like it (the irradiance
//! table): an RGBA32F image (alpha unused) and a sampler that wraps in longitude and clamps at
//! the poles.
use crate::backend::{Context, Edge, Format, Image, ImageDesc, ImageUsage, Sampler};
use crate::error::Result;
use crate::scene::EnvMap;
use std::sync::Arc;

pub struct GpuEnvironment {
    pub image: Image,
    pub sampler: Sampler,
}

impl GpuEnvironment {
    pub fn new(ctx: &Arc<Context>, map: &EnvMap) -> Result<GpuEnvironment> {
        GpuEnvironment::table(ctx, "environment", map.width(), map.height(), map.pixels())
    }

    /// `width`×`height` RGB texels, row 0 at the top.
    pub fn table(
        ctx: &Arc<Context>,
        name: &str,
        width: u32,
        height: u32,
        pixels: &[[f32; 3]],
    ) -> Result<GpuEnvironment> {
        let image = Image::new(
            ctx,
            &ImageDesc {
                name,
                width,
                height,
                layers: 1,
                levels: 1,
                array: false,
                format: Format::RGBA32_FLOAT,
                usage: ImageUsage::SAMPLED | ImageUsage::TRANSFER_DST,
            },
        )?;
        // Row by row: the RGBA copy of a large map never exists whole on the host.
        image.upload_rows(|first_row, texels| {
            let start = first_row as usize * width as usize;
            for (texel, p) in texels.chunks_exact_mut(16).zip(&pixels[start..]) {
                for (bytes, v) in texel.chunks_exact_mut(4).zip([p[0], p[1], p[2], 0.0]) {
                    bytes.copy_from_slice(&v.to_ne_bytes());
                }
            }
        })?;
        let sampler = Sampler::new(ctx, &format!("{name}.sampler"), true, Edge::Repeat, Edge::Clamp)?;
        Ok(GpuEnvironment { image, sampler })
    }
}
