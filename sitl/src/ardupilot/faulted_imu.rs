//! ArduPilot's IMU through the sensor faults, shared by ArduPilot mode and the fleet's
//! ArduPilot members. ArduPilot needs a gyro and an accel value in every JSON frame (it drops
//! a frame without them), so an off one repeats its last value.

use flyloop_core::faults::Delivered;
use flyloop_core::sensors::{ImuReading, SensorReading, baro};
use flyloop_core::vehicle::Kinematics;
use nalgebra::Vector3;

/// `imu` (the vehicle at `k`) after `faults` (the sensor path on a reading: changes it in
/// place and says what it delivers); `last` is the sample last sent this way, updated.
pub fn apply(
    imu: ImuReading,
    k: &Kinematics,
    last: &mut Option<ImuReading>,
    faults: impl FnOnce(&mut SensorReading) -> Delivered,
) -> ImuReading {
    let mut r = SensorReading {
        imu,
        mag: Vector3::zeros(),
        baro: baro::reading(k.position.z, 0.0),
    };
    let d = faults(&mut r);
    let held = last.unwrap_or(imu);
    let out = ImuReading {
        accel: if d.accel { r.imu.accel } else { held.accel },
        gyro: if d.gyro { r.imu.gyro } else { held.gyro },
    };
    *last = Some(out);
    out
}
