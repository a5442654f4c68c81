//! SH projection of the environment on the GPU, in two compute passes: `sh_project` (one
//! partial sum per workgroup of texels, with exact texel solid angles) and `sh_reduce` (the
//! partials added in a fixed order). Run when the environment changes, not every frame.
use super::environment::GpuEnvironment;
use crate::backend::{
    vk, Binding, BindingKind, Buffer, BufferDesc, ComputePipeline, Context, MemoryLocation,
};
use crate::error::Result;
use crate::layouts::{bytes_of, constants, spirv, ShCoeffs, ShProjectPush};
use crate::pass::{FrameExecutor, Pass};
use crate::scene::EnvMap;
use crate::sh::ShRgb9;
use std::sync::Arc;

pub struct EnvSh {
    project: ComputePipeline,
    reduce: ComputePipeline,
    partials: Buffer,
    /// The result: one `ShCoeffs` (9 radiance coefficients per channel).
    pub coefficients: Buffer,
    groups: u32,
    size: [u32; 2],
}

impl EnvSh {
    pub fn new(ctx: &Arc<Context>, map: &EnvMap) -> Result<EnvSh> {
        let texels_per_group = constants::SH_GROUP * constants::SH_TEXELS_PER_INVOCATION;
        let groups = (map.width() * map.height()).div_ceil(texels_per_group);
        let storage = vk::BufferUsageFlags::STORAGE_BUFFER;
        Ok(EnvSh {
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
                    name: "sh_partials",
                    size: groups as u64 * size_of::<ShCoeffs>() as u64,
                    usage: storage,
                    location: MemoryLocation::GpuOnly,
                },
            )?,
            coefficients: Buffer::new(
                ctx,
                &BufferDesc {
                    name: "env_sh",
                    size: size_of::<ShCoeffs>() as u64,
                    // Read per fragment as uniforms: far cheaper than a storage buffer on CPU drivers.
                    usage: storage
                        | vk::BufferUsageFlags::UNIFORM_BUFFER
                        | vk::BufferUsageFlags::TRANSFER_SRC,
                    location: MemoryLocation::GpuOnly,
                },
            )?,
            groups,
            size: [map.width(), map.height()],
        })
    }

    /// The two passes; they read "environment" and write "env_sh".
    pub fn passes<'a>(&'a self, env: &'a GpuEnvironment) -> [Pass<'a>; 2] {
        let project_push =
            ShProjectPush { size: [self.size[0], self.size[1], constants::SH_TEXELS_PER_INVOCATION, 0] };
        let reduce_push = ShProjectPush { size: [self.groups, 0, 0, 0] };
        [
            Pass::new("sh_project", &["environment"], &["sh_partials"], move |cmd| {
                self.project.dispatch(
                    cmd,
                    &[Binding::Sampled(&env.image, &env.sampler), Binding::Storage(&self.partials)],
                    bytes_of(&project_push),
                    [self.groups, 1, 1],
                )
            }),
            Pass::new("sh_reduce", &["sh_partials"], &["env_sh"], move |cmd| {
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
    let sh = EnvSh::new(ctx, map)?;
    let mut executor = FrameExecutor::new(ctx, "sh_projection")?;
    executor.run(&["environment"], sh.passes(&env).into())?;
    sh.read()
}
