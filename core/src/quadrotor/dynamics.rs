//! Equations of motion and their integration.
//!
//! World ENU, body FLU. Rotor i of PX4's quad-X sits at (±L/√2, ±L/√2): 0 front-right CCW,
//! 1 rear-left CCW, 2 front-left CW, 3 rear-right CW. Thrust T_i = k m_i² along body +z;
//! torques are r_i × F_i plus the spin reaction (a CCW rotor pushes the body toward −z).
//! Body rates are integrated as body rates: q̇ = ½ q ⊗ (0, ω), I ω̇ = τ − ω × I ω.
//! The ground pushes on four landing-gear feet ([`super::contact`]).

use super::contact::{CONTACT_LEN, Gear, STRETCH, gear_reach};
use super::params::QuadrotorParams;
use super::state::BodyState;
use nalgebra::{Quaternion, UnitQuaternion, Vector3};

/// Time derivative of a [`BodyState`] (same shape: velocity, acceleration, q̇, ω̇, ṁ, ṡ).
#[derive(Debug, Clone, Copy)]
pub struct Derivative {
    pub velocity: Vector3<f64>,
    pub acceleration: Vector3<f64>,
    pub attitude_rate: Quaternion<f64>,
    pub angular_acceleration: Vector3<f64>,
    pub motor_rates: [f64; 4],
    pub gear_stretch_rates: [[f64; 2]; 4],
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

/// The state derivative for motor commands `command` (in [0, 1]) and air velocity `wind`,
/// ground contact included: a pure function of the state.
pub fn derivatives(
    params: &QuadrotorParams,
    state: &BodyState,
    command: &[f64; 4],
    wind: &Vector3<f64>,
) -> Derivative {
    let d = derivative_vector(params, state, command, wind);
    let s = &d[STRETCH..];
    Derivative {
        velocity: Vector3::new(d[0], d[1], d[2]),
        acceleration: Vector3::new(d[3], d[4], d[5]),
        attitude_rate: Quaternion::new(d[6], d[7], d[8], d[9]),
        angular_acceleration: Vector3::new(d[10], d[11], d[12]),
        motor_rates: [d[13], d[14], d[15], d[16]],
        gear_stretch_rates: [[s[0], s[1]], [s[2], s[3]], [s[4], s[5]], [s[6], s[7]]],
    }
}

/// Length of the continuous state vector: 17 rigid-body and motor values, 8 bristles.
pub const STATE_LEN: usize = CONTACT_LEN;

/// The continuous state as one vector: position 0..3, velocity 3..6, quaternion w, x, y, z
/// 6..10, body rates 10..13, motors 13..17, bristles (x, y per foot) 17..25 — the vector the
/// stepper integrates while a foot may touch, and a Model-Exchange solver always.
pub fn state_vector(state: &BodyState) -> [f64; STATE_LEN] {
    flatten_contact(state)
}

/// Writes a [`state_vector`] back into `state`.
pub fn set_state_vector(x: &[f64; STATE_LEN], state: &mut BodyState) {
    unflatten_contact(x, state);
}

/// The time derivative of [`state_vector`]: the right-hand side RK4 integrates (with the
/// contact when the ground is on; the bristles do not move without it).
pub fn derivative_vector(
    params: &QuadrotorParams,
    state: &BodyState,
    command: &[f64; 4],
    wind: &Vector3<f64>,
) -> [f64; STATE_LEN] {
    let c = Coefficients::new(params);
    if params.ground_enabled {
        contact_rates(
            params,
            &c,
            &Gear::new(params),
            &flatten_contact(state),
            command,
            wind,
        )
    } else {
        let mut d = [0.0; CONTACT_LEN];
        d[..STRETCH].copy_from_slice(&rates(params, &c, &flatten(state), command, wind));
        d
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

/// Writes a flat state back into `s` (the bristles are left alone).
#[inline(always)]
fn unflatten_into(x: &Flat, s: &mut BodyState) {
    s.position = Vector3::new(x[0], x[1], x[2]);
    s.velocity = Vector3::new(x[3], x[4], x[5]);
    s.attitude = Quaternion::new(x[6], x[7], x[8], x[9]);
    s.body_rates = Vector3::new(x[10], x[11], x[12]);
    s.motors = [x[13], x[14], x[15], x[16]];
}

/// The state of a step that may touch the ground: [`Flat`] followed by the four bristles
/// (x, y each).
type ContactFlat = [f64; CONTACT_LEN];

#[inline(always)]
fn flatten_contact(s: &BodyState) -> ContactFlat {
    let mut x = [0.0; CONTACT_LEN];
    x[..STRETCH].copy_from_slice(&flatten(s));
    for (i, stretch) in s.gear_stretch.iter().enumerate() {
        x[STRETCH + 2 * i] = stretch[0];
        x[STRETCH + 2 * i + 1] = stretch[1];
    }
    x
}

#[inline(always)]
fn unflatten_contact(x: &ContactFlat, s: &mut BodyState) {
    let mut body = [0.0; STRETCH];
    body.copy_from_slice(&x[..STRETCH]);
    unflatten_into(&body, s);
    for (i, stretch) in s.gear_stretch.iter_mut().enumerate() {
        *stretch = [x[STRETCH + 2 * i], x[STRETCH + 2 * i + 1]];
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
    let (m0, m1, m2, m3) = (x[13], x[14], x[15], x[16]);
    // T_i = k m_i².
    let squares = [m0 * m0, m1 * m1, m2 * m2, m3 * m3];
    let [ax, ay, az] = acceleration(c, x, &squares, wind);
    let [alpha_x, alpha_y, alpha_z] = angular_acceleration(p, c, x, &squares);
    let [dqw, dqx, dqy, dqz] = attitude_rate(x);
    [
        x[3],
        x[4],
        x[5],
        ax,
        ay,
        az,
        dqw,
        dqx,
        dqy,
        dqz,
        alpha_x,
        alpha_y,
        alpha_z,
        (command[0] - m0) * c.inv_tau,
        (command[1] - m1) * c.inv_tau,
        (command[2] - m2) * c.inv_tau,
        (command[3] - m3) * c.inv_tau,
    ]
}

/// Acceleration (world) of a flat state with squared motor states `squares`: thrust along
/// body z, gravity, quadratic drag on the air-relative velocity.
#[inline(always)]
fn acceleration(c: &Coefficients, x: &Flat, squares: &[f64; 4], wind: &Vector3<f64>) -> [f64; 3] {
    let (vx, vy, vz) = (x[3], x[4], x[5]);
    let (qw, qx, qy, qz) = (x[6], x[7], x[8], x[9]);
    let [s0, s1, s2, s3] = *squares;
    let thrust = c.thrust_per_mass * ((s0 + s1) + (s2 + s3));
    let (bx, by, bz) = (
        2.0 * (qx * qz + qw * qy),
        2.0 * (qy * qz - qw * qx),
        1.0 - 2.0 * (qx * qx + qy * qy),
    );
    let (rx, ry, rz) = (vx - wind.x, vy - wind.y, vz - wind.z);
    let drag = -c.drag_per_mass * (rx * rx + ry * ry + rz * rz).sqrt();
    [
        bx * thrust + rx * drag,
        by * thrust + ry * drag,
        bz * thrust + rz * drag - c.gravity,
    ]
}

/// Angular acceleration (body) of a flat state with squared motor states `squares`: rotors,
/// damping, optional pendulum; Euler's equation with the gyroscopic term ω × Iω.
#[inline(always)]
fn angular_acceleration(
    p: &QuadrotorParams,
    c: &Coefficients,
    x: &Flat,
    squares: &[f64; 4],
) -> [f64; 3] {
    let (wx, wy, wz) = (x[10], x[11], x[12]);
    // The rotor sums are r × F and the spin reaction written out for the quad-X signs of
    // ROTOR_POSITION and ROTOR_SPIN (a test checks them against the tables).
    let [s0, s1, s2, s3] = *squares;
    let damping = p.angular_damping_linear
        + p.angular_damping_quadratic * (wx * wx + wy * wy + wz * wz).sqrt();
    let mut tx = c.roll_pitch * ((s1 + s2) - (s0 + s3)) - damping * wx;
    let mut ty = c.roll_pitch * ((s1 + s3) - (s0 + s2)) - damping * wy;
    let tz = c.yaw * ((s2 + s3) - (s0 + s1)) - damping * wz;
    if p.pendulum_coefficient != 0.0 {
        let attitude = UnitQuaternion::new_unchecked(Quaternion::new(x[6], x[7], x[8], x[9]));
        let (roll, pitch, _) = attitude.euler_angles();
        let restoring = p.pendulum_coefficient * p.mass * p.gravity;
        tx -= restoring * roll.sin();
        ty -= restoring * pitch.sin();
    }
    let (ix, iy, iz) = (c.inertia.x * wx, c.inertia.y * wy, c.inertia.z * wz);
    [
        (tx - (wy * iz - wz * iy)) * c.inv_inertia.x,
        (ty - (wz * ix - wx * iz)) * c.inv_inertia.y,
        (tz - (wx * iy - wy * ix)) * c.inv_inertia.z,
    ]
}

/// q̇ = ½ q ⊗ (0, ω) of a flat state.
#[inline(always)]
fn attitude_rate(x: &Flat) -> [f64; 4] {
    let (qw, qx, qy, qz) = (x[6], x[7], x[8], x[9]);
    let (hx, hy, hz) = (0.5 * x[10], 0.5 * x[11], 0.5 * x[12]);
    [
        -(qx * hx + qy * hy + qz * hz),
        qw * hx + qy * hz - qz * hy,
        qw * hy + qz * hx - qx * hz,
        qw * hz + qx * hy - qy * hx,
    ]
}

/// The equations of motion with the ground contact ([`super::contact`]).
#[inline(always)]
fn contact_rates(
    p: &QuadrotorParams,
    c: &Coefficients,
    gear: &Gear,
    x: &ContactFlat,
    command: &[f64; 4],
    wind: &Vector3<f64>,
) -> ContactFlat {
    let mut body = [0.0; STRETCH];
    body.copy_from_slice(&x[..STRETCH]);
    let mut d = [0.0; CONTACT_LEN];
    d[..STRETCH].copy_from_slice(&rates(p, c, &body, command, wind));
    gear.add_rates(x, &mut d);
    d
}

/// x + h·d, component-wise.
#[inline(always)]
fn advanced<const N: usize>(x: &[f64; N], d: &[f64; N], h: f64) -> [f64; N] {
    let mut out = *x;
    for (o, r) in out.iter_mut().zip(d) {
        *o += h * r;
    }
    out
}

/// One classical RK4 step of length `h` of ẋ = f(x); the quaternion (x[6..10]) is
/// renormalised afterwards.
#[inline(always)]
fn rk4<const N: usize>(x: &[f64; N], h: f64, f: impl Fn(&[f64; N]) -> [f64; N]) -> [f64; N] {
    let k1 = f(x);
    let k2 = f(&advanced(x, &k1, 0.5 * h));
    let k3 = f(&advanced(x, &k2, 0.5 * h));
    let k4 = f(&advanced(x, &k3, h));
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

/// Advances `state` by `dt` under constant `command` and `wind`, in ceil(dt / max_substep)
/// equal RK4 substeps — ceil(dt / min(max_substep, contact_substep)) when a foot may touch
/// the ground during the step.
pub fn integrate(
    params: &QuadrotorParams,
    state: &mut BodyState,
    command: &[f64; 4],
    wind: &Vector3<f64>,
    dt: f64,
) {
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
) {
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

/// Whether a foot may reach the ground within `dt`: the centre of mass may come closer to
/// the ground than the gear's reach. The bound on the fall is loose on purpose (twice the
/// largest acceleration's ½·a·dt², the speed it can gain included), so a step judged
/// airborne never touches; it costs a few operations and spares a flight the contact.
#[inline(always)]
fn may_touch(
    p: &QuadrotorParams,
    c: &Coefficients,
    s: &BodyState,
    wind: &Vector3<f64>,
    dt: f64,
) -> bool {
    let v = &s.velocity;
    let thrust_and_gravity = c.gravity + 4.0 * c.thrust_per_mass;
    let speed = v.x.abs() + v.y.abs() + v.z.abs() + thrust_and_gravity * dt;
    let air = speed + wind.x.abs() + wind.y.abs() + wind.z.abs();
    let acceleration = thrust_and_gravity + c.drag_per_mass * air * air;
    s.position.z - speed * dt - acceleration * dt * dt < gear_reach(p)
}

#[inline(always)]
fn integrate_portable(
    params: &QuadrotorParams,
    state: &mut BodyState,
    command: &[f64; 4],
    wind: &Vector3<f64>,
    dt: f64,
) {
    let c = Coefficients::new(params);
    if params.ground_enabled && may_touch(params, &c, state, wind, dt) {
        let gear = Gear::new(params);
        let substeps = substep_count(dt, params.max_substep.min(params.contact_substep));
        let h = if substeps == 1.0 { dt } else { dt / substeps };
        let mut x = flatten_contact(state);
        for _ in 0..substeps as u64 {
            x = rk4(&x, h, |y| {
                contact_rates(params, &c, &gear, y, command, wind)
            });
            gear.release_lifted_feet(&mut x);
        }
        unflatten_contact(&x, state);
        return;
    }
    let substeps = substep_count(dt, params.max_substep);
    let h = if substeps == 1.0 { dt } else { dt / substeps };
    let mut x = flatten(state);
    for _ in 0..substeps as u64 {
        x = rk4(&x, h, |y| rates(params, &c, y, command, wind));
    }
    unflatten_into(&x, state);
    // No foot reached the ground: every bristle is released.
    state.gear_stretch = [[0.0; 2]; 4];
}

/// Accelerations at the current state: linear (world, m/s², total force / mass, so 0 in a
/// hover or at rest on the ground) and angular (body, rad/s²), ground contact included.
pub fn accelerations(
    params: &QuadrotorParams,
    state: &BodyState,
    command: &[f64; 4],
    wind: &Vector3<f64>,
) -> (Vector3<f64>, Vector3<f64>) {
    let d = derivatives(params, state, command, wind);
    (d.acceleration, d.angular_acceleration)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::quadrotor::params::{ROTOR_POSITION, ROTOR_SPIN};

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
            integrate_portable(&p, &mut a, &command, &wind, dt);
            // SAFETY: AVX support was checked at the top of the test.
            unsafe { integrate_avx(&p, &mut b, &command, &wind, dt) };
        }
        let bits = |s: &BodyState| flatten_contact(s).map(f64::to_bits);
        assert_eq!(bits(&a), bits(&b));
        assert_ne!(bits(&a), bits(&start));
        // The contact path too: a tilted, sliding touchdown that bounces and settles.
        let touchdown = BodyState {
            velocity: Vector3::new(1.0, -0.5, -2.0),
            body_rates: Vector3::new(1.0, 0.5, -2.0),
            ..BodyState::at_rest(Vector3::new(0.0, 0.0, 0.3), 0.4, -0.2, 0.5, 0.0)
        };
        let (mut a, mut b) = (touchdown, touchdown);
        for _ in 0..200 {
            integrate_portable(&p, &mut a, &[0.1; 4], &wind, 0.01);
            // SAFETY: AVX support was checked at the top of the test.
            unsafe { integrate_avx(&p, &mut b, &[0.1; 4], &wind, 0.01) };
        }
        assert_eq!(bits(&a), bits(&b));
        assert!(a.position.z < 0.1, "{}", a.position.z);
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
