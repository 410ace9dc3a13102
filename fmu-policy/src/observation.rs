//! The "hover-motors" observation, built from the plant's outputs exactly as the core's
//! QuadHover task builds it for the motor interface (core/src/tasks/flight.rs,
//! `write_base_observation`): the same values in the same operation order, so that an input
//! set from Quadrotor.fmu's outputs gives the gym's observation bit for bit; then the recipe's
//! normalisation (fast_ppo.py's RunningNorm, float64) and the action mapping (gymnasium's
//! RescaleAction, float32).

use crate::estimate;
use crate::recipe::{ACTION_MAPS, Interface, Recipe};
use flyloop_core::tasks::clip_f32;

/// The plant outputs the policy reads, in input order, before the motor states.
pub const PLANT_OUTPUTS: [(&str, &str, &str); 22] = [
    ("x", "m", "Position east (world ENU): the plant's x"),
    ("y", "m", "Position north (world ENU): the plant's y"),
    ("z", "m", "Height (world ENU): the plant's z"),
    ("vx", "m/s", "Velocity east: the plant's vx"),
    ("vy", "m/s", "Velocity north: the plant's vy"),
    ("vz", "m/s", "Velocity up: the plant's vz"),
    ("ax", "m/s2", "Acceleration east: the plant's ax"),
    ("ay", "m/s2", "Acceleration north: the plant's ay"),
    ("az", "m/s2", "Acceleration up: the plant's az"),
    (
        "qw",
        "1",
        "Attitude quaternion w (body FLU to world ENU): the plant's qw",
    ),
    ("qx", "1", "Attitude quaternion x: the plant's qx"),
    ("qy", "1", "Attitude quaternion y: the plant's qy"),
    ("qz", "1", "Attitude quaternion z: the plant's qz"),
    ("wx", "rad/s", "Body rate about x (forward): the plant's wx"),
    ("wy", "rad/s", "Body rate about y (left): the plant's wy"),
    ("wz", "rad/s", "Body rate about z (up): the plant's wz"),
    (
        "dwx",
        "rad/s2",
        "Angular acceleration about body x: the plant's dwx",
    ),
    (
        "dwy",
        "rad/s2",
        "Angular acceleration about body y: the plant's dwy",
    ),
    (
        "dwz",
        "rad/s2",
        "Angular acceleration about body z: the plant's dwz",
    ),
    (
        "wind_x",
        "m/s",
        "Wind at the vehicle, east: the plant's wind_x",
    ),
    (
        "wind_y",
        "m/s",
        "Wind at the vehicle, north: the plant's wind_y",
    ),
    (
        "wind_z",
        "m/s",
        "Wind at the vehicle, up: the plant's wind_z",
    ),
];

/// Where the motor states start among the inputs.
pub const MOTOR_STATES: usize = PLANT_OUTPUTS.len();

/// The recipe's observation (float32, clipped into its bounds) for the plant outputs `inputs`
/// (in input order), the target (world ENU) and the FMU's previous outputs.
pub fn observation(
    recipe: &Recipe,
    inputs: &[f64],
    target: [f64; 3],
    previous: &[f64],
) -> Vec<f32> {
    match recipe.interface() {
        Interface::HoverMotors => hover_motors(recipe, inputs, target, previous),
        Interface::RatesEstimate => estimate::observation(recipe, inputs, target, previous),
    }
}

/// The gym's motor-interface observation for the plant outputs `inputs` (in input order),
/// the target (world ENU) and the previous motor commands.
fn hover_motors(recipe: &Recipe, inputs: &[f64], target: [f64; 3], previous: &[f64]) -> Vec<f32> {
    let n = recipe.rotors;
    let at = |i: usize| inputs.get(i).copied().unwrap_or(0.0);
    let (w, x, y, z) = (at(9), at(10), at(11), at(12));
    // q and -q are the same attitude: the hemisphere w >= 0, as the core reports it.
    let quaternion = if w < 0.0 {
        [-w, -x, -y, -z]
    } else {
        [w, x, y, z]
    };
    // BodyState::body_z_axis of the plant's (unflipped) quaternion.
    let body_z = [
        2.0 * (x * z + w * y),
        2.0 * (y * z - w * x),
        1.0 - 2.0 * (x * x + y * y),
    ];
    let offset = [target[0] - at(0), target[1] - at(1), target[2] - at(2)];
    let motor_states = (0..n).map(|i| at(MOTOR_STATES + i));
    let values = offset
        .into_iter()
        .chain((3..9).map(at))
        .chain(quaternion)
        .chain((13..19).map(at))
        .chain(body_z)
        .chain((19..22).map(at))
        .chain(motor_states)
        .chain((0..n).map(|i| previous.get(i).copied().unwrap_or(0.0)));
    let bounds = recipe.observation_low.iter().zip(&recipe.observation_high);
    values
        .zip(bounds)
        .map(|(v, (lo, hi))| clip_f32(v, *lo as f32, *hi as f32))
        .collect()
}

/// fast_ppo.py's RunningNorm: (o - mean) / sqrt(var + epsilon) in float64, clipped, float32.
pub fn normalised(recipe: &Recipe, observation: &[f32]) -> Vec<f32> {
    let clip = recipe.normalisation_clip;
    let stats = recipe.observation_mean.iter().zip(&recipe.observation_var);
    observation
        .iter()
        .zip(stats)
        .map(|(o, (mean, var))| {
            let z = (f64::from(*o) - mean) / (var + recipe.normalisation_epsilon).sqrt();
            z.clamp(-clip, clip) as f32
        })
        .collect()
}

/// The FMU's outputs for the network's output: clipped into +-action_clip (float32), then
/// the recipe's action map in float32, as the env receives it — gymnasium's RescaleAction
/// `(a - intercept) / gradient`, or fast_ppo.py's `low + (a + 1) * 0.5 * (high - low)`
/// followed by the env's clip into `[low, high]` (float64: the action as applied).
pub fn commands(recipe: &Recipe, action: &[f32]) -> Vec<f64> {
    let clip = recipe.action_clip as f32;
    let clipped = action.iter().map(|a| {
        if a.is_nan() {
            0.0
        } else {
            a.clamp(-clip, clip)
        }
    });
    if recipe.action_map == ACTION_MAPS[0] {
        let map = recipe.action_intercept.iter().zip(&recipe.action_gradient);
        clipped
            .zip(map)
            .map(|(a, (intercept, gradient))| f64::from((a - *intercept as f32) / *gradient as f32))
            .collect()
    } else {
        let bounds = recipe.action_low.iter().zip(&recipe.action_high);
        clipped
            .zip(bounds)
            .map(|(a, (low, high))| {
                let (lo, hi) = (*low as f32, *high as f32);
                f64::from(lo + (a + 1.0) * 0.5 * (hi - lo)).clamp(*low, *high)
            })
            .collect()
    }
}
