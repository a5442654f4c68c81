//! Flat groups with no holes (a floor, a wall): an occluder of this kind hides a receiver from a
//! light source wholly when the receiver lies behind its plane and the receiver's shadow cylinder
//! along the source, widened by the penumbra, falls inside it. The source is then taken away from
//! the receiver whole, with no occlusion layer to draw, filter and read: under a sky the floor
//! hides every region below the horizon from what stands on it, nearly half of the layers of the
//! default scene.
use crate::scene::Group;
use glam::{Mat4, Vec2, Vec3};

/// A group whose triangles lie in one plane and fill their convex hull exactly.
#[derive(Clone, Debug, PartialEq)]
pub struct Sheet {
    /// A point of the plane and its unit normal (object space).
    origin: Vec3,
    normal: Vec3,
    /// Plane axes completing `normal`.
    axes: [Vec3; 2],
    /// The convex hull in plane coordinates, counter-clockwise.
    hull: Vec<Vec2>,
    /// The group's extent (object units), which scales the tolerances.
    extent: f32,
}

/// Relative tolerance of flatness, areas and boundaries.
const TOLERANCE: f32 = 1e-4;

impl Sheet {
    /// `group` as a sheet, or `None` when its triangles leave its plane, leave a hole or a notch
    /// in their hull, or have no area.
    pub fn of(group: &Group) -> Option<Sheet> {
        let triangles = || {
            group.meshes.iter().flat_map(|m| {
                m.indices
                    .chunks_exact(3)
                    .map(move |t| [t[0], t[1], t[2]].map(|i| Vec3::from(m.positions[i as usize])))
            })
        };
        let points = || group.meshes.iter().flat_map(|m| m.positions.iter().map(|p| Vec3::from(*p)));
        let (lo, hi) = points().fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(a, b), p| (a.min(p), b.max(p)));
        let extent = (hi - lo).max_element();
        if extent.is_nan() || extent <= 0.0 {
            return None;
        }
        let [a, b, c] = triangles().max_by(|s, t| area3(s).total_cmp(&area3(t)))?;
        let normal = (b - a).cross(c - a).try_normalize()?;
        if points().any(|p| (p - a).dot(normal).abs() > TOLERANCE * extent) {
            return None;
        }
        let helper = if normal.y.abs() < 0.9 { Vec3::Y } else { Vec3::X };
        let u = helper.cross(normal).normalize();
        let axes = [u, normal.cross(u)];
        let flat = |p: Vec3| Vec2::new((p - a).dot(axes[0]), (p - a).dot(axes[1]));
        let hull = convex_hull(points().map(flat).collect());
        let hull_area = polygon_area(&hull);
        let area: f32 = triangles()
            .map(|t| 0.5 * (flat(t[1]) - flat(t[0])).perp_dot(flat(t[2]) - flat(t[0])).abs())
            .sum();
        // Triangles that overlap, or leave a notch, cannot sum to the hull's area unless they
        // also leave a gap, whose rim is a boundary edge off the hull.
        if hull_area <= 0.0 || (area - hull_area).abs() > TOLERANCE * hull_area {
            return None;
        }
        let sheet = Sheet { origin: a, normal, axes, hull, extent };
        let rim_on_hull = group.meshes.iter().all(|m| {
            boundary_edges(&m.indices).into_iter().all(|(i, j)| {
                let (p, q) =
                    (flat(Vec3::from(m.positions[i as usize])), flat(Vec3::from(m.positions[j as usize])));
                [p, q, 0.5 * (p + q)].iter().all(|x| sheet.inside_by(*x).abs() <= TOLERANCE * extent)
            })
        });
        rim_on_hull.then_some(sheet)
    }

    /// Whether the sheet, placed by `transform` (uniform scale), hides every point of the world
    /// box `corners` from the light towards world direction `w`, with `margin(d)` (world units)
    /// to spare around the shadow of a corner at distance d from the plane along w, for the
    /// penumbra. Touching the plane counts as behind it.
    pub fn hides(&self, transform: &Mat4, corners: &[Vec3; 8], w: Vec3, margin: impl Fn(f32) -> f32) -> bool {
        let inverse = transform.inverse();
        let scale = transform.x_axis.truncate().length();
        let w = inverse.transform_vector3(w).normalize();
        let facing = w.dot(self.normal);
        // Grazing: the shadow runs off along the plane.
        if facing.abs() < 1e-3 {
            return false;
        }
        corners.iter().all(|c| {
            let c = inverse.transform_point3(*c) - self.origin;
            let height = c.dot(self.normal);
            if height * facing.signum() > TOLERANCE * self.extent {
                return false; // on the light's side of the plane
            }
            // Along w to the plane.
            let distance = -height / facing;
            let hit = c + distance * w;
            self.inside_by(Vec2::new(hit.dot(self.axes[0]), hit.dot(self.axes[1])))
                >= margin(distance * scale) / scale
        })
    }

    /// How far `p` (plane coordinates) lies inside the hull: its least distance to an edge's
    /// line, negative outside.
    fn inside_by(&self, p: Vec2) -> f32 {
        let n = self.hull.len();
        (0..n)
            .map(|k| {
                let (a, b) = (self.hull[k], self.hull[(k + 1) % n]);
                (b - a).normalize().perp_dot(p - a)
            })
            .fold(f32::INFINITY, f32::min)
    }
}

fn area3(t: &[Vec3; 3]) -> f32 {
    (t[1] - t[0]).cross(t[2] - t[0]).length()
}

/// Counter-clockwise convex hull (Andrew's monotone chain), collinear points dropped.
fn convex_hull(mut points: Vec<Vec2>) -> Vec<Vec2> {
    points.sort_by(|a, b| a.x.total_cmp(&b.x).then(a.y.total_cmp(&b.y)));
    points.dedup();
    if points.len() < 3 {
        return points;
    }
    let mut hull: Vec<Vec2> = Vec::with_capacity(2 * points.len());
    for pass in [points.clone(), points.into_iter().rev().collect()] {
        let start = hull.len();
        for p in pass {
            while hull.len() >= start + 2
                && (hull[hull.len() - 1] - hull[hull.len() - 2]).perp_dot(p - hull[hull.len() - 2]) <= 0.0
            {
                hull.pop();
            }
            hull.push(p);
        }
        hull.pop();
    }
    hull
}

fn polygon_area(polygon: &[Vec2]) -> f32 {
    let n = polygon.len();
    0.5 * (0..n).map(|k| polygon[k].perp_dot(polygon[(k + 1) % n])).sum::<f32>()
}

/// The edges (vertex index pairs) that only one triangle has.
fn boundary_edges(indices: &[u32]) -> Vec<(u32, u32)> {
    let mut edges: std::collections::HashMap<(u32, u32), u32> = std::collections::HashMap::new();
    for t in indices.chunks_exact(3) {
        for k in 0..3 {
            let (i, j) = (t[k], t[(k + 1) % 3]);
            *edges.entry((i.min(j), i.max(j))).or_default() += 1;
        }
    }
    edges.into_iter().filter(|&(_, n)| n == 1).map(|(e, _)| e).collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::frame::bounds::box_corners;
    use crate::scene::{Mesh, Transform};

    /// An n × n grid over [-1, 1]² at y = 0, normals up, without the triangles `skip` names.
    fn grid(n: u32, skip: impl Fn(u32) -> bool) -> Group {
        let mut positions = Vec::new();
        for j in 0..=n {
            for i in 0..=n {
                positions.push([2.0 * i as f32 / n as f32 - 1.0, 0.0, 2.0 * j as f32 / n as f32 - 1.0]);
            }
        }
        let mut indices = Vec::new();
        for j in 0..n {
            for i in 0..n {
                let k = j * (n + 1) + i;
                indices.extend([k, k + n + 1, k + 1, k + 1, k + n + 1, k + n + 2]);
            }
        }
        let indices = indices
            .chunks_exact(3)
            .enumerate()
            .filter(|(t, _)| !skip(*t as u32))
            .flat_map(|(_, t)| t.to_vec())
            .collect();
        let normals = vec![[0.0, 1.0, 0.0]; positions.len()];
        let mesh =
            Mesh { name: "grid".into(), positions, normals, indices, albedo: [0.5; 3], texturing: None };
        Group::new("floor", vec![mesh], Transform::default())
    }

    fn corners(lo: Vec3, hi: Vec3) -> [Vec3; 8] {
        box_corners(lo, hi, &Mat4::IDENTITY)
    }

    #[test]
    fn a_grid_floor_is_a_sheet_and_one_with_a_hole_or_a_notch_is_not() {
        assert!(Sheet::of(&grid(4, |_| false)).is_some());
        // Both triangles of an inner cell: a hole whose rim lies inside the hull.
        assert_eq!(Sheet::of(&grid(4, |t| t == 10 || t == 11)), None);
        // A corner cell: a notch, the hull's area no longer matched.
        assert_eq!(Sheet::of(&grid(4, |t| t == 0 || t == 1)), None);
        let mut bent = grid(4, |_| false);
        bent.meshes[0].positions[12][1] = 0.1;
        assert_eq!(Sheet::of(&bent), None, "a vertex off the plane");
    }

    #[test]
    fn a_sheet_hides_what_stands_on_it_from_below_only_where_the_shadow_stays_on_it() {
        let sheet = Sheet::of(&grid(4, |_| false)).unwrap();
        let placed = Mat4::from_scale_rotation_translation(
            Vec3::splat(2.0),
            glam::Quat::IDENTITY,
            Vec3::new(0.0, -1.0, 0.0),
        );
        // The floor spans [-2, 2]² at y = -1; a box standing on it, 0.5 wide and 0.5 high.
        let standing = corners(Vec3::new(-0.25, -1.0, -0.25), Vec3::new(0.25, -0.5, 0.25));
        let down = Vec3::NEG_Y;
        let fixed = |m: f32| move |_: f32| m;
        assert!(sheet.hides(&placed, &standing, down, fixed(0.0)), "straight from below, touching");
        assert!(sheet.hides(&placed, &standing, down, fixed(1.7)), "with a margin that fits");
        assert!(!sheet.hides(&placed, &standing, down, fixed(1.8)), "margin beyond the floor's edge");
        assert!(!sheet.hides(&placed, &standing, Vec3::Y, fixed(0.0)), "the light above the floor");
        // The margin grows with the distance from the plane: 0.5 at the top corners only.
        assert!(sheet.hides(&placed, &standing, down, |d: f32| 3.5 * d));
        assert!(!sheet.hides(&placed, &standing, down, |d: f32| 3.6 * d));
        // 45° below the horizon: the top corners' shadows move 0.5 sideways.
        let slanted = Vec3::new(1.0, -1.0, 0.0).normalize();
        assert!(sheet.hides(&placed, &standing, slanted, fixed(1.2)));
        assert!(!sheet.hides(&placed, &standing, slanted, fixed(1.3)));
        assert!(
            !sheet.hides(&placed, &standing, Vec3::new(1.0, -1e-4, 0.0).normalize(), fixed(0.0)),
            "grazing"
        );
        let beside = corners(Vec3::new(1.9, -1.0, 0.0), Vec3::new(2.2, -0.5, 0.3));
        assert!(!sheet.hides(&placed, &beside, down, fixed(0.0)), "overhanging the edge");
    }
}
