//! Light probes (Morishige 2014).
//!
//! Capture ([`ProbeCapture`]): a cube map of the scene at each probe projected to SH on the GPU;
//! [`ProbeSet`]: placement, capture and interpolation; [`ProbeGroups`]: which groups move (those
//! with keyframes, wherever they are in the scene; a scene without any moves its first group)
//! and which are static (captured by the probes, lit by their own technique); [`technique`]:
//! each moving group lit by the probes with its own lookup. The geometry:
//!
//! Automatic placement ([`ProbePlacement::Auto`]) captures a dense set of candidates, keeps
//! those the others cannot reproduce ([`reduce`]), moves each kept one to the nearby candidate
//! that lowers the error over all candidates ([`relocate`]) and fits the kept ones' SH to every
//! candidate's capture ([`fit`]); a regular grid with trilinear interpolation
//! ([`Lattice`], [`ProbeInterpolation::Trilinear`]) is the baseline it is measured against
//! (`kage bench probe-count`).
//!
//! [`TetMesh::build`] tetrahedralizes the probe positions (3D Delaunay, incremental, with exact
//! orientation and in-sphere predicates and a symbolic perturbation for cospherical sets such as
//! grids); a [`Walker`] finds the tetrahedron that holds a point by walking from the previous
//! one, and gives the barycentric weights of its four probes. Outside the convex hull the weights
//! are those of the hull's nearest point ([`Location::extrapolated`]), continuous across the hull.
//! With [`ProbeVisibility::Rays`] (the default) the probes the point cannot see through the
//! static groups lose their weight ([`Occluders`]): no light through walls.
//!
//! Duplicate positions are merged, keeping the first ([`TetMesh::merged`]); fewer than four
//! distinct positions, or all of them in one plane, is an error
//! ([`ProbeError`](crate::error::ProbeError)): there is no lower-dimensional fallback.
mod capture;
mod delaunay;
mod dering;
mod detour;
mod extrapolate;
pub mod fit;
mod input;
mod lookup;
pub mod positions_file;
mod predicates;
mod reduce;
mod relocate;
mod rng;
mod set;
mod solids;
mod spatial_sort;
pub mod technique;
#[cfg(test)]
mod tests;
mod tetmesh;
mod trilinear;
mod visibility;

pub use capture::{
    CaptureCost, CaptureSettings, CapturedLight, InvalidProbe, ProbeCapture, BACK_FACE_RAYS, CUBE_SIZES,
    DEFAULT_CUBE_SIZE, DEFAULT_SAMPLES, MAX_BACK_FACES, RADIANCE_SEED,
};
pub use dering::Dering;
pub use input::{check_count, Merged, MAX_PROBES};
pub use lookup::{Location, Walker};
pub use reduce::reduce;
pub use relocate::relocate;
pub use set::{
    bounds, capture_at, grid_lattice, open_to_probes, Lookup, ProbeCounts, ProbeGroups, ProbeInterpolation,
    ProbePlacement, ProbeSet, ProbeSettings, StaticLighting, AUTO_CANDIDATES, DEFAULT_GRID,
    DEFAULT_TOLERANCE, MAX_GRID,
};
pub use solids::{Hit, Solids};
pub use tetmesh::{Across, TetMesh};
pub use trilinear::Lattice;
pub use visibility::{
    LookupCounts, Occluders, ProbeVisibility, Seen, Visibility, NEAREST_TRIES, RAYS_PER_PROBE,
};
