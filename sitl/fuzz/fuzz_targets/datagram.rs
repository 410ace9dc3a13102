//! Any bytes, on either link, in lockstep or real time: the handler must not panic, and a
//! valid step that follows must still be answered.
#![no_main]

use flyloop_sitl::model::TaskKind;
use flyloop_sitl::sim::{Link, Mode, Sim, SimOptions};
use libfuzzer_sys::fuzz_target;
use std::time::Instant;

fuzz_target!(|data: &[u8]| {
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
    let peer = "127.0.0.1:9".parse().expect("a literal address");
    let mut out = Vec::new();
    sim.handle(link, peer, datagram, now, &mut out);
    sim.realtime_tick(now);
    out.clear();
    sim.gcs_tick(now, &mut out);
});
