//! PX4's failure injection codes (MAV_CMD_INJECT_FAILURE: param1 FAILURE_UNIT, param2
//! FAILURE_TYPE, param3 instance) as faults of the catalogue, so a MAVLink control link can
//! drive the same fault path the config files and the gym do. PX4 numbers motor instances
//! from 1, 0 = all; so does [`FaultSpec::motor`].

use super::catalogue::{FaultKind, SensorId};
use super::spec::{FaultSpec, MAX_MOTOR};
use crate::error::ParamError;

/// MAVLink FAILURE_UNIT values (common.xml).
pub mod unit {
    pub const SENSOR_GYRO: u8 = 0;
    pub const SENSOR_ACCEL: u8 = 1;
    pub const SENSOR_MAG: u8 = 2;
    pub const SENSOR_BARO: u8 = 3;
    pub const SENSOR_GPS: u8 = 4;
    pub const SYSTEM_BATTERY: u8 = 100;
    pub const SYSTEM_MOTOR: u8 = 101;
}

/// MAVLink FAILURE_TYPE values (common.xml).
pub mod kind {
    pub const OK: u8 = 0;
    pub const OFF: u8 = 1;
    pub const STUCK: u8 = 2;
    pub const GARBAGE: u8 = 3;
    pub const WRONG: u8 = 4;
    pub const SLOW: u8 = 5;
    pub const DELAYED: u8 = 6;
    pub const INTERMITTENT: u8 = 7;
}

/// What an inject command asks for: a fault to fire now, or clearing the unit's faults
/// (FAILURE_TYPE_OK).
#[derive(Debug, Clone, PartialEq)]
pub enum Injection {
    Fire(FaultSpec),
    Clear { motor: u8, sensor: Option<SensorId> },
}

impl Injection {
    /// What the injection does, as the STATUSTEXT says it: `fault injected: motor_off:1`,
    /// `fault cleared: gps`, `fault cleared: all motors`, `fault cleared: motor 2`.
    pub fn describe(&self) -> String {
        match self {
            Injection::Fire(spec) => format!("fault injected: {}", spec.label()),
            Injection::Clear {
                sensor: Some(s), ..
            } => format!("fault cleared: {}", s.name()),
            Injection::Clear { motor: 0, .. } => "fault cleared: all motors".to_string(),
            Injection::Clear { motor, .. } => format!("fault cleared: motor {motor}"),
        }
    }
}

/// The fault of PX4 code (`unit`, `failure`, `instance`) on a frame of `rotors`: an error
/// naming the field for a code the catalogue has no fault for.
pub fn from_px4(
    unit: u8,
    failure: u8,
    instance: u8,
    rotors: usize,
) -> Result<Injection, ParamError> {
    let sensor = match unit {
        unit::SENSOR_GYRO => Some(SensorId::Gyro),
        unit::SENSOR_ACCEL => Some(SensorId::Accel),
        unit::SENSOR_MAG => Some(SensorId::Mag),
        unit::SENSOR_BARO => Some(SensorId::Baro),
        unit::SENSOR_GPS => Some(SensorId::Gps),
        _ => None,
    };
    let unsupported = || {
        ParamError::Parse(format!(
            "failure_type {failure} is not supported for failure_unit {unit}"
        ))
    };
    if unit == unit::SYSTEM_MOTOR && (usize::from(instance) > rotors || instance > MAX_MOTOR) {
        return Err(ParamError::Parse(format!(
            "instance {instance}: the frame has motors 1 to {rotors} (0 = all)"
        )));
    }
    if failure == kind::OK {
        return match (unit, sensor) {
            (unit::SYSTEM_MOTOR, _) => Ok(Injection::Clear {
                motor: instance,
                sensor: None,
            }),
            (_, Some(s)) => Ok(Injection::Clear {
                motor: 0,
                sensor: Some(s),
            }),
            _ => Err(ParamError::Parse(format!(
                "failure_unit {unit} is not supported"
            ))),
        };
    }
    let fault_kind = match (unit, sensor, failure) {
        (unit::SYSTEM_MOTOR, _, kind::OFF) => FaultKind::MotorOff,
        (unit::SYSTEM_MOTOR, _, kind::STUCK) => FaultKind::MotorStuck,
        (unit::SYSTEM_MOTOR, _, kind::SLOW) => FaultKind::MotorLag,
        (unit::SYSTEM_MOTOR, _, kind::WRONG) => FaultKind::MotorEffectiveness,
        (unit::SYSTEM_BATTERY, _, kind::WRONG | kind::OFF) => FaultKind::LowBattery,
        (_, Some(_), kind::OFF) => FaultKind::SensorOff,
        (_, Some(_), kind::STUCK) => FaultKind::SensorStuck,
        (_, Some(_), kind::WRONG) => FaultKind::SensorBias,
        (_, Some(_), kind::GARBAGE) => FaultKind::SensorNoise,
        (_, Some(_), kind::DELAYED) => FaultKind::SensorDelay,
        (unit::SYSTEM_MOTOR | unit::SYSTEM_BATTERY, _, _) | (_, Some(_), _) => {
            return Err(unsupported());
        }
        _ => {
            return Err(ParamError::Parse(format!(
                "failure_unit {unit} is not supported"
            )));
        }
    };
    let mut fault = FaultSpec::new(fault_kind);
    fault.sensor = sensor;
    if unit == unit::SYSTEM_MOTOR {
        fault.motor = instance;
    }
    if fault_kind == FaultKind::MotorEffectiveness {
        // PX4's "wrong" motor: half its thrust.
        fault.values[0] = 0.5;
    }
    if fault_kind == FaultKind::SensorNoise {
        fault.values[0] = 10.0;
    }
    if fault_kind == FaultKind::SensorBias {
        fault.values[0] = 1.0;
    }
    Ok(Injection::Fire(fault))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn px4_codes_map_onto_the_catalogue_and_unknown_ones_are_named() {
        let Ok(Injection::Fire(f)) = from_px4(unit::SYSTEM_MOTOR, kind::OFF, 1, 4) else {
            panic!("motor off");
        };
        assert_eq!((f.kind, f.motor), (FaultKind::MotorOff, 1));
        let Ok(Injection::Fire(f)) = from_px4(unit::SENSOR_GPS, kind::OFF, 0, 4) else {
            panic!("gps off");
        };
        assert_eq!(
            (f.kind, f.sensor),
            (FaultKind::SensorOff, Some(SensorId::Gps))
        );
        assert_eq!(
            from_px4(unit::SENSOR_BARO, kind::OK, 0, 4),
            Ok(Injection::Clear {
                motor: 0,
                sensor: Some(SensorId::Baro)
            })
        );
        let e = from_px4(unit::SYSTEM_MOTOR, kind::OFF, 5, 4)
            .unwrap_err()
            .to_string();
        assert!(e.contains("instance 5") && e.contains("1 to 4"), "{e}");
        let e = from_px4(unit::SENSOR_GPS, kind::INTERMITTENT, 0, 4)
            .unwrap_err()
            .to_string();
        assert!(e.contains("failure_type 7"), "{e}");
        let e = from_px4(42, kind::OFF, 0, 4).unwrap_err().to_string();
        assert!(e.contains("failure_unit 42"), "{e}");
    }
}
