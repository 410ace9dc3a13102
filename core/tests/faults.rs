//! The fault library's physical effects through the flight tasks' fault path, its triggers,
//! seeded draws, events, and its refusals of bad input.

use flyloop_core::SimRng;
use flyloop_core::faults::{FaultKind, FaultPlan};
use flyloop_core::quadrotor::{BodyState, Frame, Quadrotor, QuadrotorParams};
use flyloop_core::tasks::flight_faults::FlightFaults;
use flyloop_core::tasks::hover::Hover;
use flyloop_core::tasks::randomization::{Randomization, VehicleParams};
use flyloop_core::tasks::registry::{TaskInstance, TaskKind, from_values_ranges_and_faults};
use flyloop_core::tasks::{InfoValue, Task};
use nalgebra::Vector3;

const DT: f64 = 0.01;

/// A quad X in still air, far above any ground, with the faults of `plan` (episode 0).
fn calm_quad(plan: &str) -> (Quadrotor, FlightFaults) {
    let params = QuadrotorParams {
        wind_enabled: false,
        ground_enabled: false,
        ..QuadrotorParams::default()
    };
    let body = BodyState::at_rest(Vector3::new(0.0, 0.0, 100.0), 0.0, 0.0, 0.0, 0.0);
    let mut quad = Quadrotor::new(params, body, SimRng::new(1)).unwrap();
    let plan = FaultPlan::from_toml_str(plan).unwrap();
    let mut faults = FlightFaults::new(plan, 4, 1e6).unwrap();
    faults.restart(0, &mut quad, DT);
    (quad, faults)
}

/// Flies `command` for `seconds` through the fault path.
fn fly(quad: &mut Quadrotor, faults: &mut FlightFaults, command: [f64; 4], seconds: f64) {
    for _ in 0..(seconds / DT).round() as usize {
        faults.begin_step(quad, DT);
        drive(quad, faults, &command, DT);
        faults.end_step();
    }
}

/// Commands `command` and advances `dt` through the actuator fault path, as a flight link does.
fn drive(quad: &mut Quadrotor, faults: &mut FlightFaults, command: &[f64], dt: f64) {
    quad.set_command(command).unwrap();
    faults.before_advance(quad, dt);
    quad.step(dt);
    faults.after_advance(quad);
}

/// Thrust of rotor `i` now, N.
fn rotor_thrust(quad: &Quadrotor, i: usize) -> f64 {
    quad.params.thrust_coefficient * quad.body.motors[i].powi(2)
}

#[test]
fn loss_of_effectiveness_scales_the_rotors_thrust_and_leaves_the_others() {
    let (mut healthy, mut none) = calm_quad("");
    let (mut weak, mut faults) =
        calm_quad("[[faults]]\nkind = 'motor_effectiveness'\nmotor = 2\neffectiveness = 0.6");
    fly(&mut healthy, &mut none, [0.5; 4], 2.0);
    fly(&mut weak, &mut faults, [0.5; 4], 2.0);
    // 2 s = 25 motor time constants: settled to 1e-11.
    let ratio = rotor_thrust(&weak, 1) / rotor_thrust(&healthy, 1);
    assert!((ratio - 0.6).abs() < 1e-9, "{ratio}");
    for i in [0, 2, 3] {
        assert_eq!(rotor_thrust(&weak, i), rotor_thrust(&healthy, i));
    }
    // The vehicle keeps being commanded 0.5 everywhere, and rolls/yaws off level.
    assert_eq!(weak.command(), [0.5; 4]);
    assert_eq!(healthy.body.body_rates, Vector3::zeros());
    assert!(
        weak.body.body_rates.norm() > 0.1,
        "{:?}",
        weak.body.body_rates
    );
}

#[test]
fn off_stuck_lost_and_damaged_rotors_give_their_thrust() {
    let cases = [
        ("kind = 'motor_off'\nmotor = 1", 0.0),
        ("kind = 'propeller_loss'\nmotor = 1", 0.0),
        (
            "kind = 'motor_stuck'\nmotor = 1\ncommand = 0.8",
            10.0 * 0.64,
        ),
        (
            "kind = 'propeller_damage'\nmotor = 1\nthrust_loss = 0.3",
            10.0 * 0.25 * 0.7,
        ),
    ];
    for (text, thrust) in cases {
        let (mut quad, mut faults) = calm_quad(&format!("[[faults]]\n{text}"));
        fly(&mut quad, &mut faults, [0.5; 4], 2.0);
        assert!(
            (rotor_thrust(&quad, 0) - thrust).abs() < 1e-8,
            "{text}: {}",
            rotor_thrust(&quad, 0)
        );
        assert!((rotor_thrust(&quad, 3) - 2.5).abs() < 1e-8);
    }
}

#[test]
fn an_added_lag_is_a_first_order_lag_in_series_with_the_motor() {
    // Step 0 → 1 at t = 0: the motor alone reaches 1 − e^{−t/τm}; with the added lag τa
    // the command it follows is 1 − e^{−t/τa} (held per step), so it is slower.
    let (mut quad, mut faults) =
        calm_quad("[[faults]]\nkind = 'motor_lag'\nmotor = 3\ntime_constant = 0.2");
    fly(&mut quad, &mut faults, [0.0; 4], 0.1);
    fly(&mut quad, &mut faults, [1.0; 4], 0.4);
    let (tm, ta, t) = (0.08f64, 0.2f64, 0.4f64);
    let alone = 1.0 - (-t / tm).exp();
    assert!(
        (quad.body.motors[0] - alone).abs() < 1e-6,
        "{}",
        quad.body.motors[0]
    );
    // Two lags in series: 1 − (τa e^{−t/τa} − τm e^{−t/τm}) / (τa − τm), within the
    // one-step hold of the lag's output.
    let series = 1.0 - (ta * (-t / ta).exp() - tm * (-t / tm).exp()) / (ta - tm);
    assert!(
        (quad.body.motors[2] - series).abs() < 0.03,
        "{} vs {series}",
        quad.body.motors[2]
    );
}

#[test]
fn a_damaged_propeller_shakes_the_accelerometer_at_the_rotor_frequency() {
    let text = "[[faults]]\nkind = 'propeller_damage'\nmotor = 1\nthrust_loss = 0\nimbalance = 4e-6\nmax_rotor_speed = 1000";
    let (mut quad, mut faults) = calm_quad(text);
    fly(&mut quad, &mut faults, [0.5; 4], 2.0);
    // Ω = 0.5 · 1000 rad/s: a = 4e-6 · 500² / 1 kg = 1 m/s².
    let mut crossings = 0;
    let mut last = faults.state().imu_vibration(&quad.body.motors, 1.0).x;
    let dt = 1e-4;
    for _ in 0..10_000 {
        drive(&mut quad, &mut faults, &[0.5; 4], dt);
        let a = faults
            .state()
            .imu_vibration(&quad.body.motors, quad.params.mass);
        assert!((a.norm() - 1.0).abs() < 1e-8, "{}", a.norm());
        if a.x.signum() != last.signum() {
            crossings += 1;
        }
        last = a.x;
    }
    // 1 s at 500 rad/s = 79.6 turns: 159 sign changes.
    assert!(
        (crossings as f64 - 500.0 / std::f64::consts::PI).abs() <= 2.0,
        "{crossings}"
    );
}

#[test]
fn a_sagging_battery_lowers_the_thrust() {
    let (mut full, mut f) = calm_quad("[[faults]]\nkind = 'battery'");
    let (mut low, mut l) = calm_quad("[[faults]]\nkind = 'low_battery'\ncharge = 0");
    fly(&mut full, &mut f, [0.5; 4], 2.0);
    fly(&mut low, &mut l, [0.5; 4], 2.0);
    assert!((rotor_thrust(&full, 0) - 2.5).abs() < 1e-8);
    // Empty: 13.2 V open circuit; 4 motors at m ≈ 0.5·s draw 0.5 + 120 s³/8 A.
    let b = l.state().battery().unwrap();
    let scale = (b.voltage(b.current) / 14.8).min(1.0);
    assert!(scale < 0.89 && scale > 0.85, "{scale}");
    let ratio = rotor_thrust(&low, 0) / 2.5;
    assert!(
        (ratio - scale * scale).abs() < 1e-3,
        "{ratio} vs {}",
        scale * scale
    );
    assert!(b.charge == 0.0 && f.state().battery().unwrap().charge < 1.0);
}

#[test]
fn a_gust_blows_its_one_minus_cosine_and_a_trigger_fires_it_at_its_time() {
    let (mut quad, mut faults) =
        calm_quad("[[faults]]\nkind = 'gust'\nnorth = 4\nrise_time = 0.5\nat = 1");
    fly(&mut quad, &mut faults, [0.5; 4], 1.0);
    assert_eq!(quad.external_wind, Vector3::zeros());
    fly(&mut quad, &mut faults, [0.5; 4], 0.26);
    // Step starting at t = 1.25: 2·(1 − cos(π/2)) = 2 m/s north.
    assert!(
        (quad.external_wind.y - 2.0).abs() < 1e-9,
        "{}",
        quad.external_wind.y
    );
    let e = &faults.state().events()[0];
    assert_eq!((e.time, e.label.as_str(), e.fired), (1.0, "gust", true));
}

fn hover(plan: &str) -> Hover {
    let nominal = VehicleParams {
        faults: FaultPlan::from_toml_str(plan).unwrap(),
        ..VehicleParams::default()
    };
    Hover::with_vehicle(nominal, Randomization::none()).unwrap()
}

fn vector(task: &dyn Task, name: &str) -> Vec<f64> {
    match task.info().into_iter().find(|(n, _)| *n == name) {
        Some((_, InfoValue::Vector(v))) => v,
        other => panic!("{name}: {other:?}"),
    }
}

fn trace(task: &mut Hover, seed: u64, steps: usize) -> Vec<u64> {
    task.reset(seed);
    let mut out = Vec::new();
    for _ in 0..steps {
        task.step(&[0.5; 4]).unwrap();
        out.extend(task.observation().iter().map(|v| u64::from(v.to_bits())));
    }
    out
}

#[test]
fn drawn_faults_are_the_same_for_the_same_seed_and_recorded_in_the_info() {
    let plan = "[[fault_randomization]]\nkinds = ['motor_effectiveness']\nat = [0.1, 0.5]\neffectiveness = [0.5, 1.0]";
    let mut a = hover(plan);
    let mut b = hover(plan);
    assert_eq!(trace(&mut a, 7, 80), trace(&mut b, 7, 80));
    let kind = vector(&a, "fault_kind");
    let motor = vector(&a, "fault_target");
    let time = vector(&a, "fault_time");
    assert_eq!(kind, [FaultKind::MotorEffectiveness as usize as f64]);
    assert!((1.0..=4.0).contains(&motor[0]));
    assert!((0.1..=0.5 + DT).contains(&time[0]), "{time:?}");
    assert_eq!(vector(&a, "fault_active"), [1.0]);
    // Another seed: another draw.
    trace(&mut b, 8, 80);
    assert_ne!(
        (vector(&b, "fault_target"), vector(&b, "fault_time")),
        (motor, time)
    );
    // A mid-episode copy continues bit for bit (the fault state is plain data).
    let mut c = a.clone();
    for _ in 0..20 {
        a.step(&[0.55; 4]).unwrap();
        c.step(&[0.55; 4]).unwrap();
    }
    assert_eq!(a, c);
}

#[test]
fn an_empty_plan_flies_the_healthy_bits_and_adds_no_info() {
    let mut faulty = hover("");
    let mut healthy = Hover::new(QuadrotorParams::default(), Default::default()).unwrap();
    assert_eq!(trace(&mut faulty, 3, 100), trace(&mut healthy, 3, 100));
    assert_eq!(faulty.info(), healthy.info());
    // A fault that fires after the end of what is flown changes nothing before it fires.
    let mut late = hover("[[faults]]\nkind = 'motor_off'\nmotor = 1\nat = 5");
    assert_eq!(trace(&mut late, 3, 100), trace(&mut healthy, 3, 100));
}

#[test]
fn a_height_trigger_fires_when_the_vehicle_climbs_past_it() {
    let (t, z) = first_firing("above_height = 1.6", 300).unwrap();
    assert!(t > 0.0 && z > 1.6 && z < 1.7, "{t} {z}");
}

/// When a motor_off fault with `trigger` first fired in `steps` Hover steps at command 0.6:
/// its time (s) and the height then (m).
fn first_firing(trigger: &str, steps: usize) -> Option<(f64, f64)> {
    let mut task = hover(&format!(
        "[[faults]]\nkind = 'motor_off'\nmotor = 1\n{trigger}"
    ));
    task.reset(0);
    for _ in 0..steps {
        task.step(&[0.6; 4]).unwrap();
        let t = vector(&task, "fault_time")[0];
        if t >= 0.0 {
            return Some((t, task.air_vehicle().body().position.z));
        }
    }
    None
}

#[test]
fn a_takeoff_trigger_fires_its_delay_after_the_first_takeoff() {
    // Hover starts in the air: it took off at 0, so the fault fires at 0.5 s of flight.
    let (t, _) = first_firing("after_takeoff = 0.5", 100)
        .expect("after_takeoff = 0.5 never fired in 1 s of flight");
    assert!((t - 0.5).abs() < 0.011, "{t}");
}

#[test]
fn bad_faults_are_refused_naming_the_field_and_its_bound() {
    let err = |task: TaskKind, text: &str| {
        let plan = FaultPlan::from_toml_str(text);
        let e = match plan {
            Err(e) => e,
            Ok(plan) => from_values_ranges_and_faults(task, [], vec![], None, plan).unwrap_err(),
        };
        e.to_string()
    };
    let e = err(TaskKind::Hover, "[[faults]]\nkind = 'wing_loss'");
    assert!(
        e.contains("`wing_loss`") && e.contains("`propeller_loss`"),
        "{e}"
    );
    let e = err(TaskKind::Hover, "[[faults]]\nkind = 'motor_off'\nmotor = 5");
    assert!(
        e.contains("`motor` = 5 is out of range: it must be in [0, 4]"),
        "{e}"
    );
    let e = err(
        TaskKind::Hover,
        "[[faults]]\nkind = 'motor_effectiveness'\neffectiveness = 1.2",
    );
    assert!(
        e.contains("`effectiveness` = 1.2 is out of range: it must be in [0, 1]"),
        "{e}"
    );
    let e = err(
        TaskKind::Hover,
        "[[fault_randomization]]\nkinds = ['motor_off', 'link_delay']",
    );
    assert!(e.contains("`link_delay` cannot be drawn"), "{e}");
    let e = err(TaskKind::Hover, "[[faults]]\nkind = 'motor_off'\nat = 10");
    assert!(e.contains("can never fire") && e.contains("10 s"), "{e}");
    let e = err(
        TaskKind::Hover,
        "[[faults]]\nkind = 'motor_off'\nat_waypoint = 1",
    );
    assert!(e.contains("no waypoints"), "{e}");
    let e = err(
        TaskKind::Waypoints,
        "[[faults]]\nkind = 'motor_off'\nat_waypoint = 15",
    );
    assert!(e.contains("has 15 waypoints"), "{e}");
    let e = err(
        TaskKind::Hover,
        "[[faults]]\nkind = 'sensor_stuck'\nsensor = 'sonar'",
    );
    assert!(e.contains("`sonar`"), "{e}");
    let e = err(TaskKind::Landing, "[[faults]]\nkind = 'motor_off'");
    assert!(e.contains("no faults"), "{e}");
    let e = err(
        TaskKind::Hover,
        "[[fault_randomization]]\nkinds = ['motor_effectiveness']\neffectiveness = [0.5, 1.5]",
    );
    assert!(e.contains("`effectiveness` = 1.5 is out of range"), "{e}");
    let e = err(
        TaskKind::Hover,
        "[[fault_randomization]]\nkinds = ['motor_off']\nmotor = [1, 6]",
    );
    assert!(e.contains("`motor` = 6 is out of range"), "{e}");
    assert!(
        from_values_ranges_and_faults(
            TaskKind::Waypoints,
            [],
            vec![],
            None,
            FaultPlan::from_toml_str("[[faults]]\nkind = 'motor_off'\nat_waypoint = 14").unwrap()
        )
        .is_ok()
    );
}

/// Issue 35 on the multirotor frames: a motor fault on a hexa addresses its six motors (the
/// sixth stops, the other five keep their command), and a motor the hexa lacks is refused
/// naming the index and the frame's count.
#[test]
fn a_hexa_loses_its_sixth_motor_and_refuses_a_seventh() {
    let plan = |motor: u8| {
        FaultPlan::from_toml_str(&format!("[[faults]]\nkind = 'motor_off'\nmotor = {motor}"))
            .unwrap()
    };
    let nominal = VehicleParams {
        frame: Frame::named("hexa_x").unwrap(),
        faults: plan(6),
        ..VehicleParams::default()
    };
    let mut task = Hover::with_vehicle(nominal, Randomization::none()).unwrap();
    task.reset(0);
    for _ in 0..100 {
        task.step(&[0.6; 6]).unwrap();
    }
    let motors = task.air_vehicle().body().motors;
    assert_eq!(motors.len(), 6);
    // Spun down through the motor lag over the 1 s flown (from hover).
    assert!(motors[5] < 1e-4, "{motors:?}");
    for (i, m) in motors[..5].iter().enumerate() {
        assert!((m - 0.6).abs() < 1e-3, "motor {}: {m}", i + 1);
    }
    assert_eq!(vector(&task, "fault_target"), vec![6.0]);
    // The command read back is what was commanded, not what the faulted motor got.
    assert_eq!(&task.air_vehicle().motor_command()[..], &[0.6; 6]);
    let e = from_values_ranges_and_faults(
        TaskKind::Hover,
        [],
        vec![],
        Frame::named("hexa_x").ok(),
        plan(7),
    )
    .unwrap_err()
    .to_string();
    assert!(
        e.contains("`motor` = 7 is out of range: it must be in [0, 6]"),
        "{e}"
    );
}

/// MAV_CMD_INJECT_FAILURE's codes on a healthy task: all motors off (FAILURE_UNIT 101,
/// FAILURE_TYPE 1, instance 0) stops every rotor; the info gets the injected slot; a reset
/// flies healthy again.
#[test]
fn an_injected_px4_motor_failure_stops_the_rotors_until_the_reset() {
    let mut task = TaskInstance::build(TaskKind::Hover, &Default::default()).unwrap();
    task.reset(0);
    let done = task.inject_px4(101, 1, 0).unwrap();
    assert_eq!(done, "fault injected: motor_off:0");
    for _ in 0..100 {
        task.step(&[0.6; 4]).unwrap();
    }
    let TaskInstance::Hover(hover) = &task else {
        unreachable!()
    };
    let motors = hover.air_vehicle().body().motors;
    assert!(motors.iter().all(|m| *m < 1e-4), "{motors:?}");
    assert_eq!(vector(hover.as_ref(), "fault_active"), vec![1.0]);
    task.reset(0);
    task.step(&[0.6; 4]).unwrap();
    let TaskInstance::Hover(hover) = &task else {
        unreachable!()
    };
    assert!(vector(hover.as_ref(), "fault_active").is_empty());
}
