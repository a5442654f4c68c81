//! The transfer precomputation as compute jobs over the BVH (`shaders-glsl/prt_transfer.comp`,
//! one invocation per vertex). The work is cut into submissions of at most
//! [`RAYS_PER_SUBMISSION`] rays, so that no single submission runs long on a CPU driver and the
//! caller can show progress between them; within a submission, each dispatch casts only
//! [`RAYS_PER_DISPATCH`] rays per vertex (the shader says why).
use std::sync::Arc;
use std::time::Instant;

use super::{buried, mesh_layout, MeshTransfer, PrtParams, TransferSet, Visibility};
use crate::backend::{
    Binding, BindingKind, Buffer, BufferDesc, BufferUsage, ComputePipeline, Context, MemoryLocation,
};
use crate::error::{Error, Result};
use crate::layouts::{bytes_of, bytes_of_slice, constants, spirv, PrtTransferPush, PrtVertex};
use crate::pass::{scaled_to_submissions, FrameExecutor, Pass};
use crate::progress::Progress;

use crate::raycast::{GpuBvh, SceneBvh};
use crate::scene::Scene;

/// Rays per submission: a fraction of a second on lavapipe with two cores, a few milliseconds
/// on a discrete GPU, where the per-submission cost is still small beside it.
pub const RAYS_PER_SUBMISSION: u64 = 1 << 21;

/// Rays per vertex per dispatch, shared by its [`constants::PRT_LANES`] invocations: 32 per
/// invocation, few enough that llvmpipe's limit of 65,535 loop iterations per invocation
/// leaves each ray's traversal about 2,000 iterations.
pub const RAYS_PER_DISPATCH: u32 = 32 * constants::PRT_LANES;

/// Computes the transfer of every vertex of `scene`: builds and uploads the BVH, runs the
/// compute jobs and reads the result back. `progress(done, total)` is called with vertex counts
/// after each submission; when it returns false the work stops with [`Error::Cancelled`].
/// [`TransferSet::seconds`] is the wall-clock time of all of it.
pub fn precompute(
    ctx: &Arc<Context>,
    scene: &Scene,
    params: PrtParams,
    progress: &mut Progress,
) -> Result<TransferSet> {
    let params = params.validated()?;
    let start = Instant::now();
    let layout = mesh_layout(scene);
    let total: usize = layout.iter().map(|m| m.2).sum();
    let (coefficients, seconds, traversal_seconds) = if total == 0 {
        (Vec::new(), start.elapsed().as_secs_f64(), 0.0)
    } else {
        let bvh = GpuBvh::new(ctx, &SceneBvh::build(scene)?)?;
        let mut jobs = Jobs::new(ctx, scene, &bvh, params, total)?;
        let (mut coefficients, back_hits) = jobs.run(progress)?;
        buried::fill(scene, params, &back_hits, &mut coefficients);
        let seconds = start.elapsed().as_secs_f64();
        // Timed after the wall clock stops: the jobs' own dispatches again with tracing off.
        (coefficients, seconds, jobs.traversal_seconds()?)
    };
    let mut rest = coefficients.as_slice();
    let meshes = layout
        .into_iter()
        .map(|(group, mesh, vertices)| {
            let (mine, others) = rest.split_at(vertices * params.coeffs());
            rest = others;
            MeshTransfer { group, mesh, coefficients: mine.to_vec() }
        })
        .collect();
    Ok(TransferSet { params, seconds, traversal_seconds, meshes })
}

/// The transfer jobs of one scene: the shader, its buffers and the dispatches.
struct Jobs<'a> {
    ctx: &'a Arc<Context>,
    bvh: &'a GpuBvh,
    params: PrtParams,
    total: usize,
    batches: Vec<Vec<PrtTransferPush>>,
    vertices: Buffer,
    output: Buffer,
    rays_cast: Buffer,
    back_hits: Buffer,
    executor: FrameExecutor,
    /// Seconds the jobs run so far took from submission to completion.
    job_seconds: f64,
}

impl<'a> Jobs<'a> {
    fn new(
        ctx: &'a Arc<Context>,
        scene: &Scene,
        bvh: &'a GpuBvh,
        params: PrtParams,
        total: usize,
    ) -> Result<Self> {
        let too_many = || {
            Error::InvalidArgument(format!(
                "PRT over {total} vertices × {} coefficients exceeds the 32-bit indices of the \
                 transfer shader",
                params.coeffs()
            ))
        };
        let out_floats = total.checked_mul(params.coeffs()).ok_or_else(too_many)?;
        u32::try_from(out_floats).map_err(|_| too_many())?;

        let vertices: Vec<PrtVertex> = scene
            .meshes()
            .flat_map(|(_, mesh)| mesh.positions.iter().zip(&mesh.normals))
            .map(|(p, n)| PrtVertex { position: [p[0], p[1], p[2], 0.0], normal: [n[0], n[1], n[2], 0.0] })
            .collect();
        let storage = BufferUsage::STORAGE;
        let readback = |name, size| {
            Buffer::new(
                ctx,
                &BufferDesc {
                    name,
                    size,
                    usage: storage | BufferUsage::TRANSFER_SRC,
                    location: MemoryLocation::GpuOnly,
                },
            )
        };
        Ok(Jobs {
            ctx,
            bvh,
            params,
            total,
            batches: submissions(&mesh_layout(scene), params),
            vertices: Buffer::with_data(ctx, "prt_vertices", storage, bytes_of_slice(&vertices))?,
            output: readback("prt_transfer", out_floats as u64 * 4)?,
            rays_cast: readback("prt_rays_cast", total as u64 * 4)?,
            back_hits: readback("prt_back_hits", total as u64 * 4)?,
            executor: FrameExecutor::new(ctx, "prt_precompute")?,
            job_seconds: 0.0,
        })
    }

    /// The transfer shader, tracing its rays or (`trace` false) taking every ray as a miss.
    fn pipeline(&self, trace: bool) -> Result<ComputePipeline> {
        let mut kinds = GpuBvh::BINDING_KINDS.to_vec();
        kinds.extend([BindingKind::StorageBuffer; 4]);
        ComputePipeline::specialized(
            self.ctx,
            if trace { "prt_transfer" } else { "prt_transfer_untraced" },
            spirv::PRT_TRANSFER_COMP,
            &kinds,
            size_of::<PrtTransferPush>() as u32,
            &[
                self.params.coeffs() as u32,
                u32::from(trace),
                u32::from(self.params.visibility == Visibility::Scene),
            ],
        )
    }

    /// Casts `rays` rays per vertex of `batch`, from ray `first` on, as dispatches of at most
    /// [`RAYS_PER_DISPATCH`] rays, and waits for them; returns the seconds from submission to
    /// completion, timed on the host (a CPU driver's timestamps around compute work are not
    /// reliable, see vendor-notes.md).
    fn submit(
        &mut self,
        pipeline: &ComputePipeline,
        batch: &[PrtTransferPush],
        first: u32,
        rays: u32,
    ) -> Result<f64> {
        let mut bindings: Vec<Binding> = self.bvh.bindings().into_iter().collect();
        bindings.extend([
            Binding::Storage(&self.vertices),
            Binding::Storage(&self.output),
            Binding::Storage(&self.rays_cast),
            Binding::Storage(&self.back_hits),
        ]);
        let ctx = self.ctx;
        let pass = Pass::new("prt_transfer", |cmd| {
            for first_ray in (first..first + rays).step_by(RAYS_PER_DISPATCH as usize) {
                // Each dispatch adds to the sums the previous one wrote.
                if first_ray > first {
                    ctx.full_barrier(cmd);
                }
                let count = RAYS_PER_DISPATCH.min(first + rays - first_ray);
                for push in batch {
                    let push = PrtTransferPush { params: [first_ray, count, 0, 0], ..*push };
                    let groups = push.range[1].div_ceil(constants::PRT_GROUP / constants::PRT_LANES);
                    pipeline.dispatch(cmd, &bindings, bytes_of(&push), [groups, 1, 1]);
                }
            }
        });
        let start = Instant::now();
        self.executor.run(vec![pass])?;
        Ok(start.elapsed().as_secs_f64())
    }

    /// Runs the shader over every vertex; returns the coefficients in scene order and how many
    /// of each vertex's rays ended on the back of a surface.
    fn run(&mut self, progress: &mut Progress) -> Result<(Vec<f32>, Vec<u32>)> {
        let (total, rays) = (self.total, self.params.rays);
        let pipeline = self.pipeline(true)?;
        let mut done = 0;
        let cancelled = || Error::Cancelled("the PRT precomputation");
        if !progress(done, total) {
            return Err(cancelled());
        }
        for batch in std::mem::take(&mut self.batches) {
            self.job_seconds += self.submit(&pipeline, &batch, 0, rays)?;
            done += batch.iter().map(|p| p.range[1] as usize).sum::<usize>();
            self.batches.push(batch);
            if !progress(done, total) {
                return Err(cancelled());
            }
        }
        if let Some((vertex, &got)) =
            words(self.rays_cast.read()?).iter().enumerate().find(|(_, n)| **n != rays)
        {
            return Err(Error::Unsupported(format!(
                "shader loops as long as the PRT needs: the driver stopped after {got} of {rays} rays \
                 for vertex {vertex}, so the transfer would be wrong"
            )));
        }
        let bytes = self.output.read()?;
        let coefficients =
            bytes.chunks_exact(4).map(|c| f32::from_ne_bytes([c[0], c[1], c[2], c[3]])).collect();
        Ok((coefficients, words(self.back_hits.read()?)))
    }

    /// The seconds the jobs spent tracing rays (see [`TransferSet::traversal_seconds`]): the
    /// jobs' time less that of the same submissions with tracing off, each timed with one
    /// dispatch round (`RAYS_PER_DISPATCH` rays per vertex) and with two, so that a
    /// submission's own cost counts once per batch as the jobs paid it, not once per round
    /// ([`scaled_to_submissions`]). Overwrites the results, which [`Jobs::run`] has read.
    fn traversal_seconds(mut self) -> Result<f32> {
        let rounds = self.params.rays.div_ceil(RAYS_PER_DISPATCH);
        let round = self.params.rays.min(RAYS_PER_DISPATCH);
        let pipeline = self.pipeline(false)?;
        let batches = std::mem::take(&mut self.batches);
        // An untimed warm-up first (on a CPU driver, the shader's compilation).
        self.submit(&pipeline, &batches[0], 0, round)?;
        let mut untraced = 0.0;
        for batch in &batches {
            let one = self.submit(&pipeline, batch, 0, round)?;
            untraced += match rounds {
                1 => one,
                _ => scaled_to_submissions(
                    one,
                    self.submit(&pipeline, batch, 0, 2 * round)?,
                    2,
                    rounds,
                    rounds,
                ),
            };
        }
        Ok((self.job_seconds - untraced).max(0.0) as f32)
    }
}

fn words(bytes: Vec<u8>) -> Vec<u32> {
    bytes.chunks_exact(4).map(|c| u32::from_ne_bytes([c[0], c[1], c[2], c[3]])).collect()
}

/// Splits the meshes into dispatches (a dispatch never spans two meshes: the group is a push
/// constant) and packs consecutive dispatches into submissions of at most
/// [`RAYS_PER_SUBMISSION`] rays; a vertex's rays are never split.
fn submissions(layout: &[(usize, usize, usize)], params: PrtParams) -> Vec<Vec<PrtTransferPush>> {
    let budget = (RAYS_PER_SUBMISSION / u64::from(params.rays)).max(1) as usize;
    let mut out = Vec::new();
    let mut batch = Vec::new();
    let (mut used, mut first) = (0, 0);
    for &(group, _, vertices) in layout {
        let mut left = vertices;
        while left > 0 {
            let count = left.min(budget - used);
            batch.push(PrtTransferPush {
                range: [first as u32, count as u32, group as u32, params.rays],
                // The ray range is filled in per dispatch.
                params: [0; 4],
            });
            first += count;
            left -= count;
            used += count;
            if used == budget {
                out.push(std::mem::take(&mut batch));
                used = 0;
            }
        }
    }
    if !batch.is_empty() {
        out.push(batch);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn submissions_cover_every_vertex_once_within_budget() {
        let params = PrtParams { bands: 3, rays: (RAYS_PER_SUBMISSION / 100) as u32, ..PrtParams::DEFAULT };
        let layout = [(0, 0, 250), (0, 1, 30), (1, 0, 5), (2, 0, 101)];
        let batches = submissions(&layout, params);
        let mut next = 0;
        for batch in &batches {
            let rays: u64 = batch.iter().map(|p| u64::from(p.range[1]) * u64::from(params.rays)).sum();
            assert!(rays <= RAYS_PER_SUBMISSION, "{rays} rays in one submission");
            for push in batch {
                assert_eq!(push.range[0], next, "dispatches are contiguous");
                next += push.range[1];
            }
        }
        assert_eq!(next, 386);
        // The group of each dispatch is its mesh's.
        let groups: Vec<u32> = batches.iter().flatten().map(|p| p.range[2]).collect();
        assert_eq!(groups.first(), Some(&0));
        assert_eq!(groups.last(), Some(&2));
    }

    #[test]
    fn more_rays_than_the_budget_still_make_progress() {
        let params = PrtParams { bands: 2, rays: (RAYS_PER_SUBMISSION * 2) as u32, ..PrtParams::DEFAULT };
        let batches = submissions(&[(0, 0, 3)], params);
        assert_eq!(batches.len(), 3);
        assert!(batches.iter().all(|b| b.len() == 1 && b[0].range[1] == 1));
    }
}
