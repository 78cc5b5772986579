//! Progressive render jobs, as the lab's `r` key renders: the image at 1/8, 1/4, 1/2 and full
//! resolution, each level a PNG the page shows as soon as it exists. One render thread works
//! through the jobs one at a time. A new job supersedes every older one: it takes the place of
//! the job waiting, if any (the queue holds one), and sets the running job's cancel flag, which
//! the engines read before each tile or row, so the running job stops within about one tile per
//! thread and becomes `superseded`.
//!
//! ```text
//! POST /api/render -> rate limit (token bucket) -> Renders::submit:
//!     the waiting job, if any, is superseded; the running job's cancel flag is set
//!     -> the one waiting place -> render thread:
//!     for level in 1/8, 1/4, 1/2, 1:
//!         Engine::prepare(scene with the job's camera, settings at the level's size)
//!             .render_until(progress, cancel)  -> None: superseded, stop
//!         -> PNG + ray counts and seconds -> RenderState (read by GET /api/render/{id})
//! ```

use crate::output::bench_record::KindFigures;
use crate::output::cost_map::{CostInput, Count, overlay};
use crate::output::image_file::png_bytes;
use crate::render::engine::{Prepared, clamp_to_finite};
use crate::render::film::ToneMap;
use crate::render::progress::Progress;
use crate::render::scene::{Camera, Scene};
use crate::view::request::{CostOverlay, Resolved, ViewSettings};
use crate::view::scene_json::CameraFrame;
use crate::view::{CountedRender, keep, lock};
use serde::Serialize;
use std::borrow::Cow;
use std::collections::VecDeque;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::{Arc, Condvar, Mutex};
use std::time::Instant;

/// How many finished jobs are kept for their images and pixels.
pub(crate) const KEPT_RENDERS: usize = 8;

/// Render starts admitted at once: the bucket's size.
pub(crate) const RENDER_BURST: u32 = 20;

/// Render starts admitted per second, sustained: the bucket's refill rate. The page asks for
/// at most about 5 a second (a setting changed, a view orbited), so it never meets the limit,
/// and a burst of 20 covers a user who changes several settings at once. A job that is
/// superseded costs its engine's set-up (a mesh's BVH) and a tile per thread; past 20 a second a
/// client is a script, and the limit keeps it from holding the render thread in set-ups.
pub(crate) const RENDER_RATE: f64 = 20.0;

/// The divisors of the levels, coarse to fine.
const LEVEL_DIVISORS: [u32; 4] = [8, 4, 2, 1];

/// Where a job is.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
#[serde(rename_all = "lowercase", tag = "state", content = "error")]
pub(crate) enum Status {
    /// Waiting for the render thread.
    #[default]
    Queued,
    /// Rendering the level after the last in `levels`.
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
    pub width: u32,
    pub height: u32,
    /// Rays by kind, each kind per thread-second of its own work (null when not measured: the
    /// reference renders without kind timers), and all rays over the seconds the engine took
    /// (set-up included).
    pub rays: KindFigures,
    /// The cost-map overlay's legend, when the job asked for one (the level was then rendered
    /// with the traversal counted, and its times include the counting).
    pub cost: Option<CostLegend>,
}

/// What the page prints beside a level's cost-map overlay (`GET /api/render/{job}/{k}.cost.png`).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub(crate) struct CostLegend {
    /// The rays counted.
    pub kind: CostOverlay,
    /// The count shown.
    pub measure: Count,
    /// The top of the linear scale (the scale starts at 0), per pixel and camera sample.
    pub high: f64,
    /// The largest value of the map.
    pub largest: f32,
    /// The frame's mean per ray (null without rays of the kind).
    pub per_ray: Option<f64>,
}

/// What the page polls.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub(crate) struct RenderStatus {
    pub job: u64,
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
    /// The render camera's frame, for the 3D view.
    pub frame: CameraFrame,
}

/// One job: its inputs, and what it has produced so far.
pub(crate) struct RenderJob {
    /// Its id (increasing).
    pub id: u64,
    /// The settings and camera at full resolution.
    pub resolved: Resolved,
    pub sizes: Vec<[u32; 2]>,
    /// Set when a newer job supersedes this one: the engines read it before each work unit.
    cancel: AtomicBool,
    /// The job that superseded this one (0: none).
    superseded_by: AtomicU64,
    done_units: AtomicU64,
    total_units: AtomicU64,
    state: Mutex<RenderState>,
}

#[derive(Default)]
struct RenderState {
    status: Status,
    levels: Vec<Level>,
    pngs: Vec<Arc<Vec<u8>>>,
    /// Each level's cost-map overlay, when the job asked for one.
    cost_pngs: Vec<Option<Arc<Vec<u8>>>>,
}

impl RenderJob {
    /// The status for the page.
    pub(crate) fn status(&self) -> RenderStatus {
        let r = &self.resolved;
        let state = lock(&self.state);
        RenderStatus {
            job: self.id,
            status: state.status.clone(),
            sizes: self.sizes.clone(),
            levels: state.levels.clone(),
            progress: [
                self.done_units.load(Ordering::Relaxed),
                self.total_units.load(Ordering::Relaxed),
            ],
            settings: r.to_json(),
            frame: CameraFrame::new(&r.camera, r.settings.width, r.settings.height),
        }
    }

    /// Where it is now.
    pub(crate) fn state(&self) -> Status {
        lock(&self.state).status.clone()
    }

    /// The job that superseded this one, once one has.
    pub(crate) fn superseded_by(&self) -> Option<u64> {
        Some(self.superseded_by.load(Ordering::Relaxed)).filter(|&id| id != 0)
    }

    /// Level `k`'s PNG, once rendered.
    pub(crate) fn png(&self, k: usize) -> Option<Arc<Vec<u8>>> {
        lock(&self.state).pngs.get(k).cloned()
    }

    /// Level `k`'s cost-map overlay, once rendered, when the job asked for one.
    pub(crate) fn cost_png(&self, k: usize) -> Option<Arc<Vec<u8>>> {
        lock(&self.state).cost_pngs.get(k).cloned().flatten()
    }

    fn set_status(&self, status: Status) {
        lock(&self.state).status = status;
    }

    /// Marks the job superseded by `by` (unless a job did before) and tells its render, if
    /// any, to stop.
    fn supersede(&self, by: u64) {
        let _ = self
            .superseded_by
            .compare_exchange(0, by, Ordering::Relaxed, Ordering::Relaxed);
        self.cancel.store(true, Ordering::Relaxed);
    }
}

/// The level sizes of a `width` × `height` image, rounded up, without repeats (a 10-pixel image
/// has fewer than four levels).
fn level_sizes(width: u32, height: u32) -> Vec<[u32; 2]> {
    let mut sizes: Vec<[u32; 2]> = LEVEL_DIVISORS
        .map(|d| [width.div_ceil(d), height.div_ceil(d)])
        .to_vec();
    sizes.dedup();
    sizes
}

/// The render thread's inbox: at most one job waiting (a newer one takes its place), and the
/// job being rendered, whose cancel flag a newer job sets.
#[derive(Default)]
struct Inbox {
    waiting: Option<Arc<RenderJob>>,
    running: Option<Arc<RenderJob>>,
    /// The render thread has stopped, or must.
    closed: bool,
}

/// The inbox and the signal that a job is waiting, shared by [`Renders`] and the render thread.
#[derive(Default)]
struct Queue {
    inbox: Mutex<Inbox>,
    ready: Condvar,
}

impl Queue {
    /// Stops the render thread: the running job is cancelled, the waiting one dropped.
    fn close(&self) {
        let mut inbox = lock(&self.inbox);
        inbox.closed = true;
        if let Some(job) = &inbox.running {
            job.cancel.store(true, Ordering::Relaxed);
        }
        self.ready.notify_all();
    }
}

/// The rate limit on render starts: a token bucket of [`RENDER_BURST`] starts, refilled at
/// [`RENDER_RATE`] a second. Hand-written: the crates that do this (governor) bring a clock
/// and a keyed store the one bucket here has no use for.
#[derive(Debug)]
struct TokenBucket {
    tokens: f64,
    at: Instant,
}

impl TokenBucket {
    fn full(now: Instant) -> TokenBucket {
        TokenBucket {
            tokens: RENDER_BURST as f64,
            at: now,
        }
    }

    /// Takes one token at `now`, or says in how many seconds there is one (rounded up, at
    /// least 1).
    fn take(&mut self, now: Instant) -> Result<(), u32> {
        let refill = now.saturating_duration_since(self.at).as_secs_f64() * RENDER_RATE;
        self.tokens = (self.tokens + refill).min(RENDER_BURST as f64);
        self.at = now;
        if self.tokens >= 1.0 {
            self.tokens -= 1.0;
            Ok(())
        } else {
            let wait = (1.0 - self.tokens) / RENDER_RATE;
            Err((wait.ceil() as u32).max(1))
        }
    }
}

/// The jobs, the render thread's inbox and the rate limit on new jobs.
pub(crate) struct Renders {
    next: AtomicU64,
    kept: Mutex<VecDeque<Arc<RenderJob>>>,
    queue: Arc<Queue>,
    bucket: Mutex<TokenBucket>,
}

/// What the render thread renders with.
pub(crate) struct Renderer {
    pub scene: Arc<Scene>,
    /// The worker threads.
    pub pool: Arc<rayon::ThreadPool>,
    /// The wavefront engine's camera samples per tile.
    pub batch_size: usize,
    pub counted: CountedRender,
}

impl Renders {
    /// Starts the render thread.
    pub(crate) fn start(renderer: Renderer) -> std::io::Result<Arc<Renders>> {
        let queue = Arc::new(Queue::default());
        let inbox = queue.clone();
        std::thread::Builder::new()
            .name("render".into())
            .spawn(move || render_thread(&inbox, &renderer))?;
        Ok(Arc::new(Renders {
            next: AtomicU64::new(1),
            kept: Mutex::new(VecDeque::new()),
            queue,
            bucket: Mutex::new(TokenBucket::full(Instant::now())),
        }))
    }

    /// Queues a job, unless the rate limit refuses it (then the seconds until it admits one).
    /// It takes the place of the job waiting, which is superseded without starting, and cancels
    /// the job running.
    pub(crate) fn submit(&self, resolved: Resolved) -> Result<Arc<RenderJob>, u32> {
        lock(&self.bucket).take(Instant::now())?;
        let id = self.next.fetch_add(1, Ordering::Relaxed);
        let sizes = level_sizes(resolved.settings.width, resolved.settings.height);
        let job = Arc::new(RenderJob {
            id,
            resolved,
            sizes,
            cancel: AtomicBool::new(false),
            superseded_by: AtomicU64::new(0),
            done_units: AtomicU64::new(0),
            total_units: AtomicU64::new(0),
            state: Mutex::default(),
        });
        keep(&self.kept, job.clone(), KEPT_RENDERS);
        let mut inbox = lock(&self.queue.inbox);
        if inbox.closed {
            job.set_status(Status::Failed("the render thread has stopped".into()));
            return Ok(job);
        }
        if let Some(old) = inbox.waiting.replace(job.clone()) {
            old.supersede(id);
            old.set_status(Status::Superseded);
        }
        // Its status turns `superseded` when the render thread has stopped it.
        if let Some(running) = &inbox.running {
            running.supersede(id);
        }
        self.queue.ready.notify_one();
        Ok(job)
    }

    /// The job `id`, while it is kept.
    pub(crate) fn get(&self, id: u64) -> Option<Arc<RenderJob>> {
        lock(&self.kept).iter().find(|j| j.id == id).cloned()
    }

    /// The newest job's id (0 before the first).
    pub(crate) fn newest(&self) -> u64 {
        self.next.load(Ordering::Relaxed) - 1
    }
}

impl Drop for Renders {
    fn drop(&mut self) {
        self.queue.close();
    }
}

/// Closes the queue when the render thread ends, however it ends: a later job fails at once
/// instead of waiting for a thread that is gone.
struct CloseOnExit<'a>(&'a Queue);

impl Drop for CloseOnExit<'_> {
    fn drop(&mut self) {
        self.0.close();
    }
}

fn render_thread(queue: &Queue, renderer: &Renderer) {
    let _close = CloseOnExit(queue);
    loop {
        let job = {
            let mut inbox = lock(&queue.inbox);
            loop {
                if inbox.closed {
                    return;
                }
                if let Some(job) = inbox.waiting.take() {
                    inbox.running = Some(job.clone());
                    break job;
                }
                inbox = queue.ready.wait(inbox).unwrap_or_else(|e| e.into_inner());
            }
        };
        job.set_status(Status::Running);
        // A panic in an engine must not take the viewer down: the job fails with the message.
        let outcome = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
            renderer.render_levels(&job)
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
        lock(&queue.inbox).running = None;
    }
}

/// The scene seen through `camera`: a copy only when the camera differs from the file's.
pub(crate) fn with_camera<'a>(scene: &'a Scene, camera: &Camera) -> Cow<'a, Scene> {
    if scene.camera == *camera {
        Cow::Borrowed(scene)
    } else {
        let mut copy = scene.clone();
        copy.camera = *camera;
        Cow::Owned(copy)
    }
}

impl Renderer {
    /// Renders every level; false when superseded before the last was finished.
    fn render_levels(&self, job: &RenderJob) -> anyhow::Result<bool> {
        let r = &job.resolved;
        let scene = with_camera(&self.scene, &r.camera);
        for &[width, height] in &job.sizes {
            if job.cancel.load(Ordering::Relaxed) {
                return Ok(false);
            }
            let settings = crate::render::settings::RenderSettings {
                width,
                height,
                ..r.settings.clone()
            };
            let start = Instant::now();
            let prepared = r.engine.prepare(&scene, &settings, self.batch_size);
            // Steps come from every worker: the count only grows within a level.
            let report = |done, total, _: &str| {
                job.total_units.store(total, Ordering::Relaxed);
                match done {
                    0 => job.done_units.store(0, Ordering::Relaxed),
                    _ => _ = job.done_units.fetch_max(done, Ordering::Relaxed),
                }
            };
            let progress = Progress {
                report: &report,
                ..Progress::SILENT
            };
            let rendered = self.pool.install(|| match (&prepared, r.cost_map.kind()) {
                (Prepared::Wavefront(w), Some(kind)) => (self.counted)(w, &progress, &job.cancel)
                    .map(|(mut film, stats, costs)| {
                        clamp_to_finite(&mut film);
                        let overlay = costs.pixels.as_ref().map(|pixels| {
                            let input = CostInput {
                                pixels,
                                width,
                                height,
                                aa_samples: settings.aa_samples,
                                totals: &costs.totals,
                                rays: &stats.counts,
                            };
                            overlay(&input, kind, r.cost_measure)
                        });
                        (film, stats, overlay)
                    }),
                _ => prepared
                    .render_until(&progress, &job.cancel)
                    .map(|(film, stats)| (film, stats, None)),
            });
            let Some((film, stats, overlay)) = rendered else {
                return Ok(false);
            };
            let seconds = start.elapsed().as_secs_f64();
            let png = png_bytes(&film.to_rgb8(ToneMap::Clamp))?;
            let cost = overlay.as_ref().map(|map| CostLegend {
                kind: r.cost_map,
                measure: r.cost_measure,
                high: map.scale.high,
                largest: map.largest,
                per_ray: map.per_ray,
            });
            let cost_png = overlay
                .map(|map| png_bytes(&map.image(width, height)))
                .transpose()?;
            let mut state = lock(&job.state);
            state.levels.push(Level {
                width,
                height,
                rays: KindFigures::new(&stats, seconds),
                cost,
            });
            state.pngs.push(Arc::new(png));
            state.cost_pngs.push(cost_png.map(Arc::new));
        }
        Ok(true)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::engine::Engine;
    use std::time::Duration;

    #[test]
    fn levels_go_coarse_to_fine_without_repeats() {
        assert_eq!(
            level_sizes(512, 300),
            vec![[64, 38], [128, 75], [256, 150], [512, 300]]
        );
        assert_eq!(level_sizes(3, 2), vec![[1, 1], [2, 1], [3, 2]]);
        assert_eq!(level_sizes(1, 1), vec![[1, 1]]);
    }

    fn resolved() -> Resolved {
        let settings = crate::render::settings::RenderSettings::default();
        Resolved {
            settings,
            engine: Engine::Wavefront,
            camera: Scene::builtin_default().camera,
            cost_map: CostOverlay::Off,
            cost_measure: Count::Nodes,
        }
    }

    #[test]
    fn one_job_waits_a_newer_one_replaces_it_and_cancels_the_running_one() {
        // No render thread: the test plays its part on the queue.
        let jobs = Renders {
            next: AtomicU64::new(1),
            kept: Mutex::new(VecDeque::new()),
            queue: Arc::new(Queue::default()),
            bucket: Mutex::new(TokenBucket::full(Instant::now())),
        };
        let a = jobs.submit(resolved()).unwrap();
        // The render thread takes it.
        {
            let mut inbox = lock(&jobs.queue.inbox);
            inbox.running = inbox.waiting.take();
        }
        let b = jobs.submit(resolved()).unwrap();
        assert!(
            a.cancel.load(Ordering::Relaxed),
            "the running job is told to stop"
        );
        // It turns superseded when its render has stopped, which the render thread says.
        assert_eq!(a.state(), Status::Queued);
        assert_eq!(a.superseded_by(), Some(b.id));
        let c = jobs.submit(resolved()).unwrap();
        assert_eq!(b.state(), Status::Superseded, "the waiting job is replaced");
        assert_eq!(b.superseded_by(), Some(c.id));
        assert_eq!(a.superseded_by(), Some(b.id), "the first to supersede it");
        assert!(!c.cancel.load(Ordering::Relaxed));
        {
            let inbox = lock(&jobs.queue.inbox);
            assert_eq!(inbox.waiting.as_ref().map(|j| j.id), Some(c.id));
            assert_eq!(inbox.running.as_ref().map(|j| j.id), Some(a.id));
        }
        // Twenty starts at once, then the limit; eight jobs kept.
        let more: Vec<_> = (3..20).map(|_| jobs.submit(resolved()).unwrap()).collect();
        assert_eq!(jobs.submit(resolved()).err(), Some(1));
        assert_eq!(jobs.newest(), 20);
        assert!(
            more.iter()
                .rev()
                .skip(1)
                .all(|j| j.state() == Status::Superseded)
        );
        assert!(jobs.get(12).is_none() && jobs.get(13).is_some());
        assert_eq!(jobs.kept.lock().unwrap().len(), KEPT_RENDERS);
    }

    #[test]
    fn the_bucket_admits_a_burst_then_one_start_per_refill() {
        let t0 = Instant::now();
        let mut bucket = TokenBucket::full(t0);
        for i in 0..20 {
            assert_eq!(bucket.take(t0), Ok(()), "start {i} of the burst");
        }
        // Empty: the next token is 1/20 s away, which rounds up to a whole second.
        assert_eq!(bucket.take(t0), Err(1));
        let step = Duration::from_millis(50);
        assert_eq!(bucket.take(t0 + step), Ok(()));
        assert!(bucket.take(t0 + step).is_err());
        assert!(bucket.take(t0 + step + step / 2).is_err());
        assert_eq!(bucket.take(t0 + 2 * step), Ok(()));
        // A long pause fills it to the burst, no further.
        let later = t0 + Duration::from_secs(60);
        for i in 0..20 {
            assert_eq!(bucket.take(later), Ok(()), "start {i} after a pause");
        }
        assert!(bucket.take(later).is_err());
    }
}
