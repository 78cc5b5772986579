//! Ray counters by kind. Only rays actually cast count: a masked-off SIMD lane is not a ray.

use serde::{Deserialize, Serialize};
use std::ops::{Add, AddAssign};

/// Rays cast, by kind.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct RayCounts {
    /// Primary rays from the camera.
    pub camera: u64,
    /// Occlusion rays towards light sample points.
    pub shadow: u64,
    /// Mirror rays.
    pub reflection: u64,
}

impl RayCounts {
    /// All kinds together.
    pub fn total(&self) -> u64 {
        self.camera + self.shadow + self.reflection
    }
}

impl Add for RayCounts {
    type Output = RayCounts;
    fn add(self, o: RayCounts) -> RayCounts {
        RayCounts {
            camera: self.camera + o.camera,
            shadow: self.shadow + o.shadow,
            reflection: self.reflection + o.reflection,
        }
    }
}

impl AddAssign for RayCounts {
    fn add_assign(&mut self, o: RayCounts) {
        *self = *self + o;
    }
}
