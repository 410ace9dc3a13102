//! Every parameter set a task is built from.

use crate::faults::FaultPlan;
use crate::lander2d::Lander2dParams;
use crate::quadrotor::{Frame, QuadrotorParams};
use crate::rate_loop::RateLoopParams;
use crate::tasks::flight::FlightParams;
use crate::tasks::landing::LandingParams;
use crate::tasks::randomization::{Randomization, VehicleParams};
use crate::tasks::waypoints::WaypointParams;

/// Every parameter set a task is built from; a task uses only its own sets
/// ([`super::param_rows::Group::for_task`]).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct TaskConfig {
    pub quadrotor: QuadrotorParams,
    /// PX4's rate loop, flown by the flight tasks' rates interface.
    pub rate_loop: RateLoopParams,
    pub flight: FlightParams,
    pub waypoints: WaypointParams,
    pub lander: Lander2dParams,
    pub landing: LandingParams,
    /// Per-episode ranges of the flight tasks' vehicle parameters (empty: off).
    pub randomize: Randomization,
    /// The flight tasks' rotor table (`Frame::named("hexa_x")`, …); default the quad X.
    pub frame: Frame,
    /// The flight tasks' faults (`[[faults]]`, `[[fault_randomization]]`; empty: none).
    pub faults: FaultPlan,
}

impl TaskConfig {
    /// The flight tasks' vehicle: quadrotor, rate loop and flight parameters, and the frame.
    pub fn vehicle(&self) -> VehicleParams {
        VehicleParams {
            quadrotor: self.quadrotor.clone(),
            rate_loop: self.rate_loop.clone(),
            flight: self.flight.clone(),
            frame: self.frame.clone(),
            faults: self.faults.clone(),
        }
    }
}
