//! SH projection on the GPU, in two compute passes: `sh_project` (one partial sum per workgroup
//! of texels, with exact texel solid angles) and `sh_reduce` (the partials added in a fixed
//! order). One projection serves any image of radiance whose texels map to directions: the
//! environment map (equirectangular; run when the environment changes, not every frame) and a
//! light probe's cube map ([`Mapping::Cube`]).
use super::environment::GpuEnvironment;
use crate::backend::{
    Binding, BindingKind, Buffer, BufferDesc, BufferUsage, ComputePipeline, Context, Image, MemoryLocation,
    Sampler,
};
use crate::error::Result;
use crate::layouts::{bytes_of, constants, spirv, ShCoeffs, ShProjectPush};
use crate::pass::{FrameExecutor, Pass};
use crate::scene::EnvMap;
use crate::sh::ShRgb9;
use std::sync::Arc;

/// How texels map to directions (shaders-glsl/sh_project.comp).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Mapping {
    /// A `width`×`height` equirectangular environment map (the scene module's convention).
    Equirect { width: u32, height: u32 },
    /// A cube map of `side`² texels a face, the six faces stacked top to bottom in one
    /// `side`×6·`side` image (shaders-glsl/include/cube.glsl).
    Cube { side: u32 },
}

impl Mapping {
    fn size(self) -> [u32; 2] {
        match self {
            Mapping::Equirect { width, height } => [width, height],
            Mapping::Cube { side } => [side, 6 * side],
        }
    }

    /// Cells per side of a texel that `sh_project.comp` integrates over (it computes the same).
    fn subdivisions(self) -> u32 {
        match self {
            Mapping::Equirect { height, .. } => crate::sh::equirect_subdivisions(height),
            Mapping::Cube { .. } => 1,
        }
    }

    fn id(self) -> u32 {
        match self {
            Mapping::Equirect { .. } => constants::SH_MAPPING_EQUIRECT,
            Mapping::Cube { .. } => constants::SH_MAPPING_CUBE,
        }
    }
}

/// The debug names of one projection's buffers.
#[derive(Clone, Copy, Debug)]
pub struct ProjectionNames {
    /// The partial sums (between the two passes).
    pub partials: &'static str,
    /// The result (the second pass's output).
    pub result: &'static str,
}

/// The environment's projection as the renderer runs it.
pub const ENVIRONMENT: ProjectionNames = ProjectionNames { partials: "sh_partials", result: "env_sh" };

pub struct ShProjection {
    project: ComputePipeline,
    reduce: ComputePipeline,
    partials: Buffer,
    /// The result: one `ShCoeffs` (9 radiance coefficients per channel).
    pub coefficients: Buffer,
    groups: u32,
    mapping: Mapping,
}

impl ShProjection {
    pub fn new(ctx: &Arc<Context>, mapping: Mapping, names: ProjectionNames) -> Result<ShProjection> {
        let [width, height] = mapping.size();
        let texels_per_group = constants::SH_GROUP * constants::SH_TEXELS_PER_INVOCATION;
        // Below 512 rows, at most 2·(2·512)² cells: no overflow; above, one cell per texel.
        let cells = width * height * mapping.subdivisions().pow(2);
        let groups = cells.div_ceil(texels_per_group);
        let storage = BufferUsage::STORAGE;
        Ok(ShProjection {
            project: ComputePipeline::new(
                ctx,
                "sh_project",
                spirv::SH_PROJECT_COMP,
                &[BindingKind::SampledImage, BindingKind::StorageBuffer],
                size_of::<ShProjectPush>() as u32,
            )?,
            reduce: ComputePipeline::new(
                ctx,
                "sh_reduce",
                spirv::SH_REDUCE_COMP,
                &[BindingKind::StorageBuffer, BindingKind::StorageBuffer],
                size_of::<ShProjectPush>() as u32,
            )?,
            partials: Buffer::new(
                ctx,
                &BufferDesc {
                    name: names.partials,
                    size: groups as u64 * size_of::<ShCoeffs>() as u64,
                    usage: storage,
                    location: MemoryLocation::GpuOnly,
                },
            )?,
            coefficients: Buffer::new(
                ctx,
                &BufferDesc {
                    name: names.result,
                    size: size_of::<ShCoeffs>() as u64,
                    // Read per fragment as uniforms: far cheaper than a storage buffer on CPU drivers.
                    usage: storage | BufferUsage::UNIFORM | BufferUsage::TRANSFER_SRC,
                    location: MemoryLocation::GpuOnly,
                },
            )?,
            groups,
            mapping,
        })
    }

    /// The environment map's projection (names [`ENVIRONMENT`]).
    pub fn environment(ctx: &Arc<Context>, map: &EnvMap) -> Result<ShProjection> {
        ShProjection::new(ctx, Mapping::Equirect { width: map.width(), height: map.height() }, ENVIRONMENT)
    }

    /// The two passes; they read `image` (which must match the mapping's size) and write the
    /// result buffer.
    pub fn passes<'a>(&'a self, image: &'a Image, sampler: &'a Sampler) -> [Pass<'a>; 2] {
        let [width, height] = self.mapping.size();
        let project_push =
            ShProjectPush { size: [width, height, constants::SH_TEXELS_PER_INVOCATION, self.mapping.id()] };
        let reduce_push = ShProjectPush { size: [self.groups, 0, 0, 0] };
        [
            Pass::new("sh_project", move |cmd| {
                self.project.dispatch(
                    cmd,
                    &[Binding::Sampled(image, sampler), Binding::Storage(&self.partials)],
                    bytes_of(&project_push),
                    [self.groups, 1, 1],
                )
            }),
            Pass::new("sh_reduce", move |cmd| {
                self.reduce.dispatch(
                    cmd,
                    &[Binding::Storage(&self.partials), Binding::Storage(&self.coefficients)],
                    bytes_of(&reduce_push),
                    [1, 1, 1],
                )
            }),
        ]
    }

    /// Reads the coefficients back (after a frame that ran the passes).
    pub fn read(&self) -> Result<ShRgb9> {
        let bytes = self.coefficients.read()?;
        let mut sh = ShRgb9::default();
        for (i, c) in sh.c.iter_mut().enumerate() {
            for (k, v) in c.iter_mut().enumerate() {
                let at = (i * 4 + k) * 4;
                *v = f32::from_ne_bytes([bytes[at], bytes[at + 1], bytes[at + 2], bytes[at + 3]]);
            }
        }
        Ok(sh)
    }
}

/// Projects `map` on the GPU and returns its 9 coefficients per channel.
pub fn project(ctx: &Arc<Context>, map: &EnvMap) -> Result<ShRgb9> {
    let env = GpuEnvironment::new(ctx, map)?;
    let sh = ShProjection::environment(ctx, map)?;
    let mut executor = FrameExecutor::new(ctx, "sh_projection")?;
    executor.run(sh.passes(&env.image, &env.sampler).into())?;
    sh.read()
}
