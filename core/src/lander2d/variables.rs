//! The Lander2D's variable table: inputs, outputs, physical parameters and start values,
//! with value references, for the FMU and the SITL.

use super::model::Lander2d;
use super::params::{Lander2dInitial, Lander2dParams};
use crate::error::{InputError, ParamError};
use crate::variables::{InputRow, OutputRow, VariableTable};

fn flag(b: bool) -> f64 {
    if b { 1.0 } else { 0.0 }
}

/// Outputs; their order fixes the value references.
const OUTPUTS: &[OutputRow<Lander2d>] = &[
    OutputRow::real("x", "m", "Drone centre x", |l| l.drone().x),
    OutputRow::real(
        "y",
        "m",
        "Drone centre y (height; the ground is at ground_height)",
        |l| l.drone().y,
    ),
    OutputRow::real("vx", "m/s", "Drone velocity along x", |l| l.drone().vx),
    OutputRow::real("vy", "m/s", "Drone velocity along y", |l| l.drone().vy),
    OutputRow::real(
        "ax",
        "m/s2",
        "Mean acceleration along x over the last control period",
        |l| l.acceleration()[0],
    ),
    OutputRow::real(
        "ay",
        "m/s2",
        "Mean acceleration along y over the last control period",
        |l| l.acceleration()[1],
    ),
    OutputRow::real(
        "angle",
        "rad",
        "Drone angle, counter-clockwise, in [-pi, pi)",
        |l| super::wrap_angle(l.drone().angle),
    ),
    OutputRow::real(
        "angular_velocity",
        "rad/s",
        "Drone angular velocity, counter-clockwise",
        |l| l.drone().angular_velocity,
    ),
    OutputRow::real(
        "thrust_left",
        "N",
        "Thrust of the left motor (noise and battery included)",
        |l| l.thrust()[0],
    ),
    OutputRow::real(
        "thrust_right",
        "N",
        "Thrust of the right motor (noise and battery included)",
        |l| l.thrust()[1],
    ),
    OutputRow::real("battery", "1", "Remaining battery charge", |l| l.battery()),
    OutputRow::flag(
        "landed",
        "Touched down on the platform within the safe speed and angle",
        |l| flag(l.landed()),
    ),
    OutputRow::flag(
        "crashed",
        "Touched the ground, or the platform too fast or too tilted",
        |l| flag(l.crashed()),
    ),
    OutputRow::flag("on_platform", "In contact with the platform now", |l| {
        flag(l.contact().on_platform)
    }),
    OutputRow::flag("on_ground", "In contact with the ground now", |l| {
        flag(l.contact().on_ground)
    }),
    OutputRow::real("platform_x", "m", "Platform top centre x", |l| {
        l.platform_target().0
    }),
    OutputRow::real("platform_y", "m", "Platform top centre y", |l| {
        l.platform_target().1
    }),
    OutputRow::real("platform_vx", "m/s", "Platform velocity along x", |l| {
        l.platform_vx()
    }),
    OutputRow::real(
        "wind_force_x",
        "N",
        "Wind force on the drone along x (episode wind + input)",
        |l| l.wind_force()[0],
    ),
    OutputRow::real(
        "wind_force_y",
        "N",
        "Wind force on the drone along y (episode wind + input)",
        |l| l.wind_force()[1],
    ),
    OutputRow::flag(
        "out_of_bounds",
        "Drone centre outside the world: not (0 < x < world_width and 0 < y < world_height)",
        |l| flag(l.out_of_bounds()),
    ),
    OutputRow::flag(
        "battery_empty",
        "Battery exhausted: the motors give no thrust",
        |l| flag(l.battery() <= 0.0),
    ),
];

/// Inputs; their order fixes the value references.
const INPUTS: &[InputRow<Lander2d>] = &[
    motor::<0>(
        "motor_command_left",
        "Left motor command; [-1, 1] maps onto [0, max_thrust]",
    ),
    motor::<1>(
        "motor_command_right",
        "Right motor command; [-1, 1] maps onto [0, max_thrust]",
    ),
    wind::<0>(
        "wind_force_input_x",
        "External wind force along x, added to the episode wind",
    ),
    wind::<1>(
        "wind_force_input_y",
        "External wind force along y, added to the episode wind",
    ),
];

/// Motor command `I` in [-1, 1], starting at -1 (off).
const fn motor<const I: usize>(name: &'static str, text: &'static str) -> InputRow<Lander2d> {
    InputRow::new(
        name,
        "1",
        text,
        [-1.0, 1.0, -1.0],
        |l| l.command()[I],
        set_motor::<I>,
    )
}

/// External wind force component `I` in N.
const fn wind<const I: usize>(name: &'static str, text: &'static str) -> InputRow<Lander2d> {
    let range = [-1e4, 1e4, 0.0];
    let get = |l: &Lander2d| l.external_wind_force()[I];
    InputRow::new(name, "N", text, range, get, set_wind::<I>)
}

fn set_motor<const I: usize>(lander: &mut Lander2d, value: f64) -> Result<(), InputError> {
    let mut command = lander.command();
    command[I] = value;
    lander.set_command(command)
}

fn set_wind<const I: usize>(lander: &mut Lander2d, value: f64) -> Result<(), InputError> {
    let mut force = lander.external_wind_force();
    force[I] = value;
    lander.set_external_wind_force(force)
}

impl VariableTable for Lander2d {
    type Params = Lander2dParams;
    type Initial = Lander2dInitial;
    crate::fixed_shape!(INPUTS, OUTPUTS);

    fn params(&self) -> &Lander2dParams {
        Lander2d::params(self)
    }

    /// A physical parameter rebuilds the scene around the current state (see
    /// [`Lander2d::set_parameter`]).
    fn set_parameter(&mut self, name: &'static str, value: f64) -> Result<(), ParamError> {
        Lander2d::set_parameter(self, name, value)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::params::ValueKind;
    use crate::variables::Variability;
    use crate::variables::{Rows, get, set};

    fn variables() -> Vec<crate::variables::Variable> {
        Rows::<Lander2d>::of(&()).variables()
    }

    fn lander() -> Lander2d {
        Lander2d::from_initial(Lander2dParams::default(), &Lander2dInitial::default()).unwrap()
    }

    fn vr(name: &str) -> u32 {
        let mut variables = variables().into_iter();
        variables.find(|v| v.name == name).unwrap().value_reference
    }

    #[test]
    fn names_and_value_references_are_unique_and_every_one_reads() {
        let (l, init) = (lander(), Lander2dInitial::default());
        crate::variables::assert_every_variable_reads(&l, &init, true);
        assert_eq!(variables().len(), 4 + 22 + 29 + 7);
        // 4 lies between the inputs (0..=3) and the outputs: no variable.
        assert_eq!(get(&l, &init, 4), Err(ParamError::UnknownValueReference(4)));
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
