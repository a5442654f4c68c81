//! A captured probe set (Morishige 2014, steps 1–5): where the probes are, their
//! tetrahedralization, each probe's SH, and the SH interpolated at any point with the
//! tetrahedral weights.
use super::capture::{CaptureSettings, InvalidProbe, ProbeCapture};
use super::{TetMesh, Walker};
use crate::backend::Context;
use crate::error::{Error, Result};
use crate::renderer::GpuScene;
use crate::scene::Scene;
use crate::sh::ShRgb9;
use glam::{DVec3, Vec3};
use std::sync::Arc;

/// The group that moves and takes its light from the probes: the first, the one
/// `kage render --animate` moves. Every other group is static: captured by the probes and lit
/// by its own technique.
pub const MOVING_GROUP: usize = 0;

pub fn is_static(group: usize) -> bool {
    group != MOVING_GROUP
}

/// Most probes along each axis of a grid: 64³ captures would take hours on lavapipe.
pub const MAX_GRID: u32 = 64;

/// Where the probes go.
#[derive(Clone, Debug, PartialEq)]
pub enum ProbePlacement {
    /// NX × NY × NZ probes at the cell centres of that grid over the static groups' bounding
    /// box (never on its faces: walls are there), 2 to [`MAX_GRID`] along each axis.
    Grid([u32; 3]),
    /// Explicit world positions (`{"positions": [[x, y, z], ...]}` on the command line).
    Positions(Arc<[DVec3]>),
}

/// A small grid for a room: 18 probes, two layers.
pub const DEFAULT_GRID: [u32; 3] = [3, 2, 3];

impl Default for ProbePlacement {
    fn default() -> Self {
        ProbePlacement::Grid(DEFAULT_GRID)
    }
}

/// The probes' placement and capture.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ProbeSettings {
    pub placement: ProbePlacement,
    pub capture: CaptureSettings,
}

impl ProbeSettings {
    pub fn validated(self) -> Result<ProbeSettings> {
        if let ProbePlacement::Grid(counts) = self.placement {
            if counts.iter().any(|n| !(2..=MAX_GRID).contains(n)) {
                return Err(Error::InvalidArgument(format!(
                    "probe grid {counts:?}: each count must be 2 to {MAX_GRID} (a tetrahedralization needs probes in 3D)"
                )));
            }
        }
        self.capture.validated()?;
        Ok(self)
    }

    /// The probe positions in `scene`.
    pub fn positions(&self, scene: &Scene) -> Result<Vec<DVec3>> {
        match &self.placement {
            ProbePlacement::Positions(positions) => Ok(positions.to_vec()),
            ProbePlacement::Grid(counts) => {
                let (lo, hi) = static_bounds(scene).ok_or_else(|| {
                    Error::InvalidArgument(format!(
                        "scene \"{}\" has no static group to place a probe grid in (group {MOVING_GROUP} moves)",
                        scene.name
                    ))
                })?;
                let cell = (hi - lo) / Vec3::from(counts.map(|n| n as f32));
                let mut positions = Vec::new();
                for k in 0..counts[2] {
                    for j in 0..counts[1] {
                        for i in 0..counts[0] {
                            let centre = lo + cell * (Vec3::new(i as f32, j as f32, k as f32) + 0.5);
                            positions.push(centre.as_dvec3());
                        }
                    }
                }
                Ok(positions)
            }
        }
    }
}

/// The world bounding box of the static groups' vertices.
fn static_bounds(scene: &Scene) -> Option<(Vec3, Vec3)> {
    let points = scene.groups.iter().enumerate().filter(|(g, _)| is_static(*g)).flat_map(|(_, group)| {
        let m = group.transform.matrix();
        group
            .meshes
            .iter()
            .flat_map(move |mesh| mesh.positions.iter().map(move |p| m.transform_point3((*p).into())))
    });
    bounds(points)
}

/// The bounding box of `points`; `None` when there are none.
pub fn bounds(points: impl Iterator<Item = Vec3>) -> Option<(Vec3, Vec3)> {
    points.fold(None, |b, p| Some(b.map_or((p, p), |(lo, hi): (Vec3, Vec3)| (lo.min(p), hi.max(p)))))
}

pub struct ProbeSet {
    pub mesh: TetMesh,
    /// Each probe's radiance SH, in the order of the mesh's positions.
    pub sh: Vec<ShRgb9>,
    /// The probes left out because they are inside geometry ([`ProbeCapture::keep_valid`]): the
    /// mesh holds the others, in their order.
    pub invalid: Vec<InvalidProbe>,
}

impl ProbeSet {
    /// Places the probes, leaves out those inside geometry, tetrahedralizes the others and
    /// captures each (the static groups of `gpu`, which holds `scene`).
    pub fn capture(
        ctx: &Arc<Context>,
        scene: &Scene,
        gpu: &GpuScene,
        settings: &ProbeSettings,
    ) -> Result<ProbeSet> {
        let settings = settings.clone().validated()?;
        let mut capture = ProbeCapture::new(ctx, scene, settings.capture)?;
        let (positions, invalid) = capture.keep_valid(&settings.positions(scene)?);
        // A warning, not an error: the set still lights the scene without them.
        for probe in &invalid {
            let p = probe.position;
            eprintln!(
                "kage: warning: probe {} at ({}, {}, {}) is inside geometry ({:.0}% of its directions see back faces): left out",
                probe.index,
                p.x,
                p.y,
                p.z,
                100.0 * probe.back_faces
            );
        }
        let mesh = TetMesh::build(&positions)?;
        let sh =
            positions.iter().map(|p| capture.capture(gpu, is_static, p.as_vec3())).collect::<Result<_>>()?;
        Ok(ProbeSet { mesh, sh, invalid })
    }

    /// The SH at `p`: the probes' SH weighted by the tetrahedral (or, outside the hull,
    /// extrapolation) weights that `walker` finds from where it last stopped.
    pub fn interpolate(&self, walker: &mut Walker, p: Vec3) -> Result<ShRgb9> {
        let location = walker.locate(&self.mesh, p.as_dvec3())?;
        let mut sum = ShRgb9::default();
        for (&probe, &w) in location.probes.iter().zip(&location.weights) {
            for (total, c) in sum.c.iter_mut().zip(&self.sh[probe as usize].c) {
                for (t, v) in total.iter_mut().zip(c) {
                    *t += w as f32 * v;
                }
            }
        }
        Ok(sum)
    }
}
