//! Probe capture (Morishige 2014, step 2) on the GPU: at a probe's position, the scene's static
//! groups and the environment are rendered into a cube map (six 90° views, one image), which
//! the shared SH projection ([`ShProjection`], [`Mapping::Cube`]) turns into 9 coefficients per
//! channel with exact texel solid angles.
//!
//! Light paths captured ([`CapturedLight`]): the environment wherever the probe sees it (the
//! rasterized cube map gives the visibility: walls hide the sky), and, with
//! [`CapturedLight::SkyAndWalls`], the static surfaces lit directly by the environment's SH
//! irradiance without shadows (Kage's unshadowed technique: a wall inside a closed room is lit
//! as if nothing stood between it and the sky). Not captured yet: shadowed light on the
//! surfaces, local lights, and further bounces.
use crate::backend::{vk, Buffer, BufferDesc, Context, Edge, Image, ImageDesc, MemoryLocation, Sampler};
use crate::error::{Error, Result};
use crate::layouts::{bytes_of, FrameUniforms};
use crate::pass::{FrameExecutor, Pass};
use crate::renderer::{GpuMesh, GpuScene, COLOR_FORMAT, DEPTH_FORMAT};
use crate::scene::{Camera, Scene};
use crate::sh::ShRgb9;
use crate::techniques::background::Background;
use crate::techniques::environment::GpuEnvironment;
use crate::techniques::sh_projection::{Mapping, ProjectionNames, ShProjection, ENVIRONMENT};
use crate::techniques::unshadowed::Unshadowed;
use glam::Vec3;
use std::ops::RangeInclusive;
use std::sync::Arc;

/// Texels per side of a cube face: the range and default.
pub const CUBE_SIZES: RangeInclusive<u32> = 8..=256;
pub const DEFAULT_CUBE_SIZE: u32 = 128;

/// Face f looks along `CUBE_FACES[f].0` with `CUBE_FACES[f].1` up; the SH projection maps
/// texels back to directions with the same table (shaders-glsl/include/cube.glsl).
const CUBE_FACES: [(Vec3, Vec3); 6] = [
    (Vec3::X, Vec3::Y),
    (Vec3::NEG_X, Vec3::Y),
    (Vec3::Y, Vec3::NEG_Z),
    (Vec3::NEG_Y, Vec3::Z),
    (Vec3::Z, Vec3::Y),
    (Vec3::NEG_Z, Vec3::Y),
];

/// Which light the cube maps hold (see the module documentation).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum CapturedLight {
    /// The environment where the probe sees it; static surfaces drawn black, so they only
    /// occlude. The light the reference's irradiance mode integrates.
    Sky,
    /// The sky, plus the static surfaces lit directly by the environment without shadows.
    #[default]
    SkyAndWalls,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct CaptureSettings {
    /// Texels per side of a cube face, within [`CUBE_SIZES`].
    pub cube_size: u32,
    pub light: CapturedLight,
}

impl Default for CaptureSettings {
    fn default() -> Self {
        CaptureSettings { cube_size: DEFAULT_CUBE_SIZE, light: CapturedLight::default() }
    }
}

impl CaptureSettings {
    pub fn validated(self) -> Result<CaptureSettings> {
        if !CUBE_SIZES.contains(&self.cube_size) {
            return Err(Error::InvalidArgument(format!(
                "probe cube map size {} must be {} to {} texels",
                self.cube_size,
                CUBE_SIZES.start(),
                CUBE_SIZES.end()
            )));
        }
        Ok(self)
    }
}

const PROBE_CUBE: ProjectionNames =
    ProjectionNames { source: "probe_cube", partials: "probe_sh_partials", result: "probe_sh" };
/// What every capture reads without writing it: the faces' cameras, the environment and its SH.
const IMPORTS: [&str; 3] = ["probe_faces", ENVIRONMENT.source, ENVIRONMENT.result];

/// Captures probes of one scene, one after another, reusing its cube map and pipelines.
pub struct ProbeCapture {
    ctx: Arc<Context>,
    settings: CaptureSettings,
    cube: Image,
    depth: Image,
    sampler: Sampler,
    /// One `FrameUniforms` per face.
    faces: Vec<Buffer>,
    env: GpuEnvironment,
    env_sh: ShProjection,
    background: Background,
    surfaces: Unshadowed,
    projection: ShProjection,
    executor: FrameExecutor,
}

impl ProbeCapture {
    /// Uploads `scene`'s environment and projects it (the walls' light) once.
    pub fn new(ctx: &Arc<Context>, scene: &Scene, settings: CaptureSettings) -> Result<ProbeCapture> {
        let settings = settings.validated()?;
        let side = settings.cube_size;
        let image = |name, format, usage| {
            Image::new(
                ctx,
                &ImageDesc { name, width: side, height: 6 * side, layers: 1, array: false, format, usage },
            )
        };
        let faces = (0..6)
            .map(|f| {
                Buffer::new(
                    ctx,
                    &BufferDesc {
                        name: &format!("probe_face{f}.uniforms"),
                        size: size_of::<FrameUniforms>() as u64,
                        usage: vk::BufferUsageFlags::UNIFORM_BUFFER,
                        location: MemoryLocation::CpuToGpu,
                    },
                )
            })
            .collect::<Result<_>>()?;
        let env = GpuEnvironment::new(ctx, &scene.environment)?;
        let env_sh = ShProjection::environment(ctx, &scene.environment)?;
        let mut executor = FrameExecutor::new(ctx, "probe_capture")?;
        executor.run(&[ENVIRONMENT.source], env_sh.passes(&env.image, &env.sampler).into())?;
        Ok(ProbeCapture {
            ctx: ctx.clone(),
            settings,
            cube: image(
                PROBE_CUBE.source,
                COLOR_FORMAT,
                vk::ImageUsageFlags::COLOR_ATTACHMENT | vk::ImageUsageFlags::SAMPLED,
            )?,
            depth: image("probe_depth", DEPTH_FORMAT, vk::ImageUsageFlags::DEPTH_STENCIL_ATTACHMENT)?,
            // The projection reads texels with texelFetch: the filter never applies.
            sampler: Sampler::new(ctx, "probe_cube.sampler", false, Edge::Clamp, Edge::Clamp)?,
            faces,
            env,
            env_sh,
            background: Background::new(ctx)?,
            surfaces: Unshadowed::new(ctx)?,
            projection: ShProjection::new(ctx, Mapping::Cube { side }, PROBE_CUBE)?,
            executor,
        })
    }

    /// The SH of the radiance arriving at `position`: the meshes of `scene` whose group
    /// `is_static` accepts, and the environment (not rotated) behind them.
    pub fn capture(
        &mut self,
        scene: &GpuScene,
        is_static: impl Fn(usize) -> bool,
        position: Vec3,
    ) -> Result<ShRgb9> {
        if !position.is_finite() {
            return Err(Error::InvalidArgument(format!("probe position {position} is not finite")));
        }
        for (buffer, (forward, up)) in self.faces.iter_mut().zip(CUBE_FACES) {
            let camera = Camera { position, target: position + forward, up, fov_y_deg: 90.0 };
            let view_proj = camera.projection(1.0) * camera.view();
            let uniforms = FrameUniforms {
                view_proj: view_proj.to_cols_array_2d(),
                inv_view_proj: view_proj.inverse().to_cols_array_2d(),
                camera_pos: position.extend(1.0).to_array(),
                env_params: [1.0, 0.0, 0.0, 0.0],
            };
            buffer.write(0, bytes_of(&uniforms))?;
        }
        let lit = self.settings.light == CapturedLight::SkyAndWalls;
        let albedo =
            |mesh: &GpuMesh| is_static(mesh.group).then_some(if lit { mesh.albedo } else { [0.0; 3] });
        let (ctx, cube, depth, faces, side) =
            (&self.ctx, &self.cube, &self.depth, &self.faces, self.settings.cube_size);
        let face_area = |f: u32| vk::Rect2D {
            offset: vk::Offset2D { x: 0, y: (f * side) as i32 },
            extent: vk::Extent2D { width: side, height: side },
        };
        let (background, surfaces, env, env_sh) = (&self.background, &self.surfaces, &self.env, &self.env_sh);
        let mut passes = vec![
            Pass::new("probe_background", &["probe_faces", "environment"], &["probe_cube"], move |cmd| {
                ctx.begin_rendering(cmd, Some(cube.into()), Some([0.0; 4]), None);
                for (f, uniforms) in faces.iter().enumerate() {
                    ctx.set_viewport(cmd, face_area(f as u32));
                    background.draw(ctx, cmd, uniforms, env);
                }
                ctx.end_rendering(cmd);
            }),
            Pass::new(
                "probe_surfaces",
                &["probe_faces", "env_sh", "probe_cube"],
                &["probe_cube", "probe_depth"],
                move |cmd| {
                    ctx.begin_rendering(cmd, Some(cube.into()), None, Some(depth.into()));
                    for (f, uniforms) in faces.iter().enumerate() {
                        ctx.set_viewport(cmd, face_area(f as u32));
                        surfaces.draw(ctx, cmd, uniforms, &env_sh.coefficients, scene, albedo);
                    }
                    ctx.end_rendering(cmd);
                },
            ),
        ];
        passes.extend(self.projection.passes(&self.cube, &self.sampler));
        self.executor.run(&IMPORTS, passes)?;
        self.projection.read()
    }
}
