//! The sockets and the clock: one tokio task on one thread reads both links, paces real time,
//! streams the ground-station telemetry and stops on SIGINT / SIGTERM.

use crate::sim::{Link, Mode, Sim};
use crate::stats::Stats;
use crate::wire;
use std::future::pending;
use std::io;
use std::net::SocketAddr;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;
use tokio::net::UdpSocket;
use tokio::signal::unix::{SignalKind, signal};
use tokio::time::sleep_until;

/// The ground-station link: its socket and where telemetry goes.
#[derive(Debug)]
pub struct GcsLink {
    pub socket: UdpSocket,
    pub target: SocketAddr,
}

/// Largest datagram read.
const RECEIVE_BUFFER: usize = 65_536;

async fn send(socket: &UdpSocket, bytes: &[u8], to: SocketAddr, stats: &mut Stats) {
    for datagram in wire::datagrams(bytes) {
        if let Err(e) = socket.send_to(datagram, to).await {
            stats.io_errors += 1;
            tracing::debug!(%to, error = %e, "send failed");
        }
    }
}

async fn receive(socket: Option<&UdpSocket>, buf: &mut [u8]) -> io::Result<(usize, SocketAddr)> {
    match socket {
        Some(s) => s.recv_from(buf).await,
        None => pending().await,
    }
}

fn deadline(t: Instant) -> tokio::time::Instant {
    tokio::time::Instant::from_std(t)
}

/// SIGINT and SIGTERM, caught from the moment this exists (install it before announcing the
/// SITL is ready, so an early signal still stops it cleanly).
#[derive(Debug)]
pub struct Shutdown {
    pub(crate) interrupt: tokio::signal::unix::Signal,
    pub(crate) terminate: tokio::signal::unix::Signal,
}

impl Shutdown {
    /// Must be called inside the tokio runtime.
    pub fn install() -> io::Result<Self> {
        Ok(Shutdown {
            interrupt: signal(SignalKind::interrupt())?,
            terminate: signal(SignalKind::terminate())?,
        })
    }

    /// Waits for SIGINT or SIGTERM.
    pub async fn signalled(&mut self) {
        tokio::select! {
            biased;
            _ = self.interrupt.recv() => {}
            _ = self.terminate.recv() => {}
        }
    }
}

/// How long a blocking receive of the autopilot modes waits before it looks at its stop flag
/// again.
pub(crate) const STOP_POLL: std::time::Duration = std::time::Duration::from_millis(100);

/// Runs `work` on a thread of its own (the autopilot modes' blocking socket loops) until it
/// returns; a signal meanwhile sets the stop flag `work` watches. `beside` runs again and
/// again while waiting (PX4 mode refuses second connections there). Returns what `work`
/// returned and whether a signal came: a signal taken while `work` was ending on its own is
/// still a stop (e.g. PX4 closing the socket must not swallow it). `thread` names the thread
/// in the error if it panicked.
pub(crate) async fn on_stoppable_thread<T: Send + 'static>(
    thread: &str,
    shutdown: &mut Shutdown,
    work: impl FnOnce(&AtomicBool) -> T + Send + 'static,
    mut beside: impl AsyncFnMut(),
) -> io::Result<(T, bool)> {
    let stop = Arc::new(AtomicBool::new(false));
    let flag = Arc::clone(&stop);
    let mut worker = tokio::task::spawn_blocking(move || work(&flag));
    let mut stopping = false;
    loop {
        tokio::select! {
            biased;
            joined = &mut worker => match joined {
                Ok(done) => return Ok((done, stopping)),
                Err(e) => return Err(io::Error::other(format!("{thread} failed: {e}"))),
            },
            _ = shutdown.signalled(), if !stopping => {
                stop.store(true, Ordering::Relaxed);
                stopping = true;
            }
            () = beside() => {}
        }
    }
}

/// Whether a blocking receive's error only means "nothing yet, try again".
pub(crate) fn is_retry(kind: io::ErrorKind) -> bool {
    use io::ErrorKind::{Interrupted, TimedOut, WouldBlock};
    matches!(kind, WouldBlock | TimedOut | Interrupted)
}

/// Runs until SIGINT or SIGTERM; returns the counters.
pub async fn run(
    mut sim: Sim,
    controller: UdpSocket,
    gcs: Option<GcsLink>,
    mut shutdown: Shutdown,
) -> io::Result<Stats> {
    let mut buf = vec![0u8; RECEIVE_BUFFER];
    let mut gcs_buf = vec![0u8; RECEIVE_BUFFER];
    let mut out = Vec::with_capacity(RECEIVE_BUFFER);
    let realtime = sim.options.mode == Mode::Realtime;
    let mut next_physics = Instant::now();
    let mut next_gcs = Instant::now();
    let gcs_socket = gcs.as_ref().map(|g| &g.socket);
    loop {
        tokio::select! {
            biased;
            _ = shutdown.signalled() => break,
            r = controller.recv_from(&mut buf) => match r {
                Ok((n, from)) => answer_controller(&mut sim, &controller, &buf[..n], from, &mut out).await,
                Err(e) => receive_failed(&mut sim.stats, "controller", &e),
            },
            r = receive(gcs_socket, &mut gcs_buf), if gcs_socket.is_some() => match (r, gcs_socket) {
                (Ok((n, from)), Some(socket)) => answer_gcs(&mut sim, socket, &gcs_buf[..n], from, &mut out).await,
                (Err(e), _) => receive_failed(&mut sim.stats, "ground-station", &e),
                (Ok(_), None) => {}
            },
            _ = sleep_until(deadline(next_physics)), if realtime => {
                next_physics = realtime_tick(&mut sim, &controller).await;
            },
            _ = sleep_until(deadline(next_gcs)), if gcs.is_some() => {
                if let Some(g) = &gcs {
                    next_gcs = gcs_tick(&mut sim, g, &mut out).await;
                }
            },
        }
        flush_outboxes(&mut sim, &controller, gcs.as_ref()).await;
    }
    tracing::info!("stopping on a signal");
    Ok(sim.stats)
}

/// A controller datagram: handled, and the replies sent back to `from`; the time it took
/// is counted (handling, and busy with the send).
async fn answer_controller(
    sim: &mut Sim,
    socket: &UdpSocket,
    datagram: &[u8],
    from: SocketAddr,
    out: &mut Vec<u8>,
) {
    let start = Instant::now();
    out.clear();
    sim.handle(Link::Controller, from, datagram, start, out);
    sim.stats.handling += start.elapsed();
    if !out.is_empty() {
        send(socket, out, from, &mut sim.stats).await;
    }
    sim.stats.busy += start.elapsed();
}

/// A ground-station datagram: handled, and the replies sent back to `from`.
async fn answer_gcs(
    sim: &mut Sim,
    socket: &UdpSocket,
    datagram: &[u8],
    from: SocketAddr,
    out: &mut Vec<u8>,
) {
    out.clear();
    sim.handle(Link::Gcs, from, datagram, Instant::now(), out);
    if !out.is_empty() {
        send(socket, out, from, &mut sim.stats).await;
    }
}

/// A failed receive on a link is counted and logged; the server goes on.
fn receive_failed(stats: &mut Stats, link: &str, e: &io::Error) {
    stats.io_errors += 1;
    tracing::debug!(error = %e, "receive failed on the {link} link");
}

/// The real-time clock's tick: the vehicles due step and each controller peer gets its
/// stream; returns when the next tick is due.
async fn realtime_tick(sim: &mut Sim, controller: &UdpSocket) -> Instant {
    let next = sim.realtime_tick(Instant::now());
    let stream = std::mem::take(&mut sim.stream);
    for (to, bytes) in &stream {
        send(controller, bytes, *to, &mut sim.stats).await;
    }
    sim.stream = stream;
    next
}

/// The ground-station telemetry due now, sent; returns when the next is due.
async fn gcs_tick(sim: &mut Sim, gcs: &GcsLink, out: &mut Vec<u8>) -> Instant {
    out.clear();
    let next = sim.gcs_tick(Instant::now(), out);
    send(&gcs.socket, out, gcs.target, &mut sim.stats).await;
    next
}

/// Sends the event messages (failsafe, episode ends) raised while handling the last event.
async fn flush_outboxes(sim: &mut Sim, controller: &UdpSocket, gcs: Option<&GcsLink>) {
    if !sim.controller_outbox.is_empty() {
        let bytes = std::mem::take(&mut sim.controller_outbox);
        for to in sim.live_peers(Instant::now()) {
            send(controller, &bytes, to, &mut sim.stats).await;
        }
    }
    if !sim.gcs_outbox.is_empty() {
        let bytes = std::mem::take(&mut sim.gcs_outbox);
        if let Some(g) = gcs {
            send(&g.socket, &bytes, g.target, &mut sim.stats).await;
        }
    }
}
