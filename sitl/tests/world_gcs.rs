//! A ground station on a multi-agent world, driven in process: it reads the world (every
//! stream of every vehicle, the parameter list, message requests, a parameter set for the
//! next reset) between the steps, and the controller's step replies stay the same bytes.

use crate::handler_fuzz::decoded;
use crate::world_lockstep::{reset, step_datagram, world_sim};
use flyloop_sitl::sim::Link;
use flyloop_sitl::telemetry::id;
use flyloop_sitl::wire::Encoder;
use mavlink::dialects::common::{
    COMMAND_LONG_DATA, MavCmd, MavMessage, MavParamType, PARAM_REQUEST_LIST_DATA, PARAM_SET_DATA,
};
use mavlink::types::CharArray;
use std::collections::BTreeSet;
use std::net::SocketAddr;
use std::time::{Duration, Instant};

fn request(enc: &mut Encoder, message: MavMessage) -> Vec<u8> {
    let mut out = Vec::new();
    enc.push(&mut out, 255, &message);
    out
}

fn command(target_system: u8, command: MavCmd, param1: f32, param2: f32) -> MavMessage {
    MavMessage::COMMAND_LONG(COMMAND_LONG_DATA {
        command,
        target_system,
        target_component: 1,
        param1,
        param2,
        ..Default::default()
    })
}

#[test]
fn a_ground_station_reading_the_world_never_changes_a_step_reply() {
    let (mut clean, mut watched) = (world_sim(), world_sim());
    let client: SocketAddr = "127.0.0.1:41010".parse().unwrap();
    let gcs: SocketAddr = "127.0.0.1:14550".parse().unwrap();
    let mut enc = Encoder::default();
    let start = Instant::now();
    let (mut a, mut b, mut telemetry) = (Vec::new(), Vec::new(), Vec::new());
    for sim in [&mut clean, &mut watched] {
        sim.handle(
            Link::Controller,
            client,
            &reset(&mut enc, 0, 21),
            start,
            &mut a,
        );
    }
    let mass = CharArray::from("mass");
    let asks = [
        MavMessage::PARAM_REQUEST_LIST(PARAM_REQUEST_LIST_DATA {
            target_system: 2,
            target_component: 1,
        }),
        // For the next reset: this episode flies on.
        MavMessage::PARAM_SET(PARAM_SET_DATA {
            param_value: 1.3,
            target_system: 0,
            target_component: 1,
            param_id: mass,
            param_type: MavParamType::MAV_PARAM_TYPE_REAL32,
        }),
        command(
            3,
            MavCmd::MAV_CMD_REQUEST_MESSAGE,
            id::DEBUG_FLOAT_ARRAY as f32,
            0.0,
        ),
        command(
            0,
            MavCmd::MAV_CMD_SET_MESSAGE_INTERVAL,
            id::WIND_COV as f32,
            20_000.0,
        ),
    ];
    let mut systems = BTreeSet::new();
    for k in 1..=150u64 {
        let now = start + Duration::from_millis(20 * k);
        telemetry.clear();
        watched.gcs_tick(now, &mut telemetry);
        let ask = request(&mut enc, asks[(k % 4) as usize].clone());
        watched.handle(Link::Gcs, gcs, &ask, now, &mut telemetry);
        for (s, m) in decoded(&telemetry) {
            if matches!(m, MavMessage::LOCAL_POSITION_NED(_)) {
                systems.insert(s);
            }
        }
        let datagram = step_datagram(&mut enc, k);
        a.clear();
        b.clear();
        clean.handle(Link::Controller, client, &datagram, now, &mut a);
        watched.handle(Link::Controller, client, &datagram, now, &mut b);
        assert_eq!(a, b, "step {k}: the same bytes");
    }
    assert_eq!(systems, BTreeSet::from([1, 2, 3]));
    assert_eq!(watched.stats.steps, clean.stats.steps);
    let w = watched.world.as_ref().unwrap();
    assert_eq!(w.config.quadrotor.mass, 1.3, "set for the next reset");
    assert_ne!(w.flight.config().quadrotor.mass, 1.3, "not this episode's");
}
