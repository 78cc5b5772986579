//! The server: one thread accepts connections, each admitted connection gets a thread of its
//! own for one request (connection.rs bounds its time and size), and a stop on SIGINT or
//! SIGTERM lets the requests in hand finish.
//!
//! ```text
//! accept ──(fewer than max_connections open)──> thread: read request -> routes::answer -> reply, close
//!        └─(at the limit)──> refuser thread (bounded queue): 503 + Retry-After, close
//! SIGINT/SIGTERM -> stop accepting -> wait for the open connections (at most DRAIN_TIME) -> return
//! ```
//!
//! A thread per connection, bounded by the connection limit, and a deadline per request: so a
//! slow client holds one thread for at most the request time and never blocks another's
//! request. Rejected: tiny_http (a thread per connection without a bound, no read timeout) and an
//! async server (a runtime in every build, for a page with a few requests a second).

use super::api::State;
use super::connection::{self, REQUEST_TIME, ReadError, Request};
use super::http::{ApiError, Reply};
use super::routes::{self, Gate};
use anyhow::{Context, Result};
use std::net::{IpAddr, Ipv4Addr, Ipv6Addr, SocketAddr, TcpListener, TcpStream};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::mpsc::{Receiver, SyncSender};
use std::time::{Duration, Instant};

/// The connections open at once by default; past it, new ones get a 503.
pub const DEFAULT_MAX_CONNECTIONS: usize = 256;

/// How long a stop waits for the requests in hand.
const DRAIN_TIME: Duration = Duration::from_secs(30);

/// Connections over the limit waiting for their 503; past this they are closed unanswered.
const REFUSE_QUEUE: usize = 64;

/// A bound server.
pub(crate) struct Server {
    listener: TcpListener,
    /// The address it listens on (the port filled in).
    pub addr: SocketAddr,
}

impl Server {
    /// Listens on `ip`:`port` (port 0: a free one the system chooses).
    pub(crate) fn bind(ip: IpAddr, port: u16) -> Result<Server> {
        let wanted = SocketAddr::new(ip, port);
        let listener =
            TcpListener::bind(wanted).with_context(|| format!("cannot listen on {wanted}"))?;
        let addr = listener.local_addr().context("the server has no address")?;
        Ok(Server { listener, addr })
    }

    /// Serves until SIGINT or SIGTERM; returns the signal.
    pub(crate) fn serve(
        self,
        state: Arc<State>,
        gate: Gate,
        max_connections: usize,
    ) -> Result<i32> {
        use signal_hook::consts::{SIGINT, SIGTERM};
        let mut signals = signal_hook::iterator::Signals::new([SIGINT, SIGTERM])
            .context("cannot install the signal handler")?;
        let handle = signals.handle();
        let (refuse, refused) = std::sync::mpsc::sync_channel(REFUSE_QUEUE);
        std::thread::Builder::new()
            .name("refuse".into())
            .spawn(move || refuser(&refused, max_connections))
            .context("cannot start the server's threads")?;
        let shared = Arc::new(Shared {
            state,
            gate,
            open: AtomicUsize::new(0),
            max_connections,
            stop: AtomicBool::new(false),
        });
        let acceptor = {
            let shared = shared.clone();
            std::thread::Builder::new()
                .name("accept".into())
                .spawn(move || accept(&self.listener, &shared, &refuse))
                .context("cannot start the server's threads")?
        };
        let signal = signals.forever().next().unwrap_or(SIGINT);
        handle.close();
        shared.stop.store(true, Ordering::SeqCst);
        // Wake the acceptor from accept(2) with a connection of our own.
        let _ = TcpStream::connect_timeout(&local_address(self.addr), Duration::from_secs(1));
        let _ = acceptor.join();
        let end = Instant::now() + DRAIN_TIME;
        while shared.open.load(Ordering::SeqCst) > 0 && Instant::now() < end {
            std::thread::sleep(Duration::from_millis(10));
        }
        Ok(signal)
    }
}

/// What the connection threads share.
struct Shared {
    state: Arc<State>,
    gate: Gate,
    /// Connections being served now.
    open: AtomicUsize,
    max_connections: usize,
    stop: AtomicBool,
}

/// One open connection's place under the limit, given back when its thread ends.
struct Slot(Arc<Shared>);

impl Drop for Slot {
    fn drop(&mut self) {
        self.0.open.fetch_sub(1, Ordering::SeqCst);
    }
}

/// Where a client on this machine reaches the server: loopback when bound to every interface.
pub(crate) fn local_address(addr: SocketAddr) -> SocketAddr {
    match addr.ip() {
        IpAddr::V4(ip) if ip.is_unspecified() => (Ipv4Addr::LOCALHOST, addr.port()).into(),
        IpAddr::V6(ip) if ip.is_unspecified() => (Ipv6Addr::LOCALHOST, addr.port()).into(),
        _ => addr,
    }
}

fn accept(listener: &TcpListener, shared: &Arc<Shared>, refuse: &SyncSender<TcpStream>) {
    for stream in listener.incoming() {
        if shared.stop.load(Ordering::SeqCst) {
            return;
        }
        let stream = match stream {
            Ok(s) => s,
            Err(e) => {
                // Out of file descriptors, or a connection reset while queued: go on.
                eprintln!("warning: cannot accept a connection: {e}");
                std::thread::sleep(Duration::from_millis(10));
                continue;
            }
        };
        let accepted = Instant::now();
        if shared.open.fetch_add(1, Ordering::SeqCst) >= shared.max_connections {
            shared.open.fetch_sub(1, Ordering::SeqCst);
            // When the refuser's queue is full, this one is closed unanswered.
            let _ = refuse.try_send(stream);
            continue;
        }
        let slot = Slot(shared.clone());
        let spawned = std::thread::Builder::new()
            .name("http".into())
            .spawn(move || serve_connection(stream, accepted, &slot.0, &slot));
        if let Err(e) = spawned {
            eprintln!("warning: cannot start a thread for a connection: {e}");
        }
    }
}

/// Reads the request, answers it, closes.
fn serve_connection(mut stream: TcpStream, accepted: Instant, shared: &Shared, _slot: &Slot) {
    let _ = stream.set_nodelay(true);
    let (reply, head_only) = match connection::read_request(&mut stream, accepted, REQUEST_TIME) {
        Err(ReadError::Closed) => return,
        Err(ReadError::Refused(e)) => (Reply::from(e), false),
        Ok(request) => (answer(&request, shared), request.method == "HEAD"),
    };
    connection::reply_and_close(stream, &reply, head_only);
}

/// The reply to a request; a panic in a handler becomes a 500, not a dead server.
fn answer(request: &Request, shared: &Shared) -> Reply {
    std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
        routes::answer(request, &shared.state, &shared.gate)
    }))
    .unwrap_or_else(|_| {
        Reply::from(ApiError::status(
            500,
            "internal error while answering this request (see the server's log)",
        ))
    })
}

/// Answers the connections over the limit with 503 and `Retry-After`, one at a time.
fn refuser(queue: &Receiver<TcpStream>, max_connections: usize) {
    let reply = Reply::from(ApiError::retry(
        503,
        1,
        format!(
            "this server is at its limit of {max_connections} open connections: try again in a second"
        ),
    ));
    while let Ok(mut stream) = queue.recv() {
        // Take what the client sent first, so that closing does not reset the connection
        // before it reads the answer.
        connection::linger(&mut stream, Duration::from_millis(20));
        connection::reply_and_close(stream, &reply, false);
    }
}
