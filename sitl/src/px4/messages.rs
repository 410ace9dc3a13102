//! The messages PX4 reads from its simulator, built from the core's sensor readings
//! (units as PX4's simulator_mavlink reads them; see docs/protocol.md).

use crate::kinematics::{round_i16, round_i32, round_u16};
use flyloop_core::faults::Delivered;
use flyloop_core::sensors::{GpsFix, ImuReading, SensorReading};
use mavlink::dialects::common::{HIL_GPS_DATA, HIL_SENSOR_DATA, HilSensorUpdatedFlags, MavMessage};

/// Every field group HIL_SENSOR carries each step: accel, gyro, mag and the three baro fields
/// (PX4 reads a group only when all of its bits are set). No differential pressure.
pub fn sensor_fields() -> HilSensorUpdatedFlags {
    use HilSensorUpdatedFlags as F;
    F::HIL_SENSOR_UPDATED_XACC
        | F::HIL_SENSOR_UPDATED_YACC
        | F::HIL_SENSOR_UPDATED_ZACC
        | F::HIL_SENSOR_UPDATED_XGYRO
        | F::HIL_SENSOR_UPDATED_YGYRO
        | F::HIL_SENSOR_UPDATED_ZGYRO
        | F::HIL_SENSOR_UPDATED_XMAG
        | F::HIL_SENSOR_UPDATED_YMAG
        | F::HIL_SENSOR_UPDATED_ZMAG
        | F::HIL_SENSOR_UPDATED_ABS_PRESSURE
        | F::HIL_SENSOR_UPDATED_PRESSURE_ALT
        | F::HIL_SENSOR_UPDATED_TEMPERATURE
}

/// The field groups of a sample whose off sensors deliver nothing (their bits cleared: PX4
/// reads no new value of them).
pub fn delivered_fields(d: &Delivered) -> HilSensorUpdatedFlags {
    use HilSensorUpdatedFlags as F;
    let mut fields = sensor_fields();
    let groups = [
        (
            d.accel,
            F::HIL_SENSOR_UPDATED_XACC | F::HIL_SENSOR_UPDATED_YACC | F::HIL_SENSOR_UPDATED_ZACC,
        ),
        (
            d.gyro,
            F::HIL_SENSOR_UPDATED_XGYRO | F::HIL_SENSOR_UPDATED_YGYRO | F::HIL_SENSOR_UPDATED_ZGYRO,
        ),
        (
            d.mag,
            F::HIL_SENSOR_UPDATED_XMAG | F::HIL_SENSOR_UPDATED_YMAG | F::HIL_SENSOR_UPDATED_ZMAG,
        ),
        (
            d.baro,
            F::HIL_SENSOR_UPDATED_ABS_PRESSURE
                | F::HIL_SENSOR_UPDATED_PRESSURE_ALT
                | F::HIL_SENSOR_UPDATED_TEMPERATURE,
        ),
    ];
    for (delivered, bits) in groups {
        if !delivered {
            fields.remove(bits);
        }
    }
    fields
}

/// HIL_SENSOR at simulation time `time_usec` (µs): accel m/s², gyro rad/s, mag gauss, all body
/// FRD; pressure hPa, altitude m, temperature °C.
pub fn hil_sensor(r: &SensorReading, time_usec: u64) -> MavMessage {
    hil_sensor_delivered(r, time_usec, sensor_fields())
}

/// HIL_SENSOR claiming only `fields` (a faulted sample: see [`delivered_fields`]).
pub fn hil_sensor_delivered(
    r: &SensorReading,
    time_usec: u64,
    fields: HilSensorUpdatedFlags,
) -> MavMessage {
    let (m, b) = (r.mag, r.baro);
    MavMessage::HIL_SENSOR(HIL_SENSOR_DATA {
        xmag: m.x as f32,
        ymag: m.y as f32,
        zmag: m.z as f32,
        abs_pressure: b.pressure_hpa as f32,
        diff_pressure: 0.0,
        pressure_alt: b.pressure_altitude as f32,
        temperature: b.temperature_c as f32,
        fields_updated: fields,
        ..hil_imu(&r.imu, time_usec)
    })
}

/// The IMU part of HIL_SENSOR (accel m/s², gyro rad/s, body FRD), flagged alone; the other
/// fields 0.
pub fn hil_imu(imu: &ImuReading, time_usec: u64) -> HIL_SENSOR_DATA {
    use HilSensorUpdatedFlags as F;
    let (a, g) = (imu.accel, imu.gyro);
    HIL_SENSOR_DATA {
        time_usec,
        xacc: a.x as f32,
        yacc: a.y as f32,
        zacc: a.z as f32,
        xgyro: g.x as f32,
        ygyro: g.y as f32,
        zgyro: g.z as f32,
        fields_updated: F::HIL_SENSOR_UPDATED_XACC
            | F::HIL_SENSOR_UPDATED_YACC
            | F::HIL_SENSOR_UPDATED_ZACC
            | F::HIL_SENSOR_UPDATED_XGYRO
            | F::HIL_SENSOR_UPDATED_YGYRO
            | F::HIL_SENSOR_UPDATED_ZGYRO,
        ..Default::default()
    }
}

/// HIL_GPS for `fix`, stamped `time_usec` (µs since the UNIX epoch): lat/lon degE7, alt mm
/// MSL, eph/epv cm, velocities cm/s NED, course cdeg (65535 = unknown), 3D fix.
pub fn hil_gps(fix: &GpsFix, time_usec: u64) -> MavMessage {
    let p = fix.position;
    let v = fix.velocity_ned * 100.0;
    // 65535 means "unknown" for eph, epv, vel and cog: a known value stays below it.
    let known_u16 = |x: f64| round_u16(x).min(u16::MAX - 1);
    MavMessage::HIL_GPS(HIL_GPS_DATA {
        time_usec,
        lat: round_i32(p.latitude_deg * 1e7),
        lon: round_i32(p.longitude_deg * 1e7),
        alt: round_i32(p.altitude_m * 1000.0),
        eph: known_u16(fix.eph * 100.0),
        epv: known_u16(fix.epv * 100.0),
        vel: known_u16(fix.ground_speed * 100.0),
        vn: round_i16(v.x),
        ve: round_i16(v.y),
        vd: round_i16(v.z),
        cog: fix
            .course_deg
            .map_or(u16::MAX, |c| round_u16(c * 100.0).min(35_999)),
        fix_type: 3,
        satellites_visible: fix.satellites,
        id: 0,
        yaw: 0,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use flyloop_core::sensors::{Geodetic, gps};
    use nalgebra::Vector3;

    #[test]
    fn gps_units_are_mavlinks() {
        let home = Geodetic {
            latitude_deg: 47.397742,
            longitude_deg: 8.545594,
            altitude_m: 488.0,
        };
        let fix = gps::fix(
            &home,
            0.0,
            &Vector3::new(0.0, 0.0, 5.0),
            &Vector3::new(-1.0, 0.0, 0.5),
            (0.3, 0.4),
            12,
        );
        let MavMessage::HIL_GPS(g) = hil_gps(&fix, 7) else {
            panic!("not HIL_GPS")
        };
        assert_eq!((g.lat, g.lon, g.alt), (473_977_420, 85_455_940, 493_000));
        assert_eq!((g.eph, g.epv, g.vel), (30, 40, 100));
        // Flying west, climbing: vn 0, ve −100, vd −50 cm/s, course 270°.
        assert_eq!((g.vn, g.ve, g.vd, g.cog), (0, -100, -50, 27_000));
        assert_eq!((g.fix_type, g.satellites_visible, g.time_usec), (3, 12, 7));
    }

    #[test]
    fn an_off_sensor_loses_its_field_bits() {
        let d = Delivered {
            baro: false,
            ..Delivered::ALL
        };
        assert_eq!(delivered_fields(&Delivered::ALL), sensor_fields());
        assert_eq!(delivered_fields(&d).bits(), 0x7 | 0x38 | 0x1C0);
    }

    #[test]
    fn hil_sensor_claims_accel_gyro_mag_and_baro() {
        assert_eq!(sensor_fields().bits(), 0x7 | 0x38 | 0x1C0 | 0x1A00);
    }
}
