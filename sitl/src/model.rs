//! Which model and task a vehicle flies, its parameter sets, and the task instance built from
//! them. The SITL never steps physics itself: it calls the core's [`Task`] and reads the
//! model's state for the MAVLink messages.

use crate::kinematics::Kinematics;
use flyloop_core::ParamError;
use flyloop_core::lander2d::Lander2dParams;
use flyloop_core::quadrotor::QuadrotorParams;
use flyloop_core::rate_loop::RateLoopParams;
use flyloop_core::tasks::flight::FlightParams;
use flyloop_core::tasks::hover::Hover;
use flyloop_core::tasks::landing::{Landing, LandingParams};
use flyloop_core::tasks::randomization::{Randomization, VehicleParams};
use flyloop_core::tasks::waypoints::{WaypointParams, Waypoints};
use flyloop_core::tasks::{ActionError, Info, StepOutcome, Task};

/// The simulated vehicle model.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum ModelKind {
    Quadrotor,
    Lander2d,
}

impl ModelKind {
    /// The name used on the command line.
    pub fn name(self) -> &'static str {
        match self {
            ModelKind::Quadrotor => "quadrotor",
            ModelKind::Lander2d => "lander2d",
        }
    }
}

/// The task flown on the model.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum TaskKind {
    Hover,
    Waypoints,
    Landing,
}

impl TaskKind {
    /// The model a task runs on.
    pub fn model(self) -> ModelKind {
        match self {
            TaskKind::Hover | TaskKind::Waypoints => ModelKind::Quadrotor,
            TaskKind::Landing => ModelKind::Lander2d,
        }
    }

    /// The default task of a model.
    pub fn default_for(model: ModelKind) -> TaskKind {
        match model {
            ModelKind::Quadrotor => TaskKind::Hover,
            ModelKind::Lander2d => TaskKind::Landing,
        }
    }

    /// The name carried in the task frame (DEBUG_FLOAT_ARRAY.name, at most 10 characters).
    pub fn frame_name(self) -> &'static str {
        match self {
            TaskKind::Hover => "hover",
            TaskKind::Waypoints => "waypoints",
            TaskKind::Landing => "landing",
        }
    }
}

/// Every parameter set a task is built from. Only the sets the task uses are served over the
/// parameter protocol (see [`crate::param_table`]).
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
}

impl TaskConfig {
    /// The flight tasks' vehicle: quadrotor, rate loop and flight parameters.
    pub fn vehicle(&self) -> VehicleParams {
        VehicleParams {
            quadrotor: self.quadrotor.clone(),
            rate_loop: self.rate_loop.clone(),
            flight: self.flight.clone(),
        }
    }
}

/// A task instance of one of the three kinds.
#[derive(Debug)]
pub enum TaskInstance {
    Hover(Box<Hover>),
    Waypoints(Box<Waypoints>),
    Landing(Box<Landing>),
}

impl TaskInstance {
    /// Builds `kind` from `config`; every parameter set it uses is validated by the core.
    pub fn build(kind: TaskKind, config: &TaskConfig) -> Result<Self, ParamError> {
        Ok(match kind {
            TaskKind::Hover => TaskInstance::Hover(Box::new(Hover::with_vehicle(
                config.vehicle(),
                config.randomize.clone(),
            )?)),
            TaskKind::Waypoints => TaskInstance::Waypoints(Box::new(Waypoints::with_vehicle(
                config.vehicle(),
                config.waypoints.clone(),
                config.randomize.clone(),
            )?)),
            TaskKind::Landing => TaskInstance::Landing(Box::new(Landing::new(
                config.lander.clone(),
                config.landing.clone(),
            )?)),
        })
    }

    fn task(&self) -> &dyn Task {
        match self {
            TaskInstance::Hover(t) => t.as_ref(),
            TaskInstance::Waypoints(t) => t.as_ref(),
            TaskInstance::Landing(t) => t.as_ref(),
        }
    }

    fn task_mut(&mut self) -> &mut dyn Task {
        match self {
            TaskInstance::Hover(t) => t.as_mut(),
            TaskInstance::Waypoints(t) => t.as_mut(),
            TaskInstance::Landing(t) => t.as_mut(),
        }
    }

    pub fn reset(&mut self, seed: u64) {
        self.task_mut().reset(seed);
    }

    pub fn step(&mut self, action: &[f64]) -> Result<StepOutcome, ActionError> {
        self.task_mut().step(action)
    }

    pub fn action_size(&self) -> usize {
        self.task().action_size()
    }

    pub fn action_bounds(&self) -> (Vec<f64>, Vec<f64>) {
        self.task().action_bounds()
    }

    pub fn observation_size(&self) -> usize {
        self.task().observation_size()
    }

    /// The observation's groups: (name, number of values), as the core declares them.
    pub fn observation_layout(&self) -> Vec<(&'static str, usize)> {
        self.task().observation_layout()
    }

    /// Inclusive per-value observation bounds, as the core declares them.
    pub fn observation_bounds(&self) -> (Vec<f32>, Vec<f32>) {
        self.task().observation_bounds()
    }

    pub fn write_observation(&self, out: &mut [f32]) {
        self.task().write_observation(out);
    }

    /// The current observation as a new vector.
    pub fn observation(&self) -> Vec<f32> {
        self.task().observation()
    }

    pub fn info(&self) -> Info {
        self.task().info()
    }

    /// Control period, s.
    pub fn dt(&self) -> f64 {
        self.task().dt()
    }

    /// The command that switches the motors off (quadrotor 0, lander −1 on every channel).
    pub fn motors_off(&self) -> Vec<f64> {
        self.action_bounds().0
    }

    /// Remaining battery as a fraction of the full charge, if the model has a battery.
    pub fn battery_fraction(&self) -> Option<f64> {
        match self {
            TaskInstance::Landing(t) => {
                let full = t.lander().params().initial_battery;
                Some(if full > 0.0 {
                    t.lander().battery() / full
                } else {
                    0.0
                })
            }
            _ => None,
        }
    }

    /// The vehicle's state in the core's frames (world ENU, body FLU).
    pub fn kinematics(&self) -> Kinematics {
        match self {
            TaskInstance::Hover(t) => Kinematics::of_quadrotor(t.quadrotor()),
            TaskInstance::Waypoints(t) => Kinematics::of_quadrotor(t.quadrotor()),
            TaskInstance::Landing(t) => Kinematics::of_lander(t.lander()),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_task_builds_from_the_defaults_and_steps() {
        for kind in [TaskKind::Hover, TaskKind::Waypoints, TaskKind::Landing] {
            let mut task = TaskInstance::build(kind, &TaskConfig::default()).unwrap();
            task.reset(3);
            let n = task.action_size();
            assert_eq!(n, if kind == TaskKind::Landing { 2 } else { 4 });
            let off = task.motors_off();
            assert_eq!(off.len(), n);
            task.step(&off).unwrap();
            assert!(task.kinematics().position.iter().all(|v| v.is_finite()));
        }
    }

    #[test]
    fn a_bad_parameter_is_refused_naming_it() {
        let mut config = TaskConfig::default();
        config.quadrotor.mass = -1.0;
        let err = TaskInstance::build(TaskKind::Hover, &config).unwrap_err();
        assert!(err.to_string().contains("`mass`"), "{err}");
    }
}
