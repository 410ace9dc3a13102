//! The TCP side of PX4 mode: accept PX4, pace its lockstep against the wall clock, and live
//! through PX4 going away (reset, accept the next one).

use super::session::Session;
use crate::server::{STOP_POLL, Shutdown, is_retry};
use std::io::{self, Read, Write};
use std::net::TcpStream;
use std::sync::Arc;
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
        let accepted = tokio::select! {
            biased;
            _ = shutdown.signalled() => break,
            r = listener.accept() => r,
        };
        let (stream, peer) = match accepted {
            Ok(a) => a,
            Err(e) => {
                tracing::warn!(error = %e, "accepting a PX4 connection failed");
                continue;
            }
        };
        connections += 1;
        tracing::info!(%peer, connection = connections, "PX4 connected");
        let stream = match stream.into_std().and_then(|s| {
            s.set_nonblocking(false)?;
            Ok(s)
        }) {
            Ok(s) => s,
            Err(e) => {
                tracing::warn!(%peer, error = %e, "PX4 connection unusable: dropped");
                continue;
            }
        };
        let stop = Arc::new(AtomicBool::new(false));
        let flag = Arc::clone(&stop);
        let mut connection = tokio::task::spawn_blocking(move || {
            let end = serve(&mut session, stream, pacing, &flag);
            session.flush_track();
            (session, end)
        });
        let mut stopping = false;
        let (returned, end) = loop {
            tokio::select! {
                biased;
                joined = &mut connection => match joined {
                    Ok(done) => break done,
                    Err(e) => return Err(io::Error::other(format!("PX4 connection thread failed: {e}"))),
                },
                _ = shutdown.signalled(), if !stopping => { stop.store(true, Ordering::Relaxed); stopping = true; }
                r = listener.accept() => {
                    if let Ok((second, addr)) = r {
                        tracing::warn!(peer = %addr, "refused a second PX4 connection: one PX4 is already connected");
                        drop(second);
                    }
                },
            }
        };
        session = returned;
        // A signal taken while the connection was ending on its own is still a stop: the
        // connection's own end (e.g. PX4 closed the socket) must not swallow it.
        if stopping {
            break;
        }
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
    let free_step = pacing.free_step(session.step_us());
    let mut next_free = Instant::now() + free_step;
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
            next_free
                .saturating_duration_since(Instant::now())
                .clamp(Duration::from_micros(1), STOP_POLL)
        };
        if timeout != Some(wait) {
            if let Err(e) = stream.set_read_timeout(Some(wait)) {
                return End::Closed(format!("cannot set the read timeout: {e}"));
            }
            timeout = Some(wait);
        }
        match stream.read(&mut buf) {
            Ok(0) => return End::Closed("connection closed".into()),
            Ok(n) => {
                let start = Instant::now();
                let steps = session.receive(&buf[..n], &mut out);
                session.stats.handling += start.elapsed();
                if steps > 0 {
                    pacer::wait_for(pacing, &mut anchor, session.time_us(), start);
                }
            }
            // Timed out (the next free step, or a look at the stop flag) or interrupted.
            Err(e) if is_retry(e.kind()) => {}
            Err(e) => return End::Closed(format!("read failed: {e}")),
        }
        if !session.is_lockstep() && Instant::now() >= next_free {
            session.free_step(&mut out);
            next_free += free_step;
            let now = Instant::now();
            if next_free + MAX_LAG < now {
                next_free = now + free_step;
            }
        }
        if !out.is_empty() {
            if let Err(e) = stream.write_all(&out) {
                return End::Closed(format!("write failed: {e}"));
            }
        }
    }
}
