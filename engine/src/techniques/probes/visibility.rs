//! Visibility-aware interpolation: a probe keeps only the part of its weight that the lookup
//! point sees of it through the static geometry (none behind a wall), and the weights are
//! renormalised. Without it a tetrahedron
//! (or grid cell) spanning a wall blends the light of both sides: in `two-rooms` the dim room's
//! path took 45–280 times its own irradiance from the sunlit room's probes (BENCHMARKS.md).
//!
//! The test, on the host, once per moving group per frame: for each probe of nonzero weight (4
//! for a tetrahedron, 8 for a grid cell), [`RAYS_PER_PROBE`] rays from the point through the
//! static groups' BVH, to the probe and to the corners of a cube inscribed in its **free
//! sphere** (the probe's distance to the nearest surface, [`FREE_FRACTION`] of the first hit
//! over 14 directions, at most [`SPREAD`] of its distance to the point); the probe keeps the
//! fraction of its weight whose rays arrive. A wall between point and probe stops every ray,
//! since the free sphere lies on the probe's side of it; a column stops some. A single ray to
//! the probe (tried first) cut a probe off behind any thin column and made the atrium's coarse
//! sets worse (BENCHMARKS.md). Considered and not built: DDGI's per-probe depth moments with a
//! Chebyshev test (a depth cube per probe, approximate, and made to be read per pixel on the
//! GPU, which the per-object lookup does not need); a visibility bit per tetrahedron corner
//! precomputed from the tetrahedron's centre (wrong for a point across a wall inside the
//! tetrahedron, the leak's own case).
//!
//! Hidden is not the same as elsewhere: a probe behind a column, an arch or a roof's edge is in
//! the point's own space, and its light is the point's. So a probe the rays do not wholly reach
//! keeps all its weight when the way round to it through free space ([`super::detour`]) is at
//! most [`DETOUR`] times the straight line: only probes in another space (behind a wall, reached
//! the long way through a door or an opening, or not at all) lose theirs. On the atrium bunny's
//! path that left 4 sets worse than without visibility instead of 9 (BENCHMARKS.md "The way
//! round"); two rooms joined by a door still leak where the way through the door is short.
//!
//! A tetrahedron across a wall keeps only its 1–3 corners on the point's side, and their
//! renormalised weights are coarser than the room's own tetrahedra (1.41 times the error of the
//! dim room's probes alone in `two-rooms`'s 16-probe grid): when a corner is wholly hidden, the
//! weights are instead those of the nearest point on the nearest face, among the tetrahedra
//! within [`FACE_SEARCH_STEPS`], whose three corners the point sees ([`nearest_seen_face`]), as
//! the hull's nearest point stands in outside the hull (1.00 times, BENCHMARKS.md).
//!
//! When the point sees none of its cell's probes, the nearest probe it sees among the
//! [`NEAREST_TRIES`] nearest takes all the weight ([`Seen::Nearest`]); when it sees none of
//! those either (it is inside a solid, or sealed off from every probe), the weights stay as they
//! were ([`Seen::Unweighted`]). Each outcome is counted ([`LookupCounts`]). Never a division by
//! zero: the weights renormalised sum to more than [`MIN_SEEN_WEIGHT`].
use super::capture::static_scene;
use super::delaunay::opposite;
use super::detour::FreeGrid;
use super::extrapolate::closest_on_triangle;
use super::solids::directions;
use super::tetmesh::{Across, TetMesh};
use crate::error::Result;
use crate::raycast::SceneBvh;
use crate::scene::Scene;
use glam::DVec3;
use std::cell::OnceCell;
use std::collections::{HashMap, HashSet};
use std::sync::{Arc, Mutex, OnceLock};

/// Whether a lookup weighs probes by whether the point sees them.
#[repr(u32)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, strum::FromRepr)]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
pub enum ProbeVisibility {
    /// Every probe of the cell keeps its weight: light leaks through walls.
    Off = 0,
    /// Rays from the point to each probe of its cell and around it: each keeps the fraction of
    /// its weight the point sees, a probe behind a wall none.
    #[default]
    Rays = 1,
}

/// Rays from the point to each probe: to its centre and to the 8 corners of a cube in its free
/// sphere.
pub const RAYS_PER_PROBE: usize = 9;
/// The free sphere's radius as a fraction of the nearest surface hit over 14 directions (axes
/// and diagonals): a plane's nearest point lies within 36.3° of one of them, so the first hit
/// is at most 1/cos 36.3° = 1.24 times its distance, and 0.8 of it (0.99) stays inside.
pub const FREE_FRACTION: f64 = 0.8;
/// The free sphere's radius as a fraction of the probe's distance to the point, at most: seen
/// from the point it spans at most about 15° on each side.
pub const SPREAD: f64 = 0.25;

/// The way round through free space, over the straight line, up to which a probe the point
/// does not wholly see is in its space and keeps its weight ([`super::detour`]).
pub const DETOUR: f64 = 1.5;
/// Cells of the free-space grid added to the way round's allowance: its paths' steps and ends.
pub const DETOUR_CELLS: f64 = 2.0;

/// Steps through neighbouring tetrahedra within which a tetrahedron with a corner wholly hidden
/// looks for the nearest face whose corners the point sees.
pub const FACE_SEARCH_STEPS: usize = 2;

/// The probes nearest a point that sees none of its cell's probes tried, nearest first, before
/// the lookup gives up and keeps the weights as they were.
pub const NEAREST_TRIES: usize = 32;

/// The weight the seen probes must hold to be renormalised: below it they are a rounding's
/// remainder, and the point counts as seeing none.
pub const MIN_SEEN_WEIGHT: f64 = 1e-9;

/// A probe position's key in [`Occluders`]'s paths: its coordinates' bits.
fn way_key(q: DVec3) -> [u64; 3] {
    q.to_array().map(f64::to_bits)
}

/// The static groups' surfaces, which hide probes from a point.
#[derive(Debug)]
pub struct Occluders {
    bvh: SceneBvh,
    /// The free space around them, for the way round ([`FreeGrid`]); `None` without surfaces.
    /// Built on first use: a set that never asks about the way round (no visibility, no
    /// automatic placement) does not pay for it.
    grid: OnceLock<Option<FreeGrid>>,
    /// The paths through the grid from each probe position asked about so far
    /// ([`FreeGrid::distances_from`]), by its coordinates' bits: automatic placement tries the
    /// same candidates in many sets.
    ways: Mutex<HashMap<[u64; 3], Arc<[f32]>>>,
}

impl Occluders {
    /// The static groups of `scene` (those [`super::ProbeGroups`] does not move).
    pub fn of_static(scene: &Scene) -> Result<Occluders> {
        Ok(Occluders::from_bvh(SceneBvh::build(&static_scene(scene))?))
    }

    /// Occluders from the static groups' BVH.
    pub(super) fn from_bvh(bvh: SceneBvh) -> Occluders {
        Occluders { bvh, grid: OnceLock::new(), ways: Mutex::default() }
    }

    /// The free-space grid, built the first time it is asked for.
    fn grid(&self) -> Option<&FreeGrid> {
        self.grid.get_or_init(|| FreeGrid::build(&self.bvh, self)).as_ref()
    }

    /// The distance from `q` to the nearest static surface, times [`FREE_FRACTION`] (see
    /// there); infinite in open space.
    fn free_radius(&self, q: DVec3) -> f64 {
        let q = q.as_vec3();
        let nearest = directions()
            .iter()
            .filter_map(|&d| self.bvh.closest_hit(q, d, f32::INFINITY))
            .map(|hit| f64::from(hit.t))
            .fold(f64::INFINITY, f64::min);
        FREE_FRACTION * nearest
    }

    /// Whether the probe at `q` is in the space of the lookup's point `p`: the way round from
    /// `p` to `q` through free space is at most [`DETOUR`] times the straight line (plus
    /// [`DETOUR_CELLS`] cells for the grid's steps), as past a column, an arch or a roof's
    /// edge, not through a wall.
    fn same_space(&self, point: &LookupPoint, q: DVec3) -> bool {
        let p = point.p;
        let Some(grid) = self.grid() else {
            return false;
        };
        let key = way_key(q);
        let known = self.ways.lock().ok().and_then(|ways| ways.get(&key).cloned());
        let way = known.unwrap_or_else(|| {
            let way: Arc<[f32]> = grid.distances_from(q, self).into();
            if let Ok(mut ways) = self.ways.lock() {
                ways.insert(key, way.clone());
            }
            way
        });
        let entries = point.entries.get_or_init(|| grid.entries(p, self));
        grid.way_round(&way, entries)
            .is_some_and(|d| d <= DETOUR * p.distance(q) + DETOUR_CELLS * grid.cell_size())
    }

    /// Forgets the paths from every probe position but `kept`: placement asks about each
    /// candidate, the finished set's lookups about its own probes only.
    pub(super) fn keep_ways_of(&self, kept: &[DVec3]) {
        let keys: HashSet<[u64; 3]> = kept.iter().map(|&q| way_key(q)).collect();
        if let Ok(mut ways) = self.ways.lock() {
            ways.retain(|key, _| keys.contains(key));
        }
    }

    /// Whether `q` lies sealed off in a pocket of free space (a space of the way-round grid,
    /// `detour.rs`, under 1 % of its cells), such as a gap closed on all sides between boxes: a
    /// probe there captures only the pocket's walls. False without a grid.
    pub fn sealed(&self, q: DVec3) -> bool {
        self.grid().is_some_and(|grid| grid.sealed(q, self))
    }

    /// Whether no static surface lies between `p` and `q`. A surface within a millionth of the
    /// distance of `q` does not hide it: a probe placed on a wall sees the room it faces.
    pub fn sees(&self, p: DVec3, q: DVec3) -> bool {
        let d = q - p;
        if d == DVec3::ZERO {
            return true;
        }
        // The BVH measures t in units of the direction: t = 1 is q.
        !self.bvh.occluded(p.as_vec3(), d.as_vec3(), 1.0 - 1e-6)
    }
}

/// A lookup's point and its way into the free-space grid ([`FreeGrid::entries`]: up to 8 rays),
/// found the first time one of its probes is asked about and the same for all of them.
struct LookupPoint {
    p: DVec3,
    entries: OnceCell<Vec<(usize, f64)>>,
}

impl LookupPoint {
    fn new(p: DVec3) -> LookupPoint {
        LookupPoint { p, entries: OnceCell::new() }
    }
}

/// The occluders and each probe's free sphere: what a set's lookups test visibility with.
#[derive(Clone, Debug)]
pub struct Visibility {
    occluders: Arc<Occluders>,
    /// Each probe's free radius ([`Occluders::free_radius`]), in the order of its positions.
    free: Vec<f64>,
}

impl Visibility {
    /// For probes at `positions` (14 rays each).
    pub fn new(occluders: Arc<Occluders>, positions: &[DVec3]) -> Visibility {
        let free = positions.iter().map(|&q| occluders.free_radius(q)).collect();
        Visibility { occluders, free }
    }

    /// The share of probe `probe`'s weight that `p` keeps: all of it when the probe is in `p`'s
    /// own space ([`Occluders::same_space`]), else the fraction of it `p` sees.
    fn kept_fraction(&self, point: &LookupPoint, probe: usize, q: DVec3) -> f64 {
        let seen = self.seen_fraction(point.p, probe, q);
        if seen < 1.0 && self.occluders.same_space(point, q) {
            1.0
        } else {
            seen
        }
    }

    /// The fraction of the [`RAYS_PER_PROBE`] rays from `p` to probe `probe` at `q` that no
    /// static surface stops.
    fn seen_fraction(&self, p: DVec3, probe: usize, q: DVec3) -> f64 {
        let radius = self.free[probe].min(SPREAD * p.distance(q)) / 3f64.sqrt();
        let corner = |k: usize| DVec3::new(bit(k, 1), bit(k, 2), bit(k, 4)) * radius;
        let seen = std::iter::once(q)
            .chain((0..RAYS_PER_PROBE - 1).map(|k| q + corner(k)))
            .filter(|&target| self.occluders.sees(p, target))
            .count();
        seen as f64 / RAYS_PER_PROBE as f64
    }
}

/// ±1 by bit `mask` of `k`: the cube corners.
fn bit(k: usize, mask: usize) -> f64 {
    if k & mask == 0 {
        -1.0
    } else {
        1.0
    }
}

/// What a lookup's visibility test did.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Seen {
    /// The point sees every probe of nonzero weight (or visibility is off).
    All,
    /// Some were hidden, wholly or partly: the weights times the fractions seen, renormalised.
    Some,
    /// None was seen: the nearest probe it sees alone.
    Nearest,
    /// No probe among the [`NEAREST_TRIES`] nearest is seen: the weights as they were.
    Unweighted,
}

/// Lookups counted by what their visibility test did (see [`Seen`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct LookupCounts {
    pub lookups: u64,
    /// Lookups where some probe was hidden, wholly or partly, and the weights renormalised.
    pub renormalised: u64,
    /// Lookups that fell back to the nearest probe seen.
    pub nearest: u64,
    /// Lookups that saw no probe and kept the weights as they were.
    pub unweighted: u64,
}

impl LookupCounts {
    pub fn count(&mut self, seen: Seen) {
        self.lookups += 1;
        match seen {
            Seen::All => {}
            Seen::Some => self.renormalised += 1,
            Seen::Nearest => self.nearest += 1,
            Seen::Unweighted => self.unweighted += 1,
        }
    }
}

/// Multiplies the weight of each probe of `weights` (index into `positions`, weight) by the
/// fraction of it that `p` sees and renormalises them (see the module documentation for the
/// fallbacks). With `cell`, the tetrahedral mesh and tetrahedron the weights come from: when a
/// corner is wholly hidden, the weights are instead those of the nearest face p sees
/// ([`nearest_seen_face`]).
pub(super) fn weigh_by_visibility<const N: usize>(
    weights: &mut [(usize, f64); N],
    p: DVec3,
    positions: &[DVec3],
    visibility: &Visibility,
    cell: Option<(&TetMesh, u32)>,
) -> Seen {
    let mut seen_weight = 0.0;
    let (mut hidden, mut wholly) = (false, false);
    let before = *weights;
    let mut fractions = Vec::with_capacity(N);
    let point = LookupPoint::new(p);
    for (probe, w) in weights.iter_mut().filter(|(_, w)| *w != 0.0) {
        let seen = visibility.kept_fraction(&point, *probe, positions[*probe]);
        fractions.push((*probe, seen));
        *w *= seen;
        seen_weight += *w;
        hidden |= seen < 1.0;
        wholly |= seen == 0.0;
    }
    if !hidden {
        return Seen::All;
    }
    if let (true, Some((mesh, tet))) = (wholly, cell) {
        if let Some(face) = nearest_seen_face(mesh, tet, &point, visibility, &mut fractions) {
            *weights = [(face[0].0, 0.0); N];
            weights[..3].copy_from_slice(&face);
            return Seen::Some;
        }
    }
    if seen_weight > MIN_SEEN_WEIGHT {
        weights.iter_mut().for_each(|(_, w)| *w /= seen_weight);
        return Seen::Some;
    }
    match nearest_seen(p, positions, &visibility.occluders) {
        Some(probe) => {
            *weights = [(probe, 0.0); N];
            weights[0].1 = 1.0;
            Seen::Nearest
        }
        None => {
            *weights = before;
            Seen::Unweighted
        }
    }
}

/// The weights of the point nearest `p` on the faces of the tetrahedra within
/// [`FACE_SEARCH_STEPS`] of `tet` whose three corners `p` sees, each weight times the fraction
/// seen, renormalised; `None` when there is no such face. A tetrahedron across a wall keeps
/// only its 1–3 corners on `p`'s side, whose renormalised weights are coarser than the room's
/// own tetrahedra: the nearest face wholly in the room stands for those, as the hull's nearest
/// point does outside the hull. `fractions`: the fractions known so far, (probe, fraction).
fn nearest_seen_face(
    mesh: &TetMesh,
    tet: u32,
    point: &LookupPoint,
    visibility: &Visibility,
    fractions: &mut Vec<(usize, f64)>,
) -> Option<[(usize, f64); 3]> {
    let positions = mesh.positions();
    let mut tets = vec![tet];
    let mut reached = 0;
    for _ in 0..FACE_SEARCH_STEPS {
        let end = tets.len();
        for t in reached..end {
            for across in mesh.neighbours()[tets[t] as usize] {
                if let Across::Tet(next) = across {
                    if !tets.contains(&next) {
                        tets.push(next);
                    }
                }
            }
        }
        reached = end;
    }
    let mut fraction = |probe: usize| match fractions.iter().find(|(i, _)| *i == probe) {
        Some(&(_, f)) => f,
        None => {
            let f = visibility.kept_fraction(point, probe, positions[probe]);
            fractions.push((probe, f));
            f
        }
    };
    let mut best: Option<(f64, [(usize, f64); 3])> = None;
    for &t in &tets {
        for slot in 0..4 {
            let face = opposite(mesh.tets()[t as usize], slot).map(|i| i as usize);
            let seen = face.map(&mut fraction);
            if seen.contains(&0.0) {
                continue;
            }
            let (w, distance2) = closest_on_triangle(point.p, face.map(|i| positions[i]));
            if best.is_none_or(|(d, _)| distance2 < d) {
                best = Some((distance2, std::array::from_fn(|k| (face[k], w[k] * seen[k]))));
            }
        }
    }
    let (_, mut face) = best?;
    let sum: f64 = face.iter().map(|w| w.1).sum();
    if sum <= MIN_SEEN_WEIGHT {
        return None;
    }
    face.iter_mut().for_each(|w| w.1 /= sum);
    Some(face)
}

/// The nearest of the [`NEAREST_TRIES`] probes nearest `p` that `p` sees.
fn nearest_seen(p: DVec3, positions: &[DVec3], occluders: &Occluders) -> Option<usize> {
    let mut near: Vec<(f64, usize)> = positions.iter().map(|q| (q - p).length_squared()).zip(0..).collect();
    let cmp = |a: &(f64, usize), b: &(f64, usize)| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1));
    if near.len() > NEAREST_TRIES {
        near.select_nth_unstable_by(NEAREST_TRIES, cmp);
        near.truncate(NEAREST_TRIES);
    }
    near.sort_unstable_by(cmp);
    near.into_iter().map(|(_, i)| i).find(|&i| occluders.sees(p, positions[i]))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::motion::Key;
    use crate::scene::{shapes, Camera, EnvMap, Group, Mesh, Motion, Transform};
    use crate::techniques::probes::Solids;
    use glam::Vec3;

    /// A wall 0.1 thick at x = 0 (y and z within ±2), a sealed box around (0, 0, 5), a pole 4 cm
    /// thick along Y through (2, y, 0), and a moving ball far away (so that the rest is static).
    fn walled() -> Arc<Occluders> {
        let wall = shapes::boxes(
            "wall",
            &[([-0.05, -2.0, -2.0], [0.05, 2.0, 2.0]), ([1.98, -2.0, -0.02], [2.02, 2.0, 0.02])],
            [0.5; 3],
        )
        .unwrap();
        let sealed = shapes::boxes("sealed", &[([-0.5, -0.5, 4.5], [0.5, 0.5, 5.5])], [0.5; 3]).unwrap();
        Arc::new(Occluders::of_static(&with_walls("walled", vec![wall, sealed])).unwrap())
    }

    /// A scene of static `walls` and a moving ball far away (so that the walls are static).
    fn with_walls(name: &str, walls: Vec<Mesh>) -> Scene {
        let ball = shapes::boxes("ball", &[([-0.1; 3], [0.1; 3])], [0.5; 3]).unwrap();
        let at = Transform { translation: Vec3::splat(50.0), ..Transform::default() };
        let motion = Motion { keys: vec![Key::posed(0.0, at)], loop_seconds: None };
        Scene::new(
            name,
            vec![
                Group { motion: Some(motion), ..Group::new("ball", vec![ball], at) },
                Group::new("walls", walls, Transform::default()),
            ],
            EnvMap::constant([1.0; 3]),
            Camera { position: Vec3::Z * 9.0, target: Vec3::ZERO, up: Vec3::Y, fov_y_deg: 60.0 },
        )
    }

    /// Probes 0 and 1 west of the wall, 2 and 3 east of it, 4 inside the sealed box.
    const PROBES: [DVec3; 5] = [
        DVec3::new(-1.0, 0.0, -1.0),
        DVec3::new(-1.0, 0.0, 1.0),
        DVec3::new(1.0, 0.0, -1.0),
        DVec3::new(1.0, 1.0, 1.0),
        DVec3::new(0.0, 0.0, 5.0),
    ];

    #[test]
    fn the_wall_hides_what_is_behind_it_and_nothing_else() {
        let occluders = walled();
        let east = DVec3::new(0.3, 0.0, 0.0);
        assert!(occluders.sees(east, PROBES[2]) && occluders.sees(east, PROBES[3]));
        assert!(!occluders.sees(east, PROBES[0]) && !occluders.sees(PROBES[1], east));
        // Above the wall's top nothing hides the other side.
        assert!(occluders.sees(DVec3::new(0.3, 2.5, 0.0), DVec3::new(-1.0, 2.5, 0.0)));
        // A probe on the wall's east face is seen from the east.
        assert!(occluders.sees(east, DVec3::new(0.05, 0.0, 0.5)));
    }

    #[test]
    fn hidden_probes_lose_their_weight_and_the_others_are_renormalised() {
        let visibility = Visibility::new(walled(), &PROBES);
        let mut weights = [(0, 0.2), (1, 0.2), (2, 0.36), (3, 0.24)];
        let seen = weigh_by_visibility(&mut weights, DVec3::new(0.3, 0.0, 0.0), &PROBES, &visibility, None);
        assert_eq!(seen, Seen::Some);
        // 0.36 and 0.24 of 0.6, to rounding.
        let expected = [0.0, 0.0, 0.6, 0.4];
        assert!(weights.iter().zip(expected).all(|(w, e)| (w.1 - e).abs() < 1e-12), "{weights:?}");
        // All seen: unchanged.
        let mut same = [(2, 0.5), (3, 0.5)];
        assert_eq!(
            weigh_by_visibility(&mut same, DVec3::new(0.5, 0.0, 0.0), &PROBES, &visibility, None),
            Seen::All
        );
        assert_eq!(same, [(2, 0.5), (3, 0.5)]);
    }

    #[test]
    fn a_point_seeing_none_of_its_probes_takes_the_nearest_it_sees_or_keeps_its_weights() {
        let visibility = Visibility::new(walled(), &PROBES);
        let mut counts = LookupCounts::default();
        // East of the wall, weighted on the west probes only: the nearest east probe, 2.
        let mut weights = [(0, 0.5), (1, 0.5)];
        let seen = weigh_by_visibility(&mut weights, DVec3::new(0.9, 0.0, -0.5), &PROBES, &visibility, None);
        counts.count(seen);
        assert_eq!((seen, weights), (Seen::Nearest, [(2, 1.0), (2, 0.0)]));
        // Inside the sealed box, weighted on the outside probes: it sees only probe 4, which
        // is not among the weighted ones, so it falls back to it.
        let mut inside = [(2, 0.5), (3, 0.5)];
        let seen = weigh_by_visibility(&mut inside, DVec3::new(0.2, 0.0, 5.0), &PROBES, &visibility, None);
        counts.count(seen);
        assert_eq!((seen, inside), (Seen::Nearest, [(4, 1.0), (4, 0.0)]));
        // Inside the sealed box with no probe in it: no probe seen, the weights as they were.
        let outside = [PROBES[0], PROBES[1], PROBES[2], PROBES[3]];
        let visibility = Visibility::new(walled(), &outside);
        let mut kept = [(2, 0.5), (3, 0.5)];
        let seen = weigh_by_visibility(&mut kept, DVec3::new(0.2, 0.0, 5.0), &outside, &visibility, None);
        counts.count(seen);
        assert_eq!((seen, kept), (Seen::Unweighted, [(2, 0.5), (3, 0.5)]));
        assert_eq!(counts, LookupCounts { lookups: 3, renormalised: 0, nearest: 2, unweighted: 1 });
    }

    #[test]
    fn a_thin_pole_hides_part_of_a_probe_and_a_wall_all_of_it() {
        let occluders = walled();
        // The pole stops the ray to the probe's centre, not those to its free sphere's corners
        // (0.5 from it at most: its distance to the point times SPREAD; the pole is 0.98 away).
        let (p, behind_pole) = (DVec3::new(1.0, 0.0, 0.0), DVec3::new(3.0, 0.0, 0.0));
        let probes = [behind_pole, DVec3::new(-1.0, 0.0, 0.0)];
        let visibility = Visibility::new(occluders, &probes);
        let fraction = (RAYS_PER_PROBE as f64 - 1.0) / RAYS_PER_PROBE as f64;
        assert_eq!(visibility.seen_fraction(p, 0, probes[0]), fraction);
        assert_eq!(visibility.seen_fraction(p, 1, probes[1]), 0.0);
        // The probe behind the pole is in the point's space (the way round the pole is short)
        // and keeps its weight (renormalised: all of it); the one behind the wall loses its.
        let mut weights = [(0, 0.5), (1, 0.5)];
        assert_eq!(weigh_by_visibility(&mut weights, p, &probes, &visibility, None), Seen::Some);
        assert!((weights[0].1 - 1.0).abs() < 1e-12 && weights[1].1 == 0.0, "{weights:?}");
    }

    #[test]
    fn the_way_round_tells_a_wall_from_a_pole_and_a_sealed_box() {
        let occluders = walled();
        // In open space the way round is the straight line to within the joins' 13 % and the
        // steps into the grid at each end (4 cells at most), and never shorter.
        let grid = occluders.grid().unwrap();
        let (p, q) = (DVec3::new(1.0, -1.5, -1.5), DVec3::new(1.5, 1.5, 4.0));
        let way = grid.way_round(&grid.distances_from(q, &occluders), &grid.entries(p, &occluders)).unwrap();
        assert!(way >= p.distance(q) && way <= 1.13 * p.distance(q) + 4.0 * grid.cell_size(), "{way}");
        // Past the pole: a short way round.
        assert!(occluders.same_space(&LookupPoint::new(DVec3::new(1.0, 0.0, 0.0)), DVec3::new(3.0, 0.0, 0.0)));
        // Through the wall: round its end at z = 2, over four times the straight line.
        assert!(
            !occluders.same_space(&LookupPoint::new(DVec3::new(0.3, 0.0, 0.0)), DVec3::new(-0.4, 0.0, -1.0))
        );
        // Beside the wall's end the way round is hardly longer: the same space.
        assert!(
            occluders.same_space(&LookupPoint::new(DVec3::new(1.5, 0.0, 1.9)), DVec3::new(-0.4, 0.0, 1.9))
        );
        // Into the sealed box: no way at all.
        assert!(
            !occluders.same_space(&LookupPoint::new(DVec3::new(0.2, 0.0, 5.0)), DVec3::new(1.0, 0.0, 5.0))
        );
        // A point sealed off from the grid (inside the pole) reaches no cell.
        assert!(
            !occluders.same_space(&LookupPoint::new(DVec3::new(2.0, 0.0, 0.0)), DVec3::new(1.0, 0.0, 0.0))
        );
        // The paths from each probe asked about are kept until a finished set keeps its own.
        let paths = || occluders.ways.lock().unwrap().len();
        assert_eq!(paths(), 5);
        occluders.keep_ways_of(&[q, DVec3::new(3.0, 0.0, 0.0), DVec3::new(-0.4, 0.0, 1.9)]);
        assert_eq!(paths(), 2);
    }

    /// Six slabs 0.1 thick closing a cube `side` wide around the origin (their outer faces,
    /// front faces, face its inside), on a floor 8 m wide that sets the grid's cells (1/6 m).
    fn pocket(side: f32) -> (Occluders, Solids) {
        let (h, t) = (0.5 * side, 0.1);
        let slabs = [
            ([-h - t, -h - t, -h - t], [h + t, -h, h + t]),
            ([-h - t, h, -h - t], [h + t, h + t, h + t]),
            ([-h - t, -h, -h - t], [-h, h, h + t]),
            ([h, -h, -h - t], [h + t, h, h + t]),
            ([-h, -h, -h - t], [h, h, -h]),
            ([-h, -h, h], [h, h, h + t]),
            ([-4.0, -2.0, -4.0], [4.0, -1.9, 4.0]),
        ];
        let scene = with_walls("pocket", vec![shapes::boxes("pocket", &slabs, [0.5; 3]).unwrap()]);
        (Occluders::of_static(&scene).unwrap(), Solids::of_static(&scene))
    }

    #[test]
    fn a_pocket_is_sealed_and_a_closed_room_is_not() {
        // 30 cm: about 8 cells of the grid's 48 × 14 × 48 (less than 1 %), which `Solids` does
        // not count as inside a solid.
        let (occluders, solids) = pocket(0.3);
        let inside = DVec3::new(0.02, -0.03, 0.01);
        assert!(occluders.sealed(inside) && !solids.contains(inside.as_vec3()));
        assert!(!occluders.sealed(DVec3::new(1.0, 0.0, 0.0)));
        // 1.5 m: a closed room of about 700 cells (over 2 %).
        let (occluders, _) = pocket(1.5);
        assert!(!occluders.sealed(inside));
        // Inside a slab: no cell seen.
        assert!(occluders.sealed(DVec3::new(0.0, -0.8, 0.0)));
    }

    #[test]
    fn a_tetrahedron_across_the_wall_takes_the_nearest_face_on_the_points_side() {
        // A cube of probes across the wall: every tetrahedron holding a point east of it has
        // west corners, wholly hidden.
        let positions: Vec<DVec3> = (0..8).map(|k| DVec3::new(bit(k, 1), bit(k, 2), bit(k, 4))).collect();
        let mesh = TetMesh::build(&positions).unwrap();
        let visibility = Visibility::new(walled(), &positions);
        let p = DVec3::new(0.3, 0.2, -0.4);
        let location = super::super::Walker::default().locate(&mesh, p).unwrap();
        let mut weights: [(usize, f64); 4] =
            std::array::from_fn(|k| (location.probes[k] as usize, location.weights[k]));
        let seen = weigh_by_visibility(&mut weights, p, &positions, &visibility, Some((&mesh, location.tet)));
        assert_eq!(seen, Seen::Some);
        // All the weight on the east face x = 1, reproducing p's projection onto it (1, 0.2,
        // −0.4), as the east probes alone would extrapolate it; rounding of a few operations.
        let at: DVec3 = weights.iter().map(|&(i, w)| positions[i] * w).sum();
        assert!(weights.iter().all(|&(i, w)| w == 0.0 || positions[i].x == 1.0), "{weights:?}");
        assert!(at.abs_diff_eq(DVec3::new(1.0, 0.2, -0.4), 1e-12), "{at}");
    }
}
