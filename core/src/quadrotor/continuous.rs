//! The quadrotor as a hybrid system for a Model-Exchange solver (FMI 2.0 ME): the
//! continuous state vector and its derivative — the very right-hand side the stepper's RK4
//! integrates ([`dynamics::derivative_vector`]) — the event indicators (foot heights) and
//! the discrete changes at events. Between events the command, the external wind and the
//! turbulence are constant, so the solver integrates a smooth ODE:
//! - a foot crossing the ground plane is a state event (the contact force switches on or
//!   off); a foot that has lifted off gets its bristle released, as the stepper does at the
//!   end of every substep;
//! - a turbulence sample is a time event every `turbulence_dt` seconds, drawn from the same
//!   random stream in the same order as the stepper draws it, so both see the same weather.

use super::contact::Gear;
use super::dynamics;
use super::model::Quadrotor;
use super::variables::MOTOR_STATE_NAMES;
use super::wind;
use crate::error::{CommandError, check_finite};

/// Number of event indicators: one foot height per landing-gear foot.
pub const EVENT_INDICATORS: usize = 4;

/// The continuous states that are not outputs of the variable table (those are x .. z,
/// vx .. vz, qw .. qz, wx .. wz and one motor_state_<i> per rotor): the bristle stretches,
/// (name, description), in state-vector order after the body values.
pub const BRISTLES: [(&str, &str); 8] = [
    (
        "gear_stretch_0_x",
        "Friction bristle stretch of foot 0 (front-right), east",
    ),
    (
        "gear_stretch_0_y",
        "Friction bristle stretch of foot 0 (front-right), north",
    ),
    (
        "gear_stretch_1_x",
        "Friction bristle stretch of foot 1 (rear-left), east",
    ),
    (
        "gear_stretch_1_y",
        "Friction bristle stretch of foot 1 (rear-left), north",
    ),
    (
        "gear_stretch_2_x",
        "Friction bristle stretch of foot 2 (front-left), east",
    ),
    (
        "gear_stretch_2_y",
        "Friction bristle stretch of foot 2 (front-left), north",
    ),
    (
        "gear_stretch_3_x",
        "Friction bristle stretch of foot 3 (rear-right), east",
    ),
    (
        "gear_stretch_3_y",
        "Friction bristle stretch of foot 3 (rear-right), north",
    ),
];

/// The output names of the 13 rigid-body states, in state-vector order (the motor states
/// `motor_state_<i>` follow them, one per rotor).
pub const RIGID_BODY_STATE_OUTPUTS: [&str; 13] = [
    "x", "y", "z", "vx", "vy", "vz", "qw", "qx", "qy", "qz", "wx", "wy", "wz",
];

/// The output names of the body states of a vehicle with `rotors` rotors (at most
/// `MAX_ROTORS`), in state-vector order: the rigid body, then the motor states.
pub fn body_state_outputs(rotors: usize) -> impl Iterator<Item = &'static str> + Clone {
    let motors = MOTOR_STATE_NAMES.iter().take(rotors).copied();
    RIGID_BODY_STATE_OUTPUTS.into_iter().chain(motors)
}

impl Quadrotor {
    /// Number of continuous states: 13 rigid-body values, one per motor, 8 bristles.
    pub fn state_len(&self) -> usize {
        dynamics::state_len(self.frame().rotor_count())
    }

    /// The continuous state (layout of [`dynamics::state_vector`]).
    pub fn continuous_state(&self) -> Vec<f64> {
        dynamics::state_vector(&self.body)
    }

    /// Sets the continuous state; it must have [`Quadrotor::state_len`] values, every one
    /// finite (nothing changes otherwise).
    pub fn set_continuous_state(&mut self, x: &[f64]) -> Result<(), CommandError> {
        if x.len() != self.state_len() {
            return Err(CommandError::WrongLength {
                what: "continuous state",
                expected: self.state_len(),
                got: x.len(),
            });
        }
        check_finite("continuous state", x)?;
        dynamics::set_state_vector(x, &mut self.body);
        Ok(())
    }

    /// The derivative of [`Quadrotor::continuous_state`] under the current command and wind.
    pub fn state_derivative(&self) -> Vec<f64> {
        dynamics::derivative_vector(
            &self.params,
            self.frame(),
            &self.body,
            &self.motor_input(),
            &self.surroundings(),
        )
    }

    /// The event indicators: each foot's height above the ground (a sign change is a touch
    /// down or a lift-off), or a constant 1 when the ground is off.
    pub fn event_indicators(&self) -> [f64; EVENT_INDICATORS] {
        if self.params.ground_enabled {
            self.foot_heights()
        } else {
            [1.0; EVENT_INDICATORS]
        }
    }

    /// Seconds from the last event to the next turbulence sample, or `None` without wind.
    pub fn time_to_turbulence_sample(&self) -> Option<f64> {
        self.params
            .wind_enabled
            .then_some(self.params.turbulence_dt - self.wind.since_sample)
    }

    /// The discrete changes of an event `elapsed` seconds after the previous one: the
    /// turbulence clock moves on and draws every sample that is due; the feet above the ground
    /// release their bristles.
    pub fn event_update(&mut self, elapsed: f64) {
        if self.params.wind_enabled {
            self.wind.since_sample += elapsed.max(0.0);
            while wind::sample_due(&self.params, &self.wind) {
                let rest = self.wind.since_sample - self.params.turbulence_dt;
                self.sample_turbulence();
                // Only an importer that skipped a time event leaves a rest worth keeping.
                if rest > self.params.turbulence_dt * 1e-6 {
                    self.wind.since_sample = rest;
                }
            }
        }
        if self.params.ground_enabled {
            let mut x = self.continuous_state();
            Gear::new(&self.params).release_lifted_feet(&mut x);
            dynamics::set_state_vector(&x, &mut self.body);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::quadrotor::{BodyState, QuadrotorParams};
    use crate::rng::SimRng;
    use nalgebra::Vector3;

    fn flying(wind: bool) -> Quadrotor {
        let params = QuadrotorParams {
            wind_enabled: wind,
            ..Default::default()
        };
        let mut body = BodyState::at_rest(Vector3::new(0.2, -0.1, 2.0), 0.1, -0.2, 0.3, 0.5);
        body.velocity = Vector3::new(0.3, 0.1, -0.4);
        body.body_rates = Vector3::new(0.2, -0.5, 0.1);
        let mut quad = Quadrotor::new(params, body, SimRng::new(3)).unwrap();
        quad.set_command([0.6, 0.4, 0.55, 0.45]).unwrap();
        quad
    }

    /// The state vector names the body's values in order, and writing it back is exact.
    #[test]
    fn the_state_vector_round_trips_and_its_derivative_is_the_cores() {
        let mut quad = flying(true);
        let x = quad.continuous_state();
        assert_eq!(x[..3], [0.2, -0.1, 2.0]);
        assert_eq!(x[13..17], [0.5; 4]);
        let d = quad.state_derivative();
        let core = dynamics::derivatives(
            &quad.params,
            quad.frame(),
            &quad.body,
            &quad.command(),
            &quad.surroundings(),
        );
        assert_eq!(d[..3], [0.3, 0.1, -0.4]);
        assert_eq!(d[3..6], *core.acceleration.as_slice());
        assert_eq!(d[13], (0.6 - 0.5) / 0.08);
        let mut y = x.clone();
        y[2] = 1.0;
        quad.set_continuous_state(&y).unwrap();
        assert_eq!(quad.continuous_state(), y);
        y[5] = f64::NAN;
        let Err(CommandError::NotFinite(e)) = quad.set_continuous_state(&y) else {
            panic!("a NaN state was taken");
        };
        assert_eq!((e.index, quad.continuous_state()[5]), (5, x[5]));
        let e = quad.set_continuous_state(&y[..20]).unwrap_err();
        assert_eq!(
            e.to_string(),
            "continuous state has 20 values, the vehicle takes 25"
        );
    }

    /// Events on the turbulence grid draw the same samples as the stepper does.
    #[test]
    fn time_events_draw_the_steppers_samples() {
        let mut stepped = flying(true);
        let mut evented = stepped.clone();
        for _ in 0..7 {
            stepped.step(stepped.params.turbulence_dt);
            let dt = evented.time_to_turbulence_sample().unwrap();
            assert!((dt - 0.01).abs() < 1e-12, "{dt}");
            evented.event_update(dt);
            assert_eq!(evented.wind, stepped.wind);
        }
        // A half-way event (a foot touching) does not sample.
        let before = evented.wind;
        evented.event_update(0.004);
        assert_eq!(evented.wind.turbulence, before.turbulence);
        assert!((evented.time_to_turbulence_sample().unwrap() - 0.006).abs() < 1e-15);
        assert_eq!(flying(false).time_to_turbulence_sample(), None);
    }

    /// Foot heights are the indicators; a lifted foot loses its bristle at an event.
    #[test]
    fn feet_are_the_event_indicators_and_lift_off_releases_the_bristle() {
        let mut quad = flying(false);
        assert_eq!(quad.event_indicators(), quad.foot_heights());
        quad.body.gear_stretch = [[1e-4, -2e-4]; 4];
        quad.body.position.z = 0.0; // two feet in the ground, two above (tilted)
        let heights = quad.foot_heights();
        quad.event_update(0.0);
        for (h, s) in heights.iter().zip(quad.body.gear_stretch) {
            assert_eq!(s == [0.0; 2], *h > 0.0, "{h} {s:?}");
        }
        quad.params.ground_enabled = false;
        assert_eq!(quad.event_indicators(), [1.0; 4]);
    }
}
