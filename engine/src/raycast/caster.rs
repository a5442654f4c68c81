//! Casts lists of rays on the GPU through bvh.glsl (shaders-glsl/raycast.comp): the test and
//! benchmark harness of the BVH. Techniques trace their own rays in their own shaders.
use super::GpuBvh;
use crate::backend::{
    Binding, BindingKind, Buffer, BufferDesc, BufferUsage, ComputePipeline, Context, MemoryLocation,
    TexelBuffer,
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
    /// Two texels per ray, as raycast.comp reads them.
    rays: TexelBuffer,
    results: Buffer,
    count: u32,
}

impl GpuRays {
    pub fn new(ctx: &Arc<Context>, rays: &[CastRay]) -> Result<GpuRays> {
        let count = u32::try_from(rays.len()).ok().filter(|&n| n > 0).ok_or_else(|| {
            Error::InvalidArgument(format!("cannot cast {} rays: give 1 to 2^32 - 1", rays.len()))
        })?;
        Ok(GpuRays {
            rays: TexelBuffer::with_data(ctx, "raycast.rays", bytes_of_slice(rays))?,
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
    ctx: Arc<Context>,
    /// One pipeline per query (the shader's specialization constant), each made at its first
    /// cast, indexed by the query's `constants::CAST_*` value.
    pipelines: [Option<ComputePipeline>; QUERIES],
    executor: FrameExecutor,
}

/// Workgroups per dispatch: Vulkan guarantees at least 65535 in x.
const MAX_GROUPS: u32 = 65535;

/// The queries of raycast.comp (`constants::CAST_*` run from 0 up to this, exclusive).
const QUERIES: usize = constants::CAST_PACKET_OBJECT_SPACE as usize + 1;

impl Query {
    /// The shader's query (`constants::CAST_*`), its pipeline's name and the group an
    /// object-space query casts against.
    fn shader_query(self) -> (u32, &'static str, u32) {
        match self {
            Query::ClosestHit => (constants::CAST_CLOSEST, "raycast.closest_hit", 0),
            Query::Occluded => (constants::CAST_OCCLUDED, "raycast.occluded", 0),
            Query::OccludedObjectSpace { instance } => {
                (constants::CAST_OCCLUDED_OBJECT_SPACE, "raycast.occluded_object_space", instance)
            }
            Query::Surface => (constants::CAST_SURFACE, "raycast.surface", 0),
            Query::PacketObjectSpace { instance } => {
                (constants::CAST_PACKET_OBJECT_SPACE, "raycast.packet_object_space", instance)
            }
        }
    }
}

impl RayCaster {
    pub fn new(ctx: &Arc<Context>) -> Result<RayCaster> {
        Ok(RayCaster {
            ctx: ctx.clone(),
            pipelines: Default::default(),
            executor: FrameExecutor::new(ctx, "raycast")?,
        })
    }

    /// Casts every ray of `rays` as one pass (several dispatches when the rays exceed one
    /// dispatch's workgroup limit) and returns the pass's GPU time in ms, if the device has
    /// timestamps. Read the results with [`GpuRays::read`].
    pub fn cast(&mut self, bvh: &GpuBvh, rays: &GpuRays, query: Query) -> Result<Option<f64>> {
        let (mode, name, instance) = query.shader_query();
        let pipeline = match &mut self.pipelines[mode as usize] {
            Some(pipeline) => pipeline,
            slot => {
                let mut kinds = GpuBvh::BINDING_KINDS.to_vec();
                kinds.extend([BindingKind::TexelBuffer, BindingKind::StorageBuffer]);
                slot.insert(ComputePipeline::specialized(
                    &self.ctx,
                    name,
                    spirv::RAYCAST_COMP,
                    &kinds,
                    size_of::<CastPush>() as u32,
                    &[mode],
                )?)
            }
        };
        let pipeline = &*pipeline;
        let per_dispatch = MAX_GROUPS * constants::RAYCAST_GROUP;
        let timings = self.executor.run(vec![Pass::new("raycast", move |cmd| {
            let mut bindings: Vec<Binding> = bvh.bindings().into();
            bindings.extend([Binding::Texel(&rays.rays), Binding::Storage(&rays.results)]);
            for first in (0..rays.count).step_by(per_dispatch as usize) {
                let push = CastPush { params: [rays.count, 0, instance, first] };
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
