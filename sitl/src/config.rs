//! The config file: a flat TOML table of the task's parameters (model and task sets), by the
//! core's names or their MAVLink short ids. Missing keys keep the core's defaults; every error
//! names the parameter and its bound (the core's [`ParamError`]).

use flyloop_core::ParamError;
use flyloop_core::tasks::randomization::ParamRange;
use flyloop_core::tasks::registry::{TaskConfig, TaskKind, from_values_and_ranges, param_rows};
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

/// Parses `text` into the parameter sets of `task` (other sets keep their defaults) and
/// checks that the task builds from them.
pub fn parse(task: TaskKind, text: &str) -> Result<TaskConfig, ParamError> {
    let table: toml::Table = toml::from_str(text)?;
    let mut values: Vec<(&str, f64)> = Vec::with_capacity(table.len());
    let mut ranges = Vec::new();
    for (key, value) in &table {
        if key == RANDOMIZE_TABLE {
            ranges = parse_ranges(value)?;
            continue;
        }
        let Some(number) = toml_number(value) else {
            let entry = param_rows::find(&param_rows::entries(task), task, key)?;
            return Err(ParamError::Parse(format!(
                "parameter `{}` must be a number or a boolean",
                entry.name
            )));
        };
        values.push((key.as_str(), number));
    }
    from_values_and_ranges(task, values, ranges)
}

/// The config file's table of randomisation ranges: `[randomize]` with `name = [low, high]`.
pub const RANDOMIZE_TABLE: &str = "randomize";

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
pub(crate) fn toml_number(value: &toml::Value) -> Option<f64> {
    match value {
        toml::Value::Integer(i) => Some(*i as f64),
        toml::Value::Float(x) => Some(*x),
        toml::Value::Boolean(b) => Some(f64::from(u8::from(*b))),
        _ => None,
    }
}

/// The parameter sets of `task` from the file at `path`.
pub fn load(task: TaskKind, path: &Path) -> Result<TaskConfig, ConfigError> {
    read(path, |text| parse(task, text))
}

/// Reads the parameter file at `path` with `parse`; the one loader of every mode, so a
/// missing file and a bad value are reported the same way.
pub fn read<T>(
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
mod tests {
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
}
