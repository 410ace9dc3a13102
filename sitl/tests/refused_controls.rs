//! Controls the SITL will not step are never met with silence (docs/protocol.md section 12):
//! each kind is counted and answered with a STATUSTEXT to its sender, at most
//! TEXTS_PER_WINDOW per peer per TEXT_WINDOW; nothing is stepped.

use flyloop_core::tasks::registry::TaskKind;
use flyloop_sitl::sim::{Link, Sim, SimOptions, TEXT_WINDOW, TEXTS_PER_WINDOW};
use flyloop_sitl::wire::{Encoder, frames};
use mavlink::MavHeader;
use mavlink::dialects::common::{HIL_ACTUATOR_CONTROLS_DATA, HilActuatorControlsFlags, MavMessage};
use std::time::{Duration, Instant};

fn controls(enc: &mut Encoder, system_id: u8, step: u64, flags: u64, m: f32) -> Vec<u8> {
    let mut c = [0.0; 16];
    c[..4].copy_from_slice(&[m, 0.5, 0.5, 0.5]);
    let msg = MavMessage::HIL_ACTUATOR_CONTROLS(HIL_ACTUATOR_CONTROLS_DATA {
        time_usec: step,
        controls: c,
        flags: HilActuatorControlsFlags::from_bits_retain(flags),
        ..Default::default()
    });
    let mut out = Vec::new();
    enc.push(&mut out, system_id, &msg);
    out
}

/// Lockstep controls for vehicle `system_id` in a MAVLink 1 frame.
fn mavlink1_controls(system_id: u8) -> Vec<u8> {
    let header = MavHeader {
        system_id,
        component_id: 1,
        sequence: 0,
    };
    let msg = MavMessage::HIL_ACTUATOR_CONTROLS(HIL_ACTUATOR_CONTROLS_DATA {
        controls: [0.5; 16],
        flags: HilActuatorControlsFlags::HIL_ACTUATOR_CONTROLS_FLAGS_LOCKSTEP,
        ..Default::default()
    });
    let mut out = Vec::new();
    mavlink::write_v1_msg(&mut out, header, &msg).unwrap();
    out
}

/// Every message of a reply: (sending system id, STATUSTEXT text with its chunks joined,
/// or the message's name).
pub(crate) fn said(reply: &[u8]) -> Vec<(u8, String)> {
    let mut out: Vec<(u8, String)> = Vec::new();
    for f in frames(reply) {
        let f = f.unwrap();
        match &f.message {
            MavMessage::STATUSTEXT(t) => {
                let bytes = t.text.to_vec();
                let end = bytes.iter().position(|&b| b == 0).unwrap_or(bytes.len());
                let chunk = String::from_utf8_lossy(&bytes[..end]).into_owned();
                match out.last_mut() {
                    Some((_, text)) if t.chunk_seq > 0 => text.push_str(&chunk),
                    _ => out.push((f.header.system_id, chunk)),
                }
            }
            m => out.push((f.header.system_id, mavlink::Message::message_name(m).into())),
        }
    }
    out
}

fn sim(vehicles: u8) -> Sim {
    let mut options = SimOptions::new(TaskKind::Hover);
    options.vehicles = vehicles;
    Sim::new(options, Instant::now()).unwrap()
}

const PEER: &str = "127.0.0.1:40200";

fn send(sim: &mut Sim, link: Link, datagram: &[u8], now: Instant) -> Vec<(u8, String)> {
    let mut out = Vec::new();
    sim.handle(link, PEER.parse().unwrap(), datagram, now, &mut out);
    said(&out)
}

#[test]
fn every_kind_of_refused_controls_gets_a_statustext_and_is_counted() {
    let mut enc = Encoder::default();
    let mut sim = sim(2);
    let t0 = Instant::now();
    let lockstep = 1;
    let step = |k: u64| k * 10_000;
    // Three good steps for vehicle 1, named by their end.
    for k in 1..=3 {
        let reply = send(
            &mut sim,
            Link::Controller,
            &controls(&mut enc, 1, step(k), lockstep, 0.5),
            t0,
        );
        assert_eq!(reply.len(), 2, "state and task frame");
    }
    let cases: [(Vec<u8>, Link, (u8, &str)); 6] = [
        (
            controls(&mut enc, 7, step(4), lockstep, 0.5),
            Link::Controller,
            (
                1,
                "system 7: no such vehicle (system ids 1..2): step refused",
            ),
        ),
        (
            controls(&mut enc, 1, step(4), 0, 0.5),
            Link::Controller,
            (
                1,
                "vehicle 1: controls without the LOCKSTEP flag (flags = 0) in lockstep mode: step refused",
            ),
        ),
        (
            controls(&mut enc, 1, step(4), lockstep, f32::NAN),
            Link::Controller,
            (1, "vehicle 1: controls[0] = NaN: step refused"),
        ),
        (
            controls(&mut enc, 1, step(2), lockstep, 0.5),
            Link::Controller,
            (
                1,
                "vehicle 1: time_usec 20000 is older than the clock, 30000 us (a late duplicate): step refused",
            ),
        ),
        (
            controls(&mut enc, 2, step(1), lockstep, 0.5),
            Link::Gcs,
            (
                2,
                "vehicle 2: controls on the ground-station link are not flown (send them to --listen): step refused",
            ),
        ),
        (
            mavlink1_controls(2),
            Link::Controller,
            (
                2,
                "system 2: controls in MAVLink 1, which this SITL does not read (pymavlink: set MAVLINK20=1): step refused",
            ),
        ),
    ];
    for (k, (datagram, link, (system_id, text))) in cases.iter().enumerate() {
        // A second apart: the rate limit holds none back.
        let now = t0 + Duration::from_secs(k as u64 + 1);
        let reply = send(&mut sim, *link, datagram, now);
        let joined: String = reply.iter().map(|(_, t)| t.as_str()).collect();
        assert_eq!(joined, *text, "case {k}");
        assert!(
            reply.iter().all(|(s, _)| s == system_id),
            "case {k}: {reply:?}"
        );
    }
    let s = &sim.stats;
    assert_eq!(
        (
            s.unknown_vehicle,
            s.unflagged_controls,
            s.refused_controls,
            s.stale_controls,
            s.gcs_controls
        ),
        (1, 1, 1, 1, 1)
    );
    assert_eq!(s.mavlink1, 1);
    assert_eq!((s.refusal_texts, s.refusal_texts_held), (6, 0));
    assert_eq!(
        (s.steps, sim.vehicles[0].clock_us, sim.vehicles[1].clock_us),
        (3, 30_000, 0)
    );
    // The repeat of the last step is no refusal: its cached reply, no step.
    let again = send(
        &mut sim,
        Link::Controller,
        &controls(&mut enc, 1, step(3), lockstep, 0.5),
        t0,
    );
    assert_eq!(again.len(), 2);
    assert_eq!((sim.stats.repeated_steps, sim.stats.steps), (1, 3));
}

#[test]
fn a_flood_of_refused_controls_is_answered_at_the_rate_limit() {
    let mut enc = Encoder::default();
    let mut sim = sim(1);
    let t0 = Instant::now();
    for step in [10_000, 20_000] {
        send(
            &mut sim,
            Link::Controller,
            &controls(&mut enc, 1, step, 1, 0.5),
            t0,
        );
    }
    let late = controls(&mut enc, 1, 10_000, 1, 0.5);
    // 1,000 late duplicates over 2 s (one every 2 ms): 5 texts a second, the first of each
    // new second telling how many went unanswered.
    let mut texts = Vec::new();
    for k in 0..1_000u64 {
        let now = t0 + Duration::from_millis(2 * k);
        texts.extend(
            send(&mut sim, Link::Controller, &late, now)
                .into_iter()
                .map(|(_, t)| t),
        );
    }
    let per_window = TEXTS_PER_WINDOW as usize;
    assert_eq!(TEXT_WINDOW, Duration::from_secs(1));
    assert_eq!(texts.len(), 2 * per_window);
    assert!(
        texts[per_window].ends_with("(495 more refused since, not answered)"),
        "{}",
        texts[per_window]
    );
    let s = &sim.stats;
    assert_eq!(
        (s.stale_controls, s.refusal_texts, s.refusal_texts_held),
        (1_000, 10, 990)
    );
    assert_eq!((s.steps, sim.vehicles[0].clock_us), (2, 20_000));
}
