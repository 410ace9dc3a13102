//! The "rates-estimate" observation: the gym's rates interface (16 values, PX4's frames turned
//! by the heading; core/src/tasks/flight_link.rs, `estimate` and `write_observation`), built
//! from inputs named like the plant's outputs.
//!
//! In the gym (and through PX4) the policy sees the autopilot's *estimate*. In an FMU system
//! there is no estimator: the estimate is the plant's true state, its outputs — what the gym's
//! estimate is without `observation_noise`. The operations are the core's, in its order (the
//! noise terms the core adds are the zeros it adds without noise), so a plant state gives the
//! gym's observation bit for bit.

use crate::recipe::Recipe;
use flyloop_core::frames::{attitude_ned, enu_to_ned, flu_to_frd};
use flyloop_core::tasks::clip_f32;
use nalgebra::{Quaternion, UnitQuaternion, Vector3};

/// The plant outputs the policy reads, in input order (their units and descriptions are the
/// hover recipe's, [`crate::observation::PLANT_OUTPUTS`]).
pub const ESTIMATE_INPUTS: [&str; 13] = [
    "x", "y", "z", "vx", "vy", "vz", "qw", "qx", "qy", "qz", "wx", "wy", "wz",
];

/// The setpoint the policy writes, in output order: RateController.fmu's inputs.
pub const SETPOINT_OUTPUTS: [(&str, &str, &str); 4] = [
    (
        "thrust",
        "1",
        "Collective thrust setpoint, PX4's normalised thrust: RateController's thrust",
    ),
    (
        "roll_rate",
        "rad/s",
        "Roll rate setpoint, body FRD: RateController's roll_rate",
    ),
    (
        "pitch_rate",
        "rad/s",
        "Pitch rate setpoint, body FRD: RateController's pitch_rate",
    ),
    (
        "yaw_rate",
        "rad/s",
        "Yaw rate setpoint, body FRD: RateController's yaw_rate",
    ),
];

/// A world NED vector in the heading frame of `yaw` (the core's `heading_frame`).
fn heading_frame(yaw: f64, v: &Vector3<f64>) -> Vector3<f64> {
    let (s, c) = yaw.sin_cos();
    Vector3::new(c * v.x + s * v.y, -s * v.x + c * v.y, v.z)
}

/// The gym's rates observation (float32, clipped into the recipe's bounds) for the plant
/// outputs `inputs` (in [`ESTIMATE_INPUTS`] order), the target (world ENU) and the previous
/// setpoint as applied.
pub fn observation(
    recipe: &Recipe,
    inputs: &[f64],
    target: [f64; 3],
    previous: &[f64],
) -> Vec<f32> {
    let at = |i: usize| inputs.get(i).copied().unwrap_or(0.0);
    let vector = |i: usize| Vector3::new(at(i), at(i + 1), at(i + 2));
    let no_noise = Vector3::<f64>::zeros();
    let position_ned = enu_to_ned(&vector(0)) + no_noise;
    let velocity_ned = enu_to_ned(&vector(3)) + no_noise;
    let rates_frd = flu_to_frd(&vector(10)) + no_noise;
    let attitude = UnitQuaternion::new_unchecked(Quaternion::new(at(6), at(7), at(8), at(9)));
    let (roll, pitch, yaw) = attitude_ned(&attitude).euler_angles();
    let (roll, pitch, yaw) = (roll + no_noise.x, pitch + no_noise.y, yaw + no_noise.z);
    // Tilt without heading: R_z(-yaw)·R = R_y(pitch)·R_x(roll); its third column.
    let down_axis = UnitQuaternion::from_euler_angles(roll, pitch, 0.0) * Vector3::z();
    let target = Vector3::new(target[0], target[1], target[2]);
    let offset = heading_frame(yaw, &(enu_to_ned(&target) - position_ned));
    let velocity = heading_frame(yaw, &velocity_ned);
    let previous = (0..SETPOINT_OUTPUTS.len()).map(|i| previous.get(i).copied().unwrap_or(0.0));
    let values = offset
        .iter()
        .chain(velocity.iter())
        .chain(down_axis.iter())
        .chain(rates_frd.iter())
        .copied()
        .chain(previous);
    let bounds = recipe.observation_low.iter().zip(&recipe.observation_high);
    values
        .zip(bounds)
        .map(|(v, (lo, hi))| clip_f32(v, *lo as f32, *hi as f32))
        .collect()
}
