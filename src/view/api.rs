//! The API's handlers: each takes the shared [`State`] and the request's parts, and returns a
//! reply or an [`ApiError`] (a 4xx naming what was wrong with the request).

use super::compare::{CompareRequest, Comparisons, KEPT};
use super::http::{ApiError, Reply, number, query};
use super::renders::{
    KEPT_RENDERS, RENDER_BURST, RENDER_RATE, RenderJob, Renders, Status, with_camera,
};
use super::request::{Resolved, ViewSettings, parse_json};
use super::scene_json::SceneJson;
use super::tree;
use crate::render::engine::Engine;
use crate::render::quote::quote;
use crate::render::sampling::LightSampler;
use crate::render::scene::Scene;
use crate::trace::palette::{MAIN_CAMERA, Rgb, Style};
use serde::Serialize;
use std::sync::Arc;

/// Everything the handlers share.
pub(crate) struct State {
    /// The scene, read once at start.
    pub scene: Arc<Scene>,
    /// The settings the command line gave: what a request leaves out.
    pub base: Resolved,
    pub jobs: Arc<Renders>,
    pub comparisons: Comparisons,
    /// The worker threads renders run on.
    pub pool: Arc<rayon::ThreadPool>,
    /// The scene's geometry as JSON, made once.
    pub scene_json: Vec<u8>,
}

/// `GET /api/scene`.
pub(crate) fn scene(state: &State) -> Reply {
    Reply::bytes("application/json", state.scene_json.clone())
}

/// The JSON of `GET /api/scene`, made once at start.
pub(crate) fn scene_json(scene: &Scene, base: &Resolved) -> Vec<u8> {
    #[derive(Serialize)]
    struct Body<'a> {
        scene: SceneJson,
        settings: ViewSettings,
        samplers: Vec<&'a str>,
        engines: Vec<&'a str>,
        simd: &'a str,
        /// An object, name to colour: the 3D view's, `raywave::trace::palette`'s (the lab's),
        /// each ray style's, then the render camera's (shadow_blocked rays are drawn dashed past
        /// the blocker).
        #[serde(serialize_with = "as_object")]
        palette: Vec<(&'a str, Rgb)>,
    }
    fn as_object<S: serde::Serializer>(pairs: &[(&str, Rgb)], s: S) -> Result<S::Ok, S::Error> {
        s.collect_map(pairs.iter().copied())
    }
    serde_json::to_vec(&Body {
        scene: SceneJson::new(scene),
        settings: base.to_json(),
        samplers: LightSampler::ALL.iter().map(|s| s.name()).collect(),
        engines: vec![Engine::Wavefront.name(), Engine::Reference.name()],
        simd: crate::simd_path(),
        palette: (Style::ALL.iter().map(|s| (s.name(), s.colour())))
            .chain([("main_camera", MAIN_CAMERA)])
            .collect(),
    })
    .unwrap_or_default()
}

/// `POST /api/render`: starts a job, unless more than the rate limit's starts came in the
/// last second (429 with `Retry-After`).
pub(crate) fn render(state: &State, body: &[u8]) -> Result<Reply, ApiError> {
    let resolved = parse_json::<ViewSettings>(body, "settings")?.resolve(&state.base)?;
    let job = state.jobs.submit(resolved).map_err(|seconds| {
        ApiError::retry(
            429,
            seconds,
            format!(
                "too many renders started: at most {RENDER_BURST} at once and {RENDER_RATE} a \
                 second; retry in {seconds} s"
            ),
        )
    })?;
    Ok(Reply::json(&job.status()))
}

/// A path's `text` as a number, or a 400 saying `what` was expected.
fn path_number(text: &str, what: &str) -> Result<u64, ApiError> {
    text.parse()
        .map_err(|_| ApiError::bad(format!("expected {what}, found `{}`", quote(text))))
}

/// Job `id`, or a 404 when it is not kept.
fn job_by_id(state: &State, id: u64) -> Result<Arc<RenderJob>, ApiError> {
    state.jobs.get(id).ok_or_else(|| {
        ApiError::not_found(format!(
            "no render job {id}: only the last {KEPT_RENDERS} are kept"
        ))
    })
}

/// `GET /api/render/{job}`.
pub(crate) fn render_status(state: &State, job: &str) -> Result<Reply, ApiError> {
    let job = job_by_id(state, path_number(job, "a job number")?)?;
    Ok(Reply::json(&job.status()))
}

/// `GET /api/render/{job}/{level}.png`, and `{level}.cost.png`: the level's cost-map overlay.
pub(crate) fn render_png(state: &State, job: &str, level: &str) -> Result<Reply, ApiError> {
    let job = job_by_id(state, path_number(job, "a job number")?)?;
    let (id, levels) = (job.id, job.sizes.len());
    let (k, cost) = match level.strip_suffix(".cost.png") {
        Some(k) => (k, true),
        None => (level.strip_suffix(".png").unwrap_or(""), false),
    };
    let k: usize = k.parse().map_err(|_| {
        ApiError::bad(format!(
            "expected a level as N.png or N.cost.png, found `{}`",
            quote(level)
        ))
    })?;
    if k >= levels {
        return Err(ApiError::not_found(format!(
            "job {id} has levels 0..{levels}, not {k}"
        )));
    }
    let png = if cost {
        job.cost_png(k).ok_or_else(|| format!(
            "level {k} of job {id} has no cost map: ask for one with cost_map in the settings (the level may not be rendered yet: see GET /api/render/{id})"
        ))
    } else {
        job.png(k).ok_or_else(|| {
            format!("level {k} of job {id} is not rendered (yet): see GET /api/render/{id}")
        })
    };
    let png = png.map_err(ApiError::not_found)?;
    Ok(Reply::bytes("image/png", png.as_ref().clone()))
}

/// `GET /api/pixel?job=J&x=X&y=Y`: the ray tree of pixel (x, y) of job J's full-size image;
/// 410 for a job whose image will never be finished (superseded or failed), naming the job to
/// ask instead.
pub(crate) fn pixel(state: &State, q: &str) -> Result<Reply, ApiError> {
    let pairs = query(q, &["job", "x", "y"])?;
    let job = job_by_id(state, number(&pairs, "job")?)?;
    let (id, newest) = (job.id, state.jobs.newest());
    let gone = match job.state() {
        Status::Superseded => {
            let by = job.superseded_by().unwrap_or(newest);
            let ask = if newest == by {
                format!("ask for job {by}'s pixels")
            } else {
                format!("ask for the newest job's pixels, job {newest}")
            };
            Some(format!(
                "job {id} was superseded by job {by} before its image was finished: {ask}"
            ))
        }
        Status::Failed(error) => {
            let ask = if newest == id {
                "start a new render and ask for its pixels".to_string()
            } else {
                format!("ask for job {newest}'s pixels")
            };
            Some(format!(
                "job {id} failed before its image was finished ({error}): {ask}"
            ))
        }
        Status::Queued | Status::Running | Status::Done => None,
    };
    if let Some(message) = gone {
        return Err(ApiError::status(410, message));
    }
    let (x, y): (u32, u32) = (number(&pairs, "x")?, number(&pairs, "y")?);
    let scene = with_camera(&state.scene, &job.resolved.camera);
    let tree = tree::pixel_tree(&scene, &job.resolved.settings, x, y)?;
    Ok(Reply::json(&tree))
}

/// `POST /api/compare`.
pub(crate) fn compare(state: &State, body: &[u8]) -> Result<Reply, ApiError> {
    let request = CompareRequest::parse(body)?;
    let result = state
        .comparisons
        .run(&request, &state.scene, &state.base, &state.pool)?;
    Ok(Reply::json(&result))
}

/// `GET /api/compare/{id}/{name}.png`.
pub(crate) fn compare_png(state: &State, id: &str, name: &str) -> Result<Reply, ApiError> {
    let n = path_number(id, "a comparison number")?;
    let png = name
        .strip_suffix(".png")
        .and_then(|name| state.comparisons.png(n, name))
        .ok_or_else(|| {
            ApiError::not_found(format!(
                "no image `{}` in comparison {n} (only the last {KEPT} are kept)",
                quote(name)
            ))
        })?;
    Ok(Reply::bytes("image/png", png.as_ref().clone()))
}
