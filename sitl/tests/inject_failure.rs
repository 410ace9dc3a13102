//! Issue 35: MAV_CMD_INJECT_FAILURE on the lockstep task mode's link, in process through
//! the SITL's own handler: PX4's codes (param1 FAILURE_UNIT, param2 FAILURE_TYPE, param3
//! instance, 1 = first motor, 0 = all) fire the fault in the vehicle's task, acknowledged
//! ACCEPTED with a STATUSTEXT naming it; codes the catalogue lacks are UNSUPPORTED and
//! parameters that are no codes DENIED, each with a STATUSTEXT naming the field.

use flyloop_core::faults::px4::{kind, unit};
use flyloop_core::tasks::registry::TaskKind;
use flyloop_sitl::sim::{Link, Sim, SimOptions};
use flyloop_sitl::wire::{Encoder, frames};
use mavlink::dialects::common::{COMMAND_LONG_DATA, MavCmd, MavMessage, MavResult};
use std::net::SocketAddr;
use std::time::Instant;

/// The ACK result and the STATUSTEXTs of the reply to an inject command with `params`.
fn inject(sim: &mut Sim, params: [f32; 3]) -> (MavResult, Vec<String>) {
    let msg = MavMessage::COMMAND_LONG(COMMAND_LONG_DATA {
        param1: params[0],
        param2: params[1],
        param3: params[2],
        command: MavCmd::MAV_CMD_INJECT_FAILURE,
        target_system: 1,
        target_component: 1,
        ..Default::default()
    });
    let mut datagram = Vec::new();
    Encoder::default().push(&mut datagram, 255, &msg);
    let peer: SocketAddr = "127.0.0.1:40110".parse().unwrap();
    let mut out = Vec::new();
    sim.handle(Link::Controller, peer, &datagram, Instant::now(), &mut out);
    let result = frames(&out)
        .find_map(|f| match f.unwrap().message {
            MavMessage::COMMAND_ACK(a) => Some(a.result),
            _ => None,
        })
        .unwrap();
    let texts = crate::refused_controls::said(&out)
        .into_iter()
        .map(|(_, t)| t)
        .filter(|t| t != "COMMAND_ACK")
        .collect();
    (result, texts)
}

#[test]
fn px4_failure_codes_fire_faults_and_unknown_ones_are_refused_naming_the_field() {
    let mut sim = Sim::new(SimOptions::new(TaskKind::Hover), Instant::now()).unwrap();
    let (motor, off) = (f32::from(unit::SYSTEM_MOTOR), f32::from(kind::OFF));
    let (r, t) = inject(&mut sim, [motor, off, 1.0]);
    assert_eq!(
        (r, t),
        (
            MavResult::MAV_RESULT_ACCEPTED,
            vec!["fault injected: motor_off:1".to_string()]
        )
    );
    let gps = f32::from(unit::SENSOR_GPS);
    let (r, t) = inject(&mut sim, [gps, off, 0.0]);
    assert_eq!(
        (r, t),
        (
            MavResult::MAV_RESULT_ACCEPTED,
            vec!["fault injected: sensor_off:gps".to_string()]
        )
    );
    let (r, t) = inject(&mut sim, [motor, f32::from(kind::OK), 0.0]);
    assert_eq!(
        (r, t),
        (
            MavResult::MAV_RESULT_ACCEPTED,
            vec!["fault cleared: all motors".to_string()]
        )
    );
    // A motor the quad X lacks: the instance and the frame's count.
    let (r, t) = inject(&mut sim, [motor, off, 5.0]);
    assert_eq!(r, MavResult::MAV_RESULT_UNSUPPORTED);
    assert!(
        t[0].contains("instance 5") && t[0].contains("1 to 4"),
        "{t:?}"
    );
    let (r, t) = inject(&mut sim, [42.0, off, 0.0]);
    assert_eq!(r, MavResult::MAV_RESULT_UNSUPPORTED);
    assert!(t[0].contains("failure_unit 42"), "{t:?}");
    let (r, t) = inject(&mut sim, [motor, 1.5, 0.0]);
    assert_eq!(r, MavResult::MAV_RESULT_DENIED);
    assert!(t[0].contains("param2 (failure_type) = 1.5"), "{t:?}");
}
