//! Commands (COMMAND_LONG) on either link: reset, message intervals, message requests.

use super::{Link, Mode, RESET_COMMAND, Sim};
use crate::telemetry::{self, Status, id};
use mavlink::MavHeader;
use mavlink::dialects::common::{
    COMMAND_ACK_DATA, COMMAND_LONG_DATA, MavCmd, MavMessage, MavResult, MavSeverity,
};
use std::ops::Range;

impl Sim {
    pub(super) fn ack(
        &mut self,
        link: Link,
        out: &mut Vec<u8>,
        i: usize,
        header: MavHeader,
        command: MavCmd,
        result: MavResult,
    ) {
        let m = MavMessage::COMMAND_ACK(COMMAND_ACK_DATA {
            command,
            result,
            progress: 0,
            result_param2: 0,
            target_system: header.system_id,
            target_component: header.component_id,
        });
        self.push(link, out, i, &m);
    }

    /// Acknowledges `command` from every vehicle in `targets` with `result`.
    pub(super) fn ack_all(
        &mut self,
        link: Link,
        out: &mut Vec<u8>,
        targets: Range<usize>,
        header: MavHeader,
        command: MavCmd,
        result: MavResult,
    ) {
        for i in targets {
            self.ack(link, out, i, header, command, result);
        }
    }

    // MAV_CMD_REQUEST_AUTOPILOT_CAPABILITIES is superseded but ground stations still send it.
    #[allow(deprecated)]
    pub(super) fn on_command(
        &mut self,
        link: Link,
        header: MavHeader,
        c: &COMMAND_LONG_DATA,
        peer: Option<usize>,
        out: &mut Vec<u8>,
    ) {
        let Some(targets) = self.targets(c.target_system) else {
            return;
        };
        match c.command {
            RESET_COMMAND => self.on_reset(link, header, c, targets, peer, out),
            MavCmd::MAV_CMD_SET_MESSAGE_INTERVAL => {
                let result =
                    self.set_message_interval(link, c.param1, c.param2, peer, targets.clone());
                if result != MavResult::MAV_RESULT_ACCEPTED {
                    self.stats.refused_requests += 1;
                }
                self.ack_all(link, out, targets, header, c.command, result);
            }
            MavCmd::MAV_CMD_INJECT_FAILURE => self.on_inject_failure(link, header, c, targets, out),
            MavCmd::MAV_CMD_REQUEST_MESSAGE | MavCmd::MAV_CMD_REQUEST_AUTOPILOT_CAPABILITIES => {
                self.on_message_request(link, header, c, targets, out);
            }
            _ => {
                self.stats.ignored_messages += 1;
                tracing::debug!(command = ?c.command, "unsupported command");
                let unsupported = MavResult::MAV_RESULT_UNSUPPORTED;
                self.ack_all(link, out, targets, header, c.command, unsupported);
            }
        }
    }

    /// The reset command: each vehicle in `targets` reset with its seed, or, for a request
    /// that does not parse, denied on each with the reason as a STATUSTEXT.
    fn on_reset(
        &mut self,
        link: Link,
        header: MavHeader,
        c: &COMMAND_LONG_DATA,
        targets: Range<usize>,
        peer: Option<usize>,
        out: &mut Vec<u8>,
    ) {
        let all = c.target_system == 0;
        match crate::commands::reset_request(c) {
            Ok(request) => {
                for i in targets {
                    let seed = request.seed_for(&self.vehicles[i], all);
                    self.reset_vehicle(link, header, i, seed, peer, out);
                }
            }
            Err(e) => {
                self.stats.refused_requests += 1;
                tracing::debug!(error = %e, "reset refused");
                for i in targets {
                    let why = format!("reset refused: {e}");
                    self.refuse_reset(link, out, i, header, MavResult::MAV_RESULT_DENIED, &why);
                }
            }
        }
    }

    /// MAV_CMD_INJECT_FAILURE (param1 FAILURE_UNIT, param2 FAILURE_TYPE, param3 instance in
    /// PX4's numbering: 1 = first motor, 0 = all): each vehicle in `targets` fires the fault
    /// now, acknowledged ACCEPTED with a STATUSTEXT naming it; a code the catalogue lacks is
    /// UNSUPPORTED, a parameter that is no code DENIED, each with a STATUSTEXT naming the field.
    fn on_inject_failure(
        &mut self,
        link: Link,
        header: MavHeader,
        c: &COMMAND_LONG_DATA,
        targets: Range<usize>,
        out: &mut Vec<u8>,
    ) {
        for i in targets {
            let task = &mut self.vehicles[i].task;
            let (result, severity, text) =
                crate::commands::inject_outcome(c, |u, f, n| task.inject_px4(u, f, n));
            if result != MavResult::MAV_RESULT_ACCEPTED {
                self.stats.refused_requests += 1;
            }
            self.ack(link, out, i, header, c.command, result);
            self.push_text(link, out, i, severity, &text);
        }
    }

    /// REQUEST_MESSAGE (or the older REQUEST_AUTOPILOT_CAPABILITIES): each vehicle in
    /// `targets` acknowledges, then sends the message if it has it.
    pub(super) fn on_message_request(
        &mut self,
        link: Link,
        header: MavHeader,
        c: &COMMAND_LONG_DATA,
        targets: Range<usize>,
        out: &mut Vec<u8>,
    ) {
        let message_id = if c.command == MavCmd::MAV_CMD_REQUEST_MESSAGE {
            crate::commands::message_id(c.param1)
        } else {
            Some(id::AUTOPILOT_VERSION)
        };
        for i in targets {
            let reply = message_id.and_then(|m| self.message(i, m));
            let result = if reply.is_some() {
                MavResult::MAV_RESULT_ACCEPTED
            } else {
                self.stats.refused_requests += 1;
                MavResult::MAV_RESULT_UNSUPPORTED
            };
            self.ack(link, out, i, header, c.command, result);
            for m in reply.into_iter().flatten() {
                self.push(link, out, i, &m);
            }
        }
    }

    /// Resets vehicle `i` with `seed` and acknowledges it; the peer that asked (controller
    /// link) gets the new state as a step's reply carries it.
    fn reset_vehicle(
        &mut self,
        link: Link,
        header: MavHeader,
        i: usize,
        seed: u64,
        peer: Option<usize>,
        out: &mut Vec<u8>,
    ) {
        match self.vehicles[i].reset(seed) {
            Ok(()) => {
                self.stats.resets += 1;
                self.runtime[i].running = false;
                self.runtime[i].failsafe = false;
                self.record(i, &[]);
                let accepted = MavResult::MAV_RESULT_ACCEPTED;
                self.ack(link, out, i, header, RESET_COMMAND, accepted);
                if let Some(p) = peer {
                    self.push_vehicle_reply(i, p, out);
                }
            }
            Err(e) => {
                self.stats.refused_requests += 1;
                let why = format!("reset failed: {e}");
                self.refuse_reset(link, out, i, header, MavResult::MAV_RESULT_FAILED, &why);
            }
        }
    }

    /// A reset vehicle `i` did not do: acknowledged with `result`, and `why` as an error text.
    fn refuse_reset(
        &mut self,
        link: Link,
        out: &mut Vec<u8>,
        i: usize,
        header: MavHeader,
        result: MavResult,
        why: &str,
    ) {
        self.ack(link, out, i, header, RESET_COMMAND, result);
        self.push_text(link, out, i, MavSeverity::MAV_SEVERITY_ERROR, why);
    }

    /// SET_MESSAGE_INTERVAL: on the controller link it chooses what the sending peer gets
    /// (HIL_STATE_QUATERNION, DEBUG_FLOAT_ARRAY); on the ground-station link it sets a stream
    /// (of every vehicle, or in a world of the `targets` vehicles').
    pub(super) fn set_message_interval(
        &mut self,
        link: Link,
        message: f32,
        interval: f32,
        peer: Option<usize>,
        targets: Range<usize>,
    ) -> MavResult {
        let (Some(message), true) = (crate::commands::message_id(message), interval.is_finite())
        else {
            return MavResult::MAV_RESULT_DENIED;
        };
        match (link, peer) {
            (Link::Controller, Some(p)) => {
                let enabled = interval >= 0.0;
                let default_us = (1e6 / self.options.state_rate_hz.max(1e-3)).round() as u64;
                let p = &mut self.peers[p];
                match message {
                    id::HIL_STATE_QUATERNION => p.state = enabled,
                    id::DEBUG_FLOAT_ARRAY => p.frame = enabled,
                    _ => return MavResult::MAV_RESULT_UNSUPPORTED,
                }
                if interval > 0.0 {
                    p.interval_us = interval as u64;
                } else if interval == 0.0 {
                    p.interval_us = default_us.max(1);
                }
                MavResult::MAV_RESULT_ACCEPTED
            }
            _ => {
                let sets = if self.gcs_streams.len() == 1 {
                    0..1
                } else {
                    targets
                };
                let mut result = MavResult::MAV_RESULT_ACCEPTED;
                for s in sets {
                    result = self.gcs_streams[s].set_interval(message, interval);
                }
                result
            }
        }
    }

    /// The message `message_id` of vehicle `i` (one or more MAVLink messages), if this SITL
    /// sends it.
    pub(super) fn message(&mut self, i: usize, message_id: u32) -> Option<Vec<MavMessage>> {
        if self.world.is_some() {
            return self.world_message(i, message_id);
        }
        let status = self.status(i);
        let home = self.options.home;
        let v = &mut self.vehicles[i];
        Some(match message_id {
            id::HEARTBEAT => vec![telemetry::heartbeat(v, status)],
            id::SYS_STATUS => vec![telemetry::sys_status(v)],
            id::ATTITUDE => vec![telemetry::attitude(v)],
            id::LOCAL_POSITION_NED => vec![telemetry::local_position_ned(v)],
            id::GLOBAL_POSITION_INT => vec![telemetry::global_position_int(v, &home)],
            id::VFR_HUD => vec![telemetry::vfr_hud(v, &home)],
            id::HIL_STATE_QUATERNION => vec![telemetry::hil_state_quaternion(v, &home)],
            id::AUTOPILOT_VERSION => vec![telemetry::autopilot_version(v)],
            id::HOME_POSITION => vec![telemetry::home_position(v, &home)],
            id::SERVO_OUTPUT_RAW => vec![telemetry::servo_output_raw(v)],
            id::WIND_COV => vec![telemetry::wind_cov(v)],
            id::DEBUG_FLOAT_ARRAY => {
                let (name, time) = (v.kind.frame_name(), v.clock_us);
                crate::task_frame::messages(name, time, v.frame()).collect()
            }
            _ => return None,
        })
    }

    pub(super) fn status(&self, i: usize) -> Status {
        let rt = &self.runtime[i];
        match self.options.mode {
            // Armed only while a controller flies it: from its first step after a reset
            // until its episode ends (a SITL nobody steps is not armed).
            Mode::Lockstep => {
                let last = &self.vehicles[i].last;
                if last.step > 0 && !last.terminated && !last.truncated {
                    Status::Active
                } else {
                    Status::Standby
                }
            }
            Mode::Realtime if rt.failsafe => Status::Failsafe,
            Mode::Realtime if rt.running => Status::Active,
            Mode::Realtime => Status::Standby,
        }
    }
}
