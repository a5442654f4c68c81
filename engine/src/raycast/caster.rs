//! Casts lists of rays on the GPU through bvh.glsl (shaders-glsl/raycast.comp): the test and
//! benchmark harness of the BVH. Techniques trace their own rays in their own shaders.
use super::GpuBvh;
use crate::backend::{
    Binding, BindingKind, Buffer, BufferDesc, BufferUsage, ComputePipeline, Context, MemoryLocation,
};
use crate::error::{Error, Result};
use crate::layouts::{bytes_of, bytes_of_slice, constants, spirv, CastPush, CastRay, CastResult};
use crate::pass::{FrameExecutor, Pass};

use std::sync::Arc;

/// What to ask of each ray.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Query {
    /// `bvh_closest_hit`: t, instance, triangle and barycentrics.
    ClosestHit,
    /// `bvh_occluded`: instance 0 when occluded, `KAGE_NO_HIT` when not.
    Occluded,
    /// `bvh_occluded_object_space` against one group, rays in its object space; reported as
    /// for [`Query::Occluded`].
    OccludedObjectSpace { instance: u32 },
    /// [`Query::ClosestHit`] plus `bvh_surface` at the hit (the surface members of
    /// `CastResult`, which other queries leave undefined).
    Surface,
    /// Closest hits against one group, rays in its object space, traced by packets of
    /// `constants::BVH_PACKET` consecutive rays from the first one's origin
    /// (`bvh_closest_hits_packet`, the PRT's traversal); reported as for [`Query::ClosestHit`].
    PacketObjectSpace { instance: u32 },
}

/// Rays on the GPU with room for their results.
pub struct GpuRays {
    rays: Buffer,
    results: Buffer,
    count: u32,
}

impl GpuRays {
    pub fn new(ctx: &Arc<Context>, rays: &[CastRay]) -> Result<GpuRays> {
        let count = u32::try_from(rays.len()).ok().filter(|&n| n > 0).ok_or_else(|| {
            Error::InvalidArgument(format!("cannot cast {} rays: give 1 to 2^32 - 1", rays.len()))
        })?;
        Ok(GpuRays {
            rays: Buffer::with_data(ctx, "raycast.rays", BufferUsage::STORAGE, bytes_of_slice(rays))?,
            results: Buffer::new(
                ctx,
                &BufferDesc {
                    name: "raycast.results",
                    size: rays.len() as u64 * size_of::<CastResult>() as u64,
                    usage: BufferUsage::STORAGE | BufferUsage::TRANSFER_SRC,
                    location: MemoryLocation::GpuOnly,
                },
            )?,
            count,
        })
    }

    /// The results of the last cast, one per ray.
    pub fn read(&self) -> Result<Vec<CastResult>> {
        let bytes = self.results.read()?;
        Ok(bytes
            .chunks_exact(size_of::<CastResult>())
            .map(|c| {
                let word =
                    |i: usize| u32::from_ne_bytes([c[4 * i], c[4 * i + 1], c[4 * i + 2], c[4 * i + 3]]);
                let vec4 = |at: usize| std::array::from_fn(|i| f32::from_bits(word(at + i)));
                CastResult {
                    hit: vec4(0),
                    ids: std::array::from_fn(|i| word(4 + i)),
                    position: vec4(8),
                    geometric_normal: vec4(12),
                    shading_normal: vec4(16),
                    albedo: vec4(20),
                }
            })
            .collect())
    }
}

pub struct RayCaster {
    pipeline: ComputePipeline,
    /// The same shader specialized for [`Query::PacketObjectSpace`].
    packet_pipeline: ComputePipeline,
    executor: FrameExecutor,
}

/// Workgroups per dispatch: Vulkan guarantees at least 65535 in x.
const MAX_GROUPS: u32 = 65535;

impl RayCaster {
    pub fn new(ctx: &Arc<Context>) -> Result<RayCaster> {
        let mut kinds = GpuBvh::BINDING_KINDS.to_vec();
        kinds.extend([BindingKind::StorageBuffer, BindingKind::StorageBuffer]);
        let pipeline = |name, packets: bool| {
            ComputePipeline::specialized(
                ctx,
                name,
                spirv::RAYCAST_COMP,
                &kinds,
                size_of::<CastPush>() as u32,
                &[u32::from(packets)],
            )
        };
        Ok(RayCaster {
            pipeline: pipeline("raycast", false)?,
            packet_pipeline: pipeline("raycast_packets", true)?,
            executor: FrameExecutor::new(ctx, "raycast")?,
        })
    }

    /// Casts every ray of `rays` as one pass (several dispatches when the rays exceed one
    /// dispatch's workgroup limit) and returns the pass's GPU time in ms, if the device has
    /// timestamps. Read the results with [`GpuRays::read`].
    pub fn cast(&mut self, bvh: &GpuBvh, rays: &GpuRays, query: Query) -> Result<Option<f64>> {
        let (mode, instance) = match query {
            Query::ClosestHit => (0, 0),
            Query::Occluded => (1, 0),
            Query::OccludedObjectSpace { instance } => (2, instance),
            Query::Surface => (3, 0),
            Query::PacketObjectSpace { instance } => (4, instance),
        };
        let per_dispatch = MAX_GROUPS * constants::RAYCAST_GROUP;
        let pipeline = match query {
            Query::PacketObjectSpace { .. } => &self.packet_pipeline,
            _ => &self.pipeline,
        };
        let timings = self.executor.run(vec![Pass::new("raycast", move |cmd| {
            let mut bindings: Vec<Binding> = bvh.bindings().into();
            bindings.extend([Binding::Storage(&rays.rays), Binding::Storage(&rays.results)]);
            for first in (0..rays.count).step_by(per_dispatch as usize) {
                let push = CastPush { params: [rays.count, mode, instance, first] };
                let n = (rays.count - first).min(per_dispatch);
                pipeline.dispatch(
                    cmd,
                    &bindings,
                    bytes_of(&push),
                    [n.div_ceil(constants::RAYCAST_GROUP), 1, 1],
                );
            }
        })])?;
        Ok(timings[0].gpu_ms)
    }
}
