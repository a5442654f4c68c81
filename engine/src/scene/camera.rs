//! A pinhole camera and the matrices the renderer draws with.
use glam::{Mat4, Vec3};

use super::SceneError;

/// Clip planes of every projection. The scenes Kage renders are a few units across; with a 32-bit
/// float depth buffer this range keeps depth precision far below a pixel.
pub const NEAR: f32 = 0.01;
pub const FAR: f32 = 1000.0;

#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Camera {
    pub position: Vec3,
    pub target: Vec3,
    pub up: Vec3,
    /// Vertical field of view, in (0, 180) degrees.
    pub fov_y_deg: f32,
}

impl Camera {
    /// World to view space (right-handed, looking down −Z).
    pub fn view(&self) -> Mat4 {
        Mat4::look_at_rh(self.position, self.target, self.up)
    }

    /// View to Vulkan clip space: depth 0 at [`NEAR`] to 1 at [`FAR`], and Y negated because
    /// Vulkan's framebuffer Y points down; so +Y in the world is up in the image (row 0 = top).
    pub fn projection(&self, aspect: f32) -> Mat4 {
        self.projection_from(aspect, NEAR)
    }

    /// The eye rays of [`Camera::projection`] at `aspect`, as `[x, y, forward]`: the ray through
    /// NDC point (x, y) points along `forward + x * ndc.x + y * ndc.y` (unit view depth). In double
    /// precision from the camera's basis, because unprojecting through the inverse of the
    /// view-projection in float strays about 1/50 px (the near plane's conditioning), which moves
    /// a pixel's ray across edges the rasterizer places to 1/256 px.
    pub fn eye_rays(&self, aspect: f32) -> [Vec3; 3] {
        let forward = (self.target.as_dvec3() - self.position.as_dvec3()).normalize();
        let right = forward.cross(self.up.as_dvec3()).normalize();
        let up = right.cross(forward);
        let tan = (f64::from(self.fov_y_deg).to_radians() * 0.5).tan();
        // NDC y grows downward (the projection's flip).
        [right * tan * f64::from(aspect), -up * tan, forward].map(|v| v.as_vec3())
    }

    /// [`Camera::projection`] with the near plane at `near` instead of [`NEAR`].
    pub fn projection_from(&self, aspect: f32, near: f32) -> Mat4 {
        let flip_y = Mat4::from_scale(Vec3::new(1.0, -1.0, 1.0));
        flip_y * Mat4::perspective_rh(self.fov_y_deg.to_radians(), aspect, near, FAR)
    }

    /// A checked camera from plain arrays, as scene files and the C ABI give it.
    pub fn from_arrays(
        position: [f32; 3],
        target: [f32; 3],
        up: [f32; 3],
        fov_y_deg: f32,
    ) -> Result<Camera, SceneError> {
        Camera { position: Vec3::from(position), target: Vec3::from(target), up: Vec3::from(up), fov_y_deg }
            .validated()
    }

    /// Checks that the view and projection matrices will be well defined.
    pub fn validated(self) -> Result<Camera, SceneError> {
        for (name, v) in [("position", self.position), ("target", self.target), ("up", self.up)] {
            if !v.is_finite() {
                return Err(SceneError::invalid(format!("camera {name} {v} is not finite")));
            }
        }
        // Directions scaled by their largest component before normalizing: far-away points
        // (1e30) would overflow a squared length, and tiny vectors underflow one.
        let direction =
            |v: Vec3| (v.abs().max_element() > 0.0).then(|| (v / v.abs().max_element()).normalize());
        let Some(forward) = direction(self.target - self.position).filter(|f| f.is_finite()) else {
            return Err(SceneError::invalid(format!(
                "camera position {} and target {} are the same point, or too far apart for f32",
                self.position, self.target
            )));
        };
        let Some(up) = direction(self.up) else {
            return Err(SceneError::invalid("camera up vector has zero length"));
        };
        if forward.cross(up).length_squared() < 1e-12 {
            return Err(SceneError::invalid("camera up vector is parallel to the viewing direction"));
        }
        if !(self.fov_y_deg > 0.0 && self.fov_y_deg < 180.0) {
            return Err(SceneError::invalid(format!(
                "camera fov_y_deg must be in (0, 180) degrees, got {}",
                self.fov_y_deg
            )));
        }
        Ok(self)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn camera() -> Camera {
        Camera { position: Vec3::new(0.0, 0.0, 5.0), target: Vec3::ZERO, up: Vec3::Y, fov_y_deg: 60.0 }
    }

    /// A camera far away or with a tiny up vector is still a camera, not "up is parallel".
    #[test]
    fn far_cameras_and_tiny_up_vectors_are_valid() {
        let far = Camera { position: Vec3::new(0.0, 0.0, 1e30), ..camera() };
        far.validated().unwrap();
        Camera { up: Vec3::new(0.0, 1e-30, 0.0), ..camera() }.validated().unwrap();
        let parallel = Camera { up: Vec3::Z, ..far }.validated().unwrap_err().to_string();
        assert!(parallel.contains("parallel"), "{parallel}");
    }

    #[test]
    fn world_up_is_image_top_and_depth_is_zero_to_one() {
        let c = camera();
        let clip = c.projection(1.0) * c.view();
        let above = clip.project_point3(Vec3::new(0.0, 1.0, 0.0));
        // Vulkan NDC: y = -1 is the top row.
        assert!(above.y < 0.0);
        let near = clip.project_point3(Vec3::new(0.0, 0.0, 5.0 - NEAR));
        let far = clip.project_point3(Vec3::new(0.0, 0.0, 5.0 - FAR));
        assert!(near.z.abs() < 1e-5 && (far.z - 1.0).abs() < 1e-5);
    }

    /// Each eye ray lands where the rasterizer's matrices (evaluated exactly) put its NDC point,
    /// to 1/2000 of a pixel at 512² (2 NDC units a side): unprojecting through the inverse
    /// view-projection in float misses by about 1/50 px.
    #[test]
    fn eye_rays_pass_through_their_ndc_points() {
        let c = Camera {
            position: Vec3::new(4.5, 3.2, 6.1),
            target: Vec3::new(0.3, 0.4, 0.2),
            up: Vec3::Y,
            fov_y_deg: 50.0,
        };
        let aspect = 1.5;
        let view_proj = (c.projection(aspect) * c.view()).as_dmat4();
        let [x, y, forward] = c.eye_rays(aspect);
        let mut worst = 0.0f64;
        for i in 0..=8 {
            for j in 0..=8 {
                let ndc = glam::DVec2::new(i as f64 / 4.0 - 1.0, j as f64 / 4.0 - 1.0);
                let dir = (forward + x * ndc.x as f32 + y * ndc.y as f32).as_dvec3();
                let landed = view_proj.project_point3(c.position.as_dvec3() + dir * 3.0);
                worst = worst.max((landed.truncate() - ndc).abs().max_element());
            }
        }
        assert!(worst < 2.0 / 512.0 / 2000.0, "an eye ray misses its NDC point by {worst}");
    }

    #[test]
    fn bad_cameras_are_rejected() {
        assert!(camera().validated().is_ok());
        let bad = [
            Camera { target: camera().position, ..camera() },
            Camera { up: Vec3::ZERO, ..camera() },
            Camera { up: Vec3::Z, ..camera() },
            Camera { fov_y_deg: 0.0, ..camera() },
            Camera { fov_y_deg: 180.0, ..camera() },
            Camera { fov_y_deg: f32::NAN, ..camera() },
            Camera { position: Vec3::new(f32::NAN, 0.0, 0.0), ..camera() },
        ];
        for c in bad {
            assert!(c.validated().is_err(), "{c:?}");
        }
    }
}
