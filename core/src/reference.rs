//! The parameter reference (docs/parameters.md), generated from the parameter tables so the
//! documentation cannot drift from the code: a test compares the checked-in file with
//! [`parameter_reference`], and `cargo run -p flyloop-core --example parameter_reference`
//! prints it.

use crate::lander2d::{Lander2dInitial, Lander2dParams};
use crate::params::Parameters;
use crate::quadrotor::{QuadrotorInitial, QuadrotorParams};
use crate::rate_loop::RateLoopParams;
use crate::sensors::SensorParams;
use crate::tasks::flight::FlightParams;
use crate::tasks::landing::LandingParams;
use crate::tasks::waypoints::WaypointParams;

/// The reference's title and what it is.
const INTRO: &str = "# Parameter reference\n\n\
     Generated from the parameter tables in `core/` by\n\
     `cargo run -p flyloop-core --example parameter_reference > docs/parameters.md`;\n\
     a test fails when this file and the code disagree. Every value is checked against\n\
     its range when set (from TOML/JSON, over MAVLink, through the FMU), and the error\n\
     names the parameter and the bound it broke.\n";

/// The whole reference as markdown.
pub fn parameter_reference() -> String {
    let mut out = String::from(INTRO);
    for (title, text, table) in sections() {
        out.push_str(&format!("\n## {title}\n\n{text}\n\n{table}"));
    }
    out
}

/// Every parameter table in the reference's order: (title, what it holds, markdown table).
fn sections() -> [(&'static str, &'static str, String); 9] {
    [
        (
            "Quadrotor model (`QuadrotorParams`)",
            "Physical parameters of the 3D quadrotor (world ENU, body FLU, PX4 quad-X).",
            QuadrotorParams::markdown_table(),
        ),
        (
            "Quadrotor start values (`QuadrotorInitial`, FMU only)",
            "Seed and initial state of an FMU instance.",
            QuadrotorInitial::markdown_table(),
        ),
        (
            "Quadrotor sensors (`SensorParams`, PX4 mode)",
            "Home point, Earth field and noise of the IMU (body FRD), magnetometer, barometer (ISA) and GPS that PX4 reads; the field defaults are the World Magnetic Model at the default home.",
            SensorParams::markdown_table(),
        ),
        (
            "PX4's rate loop (`RateLoopParams`, the flight tasks' rates interface)",
            "PX4 v1.16.0's multicopter rate controller, gyro filters and control allocation as the core models them; defaults are airframe 10016 none_iris's (body FRD, normalised torque). Any real parameter here, of the quadrotor, and the flight tasks' `action_latency` and `obs_noise_*` can be randomised per episode by name (`randomize` / the config file's `[randomize]` table).",
            RateLoopParams::markdown_table(),
        ),
        (
            "Hover and Waypoints tasks (`FlightParams`)",
            "Episode settings shared by QuadHover and QuadWaypoints (seed 001's DroneEnv arguments).",
            FlightParams::markdown_table(),
        ),
        (
            "Waypoints task (`WaypointParams`)",
            "Extra settings of QuadWaypoints (seed 001's SequentialWaypointEnv arguments).",
            WaypointParams::markdown_table(),
        ),
        (
            "Lander2D model (`Lander2dParams`)",
            "Physical parameters of the 2D lander on rapier2d (world x right, y up, metres).",
            Lander2dParams::markdown_table(),
        ),
        (
            "Lander2D start values (`Lander2dInitial`, FMU only)",
            "Seed and initial state of an FMU instance.",
            Lander2dInitial::markdown_table(),
        ),
        (
            "Landing task (`LandingParams`)",
            "Episode settings of Lander2D (seed 000's arguments).",
            LandingParams::markdown_table(),
        ),
    ]
}
