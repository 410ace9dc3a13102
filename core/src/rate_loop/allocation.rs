//! PX4's control allocation for a multirotor (`src/modules/control_allocator`): the rotors'
//! effectiveness matrix, its pseudo-inverse normalised as PX4 normalises it, the sequential
//! desaturation with airmode off, and the motors' thrust model.
//!
//! Control vector: [roll, pitch, yaw torque (normalised, body FRD), thrust x, y, z
//! (normalised, body FRD: a collective thrust T is z = −T)]; actuators: the motors in the
//! core's order (front-right, rear-left, front-left, rear-right), each in [0, 1].

use nalgebra::{Matrix4, SMatrix, Vector3};
use serde::{Deserialize, Serialize};

/// One rotor as PX4's `CA_ROTORn_*` parameters describe it (body FRD).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Rotor {
    /// Position relative to the centre of mass, m (`CA_ROTORn_PX/PY/PZ`).
    pub position: Vector3<f64>,
    /// Moment ratio: yaw torque per unit thrust, m, positive for a counter-clockwise rotor
    /// (`CA_ROTORn_KM`).
    pub moment_ratio: f64,
}

/// Yaw's share of headroom above full thrust (PX4's `MINIMUM_YAW_MARGIN`).
const MINIMUM_YAW_MARGIN: f64 = 0.15;
/// PX4 compares in single precision; the same threshold keeps the same decisions.
const FLT_EPSILON: f64 = f32::EPSILON as f64;
/// Mixer entries smaller than this do not take part in a desaturation (PX4: 0.2).
const DESATURATION_MIN_ENTRY: f64 = 0.2;

/// The normalised mixer of four rotors and what it saturated last.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Allocation {
    /// Normalised pseudo-inverse: motor = mix · [roll, pitch, yaw, thrust_z].
    mix: SMatrix<f64, 4, 4>,
    /// Effectiveness rows [roll, pitch, yaw, thrust_z] per motor, in normalised units
    /// (PX4's effectiveness times its normalisation scale), to tell what was allocated.
    effectiveness: SMatrix<f64, 4, 4>,
    /// Thrust model factor (`THR_MDL_FAC`): rel. thrust = f·u² + (1 − f)·u.
    thrust_model_factor: f64,
}

/// What the allocator did with one control setpoint.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Allocated {
    /// Motor outputs in [0, 1] after the thrust model, before PX4's PWM step of 0.001.
    pub motors: [f64; 4],
    /// Setpoint minus what the motors produce, per torque axis (roll, pitch, yaw).
    pub unallocated_torque: Vector3<f64>,
}

impl Allocation {
    /// The allocation of `rotors` (each pushing along body −z with the same thrust
    /// coefficient, which cancels in the normalisation). `None` if the rotors cannot
    /// control roll, pitch, yaw and thrust independently.
    pub fn new(rotors: &[Rotor; 4], thrust_model_factor: f64) -> Option<Self> {
        // Effectiveness of rotor i: moment = p × a − km·a, thrust = a, with a = (0, 0, −1).
        let axis = Vector3::new(0.0, 0.0, -1.0);
        let mut e = Matrix4::zeros();
        for (i, r) in rotors.iter().enumerate() {
            let moment = r.position.cross(&axis) - r.moment_ratio * axis;
            e[(0, i)] = moment.x;
            e[(1, i)] = moment.y;
            e[(2, i)] = moment.z;
            e[(3, i)] = axis.z;
        }
        let mix = e.try_inverse()?;
        // PX4's normalisation: roll and pitch share one scale (the larger RMS column over
        // half its non-zero entries), yaw by its column's largest entry, thrust by its mean
        // |entry|.
        let rms = |c: usize| {
            let n = mix.column(c).iter().filter(|v| v.abs() > 1e-3).count();
            if n == 0 {
                1.0
            } else {
                (mix.column(c).norm_squared() / (n as f64 / 2.0)).sqrt()
            }
        };
        let roll_pitch = rms(0).max(rms(1));
        let yaw = mix.column(2).max();
        let nonzero = mix
            .column(3)
            .iter()
            .filter(|v| v.abs() > FLT_EPSILON)
            .count();
        let thrust = mix.column(3).iter().map(|v| v.abs()).sum::<f64>() / nonzero.max(1) as f64;
        let scale = [roll_pitch, roll_pitch, yaw, thrust];
        if scale.iter().any(|s| !(s.is_finite() && *s > 0.0)) {
            return None;
        }
        let mut mix_n = mix;
        let mut e_n = e;
        for (c, s) in scale.iter().enumerate() {
            mix_n.column_mut(c).scale_mut(1.0 / s);
            e_n.row_mut(c).scale_mut(*s);
        }
        Some(Allocation {
            mix: mix_n,
            effectiveness: e_n,
            thrust_model_factor,
        })
    }

    /// Motor outputs for normalised `torque` (body FRD) and collective `thrust` in [0, 1],
    /// with airmode off: thrust is only ever reduced to make room for roll and pitch, which
    /// are scaled back before yaw is mixed in with its own headroom.
    pub fn allocate(&self, torque: &Vector3<f64>, thrust: f64) -> Allocated {
        let control = [torque.x, torque.y, torque.z, -thrust];
        let column = |c: usize| -> [f64; 4] { std::array::from_fn(|i| self.mix[(i, c)]) };
        let (roll, pitch, yaw, thrust_z) = (column(0), column(1), column(2), column(3));
        let mut sp: [f64; 4] = std::array::from_fn(|i| {
            roll[i] * control[0] + pitch[i] * control[1] + thrust_z[i] * control[3]
        });
        let (min, max) = ([0.0; 4], [1.0; 4]);
        desaturate(&mut sp, &thrust_z, &min, &max, true);
        desaturate(&mut sp, &roll, &min, &max, false);
        desaturate(&mut sp, &pitch, &min, &max, false);
        for i in 0..4 {
            sp[i] += yaw[i] * control[2];
        }
        let yaw_max = max.map(|m| m + (m - 0.0) * MINIMUM_YAW_MARGIN);
        desaturate(&mut sp, &yaw, &min, &yaw_max, false);
        desaturate(&mut sp, &thrust_z, &min, &max, true);

        let clipped = sp.map(|u| u.clamp(0.0, 1.0));
        let produced = self.effectiveness * nalgebra::Vector4::from(clipped);
        let unallocated_torque = Vector3::new(
            control[0] - produced[0],
            control[1] - produced[1],
            control[2] - produced[2],
        );
        Allocated {
            motors: clipped.map(|u| thrust_model(u, self.thrust_model_factor)),
            unallocated_torque,
        }
    }
}

/// PX4's sequential desaturation step: moves `sp` along `direction` by the gain that
/// brings it inside [min, max] as far as one gain can, then half of the remaining gain.
/// With `reduce_only`, a move that would add thrust (a negative gain along the thrust
/// column, whose entries are negative) is skipped.
fn desaturate(
    sp: &mut [f64; 4],
    direction: &[f64; 4],
    min: &[f64; 4],
    max: &[f64; 4],
    reduce_only: bool,
) {
    let gain = desaturation_gain(sp, direction, min, max);
    if reduce_only && gain < 0.0 {
        return;
    }
    for i in 0..4 {
        sp[i] += gain * direction[i];
    }
    let gain = 0.5 * desaturation_gain(sp, direction, min, max);
    for i in 0..4 {
        sp[i] += gain * direction[i];
    }
}

/// PX4's `computeDesaturationGain`: the smallest and largest gains that bring each
/// saturated output to its bound, added.
fn desaturation_gain(sp: &[f64; 4], direction: &[f64; 4], min: &[f64; 4], max: &[f64; 4]) -> f64 {
    let (mut k_min, mut k_max) = (0.0f64, 0.0f64);
    for i in 0..4 {
        if direction[i].abs() < DESATURATION_MIN_ENTRY {
            continue;
        }
        let bound = if sp[i] < min[i] {
            min[i]
        } else if sp[i] > max[i] {
            max[i]
        } else {
            continue;
        };
        let k = (bound - sp[i]) / direction[i];
        k_min = k_min.min(k);
        k_max = k_max.max(k);
    }
    k_min + k_max
}

/// PX4's thrust model (`THR_MDL_FAC` = f): the output u whose relative thrust
/// f·u² + (1 − f)·u is the demand `control`; f = 0 is linear.
pub fn thrust_model(control: f64, factor: f64) -> f64 {
    if !(factor > 0.0 && factor <= 1.0) {
        return control;
    }
    if control <= 0.0 {
        return 0.0;
    }
    let b = 1.0 - factor;
    let tmp1 = b / (2.0 * factor);
    let tmp2 = b * b / (4.0 * factor * factor);
    -tmp1 + (tmp2 + control / factor).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rate_loop::RateLoopParams;

    fn iris() -> Allocation {
        let p = RateLoopParams::default();
        Allocation::new(&p.rotors(), 0.0).unwrap()
    }

    #[test]
    fn normalised_mix_is_px4s_for_none_iris() {
        // PX4 v1.16.0, airframe 10016: per motor roll ∓0.4953835, pitch ±0.7071068, yaw
        // +0.7653061 / +1 / −0.7653061 / −1, thrust 1 (its allocator's normalised matrix).
        let a = iris();
        // Pitch is ±1/√2: the larger of the two columns' RMS sets the shared scale.
        let p = std::f64::consts::FRAC_1_SQRT_2;
        let expected = [
            [-0.4953835, p, 0.7653061, -1.0],
            [0.4953835, -p, 1.0, -1.0],
            [0.4953835, p, -0.7653061, -1.0],
            [-0.4953835, -p, -1.0, -1.0],
        ];
        for (i, row) in expected.iter().enumerate() {
            for (j, v) in row.iter().enumerate() {
                assert!(
                    (a.mix[(i, j)] - v).abs() < 1e-6,
                    "mix[{i}][{j}] = {}",
                    a.mix[(i, j)]
                );
            }
        }
    }

    #[test]
    fn unsaturated_outputs_are_thrust_plus_mixed_torque() {
        let a = iris();
        let out = a.allocate(&Vector3::new(0.1, -0.05, 0.02), 0.5);
        let m = &a.mix;
        for i in 0..4 {
            let u = 0.5 + m[(i, 0)] * 0.1 + m[(i, 1)] * -0.05 + m[(i, 2)] * 0.02;
            assert!(
                (out.motors[i] - u).abs() < 1e-12,
                "{i}: {} vs {u}",
                out.motors[i]
            );
        }
        assert!(
            out.unallocated_torque.norm() < 1e-12,
            "{}",
            out.unallocated_torque
        );
    }

    #[test]
    fn roll_beyond_authority_lowers_thrust_then_scales_roll_never_raises_thrust() {
        let a = iris();
        // Full thrust and a roll command: thrust is lowered to make room (motors ≤ 1).
        let out = a.allocate(&Vector3::new(0.5, 0.0, 0.0), 1.0);
        assert!(out.motors.iter().all(|&u| (0.0..=1.0).contains(&u)));
        let produced = out.motors[1] + out.motors[2] - out.motors[0] - out.motors[3];
        assert!(
            produced > 0.0,
            "roll in the asked direction: {:?}",
            out.motors
        );
        // Zero thrust: airmode off never adds thrust, so no torque is produced at all.
        let out = a.allocate(&Vector3::new(0.3, 0.2, 0.1), 0.0);
        assert!(
            out.motors.iter().all(|&u| u.abs() < 1e-12),
            "{:?}",
            out.motors
        );
        assert!(out.unallocated_torque.x > 0.0 && out.unallocated_torque.y > 0.0);
    }

    #[test]
    fn yaw_gets_its_headroom_after_roll_and_pitch() {
        let a = iris();
        // At hover thrust a large yaw demand saturates; roll and pitch stay produced.
        let out = a.allocate(&Vector3::new(0.05, 0.0, 2.0), 0.5);
        assert!(out.motors.iter().all(|&u| (0.0..=1.0).contains(&u)));
        assert!(out.unallocated_torque.z > 0.1, "{}", out.unallocated_torque);
        assert!(
            out.unallocated_torque.x.abs() < 1e-9,
            "{}",
            out.unallocated_torque
        );
    }

    #[test]
    fn thrust_model_inverts_the_quadratic_curve() {
        for f in [0.3, 0.7, 1.0] {
            for u in [0.0, 0.1, 0.5, 1.0] {
                let x = thrust_model(u, f);
                assert!((f * x * x + (1.0 - f) * x - u).abs() < 1e-12);
            }
        }
        assert_eq!(thrust_model(0.42, 0.0), 0.42);
    }

    #[test]
    fn rotors_on_a_line_cannot_be_allocated() {
        let mut p = RateLoopParams::default();
        (p.rotor0_y, p.rotor1_y, p.rotor2_y, p.rotor3_y) = (0.0, 0.0, 0.0, 0.0);
        assert!(Allocation::new(&p.rotors(), 0.0).is_none());
    }
}
