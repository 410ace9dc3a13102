//! A flight task's faults: the fault state of the episode, its clock, and how a control step
//! goes through the core's actuator and air fault paths ([`crate::faults`]). A task without
//! faults has none of this: its vehicle steps exactly as before.

use crate::error::ParamError;
use crate::faults::catalogue::Target;
use crate::faults::px4::Injection;
use crate::faults::{Conditions, FaultPlan, FaultState, Reach, SensorId};
use crate::quadrotor::Motors;
use crate::tasks::{InfoRef, InfoVisitor};
use crate::vehicle::AirVehicle;
use serde::{Deserialize, Serialize};

/// The faults of a flight vehicle over an episode.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FlightFaults {
    state: FaultState,
    /// Control steps done this episode (the clock: time = steps · dt).
    steps: u64,
    /// The task's current waypoint, if it has waypoints.
    waypoint: Option<u32>,
    /// Per slot, for the info: catalogue index of the kind (−1: none drawn), the motor
    /// number or sensor index, the time it fired (−1: not yet), whether it is active.
    info: [Vec<f64>; 4],
    /// The command the faulted motors stand in for while the vehicle advances.
    commanded: Option<Motors>,
}

impl FlightFaults {
    /// The faults of `plan` for a vehicle of `rotors` rotors flying episodes of `duration`
    /// seconds; a motor the frame lacks or a time trigger past the episode's end is refused
    /// (waypoint triggers are checked by the task that has the waypoints).
    pub fn new(plan: FaultPlan, rotors: usize, duration: f64) -> Result<Self, ParamError> {
        plan.check(&Reach {
            duration: Some(duration),
            waypoints: Some(u32::MAX),
            rotors,
        })?;
        let slots = plan.slots();
        Ok(FlightFaults {
            state: FaultState::new(plan, rotors),
            steps: 0,
            waypoint: None,
            info: std::array::from_fn(|_| vec![0.0; slots]),
            commanded: None,
        })
    }

    pub fn state(&self) -> &FaultState {
        &self.state
    }

    /// Mutable access (run-time injection by a front end).
    pub fn state_mut(&mut self) -> &mut FaultState {
        &mut self.state
    }

    /// The task's current waypoint (for `at_waypoint` triggers).
    pub fn set_waypoint(&mut self, index: u32) {
        self.waypoint = Some(index);
    }

    /// The episode with `seed` starts: its faults drawn; those due at time 0 fire.
    pub fn restart(&mut self, seed: u64, quad: &mut dyn AirVehicle, dt: f64) {
        self.state.reset(seed);
        self.steps = 0;
        self.waypoint = self.waypoint.map(|_| 0);
        self.begin_step(quad, dt);
    }

    /// At the start of a control step: fires and clears faults by their triggers, and sets
    /// the air faults' wind for the step.
    pub fn begin_step(&mut self, quad: &mut dyn AirVehicle, dt: f64) {
        let time = self.steps as f64 * dt;
        let takeoff = (!quad.is_grounded()).then_some(time);
        let height = quad.body().position.z;
        self.state.update(&Conditions {
            time,
            height,
            takeoff,
            waypoint: self.waypoint,
        });
        quad.set_external_wind(self.state.wind(time, height));
        self.refresh_info(dt);
    }

    /// At the end of a control step.
    pub fn end_step(&mut self) {
        self.steps += 1;
    }

    /// Before the vehicle advances by `dt` (its command set): the actuator fault path puts
    /// what the motors get in place of the command, kept to be restored by
    /// [`FlightFaults::after_advance`]. Nothing happens while no actuator fault acts.
    pub fn before_advance(&mut self, quad: &mut dyn AirVehicle, dt: f64) {
        if !self.state.acts_on_motors() {
            self.commanded = None;
            return;
        }
        let commanded = quad.motor_command();
        let mut motors = commanded;
        self.state
            .motor_commands(&commanded, &quad.body().motors, dt, &mut motors);
        // Same length as the frame's command, each value in [0, 1].
        let _ = quad.set_actuators(&motors[..]);
        self.commanded = Some(commanded);
    }

    /// After the vehicle advanced: it holds the commanded values again (what a controller
    /// reads back), not the faulted ones.
    pub fn after_advance(&mut self, quad: &mut dyn AirVehicle) {
        if let Some(commanded) = self.commanded.take() {
            let _ = quad.set_actuators(&commanded[..]);
        }
    }

    /// A run-time injection (MAV_CMD_INJECT_FAILURE) now, `dt` being the control period:
    /// the fault fires in a new slot, or the unit's active faults clear. It lasts until the
    /// episode ends (a reset draws the plan's faults again).
    pub fn inject(&mut self, injection: Injection, dt: f64) {
        let time = self.steps as f64 * dt;
        match injection {
            Injection::Fire(spec) => self.state.inject(spec, time),
            Injection::Clear { motor, sensor } => self.state.clear(motor, sensor, time),
        }
        self.refresh_info(dt);
    }

    fn refresh_info(&mut self, _dt: f64) {
        // Injected faults add slots to the schedule.
        let slots = self.state.schedule().len();
        for values in &mut self.info {
            values.resize(slots, 0.0);
        }
        let [kind, target, time, active] = &mut self.info;
        for (i, spec) in self.state.schedule().iter().enumerate() {
            kind[i] = spec.as_ref().map_or(-1.0, |s| s.kind as usize as f64);
            target[i] = spec
                .as_ref()
                .map_or(0.0, |s| match (s.kind.spec().target, s.sensor) {
                    (Target::Motor, _) => f64::from(s.motor),
                    (Target::Sensor, Some(sensor)) => sensor_index(sensor),
                    _ => 0.0,
                });
            time[i] = self.state.fired()[i].unwrap_or(-1.0);
            active[i] = f64::from(u8::from(self.state.is_active(i)));
        }
    }

    /// Info entries: per slot of the schedule, `fault_kind` (index in the catalogue, −1:
    /// none drawn this episode), `fault_target` (motor number, or sensor index in gyro,
    /// accel, mag, baro, gps), `fault_time` (s, −1: not fired), `fault_active` (1/0).
    pub fn visit_info(&self, visit: &mut InfoVisitor<'_>) {
        let names = ["fault_kind", "fault_target", "fault_time", "fault_active"];
        for (name, values) in names.into_iter().zip(&self.info) {
            visit(name, InfoRef::Vector(values));
        }
    }
}

fn sensor_index(s: SensorId) -> f64 {
    s as usize as f64
}
