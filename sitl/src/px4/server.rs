//! The TCP side of PX4 mode: accept PX4, pace its lockstep against the wall clock, and live
//! through PX4 going away (reset, accept the next one).

use super::session::Session;
use crate::server::{STOP_POLL, Shutdown, is_retry, on_stoppable_thread};
use std::io::{self, Read, Write};
use std::net::{SocketAddr, TcpStream};
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant, SystemTime, UNIX_EPOCH};

pub use crate::pacer::Pacing;
use crate::pacer::{self, Anchor, MAX_LAG};
use tokio::net::TcpListener;

fn unix_now_us() -> u64 {
    SystemTime::now()
        .duration_since(UNIX_EPOCH)
        .map_or(0, |d| d.as_micros() as u64)
}

/// What ended a connection.
enum End {
    Shutdown,
    Closed(String),
}

/// Serves PX4 connections one at a time until SIGINT / SIGTERM.
///
/// Each connection runs on a thread of its own with blocking socket calls: one read and one
/// write per lockstep step, with no readiness poll in between (an event loop adds an
/// epoll_wait per step, a third of the syscalls). This task meanwhile refuses second
/// connections and turns signals into the connection thread's stop flag.
pub async fn run(
    mut session: Session,
    listener: TcpListener,
    pacing: Pacing,
    mut shutdown: Shutdown,
) -> io::Result<Session> {
    let mut connections = 0u64;
    loop {
        let (stream, peer) = tokio::select! {
            biased;
            _ = shutdown.signalled() => break,
            r = listener.accept() => match r {
                Ok(accepted) => accepted,
                Err(e) => {
                    tracing::warn!(error = %e, "accepting a PX4 connection failed");
                    continue;
                }
            },
        };
        connections += 1;
        tracing::info!(%peer, connection = connections, "PX4 connected");
        let Some(stream) = blocking_stream(stream, peer) else {
            continue;
        };
        let end;
        (session, end) = connection(session, stream, pacing, &listener, &mut shutdown).await?;
        match end {
            End::Shutdown => break,
            End::Closed(why) => {
                tracing::warn!(
                    %peer,
                    time_us = session.time_us(),
                    steps = session.stats.steps,
                    "PX4 disconnected ({why}): vehicle reset to its start state, waiting for the next connection"
                );
            }
        }
    }
    tracing::info!("stopping on a signal");
    Ok(session)
}

/// The accepted stream for the connection thread's blocking calls; `None` (logged) if the
/// socket refuses.
fn blocking_stream(stream: tokio::net::TcpStream, peer: SocketAddr) -> Option<TcpStream> {
    let stream = stream.into_std().and_then(|s| {
        s.set_nonblocking(false)?;
        Ok(s)
    });
    stream
        .inspect_err(|e| tracing::warn!(%peer, error = %e, "PX4 connection unusable: dropped"))
        .ok()
}

/// Serves one PX4 connection on its thread until it ends; refuses second connections
/// meanwhile.
async fn connection(
    mut session: Session,
    stream: TcpStream,
    pacing: Pacing,
    listener: &TcpListener,
    shutdown: &mut Shutdown,
) -> io::Result<(Session, End)> {
    let work = move |stop: &AtomicBool| {
        let end = serve(&mut session, stream, pacing, stop);
        session.track.flush();
        (session, end)
    };
    let refuse_second = async || {
        if let Ok((second, addr)) = listener.accept().await {
            tracing::warn!(peer = %addr, "refused a second PX4 connection: one PX4 is already connected");
            drop(second);
        }
    };
    let ((session, end), signalled) =
        on_stoppable_thread("PX4 connection thread", shutdown, work, refuse_second).await?;
    // A signal taken while the connection was ending on its own is still a stop: the
    // connection's own end (e.g. PX4 closed the socket) must not swallow it.
    Ok((session, if signalled { End::Shutdown } else { end }))
}

/// One PX4 connection, from its first HIL_SENSOR to its end, with blocking socket calls.
/// Before lockstep the read waits at most until the next free step is due; in lockstep up
/// to STOP_POLL, so `stop` is seen within that time.
fn serve(session: &mut Session, mut stream: TcpStream, pacing: Pacing, stop: &AtomicBool) -> End {
    if let Err(e) = stream.set_nodelay(true) {
        tracing::debug!(error = %e, "TCP_NODELAY not set");
    }
    let mut buf = vec![0u8; 16_384];
    let mut out = Vec::with_capacity(4096);
    session.connect(unix_now_us(), &mut out);
    if let Err(e) = stream.write_all(&out) {
        return End::Closed(format!("write failed: {e}"));
    }
    let mut free = FreeClock::starting(pacing.free_step(session.step_us()));
    let mut anchor: Option<Anchor> = None;
    // The read timeout last set: a setsockopt only when it changes (once in lockstep).
    let mut timeout: Option<Duration> = None;
    loop {
        if stop.load(Ordering::Relaxed) {
            return End::Shutdown;
        }
        out.clear();
        let wait = if session.is_lockstep() {
            STOP_POLL
        } else {
            free.until_due()
        };
        if timeout != Some(wait) {
            if let Err(e) = stream.set_read_timeout(Some(wait)) {
                return End::Closed(format!("cannot set the read timeout: {e}"));
            }
            timeout = Some(wait);
        }
        match stream.read(&mut buf) {
            Ok(0) => return End::Closed("connection closed".into()),
            Ok(n) => handle(session, &buf[..n], &mut out, pacing, &mut anchor),
            // Timed out (the next free step, or a look at the stop flag) or interrupted.
            Err(e) if is_retry(e.kind()) => {}
            Err(e) => return End::Closed(format!("read failed: {e}")),
        }
        if !session.is_lockstep() {
            free.step_if_due(session, &mut out);
        }
        if !out.is_empty() {
            if let Err(e) = stream.write_all(&out) {
                return End::Closed(format!("write failed: {e}"));
            }
        }
    }
}

/// Bytes from PX4: handled (the replies appended to `out`), then, if they stepped the
/// physics, paced against the wall clock.
fn handle(
    session: &mut Session,
    bytes: &[u8],
    out: &mut Vec<u8>,
    pacing: Pacing,
    anchor: &mut Option<Anchor>,
) {
    let start = Instant::now();
    let steps = session.receive(bytes, out);
    session.stats.handling += start.elapsed();
    if steps > 0 {
        pacer::wait_for(pacing, anchor, session.time_us(), start);
    }
}

/// The clock before lockstep: a free step every `step` of wall time, so PX4 gets sensors
/// while it starts up.
struct FreeClock {
    step: Duration,
    next: Instant,
}

impl FreeClock {
    fn starting(step: Duration) -> Self {
        FreeClock {
            step,
            next: Instant::now() + step,
        }
    }

    /// How long a read may wait for PX4 before the next free step (at least 1 µs, at most
    /// STOP_POLL).
    fn until_due(&self) -> Duration {
        self.next
            .saturating_duration_since(Instant::now())
            .clamp(Duration::from_micros(1), STOP_POLL)
    }

    /// The free step, if due; a clock more than MAX_LAG late starts again from now.
    fn step_if_due(&mut self, session: &mut Session, out: &mut Vec<u8>) {
        if Instant::now() < self.next {
            return;
        }
        session.free_step(out);
        self.next += self.step;
        let now = Instant::now();
        if self.next + MAX_LAG < now {
            self.next = now + self.step;
        }
    }
}
