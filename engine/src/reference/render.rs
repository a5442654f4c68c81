//! The reference renderer: progressive Monte Carlo direct lighting of the scene, a batch of
//! samples per pixel per submission (shaders-glsl/reference_render.comp).
//!
//! Same camera and pixel grid as the renderer: one primary ray through each pixel centre
//! ((i + ½) / width, row 0 at the top) along the camera's eye rays (`Camera::eye_rays`, which
//! the background pass and ASM's analysis take too), so that a render and the reference compare
//! pixel by pixel (neither antialiases).
use super::lighting::ReferenceLighting;
use super::metrics::EdgeTies;
use super::statistics::{accum_buffer, samples_after, Statistics};
use crate::backend::{BindingKind, Buffer, ComputePipeline, Context};
use crate::error::{Error, Result};
use crate::frame::{eye_rays, MAX_SIZE};
use crate::imageio::RgbaF32Image;
use crate::layouts::{bytes_of, constants, spirv, ReferenceLight, ReferencePush};
use crate::pass::{FrameExecutor, Pass};
use crate::scene::{Camera, Light, Scene};
use std::sync::Arc;

/// The version of the reference's output, for caches of references on disk: bump it when the
/// same scene, camera and options give another image. 3: primary rays from the camera's basis,
/// not unprojected through the inverse view-projection in float (1/50 px apart); 4: a local
/// reference's alpha 0 where it shows no surface.
pub const OUTPUT_VERSION: u32 = 4;

/// Which light the reference renders.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LightMode {
    /// The environment map, Monte Carlo with multiple importance sampling; misses show the map.
    Environment,
    /// The scene's point and spot lights with hard shadows; no environment, black background.
    /// Deterministic: one sample per pixel is exact.
    Local,
}

#[derive(Clone, Debug)]
pub struct ReferenceOptions {
    pub width: u32,
    pub height: u32,
    pub light: LightMode,
    /// Picks the random sequence; renders with different seeds are independent.
    pub seed: u32,
}

pub struct ReferenceRenderer {
    lighting: ReferenceLighting,
    pipeline: ComputePipeline,
    accum: Buffer,
    camera: Camera,
    options: ReferenceOptions,
    samples: u32,
    executor: FrameExecutor,
    /// The device's sub-pixel precision in bits, at most 16 (offsets of 1/2^16 px stay
    /// representable beside a pixel coordinate of a few thousand): see [`EdgeTies`].
    edge_bits: u32,
}

impl ReferenceRenderer {
    pub fn new(ctx: &Arc<Context>, scene: &Scene, options: &ReferenceOptions) -> Result<ReferenceRenderer> {
        let (width, height) = (options.width, options.height);
        if !(1..=MAX_SIZE).contains(&width) || !(1..=MAX_SIZE).contains(&height) {
            return Err(Error::InvalidArgument(format!(
                "image size {width}x{height}: each side must be 1 to {MAX_SIZE} pixels"
            )));
        }
        Ok(ReferenceRenderer {
            lighting: ReferenceLighting::new(ctx, scene)?,
            pipeline: ComputePipeline::new(
                ctx,
                "reference_render",
                spirv::REFERENCE_RENDER_COMP,
                &ReferenceLighting::binding_kinds(&[BindingKind::StorageBuffer, BindingKind::StorageBuffer]),
                size_of::<ReferencePush>() as u32,
            )?,
            accum: accum_buffer(ctx, "reference_accum", width as usize * height as usize)?,
            camera: scene.camera,
            options: options.clone(),
            samples: 0,
            executor: FrameExecutor::new(ctx, "reference")?,
            edge_bits: ctx.info().sub_pixel_precision_bits.min(16),
        })
    }

    /// Adds `spp` samples per pixel in one submission (keep it short: a submission must finish
    /// well within the driver's timeout).
    pub fn run_batch(&mut self, spp: u32) -> Result<()> {
        let after = samples_after(self.samples, spp, "pixel")?;
        let (width, height) = (self.options.width, self.options.height);
        let group = constants::REFERENCE_GROUP;
        let groups = [width.div_ceil(group), height.div_ceil(group), 1];
        let pipeline = &self.pipeline;
        let (lighting, accum, lights) = (&self.lighting, &self.accum, &self.lighting.lights);
        let eye_rays = eye_rays(&self.camera, width as f32 / height as f32);
        let camera_pos = self.camera.position.extend(self.lighting.env_total).to_array();
        let params = [
            (self.options.light == LightMode::Local) as u32,
            self.lighting.light_count,
            self.options.seed,
            self.edge_bits,
        ];
        let passes = super::sample_passes(spp, self.samples, |first, count| {
            let push = ReferencePush { eye_rays, camera_pos, frame: [width, height, first, count], params };
            let bindings = lighting.bindings(&[accum, lights]);
            Pass::new("reference_render", move |cmd| {
                pipeline.dispatch(cmd, &bindings, bytes_of(&push), groups)
            })
        });
        self.executor.run(passes)?;
        self.samples = after;
        Ok(())
    }

    /// Moves the camera (checked as a scene file's camera is) and starts the image over: the
    /// next batch replaces what was accumulated.
    pub fn set_camera(&mut self, camera: Camera) -> Result<()> {
        self.camera = camera.validated()?;
        self.samples = 0;
        Ok(())
    }

    /// Samples per pixel accumulated so far.
    pub fn samples(&self) -> u32 {
        self.samples
    }

    /// Per-pixel means (the image) and standard errors so far.
    pub fn statistics(&self) -> Result<Statistics> {
        Statistics::read(&self.accum, self.samples)
    }

    /// The image so far: linear radiance, row 0 at the top; alpha 1, but 0 in local mode where
    /// the pixel shows no surface (black there, where a raster render shows the environment).
    pub fn image(&self) -> Result<RgbaF32Image> {
        Ok(self.to_image(&self.statistics()?))
    }

    /// Local mode: the pixels that lie closer to an edge than the rasterizer can place one
    /// (see [`EdgeTies`]), from the last batch.
    pub fn edge_ties(&self) -> Result<EdgeTies> {
        if self.options.light != LightMode::Local || self.samples == 0 {
            return Err(Error::Internal(
                "edge ties come from a local-light reference with its batch run".into(),
            ));
        }
        let ranges = Statistics::read(&self.accum, self.samples)?.luminance_range;
        Ok(EdgeTies { width: self.options.width, height: self.options.height, bits: self.edge_bits, ranges })
    }

    pub fn to_image(&self, statistics: &Statistics) -> RgbaF32Image {
        RgbaF32Image {
            width: self.options.width,
            height: self.options.height,
            pixels: match self.options.light {
                LightMode::Local => statistics
                    .mean
                    .iter()
                    .zip(&statistics.local_coverage)
                    .map(|(&[r, g, b], &a)| [r, g, b, a])
                    .collect(),
                LightMode::Environment => statistics.mean.iter().map(|&[r, g, b]| [r, g, b, 1.0]).collect(),
            },
        }
    }
}

/// Light units: `intensity` is radiant intensity (W/sr per channel); the irradiance at distance
/// d is I cos θ / d² (inverse square, nothing else); a spot light is a hard-edged cone of full
/// angle `fov_deg`.
pub(crate) fn reference_light(light: &Light) -> ReferenceLight {
    match *light {
        Light::Point { position, intensity } => ReferenceLight {
            position: position.extend(0.0).to_array(),
            direction: [0.0, -1.0, 0.0, -1.0],
            intensity: [intensity[0], intensity[1], intensity[2], 0.0],
        },
        Light::Spot { position, direction, fov_deg, intensity } => ReferenceLight {
            position: position.extend(1.0).to_array(),
            direction: direction.normalize().extend((0.5 * fov_deg).to_radians().cos()).to_array(),
            intensity: [intensity[0], intensity[1], intensity[2], 0.0],
        },
    }
}
