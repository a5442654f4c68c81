//! What culling and fitting need to know of the groups: their object-space bounds, the sphere
//! around all of them as they stand, and the rotations of groups and environment.
use glam::{Mat3, Mat4, Vec3};

/// A group's bounds in its object space: what culling needs to know of it.
#[derive(Clone, Copy, Debug)]
pub struct GroupBounds {
    /// Bounding sphere.
    pub centre: Vec3,
    pub radius: f32,
    /// Axis-aligned box.
    pub min: Vec3,
    pub max: Vec3,
    /// The cone holding every vertex normal: unit axis and half-angle in radians (π or more:
    /// normals face every way).
    pub normal_axis: Vec3,
    pub normal_spread: f32,
}

impl GroupBounds {
    /// Whether no vertex of the group can receive light from object-space direction `w`.
    pub fn faces_away_from(&self, w: Vec3) -> bool {
        let angle = self.normal_axis.dot(w).clamp(-1.0, 1.0).acos();
        angle >= std::f32::consts::FRAC_PI_2 + self.normal_spread
    }

    /// The world positions of the box's corners, with `transform` placing the group.
    pub fn corners(&self, transform: &Mat4) -> [Vec3; 8] {
        box_corners(self.min, self.max, transform)
    }

    /// Whether this group (placed by `transform`) lies wholly on the far side of a world axis
    /// plane from `receiver`, with the light `w` on the receiver's side: then no ray from the
    /// receiver towards the light can meet it (a floor under anything lit from above). Such a
    /// pair must not get a layer: where the receiver is absent from a mask texel the occluder
    /// counts as in front of it, and the box filter would carry that into the receiver's
    /// silhouette as seen from the light, a false shadow along its terminator.
    pub fn behind_along_an_axis(
        &self,
        transform: &Mat4,
        receiver: &GroupBounds,
        placed: &Mat4,
        w: Vec3,
    ) -> bool {
        let world = |b: &GroupBounds, t: &Mat4| {
            b.corners(t)
                .iter()
                .fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), c| (lo.min(*c), hi.max(*c)))
        };
        let ((lo, hi), (r_lo, r_hi)) = (world(self, transform), world(receiver, placed));
        // Touching counts as behind (contact; the masks' contact bias already ignores it).
        let slack = 1e-4 * (r_hi - r_lo).max_element().max(1e-6);
        (0..3).any(|k| (hi[k] <= r_lo[k] + slack && w[k] >= 0.0) || (lo[k] >= r_hi[k] - slack && w[k] <= 0.0))
    }

    /// The smallest and largest signed distance along `w` of the box's corners from `origin`.
    pub fn extent_along(&self, transform: &Mat4, origin: Vec3, w: Vec3) -> (f32, f32) {
        self.corners(transform)
            .iter()
            .map(|c| (*c - origin).dot(w))
            .fold((f32::INFINITY, f32::NEG_INFINITY), |(lo, hi), d| (lo.min(d), hi.max(d)))
    }
}

/// The corners of the box `min`..`max`, placed by `transform`.
pub fn box_corners(min: Vec3, max: Vec3, transform: &Mat4) -> [Vec3; 8] {
    std::array::from_fn(|c| {
        transform.transform_point3(Vec3::new(
            if c & 1 == 0 { min.x } else { max.x },
            if c & 2 == 0 { min.y } else { max.y },
            if c & 4 == 0 { min.z } else { max.z },
        ))
    })
}

/// The object-space bounds of every group.
pub fn group_bounds(scene: &crate::scene::Scene) -> Vec<GroupBounds> {
    scene
        .groups
        .iter()
        .map(|g| {
            let points = || g.meshes.iter().flat_map(|m| m.positions.iter().map(|p| Vec3::from_array(*p)));
            let normals = || g.meshes.iter().flat_map(|m| m.normals.iter().map(|n| Vec3::from_array(*n)));
            let (min, max) =
                points().fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(a, b), p| (a.min(p), b.max(p)));
            let (min, max) = if min.x <= max.x { (min, max) } else { (Vec3::ZERO, Vec3::ZERO) };
            let centre = 0.5 * (min + max);
            let radius = points().map(|p| p.distance(centre)).fold(0.0, f32::max);
            let sum: Vec3 = normals().sum();
            let normal_axis = sum.try_normalize().unwrap_or(Vec3::Y);
            let normal_spread = if sum.length_squared() > 0.0 {
                normals().map(|n| normal_axis.dot(n).clamp(-1.0, 1.0).acos()).fold(0.0, f32::max)
            } else {
                std::f32::consts::PI
            };
            GroupBounds { centre, radius, min, max, normal_axis, normal_spread }
        })
        .collect()
}

/// The smallest sphere around the groups' bounding spheres that this simple construction finds
/// (centred on their box): each map covers all of it, so every group casts into every map.
pub fn scene_sphere(bounds: &[GroupBounds], transforms: &[Mat4]) -> (Vec3, f32) {
    let spheres: Vec<(Vec3, f32)> = bounds
        .iter()
        .zip(transforms)
        .map(|(b, t)| (t.transform_point3(b.centre), b.radius * t.x_axis.truncate().length()))
        .collect();
    let (lo, hi) = spheres
        .iter()
        .fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), &(c, r)| (lo.min(c - r), hi.max(c + r)));
    if spheres.is_empty() {
        return (Vec3::ZERO, 1.0);
    }
    let centre = 0.5 * (lo + hi);
    let radius = spheres.iter().map(|&(c, r)| c.distance(centre) + r).fold(0.0, f32::max);
    (centre, radius.max(1e-3))
}

/// The rotation part of a rigid transform with uniform scale.
pub fn rotation_of(transform: &Mat4) -> Mat3 {
    let m = Mat3::from_mat4(*transform);
    Mat3::from_cols(m.x_axis.normalize(), m.y_axis.normalize(), m.z_axis.normalize())
}

/// Rotation of the environment about +Y by `angle` radians.
pub fn env_rotation(angle: f32) -> Mat3 {
    Mat3::from_rotation_y(angle)
}
