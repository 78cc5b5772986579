//! `raywave view`: the lab's debug window in the browser. A local web server (127.0.0.1 only,
//! every asset compiled into the binary) serves one page that shows the render, coarse to fine,
//! the scene in 3D with the render's camera, one pixel's ray tree over the scene, a comparison of
//! two light samplers against the converged reference, and the rays per second by kind.
//!
//! ```text
//! server.rs      binding, worker threads, the routing table, stopping on SIGINT/SIGTERM
//! http.rs        errors as 4xx/5xx JSON, replies, bodies under a size limit, query strings
//! api.rs         the handlers
//! request.rs     the settings a page sends (JSON) -> RenderSettings, checked
//! jobs.rs        progressive render jobs on one render thread
//! tree.rs        one pixel's ray tree
//! compare.rs     two samplers side by side with their error heat maps
//! scene_json.rs  the scene's geometry and the camera's frame for WebGL
//! assets.rs      the page, its scripts and style (assets/)
//! ```

pub(crate) mod api;
pub(crate) mod assets;
pub(crate) mod compare;
pub(crate) mod http;
pub(crate) mod jobs;
pub mod request;
pub(crate) mod scene_json;
pub(crate) mod server;
pub(crate) mod tree;

use anyhow::Result;
use request::Resolved;
use std::sync::Arc;

/// What `raywave view` was started with.
pub struct ViewOptions {
    /// The scene.
    pub scene: crate::render::scene::Scene,
    /// The settings the page starts from (and every request's defaults).
    pub base: Resolved,
    /// Worker threads for renders (None: all cores).
    pub threads: Option<u32>,
    /// The wavefront engine's camera samples per tile.
    pub batch_size: usize,
    /// The port (0: any free one).
    pub port: u16,
}

/// Binds, prints the URL with `say`, and serves until SIGINT or SIGTERM; returns the signal's
/// name.
pub fn run(options: ViewOptions, say: &dyn Fn(&str) -> Result<()>) -> Result<&'static str> {
    let server = server::Server::bind(options.port)?;
    let pool = Arc::new(crate::render::engine::thread_pool(options.threads)?);
    let scene = Arc::new(options.scene);
    let jobs = jobs::Jobs::start(scene.clone(), pool.clone(), options.batch_size)
        .map_err(|e| anyhow::anyhow!("cannot start the render thread: {e}"))?;
    let state = Arc::new(api::State {
        scene_json: api::scene_json(&scene, &options.base),
        scene,
        base: options.base,
        jobs,
        comparisons: compare::Comparisons::default(),
        pool,
        port: server.port,
    });
    say(&format!(
        "raywave view: http://127.0.0.1:{}/ (Ctrl-C stops it)\n",
        server.port
    ))?;
    server.serve(state)
}
