//! Per-rotor loss of effectiveness held by the vehicle itself: what the multirotor FMUs take
//! as their `motor_effectiveness_i` inputs, so a system model can weaken a motor. The motors
//! get command·√η (clamped into [0, 1]) — the fault library's `motor_effectiveness`, through
//! the same function ([`weakened`]), so the rotor gives η of its healthy thrust and torque at
//! the same command once settled, and an FMU with η = 0.5 flies the core's faulted task's
//! bits. Every rotor at η = 1 is no fault at all: the vehicle steps as it always did.

use super::frame::MAX_ROTORS;
use super::model::Quadrotor;
use super::state::Motors;
use crate::faults::actuator::weakened;

impl Quadrotor {
    /// Rotor `index`'s effectiveness η (1 for a healthy rotor, or past the frame's rotors).
    pub fn motor_effectiveness(&self, index: usize) -> f64 {
        (self.effectiveness.as_ref())
            .and_then(|e| e.get(index).copied())
            .unwrap_or(1.0)
    }

    /// Sets rotor `index`'s effectiveness to `value`, clamped into [0, 1] (an index past the
    /// frame's rotors changes nothing). Every rotor back at 1 leaves no fault behind.
    pub fn set_motor_effectiveness(&mut self, index: usize, value: f64) {
        let n = self.frame().rotor_count();
        if index >= n || index >= MAX_ROTORS {
            return;
        }
        let mut eta = self
            .effectiveness
            .unwrap_or_else(|| Motors::uniform(n, 1.0).unwrap_or(Motors::from([1.0; 4])));
        eta[index] = value.clamp(0.0, 1.0);
        self.effectiveness = (!eta.iter().all(|&e| e == 1.0)).then_some(eta);
    }

    /// What the motors get: the command, each value weakened by its rotor's effectiveness.
    pub fn motor_input(&self) -> Motors {
        match &self.effectiveness {
            None => self.command(),
            Some(eta) => Self::weaken(&self.command(), eta),
        }
    }

    /// `command` with each value weakened by `eta` (same length).
    pub(super) fn weaken(command: &Motors, eta: &Motors) -> Motors {
        let mut out = *command;
        for (o, &e) in out.iter_mut().zip(eta.iter()) {
            *o = weakened(*o, e);
        }
        out
    }
}
