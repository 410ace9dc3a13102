//! The lander behind the vehicle seam ([`crate::vehicle`]): two engines in, its plane drawn
//! into the seam's 3D frames ([`Lander2d::kinematics`]), advanced on its own physics grid.

use super::model::Lander2d;
use crate::error::{CommandError, check_finite};
use crate::snapshot::SnapshotError;
use crate::vehicle::{Kinematics, Vehicle};

/// The lander's engines: left, right.
const ENGINES: usize = 2;

impl Vehicle for Lander2d {
    fn actuator_count(&self) -> usize {
        ENGINES
    }

    /// Each command in [-1, 1] (clamped), mapped onto [0, max_thrust] as
    /// [`Lander2d::set_command`] does.
    fn set_actuators(&mut self, commands: &[f64]) -> Result<(), CommandError> {
        let command: [f64; ENGINES] =
            commands.try_into().map_err(|_| CommandError::WrongLength {
                what: "motor command",
                expected: ENGINES,
                got: commands.len(),
            })?;
        Ok(self.set_command(command)?)
    }

    fn actuators(&self) -> Vec<f64> {
        self.command().to_vec()
    }

    /// Each engine's thrust over its full thrust.
    fn actuator_states(&self) -> Vec<f64> {
        let full = self.params().max_thrust;
        self.thrust().iter().map(|t| t / full).collect()
    }

    /// To `dt` seconds from now on the physics grid ([`Lander2d::advance_to`]).
    fn advance(&mut self, dt: f64) {
        self.advance_to(self.time() + dt);
    }

    fn kinematics(&self) -> Kinematics {
        Lander2d::kinematics(self)
    }

    /// In contact with the platform or the ground after the last physics step.
    fn is_grounded(&self) -> bool {
        let c = self.contact();
        c.on_platform || c.on_ground
    }

    fn is_finite(&self) -> bool {
        let d = self.drone();
        check_finite(
            "state",
            &[d.x, d.y, d.angle, d.vx, d.vy, d.angular_velocity],
        )
        .is_ok()
    }

    fn save(&self) -> Result<Vec<u8>, SnapshotError> {
        Lander2d::save(self)
    }
}
