//! The sockets and the wall clock of fleet mode. A thread per autopilot reads its socket
//! (PX4: accepts on its TCP port, one connection at a time; ArduPilot: its UDP port) and
//! passes what it read to the fleet thread over one channel; the fleet thread owns the
//! world, advances it whenever the barrier lets it, writes each due autopilot its sensors,
//! paces simulation time against the wall clock and silences an autopilot that keeps the
//! world waiting longer than the timeout.

use super::file::Autopilot;
use super::lockstep::{Hold, Phase};
use super::outputs::Outputs;
use super::{Fleet, Link, Notice};
use crate::pacer::{self, Anchor, Pacing};
use crate::server::{STOP_POLL, Shutdown, is_retry, on_stoppable_thread};
use crate::telemetry;
use crate::wire::Encoder;
use std::io::{self, Read, Write};
use std::net::{SocketAddr, TcpListener, TcpStream, UdpSocket};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::mpsc::{self, Receiver, RecvTimeoutError, Sender};
use std::time::{Duration, Instant, SystemTime, UNIX_EPOCH};

/// The fleet's sockets, bound before the SITL says it is ready.
#[derive(Debug)]
pub enum Socket {
    Px4(TcpListener),
    ArduPilot(UdpSocket),
}

impl Socket {
    /// The port it is bound to (an ephemeral one when asked for port 0).
    pub fn port(&self) -> io::Result<u16> {
        match self {
            Socket::Px4(listener) => listener.local_addr().map(|a| a.port()),
            Socket::ArduPilot(socket) => socket.local_addr().map(|a| a.port()),
        }
    }
}

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

/// Wall time a write to a PX4 may block before its bytes are dropped (a stalled PX4 whose
/// buffer is full must not stall the fleet).
const WRITE_TIMEOUT: Duration = Duration::from_millis(200);

/// What a socket thread read.
enum Event {
    Px4Connected {
        i: usize,
        connection: u64,
        writer: TcpStream,
        peer: SocketAddr,
    },
    Px4Bytes {
        i: usize,
        connection: u64,
        bytes: Vec<u8>,
    },
    Px4Closed {
        i: usize,
        connection: u64,
        why: String,
    },
    Datagram {
        i: usize,
        bytes: Vec<u8>,
        from: SocketAddr,
    },
}

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
    let (tx, rx) = mpsc::channel();
    let mut udp = Vec::with_capacity(sockets.len());
    for (i, socket) in sockets.into_iter().enumerate() {
        match socket {
            Socket::Px4(listener) => {
                listener.set_nonblocking(false)?;
                let tx = tx.clone();
                std::thread::Builder::new()
                    .name(format!("px4-{i}"))
                    .spawn(move || accept_px4(i, listener, tx))?;
                udp.push(None);
            }
            Socket::ArduPilot(socket) => {
                socket.set_nonblocking(false)?;
                let reader = socket.try_clone()?;
                let tx = tx.clone();
                std::thread::Builder::new()
                    .name(format!("ardupilot-{i}"))
                    .spawn(move || read_ardupilot(i, reader, tx))?;
                udp.push(Some(socket));
            }
        }
    }
    drop(tx);
    let gcs = match options.gcs {
        Some(target) => Some((UdpSocket::bind("0.0.0.0:0")?, target)),
        None => None,
    };
    let work = move |stop: &AtomicBool| {
        let mut state = Serving::new(fleet, udp, gcs, options, outputs);
        state.serve(&rx, stop);
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

/// PX4 i's port: one connection at a time (a second is refused while one is active); each
/// read goes to the fleet thread.
fn accept_px4(i: usize, listener: TcpListener, tx: Sender<Event>) {
    let active = Arc::new(AtomicBool::new(false));
    let connections = Arc::new(AtomicU64::new(0));
    loop {
        let (stream, peer) = match listener.accept() {
            Ok(accepted) => accepted,
            Err(e) => {
                tracing::warn!(error = %e, "accepting PX4 {i}'s connection failed");
                std::thread::sleep(Duration::from_millis(50));
                continue;
            }
        };
        if active.swap(true, Ordering::SeqCst) {
            tracing::warn!(%peer, port = listener.local_addr().map(|a| a.port()).unwrap_or(0), "refused a second PX4 connection: one PX4 is already connected on this port");
            continue;
        }
        let connection = connections.fetch_add(1, Ordering::SeqCst) + 1;
        let writer = match prepare(&stream) {
            Ok(w) => w,
            Err(e) => {
                tracing::warn!(%peer, error = %e, "PX4 connection unusable: dropped");
                active.store(false, Ordering::SeqCst);
                continue;
            }
        };
        let connected = Event::Px4Connected {
            i,
            connection,
            writer,
            peer,
        };
        if tx.send(connected).is_err() {
            return;
        }
        let (tx, active) = (tx.clone(), Arc::clone(&active));
        let spawned = std::thread::Builder::new()
            .name(format!("px4-{i}-read"))
            .spawn(move || {
                let why = read_px4(i, connection, stream, &tx);
                let _ = tx.send(Event::Px4Closed { i, connection, why });
                active.store(false, Ordering::SeqCst);
            });
        if let Err(e) = spawned {
            tracing::warn!(error = %e, "no thread for PX4 {i}'s connection");
            return;
        }
    }
}

/// The writing half of a PX4 connection: no Nagle delay, writes that give up.
fn prepare(stream: &TcpStream) -> io::Result<TcpStream> {
    stream.set_nodelay(true)?;
    let writer = stream.try_clone()?;
    writer.set_write_timeout(Some(WRITE_TIMEOUT))?;
    Ok(writer)
}

fn read_px4(i: usize, connection: u64, mut stream: TcpStream, tx: &Sender<Event>) -> String {
    let mut buf = vec![0u8; 16_384];
    loop {
        match stream.read(&mut buf) {
            Ok(0) => return "connection closed".into(),
            Ok(n) => {
                let bytes = buf[..n].to_vec();
                if tx
                    .send(Event::Px4Bytes {
                        i,
                        connection,
                        bytes,
                    })
                    .is_err()
                {
                    return "fleet stopped".into();
                }
            }
            Err(e) if e.kind() == io::ErrorKind::Interrupted => {}
            Err(e) => return format!("read failed: {e}"),
        }
    }
}

fn read_ardupilot(i: usize, socket: UdpSocket, tx: Sender<Event>) {
    let mut buf = vec![0u8; 2048];
    loop {
        match socket.recv_from(&mut buf) {
            Ok((n, from)) => {
                let bytes = buf[..n].to_vec();
                if tx.send(Event::Datagram { i, bytes, from }).is_err() {
                    return;
                }
            }
            Err(e) if is_retry(e.kind()) => {}
            // E.g. an ICMP error reported on the socket: the loop goes on.
            Err(e) => tracing::debug!(error = %e, "ArduPilot {i}: receive failed"),
        }
    }
}

/// The fleet thread's state.
struct Serving {
    fleet: Fleet,
    /// PX4 i's current connection: its number and writing half.
    writers: Vec<Option<(u64, TcpStream)>>,
    udp: Vec<Option<UdpSocket>>,
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
        udp: Vec<Option<UdpSocket>>,
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
            writers: (0..n).map(|_| None).collect(),
            udp,
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

    fn serve(&mut self, rx: &Receiver<Event>, stop: &AtomicBool) {
        while !stop.load(Ordering::Relaxed) {
            match rx.recv_timeout(self.wait()) {
                Ok(event) => {
                    self.handle(event);
                    // Everything already read, before stepping: fewer, larger batches.
                    while let Ok(event) = rx.try_recv() {
                        self.handle(event);
                    }
                }
                Err(RecvTimeoutError::Timeout) => {}
                Err(RecvTimeoutError::Disconnected) => return,
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

    fn handle(&mut self, event: Event) {
        match event {
            Event::Px4Connected {
                i,
                connection,
                writer,
                peer,
            } => {
                tracing::info!(%peer, vehicle = %self.fleet.members()[i].name, "PX4 connected");
                self.writers[i] = Some((connection, writer));
                self.fleet.px4_connected(i);
                self.sent_at[i] = Instant::now();
                self.flush(i);
            }
            Event::Px4Bytes {
                i,
                connection,
                bytes,
            } => {
                if self.is_current(i, connection) {
                    self.fleet.px4_bytes(i, &bytes);
                }
            }
            Event::Px4Closed { i, connection, why } => {
                if self.is_current(i, connection) {
                    self.writers[i] = None;
                    self.fleet.px4_closed(i, &why);
                }
            }
            Event::Datagram { i, bytes, from } => {
                if self.fleet.ardupilot_datagram(i, &bytes, from) {
                    self.reply_ardupilot(i);
                }
            }
        }
    }

    fn is_current(&self, i: usize, connection: u64) -> bool {
        matches!(&self.writers[i], Some((c, _)) if *c == connection)
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
            if !lockstep {
                // One free step per call: the next is due at `next_free`, which `serve`
                // waits for while it hears the sockets. Looping here instead never let a
                // paced fleet hear its starting PX4's first controls, a second PX4's
                // connection or a stop: the pacer's sleep ends at `next_free` or after it.
                return;
            }
        }
    }

    /// Autopilot i's pending bytes to its socket.
    fn flush(&mut self, i: usize) {
        let member = self.fleet.member_mut(i);
        match &member.link {
            Link::Px4(_) => {
                if member.out.is_empty() {
                    return;
                }
                if let Some((_, w)) = &mut self.writers[i] {
                    if let Err(e) = w.write_all(&member.out) {
                        tracing::warn!(vehicle = %member.name, error = %e, "write to PX4 failed: bytes dropped");
                    }
                }
                member.out.clear();
            }
            Link::ArduPilot(_) => self.reply_ardupilot(i),
        }
    }

    fn reply_ardupilot(&mut self, i: usize) {
        let member = &self.fleet.members()[i];
        let (Link::ArduPilot(a), Some(socket)) = (&member.link, &self.udp[i]) else {
            return;
        };
        if let Some(peer) = a.peer {
            if let Err(e) = socket.send_to(a.reply(), peer) {
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
