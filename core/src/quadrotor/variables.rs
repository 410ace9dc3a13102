//! The quadrotor's variable table: inputs, outputs, physical parameters and start values,
//! with value references, for the FMU and the SITL.

use super::model::Quadrotor;
use super::params::{QuadrotorInitial, QuadrotorParams};
use crate::error::{InputError, ParamError, check_finite};
use crate::params::Parameters;
use crate::variables::{InputRow, OutputRow, VariableTable};

/// Outputs; their order fixes the value references.
const OUTPUTS: &[OutputRow<Quadrotor>] = &[
    OutputRow::real("x", "m", "Position east (world ENU)", |q| q.body.position.x),
    OutputRow::real("y", "m", "Position north (world ENU)", |q| {
        q.body.position.y
    }),
    OutputRow::real("z", "m", "Height above ground (world ENU)", |q| {
        q.body.position.z
    }),
    OutputRow::real("vx", "m/s", "Velocity east", |q| q.body.velocity.x),
    OutputRow::real("vy", "m/s", "Velocity north", |q| q.body.velocity.y),
    OutputRow::real("vz", "m/s", "Velocity up", |q| q.body.velocity.z),
    OutputRow::real(
        "ax",
        "m/s2",
        "Acceleration east (total force / mass)",
        |q| q.accelerations().0.x,
    ),
    OutputRow::real(
        "ay",
        "m/s2",
        "Acceleration north (total force / mass)",
        |q| q.accelerations().0.y,
    ),
    OutputRow::real(
        "az",
        "m/s2",
        "Acceleration up (total force / mass; 0 in a hover)",
        |q| q.accelerations().0.z,
    ),
    OutputRow::real(
        "qw",
        "1",
        "Attitude quaternion w (body FLU to world ENU)",
        |q| q.body.attitude.w,
    ),
    OutputRow::real("qx", "1", "Attitude quaternion x", |q| q.body.attitude.i),
    OutputRow::real("qy", "1", "Attitude quaternion y", |q| q.body.attitude.j),
    OutputRow::real("qz", "1", "Attitude quaternion z", |q| q.body.attitude.k),
    OutputRow::real(
        "roll",
        "rad",
        "Roll (ZYX Euler, about body x forward)",
        |q| q.body.euler_angles().0,
    ),
    OutputRow::real(
        "pitch",
        "rad",
        "Pitch (ZYX Euler, about body y left; nose down positive)",
        |q| q.body.euler_angles().1,
    ),
    OutputRow::real(
        "yaw",
        "rad",
        "Yaw (ZYX Euler, from east toward north)",
        |q| q.body.euler_angles().2,
    ),
    OutputRow::real("wx", "rad/s", "Body rate about x (forward)", |q| {
        q.body.body_rates.x
    }),
    OutputRow::real("wy", "rad/s", "Body rate about y (left)", |q| {
        q.body.body_rates.y
    }),
    OutputRow::real("wz", "rad/s", "Body rate about z (up)", |q| {
        q.body.body_rates.z
    }),
    OutputRow::real(
        "motor_state_0",
        "1",
        "Lagged state of motor 0 (front-right, CCW)",
        |q| q.body.motors[0],
    ),
    OutputRow::real(
        "motor_state_1",
        "1",
        "Lagged state of motor 1 (rear-left, CCW)",
        |q| q.body.motors[1],
    ),
    OutputRow::real(
        "motor_state_2",
        "1",
        "Lagged state of motor 2 (front-left, CW)",
        |q| q.body.motors[2],
    ),
    OutputRow::real(
        "motor_state_3",
        "1",
        "Lagged state of motor 3 (rear-right, CW)",
        |q| q.body.motors[3],
    ),
    OutputRow::real(
        "wind_x",
        "m/s",
        "Wind at the vehicle, east (episode wind + turbulence + input)",
        |q| q.wind_velocity().x,
    ),
    OutputRow::real("wind_y", "m/s", "Wind at the vehicle, north", |q| {
        q.wind_velocity().y
    }),
    OutputRow::real("wind_z", "m/s", "Wind at the vehicle, up", |q| {
        q.wind_velocity().z
    }),
];

/// Inputs; their order fixes the value references.
const INPUTS: &[InputRow<Quadrotor>] = &[
    motor::<0>("motor_command_0", "Command of motor 0 (front-right, CCW)"),
    motor::<1>("motor_command_1", "Command of motor 1 (rear-left, CCW)"),
    motor::<2>("motor_command_2", "Command of motor 2 (front-left, CW)"),
    motor::<3>("motor_command_3", "Command of motor 3 (rear-right, CW)"),
    wind::<0>(
        "wind_input_x",
        "External wind east, added to the model's wind",
    ),
    wind::<1>(
        "wind_input_y",
        "External wind north, added to the model's wind",
    ),
    wind::<2>(
        "wind_input_z",
        "External wind up, added to the model's wind",
    ),
];

/// Motor command `I` in [0, 1], starting at 0.
const fn motor<const I: usize>(name: &'static str, text: &'static str) -> InputRow<Quadrotor> {
    InputRow::new(
        name,
        "1",
        text,
        [0.0, 1.0, 0.0],
        |q| q.command()[I],
        set_motor::<I>,
    )
}

/// External wind component `I` in m/s.
const fn wind<const I: usize>(name: &'static str, text: &'static str) -> InputRow<Quadrotor> {
    let range = [-100.0, 100.0, 0.0];
    InputRow::new(
        name,
        "m/s",
        text,
        range,
        |q| q.external_wind[I],
        set_wind::<I>,
    )
}

fn set_motor<const I: usize>(quad: &mut Quadrotor, value: f64) -> Result<(), InputError> {
    check_finite("motor command", &[value]).map_err(|e| InputError { index: I, ..e })?;
    quad.set_motor_command(I, value);
    Ok(())
}

fn set_wind<const I: usize>(quad: &mut Quadrotor, value: f64) -> Result<(), InputError> {
    check_finite("wind input", &[value])?;
    quad.external_wind[I] = value;
    Ok(())
}

impl VariableTable for Quadrotor {
    type Params = QuadrotorParams;
    type Initial = QuadrotorInitial;
    const INPUTS: &'static [InputRow<Self>] = INPUTS;
    const OUTPUTS: &'static [OutputRow<Self>] = OUTPUTS;

    fn params(&self) -> &QuadrotorParams {
        &self.params
    }

    fn set_parameter(&mut self, name: &'static str, value: f64) -> Result<(), ParamError> {
        self.params.set(name, value)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::quadrotor::BodyState;
    use crate::rng::SimRng;
    use crate::variables::{get, set};
    use nalgebra::Vector3;

    fn quad() -> Quadrotor {
        let body = BodyState::at_rest(Vector3::new(1.0, 2.0, 3.0), 0.0, 0.0, 0.5, 0.4);
        Quadrotor::new(QuadrotorParams::default(), body, SimRng::new(1)).unwrap()
    }

    #[test]
    fn names_and_value_references_are_unique_and_every_one_reads() {
        // Inputs read what quad() commands, not their start values.
        crate::variables::assert_every_variable_reads(&quad(), &QuadrotorInitial::default(), false);
    }

    #[test]
    fn outputs_read_the_state_and_cannot_be_set() {
        let mut q = quad();
        let mut init = QuadrotorInitial::default();
        let vr = crate::variables::value_reference::<Quadrotor>;
        assert_eq!(get(&q, &init, vr("z")).unwrap(), 3.0);
        assert!((get(&q, &init, vr("yaw")).unwrap() - 0.5).abs() < 1e-12);
        assert_eq!(
            set(&mut q, &mut init, vr("z"), 1.0),
            Err(ParamError::NotSettable("z"))
        );
    }

    #[test]
    fn inputs_and_parameters_are_range_checked_and_refusals_change_nothing() {
        let mut q = quad();
        let mut init = QuadrotorInitial::default();
        let vr = crate::variables::value_reference::<Quadrotor>;
        set(&mut q, &mut init, vr("motor_command_2"), 0.7).unwrap();
        assert_eq!(q.command()[2], 0.7);
        let err = set(&mut q, &mut init, vr("motor_command_2"), f64::NAN).unwrap_err();
        assert!(err.to_string().contains("motor_command_2"), "{err}");
        assert_eq!(q.command()[2], 0.7);
        set(&mut q, &mut init, vr("wind_input_y"), -3.0).unwrap();
        assert_eq!(q.wind_velocity().y, q.wind.velocity().y - 3.0);
        let err = set(&mut q, &mut init, vr("mass"), -1.0).unwrap_err();
        assert!(err.to_string().contains("`mass` = -1 kg"), "{err}");
        assert_eq!(q.params.mass, 1.0);
        set(&mut q, &mut init, vr("mass"), 2.0).unwrap();
        assert_eq!(q.params.mass, 2.0);
        set(&mut q, &mut init, vr("initial_z"), 4.0).unwrap();
        assert_eq!(init.initial_z, 4.0);
    }
}
