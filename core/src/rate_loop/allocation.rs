//! PX4's control allocation for a multirotor (`src/modules/control_allocator`): the rotors'
//! effectiveness matrix, its pseudo-inverse normalised as PX4 normalises it, the sequential
//! desaturation with airmode off, and the motors' thrust model.
//!
//! Control vector: [roll, pitch, yaw torque (normalised, body FRD), thrust x, y, z
//! (normalised, body FRD: a collective thrust T is z = −T)]; actuators: the frame's motors in
//! its motor order (PX4's outputs), each in [0, 1]. The rotors are PX4's `CA_ROTORn_*`
//! ([`super::px4_rotors`]).

use super::px4_rotors::Px4Rotor;
use crate::quadrotor::frame::MAX_ROTORS;
use nalgebra::{DMatrix, Matrix4, Vector3};
use serde::{Deserialize, Serialize};

/// Motor outputs of one allocation: the first `len` of `MAX_ROTORS` slots.
pub type Outputs = crate::quadrotor::Motors;

/// Yaw's share of headroom above full thrust (PX4's `MINIMUM_YAW_MARGIN`).
const MINIMUM_YAW_MARGIN: f64 = 0.15;
/// PX4 compares in single precision; the same threshold keeps the same decisions.
const FLT_EPSILON: f64 = f32::EPSILON as f64;
/// Mixer entries smaller than this do not take part in a desaturation (PX4: 0.2).
const DESATURATION_MIN_ENTRY: f64 = 0.2;

/// The normalised mixer of a frame's rotors and what it saturated last.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Allocation {
    /// Number of motors (the slots past it are zero).
    count: usize,
    /// Normalised pseudo-inverse by axis [roll, pitch, yaw, thrust_z], one entry per motor:
    /// motor i = Σ_axis mix[axis][i] · control[axis].
    mix: [[f64; MAX_ROTORS]; 4],
    /// Effectiveness rows [roll, pitch, yaw, thrust_z], one entry per motor, in normalised
    /// units (PX4's effectiveness times its normalisation scale), to tell what was allocated.
    effectiveness: [[f64; MAX_ROTORS]; 4],
    /// Thrust model factor (`THR_MDL_FAC`): rel. thrust = f·u² + (1 − f)·u.
    thrust_model_factor: f64,
}

/// What the allocator did with one control setpoint.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Allocated {
    /// Motor outputs in [0, 1] after the thrust model, before PX4's PWM step of 0.001, one
    /// per rotor.
    pub motors: Outputs,
    /// Setpoint minus what the motors produce, per torque axis (roll, pitch, yaw).
    pub unallocated_torque: Vector3<f64>,
}

impl Allocation {
    /// The allocation of `rotors` (4 to [`MAX_ROTORS`], each pushing along body −z). Thrust
    /// coefficients count relative to the largest (a common one cancels in the
    /// normalisation). `None` if the rotors cannot control roll, pitch, yaw and thrust
    /// independently.
    pub fn new(rotors: &[Px4Rotor], thrust_model_factor: f64) -> Option<Self> {
        let n = rotors.len();
        if !(4..=MAX_ROTORS).contains(&n) {
            return None;
        }
        let ct_max = rotors.iter().map(|r| r.ct).fold(0.0, f64::max);
        if !(ct_max.is_finite() && ct_max > 0.0) {
            return None;
        }
        // Effectiveness of rotor i: moment = ct·(p × a − km·a), thrust = ct·a, a = (0, 0, −1).
        let axis = Vector3::new(0.0, 0.0, -1.0);
        let mut e = DMatrix::zeros(4, n);
        for (i, r) in rotors.iter().enumerate() {
            let ct = r.ct / ct_max;
            let position = Vector3::new(r.px, r.py, 0.0);
            let moment = (position.cross(&axis) - r.km * axis) * ct;
            e[(0, i)] = moment.x;
            e[(1, i)] = moment.y;
            e[(2, i)] = moment.z;
            e[(3, i)] = axis.z * ct;
        }
        let mut mix = pseudo_inverse(&e)?;
        // PX4's normalisation: roll and pitch share one scale (the larger RMS column over
        // half its non-zero entries), yaw by its column's largest entry, thrust by its mean
        // |entry|.
        let rms = |c: usize| {
            let count = mix.column(c).iter().filter(|v| v.abs() > 1e-3).count();
            if count == 0 {
                1.0
            } else {
                (mix.column(c).norm_squared() / (count as f64 / 2.0)).sqrt()
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
        for (c, s) in scale.iter().enumerate() {
            mix.column_mut(c).scale_mut(1.0 / s);
            e.row_mut(c).scale_mut(*s);
        }
        // PX4 then zeroes the mixer's tiny entries (a hexa's side rotors do not pitch).
        mix.apply(|v| {
            if v.abs() < 1e-3 {
                *v = 0.0;
            }
        });
        let mut out = Allocation {
            count: n,
            mix: [[0.0; MAX_ROTORS]; 4],
            effectiveness: [[0.0; MAX_ROTORS]; 4],
            thrust_model_factor,
        };
        for axis in 0..4 {
            for i in 0..n {
                out.mix[axis][i] = mix[(i, axis)];
                out.effectiveness[axis][i] = e[(axis, i)];
            }
        }
        Some(out)
    }

    /// Number of motors.
    pub fn motor_count(&self) -> usize {
        self.count
    }

    /// Motor outputs for normalised `torque` (body FRD) and collective `thrust` in [0, 1],
    /// with airmode off: thrust is only ever reduced to make room for roll and pitch, which
    /// are scaled back before yaw is mixed in with its own headroom.
    pub fn allocate(&self, torque: &Vector3<f64>, thrust: f64) -> Allocated {
        // Fixed sizes for the shipped frames (as fast as the quad's own [f64; 4] code was);
        // any other count in MAX_ROTORS slots, whose zero entries change no sum and take part
        // in no desaturation.
        match self.count {
            4 => self.allocate_in::<4>(torque, thrust),
            6 => self.allocate_in::<6>(torque, thrust),
            8 => self.allocate_in::<8>(torque, thrust),
            _ => self.allocate_in::<MAX_ROTORS>(torque, thrust),
        }
    }

    fn allocate_in<const N: usize>(&self, torque: &Vector3<f64>, thrust: f64) -> Allocated {
        let control = [torque.x, torque.y, torque.z, -thrust];
        let column = |c: usize| -> [f64; N] { std::array::from_fn(|i| self.mix[c][i]) };
        let (roll, pitch, yaw, thrust_z) = (column(0), column(1), column(2), column(3));
        let mut sp: [f64; N] = std::array::from_fn(|i| {
            roll[i] * control[0] + pitch[i] * control[1] + thrust_z[i] * control[3]
        });
        let (min, max) = (0.0, 1.0);
        desaturate(&mut sp, &thrust_z, min, max, true);
        desaturate(&mut sp, &roll, min, max, false);
        desaturate(&mut sp, &pitch, min, max, false);
        for i in 0..N {
            sp[i] += yaw[i] * control[2];
        }
        let yaw_max = max + (max - 0.0) * MINIMUM_YAW_MARGIN;
        desaturate(&mut sp, &yaw, min, yaw_max, false);
        desaturate(&mut sp, &thrust_z, min, max, true);

        let clipped = sp.map(|u| u.clamp(0.0, 1.0));
        // What the clipped outputs produce, summed in motor order.
        let produced: [f64; 4] = std::array::from_fn(|axis| {
            let row = &self.effectiveness[axis];
            (1..N).fold(row[0] * clipped[0], |acc, i| row[i] * clipped[i] + acc)
        });
        let unallocated_torque = Vector3::new(
            control[0] - produced[0],
            control[1] - produced[1],
            control[2] - produced[2],
        );
        let mut motors = Outputs::zeros(self.count);
        for (m, &u) in motors.iter_mut().zip(clipped.iter()) {
            *m = thrust_model(u, self.thrust_model_factor);
        }
        Allocated {
            motors,
            unallocated_torque,
        }
    }
}

/// The pseudo-inverse (n × 4) of the 4 × n effectiveness `e`: its inverse for four rotors,
/// eᵀ (e eᵀ)⁻¹ for more (full row rank: every axis controllable). `None` when rank-deficient.
fn pseudo_inverse(e: &DMatrix<f64>) -> Option<DMatrix<f64>> {
    if e.ncols() == 4 {
        let inverse = Matrix4::from_iterator(e.iter().copied()).try_inverse()?;
        return Some(DMatrix::from_iterator(4, 4, inverse.iter().copied()));
    }
    let gram = Matrix4::from_iterator((e * e.transpose()).iter().copied());
    let inverse = DMatrix::from_iterator(4, 4, gram.try_inverse()?.iter().copied());
    let mix = e.transpose() * inverse;
    mix.iter().all(|v| v.is_finite()).then_some(mix)
}

/// PX4's sequential desaturation step: moves `sp` along `direction` by the gain that
/// brings it inside [min, max] as far as one gain can, then half of the remaining gain.
/// With `reduce_only`, a move that would add thrust (a negative gain along the thrust
/// column, whose entries are negative) is skipped.
fn desaturate<const N: usize>(
    sp: &mut [f64; N],
    direction: &[f64; N],
    min: f64,
    max: f64,
    reduce_only: bool,
) {
    let gain = desaturation_gain(sp, direction, min, max);
    if reduce_only && gain < 0.0 {
        return;
    }
    for i in 0..N {
        sp[i] += gain * direction[i];
    }
    let gain = 0.5 * desaturation_gain(sp, direction, min, max);
    for i in 0..N {
        sp[i] += gain * direction[i];
    }
}

/// PX4's `computeDesaturationGain`: the smallest and largest gains that bring each
/// saturated output to its bound, added.
fn desaturation_gain<const N: usize>(
    sp: &[f64; N],
    direction: &[f64; N],
    min: f64,
    max: f64,
) -> f64 {
    let (mut k_min, mut k_max) = (0.0f64, 0.0f64);
    for i in 0..N {
        if direction[i].abs() < DESATURATION_MIN_ENTRY {
            continue;
        }
        let bound = if sp[i] < min {
            min
        } else if sp[i] > max {
            max
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
    use crate::quadrotor::{Frame, QuadrotorParams};
    use crate::rate_loop::px4_rotors::{NONE_IRIS, px4_rotors};

    fn iris() -> Allocation {
        Allocation::new(&NONE_IRIS, 0.0).unwrap()
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
                    (a.mix[j][i] - v).abs() < 1e-6,
                    "mix[{i}][{j}] = {}",
                    a.mix[j][i]
                );
            }
        }
    }

    #[test]
    fn unsaturated_outputs_are_thrust_plus_mixed_torque() {
        let a = iris();
        let out = a.allocate(&Vector3::new(0.1, -0.05, 0.02), 0.5);
        let m = &a.mix;
        for (i, motor) in out.motors.iter().enumerate() {
            let u = 0.5 + m[0][i] * 0.1 + m[1][i] * -0.05 + m[2][i] * 0.02;
            assert!((motor - u).abs() < 1e-12, "{i}: {motor} vs {u}");
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
        let mut rotors = NONE_IRIS;
        rotors.iter_mut().for_each(|r| r.py = 0.0);
        assert!(Allocation::new(&rotors, 0.0).is_none());
        assert!(Allocation::new(&NONE_IRIS[..3], 0.0).is_none());
    }

    #[test]
    fn a_hexa_mixes_every_axis_and_its_side_rotors_do_not_pitch() {
        let p = QuadrotorParams::default();
        let a = Allocation::new(&px4_rotors(&Frame::named("hexa_x").unwrap(), &p), 0.0).unwrap();
        assert_eq!(a.motor_count(), 6);
        // PX4 6001's rotors 0 and 1 sit on the roll axis: no pitch entry, zeroed exactly.
        assert_eq!((a.mix[1][0], a.mix[1][1]), (0.0, 0.0));
        assert!(a.mix[3][..6].iter().all(|&t| (t + 1.0).abs() < 1e-12));
        // Unsaturated: the outputs produce exactly the torque asked for.
        let torque = Vector3::new(0.05, -0.04, 0.03);
        let out = a.allocate(&torque, 0.5);
        assert_eq!(out.motors.len(), 6);
        assert!(
            out.unallocated_torque.norm() < 1e-12,
            "{}",
            out.unallocated_torque
        );
        // Roll right (FRD +x): the left rotors (FRD y < 0) push harder.
        let right = a.allocate(&Vector3::new(0.1, 0.0, 0.0), 0.5);
        assert!(
            right.motors[1] > 0.5 && right.motors[0] < 0.5,
            "{:?}",
            right.motors
        );
    }
}
