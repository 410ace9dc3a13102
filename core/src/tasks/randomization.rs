//! Domain randomisation: named physical parameters drawn per episode from ranges, seeded by
//! the episode's seed, so the same seed gives the same vehicle bit for bit in every front end.
//!
//! A range names a real parameter of the quadrotor ([`QuadrotorParams`]), of PX4's rate loop
//! ([`RateLoopParams`]) or one of the flight task's latency and noise parameters, and gives
//! [low, high] inside that parameter's own bounds. Each episode draws every named parameter
//! uniformly in its range from a generator of its own (the episode's other draws — start,
//! target, wind — are the same with or without randomisation).

use crate::error::ParamError;
use crate::faults::FaultPlan;
use crate::number::Compact;
use crate::params::{ParamSpec, Parameters, ValueKind};
use crate::quadrotor::{Frame, QuadrotorParams};
use crate::rate_loop::{Px4Rotor, RateLoopParams, px4_rotors};
use crate::rng::SimRng;
use crate::tasks::flight::FlightParams;
use serde::{Deserialize, Serialize};

/// Flight-task parameters that may be randomised (the rest shape the task, not the vehicle).
pub const FLIGHT_RANDOMIZABLE: [&str; 5] = [
    "action_latency",
    "obs_noise_position",
    "obs_noise_velocity",
    "obs_noise_attitude",
    "obs_noise_rates",
];

/// Parameters that take part in a relation with another one: drawing them could break it.
const NOT_RANDOMIZABLE: [&str; 1] = ["wind_speed_min"];

/// One parameter's range, inclusive.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ParamRange {
    pub name: String,
    pub low: f64,
    pub high: f64,
}

/// The parameters drawn each episode; empty (the default) = no randomisation.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct Randomization {
    ranges: Vec<ParamRange>,
}

/// The parameter sets a flight vehicle is built from, as randomisation sees them, and its
/// frame (the rotor table; not randomised).
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct VehicleParams {
    pub quadrotor: QuadrotorParams,
    pub rate_loop: RateLoopParams,
    pub flight: FlightParams,
    #[serde(default)]
    pub frame: Frame,
    /// The vehicle's faults (empty: healthy). Not randomised by ranges: its own
    /// `[[fault_randomization]]` draws them ([`crate::faults`]).
    pub faults: FaultPlan,
}

impl VehicleParams {
    /// PX4's rotors for this vehicle's frame: what the rate loop's allocator mixes for.
    pub fn mixer(&self) -> Vec<Px4Rotor> {
        px4_rotors(&self.frame, &self.quadrotor)
    }
}

/// Where a named parameter lives.
enum Owner {
    Quadrotor(&'static ParamSpec<QuadrotorParams>),
    RateLoop(&'static ParamSpec<RateLoopParams>),
    Flight(&'static ParamSpec<FlightParams>),
}

fn owner(name: &str) -> Option<Owner> {
    if let Ok(s) = QuadrotorParams::spec(name) {
        return Some(Owner::Quadrotor(s));
    }
    if let Ok(s) = RateLoopParams::spec(name) {
        return Some(Owner::RateLoop(s));
    }
    if FLIGHT_RANDOMIZABLE.contains(&name) {
        return FlightParams::spec(name).ok().map(Owner::Flight);
    }
    None
}

impl Owner {
    fn bounds(&self) -> (&'static str, ValueKind, f64, f64, &'static str) {
        match self {
            Owner::Quadrotor(s) => (s.name, s.kind, s.min, s.max, s.unit),
            Owner::RateLoop(s) => (s.name, s.kind, s.min, s.max, s.unit),
            Owner::Flight(s) => (s.name, s.kind, s.min, s.max, s.unit),
        }
    }

    fn set(&self, params: &mut VehicleParams, value: f64) {
        match self {
            Owner::Quadrotor(s) => (s.set)(&mut params.quadrotor, value),
            Owner::RateLoop(s) => (s.set)(&mut params.rate_loop, value),
            Owner::Flight(s) => (s.set)(&mut params.flight, value),
        }
    }
}

/// Every parameter name a range may use, in the parameter tables' order (quadrotor, flight
/// task, rate loop: the order `flyloop-sitl --list-params` lists them).
pub fn randomizable_names() -> Vec<&'static str> {
    let real = |kind: ValueKind, name: &'static str| {
        (kind == ValueKind::Real && !NOT_RANDOMIZABLE.contains(&name)).then_some(name)
    };
    QuadrotorParams::specs()
        .iter()
        .filter_map(|s| real(s.kind, s.name))
        .chain(FLIGHT_RANDOMIZABLE)
        .chain(
            RateLoopParams::specs()
                .iter()
                .filter_map(|s| real(s.kind, s.name)),
        )
        .collect()
}

impl Randomization {
    /// No randomisation.
    pub fn none() -> Self {
        Randomization::default()
    }

    /// Ranges by name, in any order: they are kept, drawn and reported in the order of
    /// [`randomizable_names`] (the parameter tables' order), so the same ranges give the same
    /// vehicles however they were listed. Each name must be a randomisable parameter, named
    /// once; each range finite, low ≤ high, inside the parameter's bounds. Relations are
    /// checked by [`Randomization::check`].
    pub fn new(ranges: Vec<ParamRange>) -> Result<Self, ParamError> {
        for (i, r) in ranges.iter().enumerate() {
            let known = owner(&r.name).filter(|_| !NOT_RANDOMIZABLE.contains(&r.name.as_str()));
            let Some(owner) = known else {
                return Err(ParamError::UnknownName(format!(
                    "{}` in the randomisation ranges; randomisable: `{}",
                    r.name,
                    randomizable_names().join("`, `")
                )));
            };
            let (name, kind, min, max, unit) = owner.bounds();
            if kind != ValueKind::Real {
                return Err(ParamError::Relation {
                    name,
                    requirement: format!(
                        "randomisation range of `{name}`: only real parameters can be randomised"
                    ),
                });
            }
            if ranges[..i].iter().any(|o| o.name == r.name) {
                return Err(ParamError::Relation {
                    name,
                    requirement: format!("`{name}` has two randomisation ranges"),
                });
            }
            let inside = |v: f64| v >= min && v <= max;
            if !(inside(r.low) && inside(r.high) && r.low <= r.high) {
                return Err(ParamError::Relation {
                    name,
                    requirement: format!(
                        "randomisation range of `{name}` = [{}, {}] {unit} must be ordered (low <= high) and inside [{}, {}] {unit}",
                        Compact(r.low),
                        Compact(r.high),
                        Compact(min),
                        Compact(max)
                    ),
                });
            }
        }
        let order = randomizable_names();
        let mut ranges = ranges;
        ranges.sort_by_key(|r| order.iter().position(|n| *n == r.name));
        Ok(Randomization { ranges })
    }

    pub fn ranges(&self) -> &[ParamRange] {
        &self.ranges
    }

    pub fn is_off(&self) -> bool {
        self.ranges.is_empty()
    }

    /// `nominal` with every range at `fraction` of its way from low (0) to high (1), and
    /// the values set.
    pub fn corner(&self, nominal: &VehicleParams, fraction: f64) -> (VehicleParams, Vec<f64>) {
        let mut p = nominal.clone();
        let mut values = Vec::with_capacity(self.ranges.len());
        for r in &self.ranges {
            let value = r.low + fraction * (r.high - r.low);
            if let Some(o) = owner(&r.name) {
                o.set(&mut p, value);
            }
            values.push(value);
        }
        (p, values)
    }

    /// Checks that `nominal` with every range at its low end, and at its high end, is a
    /// valid vehicle (the relations between parameters hold at both corners).
    pub fn check(&self, nominal: &VehicleParams) -> Result<(), ParamError> {
        for fraction in [0.0, 1.0] {
            let (p, _) = self.corner(nominal, fraction);
            p.quadrotor.validate()?;
            p.rate_loop.validate()?;
            p.flight.validate()?;
        }
        Ok(())
    }

    /// The vehicle of the episode with `seed`: `nominal` with every range drawn, and the
    /// drawn values in the ranges' order. No ranges: `nominal` itself, nothing drawn.
    pub fn draw(&self, nominal: &VehicleParams, seed: u64) -> (VehicleParams, Vec<f64>) {
        let mut params = nominal.clone();
        if self.ranges.is_empty() {
            return (params, Vec::new());
        }
        let mut rng = SimRng::new(seed ^ RANDOMIZATION_STREAM);
        let mut values = Vec::with_capacity(self.ranges.len());
        for r in &self.ranges {
            let value = rng.uniform(r.low, r.high);
            if let Some(o) = owner(&r.name) {
                o.set(&mut params, value);
            }
            values.push(value);
        }
        (params, values)
    }
}

/// Salt of the randomisation's generator: its draws do not disturb the episode's own stream.
const RANDOMIZATION_STREAM: u64 = 0x0d0a_1d5e_ed00_0001;

#[cfg(test)]
mod tests {
    use super::*;

    fn range(name: &str, low: f64, high: f64) -> ParamRange {
        ParamRange {
            name: name.into(),
            low,
            high,
        }
    }

    #[test]
    fn same_seed_same_vehicle_other_seed_other_vehicle() {
        let r = Randomization::new(vec![
            range("mass", 1.2, 1.8),
            range("thrust_coefficient", 9.0, 11.0),
            range("roll_rate_p", 0.1, 0.2),
            range("action_latency", 0.0, 0.03),
        ])
        .unwrap();
        let nominal = VehicleParams::default();
        r.check(&nominal).unwrap();
        let (a, va) = r.draw(&nominal, 7);
        let (b, vb) = r.draw(&nominal, 7);
        assert_eq!(a, b);
        assert_eq!(
            va.iter().map(|v| v.to_bits()).collect::<Vec<_>>(),
            vb.iter().map(|v| v.to_bits()).collect::<Vec<_>>()
        );
        assert_eq!(a.quadrotor.mass, va[0]);
        // Drawn in the tables' order: quadrotor, flight task, rate loop.
        assert_eq!(a.flight.action_latency, va[2]);
        assert_eq!(a.rate_loop.roll_rate_p, va[3]);
        assert!((1.2..=1.8).contains(&va[0]) && (0.0..=0.03).contains(&va[2]));
        let (c, _) = r.draw(&nominal, 8);
        assert_ne!(a.quadrotor.mass, c.quadrotor.mass);
        // Untouched parameters keep their nominal values.
        assert_eq!(a.quadrotor.arm_length, nominal.quadrotor.arm_length);
    }

    #[test]
    fn the_order_ranges_are_given_in_does_not_matter() {
        let a = Randomization::new(vec![
            range("roll_rate_p", 0.1, 0.2),
            range("mass", 1.0, 2.0),
        ]);
        let b = Randomization::new(vec![
            range("mass", 1.0, 2.0),
            range("roll_rate_p", 0.1, 0.2),
        ]);
        let (a, b) = (a.unwrap(), b.unwrap());
        assert_eq!(a, b);
        let nominal = VehicleParams::default();
        assert_eq!(a.draw(&nominal, 3), b.draw(&nominal, 3));
        assert_eq!(a.ranges()[0].name, "mass");
    }

    #[test]
    fn bad_names_and_ranges_are_named() {
        let err = Randomization::new(vec![range("masss", 1.0, 2.0)])
            .unwrap_err()
            .to_string();
        assert!(err.contains("`masss`") && err.contains("`mass`"), "{err}");
        let err = Randomization::new(vec![range("mass", 2.0, 1.0)])
            .unwrap_err()
            .to_string();
        assert!(err.contains("`mass` = [2, 1] kg must be ordered"), "{err}");
        let err = Randomization::new(vec![range("mass", -1.0, 1.0)])
            .unwrap_err()
            .to_string();
        assert!(err.contains("inside [0.001, 10000] kg"), "{err}");
        let err = Randomization::new(vec![range("mass", 1.0, f64::NAN)])
            .unwrap_err()
            .to_string();
        assert!(err.contains("`mass`"), "{err}");
        let err = Randomization::new(vec![range("ground_enabled", 0.0, 1.0)])
            .unwrap_err()
            .to_string();
        assert!(
            err.contains("only real parameters can be randomised"),
            "{err}"
        );
        let err = Randomization::new(vec![range("wind_speed_min", 0.0, 1.0)])
            .unwrap_err()
            .to_string();
        assert!(err.contains("`wind_speed_min`"), "{err}");
        let err = Randomization::new(vec![range("dt", 0.01, 0.02)])
            .unwrap_err()
            .to_string();
        assert!(err.contains("`dt`"), "{err}");
        let err = Randomization::new(vec![range("mass", 1.0, 2.0), range("mass", 1.0, 2.0)])
            .unwrap_err()
            .to_string();
        assert!(err.contains("two randomisation ranges"), "{err}");
    }

    #[test]
    fn a_corner_that_breaks_a_relation_is_refused() {
        // wind_speed_max below the nominal wind_speed_min (0 by default: raise it first).
        let mut nominal = VehicleParams::default();
        nominal.quadrotor.wind_speed_min = 2.0;
        let r = Randomization::new(vec![range("wind_speed_max", 1.0, 6.0)]).unwrap();
        let err = r.check(&nominal).unwrap_err().to_string();
        assert!(err.contains("wind_speed_min"), "{err}");
    }
}
