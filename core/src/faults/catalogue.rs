//! The fault catalogue: every fault kind, what it acts on (a motor, a sensor, the battery, the
//! air) and its parameters, each with unit, bounds and default, in one table. Parsing,
//! validation, randomisation ranges and docs/faults.md all read these rows.

use crate::error::{ParamError, Role};

/// One parameter of a fault kind. Bounds are inclusive.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FieldSpec {
    pub name: &'static str,
    pub unit: &'static str,
    pub min: f64,
    pub max: f64,
    pub default: f64,
    pub description: &'static str,
}

impl FieldSpec {
    /// `value` if it lies in the bounds, else the error naming this field and them.
    pub fn check(&self, value: f64) -> Result<f64, ParamError> {
        if value >= self.min && value <= self.max {
            Ok(value)
        } else {
            Err(ParamError::OutOfRange {
                role: Role::Parameter,
                name: self.name,
                value,
                min: self.min,
                max: self.max,
                unit: self.unit,
            })
        }
    }
}

/// What a fault acts on, besides its own parameters.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Target {
    /// A motor, by PX4's instance numbering (`motor`: 1 = the first rotor of the frame's
    /// motor order, 0 = every rotor).
    Motor,
    /// One sensor (`sensor`: gyro, accel, mag, baro or gps).
    Sensor,
    /// The vehicle as a whole (battery, air, GPS-only faults).
    Vehicle,
    /// The SITL's link to whoever flies the vehicle: the autopilot's (PX4, ArduPilot) or
    /// the lockstep client's. Only the SITL has one: the gym and the FMUs refuse these.
    Link,
}

/// The sensors a sensor fault may name.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
pub enum SensorId {
    Gyro,
    Accel,
    Mag,
    Baro,
    Gps,
}

impl SensorId {
    pub const ALL: [SensorId; 5] = [
        SensorId::Gyro,
        SensorId::Accel,
        SensorId::Mag,
        SensorId::Baro,
        SensorId::Gps,
    ];

    pub fn name(self) -> &'static str {
        match self {
            SensorId::Gyro => "gyro",
            SensorId::Accel => "accel",
            SensorId::Mag => "mag",
            SensorId::Baro => "baro",
            SensorId::Gps => "gps",
        }
    }

    /// The sensor named `name`, or the error listing the known ones.
    pub fn from_name(name: &str) -> Result<SensorId, ParamError> {
        SensorId::ALL
            .into_iter()
            .find(|s| s.name() == name)
            .ok_or_else(|| {
                ParamError::UnknownName(format!(
                    "{name}` as a fault's `sensor`; sensors: `gyro`, `accel`, `mag`, `baro`, `gps"
                ))
            })
    }

    /// Unit of the sensor's value (a bias is in it; a drift in it per second).
    pub fn unit(self) -> &'static str {
        match self {
            SensorId::Gyro => "rad/s",
            SensorId::Accel => "m/s²",
            SensorId::Mag => "gauss",
            SensorId::Baro => "m",
            SensorId::Gps => "m",
        }
    }
}

/// Every fault kind of the catalogue.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
pub enum FaultKind {
    MotorEffectiveness,
    MotorOff,
    MotorStuck,
    MotorLag,
    PropellerLoss,
    PropellerDamage,
    SensorOff,
    SensorStuck,
    SensorBias,
    SensorNoise,
    SensorDelay,
    GpsJump,
    GpsDegraded,
    Battery,
    LowBattery,
    Gust,
    WindShear,
    LinkLoss,
    LinkDelay,
}

/// A fault kind's row: name, target, parameters and what it does.
#[derive(Debug)]
pub struct KindSpec {
    pub kind: FaultKind,
    pub name: &'static str,
    pub target: Target,
    pub fields: &'static [FieldSpec],
    pub effect: &'static str,
}

const fn field(
    name: &'static str,
    unit: &'static str,
    min: f64,
    max: f64,
    default: f64,
    description: &'static str,
) -> FieldSpec {
    FieldSpec {
        name,
        unit,
        min,
        max,
        default,
        description,
    }
}

const EFFECTIVENESS: FieldSpec = field(
    "effectiveness",
    "1",
    0.0,
    1.0,
    1.0,
    "Fraction of the healthy thrust and torque the rotor gives at the same command",
);
const STUCK_COMMAND: FieldSpec = field(
    "command",
    "1",
    0.0,
    1.0,
    0.5,
    "Command the motor stays at, whatever it is sent",
);
const LAG: FieldSpec = field(
    "time_constant",
    "s",
    1e-4,
    10.0,
    0.1,
    "Time constant of the first-order lag added between the command and the motor",
);
const THRUST_LOSS: FieldSpec = field(
    "thrust_loss",
    "1",
    0.0,
    1.0,
    0.2,
    "Fraction of the rotor's thrust and torque lost with the damaged blade",
);
const IMBALANCE: FieldSpec = field(
    "imbalance",
    "kg·m",
    0.0,
    1e-3,
    2e-6,
    "Mass imbalance of the damaged propeller (mass × its offset from the axis)",
);
const ROTOR_SPEED: FieldSpec = field(
    "max_rotor_speed",
    "rad/s",
    1.0,
    1e4,
    1000.0,
    "Rotor speed at motor state 1 (the speed is proportional to the motor state)",
);
const BIAS: FieldSpec = field(
    "bias",
    "sensor unit",
    -1e4,
    1e4,
    0.0,
    "Constant bias added to every axis (gyro rad/s, accel m/s², mag gauss, baro m, gps m)",
);
const DRIFT: FieldSpec = field(
    "drift",
    "sensor unit/s",
    -1e3,
    1e3,
    0.0,
    "Rate at which the bias grows from the time the fault fires",
);
const NOISE_FACTOR: FieldSpec = field(
    "factor",
    "1",
    1.0,
    1e3,
    2.0,
    "The sensor's noise standard deviation is multiplied by this",
);
const DELAY: FieldSpec = field(
    "delay",
    "s",
    0.0,
    10.0,
    0.1,
    "Age of the samples the sensor delivers",
);
const EAST: FieldSpec = field("east", "m", -1e5, 1e5, 0.0, "Offset east");
const NORTH: FieldSpec = field("north", "m", -1e5, 1e5, 0.0, "Offset north");
const UP: FieldSpec = field("up", "m", -1e5, 1e5, 0.0, "Offset up");
const SATELLITES: FieldSpec = field("satellites", "", 0.0, 255.0, 4.0, "Satellites in view");
const EPH: FieldSpec = field(
    "eph",
    "m",
    0.01,
    1e4,
    5.0,
    "Horizontal accuracy reported; the horizontal noise grows by eph / gps_eph",
);
const EPV: FieldSpec = field(
    "epv",
    "m",
    0.01,
    1e4,
    8.0,
    "Vertical accuracy reported; the vertical noise grows by epv / gps_epv",
);
const CAPACITY: FieldSpec = field(
    "capacity",
    "Ah",
    0.01,
    1e3,
    5.0,
    "Charge of the full battery",
);
const CELLS: FieldSpec = field("cells", "", 1.0, 24.0, 4.0, "Cells in series");
const RESISTANCE: FieldSpec = field(
    "internal_resistance",
    "Ω",
    0.0,
    10.0,
    0.02,
    "Internal resistance of the pack",
);
const MAX_CURRENT: FieldSpec = field(
    "max_current",
    "A",
    0.0,
    1e4,
    120.0,
    "Current drawn with every motor at state 1 (the current goes with the motor state cubed)",
);
const IDLE_CURRENT: FieldSpec = field(
    "idle_current",
    "A",
    0.0,
    1e3,
    0.5,
    "Current of the electronics",
);
const CHARGE: FieldSpec = field("charge", "1", 0.0, 1.0, 1.0, "State of charge at the start");
const LOW_CHARGE: FieldSpec = field(
    "charge",
    "1",
    0.0,
    1.0,
    0.15,
    "State of charge the battery drops to",
);
const GUST_EAST: FieldSpec = field("east", "m/s", -100.0, 100.0, 0.0, "Gust amplitude east");
const GUST_NORTH: FieldSpec = field("north", "m/s", -100.0, 100.0, 5.0, "Gust amplitude north");
const GUST_UP: FieldSpec = field("up", "m/s", -100.0, 100.0, 0.0, "Gust amplitude up");
const GUST_RISE: FieldSpec = field(
    "rise_time",
    "s",
    1e-3,
    100.0,
    1.0,
    "Time of the 1−cos rise to the full amplitude (the gust length d_m over the airspeed)",
);
const GUST_HOLD: FieldSpec = field(
    "hold",
    "s",
    0.0,
    1e4,
    0.0,
    "Time at the full amplitude before the mirrored fall",
);
const SHEAR_SPEED: FieldSpec = field(
    "speed",
    "m/s",
    0.0,
    100.0,
    5.0,
    "Wind speed at the reference height (MIL-F-8785C: W20 at 20 ft)",
);
const SHEAR_DIRECTION: FieldSpec = field(
    "direction",
    "rad",
    -7.0,
    7.0,
    0.0,
    "Direction the wind blows toward, from +x (east) toward +y (north)",
);
const SHEAR_HEIGHT: FieldSpec = field(
    "reference_height",
    "m",
    0.1,
    1e3,
    6.096,
    "Height of the reference speed (20 ft)",
);
const SHEAR_ROUGHNESS: FieldSpec = field(
    "roughness",
    "m",
    1e-4,
    10.0,
    0.0457,
    "Surface roughness length z0 (MIL-F-8785C: 0.15 ft for category C)",
);

const LINK_DELAY: FieldSpec = field(
    "delay",
    "s",
    1e-3,
    10.0,
    0.2,
    "Age of what the link delivers: the samples (or replies) reach the other side this late",
);

/// The catalogue, one row per kind.
pub static CATALOGUE: [KindSpec; 19] = [
    KindSpec {
        kind: FaultKind::MotorEffectiveness,
        name: "motor_effectiveness",
        target: Target::Motor,
        fields: &[EFFECTIVENESS],
        effect: "Thrust and reaction torque × effectiveness at the same command (the command reaching the motor × √effectiveness)",
    },
    KindSpec {
        kind: FaultKind::MotorOff,
        name: "motor_off",
        target: Target::Motor,
        fields: &[],
        effect: "The motor gets command 0 and spins down with its time constant",
    },
    KindSpec {
        kind: FaultKind::MotorStuck,
        name: "motor_stuck",
        target: Target::Motor,
        fields: &[STUCK_COMMAND],
        effect: "The motor gets `command` whatever it is sent",
    },
    KindSpec {
        kind: FaultKind::MotorLag,
        name: "motor_lag",
        target: Target::Motor,
        fields: &[LAG],
        effect: "A first-order lag of `time_constant` between the command and the motor (on top of the motor's own)",
    },
    KindSpec {
        kind: FaultKind::PropellerLoss,
        name: "propeller_loss",
        target: Target::Motor,
        fields: &[],
        effect: "The propeller is gone: no thrust, no torque",
    },
    KindSpec {
        kind: FaultKind::PropellerDamage,
        name: "propeller_damage",
        target: Target::Motor,
        fields: &[THRUST_LOSS, IMBALANCE, ROTOR_SPEED],
        effect: "Thrust and torque × (1 − thrust_loss), and an imbalance force imbalance·Ω² turning at the rotor speed Ω, which the accelerometer sees",
    },
    KindSpec {
        kind: FaultKind::SensorOff,
        name: "sensor_off",
        target: Target::Sensor,
        fields: &[],
        effect: "The sensor delivers nothing",
    },
    KindSpec {
        kind: FaultKind::SensorStuck,
        name: "sensor_stuck",
        target: Target::Sensor,
        fields: &[],
        effect: "The sensor repeats the sample it gave when the fault fired",
    },
    KindSpec {
        kind: FaultKind::SensorBias,
        name: "sensor_bias",
        target: Target::Sensor,
        fields: &[BIAS, DRIFT],
        effect: "bias + drift·(t − t_fire) added to every axis",
    },
    KindSpec {
        kind: FaultKind::SensorNoise,
        name: "sensor_noise",
        target: Target::Sensor,
        fields: &[NOISE_FACTOR],
        effect: "The noise's standard deviation × factor (independent noise of σ·√(factor² − 1) added)",
    },
    KindSpec {
        kind: FaultKind::SensorDelay,
        name: "sensor_delay",
        target: Target::Sensor,
        fields: &[DELAY],
        effect: "The sensor delivers the sample taken `delay` ago",
    },
    KindSpec {
        kind: FaultKind::GpsJump,
        name: "gps_jump",
        target: Target::Vehicle,
        fields: &[EAST, NORTH, UP],
        effect: "The GPS position jumps by (east, north, up) while the fault is active",
    },
    KindSpec {
        kind: FaultKind::GpsDegraded,
        name: "gps_degraded",
        target: Target::Vehicle,
        fields: &[SATELLITES, EPH, EPV],
        effect: "Fewer satellites and worse reported accuracy; the position noise grows in proportion",
    },
    KindSpec {
        kind: FaultKind::Battery,
        name: "battery",
        target: Target::Vehicle,
        fields: &[
            CAPACITY,
            CELLS,
            RESISTANCE,
            MAX_CURRENT,
            IDLE_CURRENT,
            CHARGE,
        ],
        effect: "A battery: open-circuit voltage from the charge, sag I·R under load; the motors' speed × min(1, V / V_nominal)",
    },
    KindSpec {
        kind: FaultKind::LowBattery,
        name: "low_battery",
        target: Target::Vehicle,
        fields: &[LOW_CHARGE],
        effect: "The battery's charge drops to `charge` (a default battery if none is given)",
    },
    KindSpec {
        kind: FaultKind::Gust,
        name: "gust",
        target: Target::Vehicle,
        fields: &[GUST_EAST, GUST_NORTH, GUST_UP, GUST_RISE, GUST_HOLD],
        effect: "MIL-F-8785C discrete gust: v = A/2·(1 − cos(π t / rise_time)), held, then the mirrored fall",
    },
    KindSpec {
        kind: FaultKind::WindShear,
        name: "wind_shear",
        target: Target::Vehicle,
        fields: &[SHEAR_SPEED, SHEAR_DIRECTION, SHEAR_HEIGHT, SHEAR_ROUGHNESS],
        effect: "MIL-F-8785C wind shear: W(h) = speed · ln(h / z0) / ln(h_ref / z0), 0 below z0",
    },
    KindSpec {
        kind: FaultKind::LinkLoss,
        name: "link_loss",
        target: Target::Link,
        fields: &[],
        effect: "The link carries nothing new for `duration` (required): commands are dropped (the motors hold the last one that got through), the other side gets no new data; the lockstep tick goes on, so neither side waits forever",
    },
    KindSpec {
        kind: FaultKind::LinkDelay,
        name: "link_delay",
        target: Target::Link,
        fields: &[LINK_DELAY],
        effect: "The data the link delivers is `delay` old (the sensors or the replies); commands act at once",
    },
];

impl FaultKind {
    /// This kind's row.
    pub fn spec(self) -> &'static KindSpec {
        // The catalogue lists every kind in declaration order.
        &CATALOGUE[self as usize]
    }

    pub fn name(self) -> &'static str {
        self.spec().name
    }

    /// The kind named `name`, or the error listing the catalogue.
    pub fn from_name(name: &str) -> Result<FaultKind, ParamError> {
        CATALOGUE
            .iter()
            .find(|s| s.name == name)
            .map(|s| s.kind)
            .ok_or_else(|| {
                let names: Vec<&str> = CATALOGUE.iter().map(|s| s.name).collect();
                ParamError::UnknownName(format!(
                    "{name}` as a fault `kind`; faults: `{}",
                    names.join("`, `")
                ))
            })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_row_is_its_kind_and_defaults_lie_in_bounds() {
        for (i, s) in CATALOGUE.iter().enumerate() {
            assert_eq!(s.kind as usize, i, "{}", s.name);
            assert_eq!(FaultKind::from_name(s.name), Ok(s.kind));
            for f in s.fields {
                assert_eq!(f.check(f.default), Ok(f.default), "{}.{}", s.name, f.name);
            }
        }
        let e = FaultKind::from_name("motor_loss").unwrap_err().to_string();
        assert!(
            e.contains("`motor_loss`") && e.contains("`motor_effectiveness`"),
            "{e}"
        );
        let e = SensorId::from_name("lidar").unwrap_err().to_string();
        assert!(e.contains("`lidar`") && e.contains("`baro`"), "{e}");
    }
}
