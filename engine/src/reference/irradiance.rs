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
use crate::pass::{FrameExecutor, Pass};
use crate::scene::Scene;
use glam::{Mat4, Vec3};
use serde::{Deserialize, Serialize};
use std::sync::Arc;

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
    lighting: ReferenceLighting,
    pipeline: ComputePipeline,
    points: Buffer,
    accum: Buffer,
    /// Per scene vertex, the radiance the surfaces reflect (a bounce), or one unused entry.
    radiance: Buffer,
    bounce: bool,
    count: u32,
    seed: u32,
    samples: u32,
    executor: FrameExecutor,
}

/// Most bounces the reference and the probes' capture compute.
pub const MAX_BOUNCES: u32 = 2;

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
) -> Result<Option<Vec<[f32; 4]>>> {
    check_bounces(bounces)?;
    if bounces > 0 && samples == 0 {
        return Err(Error::InvalidArgument(format!(
            "{bounces} bounces with 0 samples per vertex: the surfaces' radiance needs at least 1"
        )));
    }
    let points = vertex_points(scene);
    if points.is_empty() {
        return Ok((bounces > 0).then(Vec::new));
    }
    let albedo: Vec<[f32; 3]> =
        scene.meshes().flat_map(|(_, mesh)| std::iter::repeat_n(mesh.albedo, mesh.positions.len())).collect();
    let mut radiance: Option<Vec<[f32; 4]>> = None;
    for pass in 0..bounces {
        let mut reference = IrradianceReference::with_radiance(
            ctx,
            scene,
            &points,
            seed.wrapping_add(pass),
            radiance.as_deref(),
        )?;
        for batch in (0..samples).step_by(RADIANCE_BATCH as usize) {
            reference.run_batch((samples - batch).min(RADIANCE_BATCH))?;
        }
        let e = reference.statistics()?.mean;
        radiance = Some(
            e.iter()
                .zip(&albedo)
                .map(|(e, a)| {
                    let [r, g, b] = [0, 1, 2].map(|k| a[k] / std::f32::consts::PI * e[k]);
                    [r, g, b, 0.0]
                })
                .collect(),
        );
    }
    Ok(radiance)
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
        Ok(IrradianceReference {
            lighting: ReferenceLighting::new(ctx, scene)?,
            pipeline: ComputePipeline::new(
                ctx,
                "reference_irradiance",
                spirv::REFERENCE_IRRADIANCE_COMP,
                &ReferenceLighting::binding_kinds(&[BindingKind::StorageBuffer; 5]),
                size_of::<IrradiancePush>() as u32,
            )?,
            points: Buffer::with_data(
                ctx,
                "irradiance_points",
                BufferUsage::STORAGE,
                bytes_of_slice(&gpu_points),
            )?,
            accum: accum_buffer(ctx, "irradiance_accum", points.len())?,
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
            samples: 0,
            executor: FrameExecutor::new(ctx, "reference_irradiance")?,
        })
    }

    /// Adds `spp` samples per point in one submission.
    pub fn run_batch(&mut self, spp: u32) -> Result<()> {
        let after = samples_after(self.samples, spp, "point")?;
        let groups = [self.count.div_ceil(constants::IRRADIANCE_GROUP), 1, 1];
        let pipeline = &self.pipeline;
        let (lighting, accum, points, radiance) = (&self.lighting, &self.accum, &self.points, &self.radiance);
        let (count_points, seed, env_total) = (self.count, self.seed, self.lighting.env_total);
        let transport = [self.lighting.light_count, self.bounce as u32, 0, 0];
        let passes = super::sample_passes(spp, self.samples, |first, count| {
            let push = IrradiancePush {
                params: [count_points, first, count, seed],
                env: [env_total, 0.0, 0.0, 0.0],
                transport,
            };
            let bindings =
                lighting.bindings(&[accum, points, &lighting.lights, radiance, &lighting.triangle_vertices]);
            Pass::new("reference_irradiance", move |cmd| {
                pipeline.dispatch(cmd, &bindings, bytes_of(&push), groups)
            })
        });
        self.executor.run(passes)?;
        self.samples = after;
        Ok(())
    }

    pub fn samples(&self) -> u32 {
        self.samples
    }

    pub fn statistics(&self) -> Result<Statistics> {
        Statistics::read(&self.accum, self.samples)
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
