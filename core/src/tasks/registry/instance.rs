//! A built task of any kind, driven through the core's [`Task`] trait.

use super::{TaskConfig, TaskKind};
use crate::ParamError;
use crate::tasks::hover::Hover;
use crate::tasks::landing::Landing;
use crate::tasks::waypoints::Waypoints;
use crate::tasks::{ActionError, Info, InfoVisitor, StepOutcome, Task};
use crate::vehicle::Kinematics;

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

    /// The state of the task's vehicle (the vehicle seam's kinematics).
    pub fn kinematics(&self) -> Kinematics {
        match self {
            TaskInstance::Hover(t) => t.air_vehicle().kinematics(),
            TaskInstance::Waypoints(t) => t.air_vehicle().kinematics(),
            TaskInstance::Landing(t) => t.lander().kinematics(),
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

    /// Calls `visit` with each info entry, in order (see [`Task::visit_info`]).
    pub fn visit_info(&self, visit: &mut InfoVisitor<'_>) {
        self.task().visit_info(visit)
    }

    /// Control period, s.
    pub fn dt(&self) -> f64 {
        self.task().dt()
    }

    /// The command that switches the motors off (quadrotor 0, lander −1 on every channel).
    pub fn motors_off(&self) -> Vec<f64> {
        self.action_bounds().0
    }

    /// Injects PX4's failure code (MAV_CMD_INJECT_FAILURE: `unit` FAILURE_UNIT, `failure`
    /// FAILURE_TYPE, `instance` 1 = first motor, 0 = all) into the flight tasks' vehicle now;
    /// returns what was done, for the STATUSTEXT.
    /// An error names the field: a code the catalogue lacks, a motor the frame lacks, or a
    /// task without faults (the lander).
    pub fn inject_px4(
        &mut self,
        unit: u8,
        failure: u8,
        instance: u8,
    ) -> Result<String, ParamError> {
        match self {
            TaskInstance::Hover(t) => t.vehicle_mut().inject_px4(unit, failure, instance),
            TaskInstance::Waypoints(t) => t.vehicle_mut().inject_px4(unit, failure, instance),
            TaskInstance::Landing(_) => Err(ParamError::Parse(
                "failure_unit: the lander has no faults; the flight tasks (hover, waypoints) do"
                    .to_string(),
            )),
        }
    }

    /// The flight tasks' fault state, if the vehicle has faults (the SITL's lockstep link
    /// reads its link faults from it).
    pub fn fault_state(&self) -> Option<&crate::faults::FaultState> {
        let faults = match self {
            TaskInstance::Hover(t) => t.vehicle().faults(),
            TaskInstance::Waypoints(t) => t.vehicle().faults(),
            TaskInstance::Landing(_) => None,
        };
        faults.map(|f| f.state())
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
            assert!(task.observation().iter().all(|v| v.is_finite()));
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
