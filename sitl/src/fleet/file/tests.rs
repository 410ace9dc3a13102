use super::*;

fn parse_str(text: &str) -> Result<FleetSpec, FleetError> {
    parse(text, Path::new("."))
}

const MIXED: &str = r#"
[world]
downwash_enabled = false
[[vehicle]]
autopilot = "px4"
instance = 0
[[vehicle]]
autopilot = "px4"
instance = 1
position = [3.0, 0.0]
frame = "hexa_x"
[[vehicle]]
name = "copter"
autopilot = "ardupilot"
instance = 2
position = [0.0, 3.0]
"#;

#[test]
fn a_mixed_fleet_file_gives_ports_sysids_frames_and_positions() {
    let spec = parse_str(MIXED).unwrap();
    let v = &spec.vehicles;
    let row: Vec<_> = v
        .iter()
        .map(|v| (v.name.as_str(), v.listen.port(), v.sysid))
        .collect();
    assert_eq!(
        row,
        [
            ("px4-000", 4560, 1),
            ("px4-001", 4561, 2),
            ("copter", 9022, 3)
        ]
    );
    assert_eq!(v[1].vehicle.frame.rotor_count(), 6);
    assert_eq!(v[2].position, [0.0, 3.0]);
    assert!(!spec.world.wind_enabled, "no wind unless asked for");
    assert!(!spec.world.downwash_enabled);
}

fn error(text: &str) -> String {
    parse_str(text).unwrap_err().to_string()
}

#[test]
fn bad_fleet_files_name_the_item() {
    let two = |a: &str, b: &str| {
        format!("[[vehicle]]\nautopilot = \"px4\"\n{a}\n[[vehicle]]\nautopilot = \"px4\"\n{b}\n")
    };
    assert_eq!(
        error(&two("instance = 1", "instance = 2\nport = 4561")),
        "vehicle 1 (`px4-002`): port 4561 is also vehicle 0's (`px4-001`)"
    );
    let ap = "[[vehicle]]\nautopilot = \"px4\"\ninstance = 0\n[[vehicle]]\nautopilot = \"ardupilot\"\ninstance = 0\n";
    assert_eq!(
        error(ap),
        "vehicle 1 (`ardupilot-000`): sysid 1 is also vehicle 0's (`px4-000`)"
    );
    assert!(
        error(&two("instance = 0\nframe = \"hexa_y\"", "instance = 1"))
            .starts_with("vehicle 0 (`px4-000`): frame: ")
    );
    assert!(error(&two("instance = 0\nframe = \"hexa_y\"", "instance = 1")).contains("hexa_y"));
    assert_eq!(
        error(&two("instance = 0\nsysid = 7", "instance = 1")),
        "vehicle 0 (`px4-000`): sysid 7: PX4 instance 0 sets its MAV_SYS_ID to 1 itself (leave sysid out or give 1)"
    );
    assert!(
        error(&two(
            "instance = 0\nname = \"a\"",
            "instance = 1\nname = \"a\""
        ))
        .contains("name `a`")
    );
    assert!(error("[[vehicle]]\nautopilot = \"inav\"\ninstance = 0\n").contains("inav"));
    assert!(error("").contains("1 to 254 [[vehicle]]"));
    assert!(error(&two("instance = 0\nposition = [nan, 0]", "instance = 1")).contains("position"));
    assert!(
        error("[world]\ngrid = -1\n[[vehicle]]\nautopilot = \"px4\"\ninstance = 0\n")
            .starts_with("[world]: ")
    );
    assert!(
        error(&two(
            "instance = 0\nconfig = \"missing.toml\"",
            "instance = 1"
        ))
        .contains("missing.toml")
    );
}

#[test]
fn a_row_counts_ports_and_sysids_from_its_first_instance() {
    let base: SocketAddr = "127.0.0.1:4570".parse().unwrap();
    let spec = row(Autopilot::Px4, 3, base, 3.0, &AutopilotVehicle::iris()).unwrap();
    let got: Vec<_> = spec
        .vehicles
        .iter()
        .map(|v| (v.listen.port(), v.sysid, v.position))
        .collect();
    assert_eq!(
        got,
        [
            (4570, 11, [0.0, 0.0]),
            (4571, 12, [3.0, 0.0]),
            (4572, 13, [6.0, 0.0])
        ]
    );
    let base: SocketAddr = "127.0.0.1:9012".parse().unwrap();
    let spec = row(
        Autopilot::Ardupilot,
        2,
        base,
        3.0,
        &AutopilotVehicle::iris(),
    )
    .unwrap();
    let got: Vec<_> = spec
        .vehicles
        .iter()
        .map(|v| (v.listen.port(), v.sysid))
        .collect();
    assert_eq!(got, [(9012, 2), (9022, 3)]);
    let far: SocketAddr = "127.0.0.1:65530".parse().unwrap();
    assert!(
        row(Autopilot::Px4, 8, far, 3.0, &AutopilotVehicle::iris())
            .unwrap_err()
            .0
            .contains("past 65535")
    );
}
