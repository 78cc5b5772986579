//! One value per kind of ray: [`PerKind`] holds every per-kind figure (rays cast, each kind's
//! thread-time, its rate, a record's figures), indexed and iterated by [`RayKind`]. Only rays
//! actually cast count: a masked-off SIMD lane is not a ray.

use serde::{Deserialize, Serialize};
use std::ops::{Add, AddAssign, Index, IndexMut};
use std::time::{Duration, Instant};

/// The kinds of ray, in report order.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum RayKind {
    /// Primary rays from the camera.
    Camera,
    /// Occlusion rays towards light sample points.
    Shadow,
    /// Mirror rays.
    Reflection,
}

impl RayKind {
    /// Every kind, in report order.
    pub const ALL: [RayKind; 3] = [RayKind::Camera, RayKind::Shadow, RayKind::Reflection];

    /// The kind's name in reports and records: `camera`, `shadow`, `reflection`.
    pub fn name(self) -> &'static str {
        match self {
            RayKind::Camera => "camera",
            RayKind::Shadow => "shadow",
            RayKind::Reflection => "reflection",
        }
    }
}

/// A `T` for each kind of ray. Serialised as `{"camera": .., "shadow": .., "reflection": ..}`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(feature = "tools", derive(schemars::JsonSchema))]
pub struct PerKind<T> {
    /// Primary rays from the camera.
    pub camera: T,
    /// Occlusion rays towards light sample points.
    pub shadow: T,
    /// Mirror rays.
    pub reflection: T,
}

/// Rays cast, by kind.
pub type RayCounts = PerKind<u64>;

impl<T> PerKind<T> {
    /// `f(kind)` for each kind.
    pub fn from_fn(mut f: impl FnMut(RayKind) -> T) -> PerKind<T> {
        PerKind {
            camera: f(RayKind::Camera),
            shadow: f(RayKind::Shadow),
            reflection: f(RayKind::Reflection),
        }
    }

    /// `f` of each kind's value.
    pub fn map<U>(self, mut f: impl FnMut(T) -> U) -> PerKind<U> {
        PerKind {
            camera: f(self.camera),
            shadow: f(self.shadow),
            reflection: f(self.reflection),
        }
    }

    /// (kind, value) in report order.
    pub fn iter(&self) -> impl Iterator<Item = (RayKind, &T)> {
        RayKind::ALL.into_iter().map(move |k| (k, &self[k]))
    }
}

impl PerKind<u64> {
    /// All kinds together.
    pub fn total(&self) -> u64 {
        self.camera + self.shadow + self.reflection
    }
}

impl<T> Index<RayKind> for PerKind<T> {
    type Output = T;
    #[inline]
    fn index(&self, kind: RayKind) -> &T {
        match kind {
            RayKind::Camera => &self.camera,
            RayKind::Shadow => &self.shadow,
            RayKind::Reflection => &self.reflection,
        }
    }
}

impl<T> IndexMut<RayKind> for PerKind<T> {
    #[inline]
    fn index_mut(&mut self, kind: RayKind) -> &mut T {
        match kind {
            RayKind::Camera => &mut self.camera,
            RayKind::Shadow => &mut self.shadow,
            RayKind::Reflection => &mut self.reflection,
        }
    }
}

impl<T: Add<Output = T> + Copy> Add for PerKind<T> {
    type Output = PerKind<T>;
    fn add(self, o: PerKind<T>) -> PerKind<T> {
        PerKind::from_fn(|k| self[k] + o[k])
    }
}

impl<T: AddAssign + Copy> AddAssign for PerKind<T> {
    fn add_assign(&mut self, o: PerKind<T>) {
        for k in RayKind::ALL {
            self[k] += o[k];
        }
    }
}

/// Where a renderer reports the time of each kind's work: `()` measures nothing and costs
/// nothing (the timers compile away), `PerKind<Duration>` reads the clock and sums
/// thread-time per kind.
///
/// Camera: making camera rays and finding their closest hits (with the surface data there).
/// Reflection: making mirror rays and finding their closest hits. Shadow: spawning shadow
/// rays, the occlusion tests and the Shade sums. What no kind owns (the film, the ambient
/// term) is in none of them.
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

impl KindClock for PerKind<Duration> {
    type Mark = Instant;
    #[inline(always)]
    fn mark(&self) -> Instant {
        Instant::now()
    }
    #[inline(always)]
    fn since(&mut self, kind: RayKind, since: Instant) -> Instant {
        let now = Instant::now();
        self[kind] += now - since;
        now
    }
}
