//! Progressive render jobs, as the lab's `r` key renders: the image at 1/8, 1/4, 1/2 and full
//! resolution, each level a PNG the page shows as soon as it exists. One render thread works
//! through the jobs; a new job supersedes every older one, which stops at its next level (the
//! engines cannot stop inside an image, and a level is short).
//!
//! ```text
//! POST /api/render -> Jobs::submit -> channel -> render thread:
//!     for level in 1/8, 1/4, 1/2, 1:  stop if superseded
//!         Engine::prepare(scene with the job's camera, settings at the level's size).render
//!         -> PNG + ray counts and seconds -> JobState (read by GET /api/render/{id})
//! ```

use crate::output::bench_record::KindRates;
use crate::output::image_file::png_bytes;
use crate::render::engine::Engine;
use crate::render::film::ToneMap;
use crate::render::per_kind::RayCounts;
use crate::render::scene::Scene;
use crate::view::request::{Resolved, ViewSettings};
use serde::Serialize;
use std::collections::VecDeque;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::mpsc::{Receiver, Sender};
use std::sync::{Arc, Mutex};
use std::time::Instant;

/// How many finished jobs are kept for their images and pixels.
pub(crate) const KEPT_JOBS: usize = 8;

/// The divisors of the levels, coarse to fine.
pub(crate) const LEVEL_DIVISORS: [u32; 4] = [8, 4, 2, 1];

/// Where a job is.
#[derive(Clone, Debug, PartialEq, Serialize)]
#[serde(rename_all = "lowercase", tag = "state", content = "error")]
pub(crate) enum Status {
    /// Waiting for the render thread.
    Queued,
    /// Rendering level `levels_done`.
    Running,
    /// Every level rendered.
    Done,
    /// A newer job took its place before it finished.
    Superseded,
    /// The render failed (the message says why).
    Failed(String),
}

/// One rendered level.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub(crate) struct Level {
    /// Image width.
    pub width: u32,
    /// Image height.
    pub height: u32,
    /// Seconds the engine took (set-up included).
    pub seconds: f64,
    /// Rays cast, by kind.
    pub rays: RayCounts,
    /// Each kind's rays per thread-second of its own work (null when not measured: the
    /// reference renders without kind timers), and all rays per wall-clock second.
    pub rays_per_second: KindRates,
}

/// What the page polls.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub(crate) struct JobStatus {
    /// The job's id.
    pub job: u64,
    /// Where it is.
    #[serde(flatten)]
    pub status: Status,
    /// Sizes of every level, coarse to fine.
    pub sizes: Vec<[u32; 2]>,
    /// The levels rendered so far.
    pub levels: Vec<Level>,
    /// Work units done in the level being rendered, and of how many (tiles or rows).
    pub progress: [u64; 2],
    /// The settings, all filled in.
    pub settings: ViewSettings,
}

/// One job: its inputs, and what it has produced so far.
pub(crate) struct Job {
    /// Its id (increasing).
    pub id: u64,
    /// The settings and camera at full resolution.
    pub resolved: Resolved,
    /// The level sizes.
    pub sizes: Vec<[u32; 2]>,
    superseded: AtomicBool,
    done_units: AtomicU64,
    total_units: AtomicU64,
    state: Mutex<JobState>,
}

struct JobState {
    status: Status,
    levels: Vec<Level>,
    pngs: Vec<Arc<Vec<u8>>>,
}

impl Job {
    /// The status for the page.
    pub(crate) fn status(&self) -> JobStatus {
        let state = self.state.lock().unwrap_or_else(|e| e.into_inner());
        JobStatus {
            job: self.id,
            status: state.status.clone(),
            sizes: self.sizes.clone(),
            levels: state.levels.clone(),
            progress: [
                self.done_units.load(Ordering::Relaxed),
                self.total_units.load(Ordering::Relaxed),
            ],
            settings: self.resolved.to_json(),
        }
    }

    /// Level `k`'s PNG, once rendered.
    pub(crate) fn png(&self, k: usize) -> Option<Arc<Vec<u8>>> {
        let state = self.state.lock().unwrap_or_else(|e| e.into_inner());
        state.pngs.get(k).cloned()
    }

    fn set_status(&self, status: Status) {
        self.state.lock().unwrap_or_else(|e| e.into_inner()).status = status;
    }
}

/// The sizes of the levels of a `width` × `height` image: each divisor's, rounded up, without
/// repeats (a 10-pixel image has fewer than four levels).
pub(crate) fn level_sizes(width: u32, height: u32) -> Vec<[u32; 2]> {
    let mut sizes: Vec<[u32; 2]> = Vec::new();
    for d in LEVEL_DIVISORS {
        let s = [width.div_ceil(d), height.div_ceil(d)];
        if sizes.last() != Some(&s) {
            sizes.push(s);
        }
    }
    sizes
}

/// The jobs, and the channel to the render thread.
pub(crate) struct Jobs {
    next: AtomicU64,
    kept: Mutex<VecDeque<Arc<Job>>>,
    queue: Mutex<Sender<Arc<Job>>>,
}

impl Jobs {
    /// Starts the render thread, which renders on `pool` with `batch_size` (the wavefront
    /// engine's tile) and reads `scene`.
    pub(crate) fn start(
        scene: Arc<Scene>,
        pool: Arc<rayon::ThreadPool>,
        batch_size: usize,
    ) -> std::io::Result<Arc<Jobs>> {
        let (tx, rx) = std::sync::mpsc::channel();
        let jobs = Arc::new(Jobs {
            next: AtomicU64::new(1),
            kept: Mutex::new(VecDeque::new()),
            queue: Mutex::new(tx),
        });
        std::thread::Builder::new()
            .name("render".into())
            .spawn(move || render_thread(rx, &scene, &pool, batch_size))?;
        Ok(jobs)
    }

    /// Queues a job; every older job is superseded.
    pub(crate) fn submit(&self, resolved: Resolved) -> Arc<Job> {
        let id = self.next.fetch_add(1, Ordering::Relaxed);
        let sizes = level_sizes(resolved.settings.width, resolved.settings.height);
        let job = Arc::new(Job {
            id,
            resolved,
            sizes,
            superseded: AtomicBool::new(false),
            done_units: AtomicU64::new(0),
            total_units: AtomicU64::new(0),
            state: Mutex::new(JobState {
                status: Status::Queued,
                levels: Vec::new(),
                pngs: Vec::new(),
            }),
        });
        let mut kept = self.kept.lock().unwrap_or_else(|e| e.into_inner());
        for old in kept.iter() {
            old.superseded.store(true, Ordering::Relaxed);
        }
        kept.push_back(job.clone());
        while kept.len() > KEPT_JOBS {
            kept.pop_front();
        }
        drop(kept);
        let sent = self
            .queue
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .send(job.clone());
        if sent.is_err() {
            job.set_status(Status::Failed("the render thread has stopped".into()));
        }
        job
    }

    /// The job `id`, while it is kept.
    pub(crate) fn get(&self, id: u64) -> Option<Arc<Job>> {
        let kept = self.kept.lock().unwrap_or_else(|e| e.into_inner());
        kept.iter().find(|j| j.id == id).cloned()
    }
}

fn render_thread(
    rx: Receiver<Arc<Job>>,
    scene: &Scene,
    pool: &rayon::ThreadPool,
    batch_size: usize,
) {
    while let Ok(job) = rx.recv() {
        if job.superseded.load(Ordering::Relaxed) {
            job.set_status(Status::Superseded);
            continue;
        }
        job.set_status(Status::Running);
        // A panic in an engine must not take the viewer down: the job fails with the message.
        let outcome = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
            render_levels(&job, scene, pool, batch_size)
        }));
        let status = match outcome {
            Ok(Ok(true)) => Status::Done,
            Ok(Ok(false)) => Status::Superseded,
            Ok(Err(e)) => Status::Failed(format!("{e:#}")),
            Err(panic) => Status::Failed(format!(
                "the renderer panicked: {}",
                panic
                    .downcast_ref::<&str>()
                    .map(|s| s.to_string())
                    .or_else(|| panic.downcast_ref::<String>().cloned())
                    .unwrap_or_default()
            )),
        };
        job.set_status(status);
    }
}

/// The scene seen through `camera`: a copy only when the camera differs from the file's.
pub(crate) fn with_camera<'a>(
    scene: &'a Scene,
    camera: &crate::render::scene::Camera,
) -> std::borrow::Cow<'a, Scene> {
    if scene.camera == *camera {
        std::borrow::Cow::Borrowed(scene)
    } else {
        let mut copy = scene.clone();
        copy.camera = *camera;
        std::borrow::Cow::Owned(copy)
    }
}

/// Renders every level; false when superseded before the last.
fn render_levels(
    job: &Job,
    scene: &Scene,
    pool: &rayon::ThreadPool,
    batch_size: usize,
) -> anyhow::Result<bool> {
    let scene = with_camera(scene, &job.resolved.camera);
    for &[width, height] in &job.sizes {
        if job.superseded.load(Ordering::Relaxed) {
            return Ok(false);
        }
        let settings = crate::render::settings::RenderSettings {
            width,
            height,
            ..job.resolved.settings.clone()
        };
        let start = Instant::now();
        let prepared = job.resolved.engine.prepare(&scene, &settings, batch_size);
        let (units, _) = prepared.work_units(&settings);
        job.done_units.store(0, Ordering::Relaxed);
        job.total_units.store(units, Ordering::Relaxed);
        let (film, stats) = pool.install(|| {
            prepared.render(&|| {
                job.done_units.fetch_add(1, Ordering::Relaxed);
            })
        });
        let seconds = start.elapsed().as_secs_f64();
        let png = png_bytes(&film.to_rgb8(ToneMap::Clamp))?;
        let mut state = job.state.lock().unwrap_or_else(|e| e.into_inner());
        state.levels.push(Level {
            width,
            height,
            seconds,
            rays: stats.counts,
            rays_per_second: KindRates::measured(&stats, seconds),
        });
        state.pngs.push(Arc::new(png));
    }
    Ok(true)
}

/// Engines by name, for the page's menu.
pub(crate) const ENGINES: [Engine; 2] = [Engine::Wavefront, Engine::Reference];

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn levels_go_coarse_to_fine_without_repeats() {
        assert_eq!(
            level_sizes(512, 300),
            vec![[64, 38], [128, 75], [256, 150], [512, 300]]
        );
        assert_eq!(level_sizes(3, 2), vec![[1, 1], [2, 1], [3, 2]]);
        assert_eq!(level_sizes(1, 1), vec![[1, 1]]);
    }
}
