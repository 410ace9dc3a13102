//! Where the agents of each multi-agent task start and where they fly.

use super::params::MultiParams;
use crate::tasks::flight::FlightParams;
use crate::tasks::hover::out_of_bounds_distance;
use nalgebra::Vector2;
use serde::{Deserialize, Serialize};

/// The multi-agent flight tasks.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum Scenario {
    /// Each agent starts on a square grid (`hover_spacing` apart) and flies to a target of
    /// its own, drawn around its start point as the single-agent Hover draws one; a collision
    /// ends the episode for both agents in it.
    MultiHover,
    /// The agents start evenly on a circle of `swap_radius` (turned by a random angle each
    /// episode) and fly to the opposite point, all through the middle; a collision or a crash
    /// ends the episode for every agent (the swap failed).
    Swap,
}

impl Scenario {
    /// The task's name ("multi_hover", "swap").
    pub fn name(self) -> &'static str {
        match self {
            Scenario::MultiHover => "multi_hover",
            Scenario::Swap => "swap",
        }
    }

    /// The scenario called `name`.
    pub fn from_name(name: &str) -> Option<Self> {
        match name {
            "multi_hover" => Some(Scenario::MultiHover),
            "swap" => Some(Scenario::Swap),
            _ => None,
        }
    }

    /// Whether one agent's collision or crash ends the episode for every agent.
    pub fn ends_together(self) -> bool {
        self == Scenario::Swap
    }

    /// Horizontal start point of agent `i` of `n` (ENU, m); `turn` is the episode's random
    /// angle in [0, 2π) (Swap).
    pub fn start_point(self, p: &MultiParams, i: usize, n: usize, turn: f64) -> Vector2<f64> {
        match self {
            Scenario::MultiHover => {
                let columns = (n as f64).sqrt().ceil().max(1.0) as usize;
                let rows = n.div_ceil(columns);
                let (c, r) = ((i % columns) as f64, (i / columns) as f64);
                let centre = |k: usize| (k as f64 - 1.0) / 2.0;
                Vector2::new(c - centre(columns), r - centre(rows)) * p.hover_spacing
            }
            Scenario::Swap => {
                let angle = turn + std::f64::consts::TAU * i as f64 / n as f64;
                Vector2::new(angle.cos(), angle.sin()) * p.swap_radius
            }
        }
    }

    /// Height of agent `i` of `n` above its start height, m: its altitude layer (Swap, 0 when
    /// `swap_layer` is 0; MultiHover 0).
    pub fn layer_offset(self, p: &MultiParams, i: usize, n: usize) -> f64 {
        match self {
            Scenario::MultiHover => 0.0,
            Scenario::Swap => (i as f64 - (n as f64 - 1.0) / 2.0) * p.swap_layer,
        }
    }

    /// The smallest distance between two start points of `n` agents, m (infinite for one).
    pub fn start_separation(self, p: &MultiParams, n: usize) -> f64 {
        if n < 2 {
            return f64::INFINITY;
        }
        match self {
            Scenario::MultiHover => p.hover_spacing,
            Scenario::Swap => 2.0 * p.swap_radius * (std::f64::consts::PI / n as f64).sin(),
        }
    }

    /// Distance from its target beyond which an agent is out of bounds, m: Hover's √3·side,
    /// plus the circle's diameter for Swap (its target starts that far away).
    pub fn out_of_bounds(self, multi: &MultiParams, flight: &FlightParams) -> f64 {
        match self {
            Scenario::MultiHover => out_of_bounds_distance(flight),
            Scenario::Swap => out_of_bounds_distance(flight) + 2.0 * multi.swap_radius,
        }
    }
}
