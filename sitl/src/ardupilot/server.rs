//! The UDP side of ArduPilot mode: one thread with a blocking socket (one receive and one send
//! per frame), pacing against the wall clock, silence logged, signals stop it.

use super::session::{Outcome, Session};
use crate::pacer::{self, Anchor, Pacing};
use crate::server::{STOP_POLL, Shutdown, is_retry, on_stoppable_thread};
use std::future::pending;
use std::io;
use std::net::UdpSocket;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

/// Wall time without a servo packet after which ArduPilot is reported silent (it re-sends
/// an unanswered frame after 1 s, so a live ArduPilot is never this quiet).
pub const SILENCE: Duration = Duration::from_millis(1500);

/// Largest datagram read (a servo packet is 40 or 72 bytes).
const RECEIVE_BUFFER: usize = 2048;

/// Serves ArduPilot on `socket` until SIGINT / SIGTERM; returns the session (its counters).
pub async fn run(
    mut session: Session,
    socket: UdpSocket,
    pacing: Pacing,
    mut shutdown: Shutdown,
) -> io::Result<Session> {
    socket.set_nonblocking(false)?;
    socket.set_read_timeout(Some(STOP_POLL))?;
    let work = move |stop: &AtomicBool| {
        serve(&mut session, &socket, pacing, stop);
        session.track.flush();
        session
    };
    let (session, _) = on_stoppable_thread("ArduPilot thread", &mut shutdown, work, async || {
        pending::<()>().await
    })
    .await?;
    tracing::info!("stopping on a signal");
    Ok(session)
}

/// The receive–step–send loop until `stop`.
fn serve(session: &mut Session, socket: &UdpSocket, pacing: Pacing, stop: &AtomicBool) {
    let mut buf = vec![0u8; RECEIVE_BUFFER];
    let mut anchor: Option<Anchor> = None;
    let mut last_frame = Instant::now();
    let mut silent = false;
    while !stop.load(Ordering::Relaxed) {
        match socket.recv_from(&mut buf) {
            Ok((n, from)) => {
                let start = Instant::now();
                let outcome = session.receive(&buf[..n], from);
                session.stats.handling += start.elapsed();
                if outcome == Outcome::Skipped {
                    continue;
                }
                if silent {
                    tracing::info!(%from, "ArduPilot sends again");
                    silent = false;
                }
                last_frame = start;
                if outcome == Outcome::Stepped {
                    pacer::wait_for(pacing, &mut anchor, session.time_us(), start);
                }
                if let Err(e) = socket.send_to(session.reply(), from) {
                    session.stats.io_errors += 1;
                    tracing::debug!(%from, error = %e, "sending the state failed");
                }
            }
            Err(e) if is_retry(e.kind()) => {
                if session.is_active() && !silent && last_frame.elapsed() >= SILENCE {
                    silent = true;
                    tracing::warn!(
                        time_us = session.time_us(),
                        steps = session.stats.steps,
                        "no servo packet from ArduPilot for {:.1} s: stopped or killed? The vehicle holds; a restarted ArduPilot resets it",
                        SILENCE.as_secs_f64()
                    );
                    session.track.flush();
                }
            }
            Err(e) => {
                // E.g. an ICMP error reported on the socket: counted, the loop goes on.
                session.stats.io_errors += 1;
                tracing::debug!(error = %e, "receive failed");
            }
        }
    }
}
