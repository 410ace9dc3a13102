//! The wall clock of fleet mode. One thread, the fleet thread, owns the world and every
//! autopilot's socket ([`super::sockets`]): it waits on all of them at once, hands what it
//! read to the fleet, advances the world whenever the barrier lets it, writes each due
//! autopilot its sensors, paces simulation time against the wall clock and silences an
//! autopilot that keeps the world waiting longer than the timeout.

use super::file::Autopilot;
use super::lockstep::{Hold, Phase};
use super::outputs::Outputs;
use super::sockets::{Received, Sockets};
use super::{Fleet, Link, Notice};
use crate::pacer::{self, Anchor, Pacing};
use crate::server::{STOP_POLL, Shutdown, on_stoppable_thread};
use crate::telemetry;
use crate::wire::Encoder;
use std::io;
use std::net::{SocketAddr, TcpListener, UdpSocket};
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant, SystemTime, UNIX_EPOCH};

pub use super::sockets::Socket;

/// How the fleet runs.
#[derive(Debug, Clone, Copy)]
pub struct FleetOptions {
    pub pacing: Pacing,
    /// Wall time an autopilot in lockstep may keep the world waiting before its motors stop
    /// and the others go on without it.
    pub timeout: Duration,
    /// Where notices go as STATUSTEXT (a ground station), if anywhere.
    pub gcs: Option<SocketAddr>,
}

/// System id of the fleet's own STATUSTEXT.
pub const FLEET_SYSTEM: u8 = 250;

fn unix_now_us() -> u64 {
    SystemTime::now()
        .duration_since(UNIX_EPOCH)
        .map_or(0, |d| d.as_micros() as u64)
}

/// Serves the fleet until SIGINT / SIGTERM, writing `outputs` as it flies; returns it and
/// its stop line.
pub async fn run(
    fleet: Fleet,
    sockets: Vec<Socket>,
    options: FleetOptions,
    outputs: Outputs,
    mut shutdown: Shutdown,
) -> io::Result<(Fleet, String)> {
    let sockets = Sockets::new(sockets)?;
    let gcs = match options.gcs {
        Some(target) => Some((UdpSocket::bind("0.0.0.0:0")?, target)),
        None => None,
    };
    let work = move |stop: &AtomicBool| {
        super::priority::favour_this_thread();
        let mut state = Serving::new(fleet, sockets, gcs, options, outputs);
        state.serve(stop);
        state.outputs.flush();
        let summary = state.summary();
        (state.fleet, summary)
    };
    let ((fleet, summary), _) =
        on_stoppable_thread("fleet thread", &mut shutdown, work, async || {
            std::future::pending::<()>().await
        })
        .await?;
    tracing::info!("stopping on a signal");
    Ok((fleet, summary))
}

/// The fleet thread's state.
struct Serving {
    fleet: Fleet,
    sockets: Sockets,
    outputs: Outputs,
    gcs: Option<(UdpSocket, SocketAddr)>,
    encoder: Encoder,
    options: FleetOptions,
    /// When each autopilot was last sent its sensors (the start of its answer's wait).
    sent_at: Vec<Instant>,
    anchor: Option<Anchor>,
    /// The next step of the free clock (nobody in lockstep).
    next_free: Instant,
    free_step: Duration,
    steps: u64,
    started: Instant,
    next_log: Instant,
    last_log: (Instant, u64),
}

impl Serving {
    fn new(
        fleet: Fleet,
        sockets: Sockets,
        gcs: Option<(UdpSocket, SocketAddr)>,
        options: FleetOptions,
        mut outputs: Outputs,
    ) -> Self {
        let n = fleet.members().len();
        let free_step = options.pacing.free_step(super::PX4_STEP_US);
        let mut fleet = fleet;
        fleet.gps_epoch_us = unix_now_us();
        outputs.after_step(&fleet);
        Serving {
            fleet,
            sockets,
            outputs,
            gcs,
            encoder: Encoder::default(),
            options,
            sent_at: vec![Instant::now(); n],
            anchor: None,
            next_free: Instant::now(),
            free_step,
            steps: 0,
            started: Instant::now(),
            next_log: Instant::now() + SPEED_LOG,
            last_log: (Instant::now(), 0),
        }
    }

    fn serve(&mut self, stop: &AtomicBool) {
        let mut received = Vec::new();
        while !stop.load(Ordering::Relaxed) {
            // Everything read in one wake-up is handled before stepping: fewer, larger
            // batches.
            received.clear();
            received.extend_from_slice(self.sockets.poll(self.wait()));
            for r in &received {
                self.handle(r);
            }
            self.run_world();
            self.check_timeouts();
            self.send_notices();
            self.log_speed();
        }
    }

    /// How long to wait for a socket: until the next free step, the next timeout, or the
    /// next look at the stop flag.
    fn wait(&self) -> Duration {
        let now = Instant::now();
        let mut until = now + STOP_POLL;
        let l = self.fleet.lockstep();
        let free = (0..l.len()).any(|i| l.slot(i).phase == Phase::Free);
        let lockstep = (0..l.len()).any(|i| l.slot(i).phase == Phase::Lockstep);
        if free && !lockstep {
            until = until.min(self.next_free);
        }
        for i in (0..l.len()).filter(|&i| l.is_awaited(i)) {
            until = until.min(self.sent_at[i] + self.options.timeout);
        }
        until
            .saturating_duration_since(now)
            .max(Duration::from_micros(50))
    }

    fn handle(&mut self, received: &Received) {
        match received {
            &Received::Px4Connected { i, peer } => {
                tracing::info!(%peer, vehicle = %self.fleet.members()[i].name, "PX4 connected");
                self.fleet.px4_connected(i);
                self.sent_at[i] = Instant::now();
                self.flush(i);
            }
            Received::Px4Bytes { i, bytes } => {
                self.fleet
                    .px4_bytes(*i, &self.sockets.bytes()[bytes.clone()]);
            }
            Received::Px4Closed { i, why } => self.fleet.px4_closed(*i, why),
            Received::Datagram { i, bytes, from } => {
                let datagram = &self.sockets.bytes()[bytes.clone()];
                if self.fleet.ardupilot_datagram(*i, datagram, *from) {
                    self.reply_ardupilot(*i);
                }
            }
        }
    }

    /// Steps the world as far as the barrier lets it (and the free clock, when nobody is in
    /// lockstep), sending each due autopilot its sensors at once.
    fn run_world(&mut self) {
        loop {
            let now = Instant::now();
            let free = now >= self.next_free;
            let due = match self.fleet.advance(free) {
                Ok(due) => due,
                Err(Hold::Waiting(_) | Hold::Idle) => return,
            };
            self.steps += 1;
            self.outputs.after_step(&self.fleet);
            let lockstep = (0..self.fleet.lockstep().len())
                .any(|i| self.fleet.lockstep().slot(i).phase == Phase::Lockstep);
            if !lockstep {
                self.next_free = (self.next_free + self.free_step).max(now);
            }
            let sent = Instant::now();
            for i in due {
                self.sent_at[i] = sent;
                self.flush(i);
            }
            let t = self.fleet.lockstep().now_us();
            pacer::wait_for(self.options.pacing, &mut self.anchor, t, now);
        }
    }

    /// Autopilot i's pending bytes to its socket.
    fn flush(&mut self, i: usize) {
        let member = self.fleet.member_mut(i);
        match &member.link {
            Link::Px4(_) => {
                if !member.out.is_empty() {
                    self.sockets.send_px4(i, &member.out, &member.name);
                    member.out.clear();
                }
            }
            Link::ArduPilot(_) => self.reply_ardupilot(i),
        }
    }

    fn reply_ardupilot(&mut self, i: usize) {
        let member = &self.fleet.members()[i];
        let Link::ArduPilot(a) = &member.link else {
            return;
        };
        if let Some(peer) = a.peer {
            if let Err(e) = self.sockets.send_ardupilot(i, a.reply(), peer) {
                tracing::debug!(vehicle = %member.name, error = %e, "reply to ArduPilot failed");
            }
        }
    }

    /// Silences every autopilot that kept the world waiting past the timeout.
    fn check_timeouts(&mut self) {
        let now = Instant::now();
        let l = self.fleet.lockstep();
        let late: Vec<usize> = (0..l.len())
            .filter(|&i| l.is_awaited(i) && now >= self.sent_at[i] + self.options.timeout)
            .collect();
        for i in late {
            self.fleet.silence(i, now - self.sent_at[i]);
            if self.fleet.members()[i].autopilot == Autopilot::Px4 {
                // Nothing more to a PX4 that does not read; it rejoins when it answers.
                self.fleet.member_mut(i).out.clear();
            }
        }
        if !(0..self.fleet.lockstep().len())
            .any(|i| self.fleet.lockstep().slot(i).phase == Phase::Lockstep)
        {
            self.next_free = self.next_free.max(now);
        }
        self.run_world();
    }

    /// Notices as STATUSTEXT to the ground station.
    fn send_notices(&mut self) {
        let notices = self.fleet.take_notices();
        let Some((socket, target)) = &self.gcs else {
            return;
        };
        let mut out = Vec::new();
        for (k, Notice { severity, text }) in notices.iter().enumerate() {
            for m in telemetry::statustext(*severity, text, (k + 1) as u16) {
                out.clear();
                self.encoder.push(&mut out, FLEET_SYSTEM, &m);
                if let Err(e) = socket.send_to(&out, target) {
                    tracing::debug!(%target, error = %e, "STATUSTEXT not sent");
                }
            }
        }
    }
}

impl Serving {
    /// Every SPEED_LOG of wall time: simulation time and the real-time factor.
    fn log_speed(&mut self) {
        let now = Instant::now();
        if now < self.next_log {
            return;
        }
        let t = self.fleet.lockstep().now_us();
        let wall = now - self.last_log.0;
        let rtf = (t - self.last_log.1) as f64 * 1e-6 / wall.as_secs_f64();
        tracing::info!(
            time_s = format!("{:.1}", t as f64 * 1e-6),
            real_time_factor = format!("{rtf:.2}"),
            "fleet"
        );
        self.last_log = (now, t);
        self.next_log = now + SPEED_LOG;
    }

    /// The stop line: world steps, simulation and wall time, collisions.
    fn summary(&self) -> String {
        let t = self.fleet.lockstep().now_us() as f64 * 1e-6;
        let wall = self.started.elapsed().as_secs_f64();
        format!(
            "world_steps={} time_s={t:.3} wall_s={wall:.3} real_time_factor={:.3} collisions={} stale_controls={} unannounced_reads={}",
            self.steps,
            t / wall.max(1e-9),
            self.fleet.collisions,
            self.fleet.stale_controls,
            self.sockets.unannounced
        )
    }
}

/// Wall time between two speed lines in the log.
const SPEED_LOG: Duration = Duration::from_secs(10);

/// Sockets of `fleet`'s autopilots, in its (name) order.
pub fn bind(fleet: &Fleet) -> Result<Vec<Socket>, (String, SocketAddr, io::Error)> {
    (fleet.members().iter())
        .map(|m| match m.autopilot {
            Autopilot::Px4 => TcpListener::bind(m.listen)
                .map(Socket::Px4)
                .map_err(|e| (m.name.clone(), m.listen, e)),
            Autopilot::Ardupilot => UdpSocket::bind(m.listen)
                .map(Socket::ArduPilot)
                .map_err(|e| (m.name.clone(), m.listen, e)),
        })
        .collect()
}
