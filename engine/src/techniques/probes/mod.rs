//! Light probes (Morishige 2014; ../shared/papers/README.md, section 3): the geometry.
//!
//! [`TetMesh::build`] tetrahedralizes the probe positions (3D Delaunay, incremental, with exact
//! orientation and in-sphere predicates and a symbolic perturbation for cospherical sets such as
//! grids); a [`Walker`] finds the tetrahedron that holds a point by walking from the previous
//! one, and gives the barycentric weights of its four probes. Outside the convex hull the weights
//! are those of the hull's nearest point ([`Location::extrapolated`]), continuous across the hull.
//!
//! Duplicate positions are merged, keeping the first ([`TetMesh::merged`]); fewer than four
//! distinct positions, or all of them in one plane, is an error ([`ProbeError`]): there is no
//! lower-dimensional fallback.
mod capture;
mod delaunay;
mod error;
mod extrapolate;
mod input;
mod lookup;
mod predicates;
mod rng;
mod spatial_sort;
#[cfg(test)]
mod tests;
mod tetmesh;

pub use capture::{CaptureSettings, CapturedLight, ProbeCapture, CUBE_SIZES, DEFAULT_CUBE_SIZE};
pub use error::ProbeError;
pub use input::Merged;
pub use lookup::{Location, Walker};
pub use tetmesh::{Across, TetMesh};
