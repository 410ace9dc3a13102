//! Every parameter set a multi-agent task is built from, and the one way to build them from
//! `(name, value)` pairs.

use super::faults::AgentFaults;
use super::params::MultiParams;
use crate::error::ParamError;
use crate::faults::Reach;
use crate::params::Parameters;
use crate::quadrotor::{Frame, QuadrotorParams};
use crate::rate_loop::RateLoopParams;
use crate::tasks::flight::FlightParams;
use crate::tasks::randomization::{ParamRange, Randomization, VehicleParams};
use crate::world::WorldParams;

/// The parameter sets of a multi-agent task.
#[derive(Debug, Clone, PartialEq)]
pub struct MultiConfig {
    pub multi: MultiParams,
    /// The world the agents share: its wind (off by default here), contact and downwash.
    pub world: WorldParams,
    /// Every agent's flight parameters (control period, episode length, interface, …).
    pub flight: FlightParams,
    /// Every agent's nominal vehicle; its own wind is off (the wind is the world's).
    pub quadrotor: QuadrotorParams,
    pub rate_loop: RateLoopParams,
    /// Per-agent, per-episode ranges of vehicle parameters (empty: off).
    pub randomize: Randomization,
    /// The agents' faults, each table for one agent or all (empty: healthy vehicles).
    pub faults: AgentFaults,
}

impl Default for MultiConfig {
    fn default() -> Self {
        MultiConfig {
            multi: MultiParams::default(),
            world: WorldParams {
                wind_enabled: false,
                ..WorldParams::default()
            },
            flight: FlightParams::default(),
            quadrotor: QuadrotorParams::default(),
            rate_loop: RateLoopParams::default(),
            randomize: Randomization::none(),
            faults: AgentFaults::default(),
        }
    }
}

/// The set a parameter name belongs to, in the order names are looked up: a name both the
/// world and the vehicle have (the wind's) is the world's.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Set {
    Multi,
    World,
    Flight,
    Quadrotor,
    RateLoop,
}

fn set_of(name: &str) -> Option<Set> {
    if MultiParams::spec(name).is_ok() {
        Some(Set::Multi)
    } else if WorldParams::spec(name).is_ok() {
        Some(Set::World)
    } else if FlightParams::spec(name).is_ok() {
        Some(Set::Flight)
    } else if QuadrotorParams::spec(name).is_ok() {
        Some(Set::Quadrotor)
    } else if RateLoopParams::spec(name).is_ok() {
        Some(Set::RateLoop)
    } else {
        None
    }
}

/// Sets one value, checked against its row; relations are checked once all are set.
fn put<P: Parameters>(set: &mut P, name: &str, value: f64) -> Result<(), ParamError> {
    let spec = P::spec(name)?;
    spec.check(value)?;
    (spec.set)(set, value);
    Ok(())
}

impl MultiConfig {
    /// The sets from `(core name, value)` pairs (the rest keep [`MultiConfig::default`]'s
    /// values) and per-agent randomisation ranges; every value and relation is checked.
    pub fn from_values<'a>(
        pairs: impl IntoIterator<Item = (&'a str, f64)>,
        ranges: Vec<ParamRange>,
    ) -> Result<Self, ParamError> {
        let mut config = MultiConfig::default();
        for (name, value) in pairs {
            let Some(set) = set_of(name) else {
                return Err(ParamError::Parse(format!(
                    "unknown parameter `{name}` for a multi-agent task"
                )));
            };
            match set {
                Set::Multi => put(&mut config.multi, name, value)?,
                Set::World => put(&mut config.world, name, value)?,
                Set::Flight => put(&mut config.flight, name, value)?,
                Set::Quadrotor => put(&mut config.quadrotor, name, value)?,
                Set::RateLoop => put(&mut config.rate_loop, name, value)?,
            }
        }
        config.randomize = Randomization::new(ranges)?;
        config.validate()?;
        Ok(config)
    }

    /// Checks every set and the randomisation against the vehicle.
    pub fn validate(&self) -> Result<(), ParamError> {
        self.multi.validate()?;
        self.world.validate()?;
        self.flight.validate()?;
        self.quadrotor.validate()?;
        self.rate_loop.validate()?;
        self.randomize.check(&self.vehicle())?;
        self.faults.check(
            self.multi.num_agents,
            &Reach {
                duration: Some(self.flight.episode_duration()),
                waypoints: None,
                rotors: self.vehicle().frame.rotor_count(),
            },
        )
    }

    /// The config with the agents' `faults`, checked against it.
    pub fn with_faults(mut self, faults: AgentFaults) -> Result<Self, ParamError> {
        self.faults = faults;
        self.validate()?;
        Ok(self)
    }

    /// Agent `i`'s nominal vehicle with its faults.
    pub fn agent_vehicle(&self, i: u32) -> VehicleParams {
        VehicleParams {
            faults: self.faults.plan(i),
            ..self.vehicle()
        }
    }

    /// Each agent's nominal vehicle (its own wind off: the world's blows).
    pub fn vehicle(&self) -> VehicleParams {
        VehicleParams {
            quadrotor: QuadrotorParams {
                wind_enabled: false,
                ..self.quadrotor.clone()
            },
            rate_loop: self.rate_loop.clone(),
            flight: self.flight.clone(),
            frame: Frame::quad_x(),
            faults: crate::faults::FaultPlan::default(),
        }
    }
}
