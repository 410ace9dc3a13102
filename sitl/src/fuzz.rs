//! The body of the cargo-fuzz target `sitl/fuzz` (`datagram`), kept in the crate so that
//! the stable build compiles it and a normal test runs it on fixed inputs.
//!
//! The promise it checks: any bytes, on either link, in lockstep or real time, never panic
//! the handler, and a valid step that follows (from another controller) is still answered.

use crate::sim::{Link, Mode, Sim, SimOptions};
use crate::wire::{Encoder, frames};
use flyloop_core::tasks::registry::TaskKind;
use mavlink::dialects::common::{HIL_ACTUATOR_CONTROLS_DATA, HilActuatorControlsFlags, MavMessage};
use std::net::SocketAddr;
use std::time::{Duration, Instant};

/// How long (simulated wall time) real time may take to stream the answer to a step; below
/// the peer timeout, so the controller is still live.
const REALTIME_PATIENCE: Duration = Duration::from_secs(4);

/// Feeds `data` to a fresh two-vehicle simulation: the first byte picks the task, the mode
/// and the link, the rest is one datagram. Panics when the handler panics or when a valid
/// step of vehicle 1 that follows is not answered.
pub fn datagram(data: &[u8]) {
    let Some((&selector, datagram)) = data.split_first() else {
        return;
    };
    let task = match selector % 3 {
        0 => TaskKind::Hover,
        1 => TaskKind::Waypoints,
        _ => TaskKind::Landing,
    };
    let mut options = SimOptions::new(task);
    options.vehicles = 2;
    options.mode = if selector & 0x80 == 0 {
        Mode::Lockstep
    } else {
        Mode::Realtime
    };
    let now = Instant::now();
    let Ok(mut sim) = Sim::new(options, now) else {
        return;
    };
    let link = if selector & 0x40 == 0 {
        Link::Controller
    } else {
        Link::Gcs
    };
    let fuzzer = SocketAddr::from(([127, 0, 0, 1], 9));
    let mut out = Vec::new();
    sim.handle(link, fuzzer, datagram, now, &mut out);
    sim.realtime_tick(now);
    out.clear();
    sim.gcs_tick(now, &mut out);

    let controller = SocketAddr::from(([127, 0, 0, 1], 10));
    out.clear();
    sim.handle(Link::Controller, controller, &valid_step(), now, &mut out);
    let answered = match sim.options.mode {
        Mode::Lockstep => answers_vehicle_1(&out),
        Mode::Realtime => {
            let mut answered = false;
            let mut t = now;
            while !answered && t < now + REALTIME_PATIENCE {
                t += Duration::from_millis(1);
                sim.realtime_tick(t);
                answered = sim
                    .stream
                    .iter()
                    .any(|(addr, bytes)| *addr == controller && answers_vehicle_1(bytes));
            }
            answered
        }
    };
    assert!(
        answered,
        "a valid step after {datagram:02x?} was not answered"
    );
}

/// HIL_ACTUATOR_CONTROLS for vehicle 1, hover-ish, with the LOCKSTEP flag.
fn valid_step() -> Vec<u8> {
    let mut controls = [0.0; 16];
    controls[..4].copy_from_slice(&[0.5; 4]);
    let m = MavMessage::HIL_ACTUATOR_CONTROLS(HIL_ACTUATOR_CONTROLS_DATA {
        controls,
        flags: HilActuatorControlsFlags::HIL_ACTUATOR_CONTROLS_FLAGS_LOCKSTEP,
        ..Default::default()
    });
    let mut out = Vec::new();
    Encoder::default().push(&mut out, 1, &m);
    out
}

/// Whether `bytes` hold a state message (not just text) from vehicle 1.
fn answers_vehicle_1(bytes: &[u8]) -> bool {
    frames(bytes).any(|f| {
        f.is_ok_and(|f| f.header.system_id == 1 && !matches!(f.message, MavMessage::STATUSTEXT(_)))
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Fixed inputs for every selector class (task × mode × link): empty, garbage, a
    /// truncated frame, a frame with a bad checksum, a valid step of another vehicle.
    #[test]
    fn every_selector_survives_garbage_and_still_answers_a_step() {
        let step = valid_step();
        let mut other = Vec::new();
        let m = MavMessage::HIL_ACTUATOR_CONTROLS(HIL_ACTUATOR_CONTROLS_DATA {
            controls: [f32::NAN; 16],
            flags: HilActuatorControlsFlags::HIL_ACTUATOR_CONTROLS_FLAGS_LOCKSTEP,
            ..Default::default()
        });
        Encoder::default().push(&mut other, 2, &m);
        let mut bad_crc = step.clone();
        let last = bad_crc.len() - 1;
        bad_crc[last] ^= 0xFF;
        let payloads: [&[u8]; 6] = [
            b"",
            b"\xfd\xff\x00\x00\x00\x01\x01\x5d\x00\x00garbage",
            &step[..step.len() / 2],
            &bad_crc,
            &other,
            &[0xFE, 9, 0, 1, 1, 0, 1, 2, 3],
        ];
        for selector in [0u8, 1, 2, 0x40, 0x41, 0x80, 0x81, 0x82, 0xC0, 0xC2] {
            for payload in payloads {
                let mut data = vec![selector];
                data.extend_from_slice(payload);
                datagram(&data);
            }
        }
    }
}
