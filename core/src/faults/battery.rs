//! A battery pack: open-circuit voltage from the state of charge (linear per cell between
//! empty and full), a sag I·R under load, the charge drawn by the current. The motors' speed
//! goes with the voltage, so a sagging pack lowers the available thrust: the command reaching
//! the motors × min(1, V / V_nominal).

use serde::{Deserialize, Serialize};

/// Cell voltage of a full LiPo cell at rest, V.
pub const FULL_CELL: f64 = 4.2;
/// Cell voltage of an empty LiPo cell at rest, V.
pub const EMPTY_CELL: f64 = 3.3;
/// Nominal cell voltage (the ESCs' thrust is calibrated at it), V.
pub const NOMINAL_CELL: f64 = 3.7;

/// The pack's parameters (fault kind `battery`).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct BatteryParams {
    /// Charge of the full pack, Ah. Default 5.
    pub capacity: f64,
    /// Cells in series. Default 4.
    pub cells: f64,
    /// Internal resistance, Ω. Default 0.02.
    pub internal_resistance: f64,
    /// Current with every motor at state 1, A (∝ the motor state cubed). Default 120.
    pub max_current: f64,
    /// Current of the electronics, A. Default 0.5.
    pub idle_current: f64,
}

impl Default for BatteryParams {
    fn default() -> Self {
        BatteryParams {
            capacity: 5.0,
            cells: 4.0,
            internal_resistance: 0.02,
            max_current: 120.0,
            idle_current: 0.5,
        }
    }
}

/// A pack and its state of charge.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Battery {
    pub params: BatteryParams,
    /// State of charge in [0, 1].
    pub charge: f64,
    /// Current drawn in the last step, A.
    pub current: f64,
}

impl Battery {
    pub fn new(params: BatteryParams, charge: f64) -> Self {
        Battery {
            params,
            charge: charge.clamp(0.0, 1.0),
            current: 0.0,
        }
    }

    /// Open-circuit voltage at the present charge, V.
    pub fn open_circuit_voltage(&self) -> f64 {
        self.params.cells * (EMPTY_CELL + (FULL_CELL - EMPTY_CELL) * self.charge)
    }

    /// Current drawn by motors at `motors` (states in [0, 1]), A: idle + max·mean(m³).
    pub fn load_current(&self, motors: &[f64]) -> f64 {
        let n = motors.len().max(1) as f64;
        let cubes: f64 = motors.iter().map(|m| m * m * m).sum();
        self.params.idle_current + self.params.max_current * cubes / n
    }

    /// Terminal voltage under `current`, V (never below 0).
    pub fn voltage(&self, current: f64) -> f64 {
        (self.open_circuit_voltage() - current * self.params.internal_resistance).max(0.0)
    }

    /// Factor on the motor commands: the speed the voltage allows, min(1, V / V_nominal).
    pub fn command_scale(&self, current: f64) -> f64 {
        (self.voltage(current) / (self.params.cells * NOMINAL_CELL)).min(1.0)
    }

    /// Draws the motors' current for `dt` seconds and returns the command factor at the
    /// start of the interval.
    pub fn draw(&mut self, motors: &[f64], dt: f64) -> f64 {
        let current = self.load_current(motors);
        let scale = self.command_scale(current);
        self.current = current;
        self.charge = (self.charge - current * dt / (3600.0 * self.params.capacity)).max(0.0);
        scale
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn voltage_sags_under_load_and_the_charge_drains_by_coulomb_counting() {
        let mut b = Battery::new(BatteryParams::default(), 1.0);
        assert!((b.open_circuit_voltage() - 16.8).abs() < 1e-12);
        // Hover-ish load: every motor at 0.5 → 0.5 + 120·0.125 = 15.5 A, sag 0.31 V.
        let i = b.load_current(&[0.5; 4]);
        assert!((i - 15.5).abs() < 1e-12);
        assert!((b.voltage(i) - (16.8 - 0.31)).abs() < 1e-12);
        assert_eq!(b.command_scale(i), 1.0);
        // One hour at 5 A empties a 5 Ah pack.
        b.params.max_current = 0.0;
        b.params.idle_current = 5.0;
        for _ in 0..3600 {
            b.draw(&[0.0; 4], 1.0);
        }
        assert!(b.charge.abs() < 1e-9, "{}", b.charge);
        // Empty: 13.2 V at rest, 13.2 / 14.8 of the nominal speed.
        assert!((b.command_scale(0.0) - 13.2 / 14.8).abs() < 1e-12);
    }
}
