//! The renderer: a scene on the GPU, its render targets, and the frame loop that runs a
//! technique's passes and reads the picture back.
use crate::backend::{Buffer, BufferDesc, BufferUsage, Context, MemoryLocation};
use crate::error::{Error, Result};
use crate::frame::background::Background;
use crate::frame::environment::GpuEnvironment;
use crate::frame::sh_projection::ShProjection;
use crate::frame::{eye_rays, FrameInputs, FrameState, GpuScene, Targets};
use crate::imageio::RgbaF32Image;
use crate::layouts::{bytes_of, FrameUniforms};
use crate::pass::{FrameExecutor, Pass, PassTiming};
use crate::progress::Progress;
use crate::prt::TransferSet;
use crate::scene::{check_extent, Light, Scene, FAR, NEAR};
use crate::techniques::description::TechniqueDesc;
use crate::techniques::{Technique, TechniqueStats};
use glam::Mat4;
use std::sync::Arc;

/// What to render and how large.
#[derive(Clone, Debug)]
pub struct RenderOptions {
    pub width: u32,
    pub height: u32,
    pub technique: TechniqueDesc,
    /// The PRT transfer the technique's [`TechniqueDesc::precomputation`] asks for (`None` when
    /// it needs none).
    pub transfer: Option<Arc<TransferSet>>,
}

impl Default for RenderOptions {
    fn default() -> Self {
        RenderOptions { width: 512, height: 512, technique: TechniqueDesc::Unshadowed, transfer: None }
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
    /// Each group's [`crate::scene::Group::object_reach`], for `set_group_transform`.
    reach: Vec<f32>,
    /// The groups that move by themselves ([`crate::scene::Group::motion`]), their meshes left
    /// out: what [`Renderer::set_time`] poses.
    moving: Vec<(usize, crate::scene::Group)>,
}

impl Renderer {
    pub fn new(ctx: &Arc<Context>, scene: &Scene, options: &RenderOptions) -> Result<Renderer> {
        Renderer::with_progress(ctx, scene, options, &mut crate::progress::silent)
    }

    /// [`Renderer::new`], with `progress` hearing its long work (the light probes' capture).
    pub fn with_progress(
        ctx: &Arc<Context>,
        scene: &Scene,
        options: &RenderOptions,
        progress: &mut Progress,
    ) -> Result<Renderer> {
        scene.validate()?;
        let targets = Targets::new(ctx, options.width, options.height)?;
        let gpu = GpuScene::new(ctx, scene)?;
        let size = (options.width, options.height);
        let technique =
            options.technique.build(ctx, scene, &gpu, options.transfer.as_ref(), size, progress)?;
        Ok(Renderer {
            reach: scene.groups.iter().map(|g| g.object_reach()).collect(),
            moving: scene
                .groups
                .iter()
                .enumerate()
                .filter(|(_, g)| g.motion.is_some())
                .map(|(i, g)| {
                    let (name, transform, motion) = (g.name.clone(), g.transform, g.motion.clone());
                    (i, crate::scene::Group { name, meshes: Vec::new(), transform, motion })
                })
                .collect(),
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
                    usage: BufferUsage::UNIFORM,
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
        *slot = light.validated_as(index)?;
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
        let scale = transform.x_axis.truncate().length();
        check_extent(transform.w_axis.truncate(), scale, self.reach[group])
            .map_err(|e| e.within(&format!("group {group}")))?;
        *slot = transform;
        Ok(())
    }

    /// Poses every group that has a motion at `time` seconds of it (the others stay).
    pub fn set_time(&mut self, time: f32) -> Result<()> {
        if !time.is_finite() {
            return Err(Error::InvalidArgument(format!("time {time} is not finite")));
        }
        for (g, group) in &self.moving {
            self.scene.transforms[*g] = group.pose_at(time).matrix();
        }
        Ok(())
    }

    /// Renders one frame and reads it back; returns each pass's GPU time.
    pub fn render(&mut self) -> Result<Vec<PassTiming>> {
        let (width, height) = (self.targets.color.width, self.targets.color.height);
        let aspect = width as f32 / height as f32;
        let view_proj = self.camera.projection(aspect) * self.camera.view();
        let uniforms = FrameUniforms {
            view_proj: view_proj.to_cols_array_2d(),
            eye_rays: eye_rays(&self.camera, aspect),
            camera_pos: self.camera.position.extend(1.0).to_array(),
            env_params: [1.0, self.env_rotation, 0.0, 0.0],
            viewport: [width as f32, height as f32, NEAR, FAR],
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
        let analysis = self.technique.analysis_passes(&inputs);
        let mut timings = Vec::new();
        if analysis.is_empty() {
            drop(analysis);
        } else {
            timings = self.executor.run(analysis)?;
            self.technique.analysed()?;
        }
        let mut passes: Vec<Pass> = Vec::new();
        if self.env_dirty {
            passes.extend(self.env_sh.passes(&self.env.image, &self.env.sampler));
        }
        passes.push(self.background.pass(&inputs));
        passes.extend(self.technique.passes(&inputs));
        let targets = &self.targets;
        passes.push(Pass::new("readback", move |cmd| targets.record_readback(cmd)));
        let mut frame = self.executor.run(passes)?;
        // Starts count from the frame's first pass: this submission's follow the analysis's end.
        let analysis_end = crate::pass::frame_ms(&timings).unwrap_or(0.0);
        for t in &mut frame {
            t.start_ms = t.start_ms.map(|ms| ms + analysis_end);
        }
        timings.extend(frame);
        self.technique.timed(&timings);
        self.env_dirty = false;
        Ok(timings)
    }

    /// What the technique reports of the last frame besides the pass timings.
    pub fn stats(&self) -> TechniqueStats {
        self.technique.stats()
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
