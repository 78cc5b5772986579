//! proptest strategies for kernel inputs: finite coordinates in a box, and floats that are
//! mostly finite but include every special value the kernels must survive.

use glam::Vec3;
use proptest::prelude::*;

/// A finite coordinate in [−half, half).
pub fn finite(half: f32) -> impl Strategy<Value = f32> + Clone {
    -half..half
}

/// A point with finite coordinates in [−half, half)³.
pub fn vec3(half: f32) -> impl Strategy<Value = Vec3> + Clone {
    (finite(half), finite(half), finite(half)).prop_map(|(x, y, z)| Vec3::new(x, y, z))
}

/// Mostly `finite(half)`, sometimes ±0.0, ±∞, NaN or any bit pattern.
pub fn any_f32(half: f32) -> impl Strategy<Value = f32> + Clone {
    prop_oneof![
        8 => finite(half),
        1 => Just(0.0f32),
        1 => Just(-0.0f32),
        1 => Just(f32::INFINITY),
        1 => Just(f32::NEG_INFINITY),
        1 => Just(f32::NAN),
        1 => any::<f32>(),
    ]
}
