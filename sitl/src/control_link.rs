//! The control link of the PX4 and ArduPilot modes (`--control HOST:PORT`): a MAVLink UDP
//! endpoint beside the autopilot's own link that takes MAV_CMD_INJECT_FAILURE addressed to
//! the vehicle (system id 1, or 0 = all) and answers COMMAND_ACK + STATUSTEXT, as the lockstep
//! task link does ([`crate::commands::inject_outcome`]); every fault that fires or clears is
//! sent as a STATUSTEXT to the peers that spoke. The session polls it without blocking.

use crate::telemetry;
use crate::wire::{self, Encoder};
use flyloop_core::ParamError;
use mavlink::dialects::common::{
    COMMAND_ACK_DATA, COMMAND_LONG_DATA, MavCmd, MavMessage, MavResult, MavSeverity,
};
use std::io;
use std::net::{SocketAddr, UdpSocket};

/// System id of the vehicle an autopilot session flies.
pub const SYSTEM_ID: u8 = 1;

/// Peers kept for the STATUSTEXT of faults that fire (the latest that spoke).
const MAX_PEERS: usize = 8;

/// The control socket and the peers that spoke on it.
#[derive(Debug)]
pub struct ControlLink {
    socket: UdpSocket,
    peers: Vec<SocketAddr>,
    encoder: Encoder,
    buf: Vec<u8>,
    out: Vec<u8>,
    text_id: u16,
    /// System ids it takes commands for (0 = all of them, always).
    systems: Vec<u8>,
}

impl ControlLink {
    /// The link on `socket` (set non-blocking here).
    pub fn new(socket: UdpSocket) -> io::Result<Self> {
        socket.set_nonblocking(true)?;
        Ok(ControlLink {
            socket,
            peers: Vec::new(),
            encoder: Encoder::default(),
            buf: vec![0; 2048],
            out: Vec::with_capacity(256),
            text_id: 0,
            systems: vec![SYSTEM_ID],
        })
    }

    pub fn local_addr(&self) -> io::Result<SocketAddr> {
        self.socket.local_addr()
    }

    /// Takes commands for the vehicles of `systems` (a fleet's sysids) instead of
    /// [`SYSTEM_ID`].
    pub fn set_systems(&mut self, systems: Vec<u8>) {
        self.systems = systems;
    }

    /// Handles every datagram waiting: `inject` fires PX4's failure code (unit, type,
    /// instance) on the vehicle. Socket errors are logged, never fatal.
    pub fn poll(&mut self, mut inject: impl FnMut(u8, u8, u8) -> Result<String, ParamError>) {
        self.poll_addressed(|_, unit, failure, instance| inject(unit, failure, instance));
    }

    /// [`ControlLink::poll`] for several vehicles: `inject` also gets the command's
    /// target system (one of [`ControlLink::set_systems`]'s, or 0 = all).
    pub fn poll_addressed(
        &mut self,
        mut inject: impl FnMut(u8, u8, u8, u8) -> Result<String, ParamError>,
    ) {
        loop {
            let (n, from) = match self.socket.recv_from(&mut self.buf) {
                Ok(got) => got,
                Err(e) if e.kind() == io::ErrorKind::WouldBlock => return,
                Err(e) if e.kind() == io::ErrorKind::Interrupted => continue,
                Err(e) => {
                    // ICMP port unreachable from a peer gone away, and the like.
                    tracing::debug!(error = %e, "control link: receive failed");
                    return;
                }
            };
            self.remember(from);
            let datagram = self.buf[..n].to_vec();
            for frame in wire::frames(&datagram) {
                let Ok(incoming) = frame else {
                    tracing::debug!(%from, "control link: bad frame skipped");
                    continue;
                };
                if let MavMessage::COMMAND_LONG(c) = &incoming.message {
                    let header = incoming.header;
                    self.command(
                        c,
                        (header.system_id, header.component_id),
                        from,
                        &mut inject,
                    );
                }
            }
        }
    }

    fn remember(&mut self, peer: SocketAddr) {
        if !self.peers.contains(&peer) {
            if self.peers.len() == MAX_PEERS {
                self.peers.remove(0);
            }
            self.peers.push(peer);
        }
    }

    /// A command for the vehicle: INJECT_FAILURE handled, anything else UNSUPPORTED.
    fn command(
        &mut self,
        c: &COMMAND_LONG_DATA,
        sender: (u8, u8),
        from: SocketAddr,
        inject: &mut impl FnMut(u8, u8, u8, u8) -> Result<String, ParamError>,
    ) {
        let target = c.target_system;
        if target != 0 && !self.systems.contains(&target) {
            return;
        }
        let (result, text) = if c.command == MavCmd::MAV_CMD_INJECT_FAILURE {
            let (result, severity, text) =
                crate::commands::inject_outcome(c, |u, f, n| inject(target, u, f, n));
            (result, Some((severity, text)))
        } else {
            (MavResult::MAV_RESULT_UNSUPPORTED, None)
        };
        self.out.clear();
        let ack = MavMessage::COMMAND_ACK(COMMAND_ACK_DATA {
            command: c.command,
            result,
            progress: 0,
            result_param2: 0,
            target_system: sender.0,
            target_component: sender.1,
        });
        self.encoder.push(&mut self.out, SYSTEM_ID, &ack);
        if let Some((severity, text)) = text {
            tracing::warn!(%from, result = ?result, "control link: {text}");
            self.push_text(severity, &text);
        }
        self.send(from);
    }

    fn push_text(&mut self, severity: MavSeverity, text: &str) {
        self.text_id = self.text_id.wrapping_add(1).max(1);
        for m in telemetry::statustext(severity, text, self.text_id) {
            self.encoder.push(&mut self.out, SYSTEM_ID, &m);
        }
    }

    fn send(&mut self, to: SocketAddr) {
        if let Err(e) = self.socket.send_to(&self.out, to) {
            tracing::debug!(%to, error = %e, "control link: send failed");
        }
    }

    /// `text` as a STATUSTEXT to every peer that spoke (a fault fired or cleared).
    pub fn announce(&mut self, severity: MavSeverity, text: &str) {
        self.out.clear();
        self.push_text(severity, text);
        for i in 0..self.peers.len() {
            self.send(self.peers[i]);
        }
    }
}
