//! Probe capture (Morishige 2014, step 2) on the GPU: at a probe's position, the scene's static
//! groups and the environment are rendered into a cube map (six 90° views, one image), which
//! the shared SH projection ([`ShProjection`], [`Mapping::Cube`]) turns into 9 coefficients per
//! channel with exact texel solid angles.
//!
//! Light paths captured ([`CapturedLight`]): the environment wherever the probe sees it (the
//! rasterized cube map gives the visibility: walls hide the sky), and, with
//! [`CapturedLight::SkyAndWalls`], the static surfaces as Kage lights them: their outgoing
//! radiance computed once per vertex by the BVH ray caster (environment light with shadows,
//! point and spot lights with shadows, and one bounce between the surfaces:
//! [`crate::reference::surface_radiance`]) and interpolated across each triangle by the
//! rasterizer, the same radiance `kage reference --irradiance --bounces` integrates. Point and
//! spot lights have no area for the cube map to see: each one visible from the probe (a shadow
//! ray through the static groups, on the CPU) is added to the SH as the delta of radiance it is,
//! (I / d²) δ(ω − l): coefficients (I / d²) y_i(l).
//!
//! A probe inside a wall, a column or under a floor sees the back of the static surfaces
//! around it, and its light is meaningless. [`ProbeCapture::back_faces`] casts rays in
//! [`BACK_FACE_RAYS`] directions from the probe through the static groups and counts those
//! whose first hit is a back face (the side the triangle's counter-clockwise winding faces away
//! from); [`ProbeCapture::keep_valid`] leaves out, with a warning naming the probe, those where
//! more than [`MAX_BACK_FACES`] of the directions do. A probe in open space sees no back face;
//! one just behind a single-sided wall sees its back over about half the sphere.
use super::dering::Dering;
use super::set::ProbeGroups;
use super::visibility::Occluders;
use crate::backend::{
    Binding, BindingKind, Buffer, BufferDesc, BufferUsage, Context, Depth, DepthTest, Edge, Format,
    GraphicsPipeline, Image, ImageDesc, ImageUsage, MemoryLocation, Sampler, VertexAttribute, VertexBuffer,
};
use crate::error::{Error, Result};
use crate::frame::background::Background;
use crate::frame::environment::GpuEnvironment;
use crate::frame::gpu_scene::MESH_POSITIONS_UVS;
use crate::frame::scene_pass::{bind_lit, scene_pipeline_with};
use crate::frame::sh_projection::{Mapping, ProjectionNames, ShProjection};

use crate::frame::{eye_rays, GpuScene, COLOR_FORMAT, DEPTH_FORMAT};
use crate::layouts::ReferenceLight;
use crate::layouts::{bytes_of, spirv, DrawPush, FrameUniforms};
use crate::pass::{FrameExecutor, Pass};

use crate::raycast::SceneBvh;
use crate::reference::{irradiance::check_bounces, surface_radiance, SurfaceRadiance};
use crate::scene::{Camera, Scene, FAR};
use crate::sh::{eval_basis, ShRgb9};
use glam::{DVec3, Mat3, Vec3};
use std::ops::RangeInclusive;
use std::sync::Arc;
use std::time::Instant;

/// Texels per side of a cube face: the range and default.
pub const CUBE_SIZES: RangeInclusive<u32> = 8..=256;
pub const DEFAULT_CUBE_SIZE: u32 = 128;

/// The capture's near plane: a surface nearer the probe than this (up to √3 times it towards a
/// face's corner) is clipped and the probe sees through it. The eye's 1 cm let probes a few
/// millimetres from a wall see the sky behind it; at 1 mm a 32-bit float depth buffer still
/// resolves about 1 mm at 4 m (Δz ≈ z² ε / near).
pub const CAPTURE_NEAR: f32 = 1e-3;

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
#[repr(u32)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, strum::FromRepr)]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
pub enum CapturedLight {
    /// The environment and the scene's lights where the probe sees them; static surfaces drawn
    /// black, so they only occlude: `kage reference --irradiance --bounces 0`.
    Sky = 1,
    /// The sky, plus the static surfaces with the radiance the ray caster computes for them
    /// ([`CaptureSettings::bounces`]).
    #[default]
    SkyAndWalls = 0,
}

/// How the probes are captured, each setting defined here once: the command line's
/// `--probe-*` capture options (these comments are their help), the C ABI's `probe_*` fields.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "clap", derive(clap::Args))]
pub struct CaptureSettings {
    /// Texels per side of a probe's cube-map face, 8 to 256.
    #[cfg_attr(feature = "clap", arg(long = "probe-cube-size", default_value_t = CaptureSettings::default().cube_size))]
    pub cube_size: u32,
    /// What the probes capture besides the sky they see.
    #[cfg_attr(feature = "clap", arg(long = "probe-light", value_enum, default_value_t = CaptureSettings::default().light))]
    pub light: CapturedLight,
    /// Reflections of the walls' light the probes capture: 1 (walls lit directly) or 2 (and
    /// by each other once); the reference's `--bounces`.
    #[cfg_attr(feature = "clap", arg(long = "probe-bounces", default_value_t = CaptureSettings::default().bounces))]
    pub bounces: u32,
    /// Monte Carlo samples per wall vertex and bounce for the probes' capture.
    #[cfg_attr(feature = "clap", arg(long = "probe-samples", default_value_t = CaptureSettings::default().samples))]
    pub samples: u32,
    /// Window on the probes' SH against ringing: off, nonnegative (irradiance never negative),
    /// hanning:W or lanczos:W (Sloan 2008).
    #[cfg_attr(feature = "clap", arg(long = "probe-dering", value_name = "WINDOW", default_value = "off", value_parser = Dering::parse))]
    pub dering: Dering,
}

/// Each bounce's samples per vertex: seconds on lavapipe for probe-room's 729 wall vertices,
/// though their direct light keeps a relative standard error of about 47% (BENCHMARKS.md).
pub const DEFAULT_SAMPLES: u32 = 256;
/// The seed of the walls' radiance: one scene, one radiance.
pub const RADIANCE_SEED: u32 = 0x5eed;

impl Default for CaptureSettings {
    fn default() -> Self {
        CaptureSettings {
            cube_size: DEFAULT_CUBE_SIZE,
            light: CapturedLight::default(),
            bounces: crate::reference::MAX_BOUNCES,
            samples: DEFAULT_SAMPLES,
            dering: Dering::Off,
        }
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
        check_bounces(self.bounces)?;
        if let Dering::Hanning(w) | Dering::Lanczos(w) = self.dering {
            if !(w.is_finite() && w > 0.0) {
                return Err(Error::InvalidArgument(format!(
                    "the probes' deringing window width {w} must be a positive number of bands"
                )));
            }
        }
        if self.light == CapturedLight::SkyAndWalls && (self.bounces == 0 || self.samples == 0) {
            return Err(Error::InvalidArgument(format!(
                "probes capturing the walls need at least 1 bounce and 1 sample per vertex (got {} and {})",
                self.bounces, self.samples
            )));
        }
        Ok(self)
    }
}

/// Directions cast by [`ProbeCapture::back_faces`]: a Fibonacci lattice, each about 0.05 sr.
pub const BACK_FACE_RAYS: u32 = 256;
/// The fraction of directions seeing back faces above which a probe is inside geometry.
pub const MAX_BACK_FACES: f32 = 0.25;

/// A probe left out of the set: its index in the positions given, where it is, and the
/// fraction of its directions that see back faces.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct InvalidProbe {
    pub index: usize,
    pub position: DVec3,
    pub back_faces: f32,
}

/// Where a capture's time goes (`kage render` prints it; BENCHMARKS.md "Light probes: capture
/// time"): the GPU's rays for the walls' radiance, counted by the shader, the cube maps (drawn
/// and projected on the GPU, read back), and the CPU's rays through the static groups' BVH
/// (back faces and the local lights' visibility). Seconds are wall-clock, each part's work
/// waited for.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct CaptureCost {
    /// The walls' radiance: its seconds (set-up and read-back included), the rays it traced
    /// (all its bounces), the seconds of its batches of rays, and of those the seconds of all
    /// but the traversal ([`crate::reference::SurfaceRadiance::untraced_seconds`]).
    pub radiance_seconds: f64,
    pub radiance_rays: u64,
    pub radiance_batch_seconds: f64,
    pub radiance_untraced_seconds: f64,
    /// The static groups' BVH for the CPU's rays, built once.
    pub bvh_seconds: f64,
    /// Cube maps captured, the texels each drew and projected (six faces), and their seconds.
    pub cubes: u32,
    pub cube_texels: u64,
    pub cube_seconds: f64,
    /// Rays the CPU cast (back faces, local lights) and their seconds.
    pub cpu_rays: u64,
    pub cpu_seconds: f64,
}

impl CaptureCost {
    /// The seconds the walls' radiance spent in ray traversal: its batches' less the untraced.
    pub fn radiance_traversal_seconds(&self) -> f64 {
        (self.radiance_batch_seconds - self.radiance_untraced_seconds).max(0.0)
    }

    /// Millions of rays per second of the walls' radiance's traversal (0 without rays).
    pub fn radiance_mrays_per_second(&self) -> f64 {
        per_second(self.radiance_rays, self.radiance_traversal_seconds()) * 1e-6
    }

    /// Millions of cube-map texels drawn and projected per second.
    pub fn cube_mtexels_per_second(&self) -> f64 {
        per_second(self.cube_texels * u64::from(self.cubes), self.cube_seconds) * 1e-6
    }

    /// The seconds of the parts.
    pub fn seconds(&self) -> f64 {
        self.radiance_seconds + self.bvh_seconds + self.cube_seconds + self.cpu_seconds
    }
}

fn per_second(count: u64, seconds: f64) -> f64 {
    if seconds > 0.0 {
        count as f64 / seconds
    } else {
        0.0
    }
}

/// Per-vertex radiance as a second vertex buffer (location 1).
const RADIANCE_ATTRIBUTES: [VertexAttribute; 1] =
    [VertexAttribute { location: 1, format: Format::RGBA32_FLOAT, offset: 0 }];
const RADIANCE_VERTICES: VertexBuffer<'static> =
    VertexBuffer { stride: 16, attributes: &RADIANCE_ATTRIBUTES };

const PROBE_CUBE: ProjectionNames = ProjectionNames { partials: "probe_sh_partials", result: "probe_sh" };
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
    background: Background,
    surfaces: GraphicsPipeline,
    /// `[group][mesh]`: the radiance vertex buffer of each static mesh (`None` for the others).
    radiance: Vec<Vec<Option<Buffer>>>,
    /// The scene's point and spot lights, and the static groups that may hide them.
    lights: Vec<ReferenceLight>,
    statics: SceneBvh,
    projection: ShProjection,
    executor: FrameExecutor,
    cost: CaptureCost,
}

impl ProbeCapture {
    /// Uploads `scene`'s environment and computes the radiance of its static groups
    /// ([`ProbeGroups::is_static`]) once, lit by everything static (the moving groups cast no
    /// shadow on them).
    pub fn new(ctx: &Arc<Context>, scene: &Scene, settings: CaptureSettings) -> Result<ProbeCapture> {
        let settings = settings.validated()?;
        let side = settings.cube_size;
        let statics = static_scene(scene);
        let start = Instant::now();
        let (radiance, computed) = static_radiance(ctx, &statics, settings)?;
        let radiance_seconds = start.elapsed().as_secs_f64();
        let start = Instant::now();
        let bvh = SceneBvh::build(&statics)?;
        let cost = CaptureCost {
            radiance_seconds,
            radiance_rays: computed.rays,
            radiance_batch_seconds: computed.seconds,
            radiance_untraced_seconds: computed.untraced_seconds,
            bvh_seconds: start.elapsed().as_secs_f64(),
            cube_texels: 6 * u64::from(side) * u64::from(side),
            ..Default::default()
        };
        let image = |name, format, usage| {
            Image::new(
                ctx,
                &ImageDesc {
                    name,
                    width: side,
                    height: 6 * side,
                    layers: 1,
                    levels: 1,
                    array: false,
                    format,
                    usage,
                },
            )
        };
        let faces = (0..6)
            .map(|f| {
                Buffer::new(
                    ctx,
                    &BufferDesc {
                        name: &format!("probe_face{f}.uniforms"),
                        size: size_of::<FrameUniforms>() as u64,
                        usage: BufferUsage::UNIFORM,
                        location: MemoryLocation::CpuToGpu,
                    },
                )
            })
            .collect::<Result<_>>()?;
        Ok(ProbeCapture {
            ctx: ctx.clone(),
            settings,
            cube: image("probe_cube", COLOR_FORMAT, ImageUsage::COLOR_ATTACHMENT | ImageUsage::SAMPLED)?,
            depth: image("probe_depth", DEPTH_FORMAT, ImageUsage::DEPTH_ATTACHMENT)?,
            // The projection reads texels with texelFetch: the filter never applies.
            sampler: Sampler::new(ctx, "probe_cube.sampler", false, Edge::Clamp, Edge::Clamp)?,
            faces,
            env: GpuEnvironment::new(ctx, &scene.environment)?,
            background: Background::new(ctx)?,
            surfaces: scene_pipeline_with(
                ctx,
                "probe_surfaces",
                (spirv::PROBE_SURFACE_VERT, spirv::PROBE_SURFACE_FRAG),
                &[BindingKind::UniformBuffer],
                size_of::<DrawPush>(),
                &[MESH_POSITIONS_UVS, RADIANCE_VERTICES],
                DepthTest::Less,
            )?,
            radiance,
            lights: scene.lights.iter().map(crate::reference::render::reference_light).collect(),
            statics: bvh,
            projection: ShProjection::new(ctx, Mapping::Cube { side }, PROBE_CUBE)?,
            executor: FrameExecutor::new(ctx, "probe_capture")?,
            cost,
        })
    }

    /// The SH of the radiance arriving at `position`: the meshes of `scene` whose group
    /// `is_static` accepts, and the environment (not rotated) behind them. A mesh of one of the
    /// scene's moving groups ([`ProbeGroups`]) that `is_static` accepts has no radiance and is
    /// drawn black.
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
            let view_proj = camera.projection_from(1.0, CAPTURE_NEAR) * camera.view();
            let uniforms = FrameUniforms {
                view_proj: view_proj.to_cols_array_2d(),
                eye_rays: eye_rays(&camera, 1.0),
                camera_pos: position.extend(1.0).to_array(),
                env_params: [1.0, 0.0, 0.0, 0.0],
                viewport: [self.settings.cube_size as f32, self.settings.cube_size as f32, CAPTURE_NEAR, FAR],
            };
            buffer.write(0, bytes_of(&uniforms))?;
        }
        let (ctx, cube, depth, faces, side) =
            (&self.ctx, &self.cube, &self.depth, &self.faces, self.settings.cube_size);
        // Face f is the side² square at (0, f × side) of the strip.
        let face_origin = |f: usize| [0, f as u32 * side];
        let (background, surfaces, env, radiance) =
            (&self.background, &self.surfaces, &self.env, &self.radiance);
        let mut passes = vec![
            Pass::new("probe_background", move |cmd| {
                ctx.begin_rendering(cmd, Some(cube.into()), Some([0.0; 4]), None);
                for (f, uniforms) in faces.iter().enumerate() {
                    ctx.restrict_to_square(cmd, face_origin(f), side);
                    background.draw(ctx, cmd, uniforms, env);
                }
                ctx.end_rendering(cmd);
            }),
            Pass::new("probe_surfaces", move |cmd| {
                ctx.begin_rendering(cmd, Some(cube.into()), None, Some(Depth::Clear(depth.into())));
                for (f, uniforms) in faces.iter().enumerate() {
                    ctx.restrict_to_square(cmd, face_origin(f), side);
                    bind_lit(cmd, surfaces, scene, &[Binding::Uniform(uniforms)]);
                    for mesh in scene.meshes.iter().filter(|m| is_static(m.group)) {
                        let Some(Some(r)) = radiance.get(mesh.group).and_then(|g| g.get(mesh.mesh)) else {
                            continue;
                        };
                        let push = DrawPush {
                            model: scene.transforms[mesh.group].to_cols_array_2d(),
                            albedo: [0.0; 4],
                        };
                        scene.bind_albedo_map(cmd, surfaces, mesh);
                        surfaces.push(cmd, bytes_of(&push));
                        ctx.draw_indexed(cmd, &[&mesh.vertices, r], &mesh.indices, mesh.index_count);
                    }
                }
                ctx.end_rendering(cmd);
            }),
        ];
        passes.extend(self.projection.passes(&self.cube, &self.sampler));
        let start = Instant::now();
        self.executor.run(passes)?;
        let mut sh = self.projection.read()?;
        self.cost.cubes += 1;
        self.cost.cube_seconds += start.elapsed().as_secs_f64();
        let start = Instant::now();
        for light in &self.lights {
            self.cost.cpu_rays += u64::from(self.add_light(&mut sh, light, position));
        }
        self.cost.cpu_seconds += start.elapsed().as_secs_f64();
        Ok(self.settings.dering.apply(&sh))
    }

    /// What the capture took so far: the walls' radiance and BVH when it was made, then every
    /// probe's cube map, local lights and back-face check.
    pub fn cost(&self) -> CaptureCost {
        self.cost
    }

    /// The static groups as occluders of the probes ([`Occluders`]), from the BVH the
    /// capture built for its own shadow rays.
    pub fn occluders(&self) -> Occluders {
        Occluders::from_bvh(self.statics.clone())
    }

    /// The fraction of [`BACK_FACE_RAYS`] directions from `p` whose first static surface is
    /// met from behind.
    pub fn back_faces(&self, p: Vec3) -> f32 {
        let n = BACK_FACE_RAYS;
        let golden = std::f32::consts::PI * (3.0 - 5f32.sqrt());
        let back = (0..n)
            .filter(|&i| {
                let y = 1.0 - 2.0 * (i as f32 + 0.5) / n as f32;
                let r = (1.0 - y * y).max(0.0).sqrt();
                let dir = Vec3::new(r * (golden * i as f32).cos(), y, r * (golden * i as f32).sin());
                self.statics.closest_hit(p, dir, f32::INFINITY).is_some_and(|hit| {
                    let v = self.statics.triangles()[hit.triangle as usize];
                    let [a, b, c] = [v.v0, v.v1, v.v2].map(|v| Vec3::from_slice(&v[..3]));
                    let to_world = self.statics.instances()[hit.instance as usize].object_to_world;
                    let face =
                        Mat3::from_mat4(glam::Mat4::from_cols_array_2d(&to_world)) * (b - a).cross(c - a);
                    face.dot(dir) > 0.0
                })
            })
            .count();
        back as f32 / n as f32
    }

    /// The positions of probes not inside geometry ([`ProbeCapture::back_faces`] at most
    /// [`MAX_BACK_FACES`]), and those left out.
    pub fn keep_valid(&mut self, positions: &[DVec3]) -> (Vec<DVec3>, Vec<InvalidProbe>) {
        let start = Instant::now();
        let mut kept = Vec::with_capacity(positions.len());
        let mut invalid = Vec::new();
        self.cost.cpu_rays += u64::from(BACK_FACE_RAYS) * positions.len() as u64;
        for (index, &position) in positions.iter().enumerate() {
            let back_faces = self.back_faces(position.as_vec3());
            if back_faces > MAX_BACK_FACES {
                invalid.push(InvalidProbe { index, position, back_faces });
            } else {
                kept.push(position);
            }
        }
        self.cost.cpu_seconds += start.elapsed().as_secs_f64();
        (kept, invalid)
    }

    /// Adds `light`'s delta of radiance to `sh` where the probe at `p` sees it (see the module
    /// documentation); the same cone and falloff as local_light.glsl. Whether it cast a ray.
    fn add_light(&self, sh: &mut ShRgb9, light: &ReferenceLight, p: Vec3) -> bool {
        let to_light = Vec3::from_slice(&light.position[..3]) - p;
        let d = to_light.length();
        if d <= 0.0 {
            return false;
        }
        let l = to_light / d;
        let spot = light.position[3] > 0.5;
        if spot && (-l).dot(Vec3::from_slice(&light.direction[..3])) < light.direction[3] {
            return false;
        }
        if self.statics.occluded(p, l, d) {
            return true;
        }
        let mut y = [0.0; 9];
        eval_basis(3, l, &mut y);
        for (c, y) in sh.c.iter_mut().zip(y) {
            for (v, intensity) in c.iter_mut().zip(&light.intensity) {
                *v += intensity / (d * d) * y;
            }
        }
        true
    }
}

/// A copy of `scene` without the meshes of its moving groups (each stays, empty, so that group
/// indices do not change).
pub(super) fn static_scene(scene: &Scene) -> Scene {
    let groups = ProbeGroups::of(scene);
    let mut statics = scene.clone();
    for (g, group) in statics.groups.iter_mut().enumerate() {
        if groups.is_moving(g) {
            group.meshes.clear();
        }
    }
    statics
}

/// The radiance vertex buffers of [`ProbeCapture::radiance`] for the static scene `statics`
/// (zero with [`CapturedLight::Sky`]), with the rays and seconds computing it took (its
/// radiance moved into the buffers).
fn static_radiance(
    ctx: &Arc<Context>,
    statics: &Scene,
    settings: CaptureSettings,
) -> Result<(Vec<Vec<Option<Buffer>>>, SurfaceRadiance)> {
    let mut computed = match settings.light {
        CapturedLight::Sky => SurfaceRadiance::default(),
        CapturedLight::SkyAndWalls => {
            surface_radiance(ctx, statics, settings.bounces, settings.samples, RADIANCE_SEED)?
        }
    };
    let radiance = computed.radiance.take();
    let mut next = 0;
    let mut buffers = Vec::new();
    for group in &statics.groups {
        let mut meshes = Vec::new();
        for mesh in &group.meshes {
            let count = mesh.positions.len();
            let values = radiance.as_ref().map_or(vec![[0.0; 4]; count], |r| r[next..next + count].to_vec());
            next += count;
            let bytes: Vec<u8> = values.iter().flatten().flat_map(|v| v.to_ne_bytes()).collect();
            let name = format!("{}.{}.probe_radiance", group.name, mesh.name);
            meshes.push(
                (count > 0)
                    .then(|| Buffer::with_data(ctx, &name, BufferUsage::VERTEX, &bytes))
                    .transpose()?,
            );
        }
        buffers.push(meshes);
    }
    Ok((buffers, computed))
}
