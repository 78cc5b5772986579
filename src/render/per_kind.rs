//! Ray counters by kind, and the thread-time of each kind's work. Only rays actually cast
//! count: a masked-off SIMD lane is not a ray.

use serde::{Deserialize, Serialize};
use std::ops::{Add, AddAssign};
use std::time::{Duration, Instant};

/// Rays cast, by kind.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(feature = "tools", derive(schemars::JsonSchema))]
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

/// The kinds of ray, in report order.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RayKind {
    /// Primary rays from the camera.
    Camera,
    /// Occlusion rays towards light sample points.
    Shadow,
    /// Mirror rays.
    Reflection,
}

/// Thread-time spent on each kind's work, summed over worker threads.
///
/// Camera: making camera rays and finding their closest hits (with the surface data there).
/// Reflection: making mirror rays and finding their closest hits. Shadow: spawning shadow
/// rays, the occlusion tests and the Shade sums. What no kind owns (the film, the ambient
/// term) is in none of them.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct KindTimes {
    /// Camera rays' work.
    pub camera: Duration,
    /// Shadow rays' work.
    pub shadow: Duration,
    /// Mirror rays' work.
    pub reflection: Duration,
}

impl KindTimes {
    /// Adds `d` to `kind`.
    #[inline]
    pub fn add(&mut self, kind: RayKind, d: Duration) {
        match kind {
            RayKind::Camera => self.camera += d,
            RayKind::Shadow => self.shadow += d,
            RayKind::Reflection => self.reflection += d,
        }
    }
}

impl Add for KindTimes {
    type Output = KindTimes;
    fn add(self, o: KindTimes) -> KindTimes {
        KindTimes {
            camera: self.camera + o.camera,
            shadow: self.shadow + o.shadow,
            reflection: self.reflection + o.reflection,
        }
    }
}

/// Where a renderer reports the time of each kind's work: `()` measures nothing and costs
/// nothing (the timers compile away), [`KindTimes`] reads the clock.
pub trait KindClock {
    /// A point in time (`()` for the clock that measures nothing).
    type Mark: Copy;
    /// Now.
    fn mark(&self) -> Self::Mark;
    /// Adds the time since `since` to `kind`, and returns now (the start of what follows:
    /// one clock read ends one interval and begins the next).
    fn since(&mut self, kind: RayKind, since: Self::Mark) -> Self::Mark;
}

impl KindClock for () {
    type Mark = ();
    #[inline(always)]
    fn mark(&self) {}
    #[inline(always)]
    fn since(&mut self, _: RayKind, _: ()) {}
}

impl KindClock for KindTimes {
    type Mark = Instant;
    #[inline(always)]
    fn mark(&self) -> Instant {
        Instant::now()
    }
    #[inline(always)]
    fn since(&mut self, kind: RayKind, since: Instant) -> Instant {
        let now = Instant::now();
        self.add(kind, now - since);
        now
    }
}
