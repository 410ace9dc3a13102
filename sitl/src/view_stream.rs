//! The autopilot modes' ground truth for a live view (`--view ADDR`): HIL_STATE_QUATERNION
//! every [`VIEW_INTERVAL_US`] of simulation time, a HEARTBEAT and HOME_POSITION (`--home`)
//! every simulated second,
//! over UDP to `python -m flyloop.view --listen ADDR`, which draws it beside the autopilot's
//! own estimate (docs/view.md). Off unless asked for.
//!
//! In fleet mode every vehicle goes in the same datagrams, each from its autopilot's system
//! id and with its motor commands (SERVO_OUTPUT_RAW); what the fleet says (collisions, an
//! autopilot gone or silent, a fault that fires) goes out at once ([`ViewStream::event`]).

use crate::kinematics::Home;
use crate::telemetry::{self, hil_state_quaternion_of};
use crate::wire::Encoder;
use flyloop_core::vehicle::Vehicle;
use mavlink::dialects::common::*;
use std::io;
use std::net::{SocketAddr, UdpSocket};

/// Simulation time between two states sent, µs (50 Hz).
pub const VIEW_INTERVAL_US: u64 = 20_000;

/// The system id of the single-vehicle modes' truth (the view's vehicle 1).
const TRUTH_SYSTEM: u8 = 1;

/// A datagram is sent once it holds this many bytes (a large fleet's states span several).
const DATAGRAM_BYTES: usize = 8192;

/// A live view's stream.
#[derive(Debug)]
pub struct ViewStream {
    socket: UdpSocket,
    target: SocketAddr,
    home: Home,
    encoder: Encoder,
    out: Vec<u8>,
    next_us: u64,
    next_heartbeat_us: u64,
    /// Whether the states of the current interval carry a HEARTBEAT and HOME_POSITION.
    beat: bool,
}

impl ViewStream {
    /// A socket on a free local port that sends to `target`.
    pub fn new(target: SocketAddr, home: Home) -> io::Result<Self> {
        let local: SocketAddr = if target.is_ipv4() {
            ([0, 0, 0, 0], 0).into()
        } else {
            ([0u16; 8], 0).into()
        };
        let socket = UdpSocket::bind(local)?;
        socket.set_nonblocking(true)?;
        Ok(ViewStream {
            socket,
            target,
            home,
            encoder: Encoder::default(),
            out: Vec::with_capacity(256),
            next_us: 0,
            next_heartbeat_us: 0,
            beat: false,
        })
    }

    /// A new autopilot connection: its clock starts again.
    pub fn connect(&mut self) {
        self.next_us = 0;
        self.next_heartbeat_us = 0;
    }

    /// Sends `vehicle`'s state at `time_us` when one is due (a lost or refused datagram is
    /// not an error: nobody may be watching).
    pub fn send(&mut self, time_us: u64, vehicle: &dyn Vehicle) {
        if self.is_due(time_us) {
            self.push_state(time_us, TRUTH_SYSTEM, vehicle, false);
            self.flush();
        }
    }

    /// Whether the states at `time_us` are due (then the next are one interval later).
    pub fn is_due(&mut self, time_us: u64) -> bool {
        if time_us < self.next_us {
            return false;
        }
        self.next_us = time_us + VIEW_INTERVAL_US;
        self.beat = time_us >= self.next_heartbeat_us;
        if self.beat {
            self.next_heartbeat_us = time_us + 1_000_000;
        }
        true
    }

    /// Queues the state of `vehicle` (from `system_id`) at `time_us`, after a due
    /// [`Self::is_due`]; `motors`: with its motor commands.
    pub fn push_state(&mut self, time_us: u64, system_id: u8, vehicle: &dyn Vehicle, motors: bool) {
        if self.beat {
            let heartbeat = MavMessage::HEARTBEAT(HEARTBEAT_DATA {
                custom_mode: 0,
                mavtype: MavType::MAV_TYPE_QUADROTOR,
                autopilot: MavAutopilot::MAV_AUTOPILOT_GENERIC,
                base_mode: MavModeFlag::empty(),
                system_status: MavState::MAV_STATE_ACTIVE,
                mavlink_version: 3,
            });
            self.encoder.push(&mut self.out, system_id, &heartbeat);
            // Where the truth's local frame is (`--home`): the view places the autopilot's
            // estimate by its origin relative to this.
            let home = telemetry::home_position_of(&self.home, time_us);
            self.encoder.push(&mut self.out, system_id, &home);
        }
        let k = vehicle.kinematics();
        let state = hil_state_quaternion_of(&k, &self.home, time_us);
        self.encoder.push(&mut self.out, system_id, &state);
        if motors {
            let servo = telemetry::servo_output_raw_of(vehicle.actuators().into_iter(), time_us);
            self.encoder.push(&mut self.out, system_id, &servo);
        }
        if self.out.len() >= DATAGRAM_BYTES {
            self.flush();
        }
    }

    /// Sends `messages` (from `system_id`) at once: an event the view marks.
    pub fn event(&mut self, system_id: u8, messages: &[MavMessage]) {
        for m in messages {
            self.encoder.push(&mut self.out, system_id, m);
        }
        self.flush();
    }

    /// Sends what is queued.
    pub fn flush(&mut self) {
        if !self.out.is_empty() {
            let _ = self.socket.send_to(&self.out, self.target);
            self.out.clear();
        }
    }
}
