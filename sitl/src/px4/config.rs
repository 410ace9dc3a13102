//! The parameters of PX4 mode: the quadrotor's and the sensors' in one flat TOML table, each
//! key by its core name. Without `--config`, the Iris preset is used.

use crate::config::toml_number;
use flyloop_core::ParamError;
use flyloop_core::params::Parameters;
use flyloop_core::quadrotor::QuadrotorParams;
use flyloop_core::sensors::SensorParams;

/// The preset flown by default in PX4 mode (sitl/presets/px4_iris.toml, built in).
pub const IRIS_PRESET: &str = include_str!("../../presets/px4_iris.toml");

/// Vehicle and sensor parameters of PX4 mode.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Px4Config {
    pub quadrotor: QuadrotorParams,
    pub sensors: SensorParams,
}

impl Px4Config {
    /// The built-in Iris preset.
    pub fn iris() -> Self {
        // The preset is part of the binary and parsed by a unit test; defaults if ever broken.
        Self::parse(IRIS_PRESET).unwrap_or_default()
    }

    /// A flat TOML table of quadrotor and sensor parameters; missing keys keep the core's
    /// defaults, and every error names its parameter.
    pub fn parse(text: &str) -> Result<Self, ParamError> {
        let table: toml::Table = toml::from_str(text)?;
        let mut quad = Vec::new();
        let mut sensors = Vec::new();
        for (key, value) in &table {
            let number = toml_number(value).ok_or_else(|| {
                ParamError::Parse(format!("parameter `{key}` must be a number or a boolean"))
            })?;
            if QuadrotorParams::spec(key).is_ok() {
                quad.push((key.as_str(), number));
            } else if SensorParams::spec(key).is_ok() {
                sensors.push((key.as_str(), number));
            } else {
                return Err(ParamError::UnknownName(format!(
                    "{key}` for PX4 or ArduPilot mode (quadrotor or sensor parameter expected"
                )));
            }
        }
        Ok(Px4Config {
            quadrotor: QuadrotorParams::from_values(quad)?,
            sensors: SensorParams::from_values(sensors)?,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_iris_preset_parses_and_hovers_near_0_6() {
        let c = Px4Config::parse(IRIS_PRESET).unwrap();
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
    fn both_tables_are_read_and_mistakes_are_named() {
        let c = Px4Config::parse("mass = 2\ngps_rate = 5\n").unwrap();
        assert_eq!((c.quadrotor.mass, c.sensors.gps_rate), (2.0, 5.0));
        let e = Px4Config::parse("gps_rate = 0").unwrap_err().to_string();
        assert!(e.contains("`gps_rate` = 0 Hz is out of range"), "{e}");
        let e = Px4Config::parse("mas = 1").unwrap_err().to_string();
        assert!(e.contains("`mas`"), "{e}");
        let e = Px4Config::parse("mass = \"x\"").unwrap_err().to_string();
        assert!(e.contains("`mass` must be a number"), "{e}");
    }
}
