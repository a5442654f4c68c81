//! The reference's irradiance mode: E(p, n) = ∫ L_env(ω) V(ω) max(n·ω, 0) dω at listed points
//! and normals (environment light, full visibility, the same MIS estimator as the renderer),
//! one compute invocation per point (shaders-glsl/reference_irradiance.comp). Light probes are
//! checked against it.
//!
//! Input file: `{"points": [{"position": [x, y, z], "normal": [x, y, z]}, ...]}` (normals are
//! normalised; unknown fields are errors). Output: `{"irradiance": [[r, g, b], ...], "spp": N,
//! "standard_error": [[r, g, b], ...]}`, in the input's order.
use super::lighting::{ReferenceLighting, IMPORTS};
use super::statistics::{accum_buffer, samples_after, Statistics};
use crate::backend::{vk, BindingKind, Buffer, ComputePipeline, Context};
use crate::error::{Error, Result};
use crate::layouts::{bytes_of, bytes_of_slice, constants, spirv, IrradiancePoint, IrradiancePush};
use crate::pass::{FrameExecutor, Pass};
use crate::scene::Scene;
use glam::Vec3;
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
    count: u32,
    seed: u32,
    samples: u32,
    executor: FrameExecutor,
}

impl IrradianceReference {
    pub fn new(
        ctx: &Arc<Context>,
        scene: &Scene,
        points: &[Point],
        seed: u32,
    ) -> Result<IrradianceReference> {
        check_points(points)?;
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
                &ReferenceLighting::binding_kinds(&[BindingKind::StorageBuffer, BindingKind::StorageBuffer]),
                size_of::<IrradiancePush>() as u32,
            )?,
            points: Buffer::with_data(
                ctx,
                "irradiance_points",
                vk::BufferUsageFlags::STORAGE_BUFFER,
                bytes_of_slice(&gpu_points),
            )?,
            accum: accum_buffer(ctx, "irradiance_accum", points.len())?,
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
        let (lighting, accum, points) = (&self.lighting, &self.accum, &self.points);
        let (count_points, seed, env_total) = (self.count, self.seed, self.lighting.env_total);
        let passes = super::sample_passes(spp, self.samples, |first, count| {
            let push = IrradiancePush {
                params: [count_points, first, count, seed],
                env: [env_total, 0.0, 0.0, 0.0],
            };
            let bindings = lighting.bindings(&[accum, points]);
            Pass::new("reference_irradiance", &IMPORTS, &["irradiance_accum"], move |cmd| {
                pipeline.dispatch(cmd, &bindings, bytes_of(&push), groups)
            })
        });
        self.executor.run(&IMPORTS, passes)?;
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
