//! The parameter file, one loader for every mode: a flat TOML table of parameters by the
//! core's names (in the MAVLink SITL also by their MAVLink short ids), plus, for the flight
//! tasks, a `[randomize]` table of ranges. The MAVLink SITL reads the task's parameter sets
//! from it ([`parse`]), the autopilot modes their vehicle ([`AutopilotVehicle::parse`]).
//! Missing keys keep the core's defaults; every error names the parameter and its bound (the
//! core's [`ParamError`]).

use flyloop_core::ParamError;
use flyloop_core::faults::FaultPlan;
use flyloop_core::faults::plan::{FAULTS_TABLE, RANDOMIZATION_TABLE};
use flyloop_core::params::Parameters;
use flyloop_core::quadrotor::{Frame, QuadrotorParams};
use flyloop_core::sensors::SensorParams;
use flyloop_core::tasks::randomization::ParamRange;
use flyloop_core::tasks::registry::{
    TaskConfig, TaskKind, from_values_ranges_and_faults, param_rows,
};
use std::path::{Path, PathBuf};

/// Why a config file was refused.
#[derive(Debug, thiserror::Error)]
pub enum ConfigError {
    #[error("cannot read config file {path}: {source}")]
    Read {
        path: PathBuf,
        source: std::io::Error,
    },
    #[error("config file {path}: {source}")]
    Invalid { path: PathBuf, source: ParamError },
}

/// The table of the vehicle's rotors (`core/src/quadrotor/frame.rs`), in every mode.
pub const FRAME_TABLE: &str = "frame";

/// The config file's table of randomisation ranges: `[randomize]` with `name = [low, high]`.
pub const RANDOMIZE_TABLE: &str = "randomize";

/// What a parameter file sets: each parameter's number (by the key written), and the
/// `[randomize]` ranges if the file has that table.
struct Entries<'t> {
    values: Vec<(&'t str, f64)>,
    ranges: Option<Vec<ParamRange>>,
    /// `[[faults]]` and `[[fault_randomization]]` (checked against the task by the core).
    faults: FaultPlan,
}

/// Walks a parameter file's table, the one walker of every mode. `name_of` gives a key's
/// core name, or the error naming a key the mode does not know.
fn walk<'t>(
    table: &'t toml::Table,
    name_of: impl Fn(&str) -> Result<&'static str, ParamError>,
) -> Result<Entries<'t>, ParamError> {
    let mut entries = Entries {
        values: Vec::with_capacity(table.len()),
        ranges: None,
        faults: FaultPlan::default(),
    };
    for (key, value) in table {
        if key == RANDOMIZE_TABLE {
            entries.ranges = Some(parse_ranges(value)?);
            continue;
        }
        if key == FAULTS_TABLE || key == RANDOMIZATION_TABLE {
            entries.faults.add(key, value)?;
            continue;
        }
        let name = name_of(key)?;
        let number = toml_number(value).ok_or_else(|| {
            ParamError::Parse(format!("parameter `{name}` must be a number or a boolean"))
        })?;
        entries.values.push((key.as_str(), number));
    }
    Ok(entries)
}

/// `[randomize]`'s entries as ranges; each must be a pair of numbers.
fn parse_ranges(value: &toml::Value) -> Result<Vec<ParamRange>, ParamError> {
    let Some(table) = value.as_table() else {
        return Err(ParamError::Parse(format!(
            "`{RANDOMIZE_TABLE}` must be a table of `name = [low, high]` ranges"
        )));
    };
    let mut ranges = Vec::with_capacity(table.len());
    for (name, range) in table {
        let pair = range.as_array().filter(|a| a.len() == 2);
        let bounds: Option<Vec<f64>> = pair.map(|a| a.iter().filter_map(toml_number).collect());
        match bounds.as_deref() {
            Some(&[low, high]) => ranges.push(ParamRange {
                name: name.clone(),
                low,
                high,
            }),
            _ => {
                return Err(ParamError::Parse(format!(
                    "randomisation range `{name}` must be a pair of numbers [low, high]"
                )));
            }
        }
    }
    Ok(ranges)
}

/// A parameter file's value as a number: integers, floats, and booleans as 0/1; `None` for
/// anything else (the caller names the parameter in its error).
fn toml_number(value: &toml::Value) -> Option<f64> {
    match value {
        toml::Value::Integer(i) => Some(*i as f64),
        toml::Value::Float(x) => Some(*x),
        toml::Value::Boolean(b) => Some(f64::from(u8::from(*b))),
        _ => None,
    }
}

/// Parses `text` into the parameter sets of `task` (other sets keep their defaults) and
/// checks that the task builds from them.
pub fn parse(task: TaskKind, text: &str) -> Result<TaskConfig, ParamError> {
    let mut table: toml::Table = toml::from_str(text)?;
    let frame = take_frame(&mut table)?;
    let rows = param_rows::entries(task);
    let file = walk(&table, |key| Ok(param_rows::find(&rows, task, key)?.name))?;
    from_values_ranges_and_faults(
        task,
        file.values,
        file.ranges.unwrap_or_default(),
        frame,
        file.faults,
    )
}

/// The file's `[frame]` table as a frame (taken out of `table`), if it has one.
fn take_frame(table: &mut toml::Table) -> Result<Option<Frame>, ParamError> {
    match table.remove(FRAME_TABLE) {
        None => Ok(None),
        Some(toml::Value::Table(t)) => Ok(Some(Frame::from_toml_table(t)?)),
        Some(_) => Err(ParamError::Parse(format!(
            "`{FRAME_TABLE}` must be a table: `name = \"hexa_x\"`, or `name` and one `[[{FRAME_TABLE}.rotor]]` per rotor"
        ))),
    }
}

/// The preset the autopilot modes fly by default (sitl/presets/px4_iris.toml, built in).
pub const IRIS_PRESET: &str = include_str!("../presets/px4_iris.toml");

/// The vehicle of the autopilot modes (PX4 and ArduPilot): quadrotor and sensor parameters.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct AutopilotVehicle {
    pub quadrotor: QuadrotorParams,
    pub sensors: SensorParams,
    /// The rotor table (`[frame]`: `name = "hexa_x"`, or a whole table); the quad X if none.
    pub frame: Frame,
    /// `[[faults]]` and `[[fault_randomization]]` (none: a healthy vehicle), checked against
    /// the frame by the session.
    pub faults: FaultPlan,
}

impl AutopilotVehicle {
    /// The built-in Iris preset.
    pub fn iris() -> Self {
        // The preset is part of the binary and parsed by a unit test; defaults if ever broken.
        Self::parse(IRIS_PRESET).unwrap_or_default()
    }

    /// Quadrotor and sensor parameters by their core names, in one flat table, and the
    /// frame in its own `[frame]` table; no randomisation.
    pub fn parse(text: &str) -> Result<Self, ParamError> {
        let mut table: toml::Table = toml::from_str(text)?;
        let frame = take_frame(&mut table)?.unwrap_or_default();
        let file = walk(&table, autopilot_name)?;
        let rotors = frame.rotor_count();
        file.faults.check(&flyloop_core::faults::Reach {
            duration: None,
            waypoints: None,
            rotors,
        })?;
        if file.ranges.is_some() {
            return Err(ParamError::Parse(format!(
                "`{RANDOMIZE_TABLE}`: the PX4 and ArduPilot modes fly one vehicle, without randomisation"
            )));
        }
        let (quad, sensors): (Vec<_>, Vec<_>) = file
            .values
            .into_iter()
            .partition(|(key, _)| QuadrotorParams::spec(key).is_ok());
        Ok(AutopilotVehicle {
            quadrotor: QuadrotorParams::from_values(quad)?,
            sensors: SensorParams::from_values(sensors)?,
            frame,
            faults: file.faults,
        })
    }
}

/// A key of the autopilot modes' file: a quadrotor or a sensor parameter (the sets are named
/// as in docs/parameters.md).
fn autopilot_name(key: &str) -> Result<&'static str, ParamError> {
    let spec = QuadrotorParams::spec(key).map(|s| s.name);
    spec.or_else(|_| SensorParams::spec(key).map(|s| s.name))
        .map_err(|_| {
            ParamError::UnknownName(format!(
                "{key}` for PX4 or ArduPilot mode: expected one of `QuadrotorParams` or `SensorParams"
            ))
        })
}

/// The parameter sets of `task` from the file at `path`.
pub fn load(task: TaskKind, path: &Path) -> Result<TaskConfig, ConfigError> {
    read(path, |text| parse(task, text))
}

/// A multi-agent world's parameters for `vehicles` agents from the file at `path` (or the
/// defaults): a flat table by the multi-agent task's core names (the names
/// `flyloop.parallel_env` takes) and a `[randomize]` table of per-agent ranges.
pub fn load_world(
    path: Option<&Path>,
    vehicles: u8,
) -> Result<flyloop_core::tasks::multi::MultiConfig, ConfigError> {
    use crate::sim::world_config;
    match path {
        None => world_config(vehicles, &[], Vec::new()).map_err(|source| ConfigError::Invalid {
            path: PathBuf::from("(defaults)"),
            source,
        }),
        Some(path) => read(path, |text| {
            let table: toml::Table = toml::from_str(text)?;
            let mut pairs = Vec::with_capacity(table.len());
            let mut ranges = Vec::new();
            let mut faults = flyloop_core::tasks::multi::AgentFaults::default();
            for (key, value) in &table {
                if key == RANDOMIZE_TABLE {
                    ranges = parse_ranges(value)?;
                    continue;
                }
                // [[faults]] / [[fault_randomization]]: what parallel_env(faults=...) writes.
                if key == "faults" || key == "fault_randomization" {
                    faults.add(key, value)?;
                    continue;
                }
                let number = toml_number(value).ok_or_else(|| {
                    ParamError::Parse(format!("parameter `{key}` must be a number or a boolean"))
                })?;
                pairs.push((key.clone(), number));
            }
            world_config(vehicles, &pairs, ranges)?.with_faults(faults)
        }),
    }
}

/// The autopilot modes' vehicle from the file at `path`.
pub fn load_autopilot_vehicle(path: &Path) -> Result<AutopilotVehicle, ConfigError> {
    read(path, AutopilotVehicle::parse)
}

/// Reads the parameter file at `path` with `parse`, so a missing file and a bad value are
/// reported the same way in every mode.
fn read<T>(
    path: &Path,
    parse: impl FnOnce(&str) -> Result<T, ParamError>,
) -> Result<T, ConfigError> {
    let text = std::fs::read_to_string(path).map_err(|source| ConfigError::Read {
        path: path.to_path_buf(),
        source,
    })?;
    parse(&text).map_err(|source| ConfigError::Invalid {
        path: path.to_path_buf(),
        source,
    })
}

#[cfg(test)]
mod tests;
