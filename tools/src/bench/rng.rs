//! A small reproducible generator for the benchmarks' random sets.
use glam::Vec3;

/// PCG32 (O'Neill 2014): reproducible ray sets without a dependency.
pub struct Pcg32(pub u64);

impl Pcg32 {
    /// Uniform in [0, 1).
    pub fn next(&mut self) -> f32 {
        self.0 = self.0.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1_442_695_040_888_963_407);
        let x = ((((self.0 >> 18) ^ self.0) >> 27) as u32).rotate_right((self.0 >> 59) as u32);
        (x >> 8) as f32 / (1 << 24) as f32
    }

    /// Uniform on the unit sphere.
    pub fn unit_vector(&mut self) -> Vec3 {
        let z = 2.0 * self.next() - 1.0;
        let phi = std::f32::consts::TAU * self.next();
        let r = (1.0 - z * z).max(0.0).sqrt();
        Vec3::new(r * phi.cos(), r * phi.sin(), z)
    }
}
