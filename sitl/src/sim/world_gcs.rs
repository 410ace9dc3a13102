//! What a ground station sees of a multi-agent world: each vehicle is its own MAVLink system
//! (agent i is system i + 1) with the single-vehicle telemetry ([`crate::telemetry`]) built
//! from its state in the world, and the world's events — a collision, a fault that fires or
//! clears — as STATUSTEXT from the vehicles they happen to. Nothing here changes the world:
//! the lockstep replies are the same with or without a ground station.

use super::{Link, Sim};
use crate::telemetry::{self, Status, id, multirotor_mav_type};
use mavlink::dialects::common::{MavMessage, MavSeverity};

impl Sim {
    /// The message `message_id` of the world's vehicle `i` (one or more MAVLink messages), if
    /// this SITL sends it.
    pub(super) fn world_message(&mut self, i: usize, message_id: u32) -> Option<Vec<MavMessage>> {
        let home = self.options.home;
        let w = self.world.as_mut()?;
        if i >= w.num_agents() {
            return None;
        }
        // Armed only while a controller flies it: from the episode's first step until the
        // vehicle's episode ends (as a single vehicle in lockstep).
        let status = if w.episode_step > 0 && !w.flight.is_done(i) {
            Status::Active
        } else {
            Status::Standby
        };
        let time_us = w.clock_us;
        let time_boot_ms = (time_us / 1000) as u32;
        let world = w.flight.world();
        let k = world.kinematics(i);
        let quad = world.vehicle(i);
        let motors = quad.motor_command();
        Some(match message_id {
            id::HEARTBEAT => {
                let mavtype = multirotor_mav_type(quad.frame().rotor_count());
                vec![telemetry::heartbeat_of(mavtype, status)]
            }
            // The quadrotor has no battery model.
            id::SYS_STATUS => vec![telemetry::sys_status_of(None)],
            id::ATTITUDE => vec![telemetry::attitude_of(&k, time_boot_ms)],
            id::LOCAL_POSITION_NED => vec![telemetry::local_position_ned_of(&k, time_boot_ms)],
            id::GLOBAL_POSITION_INT => {
                vec![telemetry::global_position_int_of(&k, &home, time_boot_ms)]
            }
            id::VFR_HUD => {
                let throttle = motors.iter().sum::<f64>() / motors.len().max(1) as f64;
                vec![telemetry::vfr_hud_of(&k, &home, throttle)]
            }
            id::HIL_STATE_QUATERNION => {
                vec![telemetry::hil_state_quaternion_of(&k, &home, time_us)]
            }
            id::AUTOPILOT_VERSION => vec![telemetry::autopilot_version_of((i + 1) as u8)],
            id::HOME_POSITION => vec![telemetry::home_position_of(&home, time_us)],
            id::SERVO_OUTPUT_RAW => {
                vec![telemetry::servo_output_raw_of(
                    motors.iter().copied(),
                    time_us,
                )]
            }
            id::WIND_COV => vec![telemetry::wind_cov_of(&k, time_us)],
            id::DEBUG_FLOAT_ARRAY => {
                let name = w.frame_name();
                crate::task_frame::messages(name, time_us, w.frame(i)).collect()
            }
            _ => return None,
        })
    }

    /// After a world step: each collision that started, from both vehicles (CRITICAL), and
    /// each fault that fired or cleared, from its vehicle (WARNING), logged and sent to the
    /// ground station.
    pub(super) fn announce_world_events(&mut self) {
        let Some(w) = self.world.as_mut() else {
            return;
        };
        let mut texts = Vec::new();
        for c in w.flight.last_collisions() {
            let (a, b) = (c.a + 1, c.b + 1);
            let text = format!(
                "collision of vehicles {a} and {b} at t={:.3} s, closing at {:.2} m/s",
                c.time, c.speed
            );
            tracing::warn!("{text}");
            texts.push((c.a, MavSeverity::MAV_SEVERITY_CRITICAL, text.clone()));
            texts.push((c.b, MavSeverity::MAV_SEVERITY_CRITICAL, text));
        }
        for i in 0..w.num_agents() {
            let events = w.flight.fault_events(i);
            let reported = w.faults_reported[i].min(events.len());
            for e in &events[reported..] {
                let what = if e.fired { "fired" } else { "cleared" };
                let text = format!("fault {what}: {} at {:.3} s", e.label, e.time);
                tracing::warn!(system_id = i + 1, "{text}");
                texts.push((i, MavSeverity::MAV_SEVERITY_WARNING, text));
            }
            w.faults_reported[i] = events.len();
        }
        if texts.is_empty() {
            return;
        }
        let mut gcs = std::mem::take(&mut self.gcs_outbox);
        for (i, severity, text) in texts {
            self.push_text(Link::Gcs, &mut gcs, i, severity, &text);
        }
        self.gcs_outbox = gcs;
    }
}
