//! Parameters of a world: its wind field, its physics grid, contact between vehicles and
//! downwash. Each vehicle keeps its own [`crate::quadrotor::QuadrotorParams`].

use crate::error::ParamError;
use crate::number::Compact;
use crate::param;
use crate::params::{ParamSpec, Parameters};
use serde::{Deserialize, Serialize};

/// What the vehicles of one world share. Units are SI; every field's range is in
/// [`WorldParams::specs`] and enforced by [`Parameters::validate`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct WorldParams {
    /// Physics grid of the world, s: interactions (contact, downwash) are evaluated at every
    /// grid point and held until the next. Default 0.005 (the vehicles' own grid).
    pub grid: f64,
    /// The wind (mean + turbulence field) blows. Default true.
    pub wind_enabled: bool,
    /// Lower end of the mean wind speed drawn when the world starts, m/s. Default 0.
    pub wind_speed_min: f64,
    /// Upper end of the mean wind speed, m/s. Default 5.
    pub wind_speed_max: f64,
    /// Mean reversion rate of every turbulence mode (Ornstein–Uhlenbeck), 1/s. Default 0.5.
    pub turbulence_theta: f64,
    /// Diffusion of the turbulence at any one point (horizontal), m/s/√s. Default 1: a point
    /// sees the same process as a lone vehicle's turbulence.
    pub turbulence_sigma: f64,
    /// Vertical turbulence sigma / horizontal sigma. Default 0.2.
    pub turbulence_vertical_ratio: f64,
    /// Time between turbulence samples, s; a whole number of grid steps. Default 0.01.
    pub turbulence_dt: f64,
    /// Correlation length of the turbulence field, m: two points d apart see gusts
    /// correlated by exp(−d²/2ℓ²). Default 10.
    pub turbulence_correlation_length: f64,
    /// Number of random Fourier modes of the turbulence field. Default 16 (each world's
    /// correlation is the mean of 16 cosines: unbiased, rough to about ±0.25).
    pub turbulence_modes: u32,
    /// Vehicles collide (sphere hulls). Default true.
    pub collisions_enabled: bool,
    /// Normal stiffness of a contact between two hulls, N/m. Default 2000 (ω·grid ≈ 0.3 for
    /// two 1 kg vehicles).
    pub contact_stiffness: f64,
    /// Normal damping of a contact between two hulls, N·s/m. Default 20.
    pub contact_damping: f64,
    /// Propeller radius as a fraction of the arm length (hull and wake size). Default 0.5.
    pub propeller_radius_ratio: f64,
    /// A vehicle below another's rotors is pushed down by its wake. Default true.
    pub downwash_enabled: bool,
    /// Wake strength coefficient (gym-pybullet-drones' DW_COEFF_1), N. Default 2267.18.
    pub downwash_strength: f64,
    /// Wake widening per metre below the rotors (DW_COEFF_2). Default 0.16.
    pub downwash_spread: f64,
    /// Wake width offset (DW_COEFF_3), m. Default −0.11.
    pub downwash_offset: f64,
    /// Deepest point of the wake below a vehicle, m. Default 3 (there the default quad's wake
    /// pushes with 0.4 % of its weight).
    pub downwash_range: f64,
}

impl Default for WorldParams {
    fn default() -> Self {
        WorldParams {
            grid: 0.005,
            wind_enabled: true,
            wind_speed_min: 0.0,
            wind_speed_max: 5.0,
            turbulence_theta: 0.5,
            turbulence_sigma: 1.0,
            turbulence_vertical_ratio: 0.2,
            turbulence_dt: 0.01,
            turbulence_correlation_length: 10.0,
            turbulence_modes: 16,
            collisions_enabled: true,
            contact_stiffness: 2000.0,
            contact_damping: 20.0,
            propeller_radius_ratio: 0.5,
            downwash_enabled: true,
            downwash_strength: 2267.18,
            downwash_spread: 0.16,
            downwash_offset: -0.11,
            downwash_range: 3.0,
        }
    }
}

static WORLD_SPECS: [ParamSpec<WorldParams>; 19] = [
    param!(real grid, "s", 1e-5, 1.0, "World physics grid: interactions are evaluated at each grid point"),
    param!(boolean wind_enabled, "The world's wind (mean + turbulence field) blows"),
    param!(real wind_speed_min, "m/s", 0.0, 100.0, "Lower end of the mean wind speed"),
    param!(real wind_speed_max, "m/s", 0.0, 100.0, "Upper end of the mean wind speed"),
    param!(real turbulence_theta, "1/s", 0.0, 100.0, "Ornstein-Uhlenbeck mean reversion rate of each mode"),
    param!(real turbulence_sigma, "m/s/s0.5", 0.0, 100.0, "Turbulence diffusion seen at any one point (horizontal)"),
    param!(real turbulence_vertical_ratio, "1", 0.0, 10.0, "Vertical turbulence sigma / horizontal sigma"),
    param!(real turbulence_dt, "s", 1e-4, 10.0, "Time between turbulence samples (a whole number of grid steps)"),
    param!(real turbulence_correlation_length, "m", 0.01, 1e5, "Distance scale over which gusts are correlated: exp(-d^2/2l^2)"),
    param!(integer turbulence_modes, "1", 1, 1024, "Random Fourier modes of the turbulence field"),
    param!(boolean collisions_enabled, "Vehicles collide (sphere hulls)"),
    param!(real contact_stiffness, "N/m", 0.0, 1e7, "Normal stiffness of a contact between two hulls"),
    param!(real contact_damping, "N.s/m", 0.0, 1e6, "Normal damping of a contact between two hulls"),
    param!(real propeller_radius_ratio, "1", 0.0, 10.0, "Propeller radius / arm length (hull and wake size)"),
    param!(boolean downwash_enabled, "A vehicle below another's rotors is pushed down by its wake"),
    param!(real downwash_strength, "N", 0.0, 1e6, "Wake strength (gym-pybullet-drones DW_COEFF_1)"),
    param!(real downwash_spread, "1", 0.0, 10.0, "Wake widening per metre below the rotors (DW_COEFF_2)"),
    param!(real downwash_offset, "m", -10.0, 10.0, "Wake width offset (DW_COEFF_3)"),
    param!(real downwash_range, "m", 0.0, 100.0, "Deepest point of the wake below a vehicle"),
];

impl Parameters for WorldParams {
    fn specs() -> &'static [ParamSpec<Self>] {
        &WORLD_SPECS
    }

    fn check_relations(&self) -> Result<(), ParamError> {
        if self.wind_speed_min > self.wind_speed_max {
            return Err(ParamError::Relation {
                name: "wind_speed_min",
                requirement: format!(
                    "wind_speed_min ({}) must not exceed wind_speed_max ({})",
                    Compact(self.wind_speed_min),
                    Compact(self.wind_speed_max)
                ),
            });
        }
        let ratio = self.turbulence_dt / self.grid;
        if (ratio - ratio.round()).abs() > 1e-9 * ratio || ratio.round() < 1.0 {
            return Err(ParamError::Relation {
                name: "turbulence_dt",
                requirement: format!(
                    "turbulence_dt ({} s) must be a whole number of grid steps ({} s)",
                    Compact(self.turbulence_dt),
                    Compact(self.grid)
                ),
            });
        }
        Ok(())
    }
}

impl WorldParams {
    /// Grid steps between two turbulence samples.
    pub fn steps_per_sample(&self) -> u64 {
        (self.turbulence_dt / self.grid).round() as u64
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn defaults_are_valid_and_errors_name_the_parameter() {
        WorldParams::default().validate().unwrap();
        let bad = WorldParams {
            turbulence_dt: 0.012,
            ..Default::default()
        };
        let e = bad.validate().unwrap_err().to_string();
        assert!(e.contains("turbulence_dt") && e.contains("grid"), "{e}");
        let bad = WorldParams {
            contact_stiffness: -1.0,
            ..Default::default()
        };
        let e = bad.validate().unwrap_err().to_string();
        assert!(
            e.contains("contact_stiffness") && e.contains("[0, 1e7]"),
            "{e}"
        );
        assert_eq!(WorldParams::default().steps_per_sample(), 2);
    }
}
