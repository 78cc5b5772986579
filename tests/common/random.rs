//! Seeded random inputs: `rand`'s Xoshiro256++ (a named algorithm, so a seed gives the same
//! inputs on every platform and `rand` version, unlike `StdRng` or `SmallRng`), and the
//! geometric draws the traversal and spawn tests make.

use glam::Vec3;
use rand::rngs::Xoshiro256PlusPlus;
use rand::{Rng, RngExt, SeedableRng};

/// The tests' generator.
pub type TestRng = Xoshiro256PlusPlus;

/// A generator for `seed`.
pub fn seeded(seed: u64) -> TestRng {
    TestRng::seed_from_u64(seed)
}

/// Geometric draws on any `rand` generator.
pub trait Draw: Rng {
    /// Uniform in [0, 1).
    fn unit(&mut self) -> f32 {
        self.random()
    }

    /// A uniform point in the box [lo, hi].
    fn in_box(&mut self, lo: Vec3, hi: Vec3) -> Vec3 {
        let t = Vec3::new(self.unit(), self.unit(), self.unit());
        lo + (hi - lo) * t
    }

    /// A point in the cube [−half, half]³.
    fn point(&mut self, half: f32) -> Vec3 {
        self.in_box(Vec3::splat(-half), Vec3::splat(half))
    }

    /// A uniform unit direction (rejection from the unit ball, away from its centre).
    fn direction(&mut self) -> Vec3 {
        loop {
            let v = self.in_box(Vec3::splat(-1.0), Vec3::ONE);
            if v.length_squared() > 1e-3 && v.length_squared() <= 1.0 {
                return v.normalize();
            }
        }
    }
}

impl<R: Rng + ?Sized> Draw for R {}
