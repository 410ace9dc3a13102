//! Parameters of the multi-agent flight tasks (the rest of a multi-agent task's settings are
//! the single-agent flight parameters, the vehicle's and the world's).

use crate::param;
use crate::params::{ParamSpec, Parameters};
use crate::world::MAX_VEHICLES;
use serde::{Deserialize, Serialize};

/// Most neighbours an agent observes.
pub const MAX_NEIGHBOURS: u32 = 64;

/// What the multi-agent tasks add to a flight task. Units are SI; every field's range is in
/// [`MultiParams::specs`] and enforced by [`Parameters::validate`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct MultiParams {
    /// Number of agents (vehicles) in the world. Default 4.
    pub num_agents: u32,
    /// Nearest neighbours each agent observes (k); fewer present are padded as absent.
    /// Default 3.
    pub neighbours: u32,
    /// Reward taken from an agent on the step its hull starts touching another's. Default 10.
    pub collision_penalty: f64,
    /// An agent within this distance of its target has arrived, m. Default 0.5.
    pub arrival_radius: f64,
    /// Swap: radius of the circle the agents start on (each flies to the opposite point), m.
    /// Default 2.
    pub swap_radius: f64,
    /// MultiHover: distance between neighbouring start points (a square grid), m. Default 2.
    pub hover_spacing: f64,
    /// Swap: height between the agents' altitude layers, m: agent i starts and ends at
    /// `start_height + (i − (n−1)/2)·swap_layer` (0: all at `start_height`, as Swap-v0).
    /// Default 0.
    pub swap_layer: f64,
}

impl Default for MultiParams {
    fn default() -> Self {
        MultiParams {
            num_agents: 4,
            neighbours: 3,
            collision_penalty: 10.0,
            arrival_radius: 0.5,
            swap_radius: 2.0,
            hover_spacing: 2.0,
            swap_layer: 0.0,
        }
    }
}

static MULTI_SPECS: [ParamSpec<MultiParams>; 7] = [
    param!(integer num_agents, "", 1, MAX_VEHICLES, "Number of agents (vehicles) in the world"),
    param!(integer neighbours, "", 0, MAX_NEIGHBOURS, "Nearest neighbours each agent observes"),
    param!(real collision_penalty, "", 0.0, 1e6, "Reward taken on the step a collision starts"),
    param!(real arrival_radius, "m", 0.0, 1e4, "An agent this close to its target has arrived"),
    param!(real swap_radius, "m", 0.01, 1e4, "Swap: radius of the start circle"),
    param!(real hover_spacing, "m", 0.01, 1e4, "MultiHover: distance between neighbouring start points"),
    param!(real swap_layer, "m", 0.0, 10.0, "Swap: height between the agents' altitude layers"),
];

impl Parameters for MultiParams {
    fn specs() -> &'static [ParamSpec<Self>] {
        &MULTI_SPECS
    }
}
