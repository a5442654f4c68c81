//! The scene BVH in device-local buffers, bound as bvh.glsl declares them: what the traversal
//! and every hit read (nodes, triangles, attributes) as texel buffers, the albedo maps, which
//! only a textured hit reads, as storage buffers.
use super::SceneBvh;
use crate::backend::{Binding, BindingKind, Buffer, BufferUsage, Context, TexelBuffer};
use crate::error::{Error, Result};
use crate::layouts::{bytes_of_slice, constants, Pod};

use std::sync::Arc;

const BINDINGS: usize = constants::BVH_BINDINGS as usize;

pub struct GpuBvh {
    blas_pairs: TexelBuffer,
    tlas_nodes: TexelBuffer,
    instances: TexelBuffer,
    triangles: TexelBuffer,
    attributes: TexelBuffer,
    albedo_maps: Buffer,
    albedo_texels: Buffer,
}

impl GpuBvh {
    /// What [`GpuBvh::bindings`] gives, for a pipeline's binding list (these come first).
    pub const BINDING_KINDS: [BindingKind; BINDINGS] = [
        BindingKind::TexelBuffer,
        BindingKind::TexelBuffer,
        BindingKind::TexelBuffer,
        BindingKind::TexelBuffer,
        BindingKind::TexelBuffer,
        BindingKind::StorageBuffer,
        BindingKind::StorageBuffer,
    ];

    pub fn new(ctx: &Arc<Context>, bvh: &SceneBvh) -> Result<GpuBvh> {
        Ok(GpuBvh {
            blas_pairs: upload_texels(ctx, "bvh.blas_pairs", &bvh.blas_pairs)?,
            tlas_nodes: upload_texels(ctx, "bvh.tlas_nodes", &bvh.tlas_nodes)?,
            instances: upload_texels(ctx, "bvh.instances", &bvh.instances)?,
            triangles: upload_texels(ctx, "bvh.triangles", &bvh.triangles)?,
            attributes: upload_texels(ctx, "bvh.attributes", &bvh.attributes)?,
            albedo_maps: upload(ctx, "bvh.albedo_maps", &bvh.albedo_maps)?,
            albedo_texels: upload(ctx, "bvh.albedo_texels", &bvh.albedo_texels)?,
        })
    }

    /// Re-uploads what [`SceneBvh::set_transform`] changes: the instances and the top level.
    /// `bvh` must be the one this was created from (or one built from the same scene).
    pub fn update(&mut self, bvh: &SceneBvh) -> Result<()> {
        for (buffer, bytes) in [
            (self.instances.buffer(), bytes_of_slice(&bvh.instances)),
            (self.tlas_nodes.buffer(), bytes_of_slice(&bvh.tlas_nodes)),
        ] {
            if bytes.len() as u64 != buffer.size() && !bytes.is_empty() {
                return Err(Error::InvalidArgument(format!(
                    "GpuBvh::update: {} holds {} bytes but the BVH has {}; was it built from another scene?",
                    buffer.name(),
                    buffer.size(),
                    bytes.len()
                )));
            }
            if !bytes.is_empty() {
                buffer.upload(bytes)?;
            }
        }
        Ok(())
    }

    /// The buffers in binding order 0 .. KAGE_BVH_BINDINGS - 1.
    pub fn bindings(&self) -> [Binding<'_>; BINDINGS] {
        [
            Binding::Texel(&self.blas_pairs),
            Binding::Texel(&self.tlas_nodes),
            Binding::Texel(&self.instances),
            Binding::Texel(&self.triangles),
            Binding::Texel(&self.attributes),
            Binding::Storage(&self.albedo_maps),
            Binding::Storage(&self.albedo_texels),
        ]
    }

    /// The bottom-level pair buffer, for checks that it stays untouched by updates.
    pub fn blas_node_buffer(&self) -> &Buffer {
        self.blas_pairs.buffer()
    }
}

/// An empty array (a scene without triangles or groups) still needs a buffer to bind; its one
/// zeroed element is never read, because every ray misses the empty root boxes.
fn upload<T: Pod + Default>(ctx: &Arc<Context>, name: &str, items: &[T]) -> Result<Buffer> {
    Buffer::with_data(
        ctx,
        name,
        BufferUsage::STORAGE | BufferUsage::TRANSFER_SRC,
        bytes_of_slice(&one_at_least(items)),
    )
}

/// The same as texels (`T` is a whole number of them: the test below).
fn upload_texels<T: Pod + Default>(ctx: &Arc<Context>, name: &str, items: &[T]) -> Result<TexelBuffer> {
    TexelBuffer::with_data(ctx, name, bytes_of_slice(&one_at_least(items)))
}

fn one_at_least<T: Pod + Default>(items: &[T]) -> std::borrow::Cow<'_, [T]> {
    if items.is_empty() {
        vec![T::default()].into()
    } else {
        items.into()
    }
}

#[cfg(test)]
mod tests {
    use crate::layouts::{constants, BvhInstance, BvhNode, BvhPair, BvhTriangle, BvhTriangleAttributes};
    use std::mem::{offset_of, size_of};

    /// bvh.glsl reads each record as this many 16-byte texels, the instance's fields at fixed
    /// texels: the structs must be exactly that.
    #[test]
    fn records_are_whole_texels_as_the_shaders_read_them() {
        const TEXEL: usize = 16;
        assert_eq!(size_of::<BvhPair>(), constants::BVH_PAIR_TEXELS as usize * TEXEL);
        assert_eq!(size_of::<BvhNode>(), constants::BVH_NODE_TEXELS as usize * TEXEL);
        assert_eq!(size_of::<BvhTriangle>(), constants::BVH_TRIANGLE_TEXELS as usize * TEXEL);
        assert_eq!(size_of::<BvhInstance>(), constants::BVH_INSTANCE_TEXELS as usize * TEXEL);
        assert_eq!(size_of::<BvhTriangleAttributes>(), constants::BVH_ATTRIBUTE_TEXELS as usize * TEXEL);
        assert_eq!(offset_of!(BvhInstance, object_to_world), 0);
        assert_eq!(offset_of!(BvhInstance, world_to_object), 4 * TEXEL);
        assert_eq!(offset_of!(BvhInstance, info), 8 * TEXEL);
    }
}
