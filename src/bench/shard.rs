//! `raywave bench --shard I/N --out DIR`: a sweep as sharded work. Each job computes the whole
//! sweep's identity and the same split, benches only its own points, and leaves one part
//! (`crate::shard`, which also merges them); this file says what a sweep's items are.
//!
//! ```text
//! item        a point of the sweep (a size, shadow-sample count and thread count)
//! cost(point) = width · height · (1 + lights · shadow rays per light) · (runs + warm-up) / threads
//! result      the point's BenchRecord; it must carry the point's setup, the identity's build
//!             and SIMD path, and the sweep's run counts
//! ```

use crate::output::bench_record::{self as record, BenchRecord, Setup};
use crate::render::settings::ShadowMode;
use crate::shard::{Identity, Work};
use serde::{Deserialize, Serialize};

/// The estimated cost of timing one point: the rays its renders cast (camera rays, and a
/// shadow ray per light and shadow point, at every pixel; bounces and anti-aliasing are the
/// same at every point of a sweep), over all warm-up and timed runs, per worker thread, since
/// a point on one thread takes about twice as long as on two.
pub fn cost(setup: &Setup, runs: u32, warmup: u32) -> f64 {
    let s = &setup.settings;
    let per_light = match s.shadows {
        ShadowMode::Off => 0,
        ShadowMode::Hard => 1,
        ShadowMode::Soft => u64::from(s.shadow_samples),
    };
    let per_pixel = 1 + setup.scene.lights as u64 * per_light;
    let rays = u64::from(s.width) as f64
        * f64::from(s.height)
        * per_pixel as f64
        * f64::from(runs + warmup);
    rays / setup.threads.max(1) as f64
}

/// What makes a sweep the same sweep, besides the build: the engines, the run counts, and
/// every point's setup (scene, with its text's hash; settings; threads; batch size).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SweepPoints {
    /// The engines timed, in record order.
    pub engines: Vec<String>,
    /// Timed runs per engine.
    pub runs: u32,
    /// Untimed runs per engine before the timed ones.
    pub warmup: u32,
    /// Every point of the sweep, in sweep order (sizes outermost, threads innermost).
    pub points: Vec<SweepPoint>,
}

/// One point of a sweep, as its identity holds it.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SweepPoint {
    /// The swept values, `16x16+t1`; empty for a sweep of one point.
    pub label: String,
    /// Scene, settings, threads, batch size.
    pub setup: Setup,
    /// The estimated cost ([`cost`]) the split is made by.
    pub cost: f64,
}

impl Work for SweepPoints {
    const KIND: &'static str = "bench";
    const NOUN: &'static str = "sweep";
    const COMMAND: &'static str = "raywave bench --shard I/N";
    const SAME_RUN: &'static str = "run every shard with the same scene and flags (give \
        --threads when the machines' core counts differ)";
    type Result = BenchRecord;
    type Extra = ();

    fn costs(&self) -> Vec<f64> {
        self.points.iter().map(|p| p.cost).collect()
    }

    /// Scene file names are not compared (their text's hash is).
    fn differences(&self, other: &SweepPoints, a: &str, b: &str) -> Vec<String> {
        let mut out = Vec::new();
        let mut field = |name: &str, x: String, y: String| {
            if x != y {
                out.push(format!("{name}: {x} {a}, {y} {b}"));
            }
        };
        field("engines", self.engines.join(","), other.engines.join(","));
        field("runs", self.runs.to_string(), other.runs.to_string());
        field("warmup", self.warmup.to_string(), other.warmup.to_string());
        let labels = |s: &SweepPoints| {
            let v: Vec<&str> = s.points.iter().map(|p| p.label.as_str()).collect();
            format!("[{}]", v.join(", "))
        };
        field("points", labels(self), labels(other));
        if out.is_empty() {
            for (p, q) in self.points.iter().zip(&other.points) {
                let at = Some(p.label.as_str())
                    .filter(|l| !l.is_empty())
                    .unwrap_or("point");
                for d in super::compare::setup_differences(&p.setup, &q.setup, a, b) {
                    out.push(format!("{at}: {d}"));
                }
            }
        }
        out
    }

    fn check_results(
        identity: &Identity<SweepPoints>,
        items: &[usize],
        records: &[BenchRecord],
    ) -> Option<String> {
        let sweep = &identity.work;
        for (&i, r) in items.iter().zip(records) {
            let point = &sweep.points[i];
            let problem = if r.format != record::FORMAT {
                format!("record format {}, expected {}", r.format, record::FORMAT)
            } else if r.setup != point.setup {
                "the record's setup is not the sweep's".to_string()
            } else if (&r.raywave, &r.build, &r.simd)
                != (&identity.raywave, &identity.build, &identity.simd)
            {
                "the record's build is not the sweep's".to_string()
            } else if (r.runs, r.warmup) != (sweep.runs, sweep.warmup) {
                "the record's run counts are not the sweep's".to_string()
            } else {
                continue;
            };
            let at = Some(point.label.as_str()).filter(|l| !l.is_empty());
            return Some(format!("{}: {problem}", at.unwrap_or("the point")));
        }
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::output::bench_record::SceneId;
    use crate::render::settings::RenderSettings;

    fn setup(width: u32, shadows: ShadowMode, samples: u32, threads: usize) -> Setup {
        Setup {
            scene: SceneId {
                source: "s.obj".into(),
                text_hash: "0123456789abcdef".into(),
                triangles: 2,
                spheres: 0,
                lights: 3,
            },
            settings: RenderSettings {
                width,
                height: 10,
                shadows,
                shadow_samples: samples,
                ..RenderSettings::default()
            },
            threads,
            batch_size: 64,
        }
    }

    #[test]
    fn the_cost_counts_rays_of_every_run_per_thread() {
        // 20 × 10 pixels, (1 camera + 3 lights × 4 points) rays each, 6 + 1 runs, 2 threads.
        let soft = cost(&setup(20, ShadowMode::Soft, 4, 2), 6, 1);
        assert_eq!(soft, 200.0 * 13.0 * 7.0 / 2.0);
        assert_eq!(cost(&setup(20, ShadowMode::Soft, 4, 1), 6, 1), 2.0 * soft);
        assert_eq!(
            cost(&setup(20, ShadowMode::Hard, 4, 1), 6, 1),
            200.0 * 4.0 * 7.0
        );
        assert_eq!(cost(&setup(20, ShadowMode::Off, 4, 1), 6, 1), 200.0 * 7.0);
    }
}
