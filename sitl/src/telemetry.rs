//! MAVLink messages built from a vehicle's state: the lockstep ground truth
//! (HIL_STATE_QUATERNION) and the ground-station telemetry. Frames and units follow the
//! MAVLink spec (world NED, body FRD); the conversion itself lives in [`crate::kinematics`].

use crate::kinematics::{Home, Kinematics, STANDARD_GRAVITY, round_i16, round_u16};
use crate::vehicle::Vehicle;
use flyloop_core::tasks::registry::ModelKind;
use mavlink::dialects::common::*;
use mavlink::types::CharArray;

/// Message ids this SITL can send on request (REQUEST_MESSAGE) or stream.
pub mod id {
    pub const HEARTBEAT: u32 = 0;
    pub const SYS_STATUS: u32 = 1;
    pub const ATTITUDE: u32 = 30;
    pub const LOCAL_POSITION_NED: u32 = 32;
    pub const SERVO_OUTPUT_RAW: u32 = 36;
    pub const GLOBAL_POSITION_INT: u32 = 33;
    pub const VFR_HUD: u32 = 74;
    pub const HIL_STATE_QUATERNION: u32 = 115;
    pub const HIL_SENSOR: u32 = 107;
    pub const HIL_GPS: u32 = 113;
    pub const HIL_ACTUATOR_CONTROLS: u32 = 93;
    pub const AUTOPILOT_VERSION: u32 = 148;
    pub const WIND_COV: u32 = 231;
    pub const HOME_POSITION: u32 = 242;
    pub const DEBUG_FLOAT_ARRAY: u32 = 350;
}

/// What a ground station needs to draw a vehicle's status.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Status {
    /// No controller flies it: waiting for its first command or step, or its episode ended.
    Standby,
    /// A controller flies it (HEARTBEAT: armed).
    Active,
    /// Failsafe: the controller went silent and the motors are off.
    Failsafe,
}

/// Ground truth for a controller: attitude (FRD → NED), body rates, global position,
/// NED velocity, airspeed and the accelerometer's specific force, at simulation time.
pub fn hil_state_quaternion(v: &Vehicle, home: &Home) -> MavMessage {
    hil_state_quaternion_of(&v.task.kinematics(), home, v.clock_us)
}

/// HIL_STATE_QUATERNION of state `k` at simulation time `time_usec` (µs).
pub fn hil_state_quaternion_of(k: &Kinematics, home: &Home, time_usec: u64) -> MavMessage {
    let q = crate::kinematics::attitude_ned(&k.attitude);
    let rates = k.body_rates_frd();
    let g = home.global(&k.position);
    let vel = k.velocity_ned();
    let acc = k.specific_force_frd() * (1000.0 / STANDARD_GRAVITY);
    let airspeed = round_u16(k.airspeed() * 100.0);
    MavMessage::HIL_STATE_QUATERNION(HIL_STATE_QUATERNION_DATA {
        time_usec,
        attitude_quaternion: [q.w as f32, q.i as f32, q.j as f32, q.k as f32],
        rollspeed: rates.x as f32,
        pitchspeed: rates.y as f32,
        yawspeed: rates.z as f32,
        lat: g.lat,
        lon: g.lon,
        alt: g.alt_mm,
        vx: round_i16(vel.x * 100.0),
        vy: round_i16(vel.y * 100.0),
        vz: round_i16(vel.z * 100.0),
        ind_airspeed: airspeed,
        true_airspeed: airspeed,
        xacc: round_i16(acc.x),
        yacc: round_i16(acc.y),
        zacc: round_i16(acc.z),
    })
}

/// MAV_TYPE of a multirotor with `rotors` rotors: the spec's names for 3, 4, 6, 8, 10 and
/// 12 rotors, GENERIC_MULTIROTOR for any other count. A ground station picks its icon and
/// its airframe pages from this.
pub fn multirotor_mav_type(rotors: usize) -> MavType {
    match rotors {
        3 => MavType::MAV_TYPE_TRICOPTER,
        4 => MavType::MAV_TYPE_QUADROTOR,
        6 => MavType::MAV_TYPE_HEXAROTOR,
        8 => MavType::MAV_TYPE_OCTOROTOR,
        10 => MavType::MAV_TYPE_DECAROTOR,
        12 => MavType::MAV_TYPE_DODECAROTOR,
        _ => MavType::MAV_TYPE_GENERIC_MULTIROTOR,
    }
}

/// What vehicle `v` is: a multirotor by its frame's rotor count, the lander generic.
pub fn mav_type(v: &Vehicle) -> MavType {
    match v.kind.model() {
        ModelKind::Quadrotor => multirotor_mav_type(v.config.frame.rotor_count()),
        ModelKind::Lander2d => MavType::MAV_TYPE_GENERIC,
    }
}

pub fn heartbeat(v: &Vehicle, status: Status) -> MavMessage {
    heartbeat_of(mav_type(v), status)
}

/// HEARTBEAT of a vehicle of type `mavtype` in `status` (armed only while active).
pub fn heartbeat_of(mavtype: MavType, status: Status) -> MavMessage {
    // The crate's Default for bitflags is not empty: build from empty().
    let mut base_mode = MavModeFlag::empty();
    let system_status = match status {
        Status::Standby => MavState::MAV_STATE_STANDBY,
        Status::Active => {
            base_mode |= MavModeFlag::MAV_MODE_FLAG_SAFETY_ARMED;
            MavState::MAV_STATE_ACTIVE
        }
        Status::Failsafe => MavState::MAV_STATE_EMERGENCY,
    };
    MavMessage::HEARTBEAT(HEARTBEAT_DATA {
        custom_mode: 0,
        mavtype,
        autopilot: MavAutopilot::MAV_AUTOPILOT_GENERIC,
        base_mode,
        system_status,
        mavlink_version: 3,
    })
}

pub fn attitude(v: &Vehicle) -> MavMessage {
    attitude_of(&v.task.kinematics(), v.time_boot_ms())
}

/// ATTITUDE of state `k` at `time_boot_ms` (ms of simulation time).
pub fn attitude_of(k: &Kinematics, time_boot_ms: u32) -> MavMessage {
    let (roll, pitch, yaw) = crate::kinematics::euler_ned(&k.attitude);
    let rates = k.body_rates_frd();
    MavMessage::ATTITUDE(ATTITUDE_DATA {
        time_boot_ms,
        roll: roll as f32,
        pitch: pitch as f32,
        yaw: yaw as f32,
        rollspeed: rates.x as f32,
        pitchspeed: rates.y as f32,
        yawspeed: rates.z as f32,
    })
}

/// Heading in centidegrees [0, 36000).
fn heading_cdeg(k: &Kinematics) -> u16 {
    let (_, _, yaw) = crate::kinematics::euler_ned(&k.attitude);
    let deg = yaw.to_degrees().rem_euclid(360.0);
    round_u16(deg * 100.0) % 36000
}

pub fn global_position_int(v: &Vehicle, home: &Home) -> MavMessage {
    global_position_int_of(&v.task.kinematics(), home, v.time_boot_ms())
}

/// GLOBAL_POSITION_INT of state `k` over `home` at `time_boot_ms`.
pub fn global_position_int_of(k: &Kinematics, home: &Home, time_boot_ms: u32) -> MavMessage {
    let g = home.global(&k.position);
    let vel = k.velocity_ned();
    MavMessage::GLOBAL_POSITION_INT(GLOBAL_POSITION_INT_DATA {
        time_boot_ms,
        lat: g.lat,
        lon: g.lon,
        alt: g.alt_mm,
        relative_alt: g.relative_alt_mm,
        vx: round_i16(vel.x * 100.0),
        vy: round_i16(vel.y * 100.0),
        vz: round_i16(vel.z * 100.0),
        hdg: heading_cdeg(k),
    })
}

pub fn local_position_ned(v: &Vehicle) -> MavMessage {
    local_position_ned_of(&v.task.kinematics(), v.time_boot_ms())
}

/// LOCAL_POSITION_NED of state `k` at `time_boot_ms`.
pub fn local_position_ned_of(k: &Kinematics, time_boot_ms: u32) -> MavMessage {
    let p = k.position_ned();
    let vel = k.velocity_ned();
    MavMessage::LOCAL_POSITION_NED(LOCAL_POSITION_NED_DATA {
        time_boot_ms,
        x: p.x as f32,
        y: p.y as f32,
        z: p.z as f32,
        vx: vel.x as f32,
        vy: vel.y as f32,
        vz: vel.z as f32,
    })
}

/// The motor commands as fractions of their range, [0, 1] (the lander's [−1, 1] too).
fn command_fractions(v: &Vehicle) -> impl Iterator<Item = f64> + '_ {
    let (lo, hi) = v.task.action_bounds();
    v.command
        .iter()
        .zip(lo.into_iter().zip(hi))
        .map(|(c, (l, h))| (c - l) / (h - l))
}

pub fn vfr_hud(v: &Vehicle, home: &Home) -> MavMessage {
    let n = v.command.len().max(1) as f64;
    let throttle = command_fractions(v).sum::<f64>() / n;
    vfr_hud_of(&v.task.kinematics(), home, throttle)
}

/// VFR_HUD of state `k` over `home`; `throttle`: the mean motor command, a fraction of full.
pub fn vfr_hud_of(k: &Kinematics, home: &Home, throttle: f64) -> MavMessage {
    MavMessage::VFR_HUD(VFR_HUD_DATA {
        airspeed: k.airspeed() as f32,
        groundspeed: k.velocity.xy().norm() as f32,
        alt: (home.altitude_m + k.position.z) as f32,
        climb: k.velocity.z as f32,
        heading: (heading_cdeg(k) / 100) as i16,
        throttle: round_u16(throttle * 100.0),
    })
}

/// The motor commands in effect as PWM µs, 1000 (off / the range's low end) to 2000, in the
/// actuator-channel order of protocol.md §4; unused channels 0. `time_usec` is the
/// simulation time (µs, wrapping at 2^32 as the field is 32 bits).
pub fn servo_output_raw(v: &Vehicle) -> MavMessage {
    servo_output_raw_of(command_fractions(v), v.clock_us)
}

/// SERVO_OUTPUT_RAW of motor commands given as fractions of full (0 → 1000 µs, 1 → 2000 µs;
/// the first 16) at simulation time `time_us`.
pub fn servo_output_raw_of(fractions: impl Iterator<Item = f64>, time_us: u64) -> MavMessage {
    let mut pwm = [0u16; 16];
    for (p, f) in pwm.iter_mut().zip(fractions) {
        *p = round_u16(1000.0 + 1000.0 * f.clamp(0.0, 1.0));
    }
    MavMessage::SERVO_OUTPUT_RAW(SERVO_OUTPUT_RAW_DATA {
        time_usec: time_us as u32,
        servo1_raw: pwm[0],
        servo2_raw: pwm[1],
        servo3_raw: pwm[2],
        servo4_raw: pwm[3],
        servo5_raw: pwm[4],
        servo6_raw: pwm[5],
        servo7_raw: pwm[6],
        servo8_raw: pwm[7],
        port: 0,
        servo9_raw: pwm[8],
        servo10_raw: pwm[9],
        servo11_raw: pwm[10],
        servo12_raw: pwm[11],
        servo13_raw: pwm[12],
        servo14_raw: pwm[13],
        servo15_raw: pwm[14],
        servo16_raw: pwm[15],
    })
}

/// The wind at the vehicle (velocity − air velocity), world NED, m/s, at simulation time.
pub fn wind_cov(v: &Vehicle) -> MavMessage {
    wind_cov_of(&v.task.kinematics(), v.clock_us)
}

/// WIND_COV of the wind at `k` (velocity − air velocity, world NED, m/s) at `time_usec`.
pub fn wind_cov_of(k: &Kinematics, time_usec: u64) -> MavMessage {
    let wind = crate::kinematics::enu_to_ned(&(k.velocity - k.air_velocity));
    MavMessage::WIND_COV(WIND_COV_DATA {
        time_usec,
        wind_x: wind.x as f32,
        wind_y: wind.y as f32,
        wind_z: wind.z as f32,
        var_horiz: 0.0,
        var_vert: 0.0,
        wind_alt: k.position.z as f32,
        horiz_accuracy: 0.0,
        vert_accuracy: 0.0,
    })
}

pub fn home_position(v: &Vehicle, home: &Home) -> MavMessage {
    home_position_of(home, v.clock_us)
}

/// HOME_POSITION of `home` (the local origin) at simulation time `time_usec`.
pub fn home_position_of(home: &Home, time_usec: u64) -> MavMessage {
    let g = home.global(&nalgebra::Vector3::zeros());
    MavMessage::HOME_POSITION(HOME_POSITION_DATA {
        latitude: g.lat,
        longitude: g.lon,
        altitude: g.alt_mm,
        x: 0.0,
        y: 0.0,
        z: 0.0,
        q: [1.0, 0.0, 0.0, 0.0],
        approach_x: 0.0,
        approach_y: 0.0,
        approach_z: 0.0,
        time_usec,
    })
}

/// SYS_STATUS with the battery: the lander's charge in percent; the quadrotor has no battery
/// model, so its battery is reported unknown (remaining −1, voltage UINT16_MAX).
pub fn sys_status(v: &Vehicle) -> MavMessage {
    sys_status_of(v.task.battery_fraction())
}

/// SYS_STATUS of a vehicle whose battery holds `battery` (a fraction of full; None: no
/// battery model).
pub fn sys_status_of(battery: Option<f64>) -> MavMessage {
    let (remaining, voltage) = match battery {
        Some(f) => {
            let percent = (f * 100.0).round().clamp(0.0, 100.0) as i8;
            // A nominal 4S pack: 16.8 V full, 13.2 V empty, linear in between.
            (
                percent,
                round_u16((13.2 + 3.6 * f.clamp(0.0, 1.0)) * 1000.0),
            )
        }
        None => (-1, u16::MAX),
    };
    let sensors = MavSysStatusSensor::empty();
    MavMessage::SYS_STATUS(SYS_STATUS_DATA {
        onboard_control_sensors_present: sensors,
        onboard_control_sensors_enabled: sensors,
        // 1 = healthy: nothing reports an error.
        onboard_control_sensors_health: MavSysStatusSensor::all(),
        load: 0,
        voltage_battery: voltage,
        current_battery: -1,
        drop_rate_comm: 0,
        errors_comm: 0,
        errors_count1: 0,
        errors_count2: 0,
        errors_count3: 0,
        errors_count4: 0,
        battery_remaining: remaining,
        onboard_control_sensors_present_extended: MavSysStatusSensorExtended::empty(),
        onboard_control_sensors_enabled_extended: MavSysStatusSensorExtended::empty(),
        onboard_control_sensors_health_extended: MavSysStatusSensorExtended::all(),
    })
}

/// flyloop's version as MAVLink's flight_sw_version: major, minor, patch, type (255 = release).
fn software_version() -> u32 {
    let part = |s: &str| s.parse::<u32>().unwrap_or(0) & 0xFF;
    let major = part(env!("CARGO_PKG_VERSION_MAJOR"));
    let minor = part(env!("CARGO_PKG_VERSION_MINOR"));
    let patch = part(env!("CARGO_PKG_VERSION_PATCH"));
    (major << 24) | (minor << 16) | (patch << 8) | 0xFF
}

pub fn autopilot_version(v: &Vehicle) -> MavMessage {
    autopilot_version_of(v.system_id)
}

/// AUTOPILOT_VERSION of system `system_id` (its uid).
pub fn autopilot_version_of(system_id: u8) -> MavMessage {
    let capabilities = MavProtocolCapability::MAV_PROTOCOL_CAPABILITY_MAVLINK2
        | MavProtocolCapability::MAV_PROTOCOL_CAPABILITY_PARAM_ENCODE_C_CAST;
    MavMessage::AUTOPILOT_VERSION(AUTOPILOT_VERSION_DATA {
        capabilities,
        uid: u64::from(system_id),
        flight_sw_version: software_version(),
        middleware_sw_version: 0,
        os_sw_version: 0,
        board_version: 0,
        vendor_id: 0,
        product_id: 0,
        flight_custom_version: [0; 8],
        middleware_custom_version: [0; 8],
        os_custom_version: [0; 8],
        uid2: [0; 18],
    })
}

/// STATUSTEXT messages carrying `text`: one if it fits in 50 bytes, else chunks with a common
/// non-zero `id` and `chunk_seq` 0, 1, … (the last chunk shorter than 50 bytes, or followed
/// by an empty one, ends the text, as the MAVLink spec says).
pub fn statustext(severity: MavSeverity, text: &str, id: u16) -> Vec<MavMessage> {
    let bytes = text.as_bytes();
    let make = |chunk: &[u8], id: u16, seq: u8| {
        let mut t = [0u8; 50];
        t[..chunk.len()].copy_from_slice(chunk);
        MavMessage::STATUSTEXT(STATUSTEXT_DATA {
            severity,
            text: CharArray::from(t),
            id,
            chunk_seq: seq,
        })
    };
    if bytes.len() <= 50 {
        return vec![make(bytes, 0, 0)];
    }
    let mut out: Vec<MavMessage> = bytes
        .chunks(50)
        .zip(0u8..)
        .map(|(c, seq)| make(c, id, seq))
        .collect();
    if bytes.len() % 50 == 0 {
        out.push(make(&[], id, out.len() as u8));
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use flyloop_core::quadrotor::Frame;
    use flyloop_core::tasks::registry::{TaskConfig, TaskKind};

    fn hover() -> Vehicle {
        let mut config = TaskConfig::default();
        config.flight.start_attitude_range = 0.0;
        Vehicle::new(1, TaskKind::Hover, config, 3).unwrap()
    }

    #[test]
    fn hil_state_of_a_level_quadrotor_facing_east() {
        let v = hover();
        let MavMessage::HIL_STATE_QUATERNION(s) = hil_state_quaternion(&v, &Home::default()) else {
            unreachable!()
        };
        let h = std::f32::consts::FRAC_1_SQRT_2;
        assert_eq!(s.attitude_quaternion, [h, 0.0, 0.0, h]);
        assert_eq!(s.time_usec, 0);
        assert_eq!(s.alt, 488_000 + 1_500);
        assert_eq!((s.vx, s.vy, s.vz), (0, 0, 0));
        // At rest, hover thrust balances gravity: the accelerometer reads about −1 g.
        assert!((i32::from(s.zacc) + 1000).abs() <= 3, "{}", s.zacc);
    }

    #[test]
    fn motor_commands_as_pwm_and_the_wind_at_rest() {
        let mut v = hover();
        v.set_controls(&[0.0, 0.25, 0.5, 1.0]).unwrap();
        let MavMessage::SERVO_OUTPUT_RAW(s) = servo_output_raw(&v) else {
            unreachable!()
        };
        let pwm = [s.servo1_raw, s.servo2_raw, s.servo3_raw, s.servo4_raw];
        assert_eq!((pwm, s.servo5_raw), ([1000, 1250, 1500, 2000], 0));
        // At rest the wind is all the airspeed there is (the default wind is horizontal).
        let MavMessage::WIND_COV(w) = wind_cov(&v) else {
            unreachable!()
        };
        let MavMessage::HIL_STATE_QUATERNION(h) = hil_state_quaternion(&v, &Home::default()) else {
            unreachable!()
        };
        let speed = (w.wind_x.powi(2) + w.wind_y.powi(2)).sqrt();
        assert!(speed > 0.5 && w.wind_z == 0.0, "{w:?}");
        assert!(
            (speed * 100.0 - f32::from(h.true_airspeed)).abs() <= 1.0,
            "{w:?} {h:?}"
        );
    }

    #[test]
    fn heartbeat_flags_start_from_empty() {
        let MavMessage::HEARTBEAT(h) = heartbeat(&hover(), Status::Standby) else {
            unreachable!()
        };
        assert_eq!(h.base_mode, MavModeFlag::empty());
        assert_eq!(h.mavtype, MavType::MAV_TYPE_QUADROTOR);
        let MavMessage::HEARTBEAT(h) = heartbeat(&hover(), Status::Active) else {
            unreachable!()
        };
        assert_eq!(h.base_mode, MavModeFlag::MAV_MODE_FLAG_SAFETY_ARMED);
    }

    #[test]
    fn heartbeat_names_the_frame_by_its_rotor_count() {
        for (name, expected) in [
            ("quad_x", MavType::MAV_TYPE_QUADROTOR),
            ("hexa_x", MavType::MAV_TYPE_HEXAROTOR),
            ("octo_x", MavType::MAV_TYPE_OCTOROTOR),
        ] {
            let config = TaskConfig {
                frame: Frame::named(name).unwrap(),
                ..TaskConfig::default()
            };
            let v = Vehicle::new(1, TaskKind::Hover, config, 3).unwrap();
            let MavMessage::HEARTBEAT(h) = heartbeat(&v, Status::Standby) else {
                unreachable!()
            };
            assert_eq!(h.mavtype, expected, "{name}");
        }
        assert_eq!(multirotor_mav_type(12), MavType::MAV_TYPE_DODECAROTOR);
        assert_eq!(multirotor_mav_type(5), MavType::MAV_TYPE_GENERIC_MULTIROTOR);
        let lander = Vehicle::new(1, TaskKind::Landing, TaskConfig::default(), 0).unwrap();
        assert_eq!(mav_type(&lander), MavType::MAV_TYPE_GENERIC);
    }

    #[test]
    fn long_status_texts_are_chunked() {
        let text = "x".repeat(120);
        let msgs = statustext(MavSeverity::MAV_SEVERITY_ERROR, &text, 7);
        assert_eq!(msgs.len(), 3);
        let MavMessage::STATUSTEXT(last) = &msgs[2] else {
            unreachable!()
        };
        assert_eq!((last.id, last.chunk_seq), (7, 2));
        assert_eq!(statustext(MavSeverity::MAV_SEVERITY_INFO, "ok", 7).len(), 1);
        assert_eq!(
            statustext(MavSeverity::MAV_SEVERITY_INFO, &"y".repeat(100), 1).len(),
            3
        );
    }

    #[test]
    fn the_lander_reports_its_battery_and_the_quadrotor_none() {
        let MavMessage::SYS_STATUS(s) = sys_status(&hover()) else {
            unreachable!()
        };
        assert_eq!((s.battery_remaining, s.voltage_battery), (-1, u16::MAX));
        let lander = Vehicle::new(1, TaskKind::Landing, TaskConfig::default(), 0).unwrap();
        let MavMessage::SYS_STATUS(s) = sys_status(&lander) else {
            unreachable!()
        };
        assert_eq!((s.battery_remaining, s.voltage_battery), (100, 16_800));
    }
}
