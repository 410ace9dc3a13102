//! The controller link of a multi-agent world (protocol §14): HIL_ACTUATOR_CONTROLS from
//! each vehicle's system id gathered until every vehicle's command of the step is in, then
//! one world step answered with every vehicle's state and task frame; the reset of the whole
//! world; a datagram that leaves a step waiting answered with a STATUSTEXT naming the
//! vehicles it waits for.

use super::controls::{StepName, classify_step};
use super::refusal::Refusal;
use super::world_task::Gathered;
use super::{Link, Peer, RESET_COMMAND, Sim};
use crate::commands::{ResetRequest, reset_request};
use crate::telemetry;
use crate::wire::Incoming;
use flyloop_core::tasks::multi::ACTION_SIZE;
use flyloop_core::tasks::registry::ControlError;
use mavlink::MavHeader;
use mavlink::dialects::common::{
    COMMAND_LONG_DATA, HIL_ACTUATOR_CONTROLS_DATA, HilActuatorControlsFlags, MavCmd, MavMessage,
    MavResult, MavSeverity,
};
use std::net::SocketAddr;
use std::time::Instant;

impl Sim {
    /// One frame of a datagram, in world mode.
    pub(super) fn world_dispatch(
        &mut self,
        link: Link,
        from: SocketAddr,
        incoming: Incoming,
        peer: Option<usize>,
        now: Instant,
        out: &mut Vec<u8>,
    ) {
        let Incoming { header, message } = incoming;
        match (&message, peer) {
            (MavMessage::HIL_ACTUATOR_CONTROLS(c), Some(p)) => {
                self.on_world_controls(header, c, from, p, now, out)
            }
            (MavMessage::HIL_ACTUATOR_CONTROLS(_), None) => {
                self.refuse(link, from, 0, Refusal::GcsLink, now, out);
            }
            (MavMessage::COMMAND_LONG(c), _) => self.on_world_command(link, header, c, peer, out),
            (MavMessage::PARAM_REQUEST_LIST(m), _) => {
                self.on_param_request_list(link, m.target_system, out)
            }
            (MavMessage::PARAM_REQUEST_READ(m), _) => {
                self.on_param_request_read(link, header, m, out)
            }
            (MavMessage::PARAM_SET(m), _) => self.on_param_set(link, header, m, out),
            (MavMessage::HEARTBEAT(_), _) => {}
            _ => {
                self.stats.ignored_messages += 1;
                tracing::debug!(%from, ?link, "message ignored by the world");
            }
        }
    }

    fn on_world_controls(
        &mut self,
        header: MavHeader,
        c: &HIL_ACTUATOR_CONTROLS_DATA,
        from: SocketAddr,
        peer: usize,
        now: Instant,
        out: &mut Vec<u8>,
    ) {
        let Some(w) = self.world.as_mut() else { return };
        let n = w.num_agents();
        let system_id = header.system_id;
        let Some(i) = usize::from(system_id).checked_sub(1).filter(|&i| i < n) else {
            let refusal = Refusal::UnknownVehicle {
                system_id,
                vehicles: n,
            };
            return self.refuse(Link::Controller, from, 0, refusal, now, out);
        };
        let lockstep = HilActuatorControlsFlags::HIL_ACTUATOR_CONTROLS_FLAGS_LOCKSTEP;
        if !c.flags.contains(lockstep) {
            let refusal = Refusal::NotLockstep {
                flags: c.flags.bits(),
            };
            return self.refuse(Link::Controller, from, i, refusal, now, out);
        }
        let cached = w.last_reply.is_some();
        match classify_step(w.last_step, cached, w.clock_us, c.time_usec) {
            StepName::New => {}
            StepName::Repeat => {
                // A re-sent step datagram repeats every vehicle's command: one reply.
                self.stats.repeated_steps += 1;
                if !self.world_repeat_sent {
                    self.world_repeat_sent = true;
                    out.extend_from_slice(w.last_reply.as_deref().unwrap_or_default());
                }
                return;
            }
            StepName::Late(refusal) => {
                return self.refuse(Link::Controller, from, i, refusal, now, out);
            }
        }
        // Every command of a step names it alike: one naming another step while this one is
        // gathered would be flown in the wrong step (or step this one under a wrong name).
        if let Some(gathering) = w
            .gathering()
            .filter(|&g| c.time_usec != 0 && c.time_usec != g)
        {
            let refusal = Refusal::OtherStep {
                step: c.time_usec,
                gathering,
            };
            return self.refuse(Link::Controller, from, i, refusal, now, out);
        }
        let used = &c.controls[..ACTION_SIZE];
        if let Some(channel) = used.iter().position(|x| !x.is_finite()) {
            let e = ControlError::NotFinite {
                channel,
                value: used[channel],
            };
            return self.refuse(Link::Controller, from, i, Refusal::BadValue(e), now, out);
        }
        if w.gather(i, used, c.time_usec) == Gathered::Complete {
            self.world_step(peer, out);
        }
    }

    /// Steps the world with the gathered commands and answers `peer` with every vehicle's
    /// state and frame, kept for a repeat of the step.
    fn world_step(&mut self, peer: usize, out: &mut Vec<u8>) {
        let Some(w) = self.world.as_mut() else { return };
        let start = Instant::now();
        let stepped = w.step();
        self.stats.physics += start.elapsed();
        let name = match stepped {
            Ok(name) => name,
            Err(e) => {
                // Every command was checked finite, so the core takes the step.
                tracing::warn!(error = %e, "world step refused");
                return;
            }
        };
        self.stats.steps += 1;
        self.announce_world_events();
        let from = out.len();
        self.push_world_reply(peer, out);
        if let Some(w) = self.world.as_mut() {
            w.last_step = (name != 0).then_some(name);
            if name != 0 {
                let cached = w.last_reply.get_or_insert_with(Vec::new);
                cached.clear();
                cached.extend_from_slice(&out[from..]);
            }
        }
    }

    /// Every vehicle's HIL_STATE_QUATERNION and task frame, as `peer` wants them.
    fn push_world_reply(&mut self, peer: usize, out: &mut Vec<u8>) {
        let Peer { state, frame, .. } = self.peers[peer];
        let home = self.options.home;
        let Sim {
            world: Some(w),
            controller_encoder,
            ..
        } = self
        else {
            return;
        };
        let (name, time) = (w.frame_name(), w.clock_us);
        for i in 0..w.num_agents() {
            let system_id = (i + 1) as u8;
            if state {
                let k = w.flight.world().kinematics(i);
                let m = telemetry::hil_state_quaternion_of(&k, &home, time);
                controller_encoder.push(out, system_id, &m);
            }
            if frame {
                for m in crate::task_frame::messages(name, time, w.frame(i)) {
                    controller_encoder.push(out, system_id, &m);
                }
            }
        }
    }

    // MAV_CMD_REQUEST_AUTOPILOT_CAPABILITIES is superseded but ground stations still send it.
    #[allow(deprecated)]
    fn on_world_command(
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
            RESET_COMMAND => self.on_world_reset(link, header, c, peer, out),
            MavCmd::MAV_CMD_SET_MESSAGE_INTERVAL => {
                let result =
                    self.set_message_interval(link, c.param1, c.param2, peer, targets.clone());
                if result != MavResult::MAV_RESULT_ACCEPTED {
                    self.stats.refused_requests += 1;
                }
                if link == Link::Gcs {
                    // Each vehicle's streams are its own: each addressed vehicle answers.
                    self.ack_all(link, out, targets, header, c.command, result);
                } else {
                    self.world_ack(link, out, header, c.command, result);
                }
            }
            MavCmd::MAV_CMD_REQUEST_MESSAGE | MavCmd::MAV_CMD_REQUEST_AUTOPILOT_CAPABILITIES => {
                self.on_message_request(link, header, c, targets, out);
            }
            _ => {
                self.stats.ignored_messages += 1;
                let unsupported = MavResult::MAV_RESULT_UNSUPPORTED;
                self.world_ack(link, out, header, c.command, unsupported);
            }
        }
    }

    /// COMMAND_ACK from system 1 (the world answers commands as one).
    fn world_ack(
        &mut self,
        link: Link,
        out: &mut Vec<u8>,
        header: MavHeader,
        command: MavCmd,
        result: MavResult,
    ) {
        self.ack(link, out, 0, header, command, result);
    }

    /// The reset of the whole world (target_system 0): ACK, then every vehicle's state and
    /// initial frame to the controller peer that asked. A reset addressed to one vehicle, or
    /// whose seed does not parse, is denied with a STATUSTEXT saying why.
    fn on_world_reset(
        &mut self,
        link: Link,
        header: MavHeader,
        c: &COMMAND_LONG_DATA,
        peer: Option<usize>,
        out: &mut Vec<u8>,
    ) {
        let request = if c.target_system != 0 {
            Err(format!(
                "reset refused: the world resets as one, send it to target_system 0, not {}",
                c.target_system
            ))
        } else {
            reset_request(c).map_err(|e| format!("reset refused: {e}"))
        };
        let result = request.and_then(|r| {
            let Some(w) = self.world.as_mut() else {
                return Err("reset refused: no world".to_string());
            };
            let explicit = match r {
                ResetRequest::Seed(seed) => Some(seed),
                ResetRequest::NextSeed => None,
            };
            let seed = w.seed_for(explicit);
            w.reset(seed).map_err(|e| format!("reset refused: {e}"))
        });
        match result {
            Ok(()) => {
                self.stats.resets += 1;
                self.world_ack(link, out, header, c.command, MavResult::MAV_RESULT_ACCEPTED);
                if let Some(p) = peer {
                    self.push_world_reply(p, out);
                }
            }
            Err(why) => {
                self.stats.refused_requests += 1;
                tracing::debug!("{why}");
                self.world_ack(link, out, header, c.command, MavResult::MAV_RESULT_DENIED);
                self.push_text(link, out, 0, MavSeverity::MAV_SEVERITY_WARNING, &why);
            }
        }
    }

    /// After a datagram: a step still waiting for some vehicles' commands is said to the
    /// sender (rate-limited with the refusal texts) and counted.
    pub(super) fn end_world_datagram(
        &mut self,
        link: Link,
        from: SocketAddr,
        now: Instant,
        out: &mut Vec<u8>,
    ) {
        let Some(w) = self.world.as_ref() else { return };
        if link != Link::Controller || !w.incomplete() {
            return;
        }
        let n = w.num_agents();
        let missing = w.missing();
        self.stats.held_steps += 1;
        let list = (missing.iter().map(|k| k.to_string()))
            .collect::<Vec<_>>()
            .join(", ");
        let text = format!(
            "world: step held, waiting for the commands of vehicles {list} ({} of {n} in)",
            n - missing.len()
        );
        tracing::debug!(%from, "{text}");
        let Some(held) = self.refusal_texts.take(from, now) else {
            self.stats.refusal_texts_held += 1;
            return;
        };
        let text = if held > 0 {
            format!("{text} ({held} more refused since, not answered)")
        } else {
            text
        };
        self.stats.refusal_texts += 1;
        self.push_text(link, out, 0, MavSeverity::MAV_SEVERITY_WARNING, &text);
    }
}
