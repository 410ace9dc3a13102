//! The Lander2D's variable table: inputs, outputs, physical parameters and start values,
//! with value references, for the FMU and the SITL.

use super::model::Lander2d;
use super::params::{Lander2dInitial, Lander2dParams};
use crate::error::ParamError;
use crate::params::{Parameters, ValueKind};
use crate::variables::{
    Causality, Variability, Variable, parameter_at, parameter_variables, vr_block,
};

type Getter = fn(&Lander2d) -> f64;

fn flag(b: bool) -> f64 {
    if b { 1.0 } else { 0.0 }
}

/// Outputs: (name, kind, unit, description, getter). Order fixes the value references.
static OUTPUTS: &[(&str, ValueKind, &str, &str, Getter)] = &[
    ("x", ValueKind::Real, "m", "Drone centre x", |l| l.drone().x),
    (
        "y",
        ValueKind::Real,
        "m",
        "Drone centre y (height; the ground is at ground_height)",
        |l| l.drone().y,
    ),
    (
        "vx",
        ValueKind::Real,
        "m/s",
        "Drone velocity along x",
        |l| l.drone().vx,
    ),
    (
        "vy",
        ValueKind::Real,
        "m/s",
        "Drone velocity along y",
        |l| l.drone().vy,
    ),
    (
        "ax",
        ValueKind::Real,
        "m/s2",
        "Mean acceleration along x over the last control period",
        |l| l.acceleration()[0],
    ),
    (
        "ay",
        ValueKind::Real,
        "m/s2",
        "Mean acceleration along y over the last control period",
        |l| l.acceleration()[1],
    ),
    (
        "angle",
        ValueKind::Real,
        "rad",
        "Drone angle, counter-clockwise, in [-pi, pi)",
        |l| super::wrap_angle(l.drone().angle),
    ),
    (
        "angular_velocity",
        ValueKind::Real,
        "rad/s",
        "Drone angular velocity, counter-clockwise",
        |l| l.drone().angular_velocity,
    ),
    (
        "thrust_left",
        ValueKind::Real,
        "N",
        "Thrust of the left motor (noise and battery included)",
        |l| l.thrust()[0],
    ),
    (
        "thrust_right",
        ValueKind::Real,
        "N",
        "Thrust of the right motor (noise and battery included)",
        |l| l.thrust()[1],
    ),
    (
        "battery",
        ValueKind::Real,
        "1",
        "Remaining battery charge",
        |l| l.battery(),
    ),
    (
        "landed",
        ValueKind::Boolean,
        "",
        "Touched down on the platform within the safe speed and angle",
        |l| flag(l.landed()),
    ),
    (
        "crashed",
        ValueKind::Boolean,
        "",
        "Touched the ground, or the platform too fast or too tilted",
        |l| flag(l.crashed()),
    ),
    (
        "on_platform",
        ValueKind::Boolean,
        "",
        "In contact with the platform now",
        |l| flag(l.contact().on_platform),
    ),
    (
        "on_ground",
        ValueKind::Boolean,
        "",
        "In contact with the ground now",
        |l| flag(l.contact().on_ground),
    ),
    (
        "platform_x",
        ValueKind::Real,
        "m",
        "Platform top centre x",
        |l| l.platform_target().0,
    ),
    (
        "platform_y",
        ValueKind::Real,
        "m",
        "Platform top centre y",
        |l| l.platform_target().1,
    ),
    (
        "platform_vx",
        ValueKind::Real,
        "m/s",
        "Platform velocity along x",
        |l| l.platform_vx(),
    ),
    (
        "wind_force_x",
        ValueKind::Real,
        "N",
        "Wind force on the drone along x (episode wind + input)",
        |l| l.wind_force()[0],
    ),
    (
        "wind_force_y",
        ValueKind::Real,
        "N",
        "Wind force on the drone along y (episode wind + input)",
        |l| l.wind_force()[1],
    ),
];

/// Inputs: (name, unit, description, min, max, start).
static INPUTS: &[(&str, &str, &str, f64, f64, f64)] = &[
    (
        "motor_command_left",
        "1",
        "Left motor command; [-1, 1] maps onto [0, max_thrust]",
        -1.0,
        1.0,
        -1.0,
    ),
    (
        "motor_command_right",
        "1",
        "Right motor command; [-1, 1] maps onto [0, max_thrust]",
        -1.0,
        1.0,
        -1.0,
    ),
    (
        "wind_force_input_x",
        "N",
        "External wind force along x, added to the episode wind",
        -1e4,
        1e4,
        0.0,
    ),
    (
        "wind_force_input_y",
        "N",
        "External wind force along y, added to the episode wind",
        -1e4,
        1e4,
        0.0,
    ),
];

const PARAMETERS: u32 = vr_block::PARAMETER;
const INITIAL: u32 = vr_block::INITIAL;
const N_INPUTS: u32 = 4;

/// Every variable of the Lander2D, in value-reference order.
pub fn variables() -> Vec<Variable> {
    let inputs = INPUTS.iter().zip(vr_block::INPUT..).map(
        |(&(name, unit, description, min, max, start), vr)| Variable {
            name,
            value_reference: vr,
            kind: ValueKind::Real,
            causality: Causality::Input,
            variability: Variability::Continuous,
            unit,
            description,
            start: Some(start),
            min: Some(min),
            max: Some(max),
        },
    );
    let outputs =
        OUTPUTS
            .iter()
            .zip(vr_block::OUTPUT..)
            .map(|(&(name, kind, unit, description, _), vr)| Variable {
                name,
                value_reference: vr,
                kind,
                causality: Causality::Output,
                variability: if kind == ValueKind::Real {
                    Variability::Continuous
                } else {
                    Variability::Discrete
                },
                unit,
                description,
                start: None,
                min: None,
                max: None,
            });
    inputs
        .chain(outputs)
        .chain(parameter_variables::<Lander2dParams>(
            PARAMETERS,
            Variability::Fixed,
        ))
        .chain(parameter_variables::<Lander2dInitial>(
            INITIAL,
            Variability::Fixed,
        ))
        .collect()
}

fn output_at(
    vr: u32,
) -> Result<&'static (&'static str, ValueKind, &'static str, &'static str, Getter), ParamError> {
    vr.checked_sub(vr_block::OUTPUT)
        .and_then(|i| OUTPUTS.get(i as usize))
        .ok_or(ParamError::UnknownValueReference(vr))
}

/// Reads variable `vr`.
pub fn get(lander: &Lander2d, initial: &Lander2dInitial, vr: u32) -> Result<f64, ParamError> {
    match vr {
        0..=1 => Ok(lander.command()[vr as usize]),
        2..=3 => Ok(lander.external_wind_force()[(vr - 2) as usize]),
        _ if vr >= INITIAL => Ok((parameter_at::<Lander2dInitial>(vr, INITIAL)?.get)(initial)),
        _ if vr >= PARAMETERS => Ok((parameter_at::<Lander2dParams>(vr, PARAMETERS)?.get)(
            lander.params(),
        )),
        _ => Ok((output_at(vr)?.4)(lander)),
    }
}

/// Writes variable `vr`; the value is checked against the variable's range and nothing
/// changes when it is refused. A physical parameter rebuilds the scene around the current
/// state (see [`Lander2d::set_parameter`]).
pub fn set(
    lander: &mut Lander2d,
    initial: &mut Lander2dInitial,
    vr: u32,
    value: f64,
) -> Result<(), ParamError> {
    match vr {
        _ if vr < N_INPUTS => {
            let (name, unit, _, min, max, _) = INPUTS[vr as usize];
            if !(value >= min && value <= max) {
                return Err(ParamError::OutOfRange {
                    name,
                    value,
                    min,
                    max,
                    unit,
                });
            }
            // Finite and in range from here on: the setters cannot refuse it.
            let refused = |_| ParamError::NotSettable(name);
            if vr < 2 {
                let mut command = lander.command();
                command[vr as usize] = value;
                lander.set_command(command).map_err(refused)
            } else {
                let mut force = lander.external_wind_force();
                force[(vr - 2) as usize] = value;
                lander.set_external_wind_force(force).map_err(refused)
            }
        }
        _ if vr >= INITIAL => {
            let name = parameter_at::<Lander2dInitial>(vr, INITIAL)?.name;
            initial.set(name, value)
        }
        _ if vr >= PARAMETERS => {
            let name = parameter_at::<Lander2dParams>(vr, PARAMETERS)?.name;
            lander.set_parameter(name, value)
        }
        _ => Err(ParamError::NotSettable(output_at(vr)?.0)),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn lander() -> Lander2d {
        Lander2d::from_initial(Lander2dParams::default(), &Lander2dInitial::default()).unwrap()
    }

    fn vr(name: &str) -> u32 {
        variables()
            .into_iter()
            .find(|v| v.name == name)
            .unwrap()
            .value_reference
    }

    #[test]
    fn names_and_value_references_are_unique_and_every_one_reads() {
        let vars = variables();
        let l = lander();
        let init = Lander2dInitial::default();
        crate::variables::assert_names_and_value_references_are_unique(&vars);
        for v in &vars {
            let value = get(&l, &init, v.value_reference).unwrap();
            assert!(value.is_finite(), "{} = {value}", v.name);
            if let Some(start) = v.start {
                assert_eq!(value, start, "{} does not read its start value", v.name);
            }
        }
        assert_eq!(vars.len(), 4 + 20 + 29 + 7);
        assert_eq!(
            get(&l, &init, 99),
            Err(ParamError::UnknownValueReference(99))
        );
        assert_eq!(get(&l, &init, 4), Err(ParamError::UnknownValueReference(4)));
        assert_eq!(
            get(&l, &init, 10_000),
            Err(ParamError::UnknownValueReference(10_000))
        );
    }

    #[test]
    fn outputs_read_the_state_and_cannot_be_set() {
        let mut l = lander();
        let mut init = Lander2dInitial::default();
        assert_eq!(get(&l, &init, vr("x")).unwrap(), 25.0);
        assert_eq!(get(&l, &init, vr("y")).unwrap(), 40.0);
        assert_eq!(get(&l, &init, vr("battery")).unwrap(), 100.0);
        assert_eq!(get(&l, &init, vr("platform_y")).unwrap(), 10.5);
        assert_eq!(get(&l, &init, vr("landed")).unwrap(), 0.0);
        let wind = (
            get(&l, &init, vr("wind_force_x")).unwrap(),
            get(&l, &init, vr("wind_force_y")).unwrap(),
        );
        assert!((wind.0.hypot(wind.1) - 2.5).abs() < 1e-12, "{wind:?}");
        assert_eq!(
            set(&mut l, &mut init, vr("x"), 1.0),
            Err(ParamError::NotSettable("x"))
        );
        assert_eq!(
            set(&mut l, &mut init, vr("crashed"), 1.0),
            Err(ParamError::NotSettable("crashed"))
        );
        let landed = variables()
            .into_iter()
            .find(|v| v.name == "landed")
            .unwrap();
        assert_eq!(
            (landed.kind, landed.variability),
            (ValueKind::Boolean, Variability::Discrete)
        );
    }

    #[test]
    fn inputs_and_parameters_are_range_checked_and_refusals_change_nothing() {
        let mut l = lander();
        let mut init = Lander2dInitial::default();
        set(&mut l, &mut init, vr("motor_command_right"), 0.25).unwrap();
        assert_eq!(l.command(), [-1.0, 0.25]);
        let err = set(&mut l, &mut init, vr("motor_command_right"), f64::NAN).unwrap_err();
        assert!(err.to_string().contains("motor_command_right"), "{err}");
        let err = set(&mut l, &mut init, vr("motor_command_left"), 1.5).unwrap_err();
        assert!(err.to_string().contains("motor_command_left"), "{err}");
        assert_eq!(l.command(), [-1.0, 0.25]);
        let before = l.wind_force();
        set(&mut l, &mut init, vr("wind_force_input_y"), -3.0).unwrap();
        assert_eq!(l.wind_force(), [before[0], before[1] - 3.0]);
        let err = set(&mut l, &mut init, vr("drone_mass"), -1.0).unwrap_err();
        assert!(err.to_string().contains("`drone_mass` = -1 kg"), "{err}");
        assert_eq!(l.params().drone_mass, 1.5);
        set(&mut l, &mut init, vr("drone_mass"), 3.0).unwrap();
        assert_eq!(l.params().drone_mass, 3.0);
        // The scene follows: the composite inertia doubles with the mass.
        assert!((l.inertia() - 0.4325).abs() < 1e-12, "{}", l.inertia());
        assert_eq!(get(&l, &init, vr("x")).unwrap(), 25.0);
        set(&mut l, &mut init, vr("initial_y"), 30.0).unwrap();
        assert_eq!(init.initial_y, 30.0);
        let err = set(&mut l, &mut init, vr("seed"), 0.5).unwrap_err();
        assert!(
            err.to_string().contains("`seed` = 0.5 is not an integer"),
            "{err}"
        );
    }

    #[test]
    fn parameters_set_before_the_first_step_shape_the_start_and_later_keep_the_state() {
        let mut l = lander();
        let mut init = Lander2dInitial::default();
        set(&mut l, &mut init, vr("platform_start_x"), 10.0).unwrap();
        set(&mut l, &mut init, vr("initial_battery"), 50.0).unwrap();
        assert_eq!(get(&l, &init, vr("platform_x")).unwrap(), 10.0);
        assert_eq!(get(&l, &init, vr("battery")).unwrap(), 50.0);
        set(&mut l, &mut init, vr("wind_enabled"), 0.0).unwrap();
        assert_eq!(l.wind_force(), [0.0, 0.0]);
        l.step();
        let (x, battery) = (l.platform_x(), l.battery());
        set(&mut l, &mut init, vr("platform_start_x"), 30.0).unwrap();
        set(&mut l, &mut init, vr("initial_battery"), 80.0).unwrap();
        assert_eq!(
            (l.platform_x(), l.battery()),
            (x, battery),
            "a running scene keeps its state"
        );
        set(&mut l, &mut init, vr("wind_enabled"), 1.0).unwrap();
        let [fx, fy] = l.wind_force();
        assert!(
            (fx.hypot(fy) - 2.5).abs() < 1e-12,
            "the episode's wind direction comes back"
        );
    }
}
