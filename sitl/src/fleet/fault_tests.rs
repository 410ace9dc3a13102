//! Issue 35: faults in fleet mode — a fleet file's `[[faults]]` naming its vehicle, flown
//! through that vehicle's actuator and sensor paths only, each firing a notice (log and
//! STATUSTEXT) and a track event; bad tables refused naming the item.

use super::file;
use super::tests::answer;
use super::*;
use crate::control_link::ControlLink;
use std::path::Path;

const FLEET: &str = r#"
vehicle = [
  { autopilot = "px4", instance = 0 },
  { autopilot = "px4", instance = 1, position = [3.0, 0.0] },
]
[[faults]]
vehicle = "px4-001"
kind = "motor_off"
motor = 1
at = 0.1
duration = 0.2
"#;

/// Both PX4s answer every sensor with `value` for `seconds` of world time.
fn fly(f: &mut Fleet, value: f32, seconds: f64) {
    let end = f.lockstep().now_us() + (seconds * 1e6) as u64;
    while f.lockstep().now_us() < end {
        answer(f, 0, value);
        answer(f, 1, value);
        while f.advance(false).is_ok() {}
    }
}

#[test]
fn a_fault_named_for_one_vehicle_acts_on_it_alone_and_is_announced() {
    let spec = file::parse(FLEET, Path::new(".")).unwrap();
    let mut f = Fleet::new(&spec, 3, PX4_STEP_US).unwrap();
    f.px4_connected(0);
    f.px4_connected(1);
    f.take_notices();
    fly(&mut f, 0.5, 0.2);
    let (healthy, faulty) = (
        f.vehicle(0).actuator_states(),
        f.vehicle(1).actuator_states(),
    );
    assert!((healthy[0] - 0.5).abs() < 1e-3, "{healthy:?}");
    assert!(
        faulty[0] < 0.01 && (faulty[1] - 0.5).abs() < 1e-3,
        "{faulty:?}"
    );
    assert_eq!(
        f.vehicle(1).actuators(),
        vec![0.5f32 as f64; 4],
        "PX4's command kept"
    );
    fly(&mut f, 0.5, 0.3);
    assert!(
        (f.vehicle(1).actuator_states()[0] - 0.5).abs() < 1e-3,
        "cleared at 0.3 s"
    );
    let texts: Vec<String> = (f.take_notices().into_iter())
        .map(|n| n.text)
        .filter(|t| t.contains("fault"))
        .collect();
    assert_eq!(
        texts,
        [
            "px4-001: fault fired: motor_off:1 at 0.100 s",
            "px4-001: fault cleared: motor_off:1 at 0.300 s"
        ]
    );
    let log: Vec<String> = f.members()[1]
        .fault_log
        .iter()
        .map(crate::track::fault_event)
        .collect();
    assert_eq!(log, ["+motor_off:1@0.100", "-motor_off:1@0.300"]);
    assert!(f.members()[0].fault_log.is_empty());
}

#[test]
fn without_faults_a_fleet_flies_the_same_bits_as_before() {
    let text = FLEET.split("[[faults]]").next().unwrap();
    let run = |text: &str, with: bool| {
        let mut spec = file::parse(text, Path::new(".")).unwrap();
        if with {
            // A fault that never acts on this flight's motors: only a stuck baro.
            spec.vehicles[1].vehicle.faults = flyloop_core::faults::FaultPlan::from_toml_str(
                "[[faults]]\nkind = \"sensor_stuck\"\nsensor = \"baro\"\nat = 100",
            )
            .unwrap();
        }
        let mut f = Fleet::new(&spec, 3, PX4_STEP_US).unwrap();
        f.px4_connected(0);
        f.px4_connected(1);
        fly(&mut f, 0.6, 0.5);
        f.world().save().unwrap()
    };
    assert_eq!(run(text, false), run(text, true));
}

#[test]
fn bad_fleet_faults_name_the_item() {
    let err = |faults: &str| {
        let text = format!(
            "{}[[faults]]\n{faults}",
            FLEET.split("[[faults]]").next().unwrap()
        );
        file::parse(&text, Path::new(".")).unwrap_err().to_string()
    };
    let e = err("vehicle = \"px4-009\"\nkind = \"motor_off\"");
    assert_eq!(
        e,
        "[[faults]] 0: vehicle `px4-009` is not in the fleet; its vehicles: `px4-000`, `px4-001`"
    );
    let e = err("kind = \"motor_off\"");
    assert!(e.contains("[[faults]] 0: needs `vehicle`"), "{e}");
    let e = err("vehicle = \"px4-000\"\nkind = \"motor_off\"\nmotor = 5");
    assert!(
        e.contains("vehicle 0 (`px4-000`): faults:")
            && e.contains("`motor` = 5")
            && e.contains("[0, 4]"),
        "{e}"
    );
    let e = err("vehicle = \"px4-001\"\nkind = \"motor_efectiveness\"");
    assert!(
        e.contains("[[faults]] 0 (vehicle `px4-001`)") && e.contains("`motor_efectiveness`"),
        "{e}"
    );
    let e = err("vehicle = \"px4-001\"\nkind = \"gust\"");
    assert!(e.contains("`gust`") && e.contains("wind field"), "{e}");
    let e = err("vehicle = \"px4-001\"\nkind = \"link_loss\"\nduration = 1");
    assert!(
        e.contains("`link_loss`") && e.contains("not flown in fleet mode"),
        "{e}"
    );
}

#[test]
fn the_fleets_control_link_injects_into_the_vehicle_its_sysid_names() {
    use crate::px4::session::faults_tests::{answer, inject};
    use mavlink::dialects::common::MavResult;
    use std::net::UdpSocket;
    let text = FLEET.split("[[faults]]").next().unwrap();
    let spec = file::parse(text, Path::new(".")).unwrap();
    let mut f = Fleet::new(&spec, 3, PX4_STEP_US).unwrap();
    let link = ControlLink::new(UdpSocket::bind("127.0.0.1:0").unwrap()).unwrap();
    let addr = link.local_addr().unwrap();
    f.set_control(link);
    let client = UdpSocket::bind("127.0.0.1:0").unwrap();
    client
        .set_read_timeout(Some(std::time::Duration::from_secs(5)))
        .unwrap();
    client.connect(addr).unwrap();
    f.px4_connected(0);
    f.px4_connected(1);
    fly(&mut f, 0.5, 0.05);
    // FAILURE_UNIT_SYSTEM_MOTOR (101), OFF (1), motor 1, for sysid 2 (`px4-001`).
    client.send(&inject(101.0, 1.0, 1.0, 2)).unwrap();
    fly(&mut f, 0.5, 0.05);
    let (ack, said) = answer(&client);
    assert_eq!(ack.result, MavResult::MAV_RESULT_ACCEPTED);
    assert_eq!(said, "px4-001: fault injected: motor_off:1");
    // A motor the quad lacks: UNSUPPORTED, naming the instance.
    client.send(&inject(101.0, 1.0, 7.0, 1)).unwrap();
    fly(&mut f, 0.5, 0.05);
    let (ack, said) = answer(&client);
    assert_eq!(ack.result, MavResult::MAV_RESULT_UNSUPPORTED);
    assert!(said.contains("instance 7"), "{said}");
    fly(&mut f, 0.5, 0.3);
    let (healthy, faulty) = (
        f.vehicle(0).actuator_states(),
        f.vehicle(1).actuator_states(),
    );
    assert!((healthy[0] - 0.5).abs() < 1e-3, "{healthy:?}");
    assert!(faulty[0] < 0.01, "{faulty:?}");
    let log: Vec<String> = f.members()[1]
        .fault_log
        .iter()
        .map(crate::track::fault_event)
        .collect();
    assert_eq!(log.len(), 1, "{log:?}");
    assert!(log[0].starts_with("+motor_off:1@0.0"), "{log:?}");
}
