//! The autopilot modes' ground truth for a live view (`--view ADDR`): HIL_STATE_QUATERNION
//! every [`VIEW_INTERVAL_US`] of simulation time, a HEARTBEAT and HOME_POSITION (`--home`)
//! every simulated second,
//! over UDP to `python -m flyloop.view --listen ADDR`, which draws it beside the autopilot's
//! own estimate (docs/view.md). Off unless asked for.

use crate::kinematics::Home;
use crate::telemetry::hil_state_quaternion_of;
use crate::wire::Encoder;
use flyloop_core::vehicle::Vehicle;
use mavlink::dialects::common::*;
use std::io;
use std::net::{SocketAddr, UdpSocket};

/// Simulation time between two states sent, µs (50 Hz).
pub const VIEW_INTERVAL_US: u64 = 20_000;

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
        if time_us < self.next_us {
            return;
        }
        self.next_us = time_us + VIEW_INTERVAL_US;
        self.out.clear();
        if time_us >= self.next_heartbeat_us {
            self.next_heartbeat_us = time_us + 1_000_000;
            let heartbeat = MavMessage::HEARTBEAT(HEARTBEAT_DATA {
                custom_mode: 0,
                mavtype: MavType::MAV_TYPE_QUADROTOR,
                autopilot: MavAutopilot::MAV_AUTOPILOT_GENERIC,
                base_mode: MavModeFlag::empty(),
                system_status: MavState::MAV_STATE_ACTIVE,
                mavlink_version: 3,
            });
            self.encoder.push(&mut self.out, 1, &heartbeat);
            // Where the truth's local frame is (`--home`): the view places the autopilot's
            // estimate by its origin relative to this.
            let home = crate::telemetry::home_position_of(&self.home, time_us);
            self.encoder.push(&mut self.out, 1, &home);
        }
        let k = vehicle.kinematics();
        let state = hil_state_quaternion_of(&k, &self.home, time_us);
        self.encoder.push(&mut self.out, 1, &state);
        let _ = self.socket.send_to(&self.out, self.target);
    }
}
