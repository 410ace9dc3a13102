//! The vehicle a lone flight task flies: an air vehicle (any multirotor frame, held through
//! the seam, [`crate::vehicle::AirVehicle`]) and its [`FlightLink`] (the action
//! interface, randomisation and, on the rates interface, PX4's rate loop; see that module).

use super::flight_faults::FlightFaults;
use super::flight_link::FlightLink;
use super::randomization::{Randomization, VehicleParams};
use crate::error::ParamError;
use crate::quadrotor::BodyState;
use crate::rng::SimRng;
use crate::tasks::{ActionError, InfoVisitor};
use crate::vehicle::AirVehicle;
use nalgebra::Vector3;
use serde::{Deserialize, Serialize};

/// An air vehicle with its action interface and per-episode randomisation.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct FlightVehicle {
    link: FlightLink,
    quad: Box<dyn AirVehicle>,
}

// By hand: a derived `==` on a boxed trait object tries to move it (rust-lang/rust#31740).
impl PartialEq for FlightVehicle {
    fn eq(&self, other: &Self) -> bool {
        self.link == other.link && self.quad.same_as(other.quad.as_ref())
    }
}

impl FlightVehicle {
    /// A vehicle from checked parameter sets; the randomisation's ranges are checked against
    /// them (both corners must be valid vehicles).
    pub fn new(nominal: VehicleParams, randomization: Randomization) -> Result<Self, ParamError> {
        let (link, quad) = FlightLink::new(nominal, randomization)?;
        Ok(FlightVehicle { link, quad })
    }

    /// Draws the vehicle of the episode with `seed` (nominal when randomisation is off) and
    /// returns its hover motor state (0 if it cannot hover), for the task's start.
    pub fn draw(&mut self, seed: u64) -> f64 {
        self.link.draw(self.quad.as_mut(), seed);
        self.quad.hover_motor_state().unwrap_or(0.0)
    }

    /// Number of action values: one per rotor (motor interface) or four (rates interface).
    pub fn action_size(&self) -> usize {
        self.link.action_size()
    }

    /// Number of rotors.
    pub fn rotor_count(&self) -> usize {
        self.link.rotor_count()
    }

    /// Starts the episode (after [`FlightVehicle::draw`]) at `body` with the episode's
    /// generator `rng`; `seed` seeds the observation noise.
    pub fn restart(&mut self, body: BodyState, rng: SimRng, seed: u64) {
        self.link.restart(self.quad.as_mut(), body, rng, seed);
    }

    /// The vehicle flown.
    pub fn air_vehicle(&self) -> &dyn AirVehicle {
        self.quad.as_ref()
    }

    /// The vehicle flown, to place it by hand.
    pub fn air_vehicle_mut(&mut self) -> &mut dyn AirVehicle {
        self.quad.as_mut()
    }

    /// The action interface.
    pub fn link(&self) -> &FlightLink {
        &self.link
    }

    /// The episode's faults, if the vehicle has any.
    pub fn faults(&self) -> Option<&FlightFaults> {
        self.link.faults()
    }

    /// Mutable access to the faults (the task's waypoint, run-time injection).
    pub fn faults_mut(&mut self) -> Option<&mut FlightFaults> {
        self.link.faults_mut()
    }

    /// Injects PX4's failure code now (see [`FlightLink::inject_px4`]).
    pub fn inject_px4(
        &mut self,
        unit: u8,
        failure: u8,
        instance: u8,
    ) -> Result<String, ParamError> {
        self.link.inject_px4(unit, failure, instance)
    }

    /// Whether actions are thrust + body rates.
    pub fn rates_interface(&self) -> bool {
        self.link.rates_interface()
    }

    /// Inclusive action bounds of the interface.
    pub fn action_bounds(&self) -> (Vec<f64>, Vec<f64>) {
        self.link.action_bounds()
    }

    /// Applies a 4-value action (clipped into the bounds) for `dt` seconds: the vehicle
    /// integrates from one rate-loop tick to the next (none on the motor interface).
    pub fn apply(&mut self, action: &[f64], dt: f64) -> Result<(), ActionError> {
        self.link.begin(self.quad.as_mut(), action, dt)?;
        let (mut now, end) = self.link.window(dt);
        while let Some(tick) = self.link.next_tick(end) {
            if tick > now {
                self.link.advance(self.quad.as_mut(), tick - now);
                now = tick;
            }
            self.link.tick(self.quad.as_mut());
        }
        if end > now {
            self.link.advance(self.quad.as_mut(), end - now);
        }
        self.link.finish(self.quad.as_ref());
        Ok(())
    }

    /// `point` (world ENU) relative to the observed position, in the observation's frame:
    /// world ENU for the motor interface, the heading frame for the rates interface.
    pub fn observed_offset(&self, point: &Vector3<f64>) -> Vector3<f64> {
        self.link.observed_offset(self.quad.as_ref(), point)
    }

    /// Number of values of the interface's observation.
    pub fn observation_size(&self) -> usize {
        self.link.observation_size()
    }

    /// The interface's observation groups: (name, number of values), in order.
    pub fn observation_layout(&self) -> Vec<(&'static str, usize)> {
        self.link.observation_layout()
    }

    /// Bounds of the interface's observation; `position_bound` bounds target − position.
    pub fn observation_bounds(&self, position_bound: f64) -> (Vec<f32>, Vec<f32>) {
        self.link.observation_bounds(position_bound)
    }

    /// Writes the interface's observation for `target` (world ENU) into `out`, each value
    /// clipped into `lo..=hi`.
    pub fn write_observation(
        &self,
        target: &Vector3<f64>,
        lo: &[f32],
        hi: &[f32],
        out: &mut [f32],
    ) {
        self.link
            .write_observation(self.quad.as_ref(), target, lo, hi, out);
    }

    /// Info entries of the vehicle: the values drawn this episode, when randomised; the
    /// faults' slots, when it has faults.
    pub fn visit_info(&self, visit: &mut InfoVisitor<'_>) {
        self.link.visit_info(visit);
    }
}
