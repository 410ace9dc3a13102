//! The quadrotor's variable table: inputs, outputs, physical parameters and start values,
//! with value references, for the FMU and the SITL.

use super::model::Quadrotor;
use super::params::{QuadrotorInitial, QuadrotorParams};
use crate::error::ParamError;
use crate::params::{Parameters, ValueKind};
use crate::variables::{
    Causality, Variability, Variable, parameter_at, parameter_variables, vr_block,
};

type Getter = fn(&Quadrotor) -> f64;

/// Outputs: (name, unit, description, getter). Order fixes the value references.
static OUTPUTS: &[(&str, &str, &str, Getter)] = &[
    ("x", "m", "Position east (world ENU)", |q| q.body.position.x),
    ("y", "m", "Position north (world ENU)", |q| {
        q.body.position.y
    }),
    ("z", "m", "Height above ground (world ENU)", |q| {
        q.body.position.z
    }),
    ("vx", "m/s", "Velocity east", |q| q.body.velocity.x),
    ("vy", "m/s", "Velocity north", |q| q.body.velocity.y),
    ("vz", "m/s", "Velocity up", |q| q.body.velocity.z),
    (
        "ax",
        "m/s2",
        "Acceleration east (total force / mass)",
        |q| q.accelerations().0.x,
    ),
    (
        "ay",
        "m/s2",
        "Acceleration north (total force / mass)",
        |q| q.accelerations().0.y,
    ),
    (
        "az",
        "m/s2",
        "Acceleration up (total force / mass; 0 in a hover)",
        |q| q.accelerations().0.z,
    ),
    (
        "qw",
        "1",
        "Attitude quaternion w (body FLU to world ENU)",
        |q| q.body.attitude.w,
    ),
    ("qx", "1", "Attitude quaternion x", |q| q.body.attitude.i),
    ("qy", "1", "Attitude quaternion y", |q| q.body.attitude.j),
    ("qz", "1", "Attitude quaternion z", |q| q.body.attitude.k),
    (
        "roll",
        "rad",
        "Roll (ZYX Euler, about body x forward)",
        |q| q.body.euler_angles().0,
    ),
    (
        "pitch",
        "rad",
        "Pitch (ZYX Euler, about body y left; nose down positive)",
        |q| q.body.euler_angles().1,
    ),
    (
        "yaw",
        "rad",
        "Yaw (ZYX Euler, from east toward north)",
        |q| q.body.euler_angles().2,
    ),
    ("wx", "rad/s", "Body rate about x (forward)", |q| {
        q.body.body_rates.x
    }),
    ("wy", "rad/s", "Body rate about y (left)", |q| {
        q.body.body_rates.y
    }),
    ("wz", "rad/s", "Body rate about z (up)", |q| {
        q.body.body_rates.z
    }),
    (
        "motor_state_0",
        "1",
        "Lagged state of motor 0 (front-right, CCW)",
        |q| q.body.motors[0],
    ),
    (
        "motor_state_1",
        "1",
        "Lagged state of motor 1 (rear-left, CCW)",
        |q| q.body.motors[1],
    ),
    (
        "motor_state_2",
        "1",
        "Lagged state of motor 2 (front-left, CW)",
        |q| q.body.motors[2],
    ),
    (
        "motor_state_3",
        "1",
        "Lagged state of motor 3 (rear-right, CW)",
        |q| q.body.motors[3],
    ),
    (
        "wind_x",
        "m/s",
        "Wind at the vehicle, east (episode wind + turbulence + input)",
        |q| q.wind_velocity().x,
    ),
    ("wind_y", "m/s", "Wind at the vehicle, north", |q| {
        q.wind_velocity().y
    }),
    ("wind_z", "m/s", "Wind at the vehicle, up", |q| {
        q.wind_velocity().z
    }),
];

/// Inputs: (name, unit, description, min, max).
static INPUTS: &[(&str, &str, &str, f64, f64)] = &[
    (
        "motor_command_0",
        "1",
        "Command of motor 0 (front-right, CCW)",
        0.0,
        1.0,
    ),
    (
        "motor_command_1",
        "1",
        "Command of motor 1 (rear-left, CCW)",
        0.0,
        1.0,
    ),
    (
        "motor_command_2",
        "1",
        "Command of motor 2 (front-left, CW)",
        0.0,
        1.0,
    ),
    (
        "motor_command_3",
        "1",
        "Command of motor 3 (rear-right, CW)",
        0.0,
        1.0,
    ),
    (
        "wind_input_x",
        "m/s",
        "External wind east, added to the model's wind",
        -100.0,
        100.0,
    ),
    (
        "wind_input_y",
        "m/s",
        "External wind north, added to the model's wind",
        -100.0,
        100.0,
    ),
    (
        "wind_input_z",
        "m/s",
        "External wind up, added to the model's wind",
        -100.0,
        100.0,
    ),
];

const PARAMETERS: u32 = vr_block::PARAMETER;
const INITIAL: u32 = vr_block::INITIAL;

/// Every variable of the quadrotor, in value-reference order.
pub fn variables() -> Vec<Variable> {
    let inputs =
        INPUTS
            .iter()
            .zip(vr_block::INPUT..)
            .map(|(&(name, unit, description, min, max), vr)| Variable {
                name,
                value_reference: vr,
                kind: ValueKind::Real,
                causality: Causality::Input,
                variability: Variability::Continuous,
                unit,
                description,
                start: Some(0.0),
                min: Some(min),
                max: Some(max),
            });
    let outputs =
        OUTPUTS
            .iter()
            .zip(vr_block::OUTPUT..)
            .map(|(&(name, unit, description, _), vr)| Variable {
                name,
                value_reference: vr,
                kind: ValueKind::Real,
                causality: Causality::Output,
                variability: Variability::Continuous,
                unit,
                description,
                start: None,
                min: None,
                max: None,
            });
    inputs
        .chain(outputs)
        .chain(parameter_variables::<QuadrotorParams>(
            PARAMETERS,
            Variability::Fixed,
        ))
        .chain(parameter_variables::<QuadrotorInitial>(
            INITIAL,
            Variability::Fixed,
        ))
        .collect()
}

/// Reads variable `vr`.
pub fn get(quad: &Quadrotor, initial: &QuadrotorInitial, vr: u32) -> Result<f64, ParamError> {
    let command = quad.command();
    let external = quad.external_wind;
    match vr {
        0..=3 => Ok(command[vr as usize]),
        4..=6 => Ok(external[(vr - 4) as usize]),
        _ if vr >= INITIAL => Ok((parameter_at::<QuadrotorInitial>(vr, INITIAL)?.get)(
            initial,
        )),
        _ if vr >= PARAMETERS => Ok((parameter_at::<QuadrotorParams>(vr, PARAMETERS)?.get)(
            &quad.params,
        )),
        _ => {
            let index = vr
                .checked_sub(vr_block::OUTPUT)
                .ok_or(ParamError::UnknownValueReference(vr))?;
            let (_, _, _, getter) = OUTPUTS
                .get(index as usize)
                .ok_or(ParamError::UnknownValueReference(vr))?;
            Ok(getter(quad))
        }
    }
}

/// Writes variable `vr`; the value is checked against the variable's range and nothing
/// changes when it is refused.
pub fn set(
    quad: &mut Quadrotor,
    initial: &mut QuadrotorInitial,
    vr: u32,
    value: f64,
) -> Result<(), ParamError> {
    match vr {
        0..=6 => {
            let (name, unit, _, min, max) = INPUTS[vr as usize];
            if !(value >= min && value <= max) {
                return Err(ParamError::OutOfRange {
                    name,
                    value,
                    min,
                    max,
                    unit,
                });
            }
            if vr < 4 {
                let mut command = quad.command();
                command[vr as usize] = value;
                // Finite and in range: cannot fail.
                quad.set_command(command)
                    .map_err(|_| ParamError::NotSettable(name))?;
            } else {
                quad.external_wind[(vr - 4) as usize] = value;
            }
            Ok(())
        }
        _ if vr >= INITIAL => {
            let name = parameter_at::<QuadrotorInitial>(vr, INITIAL)?.name;
            initial.set(name, value)
        }
        _ if vr >= PARAMETERS => {
            let name = parameter_at::<QuadrotorParams>(vr, PARAMETERS)?.name;
            quad.params.set(name, value)
        }
        _ => {
            let index = vr
                .checked_sub(vr_block::OUTPUT)
                .ok_or(ParamError::UnknownValueReference(vr))?;
            let (name, ..) = OUTPUTS
                .get(index as usize)
                .ok_or(ParamError::UnknownValueReference(vr))?;
            Err(ParamError::NotSettable(name))
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::quadrotor::BodyState;
    use crate::rng::SimRng;
    use nalgebra::Vector3;

    fn quad() -> Quadrotor {
        let body = BodyState::at_rest(Vector3::new(1.0, 2.0, 3.0), 0.0, 0.0, 0.5, 0.4);
        Quadrotor::new(QuadrotorParams::default(), body, SimRng::new(1)).unwrap()
    }

    #[test]
    fn names_and_value_references_are_unique_and_every_one_reads() {
        let vars = variables();
        let q = quad();
        let init = QuadrotorInitial::default();
        crate::variables::assert_names_and_value_references_are_unique(&vars);
        for v in &vars {
            let value = get(&q, &init, v.value_reference).unwrap();
            assert!(value.is_finite(), "{} = {value}", v.name);
            if let Some(start) = v.start {
                if v.causality != Causality::Input {
                    assert_eq!(value, start, "{} does not read its start value", v.name);
                }
            }
        }
        assert_eq!(
            get(&q, &init, 99),
            Err(ParamError::UnknownValueReference(99))
        );
        assert_eq!(
            get(&q, &init, 10_000),
            Err(ParamError::UnknownValueReference(10_000))
        );
    }

    #[test]
    fn outputs_read_the_state_and_cannot_be_set() {
        let mut q = quad();
        let mut init = QuadrotorInitial::default();
        let vr = |name: &str| {
            variables()
                .into_iter()
                .find(|v| v.name == name)
                .unwrap()
                .value_reference
        };
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
        let vr = |name: &str| {
            variables()
                .into_iter()
                .find(|v| v.name == name)
                .unwrap()
                .value_reference
        };
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
