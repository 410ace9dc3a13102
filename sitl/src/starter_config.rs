//! `flyloop-sitl --task T --list-params toml`: a starter parameter file for `--config`,
//! every parameter of the task at its current value with unit, range and description.

use flyloop_core::params::ValueKind;
use flyloop_core::tasks::registry::param_rows::{self, Group};
use flyloop_core::tasks::registry::{TaskConfig, TaskKind};

/// The TOML text; [`crate::config::parse`] reads it back to `config`.
pub fn starter_toml(task: TaskKind, config: &TaskConfig) -> String {
    let name = task.frame_name();
    let mut out = format!(
        "# flyloop-sitl parameter file for the `{name}` task:\n\
         #     flyloop-sitl --task {name} --config this-file.toml\n\
         # Every parameter at its default; keep the lines you change (a missing key keeps its\n\
         # default). Keys are the core's names; the MAVLink short ids work too.\n"
    );
    let entries = param_rows::entries(task);
    for &group in Group::for_task(task) {
        out.push_str(&format!("\n# {}\n", group.label()));
        for e in entries.iter().filter(|e| e.group == group) {
            let value = param_rows::get(config, group, e.name).unwrap_or(f64::NAN);
            let (text, range) = match e.kind {
                // `{:?}` always writes a TOML float (1.0, 1e-5, inf).
                ValueKind::Real => (format!("{value:?}"), format!("[{}, {}]", e.min, e.max)),
                ValueKind::Integer => (format!("{value}"), format!("[{}, {}]", e.min, e.max)),
                ValueKind::Boolean => ((value != 0.0).to_string(), "true / false".into()),
            };
            let unit = if e.unit.is_empty() || e.unit == "1" {
                String::new()
            } else {
                format!("{} ", e.unit)
            };
            out.push_str(&format!(
                "{} = {text}  # {unit}{range}: {}\n",
                e.name, e.description
            ));
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::config;

    #[test]
    fn the_starter_file_reads_back_to_the_defaults_for_every_task() {
        for task in [TaskKind::Hover, TaskKind::Waypoints, TaskKind::Landing] {
            let text = starter_toml(task, &TaskConfig::default());
            let back = config::parse(task, &text).unwrap();
            assert_eq!(back, TaskConfig::default(), "{task:?}");
            let lines = text.lines().filter(|l| l.contains(" = ")).count();
            assert_eq!(lines, param_rows::entries(task).len(), "{task:?}");
        }
    }

    #[test]
    fn a_changed_config_is_written_with_its_values() {
        let mut config = TaskConfig::default();
        config.quadrotor.mass = 1.5;
        config.flight.max_steps = 250;
        config.quadrotor.wind_enabled = false;
        let text = starter_toml(TaskKind::Hover, &config);
        assert!(text.contains("\nmass = 1.5  # kg "), "{text}");
        assert!(text.contains("\nmax_steps = 250  # "), "{text}");
        assert!(
            text.contains("\nwind_enabled = false  # true / false"),
            "{text}"
        );
        assert_eq!(config::parse(TaskKind::Hover, &text).unwrap(), config);
    }

    #[test]
    fn the_example_config_in_the_repository_loads() {
        let text = include_str!("../../examples/sitl/hover.toml");
        let config = config::parse(TaskKind::Hover, text).unwrap();
        assert_eq!(config.quadrotor.mass, 1.2);
        assert!(!config.quadrotor.wind_enabled);
    }
}
