//! The reference's irradiance mode: E(p, n) = ∫ L(ω) V(ω) max(n·ω, 0) dω at listed points
//! and normals, one compute invocation per point (shaders-glsl/reference_irradiance.comp). Light
//! probes are checked against it. L is the environment (full visibility, the same MIS estimator
//! as the renderer), the scene's point and spot lights (hard shadows), and with `bounces` ≥ 1
//! the light reflected by the surfaces ([`surface_radiance`]).
//!
//! Bounces: the surfaces' outgoing radiance is computed at their vertices and interpolated
//! linearly across each triangle (a radiosity-style discretization), not traced as a full path
//! at each hit. Light probes capture the surfaces with exactly this radiance (rasterized with
//! the same interpolation), so probe and reference integrate the same light and their
//! difference measures the probes (cube map, SH, interpolation between probes) alone; the
//! discretization's own error is the mesh's, the same for both (coarse where shadows are sharp
//! between vertices).
//!
//! Input file: `{"points": [{"position": [x, y, z], "normal": [x, y, z]}, ...]}` (normals are
//! normalised; unknown fields are errors). Output: `{"irradiance": [[r, g, b], ...], "spp": N,
//! "standard_error": [[r, g, b], ...]}`, in the input's order.
use super::lighting::ReferenceLighting;
use super::statistics::{accum_buffer, samples_after, Statistics};
use crate::backend::{BindingKind, Buffer, BufferUsage, ComputePipeline, Context};
use crate::error::{Error, Result};
use crate::layouts::{bytes_of, bytes_of_slice, constants, spirv, IrradiancePoint, IrradiancePush};
use crate::pass::{scaled_to_submissions, FrameExecutor, Pass};
use crate::scene::Scene;
use glam::{Mat4, Vec3};
use serde::{Deserialize, Serialize};
use std::sync::Arc;
use std::time::Instant;

#[derive(Clone, Debug, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct PointsFile {
    pub points: Vec<Point>,
}

#[derive(Clone, Copy, Debug, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct Point {
    pub position: [f32; 3],
    pub normal: [f32; 3],
}

impl PointsFile {
    /// Parses and checks a points file's text (see `check_points`).
    pub fn parse(text: &str) -> Result<PointsFile> {
        let file: PointsFile =
            serde_json::from_str(text).map_err(|e| Error::InvalidArgument(format!("points file: {e}")))?;
        check_points(&file.points).map_err(|e| match e {
            Error::InvalidArgument(m) => Error::InvalidArgument(format!("points file: {m}")),
            e => e,
        })?;
        Ok(file)
    }
}

/// At least one point, finite values, non-zero normals; errors name the point.
fn check_points(points: &[Point]) -> Result<()> {
    if points.is_empty() {
        return Err(Error::InvalidArgument("\"points\" is empty; list at least one point".into()));
    }
    for (i, p) in points.iter().enumerate() {
        if !p.position.iter().chain(&p.normal).all(|v| v.is_finite()) {
            return Err(Error::InvalidArgument(format!("point {i} has a NaN or infinite coordinate")));
        }
        if Vec3::from(p.normal).length_squared() == 0.0 {
            return Err(Error::InvalidArgument(format!("point {i} has a zero normal")));
        }
    }
    Ok(())
}

#[derive(Clone, Debug, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct IrradianceFile {
    pub irradiance: Vec<[f32; 3]>,
    pub spp: u32,
    /// Standard error of each irradiance estimate, per channel (0 where fewer than 2 samples).
    pub standard_error: Vec<[f32; 3]>,
}

impl IrradianceFile {
    pub fn from_statistics(statistics: &Statistics) -> IrradianceFile {
        IrradianceFile {
            irradiance: statistics.mean.clone(),
            spp: statistics.samples,
            standard_error: statistics
                .standard_error
                .clone()
                .unwrap_or_else(|| vec![[0.0; 3]; statistics.mean.len()]),
        }
    }
}

pub struct IrradianceReference {
    shader: IrradianceShader,
    samples: u32,
    executor: FrameExecutor,
    /// The ray count as last read, and the rays traced so far.
    rays_read: u32,
    rays_traced: u64,
    /// Seconds the batches took, submission to completion.
    seconds: f64,
}

/// What the irradiance shader's dispatches bind and push.
struct IrradianceShader {
    lighting: ReferenceLighting,
    pipeline: ComputePipeline,
    points: Buffer,
    accum: Buffer,
    /// The shader's count of the rays it traced (a wrapping u32).
    rays: Buffer,
    /// Per scene vertex, the radiance the surfaces reflect (a bounce), or one unused entry.
    radiance: Buffer,
    bounce: bool,
    count: u32,
    seed: u32,
}

/// Most bounces the reference and the probes' capture compute.
pub const MAX_BOUNCES: u32 = 2;

/// The surfaces' radiance ([`surface_radiance`]) and what computing it took.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SurfaceRadiance {
    /// Per scene vertex, RGB and an unused 0; `None` with 0 bounces.
    pub radiance: Option<Vec<[f32; 4]>>,
    /// The rays the passes traced, as the shader counted them.
    pub rays: u64,
    /// Seconds of the passes' batches, submission to completion.
    pub seconds: f64,
    /// Of those, the seconds of all but the traversal: each pass's batches again with every
    /// ray a miss, timed on [`UNTRACED_SAMPLES`] samples and scaled to all of them (as the PRT
    /// precomputation splits its time), a submission's own cost counted once per batch
    /// ([`IrradianceReference::untraced_seconds`]).
    pub untraced_seconds: f64,
}

/// Samples per point of the untraced submission that times all but the traversal.
pub const UNTRACED_SAMPLES: u32 = 16;

/// The outgoing radiance albedo / π · E of every vertex of `scene` (scene order: groups,
/// meshes, vertices; RGB and an unused 0) with light that reflected up to `bounces` − 1 times
/// before (`bounces` = 0: no vertex radiates; 1: direct light only; 2: and one bounce between
/// the surfaces). `samples` per vertex and pass, seeded by `seed` (pass k by `seed + k`).
/// E is taken a little inside each vertex's triangles (see [`vertex_points`]) on the side of
/// its normal.
pub fn surface_radiance(
    ctx: &Arc<Context>,
    scene: &Scene,
    bounces: u32,
    samples: u32,
    seed: u32,
) -> Result<SurfaceRadiance> {
    check_bounces(bounces)?;
    if bounces > 0 && samples == 0 {
        return Err(Error::InvalidArgument(format!(
            "{bounces} bounces with 0 samples per vertex: the surfaces' radiance needs at least 1"
        )));
    }
    let points = vertex_points(scene);
    let mut out = SurfaceRadiance::default();
    if points.is_empty() {
        out.radiance = (bounces > 0).then(Vec::new);
        return Ok(out);
    }
    let albedo: Vec<[f32; 3]> =
        scene.meshes().flat_map(|(_, mesh)| std::iter::repeat_n(mesh.albedo, mesh.positions.len())).collect();
    for pass in 0..bounces {
        let mut reference = IrradianceReference::with_radiance(
            ctx,
            scene,
            &points,
            seed.wrapping_add(pass),
            out.radiance.as_deref(),
        )?;
        for batch in (0..samples).step_by(RADIANCE_BATCH as usize) {
            reference.run_batch((samples - batch).min(RADIANCE_BATCH))?;
        }
        out.rays += reference.rays_traced();
        out.seconds += reference.seconds();
        let e = reference.statistics()?.mean;
        out.untraced_seconds += reference.untraced_seconds(samples, RADIANCE_BATCH)?;
        out.radiance = Some(
            e.iter()
                .zip(&albedo)
                .map(|(e, a)| {
                    let [r, g, b] = [0, 1, 2].map(|k| a[k] / std::f32::consts::PI * e[k]);
                    [r, g, b, 0.0]
                })
                .collect(),
        );
    }
    Ok(out)
}

/// Samples per vertex per submission: a submission must stay short on a CPU driver.
const RADIANCE_BATCH: u32 = 64;

pub fn check_bounces(bounces: u32) -> Result<()> {
    if bounces > MAX_BOUNCES {
        return Err(Error::InvalidArgument(format!("{bounces} bounces: at most {MAX_BOUNCES} are computed")));
    }
    Ok(())
}

/// Each vertex of `scene` in world space, moved 1% of the way towards the mean centroid of the
/// triangles around it, with its world normal: a vertex where two walls meet lies on both, and
/// rays from it would slip through the other wall's edge (half a hemisphere of light leaking
/// into a room's corners); just inside its own triangles they leave from the room's side.
pub fn vertex_points(scene: &Scene) -> Vec<Point> {
    let mut points = Vec::with_capacity(scene.vertex_count());
    for group in &scene.groups {
        let m: Mat4 = group.transform.matrix();
        for mesh in &group.meshes {
            let mut centroid = vec![(Vec3::ZERO, 0u32); mesh.positions.len()];
            for tri in mesh.indices.chunks_exact(3) {
                let c = tri.iter().map(|&i| Vec3::from(mesh.positions[i as usize])).sum::<Vec3>() / 3.0;
                for &i in tri {
                    let (sum, n) = &mut centroid[i as usize];
                    *sum += c;
                    *n += 1;
                }
            }
            for ((p, n), (sum, count)) in mesh.positions.iter().zip(&mesh.normals).zip(centroid) {
                let p = Vec3::from(*p);
                let inside = if count > 0 { p + 0.01 * (sum / count as f32 - p) } else { p };
                points.push(Point {
                    position: m.transform_point3(inside).to_array(),
                    normal: m.transform_vector3(Vec3::from(*n)).normalize_or_zero().to_array(),
                });
            }
        }
    }
    points
}

impl IrradianceReference {
    /// Direct light only (no surface radiates).
    pub fn new(
        ctx: &Arc<Context>,
        scene: &Scene,
        points: &[Point],
        seed: u32,
    ) -> Result<IrradianceReference> {
        IrradianceReference::with_radiance(ctx, scene, points, seed, None)
    }

    /// With `radiance` (per scene vertex, as [`surface_radiance`] gives it), the surfaces the
    /// rays hit radiate it: one bounce more.
    pub fn with_radiance(
        ctx: &Arc<Context>,
        scene: &Scene,
        points: &[Point],
        seed: u32,
        radiance: Option<&[[f32; 4]]>,
    ) -> Result<IrradianceReference> {
        check_points(points)?;
        if let Some(r) = radiance {
            if r.len() != scene.vertex_count() {
                return Err(Error::InvalidArgument(format!(
                    "surface radiance for {} vertices, but the scene has {}",
                    r.len(),
                    scene.vertex_count()
                )));
            }
        }
        let count = u32::try_from(points.len())
            .map_err(|_| Error::InvalidArgument(format!("{} points are too many", points.len())))?;
        let gpu_points: Vec<IrradiancePoint> = points
            .iter()
            .map(|p| IrradiancePoint {
                position: Vec3::from(p.position).extend(0.0).to_array(),
                normal: Vec3::from(p.normal).normalize().extend(0.0).to_array(),
            })
            .collect();
        let shader = IrradianceShader {
            lighting: ReferenceLighting::new(ctx, scene)?,
            pipeline: ComputePipeline::new(
                ctx,
                "reference_irradiance",
                spirv::REFERENCE_IRRADIANCE_COMP,
                // Accumulators, points, lights, radiance, triangle vertices, the ray count.
                &ReferenceLighting::binding_kinds(&[BindingKind::StorageBuffer; 6]),
                size_of::<IrradiancePush>() as u32,
            )?,
            points: Buffer::with_data(
                ctx,
                "irradiance_points",
                BufferUsage::STORAGE,
                bytes_of_slice(&gpu_points),
            )?,
            accum: accum_buffer(ctx, "irradiance_accum", points.len())?,
            rays: Buffer::with_data(
                ctx,
                "irradiance_rays",
                BufferUsage::STORAGE | BufferUsage::TRANSFER_SRC,
                &[0; 4],
            )?,
            radiance: Buffer::with_data(
                ctx,
                "irradiance_surface_radiance",
                BufferUsage::STORAGE,
                &radiance
                    .filter(|r| !r.is_empty())
                    .unwrap_or(&[[0.0; 4]])
                    .iter()
                    .flatten()
                    .flat_map(|v| v.to_ne_bytes())
                    .collect::<Vec<u8>>(),
            )?,
            bounce: radiance.is_some(),
            count,
            seed,
        };
        let mut executor = FrameExecutor::new(ctx, "reference_irradiance")?;
        // The shader's compilation on a CPU driver, outside the batches' time.
        executor.run(shader.batch(true, 1, 0, 0))?;
        Ok(IrradianceReference { shader, samples: 0, executor, rays_read: 0, rays_traced: 0, seconds: 0.0 })
    }

    /// Adds `spp` samples per point in one submission.
    pub fn run_batch(&mut self, spp: u32) -> Result<()> {
        let after = samples_after(self.samples, spp, "point")?;
        let shader = &self.shader;
        let passes = shader.batch(true, spp, self.samples, shader.count);
        let start = Instant::now();
        self.executor.run(passes)?;
        self.seconds += start.elapsed().as_secs_f64();
        self.samples = after;
        let count = shader.rays.read()?.get(..4).and_then(|b| b.try_into().ok()).map(u32::from_ne_bytes);
        let count =
            count.ok_or_else(|| Error::Internal("the irradiance ray count read back short".into()))?;
        self.rays_traced += u64::from(count.wrapping_sub(self.rays_read));
        self.rays_read = count;
        Ok(())
    }

    /// The seconds `samples` samples per point, submitted in batches of at most `batch`, take
    /// with every ray taken as a miss (the same pipeline, told by a push constant not to
    /// trace): all but the traversal. Timed on a submission of one sample and one of
    /// [`UNTRACED_SAMPLES`], which part a submission's own cost (recording, submitting, the
    /// wait: 1.8 ms on the atrium on lavapipe) from a sample's, so that it counts once per
    /// batch, as the batches pay it; scaling the second alone counted it per 16 samples.
    /// Consumes the reference: the submissions overwrite its statistics.
    pub fn untraced_seconds(mut self, samples: u32, batch: u32) -> Result<f64> {
        let timed = samples.min(UNTRACED_SAMPLES);
        let one = self.untraced_submission(1)?;
        if timed < 2 {
            return Ok(one * f64::from(samples));
        }
        let many = self.untraced_submission(timed)?;
        Ok(scaled_to_submissions(one, many, timed, samples, batch))
    }

    /// Seconds of one submission of `spp` samples per point with every ray a miss.
    fn untraced_submission(&mut self, spp: u32) -> Result<f64> {
        let shader = &self.shader;
        let passes = shader.batch(false, spp, self.samples, shader.count);
        let start = Instant::now();
        self.executor.run(passes)?;
        Ok(start.elapsed().as_secs_f64())
    }

    /// The rays the batches so far traced, as the shader counted them.
    pub fn rays_traced(&self) -> u64 {
        self.rays_traced
    }

    /// Seconds the batches so far took, submission to completion.
    pub fn seconds(&self) -> f64 {
        self.seconds
    }

    pub fn samples(&self) -> u32 {
        self.samples
    }

    pub fn statistics(&self) -> Result<Statistics> {
        Statistics::read(&self.shader.accum, self.samples)
    }
}

impl IrradianceShader {
    /// The passes adding `spp` samples, from sample `first` on, to each of the first `points`
    /// points, tracing their rays or (`trace` false) taking each as a miss (0 points: a
    /// dispatch that only compiles the shader on a CPU driver).
    fn batch(&self, trace: bool, spp: u32, first: u32, points: u32) -> Vec<Pass<'_>> {
        let pipeline = &self.pipeline;
        let groups = [points.div_ceil(constants::IRRADIANCE_GROUP).max(1), 1, 1];
        let lighting = &self.lighting;
        let buffers = [
            &self.accum,
            &self.points,
            &lighting.lights,
            &self.radiance,
            &lighting.triangle_vertices,
            &self.rays,
        ];
        let push = |first, count| IrradiancePush {
            params: [points, first, count, self.seed],
            env: [lighting.env_total, 0.0, 0.0, 0.0],
            transport: [lighting.light_count, self.bounce as u32, u32::from(trace), 0],
        };
        super::sample_passes(spp, first, |first, count| {
            let (push, bindings) = (push(first, count), lighting.bindings(&buffers));
            Pass::new("reference_irradiance", move |cmd| {
                pipeline.dispatch(cmd, &bindings, bytes_of(&push), groups)
            })
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn points_parse_and_bad_input_is_named() {
        let file =
            PointsFile::parse(r#"{"points": [{"position": [0, 1, 2], "normal": [0, 2, 0]}]}"#).unwrap();
        assert_eq!(file.points[0].normal, [0.0, 2.0, 0.0]);
        for (text, expected) in [
            (r#"{"points": []}"#, "empty"),
            (r#"{"points": [{"position": [0, 0, 0], "normal": [0, 0, 0]}]}"#, "point 0 has a zero normal"),
            (r#"{"points": [{"position": [0, 0], "normal": [0, 1, 0]}]}"#, "points file"),
            (
                r#"{"points": [{"position": [0, 0, 0], "normal": [0, 1, 0], "radius": 1}]}"#,
                "unknown field `radius`",
            ),
            (r#"{"pts": []}"#, "unknown field `pts`"),
            ("not json", "points file"),
        ] {
            let err = PointsFile::parse(text).unwrap_err().to_string();
            assert!(err.contains(expected), "{text}: {err}");
        }
    }

    #[test]
    fn irradiance_file_round_trips() {
        let file = IrradianceFile {
            irradiance: vec![[1.0, 2.5, 3.0]],
            spp: 64,
            standard_error: vec![[0.125, 0.0, 1e-3]],
        };
        let text = serde_json::to_string(&file).unwrap();
        assert_eq!(serde_json::from_str::<IrradianceFile>(&text).unwrap(), file);
    }
}
