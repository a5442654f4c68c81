//! A small reproducible random source for the stochastic walks and the insertion order.

/// Marsaglia's xorshift32: enough to break the symmetry of a walk, and reproducible.
#[derive(Clone, Debug)]
pub struct XorShift(u32);

impl XorShift {
    pub fn new(seed: u32) -> XorShift {
        XorShift(seed.max(1))
    }

    pub fn next_u32(&mut self) -> u32 {
        let mut x = self.0;
        x ^= x << 13;
        x ^= x >> 17;
        x ^= x << 5;
        self.0 = x;
        x
    }

    /// Uniform in 0..n (n ≥ 1), by multiply-shift.
    pub fn below(&mut self, n: u32) -> u32 {
        ((self.next_u32() as u64 * n as u64) >> 32) as u32
    }
}
