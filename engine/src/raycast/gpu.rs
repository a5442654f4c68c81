//! The scene BVH in device-local storage buffers, bound as bvh.glsl declares them.
use super::SceneBvh;
use crate::backend::{Binding, BindingKind, Buffer, BufferUsage, Context};
use crate::error::{Error, Result};
use crate::layouts::{bytes_of_slice, constants, Pod};

use std::sync::Arc;

const BINDINGS: usize = constants::BVH_BINDINGS as usize;

pub struct GpuBvh {
    blas_pairs: Buffer,
    tlas_nodes: Buffer,
    instances: Buffer,
    triangles: Buffer,
    attributes: Buffer,
    albedo_maps: Buffer,
    albedo_texels: Buffer,
}

impl GpuBvh {
    /// What [`GpuBvh::bindings`] gives, for a pipeline's binding list (these come first).
    pub const BINDING_KINDS: [BindingKind; BINDINGS] = [BindingKind::StorageBuffer; BINDINGS];

    pub fn new(ctx: &Arc<Context>, bvh: &SceneBvh) -> Result<GpuBvh> {
        Ok(GpuBvh {
            blas_pairs: upload(ctx, "bvh.blas_pairs", &bvh.blas_pairs)?,
            tlas_nodes: upload(ctx, "bvh.tlas_nodes", &bvh.tlas_nodes)?,
            instances: upload(ctx, "bvh.instances", &bvh.instances)?,
            triangles: upload(ctx, "bvh.triangles", &bvh.triangles)?,
            attributes: upload(ctx, "bvh.attributes", &bvh.attributes)?,
            albedo_maps: upload(ctx, "bvh.albedo_maps", &bvh.albedo_maps)?,
            albedo_texels: upload(ctx, "bvh.albedo_texels", &bvh.albedo_texels)?,
        })
    }

    /// Re-uploads what [`SceneBvh::set_transform`] changes: the instances and the top level.
    /// `bvh` must be the one this was created from (or one built from the same scene).
    pub fn update(&mut self, bvh: &SceneBvh) -> Result<()> {
        for (buffer, bytes) in [
            (&self.instances, bytes_of_slice(&bvh.instances)),
            (&self.tlas_nodes, bytes_of_slice(&bvh.tlas_nodes)),
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
            Binding::Storage(&self.blas_pairs),
            Binding::Storage(&self.tlas_nodes),
            Binding::Storage(&self.instances),
            Binding::Storage(&self.triangles),
            Binding::Storage(&self.attributes),
            Binding::Storage(&self.albedo_maps),
            Binding::Storage(&self.albedo_texels),
        ]
    }

    /// The bottom-level pair buffer, for checks that it stays untouched by updates.
    pub fn blas_node_buffer(&self) -> &Buffer {
        &self.blas_pairs
    }
}

/// An empty array (a scene without triangles or groups) still needs a buffer to bind; its one
/// zeroed element is never read, because every ray misses the empty root boxes.
fn upload<T: Pod + Default>(ctx: &Arc<Context>, name: &str, items: &[T]) -> Result<Buffer> {
    let placeholder = [T::default()];
    let items = if items.is_empty() { &placeholder[..] } else { items };
    Buffer::with_data(ctx, name, BufferUsage::STORAGE | BufferUsage::TRANSFER_SRC, bytes_of_slice(items))
}
