//! The renderer: a scene on the GPU, its render targets, and the frame loop that runs a
//! technique's passes and reads the picture back.
use crate::backend::{vk, Buffer, BufferDesc, Context, MemoryLocation};
use crate::error::{Error, Result};
use crate::frame::background::Background;
use crate::frame::environment::GpuEnvironment;
use crate::frame::sh_projection::ShProjection;
use crate::frame::{FrameInputs, FrameState, GpuScene, Targets};
use crate::imageio::RgbaF32Image;
use crate::layouts::{bytes_of, FrameUniforms};
use crate::pass::{FrameExecutor, Pass, PassTiming};
use crate::prt::TransferSet;
use crate::scene::{Light, Scene};
use crate::techniques::asm::technique::Asm;
use crate::techniques::asm::{AsmSettings, AsmStats};
use crate::techniques::parallel_lights::ParallelLights;
use crate::techniques::probes::technique::ProbeTechnique;
use crate::techniques::probes::ProbeSettings;
use crate::techniques::shadow_map::ShadowMap;
use crate::techniques::tamura::technique::OcclusionSettings;
use crate::techniques::tamura::PrtTechnique;
use crate::techniques::unshadowed::Unshadowed;
use crate::techniques::Technique;
use glam::Mat4;
use std::sync::Arc;

/// Which technique lights the scene.
#[derive(Clone, Debug, Default)]
pub enum TechniqueChoice {
    /// SH irradiance, no shadows.
    #[default]
    Unshadowed,
    /// PRT: with `occlusion.regions == 0` Sloan's self-shadowing alone, otherwise the
    /// Tamura–Johan–Nishita technique with that many regions.
    Prt { transfer: Arc<TransferSet>, occlusion: OcclusionSettings },
    /// The paper's Fig. 3 baseline: `regions` environment regions (1 to 128) as directional
    /// lights with binary shadow maps of `shadow_map_size`² texels.
    ParallelLights { regions: usize, shadow_map_size: u32 },
    /// Light probes captured when the renderer is built light the moving group; the static
    /// groups are lit as `settings.statics` says: by `Unshadowed`, or by Sloan's PRT from
    /// `transfer` (required then).
    Probes { settings: ProbeSettings, transfer: Option<Arc<TransferSet>> },
    /// The scene's point and spot lights with hard shadows from one conventional shadow map of
    /// `size`² texels per light (the baseline of adaptive shadow maps).
    ShadowMap { size: u32 },
    /// Adaptive shadow maps (Fernando et al. 2001) for the scene's one point or spot light.
    Asm(AsmSettings),
}

/// What to render and how large.
#[derive(Clone, Debug)]
pub struct RenderOptions {
    pub width: u32,
    pub height: u32,
    pub technique: TechniqueChoice,
}

impl Default for RenderOptions {
    fn default() -> Self {
        RenderOptions { width: 512, height: 512, technique: TechniqueChoice::Unshadowed }
    }
}

pub struct Renderer {
    ctx: Arc<Context>,
    scene: GpuScene,
    camera: crate::scene::Camera,
    lights: Vec<Light>,
    env: GpuEnvironment,
    env_sh: ShProjection,
    env_dirty: bool,
    env_rotation: f32,
    background: Background,
    technique: Box<dyn Technique>,
    frame_uniforms: Buffer,
    targets: Targets,
    executor: FrameExecutor,
}

impl Renderer {
    pub fn new(ctx: &Arc<Context>, scene: &Scene, options: &RenderOptions) -> Result<Renderer> {
        scene.validate()?;
        let targets = Targets::new(ctx, options.width, options.height)?;
        let gpu = GpuScene::new(ctx, scene)?;
        let technique: Box<dyn Technique> = match &options.technique {
            TechniqueChoice::Unshadowed => Box::new(Unshadowed::new(ctx)?),
            TechniqueChoice::Prt { transfer, occlusion } => {
                Box::new(PrtTechnique::new(ctx, scene, &gpu, transfer, *occlusion)?)
            }
            TechniqueChoice::ParallelLights { regions, shadow_map_size } => {
                Box::new(ParallelLights::new(ctx, scene, *regions, *shadow_map_size)?)
            }
            TechniqueChoice::Probes { settings, transfer } => {
                Box::new(ProbeTechnique::new(ctx, scene, &gpu, settings, transfer.as_deref())?)
            }
            TechniqueChoice::ShadowMap { size } => Box::new(ShadowMap::new(ctx, scene, *size)?),
            TechniqueChoice::Asm(settings) => {
                Box::new(Asm::new(ctx, scene, &gpu, *settings, (options.width, options.height))?)
            }
        };
        Ok(Renderer {
            ctx: ctx.clone(),
            scene: gpu,
            camera: scene.camera,
            lights: scene.lights.clone(),
            env: GpuEnvironment::new(ctx, &scene.environment)?,
            env_sh: ShProjection::environment(ctx, &scene.environment)?,
            env_dirty: true,
            env_rotation: 0.0,
            background: Background::new(ctx)?,
            technique,
            frame_uniforms: Buffer::new(
                ctx,
                &BufferDesc {
                    name: "frame_uniforms",
                    size: size_of::<FrameUniforms>() as u64,
                    usage: vk::BufferUsageFlags::UNIFORM_BUFFER,
                    location: MemoryLocation::CpuToGpu,
                },
            )?,
            targets,
            executor: FrameExecutor::new(ctx, "frame")?,
        })
    }

    /// Turns the environment about +Y (counter-clockwise seen from above), in radians.
    pub fn set_env_rotation(&mut self, radians: f32) -> Result<()> {
        if !radians.is_finite() {
            return Err(Error::InvalidArgument(format!("environment rotation {radians} is not finite")));
        }
        self.env_rotation = radians;
        Ok(())
    }

    /// Moves the camera (checked as a scene file's camera is).
    pub fn set_camera(&mut self, camera: crate::scene::Camera) -> Result<()> {
        self.camera = camera.validated()?;
        Ok(())
    }

    /// Replaces the scene's light `index` (checked as a scene file's light is, a point light
    /// may become a spot light and back); techniques light the next frame with it and redo
    /// whatever they derived from it (shadow maps).
    pub fn set_light(&mut self, index: usize, light: Light) -> Result<()> {
        let count = self.lights.len();
        let slot = self.lights.get_mut(index).ok_or_else(|| {
            Error::InvalidArgument(format!("light {index} does not exist (the scene has {count})"))
        })?;
        *slot = light.validated().map_err(|e| e.within(&format!("light {index}")))?;
        Ok(())
    }

    /// Moves a group (a rigid transform: rotation, translation, uniform scale).
    pub fn set_group_transform(&mut self, group: usize, transform: Mat4) -> Result<()> {
        let count = self.scene.transforms.len();
        if !transform.is_finite() {
            return Err(Error::InvalidArgument(format!("transform of group {group} is not finite")));
        }
        let slot = self.scene.transforms.get_mut(group).ok_or_else(|| {
            Error::InvalidArgument(format!("group {group} does not exist (the scene has {count})"))
        })?;
        *slot = transform;
        Ok(())
    }

    /// Renders one frame and reads it back; returns each pass's GPU time.
    pub fn render(&mut self) -> Result<Vec<PassTiming>> {
        let (width, height) = (self.targets.color.width, self.targets.color.height);
        let view_proj = self.camera.projection(width as f32 / height as f32) * self.camera.view();
        let uniforms = FrameUniforms {
            view_proj: view_proj.to_cols_array_2d(),
            inv_view_proj: view_proj.inverse().to_cols_array_2d(),
            camera_pos: self.camera.position.extend(1.0).to_array(),
            env_params: [1.0, self.env_rotation, 0.0, 0.0],
        };
        self.frame_uniforms.write(0, bytes_of(&uniforms))?;

        self.technique.update(&FrameState {
            view_proj,
            transforms: &self.scene.transforms,
            env_rotation: self.env_rotation,
            lights: &self.lights,
        })?;

        let inputs = FrameInputs {
            ctx: &self.ctx,
            uniforms: &self.frame_uniforms,
            environment: &self.env,
            env_sh: &self.env_sh.coefficients,
            scene: &self.scene,
            targets: &self.targets,
        };
        let mut imports = vec!["frame_uniforms", "environment"];
        imports.extend_from_slice(self.technique.persistent());
        let analysis = self.technique.analysis_passes(&inputs);
        let mut timings = Vec::new();
        if analysis.is_empty() {
            drop(analysis);
        } else {
            // What the analysis wrote stays for the frame (the ASM depth prepass).
            let written: Vec<&'static str> =
                analysis.iter().flat_map(|p| p.outputs.iter().copied()).collect();
            timings = self.executor.run(&imports, analysis)?;
            imports.extend(written);
            self.technique.analysed()?;
        }
        let mut passes: Vec<Pass> = Vec::new();
        if self.env_dirty {
            passes.extend(self.env_sh.passes(&self.env.image, &self.env.sampler));
        } else {
            imports.push("env_sh");
        }
        passes.push(self.background.pass(&inputs));
        passes.extend(self.technique.passes(&inputs));
        let targets = &self.targets;
        passes.push(Pass::new("readback", &["color"], &[], move |cmd| targets.record_readback(cmd)));
        let frame = self.executor.run(&imports, passes)?;
        self.technique.timed(&frame);
        timings.extend(frame);
        self.env_dirty = false;
        Ok(timings)
    }

    /// Occlusion layers the last frame wanted but had no room for (see
    /// `OcclusionSettings::max_layers`): the least energetic regions' shadows between groups
    /// were left out.
    pub fn dropped_layers(&self) -> usize {
        self.technique.dropped_layers()
    }

    /// Bytes the technique keeps for the local lights' shadows (see
    /// `Technique::shadow_memory_bytes`); `None` when it has no shadow storage.
    pub fn shadow_memory_bytes(&self) -> Option<u64> {
        self.technique.shadow_memory_bytes()
    }

    /// The adaptive shadow map's hierarchy after the last frame (`None` unless the technique
    /// is `Asm`): bytes against the budget, resident tiles, deepest level, tiles rendered.
    pub fn asm_stats(&self) -> Option<AsmStats> {
        self.technique.asm_stats()
    }

    /// The light probes placed and kept (`None` unless the technique is `Probes`).
    pub fn probe_counts(&self) -> Option<crate::techniques::probes::ProbeCounts> {
        self.technique.probe_counts()
    }

    /// The last rendered frame: linear radiance, row 0 at the top.
    pub fn image(&self) -> Result<RgbaF32Image> {
        self.targets.read()
    }

    /// The environment's SH coefficients as the renderer uses them.
    pub fn env_sh(&self) -> Result<crate::sh::ShRgb9> {
        self.env_sh.read()
    }
}
