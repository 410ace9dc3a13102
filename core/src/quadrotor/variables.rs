//! The multirotor's variable table: inputs, outputs, physical parameters and start values,
//! with value references, for the FMU and the SITL. It is built from the frame: one motor
//! command (input) and one motor state (output) per rotor, named by index and described by
//! the rotor's place and spin; the value references follow in table order, so the quad X's
//! are those of the table before frames existed.

use super::frame::{Frame, MAX_ROTORS};
use super::model::Quadrotor;
use super::params::{QuadrotorInitial, QuadrotorParams};
use crate::error::{InputError, ParamError, check_finite};
use crate::params::Parameters;
use crate::variables::{InputRow, OutputRow, VariableTable};
use std::borrow::Cow;

/// Outputs before the motor states; their order fixes the value references.
const BODY_OUTPUTS: &[OutputRow<Quadrotor>] = &[
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
];

/// Outputs after the motor states.
const WIND_OUTPUTS: &[OutputRow<Quadrotor>] = &[
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

/// Outputs after the wind: the body's angular acceleration, which the gym's hover observation
/// holds (a policy FMU builds that observation from the plant's outputs).
const ANGULAR_ACCELERATION_OUTPUTS: &[OutputRow<Quadrotor>] = &[
    OutputRow::real(
        "dwx",
        "rad/s2",
        "Angular acceleration about body x (forward)",
        |q| q.accelerations().1.x,
    ),
    OutputRow::real(
        "dwy",
        "rad/s2",
        "Angular acceleration about body y (left)",
        |q| q.accelerations().1.y,
    ),
    OutputRow::real(
        "dwz",
        "rad/s2",
        "Angular acceleration about body z (up)",
        |q| q.accelerations().1.z,
    ),
];

/// Inputs after the motor commands.
const WIND_INPUTS: &[InputRow<Quadrotor>] = &[
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

/// `f::<0>` .. `f::<11>`: one function per rotor index (a row reads through a plain fn
/// pointer, which cannot carry the index).
macro_rules! per_rotor {
    ($f:ident) => {
        [
            $f::<0>, $f::<1>, $f::<2>, $f::<3>, $f::<4>, $f::<5>, $f::<6>, $f::<7>, $f::<8>,
            $f::<9>, $f::<10>, $f::<11>,
        ]
    };
}
const _: () = assert!(MAX_ROTORS == 12, "per_rotor! lists one function per rotor");

/// Names of the motor command inputs, by rotor index.
pub const MOTOR_COMMAND_NAMES: [&str; MAX_ROTORS] = [
    "motor_command_0",
    "motor_command_1",
    "motor_command_2",
    "motor_command_3",
    "motor_command_4",
    "motor_command_5",
    "motor_command_6",
    "motor_command_7",
    "motor_command_8",
    "motor_command_9",
    "motor_command_10",
    "motor_command_11",
];

/// Names of the motor effectiveness inputs, by rotor index.
pub const MOTOR_EFFECTIVENESS_NAMES: [&str; MAX_ROTORS] = [
    "motor_effectiveness_0",
    "motor_effectiveness_1",
    "motor_effectiveness_2",
    "motor_effectiveness_3",
    "motor_effectiveness_4",
    "motor_effectiveness_5",
    "motor_effectiveness_6",
    "motor_effectiveness_7",
    "motor_effectiveness_8",
    "motor_effectiveness_9",
    "motor_effectiveness_10",
    "motor_effectiveness_11",
];

/// Names of the motor state outputs, by rotor index.
pub const MOTOR_STATE_NAMES: [&str; MAX_ROTORS] = [
    "motor_state_0",
    "motor_state_1",
    "motor_state_2",
    "motor_state_3",
    "motor_state_4",
    "motor_state_5",
    "motor_state_6",
    "motor_state_7",
    "motor_state_8",
    "motor_state_9",
    "motor_state_10",
    "motor_state_11",
];

/// What reads a value of the vehicle, and what writes an input.
type Getter = fn(&Quadrotor) -> f64;
type Setter = fn(&mut Quadrotor, f64) -> Result<(), InputError>;

const GET_COMMAND: [Getter; MAX_ROTORS] = per_rotor!(get_command);
const SET_COMMAND: [Setter; MAX_ROTORS] = per_rotor!(set_motor);
const GET_MOTOR_STATE: [Getter; MAX_ROTORS] = per_rotor!(get_motor_state);
const GET_EFFECTIVENESS: [Getter; MAX_ROTORS] = per_rotor!(get_effectiveness);
const SET_EFFECTIVENESS: [Setter; MAX_ROTORS] = per_rotor!(set_effectiveness);

fn get_effectiveness<const I: usize>(quad: &Quadrotor) -> f64 {
    quad.motor_effectiveness(I)
}

fn set_effectiveness<const I: usize>(quad: &mut Quadrotor, value: f64) -> Result<(), InputError> {
    check_finite("motor effectiveness", &[value]).map_err(|e| InputError { index: I, ..e })?;
    quad.set_motor_effectiveness(I, value);
    Ok(())
}

fn get_command<const I: usize>(quad: &Quadrotor) -> f64 {
    quad.command().get(I).copied().unwrap_or_default()
}

fn get_motor_state<const I: usize>(quad: &Quadrotor) -> f64 {
    quad.body.motors.get(I).copied().unwrap_or_default()
}

/// "(front-right, CCW)": where rotor `index` of `frame` sits and which way it turns.
fn rotor_text(frame: &Frame, index: usize) -> String {
    let rotor = &frame.rotors()[index];
    format!("({}, {})", rotor.place(), rotor.spin.label())
}

/// Motor command inputs in [0, 1], starting at 0, one per rotor of `frame`.
fn motor_commands(frame: &Frame) -> impl Iterator<Item = InputRow<Quadrotor>> + '_ {
    (0..frame.rotor_count()).map(|i| InputRow {
        description: Cow::Owned(format!("Command of motor {i} {}", rotor_text(frame, i))),
        ..InputRow::new(
            MOTOR_COMMAND_NAMES[i],
            "1",
            "",
            [0.0, 1.0, 0.0],
            GET_COMMAND[i],
            SET_COMMAND[i],
        )
    })
}

/// Motor effectiveness inputs in [0, 1], starting at 1 (healthy), one per rotor of `frame`:
/// the fault library's loss of effectiveness as an input (after the wind inputs, so the
/// value references before them stay).
fn motor_effectiveness(frame: &Frame) -> impl Iterator<Item = InputRow<Quadrotor>> + '_ {
    (0..frame.rotor_count()).map(|i| InputRow {
        description: Cow::Owned(format!(
            "Effectiveness of motor {i} {}: fraction of its healthy thrust and torque at the same command (the motor gets command x sqrt(effectiveness)); 1 = healthy",
            rotor_text(frame, i)
        )),
        ..InputRow::new(
            MOTOR_EFFECTIVENESS_NAMES[i],
            "1",
            "",
            [0.0, 1.0, 1.0],
            GET_EFFECTIVENESS[i],
            SET_EFFECTIVENESS[i],
        )
    })
}

/// Motor state outputs, one per rotor of `frame`.
fn motor_states(frame: &Frame) -> impl Iterator<Item = OutputRow<Quadrotor>> + '_ {
    (0..frame.rotor_count()).map(|i| OutputRow {
        description: Cow::Owned(format!(
            "Lagged state of motor {i} {}",
            rotor_text(frame, i)
        )),
        ..OutputRow::real(MOTOR_STATE_NAMES[i], "1", "", GET_MOTOR_STATE[i])
    })
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
    type Shape = Frame;

    fn inputs(frame: &Frame) -> Vec<InputRow<Self>> {
        (motor_commands(frame).chain(WIND_INPUTS.to_vec()))
            .chain(motor_effectiveness(frame))
            .collect()
    }

    fn outputs(frame: &Frame) -> Vec<OutputRow<Self>> {
        let wind = WIND_OUTPUTS.iter().cloned();
        (BODY_OUTPUTS.iter().cloned())
            .chain(motor_states(frame))
            .chain(wind)
            .chain(ANGULAR_ACCELERATION_OUTPUTS.iter().cloned())
            .collect()
    }

    fn shape(&self) -> &Frame {
        self.frame()
    }

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
    use crate::variables::{Rows, get, set};
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
        let vr = |name| crate::variables::value_reference(&quad(), name);
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
        let vr = |name| crate::variables::value_reference(&quad(), name);
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

    #[test]
    fn a_hexas_table_has_a_command_and_a_state_per_rotor_in_value_reference_order() {
        let hexa = quad().with_frame(Frame::named("hexa_x").unwrap());
        crate::variables::assert_every_variable_reads(&hexa, &QuadrotorInitial::default(), false);
        let vr = |name| crate::variables::value_reference(&hexa, name);
        assert_eq!((vr("motor_command_5"), vr("wind_input_x")), (5, 6));
        assert_eq!(
            (vr("motor_state_0"), vr("motor_state_5"), vr("wind_x")),
            (119, 124, 125)
        );
        let rows = Rows::of_model(&hexa);
        let text = &rows.inputs[2].description;
        assert_eq!(text, "Command of motor 2 (30° left of forward, CW)");
        let (mut hexa, mut init) = (hexa, QuadrotorInitial::default());
        rows.set(&mut hexa, &mut init, 5, 0.7).unwrap();
        assert_eq!(hexa.command()[5], 0.7);
        assert_eq!(rows.get(&hexa, &init, 5), Ok(0.7));
        // The quad's table has no sixth motor: value reference 6 is its wind_input_z.
        assert_eq!(Rows::of_model(&quad()).inputs[6].name, "wind_input_z");
    }
}
