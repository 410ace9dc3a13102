//! When a fault fires: at a simulation time, when a condition first holds (above a height,
//! some time after takeoff, on reaching a waypoint), and for how long it stays.

use crate::error::ParamError;
use serde::{Deserialize, Serialize};

/// The moment a fault fires. Times are simulation time since the episode's start, s.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub enum Trigger {
    /// At simulation time `t` (`at = t`), s.
    At(f64),
    /// The first time the vehicle's height exceeds this (`above_height`), m.
    AboveHeight(f64),
    /// This long after the vehicle first leaves the ground (`after_takeoff`), s; a vehicle
    /// that starts in the air took off at time 0.
    AfterTakeoff(f64),
    /// When the waypoint of this index (0 = the first) becomes the current one
    /// (`at_waypoint`).
    AtWaypoint(u32),
}

/// The keys a trigger is written with, in a fault's table.
pub const TRIGGER_KEYS: [&str; 4] = ["at", "above_height", "after_takeoff", "at_waypoint"];

/// What a trigger reads of the flight, each control step.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Conditions {
    /// Simulation time, s.
    pub time: f64,
    /// Height of the centre of mass above the ground plane, m.
    pub height: f64,
    /// When the vehicle first left the ground, s (`None`: not yet).
    pub takeoff: Option<f64>,
    /// Index of the current waypoint (`None`: the task has none).
    pub waypoint: Option<u32>,
}

/// What the flight can reach, to refuse a trigger that can never fire.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Reach {
    /// Length of an episode, s (`None`: unbounded, as in the SITL's autopilot modes).
    pub duration: Option<f64>,
    /// Waypoints of the task (`None`: a task without waypoints).
    pub waypoints: Option<u32>,
    /// Rotors of the frame (a motor index must name one of them).
    pub rotors: usize,
}

impl Trigger {
    /// Whether the trigger fires under `c`.
    pub fn holds(&self, c: &Conditions) -> bool {
        match *self {
            Trigger::At(t) => c.time >= t - TIME_TOLERANCE,
            Trigger::AboveHeight(h) => c.height > h,
            Trigger::AfterTakeoff(d) => c
                .takeoff
                .is_some_and(|t0| c.time >= t0 + d - TIME_TOLERANCE),
            Trigger::AtWaypoint(i) => c.waypoint.is_some_and(|w| w >= i),
        }
    }

    /// The key it is written with.
    pub fn key(&self) -> &'static str {
        match self {
            Trigger::At(_) => "at",
            Trigger::AboveHeight(_) => "above_height",
            Trigger::AfterTakeoff(_) => "after_takeoff",
            Trigger::AtWaypoint(_) => "at_waypoint",
        }
    }

    /// The trigger written as `key = value`; the value must be finite, non-negative (a
    /// waypoint index an integer).
    pub fn parse(key: &str, value: f64) -> Result<Trigger, ParamError> {
        let bad = |requirement: &str| ParamError::Relation {
            name: static_key(key),
            requirement: format!("fault trigger `{key}` = {value} {requirement}"),
        };
        if !(value.is_finite() && value >= 0.0) {
            return Err(bad("must be a finite number >= 0"));
        }
        Ok(match key {
            "at" => Trigger::At(value),
            "above_height" => Trigger::AboveHeight(value),
            "after_takeoff" => Trigger::AfterTakeoff(value),
            "at_waypoint" if value.fract() == 0.0 && value <= f64::from(u32::MAX) => {
                Trigger::AtWaypoint(value as u32)
            }
            "at_waypoint" => return Err(bad("must be a whole waypoint index")),
            _ => {
                return Err(ParamError::UnknownName(format!(
                    "{key}` as a fault trigger; triggers: `{}",
                    TRIGGER_KEYS.join("`, `")
                )));
            }
        })
    }

    /// Refuses a trigger that cannot fire in a flight that reaches `reach`.
    pub fn check_reachable(&self, reach: &Reach) -> Result<(), ParamError> {
        let never = |requirement: String| ParamError::Relation {
            name: self.key(),
            requirement,
        };
        match (*self, reach) {
            (
                Trigger::At(t) | Trigger::AfterTakeoff(t),
                Reach {
                    duration: Some(d), ..
                },
            ) if t >= *d => Err(never(format!(
                "fault trigger `{}` = {t} s can never fire: an episode lasts {d} s (max_steps × dt); it must be < {d} s",
                self.key()
            ))),
            (
                Trigger::AtWaypoint(_),
                Reach {
                    waypoints: None, ..
                },
            ) => Err(never(
                "fault trigger `at_waypoint` can never fire: the task has no waypoints".into(),
            )),
            (
                Trigger::AtWaypoint(i),
                Reach {
                    waypoints: Some(n), ..
                },
            ) if i >= *n => Err(never(format!(
                "fault trigger `at_waypoint` = {i} can never fire: the task has {n} waypoints (indices 0 to {})",
                n.saturating_sub(1)
            ))),
            _ => Ok(()),
        }
    }
}

/// Times closer than this are the same instant, s.
const TIME_TOLERANCE: f64 = 1e-9;

fn static_key(key: &str) -> &'static str {
    TRIGGER_KEYS
        .into_iter()
        .find(|k| *k == key)
        .unwrap_or("trigger")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn triggers_fire_when_their_condition_first_holds() {
        let mut c = Conditions::default();
        assert!(!Trigger::At(1.0).holds(&c));
        c.time = 1.0;
        assert!(Trigger::At(1.0).holds(&c));
        c.height = 2.0;
        assert!(Trigger::AboveHeight(1.5).holds(&c) && !Trigger::AboveHeight(2.0).holds(&c));
        assert!(!Trigger::AfterTakeoff(0.5).holds(&c));
        c.takeoff = Some(0.5);
        assert!(Trigger::AfterTakeoff(0.5).holds(&c) && !Trigger::AfterTakeoff(0.6).holds(&c));
        assert!(!Trigger::AtWaypoint(1).holds(&c));
        c.waypoint = Some(1);
        assert!(Trigger::AtWaypoint(1).holds(&c) && !Trigger::AtWaypoint(2).holds(&c));
    }

    #[test]
    fn a_trigger_that_can_never_fire_is_named() {
        let reach = Reach {
            duration: Some(10.0),
            waypoints: None,
            rotors: 4,
        };
        let e = Trigger::At(12.0)
            .check_reachable(&reach)
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("`at` = 12 s can never fire") && e.contains("< 10 s"),
            "{e}"
        );
        let e = Trigger::AtWaypoint(0)
            .check_reachable(&reach)
            .unwrap_err()
            .to_string();
        assert!(e.contains("no waypoints"), "{e}");
        let reach = Reach {
            waypoints: Some(3),
            ..reach
        };
        let e = Trigger::AtWaypoint(3)
            .check_reachable(&reach)
            .unwrap_err()
            .to_string();
        assert!(e.contains("has 3 waypoints (indices 0 to 2)"), "{e}");
        assert!(Trigger::AtWaypoint(2).check_reachable(&reach).is_ok());
        let e = Trigger::parse("at", -1.0).unwrap_err().to_string();
        assert!(e.contains("`at` = -1 must be a finite number >= 0"), "{e}");
        let e = Trigger::parse("when", 1.0).unwrap_err().to_string();
        assert!(e.contains("`when`") && e.contains("`above_height`"), "{e}");
        let e = Trigger::parse("at_waypoint", 1.5).unwrap_err().to_string();
        assert!(e.contains("whole waypoint index"), "{e}");
    }
}
