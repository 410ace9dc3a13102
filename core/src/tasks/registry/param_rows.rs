//! One row per parameter of a task: the model's physical parameters and the task's, straight
//! from their tables ([`Parameters::specs`]). The SITL serves these rows over the MAVLink
//! parameter protocol; its parameter file and the Python extension set them by name.
//!
//! MAVLink's `param_id` holds at most 16 characters, so a longer name also gets a short id by
//! a fixed rule ([`short_id`]); either is accepted wherever a parameter is named.

use super::{TaskConfig, TaskKind};
use crate::ParamError;
use crate::params::{ParamSpec, Parameters, ValueKind};

/// Longest `param_id` MAVLink carries.
pub const PARAM_ID_LEN: usize = 16;

/// Which parameter set of a [`TaskConfig`] a row belongs to.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Group {
    Quadrotor,
    RateLoop,
    Flight,
    Waypoints,
    Lander,
    Landing,
}

impl Group {
    /// The sets a task is built from, in the order the parameter protocol lists them.
    pub fn for_task(task: TaskKind) -> &'static [Group] {
        match task {
            TaskKind::Hover => &[Group::Quadrotor, Group::Flight, Group::RateLoop],
            TaskKind::Waypoints => &[
                Group::Quadrotor,
                Group::Flight,
                Group::Waypoints,
                Group::RateLoop,
            ],
            TaskKind::Landing => &[Group::Lander, Group::Landing],
        }
    }

    /// A label for listings.
    pub fn label(self) -> &'static str {
        match self {
            Group::Quadrotor => "model (quadrotor)",
            Group::RateLoop => "model (PX4 rate loop)",
            Group::Flight => "task (flight)",
            Group::Waypoints => "task (waypoints)",
            Group::Lander => "model (lander2d)",
            Group::Landing => "task (landing)",
        }
    }
}

/// One parameter: its names, set, kind and range.
#[derive(Debug, Clone, PartialEq)]
pub struct ParamEntry {
    /// The short id, the MAVLink `param_id` (at most [`PARAM_ID_LEN`] characters).
    pub id: String,
    /// The core's name.
    pub name: &'static str,
    pub group: Group,
    pub kind: ValueKind,
    pub unit: &'static str,
    pub min: f64,
    pub max: f64,
    pub description: &'static str,
}

fn rows<P: Parameters>(group: Group) -> impl Iterator<Item = ParamEntry> {
    P::specs().iter().map(move |s: &ParamSpec<P>| ParamEntry {
        id: short_id(s.name),
        name: s.name,
        group,
        kind: s.kind,
        unit: s.unit,
        min: s.min,
        max: s.max,
        description: s.description,
    })
}

/// Every parameter of `task`, in protocol index order.
pub fn entries(task: TaskKind) -> Vec<ParamEntry> {
    let mut out = Vec::new();
    for &group in Group::for_task(task) {
        match group {
            Group::Quadrotor => out.extend(rows::<crate::quadrotor::QuadrotorParams>(group)),
            Group::RateLoop => out.extend(rows::<crate::rate_loop::RateLoopParams>(group)),
            Group::Flight => out.extend(rows::<crate::tasks::flight::FlightParams>(group)),
            Group::Waypoints => out.extend(rows::<crate::tasks::waypoints::WaypointParams>(group)),
            Group::Lander => out.extend(rows::<crate::lander2d::Lander2dParams>(group)),
            Group::Landing => out.extend(rows::<crate::tasks::landing::LandingParams>(group)),
        }
    }
    out
}

/// The row of `entries` (the rows of `task`) called `key`, by core name or short id.
pub fn find(entries: &[ParamEntry], task: TaskKind, key: &str) -> Result<ParamEntry, ParamError> {
    entries
        .iter()
        .find(|e| e.name == key || e.id == *key)
        .cloned()
        .ok_or_else(|| ParamError::UnknownName(format!("{key}` for task `{}", task.frame_name())))
}

/// Reads parameter `name` of `group` from `config`.
pub fn get(config: &TaskConfig, group: Group, name: &str) -> Result<f64, ParamError> {
    match group {
        Group::Quadrotor => config.quadrotor.get(name),
        Group::RateLoop => config.rate_loop.get(name),
        Group::Flight => config.flight.get(name),
        Group::Waypoints => config.waypoints.get(name),
        Group::Lander => config.lander.get(name),
        Group::Landing => config.landing.get(name),
    }
}

/// Sets parameter `name` of `group` in `config`, checked against its row and the set's
/// relations; on error `config` is unchanged.
pub fn set(
    config: &mut TaskConfig,
    group: Group,
    name: &str,
    value: f64,
) -> Result<(), ParamError> {
    match group {
        Group::Quadrotor => config.quadrotor.set(name, value),
        Group::RateLoop => config.rate_loop.set(name, value),
        Group::Flight => config.flight.set(name, value),
        Group::Waypoints => config.waypoints.set(name, value),
        Group::Lander => config.lander.set(name, value),
        Group::Landing => config.landing.set(name, value),
    }
}

/// Word abbreviations used only for names longer than [`PARAM_ID_LEN`].
const ABBREVIATIONS: &[(&str, &str)] = &[
    ("allowed", "alw"),
    ("angle", "ang"),
    ("angular", "ang"),
    ("attitude", "att"),
    ("battery", "batt"),
    ("bounds", "bnd"),
    ("change", "chg"),
    ("coefficient", "coef"),
    ("constant", "const"),
    ("consumption", "cons"),
    ("damping", "damp"),
    ("decay", "dcy"),
    ("detection", "det"),
    ("direction", "dir"),
    ("distance", "dist"),
    ("enable", "en"),
    ("friction", "fric"),
    ("initial", "ini"),
    ("interval", "intv"),
    ("landing", "lnd"),
    ("length", "len"),
    ("linear", "lin"),
    ("pendulum", "pend"),
    ("per", "p"),
    ("platform", "plat"),
    ("quadratic", "quad"),
    ("random", "rnd"),
    ("range", "rng"),
    ("rate", "rt"),
    ("sec", "s"),
    ("speed", "spd"),
    ("target", "tgt"),
    ("threshold", "thr"),
    ("turbulence", "turb"),
    ("velocity", "vel"),
    ("vertical", "vert"),
    ("waypoint", "wp"),
    ("waypoints", "wps"),
];

/// Unit words that may end a name; dropped from a short id that is still too long.
const UNIT_WORDS: &[&str] = &["m", "rad", "s", "deg"];

/// The MAVLink `param_id` of a core parameter name: the name itself when it fits in 16
/// characters; otherwise `out_of_bounds` becomes `oob`, each word is abbreviated by
/// [`ABBREVIATIONS`], a trailing unit word (`m`, `rad`, `s`, `deg`) is dropped if still too
/// long, and then the longest word (the last of equals) loses its last letter until it fits.
pub fn short_id(name: &str) -> String {
    if name.len() <= PARAM_ID_LEN {
        return name.to_string();
    }
    let name = name.replace("out_of_bounds", "oob");
    let mut words: Vec<String> = name
        .split('_')
        .map(|w| {
            ABBREVIATIONS
                .iter()
                .find(|(long, _)| *long == w)
                .map_or(w, |(_, short)| short)
                .to_string()
        })
        .collect();
    let length = |words: &[String]| words.iter().map(String::len).sum::<usize>() + words.len() - 1;
    if length(&words) > PARAM_ID_LEN
        && words.len() > 1
        && words
            .last()
            .is_some_and(|w| UNIT_WORDS.contains(&w.as_str()))
    {
        words.pop();
    }
    while length(&words) > PARAM_ID_LEN {
        let longest = words.iter().map(String::len).max().unwrap_or(0);
        if longest <= 1 {
            break;
        }
        if let Some(w) = words.iter_mut().rev().find(|w| w.len() == longest) {
            w.pop();
        }
    }
    let mut id = words.join("_");
    id.truncate(PARAM_ID_LEN);
    id
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::collections::HashSet;

    #[test]
    fn every_id_fits_and_is_unique_within_a_task() {
        for task in [TaskKind::Hover, TaskKind::Waypoints, TaskKind::Landing] {
            let all = entries(task);
            let mut ids = HashSet::new();
            let mut names = HashSet::new();
            for e in &all {
                assert!(e.id.len() <= PARAM_ID_LEN, "{} -> {}", e.name, e.id);
                assert!(!e.id.is_empty());
                assert!(ids.insert(e.id.clone()), "{task:?}: duplicate id {}", e.id);
                assert!(names.insert(e.name), "{task:?}: duplicate name {}", e.name);
            }
            // A short id never equals another parameter's full name.
            for e in &all {
                if e.id != e.name {
                    assert!(!names.contains(e.id.as_str()), "{} collides", e.id);
                }
            }
        }
    }

    #[test]
    fn short_ids_follow_the_documented_rule() {
        assert_eq!(short_id("mass"), "mass");
        assert_eq!(short_id("turbulence_theta"), "turbulence_theta");
        assert_eq!(short_id("angular_damping_quadratic"), "ang_damp_quad");
        assert_eq!(short_id("enable_out_of_bounds_detection"), "en_oob_det");
        assert_eq!(
            short_id("initial_angle_random_range_rad"),
            "ini_ang_rnd_rng"
        );
        assert_eq!(short_id("bonus_decay_rate_per_sec"), "bonus_dcy_rt_p_s");
        assert_eq!(short_id("target_change_interval"), "tgt_chg_intv");
        // The shrinking fallback still fits an unknown long name.
        assert_eq!(short_id("abcdefghij_klmnopqrst_uvwxyz").len(), PARAM_ID_LEN);
    }

    #[test]
    fn the_task_parameters_of_a_gym_constructor_are_all_served() {
        let ids: Vec<String> = entries(TaskKind::Hover)
            .into_iter()
            .map(|e| e.name.to_string())
            .collect();
        for name in [
            "max_steps",
            "dt",
            "wind_enabled",
            "target_change_interval",
            "wind_speed_max",
        ] {
            assert!(ids.iter().any(|i| i == name), "{name}");
        }
        let ids: Vec<&str> = entries(TaskKind::Landing)
            .into_iter()
            .map(|e| e.name)
            .collect();
        for name in [
            "max_steps",
            "moving_platform",
            "dt",
            "initial_pos_random_range_m",
        ] {
            assert!(ids.contains(&name), "{name}");
        }
    }

    #[test]
    fn set_checks_bounds_and_relations_and_keeps_the_old_value() {
        let mut c = TaskConfig::default();
        set(&mut c, Group::Quadrotor, "mass", 2.0).unwrap();
        assert_eq!(c.quadrotor.mass, 2.0);
        let err = set(&mut c, Group::Quadrotor, "mass", -1.0).unwrap_err();
        assert!(err.to_string().contains("`mass`"), "{err}");
        let err = set(&mut c, Group::Quadrotor, "wind_speed_min", 50.0).unwrap_err();
        assert!(err.to_string().contains("wind_speed_min"), "{err}");
        assert_eq!((c.quadrotor.mass, c.quadrotor.wind_speed_min), (2.0, 0.0));
    }
}
