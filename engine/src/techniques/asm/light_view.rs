//! Tiles and groups in the light's view: a tile's projection (the light's, cropped to the
//! tile's square of the view), and the rectangle of the view a group's box covers, which decides
//! the groups a tile draws and the tiles a moving group invalidates.
use super::tile::TileKey;
use glam::{Mat4, Vec2, Vec3, Vec4};

/// A rectangle of the light's view uv (u right, v down, the unit square the whole view).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct UvRect {
    pub min: Vec2,
    pub max: Vec2,
}

impl UvRect {
    pub const VIEW: UvRect = UvRect { min: Vec2::ZERO, max: Vec2::ONE };

    /// The square a tile covers.
    pub fn of_tile(key: TileKey) -> UvRect {
        let side = 1.0 / (1u64 << key.level) as f32;
        let min = Vec2::new(key.x as f32, key.y as f32) * side;
        UvRect { min, max: min + Vec2::splat(side) }
    }

    /// The bounds of a world-space box's projection through `view_proj` (the light's map). A box
    /// reaching behind the light's plane projects without bounds: the whole view.
    pub fn of_box(view_proj: &Mat4, min: Vec3, max: Vec3) -> UvRect {
        let mut rect = UvRect { min: Vec2::INFINITY, max: Vec2::NEG_INFINITY };
        for corner in 0..8 {
            let pick = |bit: usize, lo: f32, hi: f32| if corner >> bit & 1 == 0 { lo } else { hi };
            let p = Vec3::new(pick(0, min.x, max.x), pick(1, min.y, max.y), pick(2, min.z, max.z));
            let clip: Vec4 = *view_proj * p.extend(1.0);
            if clip.w <= 1e-6 {
                return UvRect::VIEW;
            }
            let uv = Vec2::new(clip.x, clip.y) / clip.w * 0.5 + 0.5;
            rect = UvRect { min: rect.min.min(uv), max: rect.max.max(uv) };
        }
        rect
    }

    /// Whether the two share more than an edge.
    pub fn overlaps(&self, other: &UvRect) -> bool {
        self.min.x < other.max.x
            && other.min.x < self.max.x
            && self.min.y < other.max.y
            && other.min.y < self.max.y
    }
}

/// World to the clip space of tile `key`: the light's `view_proj` followed by the crop and
/// scale that maps the tile's square of the view onto the whole of clip x, y ∈ [−1, 1]
/// (depth unchanged, so tiles store the same depths as the light's full map). Composed in
/// double precision: the crop's scale reaches 2^KAGE_ASM_MAX_LEVEL.
pub fn tile_view_proj(view_proj: &Mat4, key: TileKey) -> Mat4 {
    let s = (1u64 << key.level) as f64;
    // uv' = s uv − x, so ndc' = s ndc + (s − 2x − 1), times w in clip space.
    let crop = glam::DMat4::from_cols(
        glam::DVec4::new(s, 0.0, 0.0, 0.0),
        glam::DVec4::new(0.0, s, 0.0, 0.0),
        glam::DVec4::Z,
        glam::DVec4::new(s - 2.0 * f64::from(key.x) - 1.0, s - 2.0 * f64::from(key.y) - 1.0, 0.0, 1.0),
    );
    (crop * view_proj.as_dmat4()).as_mat4()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_tile_projection_maps_its_square_onto_the_whole_clip_space() {
        let view_proj = Mat4::perspective_rh(1.2, 1.0, 0.1, 10.0)
            * Mat4::look_at_rh(Vec3::new(0.0, 3.0, 0.0), Vec3::ZERO, Vec3::X);
        let key = TileKey { level: 3, x: 5, y: 2 };
        let rect = UvRect::of_tile(key);
        let tile = tile_view_proj(&view_proj, key);
        // A point at a uv inside the tile: unproject from the light's clip space at depth 0.5.
        for uv in [rect.min, rect.max, 0.5 * (rect.min + rect.max), rect.min + Vec2::new(0.1, 0.02)] {
            let ndc = (uv * 2.0 - 1.0).extend(0.5).extend(1.0);
            let world = view_proj.inverse() * ndc;
            let p = world.truncate() / world.w;
            let full: Vec4 = view_proj * p.extend(1.0);
            let cropped: Vec4 = tile * p.extend(1.0);
            let local = Vec2::new(cropped.x, cropped.y) / cropped.w * 0.5 + 0.5;
            let expected = (uv - rect.min) / (rect.max - rect.min);
            assert!((local - expected).abs().max_element() < 1e-4, "{uv}: {local} against {expected}");
            assert!((cropped.z / cropped.w - full.z / full.w).abs() < 1e-6, "depth kept");
        }
        // A box under the light projects around the view's centre; one beside the light's
        // plane covers the whole view.
        let under = UvRect::of_box(&view_proj, Vec3::splat(-0.1), Vec3::splat(0.1));
        assert!(under.overlaps(&UvRect::of_tile(TileKey { level: 1, x: 0, y: 0 })));
        assert!(!under.overlaps(&UvRect::of_tile(TileKey { level: 2, x: 0, y: 0 })));
        let beside = UvRect::of_box(&view_proj, Vec3::new(-1.0, 2.0, -1.0), Vec3::new(1.0, 4.0, 1.0));
        assert_eq!(beside, UvRect::VIEW);
    }
}
