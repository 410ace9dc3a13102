//! Fuzz-style test of the datagram handler, in process and deterministic: thousands of
//! malformed datagrams between the steps of a controller; every step is answered exactly as
//! in an undisturbed simulation, nothing panics, and every kind of bad input is counted.
// Test code: a failed unwrap is a failed test.

use flyloop_core::tasks::registry::TaskKind;
use flyloop_sitl::sim::{Link, Sim, SimOptions};
use flyloop_sitl::wire::{Encoder, frames};
use mavlink::dialects::common::{
    HIL_ACTUATOR_CONTROLS_DATA, HilActuatorControlsFlags, MavMessage, PARAM_SET_DATA,
};
use std::net::SocketAddr;
use std::time::Instant;

/// xorshift64*: a small seeded generator, so the test needs no extra crate.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_F491_4F6C_DD1D)
    }
    fn below(&mut self, n: u64) -> u64 {
        self.next() % n
    }
    fn bytes(&mut self, n: usize) -> Vec<u8> {
        (0..n).map(|_| self.next() as u8).collect()
    }
}

fn controls(system_id: u8, values: [f32; 4], enc: &mut Encoder) -> Vec<u8> {
    let mut c = [0.0; 16];
    c[..4].copy_from_slice(&values);
    let m = MavMessage::HIL_ACTUATOR_CONTROLS(HIL_ACTUATOR_CONTROLS_DATA {
        controls: c,
        flags: HilActuatorControlsFlags::HIL_ACTUATOR_CONTROLS_FLAGS_LOCKSTEP,
        ..Default::default()
    });
    let mut out = Vec::new();
    enc.push(&mut out, system_id, &m);
    out
}

fn junk(rng: &mut Rng, enc: &mut Encoder) -> Vec<u8> {
    let good = controls(1, [0.5; 4], enc);
    match rng.below(10) {
        0 => {
            let n = 1 + rng.below(400) as usize;
            rng.bytes(n)
        }
        1 => good[..1 + rng.below(good.len() as u64 - 1) as usize].to_vec(),
        2 => {
            let mut b = good.clone();
            let i = 10 + rng.below(b.len() as u64 - 10) as usize;
            b[i] ^= 1 << rng.below(8);
            b
        }
        3 => {
            let mut b = vec![0xFE, 9, 0, 1, 1, 0];
            b.extend(rng.bytes(11));
            b
        }
        4 => {
            let mut b = good.clone();
            b[7] = 0xDE;
            b[8] = 0xBC;
            b
        }
        5 => controls(1, [0.5, f32::NAN, 0.5, f32::INFINITY], enc),
        6 => controls(7 + rng.below(200) as u8, [0.5; 4], enc),
        7 => {
            // A valid header with a random payload length and garbage after it.
            let mut b = vec![0xFD, rng.below(256) as u8, 0, 0, 0, 1, 1, 93, 0, 0];
            let n = rng.below(300) as usize;
            b.extend(rng.bytes(n));
            b
        }
        8 => {
            // A parameter set with a NaN value: refused, never applied.
            let m = MavMessage::PARAM_SET(PARAM_SET_DATA {
                param_value: f32::NAN,
                target_system: 1,
                target_component: 1,
                param_id: "mass".into(),
                ..Default::default()
            });
            let mut out = Vec::new();
            enc.push(&mut out, 255, &m);
            out
        }
        _ => {
            // Good frames for vehicle 2 followed by a truncated one, in one datagram.
            let mut b = controls(2, [2.0, -3.0, 0.5, 0.5], enc);
            b.extend(&good[..good.len() / 2]);
            b
        }
    }
}

fn sim() -> Sim {
    let mut options = SimOptions::new(TaskKind::Hover);
    options.vehicles = 2;
    options.seed = 17;
    Sim::new(options, Instant::now()).unwrap()
}

/// The messages of a reply, decoded (sequence numbers left out).
pub(crate) fn decoded(bytes: &[u8]) -> Vec<(u8, MavMessage)> {
    frames(bytes)
        .map(|f| {
            let f = f.unwrap();
            (f.header.system_id, f.message)
        })
        .collect()
}

#[test]
fn thousands_of_bad_datagrams_never_change_a_step_reply() {
    let client: SocketAddr = "127.0.0.1:40000".parse().unwrap();
    let fuzzer: SocketAddr = "127.0.0.1:40001".parse().unwrap();
    let now = Instant::now();
    let mut enc = Encoder::default();
    let (mut clean, mut fuzzed) = (sim(), sim());
    let mut rng = Rng(0x9E37_79B9_7F4A_7C15);
    let (mut out_clean, mut out_fuzzed, mut scratch) = (Vec::new(), Vec::new(), Vec::new());
    for k in 0..500 {
        let x = 0.01 * (k % 13) as f32;
        let step = controls(1, [0.5 + x, 0.5, 0.5 - x, 0.5], &mut enc);
        for _ in 0..8 {
            scratch.clear();
            let bad = junk(&mut rng, &mut enc);
            fuzzed.handle(Link::Controller, fuzzer, &bad, now, &mut scratch);
            // Junk that reaches the controller link must never answer for vehicle 1 with state.
            assert!(decoded(&scratch).iter().all(|(s, m)| *s == 2
                || matches!(
                    m,
                    MavMessage::STATUSTEXT(_)
                        | MavMessage::PARAM_ERROR(_)
                        | MavMessage::PARAM_VALUE(_)
                )));
        }
        out_clean.clear();
        out_fuzzed.clear();
        clean.handle(Link::Controller, client, &step, now, &mut out_clean);
        fuzzed.handle(Link::Controller, client, &step, now, &mut out_fuzzed);
        assert_eq!(decoded(&out_clean), decoded(&out_fuzzed), "step {k}");
        assert_eq!(decoded(&out_clean).len(), 2);
    }
    let s = &fuzzed.stats;
    assert_eq!(
        s.steps - clean.stats.steps,
        fuzzed.vehicles[1].last.step,
        "only vehicle 2 also stepped"
    );
    for (name, count) in [
        ("truncated", s.truncated),
        ("bad_crc", s.bad_crc),
        ("mavlink1", s.mavlink1),
        ("unknown_message", s.unknown_message),
        ("garbage", s.garbage),
        ("refused_controls", s.refused_controls),
        ("clamped_controls", s.clamped_controls),
        ("unknown_vehicle", s.unknown_vehicle),
        ("refused_requests", s.refused_requests),
    ] {
        assert!(count > 0, "{name} never counted");
    }
    assert_eq!(
        fuzzed.vehicles[0].config.quadrotor.mass, 1.0,
        "a NaN parameter was never applied"
    );
}

#[test]
fn random_bytes_on_both_links_never_panic() {
    let mut sim = sim();
    let peer: SocketAddr = "127.0.0.1:40002".parse().unwrap();
    let mut rng = Rng(42);
    let mut out = Vec::new();
    let now = Instant::now();
    for i in 0..20_000 {
        let n = rng.below(600) as usize;
        let mut bytes = rng.bytes(n);
        if i % 2 == 0 && !bytes.is_empty() {
            bytes[0] = 0xFD; // a plausible start, so the frame decoder is exercised
        }
        out.clear();
        let link = if i % 3 == 0 {
            Link::Gcs
        } else {
            Link::Controller
        };
        sim.handle(link, peer, &bytes, now, &mut out);
    }
    assert_eq!(sim.stats.datagrams + sim.stats.gcs_datagrams, 20_000);
    assert!(sim.stats.bad_input() >= 20_000 - sim.stats.frames);
}
