//! Real time: the wall clock paces each running vehicle, the last command holds, the
//! failsafe switches the motors off, and state streams to the controller peers.

use super::{Link, MAX_CATCH_UP, PEER_TIMEOUT, Sim};
use crate::pacer::Cadence;
use mavlink::dialects::common::MavSeverity;
use std::net::SocketAddr;
use std::time::{Duration, Instant};

impl Sim {
    pub(super) fn command_arrived(&mut self, i: usize, now: Instant) {
        let rt = &mut self.runtime[i];
        rt.last_command = Some(now);
        if !rt.running {
            rt.running = true;
            rt.cadence = Cadence::starting(now);
        }
        if rt.failsafe {
            rt.failsafe = false;
            let text = format!(
                "vehicle {}: commands back, failsafe cleared",
                self.vehicles[i].system_id
            );
            self.announce(i, MavSeverity::MAV_SEVERITY_NOTICE, &text);
        }
    }

    /// A STATUSTEXT to the ground station, every live controller peer and the recording.
    fn announce(&mut self, i: usize, severity: MavSeverity, text: &str) {
        tracing::info!("{text}");
        if let Some(r) = &mut self.recorder {
            r.line(&self.vehicles[i], severity, text);
        }
        let mut gcs = std::mem::take(&mut self.gcs_outbox);
        self.push_text(Link::Gcs, &mut gcs, i, severity, text);
        self.gcs_outbox = gcs;
        let mut ctl = std::mem::take(&mut self.controller_outbox);
        self.push_text(Link::Controller, &mut ctl, i, severity, text);
        self.controller_outbox = ctl;
    }

    /// Live controller peers (heard within the last few seconds).
    pub fn live_peers(&self, now: Instant) -> Vec<SocketAddr> {
        self.peers
            .iter()
            .filter(|p| now.duration_since(p.last_heard) < PEER_TIMEOUT)
            .map(|p| p.addr)
            .collect()
    }

    /// Real time: steps every running vehicle that is due at `now`, applies the failsafe,
    /// fills [`Sim::stream`]; returns when the next vehicle is due.
    pub fn realtime_tick(&mut self, now: Instant) -> Instant {
        self.stream.clear();
        for i in 0..self.vehicles.len() {
            self.failsafe_check(i, now);
            let dt = Duration::from_micros(self.vehicles[i].dt_us().max(1));
            if !self.runtime[i].running {
                self.runtime[i].cadence = Cadence::starting(now + dt);
                continue;
            }
            let mut steps = 0;
            while steps < MAX_CATCH_UP
                && self.runtime[i].running
                && self.runtime[i].cadence.take(now, dt)
            {
                let start = Instant::now();
                self.vehicles[i].step();
                self.stats.physics += start.elapsed();
                self.stats.steps += 1;
                self.record(i, &[]);
                steps += 1;
                self.stream_step(i, now);
                if self.vehicles[i].last.terminated {
                    self.episode_terminated(i);
                }
            }
            // Too far behind (a stalled machine): skip ahead instead of racing.
            self.runtime[i].cadence.skip_if_behind(now, dt);
        }
        self.runtime
            .iter()
            .map(|r| r.cadence.next())
            .min()
            .unwrap_or(now + Duration::from_millis(10))
    }

    fn failsafe_check(&mut self, i: usize, now: Instant) {
        let rt = self.runtime[i];
        let silent = rt
            .last_command
            .is_some_and(|t| now.duration_since(t) > self.options.failsafe_timeout);
        if rt.running && silent && !rt.failsafe {
            self.runtime[i].failsafe = true;
            self.vehicles[i].motors_off();
            let text = format!(
                "vehicle {}: no command for {:.1} s, motors off (failsafe)",
                self.vehicles[i].system_id,
                self.options.failsafe_timeout.as_secs_f64()
            );
            self.announce(i, MavSeverity::MAV_SEVERITY_CRITICAL, &text);
        }
    }

    fn episode_terminated(&mut self, i: usize) {
        let seed = crate::vehicle::next_seed(self.vehicles[i].seed);
        let system_id = self.vehicles[i].system_id;
        match self.vehicles[i].reset(seed) {
            Ok(()) => {
                self.stats.resets += 1;
                self.record(i, &[]);
                let text = format!(
                    "vehicle {system_id}: episode ended, reset with seed {seed}; waiting for a command"
                );
                self.announce(i, MavSeverity::MAV_SEVERITY_WARNING, &text);
            }
            Err(e) => tracing::error!("vehicle {system_id}: reset failed: {e}"),
        }
        self.runtime[i].running = false;
        self.runtime[i].failsafe = false;
        self.runtime[i].last_command = None;
    }

    /// Streams vehicle `i`'s state to each live peer whose interval boundary was crossed.
    fn stream_step(&mut self, i: usize, now: Instant) {
        let clock = self.vehicles[i].clock_us;
        let dt = self.vehicles[i].dt_us();
        for p in 0..self.peers.len() {
            let peer = self.peers[p];
            if now.duration_since(peer.last_heard) >= PEER_TIMEOUT || !(peer.state || peer.frame) {
                continue;
            }
            let crossed = clock / peer.interval_us != clock.saturating_sub(dt) / peer.interval_us;
            if !crossed {
                continue;
            }
            let slot = match self.stream.iter().position(|(a, _)| *a == peer.addr) {
                Some(s) => s,
                None => {
                    self.stream.push((peer.addr, Vec::new()));
                    self.stream.len() - 1
                }
            };
            let mut buf = std::mem::take(&mut self.stream[slot].1);
            self.push_vehicle_reply(i, p, &mut buf);
            self.stream[slot].1 = buf;
        }
    }
}
