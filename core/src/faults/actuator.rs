//! The actuator path: the commands a flight controller sends, turned into what the motors
//! get under the active motor, propeller and battery faults. Order: a stuck or off motor
//! replaces its command; the added lag filters it; the loss of effectiveness scales it; the
//! battery's sag scales every command.
//!
//! A loss of effectiveness η (a weak motor, a damaged or lost propeller) scales the command by
//! √η: thrust kᵢ·m² and reaction torque follow the motor state squared, so the rotor gives η
//! of its healthy thrust and torque at the same command once the motor has settled — the
//! standard loss-of-effectiveness model of fault-tolerant control, with the motor's own lag
//! kept.

use super::catalogue::FaultKind;
use super::sensor::ActiveFault;
use crate::quadrotor::frame::MAX_ROTORS;

/// Whether a fault of `motor` (PX4's numbering: 0 = all) acts on rotor `index` (from 0).
pub fn acts_on(motor: u8, index: usize) -> bool {
    motor == 0 || usize::from(motor) == index + 1
}

/// The actuator path's own state: the added lags' outputs.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct LagState {
    pub output: [f64; MAX_ROTORS],
    /// Whether `output` holds a value yet (the lag starts at the command when it fires).
    pub started: [bool; MAX_ROTORS],
}

impl Default for LagState {
    fn default() -> Self {
        LagState {
            output: [0.0; MAX_ROTORS],
            started: [false; MAX_ROTORS],
        }
    }
}

/// Writes into `out` the commands the motors get for `commanded` under `faults` over the
/// next `dt` seconds (the lags advance by `dt`), before the battery's scale.
pub fn motor_commands(
    faults: &[ActiveFault<'_>],
    commanded: &[f64],
    lag: &mut LagState,
    dt: f64,
    out: &mut [f64],
) {
    for (i, (o, &c)) in out.iter_mut().zip(commanded).enumerate() {
        let mut command = c;
        let mut gain = 1.0;
        let mut lagged = false;
        for f in faults.iter().filter(|f| acts_on(f.spec.motor, i)) {
            let v = &f.spec.values;
            match f.spec.kind {
                FaultKind::MotorOff => command = 0.0,
                FaultKind::MotorStuck => command = v[0],
                FaultKind::MotorEffectiveness => gain *= v[0],
                FaultKind::PropellerLoss => gain = 0.0,
                FaultKind::PropellerDamage => gain *= 1.0 - v[0],
                _ => {}
            }
        }
        for f in faults.iter().filter(|f| acts_on(f.spec.motor, i)) {
            if f.spec.kind == FaultKind::MotorLag && !lagged {
                lagged = true;
                let tau = f.spec.values[0];
                if !lag.started[i] {
                    lag.output[i] = command;
                    lag.started[i] = true;
                }
                let held = lag.output[i];
                lag.output[i] += (command - held) * (1.0 - (-dt / tau).exp());
                command = held;
            }
        }
        if !lagged {
            lag.started[i] = false;
        }
        *o = weakened(command, gain);
    }
}

/// The command a motor of effectiveness `eta` gets for `command`: command·√η in [0, 1]
/// (the vehicle's own per-rotor effectiveness, the FMUs' input, goes through this too).
pub fn weakened(command: f64, eta: f64) -> f64 {
    (command * eta.sqrt()).clamp(0.0, 1.0)
}
