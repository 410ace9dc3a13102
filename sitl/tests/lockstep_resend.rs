//! Loss recovery of the lockstep (docs/protocol.md section 3), in process: a command that
//! names its step by `time_usec` and arrives again gets the cached reply, byte for byte,
//! without stepping; a late duplicate of an older step is refused with a STATUSTEXT;
//! unnamed steps (`time_usec` 0) step every time; a reset forgets the cached reply; a
//! client naming each step by the time it starts at gets the bytes of one naming it by the
//! time it ends at.
// Test code: a failed unwrap is a failed test.

use flyloop_core::tasks::registry::TaskKind;
use flyloop_sitl::commands::seed_params;
use flyloop_sitl::sim::{Link, Sim, SimOptions};
use flyloop_sitl::wire::{Encoder, frames};
use mavlink::dialects::common::{
    COMMAND_LONG_DATA, HIL_ACTUATOR_CONTROLS_DATA, HilActuatorControlsFlags, MavCmd, MavMessage,
};
use std::net::SocketAddr;
use std::time::{Duration, Instant};

fn controls(enc: &mut Encoder, system_id: u8, step: u64, m: f32) -> Vec<u8> {
    let mut c = [0.0; 16];
    c[..4].copy_from_slice(&[m, 0.5, 0.5, 0.5]);
    let msg = MavMessage::HIL_ACTUATOR_CONTROLS(HIL_ACTUATOR_CONTROLS_DATA {
        time_usec: step,
        controls: c,
        flags: HilActuatorControlsFlags::HIL_ACTUATOR_CONTROLS_FLAGS_LOCKSTEP,
        ..Default::default()
    });
    let mut out = Vec::new();
    enc.push(&mut out, system_id, &msg);
    out
}

fn reset(enc: &mut Encoder, seed: u64) -> Vec<u8> {
    let [p1, p2, p3, p4] = seed_params(seed);
    let msg = MavMessage::COMMAND_LONG(COMMAND_LONG_DATA {
        param1: p1,
        param2: p2,
        param3: p3,
        param4: p4,
        command: MavCmd::MAV_CMD_USER_1,
        target_system: 1,
        target_component: 1,
        ..Default::default()
    });
    let mut out = Vec::new();
    enc.push(&mut out, 255, &msg);
    out
}

fn sim() -> Sim {
    let mut options = SimOptions::new(TaskKind::Hover);
    options.seed = 5;
    Sim::new(options, Instant::now()).unwrap()
}

fn send(sim: &mut Sim, datagram: &[u8]) -> Vec<u8> {
    send_at(sim, datagram, Instant::now())
}

fn send_at(sim: &mut Sim, datagram: &[u8], now: Instant) -> Vec<u8> {
    let peer: SocketAddr = "127.0.0.1:40100".parse().unwrap();
    let mut out = Vec::new();
    sim.handle(Link::Controller, peer, datagram, now, &mut out);
    out
}

/// What a reply says: its STATUSTEXTs (a message's name for anything else).
fn texts(reply: &[u8]) -> Vec<String> {
    let said = crate::refused_controls::said(reply);
    said.into_iter().map(|(_, text)| text).collect()
}

/// The task frame's values of a reply (None if it holds none).
fn frame(reply: &[u8]) -> Option<(u64, Vec<f32>)> {
    frames(reply).find_map(|f| match f.unwrap().message {
        MavMessage::DEBUG_FLOAT_ARRAY(d) => Some((d.time_usec, d.data.to_vec())),
        _ => None,
    })
}

#[test]
fn a_repeated_step_gets_the_cached_reply_and_does_not_step() {
    let mut enc = Encoder::default();
    let (mut lossy, mut clean) = (sim(), sim());
    let dt_us = lossy.vehicles[0].dt_us();
    assert_eq!(dt_us, 10_000);
    // Each late duplicate one second after the last, so none is held back by the rate limit.
    let t0 = Instant::now();
    for k in 1..=50u64 {
        let now = t0 + Duration::from_secs(k);
        let m = 0.5 + 0.002 * (k % 7) as f32;
        let command = controls(&mut enc, 1, k * dt_us, m);
        let expected = send_at(&mut clean, &command, now);
        let first = send_at(&mut lossy, &command, now);
        assert_eq!(frame(&first), frame(&expected), "step {k}");
        // The reply "was lost": the same command again, twice.
        for _ in 0..2 {
            let again = send_at(&mut lossy, &command, now);
            assert_eq!(again, first, "step {k}: the cached bytes are sent again");
        }
        assert_eq!(lossy.vehicles[0].clock_us, k * dt_us);
        // A late duplicate of the step before: refused with a STATUSTEXT, nothing changes.
        if k > 1 {
            let late = controls(&mut enc, 1, (k - 1) * dt_us, m);
            let said = texts(&send_at(&mut lossy, &late, now));
            let clock = k * dt_us;
            let why = format!(
                "vehicle 1: time_usec {} is older than the clock, {clock} us (a late duplicate): \
                 step refused",
                (k - 1) * dt_us
            );
            assert_eq!(said, vec![why], "step {k}");
            assert_eq!(lossy.vehicles[0].clock_us, clock);
        }
    }
    assert_eq!(lossy.stats.steps, 50);
    assert_eq!(lossy.stats.repeated_steps, 100);
    assert_eq!(lossy.stats.stale_controls, 49);
    assert_eq!(lossy.stats.refusal_texts, 49);
    assert_eq!(lossy.vehicles[0].last.step, clean.vehicles[0].last.step);
    assert_eq!(
        frame(&send(&mut lossy, &reset(&mut enc, 9))).unwrap().0,
        500_000
    );
}

#[test]
fn unnamed_steps_always_step_and_a_reset_forgets_the_cached_step() {
    let mut enc = Encoder::default();
    let mut sim = sim();
    let unnamed = controls(&mut enc, 1, 0, 0.5);
    let a = frame(&send(&mut sim, &unnamed)).unwrap();
    let b = frame(&send(&mut sim, &unnamed)).unwrap();
    assert_eq!(
        (a.0, b.0),
        (10_000, 20_000),
        "time_usec 0: a new step each time"
    );
    let named = controls(&mut enc, 1, 30_000, 0.5);
    assert_eq!(frame(&send(&mut sim, &named)).unwrap().0, 30_000);
    let after_reset = frame(&send(&mut sim, &reset(&mut enc, 3))).unwrap();
    assert_eq!(
        (after_reset.0, after_reset.1[3]),
        (30_000, 0.0),
        "reset: step 0"
    );
    // The step before the reset, repeated after it: stale, not a step of the new episode.
    assert_eq!(
        texts(&send(&mut sim, &named)),
        [
            "vehicle 1: time_usec 30000 names the last step before a reset (a late duplicate): \
          step refused"
        ]
    );
    assert_eq!(sim.vehicles[0].last.step, 0);
    assert_eq!(sim.stats.stale_controls, 1);
    // A value beyond the next step's end still names the next step (one control period).
    let ahead = controls(&mut enc, 1, 99_000, 0.5);
    assert_eq!(frame(&send(&mut sim, &ahead)).unwrap().0, 40_000);
    let cached = sim.vehicles[0].last_reply.clone().unwrap();
    assert_eq!(send(&mut sim, &ahead), cached);
}

#[test]
fn a_client_naming_steps_by_their_start_gets_the_bytes_of_one_naming_them_by_their_end() {
    let mut enc_start = Encoder::default();
    let mut enc_end = Encoder::default();
    let (mut by_start, mut by_end) = (sim(), sim());
    let dt_us = by_start.vehicles[0].dt_us();
    let t0 = Instant::now();
    // The clock each client last heard of (a step's or reset's reply time_usec).
    let (mut heard_start, mut heard_end) = (0u64, 0u64);
    for k in 0..300u64 {
        let now = t0 + Duration::from_millis(k);
        if k == 150 {
            // A reset in the middle: both clients carry on from the reply's clock.
            let a = send_at(&mut by_start, &reset(&mut enc_start, 11), now);
            let b = send_at(&mut by_end, &reset(&mut enc_end, 11), now);
            assert_eq!(a, b);
            heard_start = frame(&a).unwrap().0;
            heard_end = frame(&b).unwrap().0;
        }
        let m = 0.49 + 0.003 * (k % 11) as f32;
        // PX4's convention: the time the step starts at (0 for the first: unnamed).
        let start = controls(&mut enc_start, 1, heard_start, m);
        let end = controls(&mut enc_end, 1, heard_end + dt_us, m);
        let a = send_at(&mut by_start, &start, now);
        let b = send_at(&mut by_end, &end, now);
        assert_eq!(a, b, "step {k}: the same bytes");
        heard_start = frame(&a).unwrap().0;
        heard_end = frame(&b).unwrap().0;
        assert_eq!(heard_start, (k + 1) * dt_us, "step {k}: stepped once");
        // A start-named step (not the unnamed first) repeats from the cache.
        if k > 0 {
            assert_eq!(send_at(&mut by_start, &start, now), a, "step {k}: repeat");
        }
    }
    assert_eq!(by_start.stats.steps, 300);
    assert_eq!(by_start.stats.repeated_steps, 299);
    assert_eq!(by_start.stats.stale_controls, 0);
    assert_eq!(by_end.stats.stale_controls, 0);
}
