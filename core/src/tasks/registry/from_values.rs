//! A task's parameter sets from `(name, value)` pairs: the one way front ends build a
//! [`TaskConfig`] from what a user wrote.

use super::param_rows::{self, Group, ParamEntry};
use super::{ModelKind, TaskConfig, TaskInstance, TaskKind};
use crate::ParamError;
use crate::faults::{FaultPlan, Reach};
use crate::params::Parameters;
use crate::quadrotor::Frame;
use crate::tasks::randomization::{ParamRange, Randomization};

/// The parameter sets of `task` from `(name or short id, value)` pairs (other parameters keep
/// their defaults), each checked against its row, the sets' relations checked once all are
/// applied, and the task built once to check it. The SITL's parameter file and the Python
/// extension both come through here.
pub fn from_values<'a>(
    task: TaskKind,
    pairs: impl IntoIterator<Item = (&'a str, f64)>,
) -> Result<TaskConfig, ParamError> {
    from_values_and_ranges(task, pairs, Vec::new(), None)
}

/// [`from_values`] with randomisation ranges and a frame (flight tasks only; checked
/// against the parameter sets by the core). No frame: the quad X.
pub fn from_values_and_ranges<'a>(
    task: TaskKind,
    pairs: impl IntoIterator<Item = (&'a str, f64)>,
    ranges: Vec<ParamRange>,
    frame: Option<Frame>,
) -> Result<TaskConfig, ParamError> {
    from_values_ranges_and_faults(task, pairs, ranges, frame, FaultPlan::default())
}

/// [`from_values_and_ranges`] with a fault plan (flight tasks only), checked against the
/// task and its frame: a motor the frame lacks (named with the frame's motor count), a
/// trigger that can never fire in its episodes (past `max_steps · dt`, a waypoint index it
/// does not have) is refused.
pub fn from_values_ranges_and_faults<'a>(
    task: TaskKind,
    pairs: impl IntoIterator<Item = (&'a str, f64)>,
    ranges: Vec<ParamRange>,
    frame: Option<Frame>,
    faults: FaultPlan,
) -> Result<TaskConfig, ParamError> {
    let entries = param_rows::entries(task);
    let mut values: Vec<(ParamEntry, f64)> = Vec::new();
    for (key, value) in pairs {
        values.push((param_rows::find(&entries, task, key)?, value));
    }
    let pick = |group: Group| {
        values
            .iter()
            .filter(move |(e, _)| e.group == group)
            .map(|(e, v)| (e.name, *v))
    };
    let mut config = TaskConfig::default();
    for &group in Group::for_task(task) {
        match group {
            Group::Quadrotor => config.quadrotor = Parameters::from_values(pick(group))?,
            Group::RateLoop => config.rate_loop = Parameters::from_values(pick(group))?,
            Group::Flight => config.flight = Parameters::from_values(pick(group))?,
            Group::Waypoints => config.waypoints = Parameters::from_values(pick(group))?,
            Group::Lander => config.lander = Parameters::from_values(pick(group))?,
            Group::Landing => config.landing = Parameters::from_values(pick(group))?,
        }
    }
    if !ranges.is_empty() {
        if task.model() != ModelKind::Quadrotor {
            return Err(ParamError::Parse(format!(
                "task `{}` has no randomisation; the flight tasks (hover, waypoints) do",
                task.frame_name()
            )));
        }
        config.randomize = Randomization::new(ranges)?;
    }
    if let Some(frame) = frame {
        if task.model() != ModelKind::Quadrotor {
            return Err(ParamError::Relation {
                name: "frame",
                requirement: format!(
                    "task `{}` flies no multirotor, so it takes no frame; the flight tasks (hover, waypoints) do",
                    task.frame_name()
                ),
            });
        }
        config.frame = frame;
    }
    if !faults.is_empty() {
        if task.model() != ModelKind::Quadrotor {
            return Err(ParamError::Parse(format!(
                "task `{}` has no faults; the flight tasks (hover, waypoints) do",
                task.frame_name()
            )));
        }
        let f = &config.flight;
        faults.check(&Reach {
            duration: Some(f.episode_duration()),
            waypoints: (task == TaskKind::Waypoints).then_some(config.waypoints.max_num_waypoints),
            // The frame's motors: a motor fault on a hexa addresses 1..=6.
            rotors: config.frame.rotor_count(),
        })?;
        config.faults = faults;
    }
    TaskInstance::build(task, &config)?;
    Ok(config)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_and_short_ids_set_their_parameter_and_others_keep_defaults() {
        let c = from_values(TaskKind::Hover, [("mass", 1.5), ("tgt_chg_intv", 50.0)]).unwrap();
        assert_eq!(c.quadrotor.mass, 1.5);
        assert_eq!(c.flight.target_change_interval, 50);
        assert_eq!(c.quadrotor.arm_length, 0.1);
        assert_eq!(
            from_values(TaskKind::Landing, [("masss", 1.0)])
                .unwrap_err()
                .to_string(),
            "unknown parameter `masss` for task `landing`"
        );
    }

    #[test]
    fn ranges_are_refused_for_the_lander() {
        let range = ParamRange {
            name: "mass".to_string(),
            low: 1.0,
            high: 2.0,
        };
        let err =
            from_values_and_ranges(TaskKind::Landing, [], vec![range.clone()], None).unwrap_err();
        assert!(err.to_string().contains("no randomisation"), "{err}");
        let c = from_values_and_ranges(TaskKind::Hover, [], vec![range], None).unwrap();
        assert_eq!(c.randomize.ranges().len(), 1);
    }

    #[test]
    fn a_frame_is_taken_by_the_flight_tasks_and_refused_by_the_lander() {
        let hexa = || Some(Frame::named("hexa_x").unwrap());
        let c = from_values_and_ranges(TaskKind::Waypoints, [], Vec::new(), hexa()).unwrap();
        assert_eq!(c.frame.rotor_count(), 6);
        let err = from_values_and_ranges(TaskKind::Landing, [], Vec::new(), hexa()).unwrap_err();
        assert!(err.to_string().contains("takes no frame"), "{err}");
    }
}
