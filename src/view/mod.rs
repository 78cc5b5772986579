//! `raywave view`: the lab's debug window in the browser. A local web server (loopback by
//! default, every asset compiled into the binary, every request carrying the access token)
//! serves one page that shows the render, coarse to fine, the scene in 3D with the render's
//! camera, one pixel's ray tree over the scene, a comparison of two light samplers against the
//! converged reference, and the rays per second by kind.
//!
//! ```text
//! server.rs      binding, the connection limit, a thread per connection, stopping on signals
//! connection.rs  one request read under its limits (time, head, body), its reply written
//! routes.rs      the Host, Origin and token checks, the routing table
//! token.rs       the access token: generated or given, checked in constant time, its cookie
//! http.rs        errors as 4xx/5xx JSON, replies, query strings
//! api.rs         the handlers
//! request.rs     the settings a page sends (JSON) -> RenderSettings, checked
//! renders.rs     progressive render jobs on one render thread
//! tree.rs        one pixel's ray tree
//! compare.rs     two samplers side by side with their error heat maps
//! scene_json.rs  the scene's geometry and the camera's frame for WebGL
//! assets.rs      the page, its scripts and style (assets/)
//! ```

pub(crate) mod api;
pub(crate) mod assets;
pub(crate) mod compare;
pub(crate) mod connection;
pub(crate) mod http;
pub(crate) mod renders;
pub mod request;
pub(crate) mod routes;
pub(crate) mod scene_json;
pub mod server;
pub mod token;
pub(crate) mod tree;

use crate::render::film::Film;
use crate::render::progress::Progress;
use crate::render::wavefront::{Wavefront, cost::CostReport, stats::RenderStats};
use anyhow::Result;
use request::Resolved;
use std::collections::VecDeque;
use std::net::{IpAddr, SocketAddr};
use std::sync::atomic::AtomicBool;
use std::sync::{Arc, Mutex, MutexGuard};
use token::Access;

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
    /// The address to listen on (loopback unless `--bind` says otherwise).
    pub bind: IpAddr,
    /// The port (0: any free one).
    pub port: u16,
    /// The token every request must carry, or none.
    pub access: Access,
    /// Connections open at once; past it, 503.
    pub max_connections: usize,
    /// How a level with a cost-map overlay is rendered: `Wavefront::render_counted_until` with
    /// per-pixel counts, given by the binary so that the counting instantiation of the stages
    /// is compiled there and not beside the library's uncounted ones (`render_counted`'s docs).
    pub counted: CountedRender,
}

/// A counted render of every tile with per-pixel counts, stopped once the flag is set
/// (`Wavefront::render_counted_until(progress, true, cancel)`); `None` when stopped.
pub type CountedRender =
    fn(&Wavefront, &Progress, &AtomicBool) -> Option<(Film, RenderStats, CostReport)>;

/// Binds, prints the URL with `say`, serves until SIGINT or SIGTERM; returns the signal.
pub fn run(options: ViewOptions, say: &dyn Fn(&str) -> Result<()>) -> Result<i32> {
    let server = server::Server::bind(options.bind, options.port)?;
    let pool = Arc::new(crate::render::engine::thread_pool(options.threads)?);
    let scene = Arc::new(options.scene);
    let jobs = renders::Renders::start(renders::Renderer {
        scene: scene.clone(),
        pool: pool.clone(),
        batch_size: options.batch_size,
        counted: options.counted,
    })
    .map_err(|e| anyhow::anyhow!("cannot start the render thread: {e}"))?;
    let state = Arc::new(api::State {
        scene_json: api::scene_json(&scene, &options.base),
        scene,
        base: options.base,
        jobs,
        comparisons: compare::Comparisons::default(),
        pool,
    });
    let url = url(server.addr, &options.access);
    say(&format!("raywave view: {url} (Ctrl-C stops it)\n"))?;
    let gate = routes::Gate {
        access: options.access,
        loopback: options.bind.is_loopback(),
        port: server.addr.port(),
    };
    server.serve(state, gate, options.max_connections)
}

/// The page's URL, with the token: on every interface, the loopback one.
pub fn url(addr: SocketAddr, access: &Access) -> String {
    let addr = server::local_address(addr);
    match access {
        Access::Token(token) => format!("http://{addr}/?token={}", token.as_str()),
        Access::Open => format!("http://{addr}/"),
    }
}

/// `mutex`'s guard, also after a thread panicked holding it: what it guards stays usable.
fn lock<T>(mutex: &Mutex<T>) -> MutexGuard<'_, T> {
    mutex.lock().unwrap_or_else(|e| e.into_inner())
}

/// Appends `item` to `kept`, dropping the oldest past `max`.
fn keep<T>(kept: &Mutex<VecDeque<T>>, item: T, max: usize) {
    let mut kept = lock(kept);
    kept.push_back(item);
    while kept.len() > max {
        kept.pop_front();
    }
}
