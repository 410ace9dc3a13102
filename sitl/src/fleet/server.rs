//! The wall clock of fleet mode. One fleet thread polls every autopilot's socket
//! ([`super::sockets`]: PX4 accepts on its TCP port, one connection at a time; ArduPilot its
//! UDP port), owns the world, advances it whenever the barrier lets it, writes each due
//! autopilot its sensors, paces simulation time against the wall clock and silences an
//! autopilot that keeps the world waiting longer than the timeout.

use super::file::Autopilot;
use super::lockstep::{Hold, Phase};
use super::outputs::Outputs;
use super::sockets::{Event, Sockets};
pub use super::sockets::{Socket, bind};
use super::{Fleet, Link, Notice};
use crate::pacer::{self, Anchor, Pacing};
use crate::server::{STOP_POLL, Shutdown, on_stoppable_thread};
use crate::telemetry;
use crate::wire::Encoder;
use std::io;
use std::net::{SocketAddr, UdpSocket};
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant, SystemTime, UNIX_EPOCH};

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
    let gcs = match options.gcs {
        Some(target) => Some((UdpSocket::bind("0.0.0.0:0")?, target)),
        None => None,
    };
    let work = move |stop: &AtomicBool| {
        // Made here: the io_uring in it belongs to the thread that uses it.
        let sockets = Sockets::new(sockets)?;
        let mut state = Serving::new(fleet, sockets, gcs, options, outputs);
        let served = state.serve(stop);
        state.outputs.flush();
        let summary = state.summary();
        served.map(|()| (state.fleet, summary))
    };
    let (served, _) = on_stoppable_thread("fleet thread", &mut shutdown, work, async || {
        std::future::pending::<()>().await
    })
    .await?;
    let (fleet, summary) = served?;
    tracing::info!("stopping on a signal");
    Ok((fleet, summary))
}

/// The fleet thread's state.
struct Serving {
    fleet: Fleet,
    sockets: Sockets,
    /// What is written beside the flight after every step (`--track`).
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

    fn serve(&mut self, stop: &AtomicBool) -> io::Result<()> {
        let (mut events, mut awaited) = (Vec::new(), Vec::new());
        while !stop.load(Ordering::Relaxed) {
            let l = self.fleet.lockstep();
            awaited.clear();
            awaited.extend((0..l.len()).filter(|&i| l.is_awaited(i)));
            // Everything read in one wake-up is handled before the world steps.
            self.sockets
                .poll(self.wait(&awaited), &awaited, &mut events)?;
            for event in events.drain(..) {
                self.handle(event);
            }
            self.run_world();
            self.check_timeouts();
            self.remind_silent();
            self.send_notices();
            self.log_speed();
        }
        Ok(())
    }

    /// How long to wait for a socket: until the next free step, the next timeout of the
    /// autopilots the world waits for (`awaited`), or the next look at the stop flag.
    fn wait(&self, awaited: &[usize]) -> Duration {
        let now = Instant::now();
        let mut until = now + STOP_POLL;
        let l = self.fleet.lockstep();
        let free = (0..l.len()).any(|i| l.slot(i).phase == Phase::Free);
        let lockstep = (0..l.len()).any(|i| l.slot(i).phase == Phase::Lockstep);
        if free && !lockstep {
            until = until.min(self.next_free);
        }
        for &i in awaited {
            until = until.min(self.sent_at[i] + self.options.timeout);
        }
        until
            .saturating_duration_since(now)
            .max(Duration::from_micros(50))
    }

    fn handle(&mut self, event: Event) {
        match event {
            Event::Px4Connected { i, peer } => {
                tracing::info!(%peer, vehicle = %self.fleet.members()[i].name, "PX4 connected");
                self.fleet.px4_connected(i);
                self.sent_at[i] = Instant::now();
                self.flush(i);
                self.send_queued();
            }
            Event::Px4Bytes { i, bytes } => self.fleet.px4_bytes(i, &bytes),
            Event::Px4Closed { i, why } => self.fleet.px4_closed(i, &why),
            Event::Datagram { i, bytes, from } => {
                if self.fleet.ardupilot_datagram(i, &bytes, from) {
                    self.reply_ardupilot(i);
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
            self.send_queued();
            let t = self.fleet.lockstep().now_us();
            pacer::wait_for(self.options.pacing, &mut self.anchor, t, now);
            if !lockstep {
                // One free step per call: the next is due at `next_free`, which `serve`
                // waits for while it hears the sockets. Looping here instead never let a
                // paced fleet hear its starting PX4's first controls, a second PX4's
                // connection or a stop: the pacer's sleep ends at `next_free` or after it.
                return;
            }
        }
    }

    /// The PX4 writes `flush` queued, all at once; a PX4 a write failed on is gone.
    fn send_queued(&mut self) {
        let mut closed = Vec::new();
        self.sockets.send_queued(&mut closed);
        for event in closed {
            if let Event::Px4Closed { i, why } = &event {
                let name = &self.fleet.members()[*i].name;
                tracing::warn!(vehicle = %name, why = %why, "write to PX4 failed");
            }
            self.handle(event);
        }
    }

    /// Autopilot i's pending bytes: a PX4's queued for `send_queued`, an ArduPilot's sent.
    fn flush(&mut self, i: usize) {
        let member = self.fleet.member_mut(i);
        match &member.link {
            Link::Px4(_) => {
                if member.out.is_empty() {
                    return;
                }
                self.sockets.queue_px4(i, &member.out, &member.name);
                member.out.clear();
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

    /// Every timeout, each silent PX4 still connected gets sensors at the world's time
    /// ([`Fleet::remind`]).
    fn remind_silent(&mut self) {
        let now = Instant::now();
        let mut reminded = false;
        for i in 0..self.fleet.members().len() {
            if now >= self.sent_at[i] + self.options.timeout && self.fleet.remind(i) {
                self.sent_at[i] = now;
                self.flush(i);
                reminded = true;
            }
        }
        if reminded {
            self.send_queued();
        }
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
            "world_steps={} time_s={t:.3} wall_s={wall:.3} real_time_factor={:.3} collisions={} stale_controls={}",
            self.steps,
            t / wall.max(1e-9),
            self.fleet.collisions,
            self.fleet.stale_controls
        )
    }
}

/// Wall time between two speed lines in the log.
const SPEED_LOG: Duration = Duration::from_secs(10);
