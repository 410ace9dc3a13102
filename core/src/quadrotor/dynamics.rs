//! Equations of motion and their integration.
//!
//! World ENU, body FLU. Rotor i of PX4's quad-X sits at (±L/√2, ±L/√2): 0 front-right CCW,
//! 1 rear-left CCW, 2 front-left CW, 3 rear-right CW. Thrust T_i = k m_i² along body +z;
//! torques are r_i × F_i plus the spin reaction (a CCW rotor pushes the body toward −z).
//! Body rates are integrated as body rates: q̇ = ½ q ⊗ (0, ω), I ω̇ = τ − ω × I ω.

use super::params::QuadrotorParams;
use super::state::BodyState;
use nalgebra::{Quaternion, UnitQuaternion, Vector3};

/// Spin of each rotor seen from above: −1 for CCW (reaction torque toward −z), +1 for CW.
pub const ROTOR_SPIN: [f64; 4] = [-1.0, -1.0, 1.0, 1.0];
/// Rotor position signs (forward, left), multiplied by L/√2.
pub const ROTOR_POSITION: [(f64, f64); 4] = [(1.0, -1.0), (-1.0, 1.0), (1.0, 1.0), (-1.0, -1.0)];

/// Time derivative of a [`BodyState`] (same shape: velocity, acceleration, q̇, ω̇, ṁ).
#[derive(Debug, Clone, Copy)]
pub struct Derivative {
    pub velocity: Vector3<f64>,
    pub acceleration: Vector3<f64>,
    pub attitude_rate: Quaternion<f64>,
    pub angular_acceleration: Vector3<f64>,
    pub motor_rates: [f64; 4],
}

/// Constants of the equations that depend only on the parameters, computed once per step.
#[derive(Debug, Clone, Copy)]
struct Coefficients {
    /// k·L/√2: roll/pitch torque per unit of squared motor state, N·m.
    roll_pitch: f64,
    /// k·c_yaw: yaw reaction torque per unit of squared motor state, N·m.
    yaw: f64,
    /// k/m: acceleration per unit of squared motor state, m/s².
    thrust_per_mass: f64,
    /// ½ρC_dA/m, 1/m.
    drag_per_mass: f64,
    gravity: f64,
    inertia: Vector3<f64>,
    inv_inertia: Vector3<f64>,
    inv_tau: f64,
}

impl Coefficients {
    fn new(p: &QuadrotorParams) -> Self {
        let lever = p.arm_length * std::f64::consts::FRAC_1_SQRT_2;
        Coefficients {
            roll_pitch: p.thrust_coefficient * lever,
            yaw: p.thrust_coefficient * p.yaw_torque_coefficient,
            thrust_per_mass: p.thrust_coefficient / p.mass,
            drag_per_mass: 0.5 * p.air_density * p.drag_area / p.mass,
            gravity: p.gravity,
            inertia: Vector3::new(p.inertia_xx, p.inertia_yy, p.inertia_zz),
            inv_inertia: Vector3::new(1.0 / p.inertia_xx, 1.0 / p.inertia_yy, 1.0 / p.inertia_zz),
            inv_tau: 1.0 / p.motor_time_constant,
        }
    }
}

/// The state derivative for motor commands `command` (in [0, 1]) and air velocity `wind`.
pub fn derivatives(
    params: &QuadrotorParams,
    state: &BodyState,
    command: &[f64; 4],
    wind: &Vector3<f64>,
) -> Derivative {
    let d = rates(
        params,
        &Coefficients::new(params),
        &flatten(state),
        command,
        wind,
    );
    Derivative {
        velocity: Vector3::new(d[0], d[1], d[2]),
        acceleration: Vector3::new(d[3], d[4], d[5]),
        attitude_rate: Quaternion::new(d[6], d[7], d[8], d[9]),
        angular_acceleration: Vector3::new(d[10], d[11], d[12]),
        motor_rates: [d[13], d[14], d[15], d[16]],
    }
}

/// A [`BodyState`] as one flat vector for the integrator (position 0..3, velocity 3..6,
/// quaternion w, x, y, z 6..10, body rates 10..13, motors 13..17): RK4's stage sums become
/// plain loops the compiler vectorises.
type Flat = [f64; 17];

#[inline(always)]
fn flatten(s: &BodyState) -> Flat {
    let (p, v, q, w, m) = (s.position, s.velocity, s.attitude, s.body_rates, s.motors);
    [
        p.x, p.y, p.z, v.x, v.y, v.z, q.w, q.i, q.j, q.k, w.x, w.y, w.z, m[0], m[1], m[2], m[3],
    ]
}

#[inline(always)]
fn unflatten(x: &Flat) -> BodyState {
    BodyState {
        position: Vector3::new(x[0], x[1], x[2]),
        velocity: Vector3::new(x[3], x[4], x[5]),
        attitude: Quaternion::new(x[6], x[7], x[8], x[9]),
        body_rates: Vector3::new(x[10], x[11], x[12]),
        motors: [x[13], x[14], x[15], x[16]],
    }
}

/// The equations of motion on a flat state (module docs).
#[inline(always)]
fn rates(
    p: &QuadrotorParams,
    c: &Coefficients,
    x: &Flat,
    command: &[f64; 4],
    wind: &Vector3<f64>,
) -> Flat {
    let (vx, vy, vz) = (x[3], x[4], x[5]);
    let (qw, qx, qy, qz) = (x[6], x[7], x[8], x[9]);
    let (wx, wy, wz) = (x[10], x[11], x[12]);
    let (m0, m1, m2, m3) = (x[13], x[14], x[15], x[16]);
    // T_i = k m_i²; the sums below are r × F and the spin reaction written out for the
    // quad-X signs of ROTOR_POSITION and ROTOR_SPIN (a test checks them against the tables).
    let (s0, s1, s2, s3) = (m0 * m0, m1 * m1, m2 * m2, m3 * m3);

    // Forces (world) per unit mass: thrust along body z, gravity, quadratic drag on the
    // air-relative velocity.
    let thrust = c.thrust_per_mass * ((s0 + s1) + (s2 + s3));
    let (bx, by, bz) = (
        2.0 * (qx * qz + qw * qy),
        2.0 * (qy * qz - qw * qx),
        1.0 - 2.0 * (qx * qx + qy * qy),
    );
    let (rx, ry, rz) = (vx - wind.x, vy - wind.y, vz - wind.z);
    let drag = -c.drag_per_mass * (rx * rx + ry * ry + rz * rz).sqrt();
    let ax = bx * thrust + rx * drag;
    let ay = by * thrust + ry * drag;
    let az = bz * thrust + rz * drag - c.gravity;

    // Torques (body): rotors, damping, optional pendulum; Euler's equation with the
    // gyroscopic term ω × Iω.
    let damping = p.angular_damping_linear
        + p.angular_damping_quadratic * (wx * wx + wy * wy + wz * wz).sqrt();
    let mut tx = c.roll_pitch * ((s1 + s2) - (s0 + s3)) - damping * wx;
    let mut ty = c.roll_pitch * ((s1 + s3) - (s0 + s2)) - damping * wy;
    let tz = c.yaw * ((s2 + s3) - (s0 + s1)) - damping * wz;
    if p.pendulum_coefficient != 0.0 {
        let attitude = UnitQuaternion::new_unchecked(Quaternion::new(qw, qx, qy, qz));
        let (roll, pitch, _) = attitude.euler_angles();
        let restoring = p.pendulum_coefficient * p.mass * p.gravity;
        tx -= restoring * roll.sin();
        ty -= restoring * pitch.sin();
    }
    let (ix, iy, iz) = (c.inertia.x * wx, c.inertia.y * wy, c.inertia.z * wz);
    let alpha_x = (tx - (wy * iz - wz * iy)) * c.inv_inertia.x;
    let alpha_y = (ty - (wz * ix - wx * iz)) * c.inv_inertia.y;
    let alpha_z = (tz - (wx * iy - wy * ix)) * c.inv_inertia.z;

    // q̇ = ½ q ⊗ (0, ω).
    let (hx, hy, hz) = (0.5 * wx, 0.5 * wy, 0.5 * wz);
    [
        vx,
        vy,
        vz,
        ax,
        ay,
        az,
        -(qx * hx + qy * hy + qz * hz),
        qw * hx + qy * hz - qz * hy,
        qw * hy + qz * hx - qx * hz,
        qw * hz + qx * hy - qy * hx,
        alpha_x,
        alpha_y,
        alpha_z,
        (command[0] - m0) * c.inv_tau,
        (command[1] - m1) * c.inv_tau,
        (command[2] - m2) * c.inv_tau,
        (command[3] - m3) * c.inv_tau,
    ]
}

/// x + h·d, component-wise.
#[inline(always)]
fn advanced(x: &Flat, d: &Flat, h: f64) -> Flat {
    let mut out = *x;
    for (o, r) in out.iter_mut().zip(d) {
        *o += h * r;
    }
    out
}

/// One classical RK4 step of length `h`; the quaternion is renormalised afterwards.
#[inline(always)]
fn rk4(
    p: &QuadrotorParams,
    c: &Coefficients,
    x: &Flat,
    command: &[f64; 4],
    wind: &Vector3<f64>,
    h: f64,
) -> Flat {
    let k1 = rates(p, c, x, command, wind);
    let k2 = rates(p, c, &advanced(x, &k1, 0.5 * h), command, wind);
    let k3 = rates(p, c, &advanced(x, &k2, 0.5 * h), command, wind);
    let k4 = rates(p, c, &advanced(x, &k3, h), command, wind);
    let sixth = h / 6.0;
    let mut out = *x;
    for i in 0..out.len() {
        out[i] += (k1[i] + 2.0 * (k2[i] + k3[i]) + k4[i]) * sixth;
    }
    // Back onto the unit sphere. From a unit quaternion n² is 1 ± ~1e-12 after a step, and
    // one Newton step for 1/√n² is exact to rounding with no square root or division on the
    // critical path; a state that was set off the sphere gets the exact division.
    let n2 = out[6] * out[6] + out[7] * out[7] + out[8] * out[8] + out[9] * out[9];
    let scale = if (n2 - 1.0).abs() < 1e-6 {
        1.5 - 0.5 * n2
    } else {
        n2.sqrt().recip()
    };
    for q in &mut out[6..10] {
        *q *= scale;
    }
    out
}

/// Ground plane z = 0: an inelastic, non-sliding contact. A vehicle that reaches it stops
/// sinking, stops sliding and stops turning; it lifts off as soon as thrust exceeds weight.
#[inline(always)]
fn apply_ground(s: &mut BodyState) -> bool {
    if s.position.z > 0.0 {
        return false;
    }
    s.position.z = 0.0;
    s.velocity = Vector3::new(0.0, 0.0, s.velocity.z.max(0.0));
    s.body_rates = Vector3::zeros();
    true
}

/// Advances `state` by `dt` under constant `command` and `wind`, in ceil(dt / max_substep)
/// equal RK4 substeps. Returns whether the vehicle ends the step on the ground.
pub fn integrate(
    params: &QuadrotorParams,
    state: &mut BodyState,
    command: &[f64; 4],
    wind: &Vector3<f64>,
    dt: f64,
) -> bool {
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx") {
        // SAFETY: the CPU supports AVX, checked just above.
        return unsafe { integrate_avx(params, state, command, wind, dt) };
    }
    integrate_portable(params, state, command, wind, dt)
}

/// [`integrate`] compiled with AVX's three-operand instructions: a third fewer instructions
/// (no register copies) for the same IEEE operations in the same order — no fused
/// multiply-add, no reassociation — so both paths give the same bits (a test checks).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx")]
fn integrate_avx(
    params: &QuadrotorParams,
    state: &mut BodyState,
    command: &[f64; 4],
    wind: &Vector3<f64>,
    dt: f64,
) -> bool {
    integrate_portable(params, state, command, wind, dt)
}

/// ceil(dt / max_substep), at least 1. A ratio within 1e-9 (relative) above a whole number
/// counts as that number: 0.07 / 0.01 is 7.000000000000001 in floating point, and 7
/// substeps, not 8, is what the parameters say.
pub fn substep_count(dt: f64, max_substep: f64) -> f64 {
    if dt <= max_substep {
        return 1.0;
    }
    let ratio = dt / max_substep;
    (ratio - ratio * 1e-9).ceil().max(1.0)
}

#[inline(always)]
fn integrate_portable(
    params: &QuadrotorParams,
    state: &mut BodyState,
    command: &[f64; 4],
    wind: &Vector3<f64>,
    dt: f64,
) -> bool {
    let c = Coefficients::new(params);
    let substeps = substep_count(dt, params.max_substep);
    let h = if substeps == 1.0 { dt } else { dt / substeps };
    let mut grounded = false;
    for _ in 0..substeps as u64 {
        *state = unflatten(&rk4(params, &c, &flatten(state), command, wind, h));
        grounded = params.ground_enabled && apply_ground(state);
    }
    grounded
}

/// Accelerations at the current state: linear (world, m/s², total force / mass, so 0 in a
/// hover) and angular (body, rad/s²). On the ground the contact force is included.
pub fn accelerations(
    params: &QuadrotorParams,
    state: &BodyState,
    command: &[f64; 4],
    wind: &Vector3<f64>,
    grounded: bool,
) -> (Vector3<f64>, Vector3<f64>) {
    let d = derivatives(params, state, command, wind);
    if grounded {
        (
            Vector3::new(0.0, 0.0, d.acceleration.z.max(0.0)),
            Vector3::zeros(),
        )
    } else {
        (d.acceleration, d.angular_acceleration)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The written-out torque sums in `rates` against r × F and the spin reaction summed
    /// over the rotor tables, for unequal motor states.
    #[test]
    fn torque_sums_match_the_rotor_tables() {
        let p = QuadrotorParams::default();
        let c = Coefficients::new(&p);
        let motors = [0.3, 0.55, 0.7, 0.45];
        let mut state = BodyState::at_rest(Vector3::zeros(), 0.0, 0.0, 0.0, 0.0);
        state.motors = motors;
        let d = rates(&p, &c, &flatten(&state), &motors, &Vector3::zeros());
        let lever = p.arm_length * std::f64::consts::FRAC_1_SQRT_2;
        let mut expected = Vector3::zeros();
        for i in 0..4 {
            let thrust = p.thrust_coefficient * motors[i] * motors[i];
            let (fwd, left) = ROTOR_POSITION[i];
            let r = Vector3::new(fwd * lever, left * lever, 0.0);
            expected += r.cross(&Vector3::new(0.0, 0.0, thrust));
            expected.z += ROTOR_SPIN[i] * p.yaw_torque_coefficient * thrust;
        }
        let torque = Vector3::new(
            d[10] * p.inertia_xx,
            d[11] * p.inertia_yy,
            d[12] * p.inertia_zz,
        );
        assert!((torque - expected).norm() < 1e-12, "{torque} vs {expected}");
        assert!(expected.x.abs() > 1e-3 && expected.y.abs() > 1e-3 && expected.z.abs() > 1e-4);
    }

    /// The AVX build of the integrator and the portable one give the same bits: same IEEE
    /// operations in the same order, only the instruction encoding differs.
    #[cfg(target_arch = "x86_64")]
    #[test]
    fn avx_and_portable_integrators_agree_bit_for_bit() {
        if !std::arch::is_x86_feature_detected!("avx") {
            return;
        }
        let p = QuadrotorParams {
            pendulum_coefficient: 0.3,
            ..QuadrotorParams::default()
        };
        let start = BodyState {
            velocity: Vector3::new(1.5, -0.7, 0.3),
            body_rates: Vector3::new(2.0, -1.0, 3.0),
            ..BodyState::at_rest(Vector3::new(0.3, 0.2, 2.0), 0.3, -0.2, 1.0, 0.4)
        };
        let (mut a, mut b) = (start, start);
        let wind = Vector3::new(3.0, -1.0, 0.2);
        for i in 0..500 {
            let m = 0.3 + 0.4 * ((i % 7) as f64 / 7.0);
            let command = [m, 0.9 - m, 0.5, 0.45];
            let dt = if i % 3 == 0 { 0.025 } else { 0.01 };
            let ga = integrate_portable(&p, &mut a, &command, &wind, dt);
            // SAFETY: AVX support was checked at the top of the test.
            let gb = unsafe { integrate_avx(&p, &mut b, &command, &wind, dt) };
            assert_eq!(ga, gb);
        }
        let bits = |s: &BodyState| flatten(s).map(f64::to_bits);
        assert_eq!(bits(&a), bits(&b));
        assert_ne!(bits(&a), bits(&start));
    }

    /// Regression: 0.07 s at 0.01 s substeps took 8 substeps (0.07 / 0.01 = 7.000000000000001).
    #[test]
    fn substep_count_ignores_rounding_noise_in_the_ratio() {
        assert_eq!(substep_count(0.07, 0.01), 7.0);
        assert_eq!(substep_count(0.03, 0.01), 3.0);
        assert_eq!(substep_count(0.01, 0.01), 1.0);
        assert_eq!(substep_count(0.005, 0.01), 1.0);
        assert_eq!(substep_count(0.0701, 0.01), 8.0);
        assert_eq!(substep_count(1.0, 0.3), 4.0);
    }

    /// The cheap renormalisation keeps a unit quaternion on the sphere over a long flight,
    /// and a quaternion set off the sphere is brought back onto it in one step.
    #[test]
    fn attitude_stays_a_unit_quaternion() {
        let p = QuadrotorParams {
            wind_enabled: false,
            ground_enabled: false,
            ..QuadrotorParams::default()
        };
        let mut s = BodyState::at_rest(Vector3::new(0.0, 0.0, 100.0), 0.2, 0.1, 0.3, 0.5);
        s.body_rates = Vector3::new(3.0, -2.0, 5.0);
        for _ in 0..100_000 {
            integrate(&p, &mut s, &[0.5, 0.45, 0.55, 0.5], &Vector3::zeros(), 0.01);
        }
        assert!(
            (s.attitude.norm() - 1.0).abs() < 1e-14,
            "{}",
            s.attitude.norm()
        );
        s.attitude *= 3.0;
        integrate(&p, &mut s, &[0.5; 4], &Vector3::zeros(), 0.01);
        assert!(
            (s.attitude.norm() - 1.0).abs() < 1e-14,
            "{}",
            s.attitude.norm()
        );
    }
}
