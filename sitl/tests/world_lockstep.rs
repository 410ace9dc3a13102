//! A multi-agent world on the lockstep link (protocol §14), driven in process: each step's
//! reply carries the core's own observations and reward bits; junk between the steps (bad
//! frames, refused and partial commands, resets addressed to one vehicle, random bytes)
//! never changes a step's reply and never panics; a reset drops the commands a step held.

use crate::handler_fuzz::decoded;
use flyloop_core::tasks::multi::{MultiFlight, Scenario};
use flyloop_core::tasks::registry::TaskKind;
use flyloop_sitl::commands::seed_params;
use flyloop_sitl::sim::{
    EXTRA_VALUES, Link, Sim, SimOptions, WorldTask, reward_from_pieces, world_config,
};
use flyloop_sitl::wire::Encoder;
use mavlink::dialects::common::{
    COMMAND_LONG_DATA, HIL_ACTUATOR_CONTROLS_DATA, HilActuatorControlsFlags, MavCmd, MavMessage,
    MavResult,
};
use std::net::SocketAddr;
use std::time::Instant;

const AGENTS: u8 = 3;

pub(crate) fn world_sim() -> Sim {
    let config = world_config(AGENTS, &[("wind_enabled".into(), 1.0)], Vec::new()).unwrap();
    let world = WorldTask::new(Scenario::MultiHover, config, 11).unwrap();
    Sim::new_world(SimOptions::new(TaskKind::Hover), world, Instant::now()).unwrap()
}

fn controls(enc: &mut Encoder, system_id: u8, values: [f32; 4], step: u64, flags: bool) -> Vec<u8> {
    let mut c = [0.0; 16];
    c[..4].copy_from_slice(&values);
    let flags = if flags {
        HilActuatorControlsFlags::HIL_ACTUATOR_CONTROLS_FLAGS_LOCKSTEP
    } else {
        HilActuatorControlsFlags::empty()
    };
    let m = MavMessage::HIL_ACTUATOR_CONTROLS(HIL_ACTUATOR_CONTROLS_DATA {
        time_usec: step,
        controls: c,
        flags,
        ..Default::default()
    });
    let mut out = Vec::new();
    enc.push(&mut out, system_id, &m);
    out
}

pub(crate) fn reset(enc: &mut Encoder, target_system: u8, seed: u64) -> Vec<u8> {
    let [param1, param2, param3, param4] = seed_params(seed);
    let m = MavMessage::COMMAND_LONG(COMMAND_LONG_DATA {
        command: MavCmd::MAV_CMD_USER_1,
        target_system,
        target_component: 1,
        param1,
        param2,
        param3,
        param4,
        ..Default::default()
    });
    let mut out = Vec::new();
    enc.push(&mut out, 255, &m);
    out
}

/// Each vehicle's task frame values in a reply, by system id order.
fn frame_values(bytes: &[u8]) -> Vec<Vec<f32>> {
    let mut out: Vec<Vec<f32>> = vec![Vec::new(); usize::from(AGENTS)];
    for (s, m) in decoded(bytes) {
        if let MavMessage::DEBUG_FLOAT_ARRAY(d) = m {
            out[usize::from(s) - 1].extend_from_slice(&d.data);
        }
    }
    out
}

pub(crate) fn step_datagram(enc: &mut Encoder, k: u64) -> Vec<u8> {
    let x = 0.02 * (k % 7) as f32;
    (1..=AGENTS)
        .flat_map(|s| controls(enc, s, [0.55 + x, 0.5, 0.5 - x, 0.52], k * 10_000, true))
        .collect()
}

#[test]
fn each_step_reply_is_the_core_world_stepped_directly() {
    let mut sim = world_sim();
    let client: SocketAddr = "127.0.0.1:41000".parse().unwrap();
    let mut enc = Encoder::default();
    let mut out = Vec::new();
    sim.handle(
        Link::Controller,
        client,
        &reset(&mut enc, 0, 99),
        Instant::now(),
        &mut out,
    );
    let config = world_config(AGENTS, &[("wind_enabled".into(), 1.0)], Vec::new()).unwrap();
    let mut core = MultiFlight::new(Scenario::MultiHover, config).unwrap();
    core.reset(99).unwrap();
    let n_obs = core.observation_size();
    for k in 1..=120 {
        out.clear();
        let datagram = step_datagram(&mut enc, k);
        sim.handle(
            Link::Controller,
            client,
            &datagram,
            Instant::now(),
            &mut out,
        );
        let x = 0.02 * (k % 7) as f32;
        let action: Vec<f64> = [0.55 + x, 0.5, 0.5 - x, 0.52].map(f64::from).repeat(3);
        core.step(&action).unwrap();
        for (i, values) in frame_values(&out).iter().enumerate() {
            let mut obs = vec![0f32; n_obs];
            core.write_observation(i, &mut obs);
            assert_eq!(&values[6..6 + n_obs], &obs[..], "step {k}, agent {i}");
            let n_info = values[5] as usize;
            let extra = &values[6 + n_obs + n_info..6 + n_obs + n_info + EXTRA_VALUES];
            let reward = reward_from_pieces(&extra[1..]);
            assert_eq!(reward.to_bits(), core.outcome(i).reward.to_bits());
            assert_eq!(extra[0], f32::from(u8::from(core.is_active(i))));
        }
        if core.all_done() {
            break;
        }
    }
    assert_eq!(sim.stats.held_steps, 0);
}

#[test]
fn junk_between_steps_never_changes_a_step_reply() {
    let (mut clean, mut fuzzed) = (world_sim(), world_sim());
    let client: SocketAddr = "127.0.0.1:41001".parse().unwrap();
    let fuzzer: SocketAddr = "127.0.0.1:41002".parse().unwrap();
    let mut enc = Encoder::default();
    let now = Instant::now();
    let (mut a, mut b, mut scratch) = (Vec::new(), Vec::new(), Vec::new());
    let mut rng = 0x9E37_79B9_7F4A_7C15u64;
    for k in 1..=200u64 {
        for j in 0..6u64 {
            rng ^= rng << 13;
            rng ^= rng >> 7;
            rng ^= rng << 17;
            let junk = match (k + j) % 6 {
                0 => controls(&mut enc, 2, [f32::NAN, 0.5, 0.5, 0.5], 0, true),
                1 => controls(&mut enc, 9, [0.5; 4], 0, true),
                2 => controls(&mut enc, 1, [0.5; 4], 0, false),
                3 => reset(&mut enc, 2, 5),
                // A partial step: replaced by the client's own command for vehicle 2.
                4 => controls(&mut enc, 2, [0.9; 4], k * 10_000, true),
                _ => (0..(rng % 300) as usize)
                    .map(|i| (rng >> (i % 56)) as u8)
                    .collect(),
            };
            scratch.clear();
            fuzzed.handle(Link::Controller, fuzzer, &junk, now, &mut scratch);
            let frames_out = decoded(&scratch)
                .into_iter()
                .filter(|(_, m)| matches!(m, MavMessage::DEBUG_FLOAT_ARRAY(_)))
                .count();
            assert_eq!(frames_out, 0, "junk never steps the world");
        }
        let datagram = step_datagram(&mut enc, k);
        a.clear();
        b.clear();
        clean.handle(Link::Controller, client, &datagram, now, &mut a);
        fuzzed.handle(Link::Controller, client, &datagram, now, &mut b);
        assert_eq!(decoded(&a), decoded(&b), "step {k}");
    }
    let s = &fuzzed.stats;
    assert_eq!(s.steps, clean.stats.steps);
    for (name, count) in [
        ("refused_controls", s.refused_controls),
        ("unknown_vehicle", s.unknown_vehicle),
        ("unflagged_controls", s.unflagged_controls),
        ("refused_requests", s.refused_requests),
        ("held_steps", s.held_steps),
    ] {
        assert!(count > 0, "{name} never counted");
    }
}

#[test]
fn a_reset_drops_the_commands_a_step_held() {
    let mut sim = world_sim();
    let client: SocketAddr = "127.0.0.1:41003".parse().unwrap();
    let mut enc = Encoder::default();
    let now = Instant::now();
    let mut out = Vec::new();
    let first_two: Vec<u8> = (1..=2)
        .flat_map(|s| controls(&mut enc, s, [0.5; 4], 10_000, true))
        .collect();
    sim.handle(Link::Controller, client, &first_two, now, &mut out);
    assert_eq!(sim.stats.held_steps, 1);
    out.clear();
    sim.handle(
        Link::Controller,
        client,
        &reset(&mut enc, 0, 3),
        now,
        &mut out,
    );
    let acks: Vec<_> = decoded(&out)
        .into_iter()
        .filter_map(|(_, m)| match m {
            MavMessage::COMMAND_ACK(a) => Some(a.result),
            _ => None,
        })
        .collect();
    assert_eq!(acks, vec![MavResult::MAV_RESULT_ACCEPTED]);
    out.clear();
    let third = controls(&mut enc, 3, [0.5; 4], 10_000, true);
    sim.handle(Link::Controller, client, &third, now, &mut out);
    assert_eq!(sim.stats.steps, 0, "the held commands went with the reset");
    assert_eq!(sim.stats.held_steps, 2);
}

#[test]
fn a_command_naming_another_step_than_the_one_gathered_is_refused() {
    let mut sim = world_sim();
    let client: SocketAddr = "127.0.0.1:41004".parse().unwrap();
    let mut enc = Encoder::default();
    let now = Instant::now();
    let mut out = Vec::new();
    let first = controls(&mut enc, 1, [0.5; 4], 10_000, true);
    sim.handle(Link::Controller, client, &first, now, &mut out);
    out.clear();
    let other = controls(&mut enc, 2, [0.5; 4], 20_000, true);
    sim.handle(Link::Controller, client, &other, now, &mut out);
    let said = crate::refused_controls::said(&out);
    assert!(
        said.iter()
            .any(|(s, t)| *s == 2
                && t.contains("time_usec 20000 is not the step being gathered, 10000")),
        "{said:?}"
    );
    assert_eq!(sim.stats.stale_controls, 1);
    // The step still waits for vehicles 2 and 3, and steps under its own name.
    let rest: Vec<u8> = (2..=AGENTS)
        .flat_map(|s| controls(&mut enc, s, [0.5; 4], 10_000, true))
        .collect();
    out.clear();
    sim.handle(Link::Controller, client, &rest, now, &mut out);
    assert_eq!(sim.stats.steps, 1);
    assert_eq!(
        frame_values(&out).iter().filter(|v| !v.is_empty()).count(),
        3
    );
    // The refused command was not kept for the next step: vehicle 2 alone steps nothing.
    out.clear();
    sim.handle(Link::Controller, client, &other, now, &mut out);
    assert_eq!(sim.stats.steps, 1);
    assert!(
        sim.world
            .as_ref()
            .is_some_and(|w| w.missing() == vec![1, 3])
    );
}
