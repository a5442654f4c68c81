//! A captured probe set (Morishige 2014, steps 1–5): where the probes are, their
//! tetrahedralization, each probe's SH, and the SH interpolated at any point with the
//! tetrahedral weights.
use super::capture::{CaptureCost, CaptureSettings, InvalidProbe, ProbeCapture};
use super::fit::fit;
use super::reduce::{blend, reduce};
use super::relocate::relocate;
use super::solids::Solids;
use super::trilinear::Lattice;
use super::visibility::{weigh_by_visibility, Occluders, ProbeVisibility, Seen, Visibility};
use super::{TetMesh, Walker};
use crate::backend::Context;
use crate::error::{Error, Result};
use crate::frame::GpuScene;
use crate::progress::Progress;
use crate::scene::Scene;
use crate::sh::ShRgb9;
use glam::{DVec3, Vec3};
use std::sync::Arc;

/// Which groups of a scene move and take their light from the probes, and which are static:
/// captured by the probes and lit by their own technique ([`StaticLighting`]).
///
/// The moving groups are those with a motion ([`crate::scene::Group::motion`]: keyframes),
/// wherever they stand in the scene's list: Blender writes its nodes in creation order, so the
/// animated object may well come after the ground. Each one looks its light up on its own
/// (its own centre, its own interpolated SH).
///
/// A scene where no group has a motion (one built from a C host's arrays, which moves its groups
/// with `kage_renderer_set_group_transform`, or a scene file without keyframes) falls back to
/// its first group alone as the moving one, the rule before keyframes existed;
/// [`ProbeGroups::fallback`] says so, and the technique prints a note. Every built-in scene's
/// first group has a motion (the hop), so for them both rules agree.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ProbeGroups {
    /// The moving groups' indices, increasing.
    moving: Vec<usize>,
    fallback: bool,
}

impl ProbeGroups {
    pub fn of(scene: &Scene) -> ProbeGroups {
        let moving: Vec<usize> =
            (0..scene.groups.len()).filter(|&g| scene.groups[g].motion.is_some()).collect();
        if moving.is_empty() && !scene.groups.is_empty() {
            return ProbeGroups { moving: vec![0], fallback: true };
        }
        ProbeGroups { moving, fallback: false }
    }

    /// The moving groups' indices, in the scene's order.
    pub fn moving(&self) -> &[usize] {
        &self.moving
    }

    pub fn is_moving(&self, group: usize) -> bool {
        self.moving.binary_search(&group).is_ok()
    }

    pub fn is_static(&self, group: usize) -> bool {
        !self.is_moving(group)
    }

    /// No group has a motion: the first is the moving one (see [`ProbeGroups`]).
    pub fn fallback(&self) -> bool {
        self.fallback
    }

    /// The moving groups named for a message: `group 0 ("bunny"), group 2 ("ball")`.
    pub fn describe(&self, scene: &Scene) -> String {
        let name = |g: usize| format!("group {g} (\"{}\")", scene.groups[g].name);
        self.moving.iter().map(|&g| name(g)).collect::<Vec<_>>().join(", ")
    }
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
    /// Automatic: the cell centres of a `candidates` grid over the static groups' bounding box
    /// that are not inside a solid ([`Solids`]) nor sealed in a pocket ([`Occluders::sealed`])
    /// are captured, then those that the others
    /// reproduce by tetrahedral interpolation within `tolerance` are dropped (see
    /// [`super::reduce`]), the kept ones moved to nearby candidates while that lowers the error
    /// over all of them ([`super::relocate`]) and their SH fitted to every capture
    /// ([`super::fit`]). `None` candidates: [`AUTO_CANDIDATES`] along the box's longest side,
    /// proportionally fewer along the others.
    Auto { tolerance: f32, candidates: Option<[u32; 3]> },
}

/// Candidates along the longest side of the box in automatic placement.
pub const AUTO_CANDIDATES: u32 = 8;
/// Automatic placement's tolerance when none is given: 5% of the candidates' mean irradiance.
pub const DEFAULT_TOLERANCE: f32 = 0.05;

/// How the light between probes is found.
#[repr(u32)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, strum::FromRepr)]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
pub enum ProbeInterpolation {
    /// Barycentric weights of the Delaunay tetrahedron holding the point (Morishige 2014).
    #[default]
    Tetrahedral = 0,
    /// Trilinear weights of the grid cell holding the point: a [`ProbePlacement::Grid`] only.
    Trilinear = 1,
}

/// A small grid for a room: 18 probes, two layers.
pub const DEFAULT_GRID: [u32; 3] = [3, 2, 3];

impl Default for ProbePlacement {
    fn default() -> Self {
        ProbePlacement::Grid(DEFAULT_GRID)
    }
}

/// How the static groups are lit in the frame the probes light the moving groups in.
#[repr(u32)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, strum::FromRepr)]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
pub enum StaticLighting {
    /// The environment's SH irradiance, unshadowed.
    #[default]
    Unshadowed = 0,
    /// Sloan's PRT: self-shadowed by the static groups (needs the PRT precomputation).
    Sloan = 1,
}

/// The probes' placement and capture, and the static groups' lighting beside them, each
/// setting defined here once: the command line's `--probe-*` options (these comments are
/// their help; the placement is `kage render --probes`, resolved against the scene), the C
/// ABI's `probe_*` fields.
#[derive(Clone, Debug, Default, PartialEq)]
#[cfg_attr(feature = "clap", derive(clap::Args))]
pub struct ProbeSettings {
    #[cfg_attr(feature = "clap", arg(skip))]
    pub placement: ProbePlacement,
    #[cfg_attr(feature = "clap", command(flatten))]
    pub capture: CaptureSettings,
    /// How the light between probes is found: `trilinear` needs a `grid:` placement.
    #[cfg_attr(feature = "clap", arg(long = "probe-interpolation", value_enum, default_value_t = ProbeInterpolation::default()))]
    pub interpolation: ProbeInterpolation,
    /// Whether a moving group's lookup leaves out the probes its centre cannot see through the
    /// static groups (`rays`), so that no light comes through walls.
    #[cfg_attr(feature = "clap", arg(long = "probe-visibility", value_enum, default_value_t = ProbeVisibility::default()))]
    pub visibility: ProbeVisibility,
    /// How the probes technique lights the static groups beside the probe-lit moving ones.
    #[cfg_attr(feature = "clap", arg(long = "probe-statics", value_enum, default_value_t = StaticLighting::default()))]
    pub statics: StaticLighting,
}

impl ProbeSettings {
    pub fn validated(self) -> Result<ProbeSettings> {
        let grid = match self.placement {
            ProbePlacement::Grid(counts) => Some(("probe grid", counts)),
            ProbePlacement::Auto { candidates, .. } => candidates.map(|c| ("probe candidate grid", c)),
            ProbePlacement::Positions(_) => None,
        };
        if let Some((what, counts)) = grid {
            if counts.iter().any(|n| !(2..=MAX_GRID).contains(n)) {
                return Err(Error::InvalidArgument(format!(
                    "{what} {counts:?}: each count must be 2 to {MAX_GRID} (a tetrahedralization needs probes in 3D)"
                )));
            }
        }
        if let ProbePlacement::Auto { tolerance, .. } = self.placement {
            if !(tolerance.is_finite() && tolerance > 0.0) {
                return Err(Error::InvalidArgument(format!(
                    "automatic probe placement: tolerance {tolerance} must be a positive number (a relative irradiance error, such as 0.05)"
                )));
            }
        }
        if self.interpolation == ProbeInterpolation::Trilinear
            && !matches!(self.placement, ProbePlacement::Grid(_))
        {
            return Err(Error::InvalidArgument(
                "trilinear probe interpolation needs a probe grid (grid:NX,NY,NZ)".into(),
            ));
        }
        self.capture.validated()?;
        Ok(self)
    }

    /// The probe positions in `scene`; for automatic placement, the candidates that are
    /// [`open_to_probes`] (`occluders`: `scene`'s static groups, [`Occluders::of_static`]).
    pub fn positions(&self, scene: &Scene, occluders: &Occluders) -> Result<Vec<DVec3>> {
        match &self.placement {
            ProbePlacement::Positions(positions) => Ok(positions.to_vec()),
            ProbePlacement::Grid(counts) => Ok(grid_lattice(scene, *counts)?.positions()),
            ProbePlacement::Auto { candidates, .. } => {
                let counts = match candidates {
                    Some(counts) => *counts,
                    None => {
                        let (lo, hi) = static_bounds_of(scene)?;
                        let extent = hi - lo;
                        let along = |e: f32| {
                            ((AUTO_CANDIDATES as f32 * e / extent.max_element()).round() as u32)
                                .clamp(2, MAX_GRID)
                        };
                        extent.to_array().map(along)
                    }
                };
                let solids = Solids::of_static(scene);
                let lattice = grid_lattice(scene, counts)?;
                Ok(lattice
                    .positions()
                    .into_iter()
                    .filter(|&p| open_to_probes(&solids, occluders, p))
                    .collect())
            }
        }
    }
}

/// Whether automatic placement may keep a candidate at `p`: outside the solids, and not sealed
/// in a pocket of free space ([`Occluders::sealed`]).
pub fn open_to_probes(solids: &Solids, occluders: &Occluders, p: DVec3) -> bool {
    !solids.contains(p.as_vec3()) && !occluders.sealed(p)
}

/// The cell centres of a `counts` grid over the static groups' bounding box. Along an axis
/// where that box is flat (a floor alone) every probe would lie in one plane, which no
/// tetrahedron spans: there the grid spans the whole scene's box instead, the moving groups as
/// the scene places them included.
pub fn grid_lattice(scene: &Scene, counts: [u32; 3]) -> Result<Lattice> {
    let (mut lo, mut hi) = static_bounds_of(scene)?;
    let (all_lo, all_hi) = world_bounds(scene, |_| true).unwrap_or((lo, hi));
    let extent = hi - lo;
    for axis in 0..3 {
        if extent[axis] <= FLAT * extent.max_element() {
            (lo[axis], hi[axis]) = (all_lo[axis], all_hi[axis]);
        }
    }
    Ok(Lattice::cell_centres(lo, hi, counts))
}

/// A box side at most this fraction of its longest is flat (for [`grid_lattice`]).
const FLAT: f32 = 1e-3;

fn static_bounds_of(scene: &Scene) -> Result<(Vec3, Vec3)> {
    let groups = ProbeGroups::of(scene);
    world_bounds(scene, |g| groups.is_static(g)).ok_or_else(|| {
        let why = if groups.fallback() {
            ": no group has keyframes, so the first one is the moving one"
        } else {
            ""
        };
        Error::InvalidArgument(format!(
            "scene \"{}\" has no static group to place probes in (moving: {}{why})",
            scene.name,
            groups.describe(scene)
        ))
    })
}

/// The world bounding box of the vertices of the groups `keep` takes (by index).
fn world_bounds(scene: &Scene, keep: impl Fn(usize) -> bool) -> Option<(Vec3, Vec3)> {
    let points = scene.groups.iter().enumerate().filter(|(g, _)| keep(*g)).flat_map(|(_, group)| {
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

/// What a probe set kept of the positions its placement gave.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ProbeCounts {
    /// Probes the set interpolates.
    pub kept: usize,
    /// Probes captured (outside geometry): automatic placement keeps `kept` of them, the other
    /// placements all.
    pub candidates: usize,
    /// Positions left out because they lie inside geometry.
    pub inside_geometry: usize,
}

pub struct ProbeSet {
    pub mesh: TetMesh,
    /// Each probe's radiance SH, in the order of the mesh's positions.
    pub sh: Vec<ShRgb9>,
    /// The grid, when the interpolation is trilinear; `None`: tetrahedral.
    pub trilinear: Option<Lattice>,
    /// Probes captured before automatic placement dropped the redundant ones (the probe count
    /// for the other placements).
    pub candidates: usize,
    /// The probes left out because they are inside geometry ([`ProbeCapture::keep_valid`]): the
    /// mesh holds the others, in their order.
    pub invalid: Vec<InvalidProbe>,
    /// What hides probes from a lookup point ([`ProbeVisibility::Rays`]); `None`: every probe
    /// of the cell weighs.
    pub visibility: Option<Visibility>,
    /// What [`ProbeSet::capture`] took; `None` for a set made from SH given.
    pub capture_cost: Option<CaptureCost>,
}

/// (probe, weight) pairs: a grid cell's eight, or a tetrahedron's four and four of weight 0.
pub type Weights = [(usize, f64); 8];

/// The interpolation's weights at a point and what its visibility test did.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Lookup {
    pub weights: Weights,
    pub seen: Seen,
}

impl ProbeSet {
    /// Places the probes, leaves out those inside geometry, tetrahedralizes the others and
    /// captures each (the static groups of `gpu`, which holds `scene`). `progress` hears the
    /// probes captured, one more unit for the placement after them, and may stop the work.
    pub fn capture(
        ctx: &Arc<Context>,
        scene: &Scene,
        gpu: &GpuScene,
        settings: &ProbeSettings,
        progress: &mut Progress,
    ) -> Result<ProbeSet> {
        let settings = settings.clone().validated()?;
        let mut capture = ProbeCapture::new(ctx, scene, settings.capture)?;
        // One BVH and one free-space grid for the placement's candidates and the lookups.
        let occluders = Arc::new(capture.occluders());
        let (positions, invalid) = capture.keep_valid(&settings.positions(scene, &occluders)?);
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
        let candidates = positions.len();
        let cancelled = || Error::Cancelled("the light probes' capture");
        let groups = ProbeGroups::of(scene);
        let mut sh: Vec<ShRgb9> = Vec::with_capacity(candidates);
        for p in &positions {
            if !progress(sh.len(), candidates + 1) {
                return Err(cancelled());
            }
            sh.push(capture.capture(gpu, |g| groups.is_static(g), p.as_vec3())?);
        }
        if !progress(candidates, candidates + 1) {
            return Err(cancelled());
        }
        let occluders = (settings.visibility == ProbeVisibility::Rays).then_some(occluders);
        let set = match (&settings.placement, settings.interpolation) {
            (ProbePlacement::Auto { tolerance, .. }, _) => {
                ProbeSet::placed(&positions, &sh, *tolerance, occluders.clone())?
            }
            (ProbePlacement::Grid(counts), ProbeInterpolation::Trilinear) => {
                // A lattice needs every corner: a probe left out leaves a hole no weight fills.
                if let Some(probe) = invalid.first() {
                    return Err(Error::InvalidArgument(format!(
                        "trilinear interpolation needs every grid probe, and probe {} at {} is inside geometry: use tetrahedral interpolation",
                        probe.index, probe.position
                    )));
                }
                ProbeSet::trilinear(grid_lattice(scene, *counts)?, sh)?
            }
            _ => ProbeSet::tetrahedral(&positions, sh)?,
        };
        if let Some(occluders) = &occluders {
            occluders.keep_ways_of(set.mesh.positions());
        }
        let mut set = set.seeing(occluders);
        set.candidates = candidates;
        set.invalid = invalid;
        set.capture_cost = Some(capture.cost());
        progress(candidates + 1, candidates + 1);
        Ok(set)
    }

    /// Tetrahedral interpolation of the SH captured at `positions`.
    pub fn tetrahedral(positions: &[DVec3], sh: Vec<ShRgb9>) -> Result<ProbeSet> {
        let candidates = positions.len();
        Ok(ProbeSet {
            mesh: TetMesh::build(positions)?,
            sh,
            trilinear: None,
            candidates,
            invalid: Vec::new(),
            visibility: None,
            capture_cost: None,
        })
    }

    /// Trilinear interpolation of the SH captured at the positions of `lattice`.
    pub fn trilinear(lattice: Lattice, sh: Vec<ShRgb9>) -> Result<ProbeSet> {
        let mut set = ProbeSet::tetrahedral(&lattice.positions(), sh)?;
        set.trilinear = Some(lattice);
        Ok(set)
    }

    /// Automatic placement at `tolerance` from the SH captured at `positions`, as the engine
    /// runs it: the probes [`reduce`] keeps, moved by [`relocate`], their SH fitted to `sh`;
    /// with `occluders`, the relocation and the fit weigh probes by visibility as the set's
    /// lookups then do (the reduction does not yet).
    pub fn placed(
        positions: &[DVec3],
        sh: &[ShRgb9],
        tolerance: f32,
        occluders: Option<Arc<Occluders>>,
    ) -> Result<ProbeSet> {
        let kept = relocate(positions, sh, reduce(positions, sh, tolerance)?, occluders.as_ref())?;
        ProbeSet::kept(positions, sh, &kept)?.seeing(occluders).fitted(positions, sh)
    }

    /// Tetrahedral interpolation of the SH captured at those of `positions` that `kept` indexes:
    /// with the indices [`reduce`] keeps, the first step of [`ProbeSet::placed`], measured alone
    /// by `kage bench probe-count`.
    pub fn kept(positions: &[DVec3], sh: &[ShRgb9], kept: &[usize]) -> Result<ProbeSet> {
        let points: Vec<DVec3> = kept.iter().map(|&i| positions[i]).collect();
        let mut set = ProbeSet::tetrahedral(&points, kept.iter().map(|&i| sh[i]).collect())?;
        set.candidates = positions.len();
        Ok(set)
    }

    /// The set with its probes' SH fitted by least squares to `captured`, the SH captured at
    /// each of `positions` (see [`super::fit`]), with the weights its lookups give (by
    /// visibility when it has occluders).
    pub fn fitted(self, positions: &[DVec3], captured: &[ShRgb9]) -> Result<ProbeSet> {
        let rows = self.rows(positions)?;
        self.fitted_by(&rows, captured)
    }

    /// The set whose lookups weigh probes by how much of them the point sees through
    /// `occluders` (`None`: not at all).
    pub fn seeing(mut self, occluders: Option<Arc<Occluders>>) -> ProbeSet {
        self.visibility = occluders.map(|o| Visibility::new(o, self.mesh.positions()));
        self
    }

    /// The interpolation's (probe, weight) pairs of weight other than 0 at each of `positions`.
    pub(super) fn rows(&self, positions: &[DVec3]) -> Result<Vec<Vec<(usize, f64)>>> {
        let mut walker = Walker::default();
        positions
            .iter()
            .map(|&p| {
                let weights = self.lookup(&mut walker, p)?.weights;
                Ok(weights.into_iter().filter(|&(_, w)| w != 0.0).collect())
            })
            .collect()
    }

    /// [`ProbeSet::fitted`] to `captured` at the positions whose [`ProbeSet::rows`] are `rows`.
    pub(super) fn fitted_by(mut self, rows: &[Vec<(usize, f64)>], captured: &[ShRgb9]) -> Result<ProbeSet> {
        self.sh = fit(rows, captured, &self.sh)?;
        Ok(self)
    }

    /// The probes the set interpolates.
    pub fn probe_count(&self) -> usize {
        self.sh.len()
    }

    /// How many probes were placed, left out and kept.
    pub fn counts(&self) -> ProbeCounts {
        ProbeCounts {
            kept: self.probe_count(),
            candidates: self.candidates,
            inside_geometry: self.invalid.len(),
        }
    }

    /// The SH at `p`: [`ProbeSet::blend`] of the [`ProbeSet::lookup`] there.
    pub fn interpolate(&self, walker: &mut Walker, p: Vec3) -> Result<ShRgb9> {
        Ok(self.blend(&self.lookup(walker, p.as_dvec3())?.weights))
    }

    /// The probes' SH weighted by `weights` (probe, weight).
    pub fn blend(&self, weights: &[(usize, f64)]) -> ShRgb9 {
        blend(weights.iter().map(|&(probe, w)| (&self.sh[probe], w)))
    }

    /// The weights at `p`: the trilinear weights of the grid, or the tetrahedral (outside the
    /// hull, extrapolation) weights that `walker` finds from where it last stopped; with
    /// [`ProbeSet::visibility`], those of the probes `p` does not see moved to the others
    /// ([`Visibility`]).
    pub fn lookup(&self, walker: &mut Walker, p: DVec3) -> Result<Lookup> {
        self.lookup_with(walker, p, self.visibility.as_ref())
    }

    /// [`ProbeSet::lookup`] with `visibility` in place of the set's own (`None`: every probe
    /// weighs), to measure the set both ways.
    pub fn lookup_with(
        &self,
        walker: &mut Walker,
        p: DVec3,
        visibility: Option<&Visibility>,
    ) -> Result<Lookup> {
        let (mut weights, tet) = self.weights(walker, p)?;
        let seen = match visibility {
            Some(visibility) => {
                let cell = tet.map(|tet| (&self.mesh, tet));
                weigh_by_visibility(&mut weights, p, self.mesh.positions(), visibility, cell)
            }
            None => Seen::All,
        };
        Ok(Lookup { weights, seen })
    }

    /// The interpolation's (probe, weight) pairs at `p`: a grid cell's eight, or a
    /// tetrahedron's four and four of weight 0, with the tetrahedron.
    fn weights(&self, walker: &mut Walker, p: DVec3) -> Result<(Weights, Option<u32>)> {
        if let Some(lattice) = &self.trilinear {
            return Ok((lattice.weights(p).map(|(probe, w)| (probe as usize, w)), None));
        }
        let location = walker.locate(&self.mesh, p)?;
        let weights = std::array::from_fn(|k| {
            if k < 4 {
                (location.probes[k] as usize, location.weights[k])
            } else {
                (0, 0.0)
            }
        });
        Ok((weights, Some(location.tet)))
    }
}

/// The SH captured at each of `positions` (the static groups of `gpu`, which holds `scene`).
pub fn capture_at(
    ctx: &Arc<Context>,
    scene: &Scene,
    gpu: &GpuScene,
    settings: CaptureSettings,
    positions: &[DVec3],
) -> Result<Vec<ShRgb9>> {
    let mut capture = ProbeCapture::new(ctx, scene, settings)?;
    let groups = ProbeGroups::of(scene);
    positions.iter().map(|p| capture.capture(gpu, |g| groups.is_static(g), p.as_vec3())).collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::motion::Key;
    use crate::scene::{shapes, Camera, EnvMap, Group, Motion, Transform};

    fn group(name: &str, at: Vec3, moves: bool) -> Group {
        let mesh = shapes::boxes(name, &[([-0.5; 3], [0.5; 3])], [0.5; 3]).unwrap();
        let transform = Transform { translation: at, ..Transform::default() };
        let motion = moves.then(|| Motion { keys: vec![Key::posed(0.0, transform)], loop_seconds: None });
        Group { name: name.into(), meshes: vec![mesh], transform, motion }
    }

    fn scene(groups: Vec<Group>) -> Scene {
        Scene::new(
            "boxes",
            groups,
            EnvMap::constant([1.0; 3]),
            Camera { position: Vec3::Z * 9.0, target: Vec3::ZERO, up: Vec3::Y, fov_y_deg: 60.0 },
        )
    }

    #[test]
    fn the_moving_groups_are_those_with_keyframes_wherever_they_are() {
        let groups = vec![group("floor", Vec3::ZERO, false), group("ball", Vec3::X * 9.0, true)];
        let moving = ProbeGroups::of(&scene(groups.clone()));
        assert_eq!((moving.moving(), moving.fallback()), (&[1][..], false));
        assert!(moving.is_static(0) && moving.is_moving(1));
        let mut three = groups.clone();
        three.push(group("cart", Vec3::Y * 9.0, true));
        assert_eq!(ProbeGroups::of(&scene(three)).moving(), [1, 2]);
        // Without keyframes the first group moves.
        let still = vec![group("ball", Vec3::X * 9.0, false), group("floor", Vec3::ZERO, false)];
        let fallback = ProbeGroups::of(&scene(still));
        assert_eq!((fallback.moving(), fallback.fallback()), (&[0][..], true));
        assert!(ProbeGroups::of(&scene(vec![])).moving().is_empty());
    }

    #[test]
    fn the_probes_span_the_static_groups_alone_whatever_their_order() {
        // The moving ball far away leaves the grid over the floor's unit box either way.
        for groups in [
            vec![group("floor", Vec3::ZERO, false), group("ball", Vec3::X * 9.0, true)],
            vec![group("ball", Vec3::X * 9.0, true), group("floor", Vec3::ZERO, false)],
        ] {
            let lattice = grid_lattice(&scene(groups), [2; 3]).unwrap();
            let (lo, hi) = bounds(lattice.positions().iter().map(|p| p.as_vec3())).unwrap();
            assert!(
                lo.abs_diff_eq(Vec3::splat(-0.25), 1e-6) && hi.abs_diff_eq(Vec3::splat(0.25), 1e-6),
                "{lo} {hi}"
            );
        }
        // Every group moving leaves none to place probes in, and the message says which move.
        let all = scene(vec![group("ball", Vec3::ZERO, true), group("cart", Vec3::X, true)]);
        let occluders = Occluders::of_static(&all).unwrap();
        let error = ProbeSettings::default().positions(&all, &occluders).unwrap_err().to_string();
        assert!(error.contains("no static group") && error.contains("group 1 (\"cart\")"), "{error}");
    }
}
