//! Precomputed radiance transfer (Sloan, Kautz, Snyder 2002): per-vertex transfer vectors with
//! self-visibility, the base of the Tamura–Johan–Nishita soft shadows.
//!
//! For vertex `x` with normal `n`, coefficient `i = l(l + 1) + m` of its transfer vector is
//! `T_i(x) = ∫ (1/π) v_s(x, ω) max(ω·n, 0) y_i(ω) dω` (the paper's eq. (5) with ρ = 1), where
//! `v_s` is binary visibility against the vertex's own group only ([`Visibility::Group`]), or
//! against the whole scene at rest ([`Visibility::Scene`]), in the group's object space.
//!
//! Two choices keep the data small and reusable:
//! - The albedo is left out (ρ = 1): a mesh has one RGB albedo, so the shader multiplies it in
//!   and the transfer stays one channel, a third of the size of an RGB transfer.
//! - Object space: the transfer rotates with its group, so moving a group never invalidates
//!   it; the renderer rotates the environment's SH into the group's frame instead.
//!
//! [`transfer`] computes a [`TransferSet`] on the GPU, [`buried`] mends the vertices that lie
//! inside their own mesh, [`cache`] stores it on disk, [`lobe`] gives the unshadowed
//! transfer in closed form (the check for convex objects) and [`directions`] the rays the
//! shader casts.
pub mod buried;
pub mod cache;
pub mod directions;
pub mod lobe;
pub mod transfer;

use crate::error::{Error, Result};
use crate::scene::Scene;

/// The fewest SH bands the precomputation produces: 2 bands are the least that carry direction.
pub const MIN_BANDS: u32 = 2;
/// The most: what `sh.rs` and the shader's basis evaluate.
pub const MAX_BANDS: u32 = crate::sh::MAX_BANDS as u32;
/// Upper bound on rays per vertex, far beyond where the Monte Carlo error stops mattering, low
/// enough that a typo cannot ask for days of work.
pub const MAX_RAYS: u32 = 1 << 20;

/// What a vertex's transfer is shadowed by.
#[repr(u32)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, strum::FromRepr)]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
pub enum Visibility {
    /// Its own group only: the transfer holds whatever pose the groups take (Sloan's PRT as
    /// the Tamura technique uses it).
    #[default]
    Group = 0,
    /// The whole scene at its rest pose (the groups' transforms in the scene): Sloan's PRT as
    /// the paper compares against, the shadows between groups baked into the receivers'
    /// vertices, and wrong once a group moves.
    Scene = 1,
}

/// What to precompute, each parameter defined here once: the command line takes the bands and
/// rays as options (these comments are their help), the C ABI as `kage_technique_desc` fields.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "clap", derive(clap::Args))]
pub struct PrtParams {
    /// SH bands of the PRT transfer, 2 to 5 (bands² coefficients per vertex).
    #[cfg_attr(feature = "clap", arg(long, default_value_t = PrtParams::DEFAULT.bands))]
    pub bands: u32,
    /// Visibility rays per vertex of the PRT precomputation.
    #[cfg_attr(feature = "clap", arg(long, default_value_t = PrtParams::DEFAULT.rays))]
    pub rays: u32,
    /// Against what visibility is tested: set by the technique that needs the transfer.
    #[cfg_attr(feature = "clap", arg(skip = PrtParams::DEFAULT.visibility))]
    pub visibility: Visibility,
}

impl PrtParams {
    /// 3 bands as in the paper; 2048 rays keep the unshadowed error of every coefficient below
    /// 1e-3 (the quasi-Monte Carlo error falls about as 1/N: ~5e-4 at 1024, ~1e-4 at 4096).
    pub const DEFAULT: PrtParams = PrtParams { bands: 3, rays: 2048, visibility: Visibility::Group };

    pub fn validated(self) -> Result<PrtParams> {
        if !(MIN_BANDS..=MAX_BANDS).contains(&self.bands) {
            return Err(Error::InvalidArgument(format!(
                "PRT with {} SH bands: Kage supports {MIN_BANDS} to {MAX_BANDS}",
                self.bands
            )));
        }
        if !(1..=MAX_RAYS).contains(&self.rays) {
            return Err(Error::InvalidArgument(format!(
                "PRT with {} rays per vertex: must be 1 to {MAX_RAYS}",
                self.rays
            )));
        }
        Ok(self)
    }

    /// Coefficients per vertex.
    pub fn coeffs(&self) -> usize {
        (self.bands * self.bands) as usize
    }
}

impl Default for PrtParams {
    fn default() -> Self {
        PrtParams::DEFAULT
    }
}

/// The transfer of one mesh.
#[derive(Clone, Debug, PartialEq)]
pub struct MeshTransfer {
    /// Index of the mesh's group in [`Scene::groups`].
    pub group: usize,
    /// Index of the mesh in its group's `meshes`.
    pub mesh: usize,
    /// `bands²` coefficients per vertex, vertex-major, in the mesh's vertex order.
    pub coefficients: Vec<f32>,
}

/// The transfer of every vertex of a scene.
#[derive(Clone, Debug, PartialEq)]
pub struct TransferSet {
    pub params: PrtParams,
    /// Wall-clock seconds the precomputation took (when loaded from a cache: when it was made).
    pub seconds: f64,
    /// Of those, the seconds spent tracing rays: the transfer jobs' time (submission to
    /// completion) less the same jobs' time with tracing switched off (every ray taken as a
    /// miss, so the rest of their work is if anything overcounted).
    pub traversal_seconds: f32,
    /// One per mesh, in scene order (groups, then meshes within a group).
    pub meshes: Vec<MeshTransfer>,
}

impl TransferSet {
    pub fn vertex_count(&self) -> usize {
        self.meshes.iter().map(|m| m.coefficients.len() / self.params.coeffs()).sum()
    }

    /// Bytes of coefficient data (f32), what the GPU would hold.
    pub fn data_bytes(&self) -> usize {
        self.meshes.iter().map(|m| m.coefficients.len() * 4).sum()
    }

    /// The coefficients of one vertex; `None` out of range.
    pub fn vertex(&self, group: usize, mesh: usize, vertex: usize) -> Option<&[f32]> {
        let n = self.params.coeffs();
        let m = self.meshes.iter().find(|m| m.group == group && m.mesh == mesh)?;
        m.coefficients.get(vertex * n..(vertex + 1) * n)
    }
}

/// Every mesh of `scene` as (group, mesh, vertex count), in scene order: the layout a
/// [`TransferSet`] of the scene has.
pub(crate) fn mesh_layout(scene: &Scene) -> Vec<(usize, usize, usize)> {
    scene
        .groups
        .iter()
        .enumerate()
        .flat_map(|(g, group)| {
            group.meshes.iter().enumerate().map(move |(m, mesh)| (g, m, mesh.vertex_count()))
        })
        .collect()
}
