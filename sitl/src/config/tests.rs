use super::*;

#[test]
fn names_and_short_ids_both_set_their_parameter() {
    let c = parse(
        TaskKind::Hover,
        "mass = 1.5\nmax_steps = 200\nwind_enabled = false\ntgt_chg_intv = 50\n",
    )
    .unwrap();
    assert_eq!(c.quadrotor.mass, 1.5);
    assert_eq!(c.flight.max_steps, 200);
    assert!(!c.quadrotor.wind_enabled);
    assert_eq!(c.flight.target_change_interval, 50);
    assert_eq!(
        c.quadrotor.arm_length, 0.1,
        "missing keys keep their defaults"
    );
}

#[test]
fn a_bad_value_names_the_parameter_and_its_bound() {
    let err = parse(TaskKind::Hover, "mass = -2.0")
        .unwrap_err()
        .to_string();
    assert!(err.contains("`mass` = -2 kg is out of range"), "{err}");
    let err = parse(TaskKind::Landing, "max_steps = 0")
        .unwrap_err()
        .to_string();
    assert!(err.contains("`max_steps` = 0 is out of range"), "{err}");
    let err = parse(TaskKind::Hover, "max_num_waypoints = 3")
        .unwrap_err()
        .to_string();
    assert!(err.contains("max_num_waypoints"), "{err}");
    assert_eq!(
        parse(TaskKind::Hover, "masss = 1").unwrap_err().to_string(),
        "unknown parameter `masss` for task `hover`"
    );
    let err = parse(TaskKind::Hover, "mass = \"heavy\"")
        .unwrap_err()
        .to_string();
    assert!(err.contains("`mass` must be a number"), "{err}");
    let err = parse(TaskKind::Hover, "mass = ").unwrap_err().to_string();
    assert!(err.contains("invalid parameter file"), "{err}");
}

#[test]
fn randomisation_ranges_come_from_their_table() {
    let c = parse(
        TaskKind::Hover,
        "mass = 1.5\n[randomize]\nmass = [1.2, 1.8]\nroll_rate_p = [0.1, 0.2]\n",
    )
    .unwrap();
    let r = c.randomize.ranges();
    assert_eq!(r.len(), 2);
    assert_eq!(
        (r[0].name.as_str(), r[0].low, r[0].high),
        ("mass", 1.2, 1.8)
    );
    let err = parse(TaskKind::Hover, "[randomize]\nmass = [2.0, 1.0]")
        .unwrap_err()
        .to_string();
    assert!(err.contains("`mass` = [2, 1] kg must be ordered"), "{err}");
    let err = parse(TaskKind::Hover, "[randomize]\nmass = 1.0")
        .unwrap_err()
        .to_string();
    assert!(err.contains("range `mass` must be a pair"), "{err}");
    let err = parse(TaskKind::Hover, "[randomize]\nmasss = [1, 2]")
        .unwrap_err()
        .to_string();
    assert!(err.contains("`masss`"), "{err}");
    let err = parse(TaskKind::Landing, "[randomize]\nmass = [1, 2]")
        .unwrap_err()
        .to_string();
    assert!(err.contains("no randomisation"), "{err}");
}

#[test]
fn relations_between_parameters_are_checked() {
    let err = parse(
        TaskKind::Hover,
        "wind_speed_min = 9.0\nwind_speed_max = 3.0",
    )
    .unwrap_err()
    .to_string();
    assert!(err.contains("wind_speed_min"), "{err}");
    parse(
        TaskKind::Hover,
        "wind_speed_min = 2.0\nwind_speed_max = 3.0",
    )
    .unwrap();
}

#[test]
fn the_iris_preset_parses_and_hovers_near_0_6() {
    let c = AutopilotVehicle::parse(IRIS_PRESET).unwrap();
    assert_eq!(c, AutopilotVehicle::iris());
    assert_eq!(c.quadrotor.mass, 1.5);
    assert!(!c.quadrotor.wind_enabled);
    let hover = c.quadrotor.hover_motor_state().unwrap();
    assert!((hover - 0.6066).abs() < 1e-3, "{hover}");
    assert_eq!(c.sensors, SensorParams::default());
    // Feet under the rotors; standing, the centre of mass is 5.4 cm up.
    let q = &c.quadrotor;
    assert!((q.gear_x - q.arm_length / 2f64.sqrt()).abs() < 1e-3);
    assert_eq!(q.gear_x, q.gear_y);
    let rest = flyloop_core::quadrotor::contact::rest_height(q);
    assert!((rest - 0.0538).abs() < 1e-4, "{rest}");
}

#[test]
fn the_autopilot_vehicle_reads_both_sets_and_names_mistakes() {
    let c = AutopilotVehicle::parse("mass = 2\ngps_rate = 5\n").unwrap();
    assert_eq!((c.quadrotor.mass, c.sensors.gps_rate), (2.0, 5.0));
    assert_eq!(
        c.quadrotor.arm_length, 0.1,
        "missing keys keep their defaults"
    );
    let e = AutopilotVehicle::parse("gps_rate = 0")
        .unwrap_err()
        .to_string();
    assert!(e.contains("`gps_rate` = 0 Hz is out of range"), "{e}");
    assert_eq!(
        AutopilotVehicle::parse("mas = 1").unwrap_err().to_string(),
        "unknown parameter `mas` for PX4 or ArduPilot mode: expected one of `QuadrotorParams` or `SensorParams`"
    );
    assert_eq!(
        AutopilotVehicle::parse("mass = \"x\"")
            .unwrap_err()
            .to_string(),
        "invalid parameter file: parameter `mass` must be a number or a boolean"
    );
    // Short ids are the MAVLink SITL's; a task's parameter is not the vehicle's.
    for key in ["ang_damp_quad", "max_steps"] {
        let e = AutopilotVehicle::parse(&format!("{key} = 1"))
            .unwrap_err()
            .to_string();
        assert!(e.contains(&format!("`{key}` for PX4")), "{e}");
    }
    let e = AutopilotVehicle::parse("[randomize]\nmass = [1, 2]")
        .unwrap_err()
        .to_string();
    assert!(e.contains("without randomisation"), "{e}");
}

#[test]
fn the_frame_presets_parse_and_hover_on_their_rotors() {
    for (file, text, rotors) in [
        (
            "px4_hexa_x",
            include_str!("../../presets/px4_hexa_x.toml"),
            6,
        ),
        (
            "ardupilot_hexa_x",
            include_str!("../../presets/ardupilot_hexa_x.toml"),
            6,
        ),
        (
            "ardupilot_octo_x",
            include_str!("../../presets/ardupilot_octo_x.toml"),
            8,
        ),
    ] {
        let v = AutopilotVehicle::parse(text).unwrap();
        assert_eq!(v.frame.rotor_count(), rotors, "{file}");
        let quad =
            flyloop_core::quadrotor::standing_multirotor_at(v.quadrotor, v.frame, 0, [0.0; 2])
                .unwrap()
                .take();
        let hover = quad.hover_motor_state().unwrap();
        assert!((0.5..0.65).contains(&hover), "{file}: hover at {hover}");
    }
    assert_eq!(AutopilotVehicle::iris().frame.name(), "quad_x");
}

/// Regression (issue 33): a frame the core refuses is a config error naming the rotor and
/// the field, never a panic or a silent quad.
#[test]
fn a_bad_frame_table_names_the_rotor_and_field() {
    let bad = "mass = 2\n[frame]\nname = \"tri\"\n[[frame.rotor]]\nx = 1\ny = 0\nspin = \"cw\"";
    let e = AutopilotVehicle::parse(bad).unwrap_err().to_string();
    assert_eq!(e, "frame `tri` has 1 rotors: a frame needs 4 to 12");
    let e = AutopilotVehicle::parse("[frame]\nname = \"dodeca\"").unwrap_err();
    assert!(e.to_string().starts_with("unknown frame `dodeca`"), "{e}");
    let e = AutopilotVehicle::parse("frame = 6").unwrap_err();
    assert!(e.to_string().contains("`frame` must be a table"), "{e}");
    let mut text = String::from("[frame]\nname = \"flat\"\n");
    for (x, y, spin) in [(1, 1, "cw"), (-1, -1, "cw"), (1, -1, "ccw"), (-1, 1, "ccw")] {
        text += &format!(
            "[[frame.rotor]]\nx = {x}\ny = {y}\nspin = \"{spin}\"\nthrust_coefficient = -1\n"
        );
    }
    let e = AutopilotVehicle::parse(&text).unwrap_err().to_string();
    assert!(
        e.contains("rotor 0: `thrust_coefficient` = -1 is out of range"),
        "{e}"
    );
}

/// Issue 35: the lockstep task mode takes `[[faults]]` and `[[fault_randomization]]` from its
/// config file through the core's one parser; bad ones name the field and its bound.
#[test]
fn faults_in_the_config_file_reach_the_task() {
    let text = "mass = 1.1\n[[faults]]\nkind = \"motor_effectiveness\"\nmotor = 2\neffectiveness = 0.5\nat = 1.0\n\
                [[fault_randomization]]\nkinds = [\"gust\", \"motor_off\"]\nat = [0.0, 2.0]\n";
    let c = parse(TaskKind::Hover, text).unwrap();
    assert_eq!((c.faults.faults.len(), c.faults.draws.len()), (1, 1));
    assert_eq!(c.quadrotor.mass, 1.1);
    let e = parse(
        TaskKind::Hover,
        "[[faults]]\nkind = \"motor_off\"\nmotor = 9",
    )
    .unwrap_err()
    .to_string();
    assert!(
        e.contains("`motor` = 9 is out of range: it must be in [0, 4]"),
        "{e}"
    );
    let e = parse(TaskKind::Hover, "faults = 3")
        .unwrap_err()
        .to_string();
    assert!(e.contains("`faults` must be tables"), "{e}");
}

/// Issue 35: the PX4 and ArduPilot modes take faults too, checked against their frame and an
/// open-ended flight (no waypoints).
#[test]
fn the_autopilot_modes_take_faults_checked_against_their_frame() {
    let v = AutopilotVehicle::parse(
        "[[faults]]\nkind = \"sensor_off\"\nsensor = \"gps\"\nat = 30.0\n\
         [[fault_randomization]]\nkinds = [\"gust\"]\nat = [1.0, 2.0]",
    )
    .unwrap();
    assert_eq!((v.faults.faults.len(), v.faults.draws.len()), (1, 1));
    let e = AutopilotVehicle::parse("[[faults]]\nkind = \"motor_off\"\nmotor = 5")
        .unwrap_err()
        .to_string();
    assert!(e.contains("it must be in [0, 4]"), "{e}");
    let e = AutopilotVehicle::parse("[[faults]]\nkind = \"motor_off\"\nat_waypoint = 1")
        .unwrap_err()
        .to_string();
    assert!(e.contains("no waypoints"), "{e}");
}

/// A motor fault on a hexa addresses its six motors; a motor the frame lacks is refused
/// naming the index and the frame's count.
#[test]
fn a_hexa_motor_fault_addresses_six_motors() {
    let hexa = "[frame]\nname = \"hexa_x\"\n[[faults]]\nkind = \"motor_off\"\nmotor = ";
    let c = parse(TaskKind::Hover, &format!("{hexa}6")).unwrap();
    assert_eq!((c.frame.rotor_count(), c.faults.faults[0].motor), (6, 6));
    let e = parse(TaskKind::Hover, &format!("{hexa}7"))
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("`motor` = 7 is out of range: it must be in [0, 6]"),
        "{e}"
    );
}

/// The task modes fly the file's `[frame]` too (the gym's SITL backend writes it), with the
/// lander refusing one; no `[frame]` is the quad X.
#[test]
fn a_task_config_flies_its_frame_table() {
    let c = parse(TaskKind::Hover, "mass = 1.2\n[frame]\nname = \"hexa_x\"").unwrap();
    assert_eq!((c.frame.rotor_count(), c.quadrotor.mass), (6, 1.2));
    let c = parse(
        TaskKind::Waypoints,
        "[randomize]\nmass = [1, 2]\n[frame]\nname = \"octo_x\"",
    );
    assert_eq!(c.unwrap().frame.rotor_count(), 8);
    assert!(
        parse(TaskKind::Hover, "mass = 1.2")
            .unwrap()
            .frame
            .is_quad_x()
    );
    let e = parse(TaskKind::Hover, "[frame]\nname = \"tri\"").unwrap_err();
    assert!(
        e.to_string()
            .starts_with("unknown frame `tri`: the shipped frames are"),
        "{e}"
    );
    let e = parse(TaskKind::Landing, "[frame]\nname = \"hexa_x\"").unwrap_err();
    assert!(e.to_string().contains("takes no frame"), "{e}");
}
