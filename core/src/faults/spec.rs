//! One fault as written: its kind, its target (a motor or a sensor), its parameters, its
//! trigger and how long it lasts — read from a TOML table (`[[faults]]` in a config file; the
//! gym's `faults=[{...}]` is written into the same table) and checked against the catalogue.

use super::catalogue::{FaultKind, SensorId, Target};
use super::trigger::{Reach, TRIGGER_KEYS, Trigger};
use crate::error::{ParamError, Role};
use serde::{Deserialize, Serialize};

/// A checked fault: every value inside its field's bounds.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FaultSpec {
    pub kind: FaultKind,
    /// Motor faults: PX4's instance number (1 = the first rotor, 0 = every rotor); 0 for
    /// the others.
    pub motor: u8,
    /// Sensor faults: the sensor.
    pub sensor: Option<SensorId>,
    /// The kind's parameters, in its catalogue row's order.
    pub values: Vec<f64>,
    pub trigger: Trigger,
    /// How long the fault stays once fired, s (`None`: to the end of the episode).
    pub duration: Option<f64>,
}

/// Most rotors a frame has (PX4 numbers its motor instances 1..=this).
pub const MAX_MOTOR: u8 = crate::quadrotor::frame::MAX_ROTORS as u8;

impl FaultSpec {
    /// A fault of `kind` at its defaults, firing at time 0, for every motor.
    pub fn new(kind: FaultKind) -> Self {
        FaultSpec {
            kind,
            motor: 0,
            sensor: (kind.spec().target == Target::Sensor).then_some(SensorId::Gyro),
            values: kind.spec().fields.iter().map(|f| f.default).collect(),
            trigger: Trigger::At(0.0),
            duration: None,
        }
    }

    /// The value of field `name` (`None` when the kind has no such field).
    pub fn value(&self, name: &str) -> Option<f64> {
        let fields = self.kind.spec().fields;
        fields
            .iter()
            .position(|f| f.name == name)
            .map(|i| self.values[i])
    }

    /// Sets field `name` to `value`, checked against its bounds.
    pub fn set(&mut self, name: &str, value: f64) -> Result<(), ParamError> {
        let spec = self.kind.spec();
        match name {
            "motor" if spec.target == Target::Motor => {
                self.motor = motor_number(value)?;
                return Ok(());
            }
            "duration" => {
                if !(value.is_finite() && value > 0.0) {
                    return Err(ParamError::OutOfRange {
                        role: Role::Parameter,
                        name: "duration",
                        value,
                        min: f64::MIN_POSITIVE,
                        max: f64::MAX,
                        unit: "s",
                    });
                }
                self.duration = Some(value);
                return Ok(());
            }
            key if TRIGGER_KEYS.contains(&key) => {
                self.trigger = Trigger::parse(key, value)?;
                return Ok(());
            }
            _ => {}
        }
        match spec.fields.iter().position(|f| f.name == name) {
            Some(i) => {
                self.values[i] = spec.fields[i].check(value)?;
                Ok(())
            }
            None => Err(self.unknown_field(name)),
        }
    }

    fn unknown_field(&self, name: &str) -> ParamError {
        let spec = self.kind.spec();
        let mut keys: Vec<&str> = vec!["kind"];
        match spec.target {
            Target::Motor => keys.push("motor"),
            Target::Sensor => keys.push("sensor"),
            Target::Vehicle | Target::Link => {}
        }
        keys.extend(spec.fields.iter().map(|f| f.name));
        keys.extend(TRIGGER_KEYS);
        keys.push("duration");
        ParamError::UnknownName(format!(
            "{name}` for fault `{}`; its keys: `{}",
            spec.name,
            keys.join("`, `")
        ))
    }

    /// A fault from its TOML table: `kind`, then `motor` or `sensor`, the kind's fields, at
    /// most one trigger key (default `at = 0`) and `duration`.
    pub fn from_toml(table: &toml::Table) -> Result<FaultSpec, ParamError> {
        let kind = match table.get("kind") {
            Some(toml::Value::String(k)) => FaultKind::from_name(k)?,
            Some(other) => {
                return Err(ParamError::Parse(format!(
                    "a fault's `kind` must be a string, got {other}"
                )));
            }
            None => {
                return Err(ParamError::Parse(
                    "a fault needs a `kind` (e.g. kind = \"motor_effectiveness\")".into(),
                ));
            }
        };
        let mut fault = FaultSpec::new(kind);
        let triggers = table.keys().filter(|k| TRIGGER_KEYS.contains(&k.as_str()));
        if triggers.count() > 1 {
            return Err(ParamError::Parse(format!(
                "fault `{}` has more than one trigger; give one of `{}`",
                kind.name(),
                TRIGGER_KEYS.join("`, `")
            )));
        }
        for (key, value) in table {
            match (key.as_str(), value) {
                ("kind", _) => {}
                ("sensor", toml::Value::String(s)) if kind.spec().target == Target::Sensor => {
                    fault.sensor = Some(SensorId::from_name(s)?);
                }
                ("sensor", _) if kind.spec().target == Target::Sensor => {
                    return Err(ParamError::Parse(format!(
                        "fault `{}`: `sensor` must be a string (gyro, accel, mag, baro, gps)",
                        kind.name()
                    )));
                }
                (key, value) => {
                    let number = match value {
                        toml::Value::Integer(i) => *i as f64,
                        toml::Value::Float(x) => *x,
                        _ => {
                            if !TRIGGER_KEYS.contains(&key) && fault.set(key, 0.0).is_err() {
                                return Err(fault.unknown_field(key));
                            }
                            return Err(ParamError::Parse(format!(
                                "fault `{}`: `{key}` must be a number",
                                kind.name()
                            )));
                        }
                    };
                    fault.set(key, number)?;
                }
            }
        }
        if kind == FaultKind::LinkLoss && fault.duration.is_none() {
            return Err(ParamError::Parse(
                "fault `link_loss` needs a `duration` (s): a link lost for good would leave the autopilot or the client without data forever".into(),
            ));
        }
        if kind.spec().target == Target::Sensor && !table.contains_key("sensor") {
            return Err(ParamError::Parse(format!(
                "fault `{}` needs a `sensor` (gyro, accel, mag, baro or gps)",
                kind.name()
            )));
        }
        Ok(fault)
    }

    /// Refuses a fault the flight cannot have: a motor the frame lacks, a trigger that can
    /// never fire, a sensor fault GPS-only parameters do not fit.
    pub fn check(&self, reach: &Reach) -> Result<(), ParamError> {
        if usize::from(self.motor) > reach.rotors {
            return Err(ParamError::OutOfRange {
                role: Role::Parameter,
                name: "motor",
                value: f64::from(self.motor),
                min: 0.0,
                max: reach.rotors as f64,
                unit: "",
            });
        }
        self.trigger.check_reachable(reach)
    }

    /// A short label: kind, then the motor or sensor (`motor_effectiveness:2`,
    /// `sensor_stuck:baro`).
    pub fn label(&self) -> String {
        match (self.kind.spec().target, self.sensor) {
            (Target::Motor, _) => format!("{}:{}", self.kind.name(), self.motor),
            (Target::Sensor, Some(s)) => format!("{}:{}", self.kind.name(), s.name()),
            _ => self.kind.name().to_string(),
        }
    }
}

/// A motor instance number (0 = all, 1..=MAX_MOTOR); the frame's own count is checked by
/// [`FaultSpec::check`].
fn motor_number(value: f64) -> Result<u8, ParamError> {
    if value.fract() == 0.0 && (0.0..=f64::from(MAX_MOTOR)).contains(&value) {
        Ok(value as u8)
    } else {
        Err(ParamError::OutOfRange {
            role: Role::Parameter,
            name: "motor",
            value,
            min: 0.0,
            max: f64::from(MAX_MOTOR),
            unit: "",
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(text: &str) -> Result<FaultSpec, ParamError> {
        FaultSpec::from_toml(&toml::from_str(text).unwrap())
    }

    #[test]
    fn a_fault_reads_its_kind_target_fields_and_trigger() {
        let f = parse("kind = 'motor_effectiveness'\nmotor = 2\neffectiveness = 0.6\nabove_height = 3\nduration = 2.5").unwrap();
        assert_eq!(f.kind, FaultKind::MotorEffectiveness);
        assert_eq!((f.motor, f.value("effectiveness")), (2, Some(0.6)));
        assert_eq!(
            (f.trigger, f.duration),
            (Trigger::AboveHeight(3.0), Some(2.5))
        );
        assert_eq!(f.label(), "motor_effectiveness:2");
        let f = parse("kind = 'sensor_bias'\nsensor = 'baro'\nbias = 4\ndrift = 0.1").unwrap();
        assert_eq!(
            (f.sensor, f.value("drift")),
            (Some(SensorId::Baro), Some(0.1))
        );
        assert_eq!(f.trigger, Trigger::At(0.0));
    }

    #[test]
    fn bad_faults_name_the_field_and_its_bound() {
        let err = |t: &str| parse(t).unwrap_err().to_string();
        let e = err("kind = 'motor_effectiveness'\neffectiveness = 1.5");
        assert!(
            e.contains("`effectiveness` = 1.5 is out of range: it must be in [0, 1]"),
            "{e}"
        );
        let e = err("kind = 'motor_effectivness'");
        assert!(
            e.contains("`motor_effectivness`") && e.contains("`motor_effectiveness`"),
            "{e}"
        );
        let e = err("kind = 'sensor_off'\nsensor = 'lidar'");
        assert!(e.contains("`lidar`"), "{e}");
        let e = err("kind = 'sensor_off'");
        assert!(e.contains("needs a `sensor`"), "{e}");
        let e = err("kind = 'motor_off'\nmotor = 2.5");
        assert!(e.contains("`motor` = 2.5 is out of range"), "{e}");
        let e = err("kind = 'motor_off'\nefectiveness = 1");
        assert!(e.contains("`efectiveness` for fault `motor_off`"), "{e}");
        let e = err("kind = 'gust'\nat = 1\nabove_height = 2");
        assert!(e.contains("more than one trigger"), "{e}");
        let e = err("kind = 'gust'\nduration = 0");
        assert!(e.contains("`duration` = 0"), "{e}");
        let e = err("kind = 'link_loss'\nat = 3");
        assert!(
            e.contains("`link_loss` needs a `duration`"),
            "a link lost for good: {e}"
        );
        let e = err("kind = 'link_delay'\ndelay = 20\nduration = 1");
        assert!(e.contains("`delay` = 20 s is out of range"), "{e}");
        let e = err("kind = 'link_loss'\nmotor = 1\nduration = 1");
        assert!(e.contains("`motor` for fault `link_loss`"), "{e}");
        let f = parse("kind = 'motor_off'\nmotor = 5").unwrap();
        let reach = Reach {
            duration: None,
            waypoints: None,
            rotors: 4,
        };
        let e = f.check(&reach).unwrap_err().to_string();
        assert!(
            e.contains("`motor` = 5 is out of range: it must be in [0, 4]"),
            "{e}"
        );
    }
}
