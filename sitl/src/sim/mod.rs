//! The simulation as the network sees it: vehicles addressed by system id, the datagram
//! handler for both links, and the real-time clock's steps. No sockets here: the server
//! ([`crate::server`]) passes datagrams in and sends what comes out, so tests and the fuzz
//! target drive this directly.

use crate::gcs_streams::GcsStreams;
use crate::kinematics::Home;
use crate::pacer::Cadence;
use crate::stats::Stats;
use crate::telemetry;
use crate::vehicle::Vehicle;
use crate::wire::{self, Encoder, FrameError, Incoming};
use flyloop_core::tasks::registry::{TaskConfig, TaskKind};

use flyloop_core::ParamError;
use mavlink::dialects::common::{MavCmd, MavMessage, MavSeverity};
use std::net::SocketAddr;
use std::time::{Duration, Instant};

mod command_handler;
mod controls;
mod realtime;
mod refusal;
mod world_gcs;
mod world_handler;
mod world_task;

use refusal::{Refusal, TextBudget};
pub use refusal::{TEXT_WINDOW, TEXTS_PER_WINDOW};
pub use world_task::{EXTRA_VALUES, WorldTask, reward_from_pieces, world_config};

/// How physics is paced.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum Mode {
    /// One control period per HIL_ACTUATOR_CONTROLS with the LOCKSTEP flag; no wall clock.
    Lockstep,
    /// Paced by the wall clock at the task's control rate; the last command holds.
    Realtime,
}

impl Mode {
    /// The name used on the command line.
    pub fn name(self) -> &'static str {
        match self {
            Mode::Lockstep => "lockstep",
            Mode::Realtime => "realtime",
        }
    }
}

/// Which socket a datagram came in on.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Link {
    /// The controller link (`--listen`): lockstep, ground truth, task frames.
    Controller,
    /// The ground-station link (`--gcs`).
    Gcs,
}

/// Reset command (COMMAND_LONG): MAV_CMD_USER_1.
pub const RESET_COMMAND: MavCmd = MavCmd::MAV_CMD_USER_1;

/// Everything the simulation is started with.
#[derive(Debug, Clone)]
pub struct SimOptions {
    pub task: TaskKind,
    pub vehicles: u8,
    /// Vehicle k starts with seed `seed + k − 1` (wrapping).
    pub seed: u64,
    pub config: TaskConfig,
    pub mode: Mode,
    pub home: Home,
    /// Whether a controller peer gets HIL_STATE_QUATERNION in its replies until it says
    /// otherwise (SET_MESSAGE_INTERVAL).
    pub state_in_reply: bool,
    /// Real time: controller silence after which the motors go off.
    pub failsafe_timeout: Duration,
    /// Real time: HIL_STATE_QUATERNION (and task frame) stream rate to controller peers, Hz.
    pub state_rate_hz: f64,
}

impl SimOptions {
    pub fn new(task: TaskKind) -> Self {
        SimOptions {
            task,
            vehicles: 1,
            seed: 0,
            config: TaskConfig::default(),
            mode: Mode::Lockstep,
            home: Home::default(),
            state_in_reply: true,
            failsafe_timeout: Duration::from_millis(500),
            state_rate_hz: 50.0,
        }
    }
}

/// A controller peer: where replies and the real-time stream go, and what they hold.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Peer {
    addr: SocketAddr,
    /// HIL_STATE_QUATERNION in lockstep replies / the real-time stream.
    state: bool,
    /// Task frame in lockstep replies / the real-time stream.
    frame: bool,
    /// Real-time stream interval, µs of simulation time.
    interval_us: u64,
    last_heard: Instant,
}

/// Peers silent this long stop getting the real-time stream.
const PEER_TIMEOUT: Duration = Duration::from_secs(5);
/// Peers remembered at once (the least recently heard one is forgotten).
const MAX_PEERS: usize = 32;
/// Real time: steps a late vehicle may catch up at once before the clock skips ahead.
const MAX_CATCH_UP: u32 = 10;

/// Real-time bookkeeping of a vehicle.
#[derive(Debug, Clone, Copy)]
struct Runtime {
    /// Steps only while running: from its first command until its episode terminates.
    running: bool,
    failsafe: bool,
    last_command: Option<Instant>,
    cadence: Cadence,
}

/// The simulation.
#[derive(Debug)]
pub struct Sim {
    pub options: SimOptions,
    pub vehicles: Vec<Vehicle>,
    runtime: Vec<Runtime>,
    pub stats: Stats,
    controller_encoder: Encoder,
    gcs_encoder: Encoder,
    peers: Vec<Peer>,
    next_text_id: u16,
    /// The per-peer rate limit of the texts that answer refused controls.
    refusal_texts: TextBudget,
    /// The ground-station streams: one set every vehicle follows, or one per vehicle of a
    /// world (SET_MESSAGE_INTERVAL addressed to its system id).
    gcs_streams: Vec<GcsStreams>,
    /// Messages for the ground station raised by events (failsafe, resets), sent by the server.
    pub gcs_outbox: Vec<u8>,
    /// Messages for every live controller peer raised by events in real time.
    pub controller_outbox: Vec<u8>,
    /// Real-time stream output: one datagram per peer.
    pub stream: Vec<(SocketAddr, Vec<u8>)>,
    /// `--record FILE`: every step of every vehicle.
    pub recorder: Option<crate::record::Recorder>,
    /// A multi-agent task served as one world (protocol §14); `vehicles` is empty then.
    pub world: Option<WorldTask>,
    /// The datagram being handled has had the world's cached reply (a repeated step).
    world_repeat_sent: bool,
}

impl Sim {
    /// Vehicles 1..=N, each reset with its own seed.
    pub fn new(options: SimOptions, now: Instant) -> Result<Self, ParamError> {
        let vehicles = (1..=options.vehicles)
            .map(|k| {
                let seed = options.seed.wrapping_add(u64::from(k) - 1);
                Vehicle::new(k, options.task, options.config.clone(), seed)
            })
            .collect::<Result<Vec<_>, _>>()?;
        let runtime = vec![
            Runtime {
                running: false,
                failsafe: false,
                last_command: None,
                cadence: Cadence::starting(now),
            };
            vehicles.len()
        ];
        Ok(Sim {
            options,
            vehicles,
            runtime,
            stats: Stats::default(),
            controller_encoder: Encoder::default(),
            gcs_encoder: Encoder::default(),
            peers: Vec::new(),
            next_text_id: 1,
            refusal_texts: TextBudget::default(),
            gcs_streams: vec![GcsStreams::new(now)],
            gcs_outbox: Vec::new(),
            controller_outbox: Vec::new(),
            stream: Vec::new(),
            recorder: None,
            world: None,
            world_repeat_sent: false,
        })
    }

    /// A simulation serving `world` (a multi-agent task, lockstep) instead of vehicles.
    pub fn new_world(
        options: SimOptions,
        world: WorldTask,
        now: Instant,
    ) -> Result<Self, ParamError> {
        let options = SimOptions {
            vehicles: 0,
            ..options
        };
        let mut sim = Sim::new(options, now)?;
        // Each vehicle of the world streams to the ground station as its own system.
        sim.gcs_streams = vec![GcsStreams::new(now); world.num_agents()];
        sim.world = Some(world);
        Ok(sim)
    }

    /// The system id vehicle (or world agent) index `i` sends as.
    pub(crate) fn system_id_of(&self, i: usize) -> Option<u8> {
        match &self.world {
            Some(w) => (i < w.num_agents()).then(|| (i + 1) as u8),
            None => self.vehicles.get(i).map(|v| v.system_id),
        }
    }

    /// How many systems this SITL speaks for: its vehicles, or the world's.
    pub(crate) fn system_count(&self) -> usize {
        match &self.world {
            Some(w) => w.num_agents(),
            None => self.vehicles.len(),
        }
    }

    fn vehicle_index(&self, system_id: u8) -> Option<usize> {
        let i = usize::from(system_id).checked_sub(1)?;
        (i < self.system_count()).then_some(i)
    }

    /// The vehicles (a world's agents) a message with `target_system` addresses (0 = all);
    /// None if no vehicle has that id.
    pub(crate) fn targets(&mut self, target_system: u8) -> Option<std::ops::Range<usize>> {
        if target_system == 0 {
            return Some(0..self.system_count());
        }
        match self.vehicle_index(target_system) {
            Some(i) => Some(i..i + 1),
            None => {
                self.stats.unknown_vehicle += 1;
                tracing::debug!(target_system, "message for an unknown system id skipped");
                None
            }
        }
    }

    fn encoder(&mut self, link: Link) -> &mut Encoder {
        match link {
            Link::Controller => &mut self.controller_encoder,
            Link::Gcs => &mut self.gcs_encoder,
        }
    }

    /// Appends `message` from vehicle index `i` on `link`.
    pub(crate) fn push(&mut self, link: Link, out: &mut Vec<u8>, i: usize, message: &MavMessage) {
        let system_id = self.system_id_of(i).unwrap_or(1);
        self.encoder(link).push(out, system_id, message);
    }

    /// Appends a STATUSTEXT (chunked if long) from vehicle index `i`.
    pub(crate) fn push_text(
        &mut self,
        link: Link,
        out: &mut Vec<u8>,
        i: usize,
        severity: MavSeverity,
        text: &str,
    ) {
        let id = self.next_text_id;
        self.next_text_id = self.next_text_id.checked_add(1).unwrap_or(1);
        for m in telemetry::statustext(severity, text, id) {
            self.push(link, out, i, &m);
        }
    }

    fn peer_index(&mut self, addr: SocketAddr, now: Instant) -> usize {
        if let Some(i) = self.peers.iter().position(|p| p.addr == addr) {
            self.peers[i].last_heard = now;
            return i;
        }
        if self.peers.len() >= MAX_PEERS {
            if let Some(oldest) = (0..self.peers.len()).min_by_key(|&i| self.peers[i].last_heard) {
                self.peers.swap_remove(oldest);
            }
        }
        let interval_us = (1e6 / self.options.state_rate_hz.max(1e-3)).round() as u64;
        self.peers.push(Peer {
            addr,
            state: self.options.state_in_reply,
            frame: true,
            interval_us: interval_us.max(1),
            last_heard: now,
        });
        self.peers.len() - 1
    }

    /// Handles one datagram from `from` on `link`; replies for the sender are appended to
    /// `out` (the server sends them back as one datagram).
    pub fn handle(
        &mut self,
        link: Link,
        from: SocketAddr,
        datagram: &[u8],
        now: Instant,
        out: &mut Vec<u8>,
    ) {
        match link {
            Link::Controller => self.stats.datagrams += 1,
            Link::Gcs => self.stats.gcs_datagrams += 1,
        }
        self.world_repeat_sent = false;
        for frame in wire::frames(datagram) {
            match frame {
                Ok(incoming) => {
                    self.stats.frames += 1;
                    self.dispatch(link, from, incoming, now, out);
                }
                Err(e) => {
                    self.stats.count_frame_error(e);
                    tracing::debug!(%from, ?link, error = ?e, "frame skipped");
                    if let FrameError::MavlinkV1 {
                        controls_from: Some(system_id),
                    } = e
                    {
                        let i = self.vehicle_index(system_id).unwrap_or(0);
                        let refusal = Refusal::MavlinkV1 { system_id };
                        self.refuse(link, from, i, refusal, now, out);
                    }
                }
            }
        }
        if self.world.is_some() {
            self.end_world_datagram(link, from, now, out);
        }
    }

    fn dispatch(
        &mut self,
        link: Link,
        from: SocketAddr,
        incoming: Incoming,
        now: Instant,
        out: &mut Vec<u8>,
    ) {
        let peer = (link == Link::Controller).then(|| self.peer_index(from, now));
        if self.world.is_some() {
            return self.world_dispatch(link, from, incoming, peer, now, out);
        }
        let Incoming { header, message } = incoming;
        match (&message, peer) {
            (MavMessage::HIL_ACTUATOR_CONTROLS(c), Some(p)) => {
                self.on_controls(header, c, from, p, now, out)
            }
            (MavMessage::HIL_ACTUATOR_CONTROLS(_), None) => {
                let i = self.vehicle_index(header.system_id).unwrap_or(0);
                self.refuse(link, from, i, Refusal::GcsLink, now, out);
            }
            (MavMessage::COMMAND_LONG(c), _) => self.on_command(link, header, c, peer, out),
            (MavMessage::PARAM_REQUEST_LIST(m), _) => {
                let t = m.target_system;
                self.on_param_request_list(link, t, out)
            }
            (MavMessage::PARAM_REQUEST_READ(m), _) => {
                self.on_param_request_read(link, header, m, out)
            }
            (MavMessage::PARAM_SET(m), _) => self.on_param_set(link, header, m, out),
            (MavMessage::HEARTBEAT(_), _) => {}
            _ => {
                self.stats.ignored_messages += 1;
                tracing::debug!(%from, ?link, message = message_name(&message), "message ignored");
            }
        }
    }

    /// Appends vehicle `i`'s step (or reset) to the recording, if one is made; `reply`: the
    /// frames already encoded for it (see [`crate::record::Recorder::step`]).
    pub(crate) fn record(&mut self, i: usize, reply: &[u8]) {
        if let Some(r) = &mut self.recorder {
            r.step(&mut self.vehicles[i], &self.options.home, reply);
        }
    }

    /// HIL_STATE_QUATERNION and the task frame of vehicle `i`, as `peer` wants them.
    fn push_vehicle_reply(&mut self, i: usize, peer: usize, out: &mut Vec<u8>) {
        let Peer { state, frame, .. } = self.peers[peer];
        if state {
            let m = telemetry::hil_state_quaternion(&self.vehicles[i], &self.options.home);
            self.push(Link::Controller, out, i, &m);
        }
        if frame {
            self.push_frame(i, out);
        }
    }

    fn push_frame(&mut self, i: usize, out: &mut Vec<u8>) {
        let v = &mut self.vehicles[i];
        let (name, time, system_id) = (v.kind.frame_name(), v.clock_us, v.system_id);
        let values = v.frame();
        for m in crate::task_frame::messages(name, time, values) {
            self.controller_encoder.push(out, system_id, &m);
        }
    }

    // ---- ground station ----

    /// The vehicles stream set `s` speaks for: all with one set, else vehicle `s`.
    fn stream_systems(&self, s: usize) -> std::ops::Range<usize> {
        if self.gcs_streams.len() == 1 {
            0..self.system_count()
        } else {
            s..s + 1
        }
    }

    /// Appends the ground-station telemetry due at `now`; returns when the next is due.
    pub fn gcs_tick(&mut self, now: Instant, out: &mut Vec<u8>) -> Instant {
        for s in 0..self.gcs_streams.len() {
            let due = self.gcs_streams[s].due(now);
            for message_id in due {
                for i in self.stream_systems(s) {
                    if let Some(messages) = self.message(i, message_id) {
                        for m in messages {
                            self.push(Link::Gcs, out, i, &m);
                        }
                    }
                }
            }
        }
        (self.gcs_streams.iter().map(GcsStreams::next_due))
            .min()
            .unwrap_or_else(|| now + Duration::from_secs(1))
    }
}

/// The message's name for logs.
fn message_name(m: &MavMessage) -> &'static str {
    use mavlink::Message;
    m.message_name()
}
