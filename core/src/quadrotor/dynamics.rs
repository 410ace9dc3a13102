//! Equations of motion and their integration.
//!
//! World ENU, body FLU. The rotors are the frame's table ([`super::frame`]): rotor i at
//! L·(xᵢ, yᵢ) pushes T_i = kᵢ mᵢ² along body +z; torques are r_i × F_i plus the spin
//! reaction (a CCW rotor pushes the body toward −z), summed as [`super::mixing`] groups them.
//! Body rates are integrated as body rates: q̇ = ½ q ⊗ (0, ω), I ω̇ = τ − ω × I ω.
//! The ground pushes on four landing-gear feet ([`super::contact`]).
//!
//! The integrator works on flat arrays of a length fixed at compile time: 13 rigid-body
//! values, then the motors (4 for a quad; a frame of n rotors runs in the next size up of 4,
//! 6, 8 or 12, its unused motors held at zero), then the 8 bristles when a foot may touch. The
//! quad X runs exactly the operations it ran before frames existed.

use super::contact::{BRISTLES, Gear, gear_reach};
use super::frame::{Frame, MAX_ROTORS};
use super::mixing::Mixing;
use super::params::QuadrotorParams;
use super::state::{BodyState, Motors};
use nalgebra::{Quaternion, UnitQuaternion, Vector3};

/// Rigid-body values at the head of every flat state: position 0..3, velocity 3..6,
/// quaternion w, x, y, z 6..10, body rates 10..13.
pub(crate) const BODY: usize = 13;

/// Time derivative of a [`BodyState`] (same shape: velocity, acceleration, q̇, ω̇, ṁ, ṡ).
#[derive(Debug, Clone, Copy)]
pub struct Derivative {
    pub velocity: Vector3<f64>,
    pub acceleration: Vector3<f64>,
    pub attitude_rate: Quaternion<f64>,
    pub angular_acceleration: Vector3<f64>,
    pub motor_rates: Motors,
    pub gear_stretch_rates: [[f64; 2]; 4],
}

impl Derivative {
    /// In the layout of [`state_vector`]: the derivative of each continuous state.
    pub fn to_vec(&self) -> Vec<f64> {
        let mut d = Vec::with_capacity(state_len(self.motor_rates.len()));
        d.extend(self.velocity.iter().chain(self.acceleration.iter()));
        let q = &self.attitude_rate;
        d.extend([q.w, q.i, q.j, q.k]);
        d.extend(self.angular_acceleration.iter());
        d.extend(self.motor_rates.iter());
        d.extend(self.gear_stretch_rates.iter().flatten());
        d
    }
}

/// Constants of the equations that depend only on the parameters and the frame: computed
/// once per step by [`integrate`], kept by a vehicle until its parameters change
/// ([`ConstantsCache`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Constants {
    /// Per thrust term: kᵢ/m, m/s² per unit of squared motor state.
    thrust: [f64; MAX_ROTORS],
    /// Per roll term: kᵢ·L·|yᵢ|, N·m.
    roll: [f64; MAX_ROTORS],
    /// Per pitch term: kᵢ·L·|xᵢ|, N·m.
    pitch: [f64; MAX_ROTORS],
    /// Per yaw term: kᵢ·cᵢ, N·m.
    yaw: [f64; MAX_ROTORS],
    /// Σ kᵢ/m: the acceleration of every motor at full state, m/s².
    full_thrust_per_mass: f64,
    /// ½ρC_dA/m, 1/m.
    drag_per_mass: f64,
    gravity: f64,
    inertia: Vector3<f64>,
    inv_inertia: Vector3<f64>,
    /// 1/τᵢ per motor, 1/s (zero for an unused slot).
    inv_tau: [f64; MAX_ROTORS],
}

/// The frame's sums and the constants, as the equations read them.
#[derive(Debug, Clone, Copy)]
struct Coefficients<'f> {
    mixing: &'f Mixing,
    k: &'f Constants,
}

impl std::ops::Deref for Coefficients<'_> {
    type Target = Constants;
    fn deref(&self) -> &Constants {
        self.k
    }
}

/// The parameters [`Constants`] depend on, by their bits (the frame is fixed per vehicle).
fn constants_key(p: &QuadrotorParams) -> [u64; 11] {
    [
        p.mass,
        p.arm_length,
        p.inertia_xx,
        p.inertia_yy,
        p.inertia_zz,
        p.gravity,
        p.thrust_coefficient,
        p.motor_time_constant,
        p.yaw_torque_coefficient,
        p.air_density,
        p.drag_area,
    ]
    .map(f64::to_bits)
}

/// A vehicle's [`Constants`], recomputed only when a parameter they depend on changed. Not
/// part of the vehicle's state: equal to any other, skipped by serde, empty after a restore.
#[derive(Debug, Clone, Default)]
pub struct ConstantsCache(Option<([u64; 11], Constants)>);

impl PartialEq for ConstantsCache {
    fn eq(&self, _: &Self) -> bool {
        true
    }
}

impl ConstantsCache {
    /// The constants of `params` on `frame` (the frame must be the one the cache has served
    /// so far: a vehicle given a new frame starts a new cache).
    pub fn get(&mut self, params: &QuadrotorParams, frame: &Frame) -> &Constants {
        let key = constants_key(params);
        match self.0 {
            Some((k, _)) if k == key => {}
            _ => self.0 = Some((key, Constants::new(params, frame))),
        }
        match &self.0 {
            Some((_, c)) => c,
            None => unreachable!("filled just above"),
        }
    }
}

impl Constants {
    /// The constants of `params` on `frame`.
    pub fn new(p: &QuadrotorParams, frame: &Frame) -> Self {
        let rotors = frame.rotors();
        let mixing = frame.mixing();
        let k = |i: u8| {
            rotors[i as usize]
                .thrust_coefficient
                .unwrap_or(p.thrust_coefficient)
        };
        let mut c = Constants {
            thrust: [0.0; MAX_ROTORS],
            roll: [0.0; MAX_ROTORS],
            pitch: [0.0; MAX_ROTORS],
            yaw: [0.0; MAX_ROTORS],
            full_thrust_per_mass: 0.0,
            drag_per_mass: 0.5 * p.air_density * p.drag_area / p.mass,
            gravity: p.gravity,
            inertia: Vector3::new(p.inertia_xx, p.inertia_yy, p.inertia_zz),
            inv_inertia: Vector3::new(1.0 / p.inertia_xx, 1.0 / p.inertia_yy, 1.0 / p.inertia_zz),
            inv_tau: [0.0; MAX_ROTORS],
        };
        for (t, term) in mixing.thrust.terms().iter().enumerate() {
            c.thrust[t] = k(term.representative) / p.mass;
            c.full_thrust_per_mass += term.len() as f64 * c.thrust[t];
        }
        for (t, term) in mixing.roll.terms().iter().enumerate() {
            let r = &rotors[term.representative as usize];
            c.roll[t] = k(term.representative) * (p.arm_length * r.y.abs());
        }
        for (t, term) in mixing.pitch.terms().iter().enumerate() {
            let r = &rotors[term.representative as usize];
            c.pitch[t] = k(term.representative) * (p.arm_length * r.x.abs());
        }
        for (t, term) in mixing.yaw.terms().iter().enumerate() {
            let r = &rotors[term.representative as usize];
            c.yaw[t] =
                k(term.representative) * r.torque_coefficient.unwrap_or(p.yaw_torque_coefficient);
        }
        for (i, r) in rotors.iter().enumerate() {
            c.inv_tau[i] = 1.0 / r.time_constant.unwrap_or(p.motor_time_constant);
        }
        c
    }
}

/// Calls `$f::<L, C>(args)` with the flat lengths of a frame of `$rotors` rotors: L = 13 +
/// motor slots (4, 6, 8 or 12), C = L + 8 bristles.
macro_rules! by_size {
    ($rotors:expr, $f:ident($($arg:expr),*)) => {
        match $rotors {
            ..=4 => $f::<17, 25>($($arg),*),
            5..=6 => $f::<19, 27>($($arg),*),
            7..=8 => $f::<21, 29>($($arg),*),
            _ => $f::<25, 33>($($arg),*),
        }
    };
}

/// What acts on a vehicle from outside, held over a step: the wind, and a push (an
/// acceleration: force / mass) from other bodies — a neighbour's contact or downwash in a
/// world. A vehicle alone has no push, and then none of its arithmetic is done.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Surroundings {
    /// Air velocity, world ENU, m/s.
    pub wind: Vector3<f64>,
    /// Acceleration from outside forces, world ENU, m/s²; `None` when nothing pushes.
    pub push: Option<Vector3<f64>>,
}

impl From<Vector3<f64>> for Surroundings {
    fn from(wind: Vector3<f64>) -> Self {
        Surroundings { wind, push: None }
    }
}

/// The state derivative for motor commands `command` (in [0, 1]) and surroundings `air`,
/// ground contact included: a pure function of the state.
pub fn derivatives(
    params: &QuadrotorParams,
    frame: &Frame,
    state: &BodyState,
    command: &Motors,
    air: &Surroundings,
) -> Derivative {
    by_size!(
        frame.rotor_count(),
        derivatives_sized(params, frame, state, command, air)
    )
}

fn derivatives_sized<const L: usize, const C: usize>(
    params: &QuadrotorParams,
    frame: &Frame,
    state: &BodyState,
    command: &Motors,
    air: &Surroundings,
) -> Derivative {
    let d = derivative_sized::<L, C>(params, frame, state, command, air);
    let n = frame.rotor_count();
    let s = &d[L..];
    let mut motor_rates = Motors::zeros(n);
    motor_rates.copy_from_slice(&d[BODY..BODY + n]);
    Derivative {
        velocity: Vector3::new(d[0], d[1], d[2]),
        acceleration: Vector3::new(d[3], d[4], d[5]),
        attitude_rate: Quaternion::new(d[6], d[7], d[8], d[9]),
        angular_acceleration: Vector3::new(d[10], d[11], d[12]),
        motor_rates,
        gear_stretch_rates: [[s[0], s[1]], [s[2], s[3]], [s[4], s[5]], [s[6], s[7]]],
    }
}

/// Length of the continuous state vector of a frame of `rotors` rotors: 13 rigid-body
/// values, one per motor, 8 bristles (25 for a quad).
pub fn state_len(rotors: usize) -> usize {
    BODY + rotors + BRISTLES
}

/// The continuous state as one vector: position 0..3, velocity 3..6, quaternion w, x, y, z
/// 6..10, body rates 10..13, the n motors 13..13+n, bristles (x, y per foot) after them — the
/// vector the stepper integrates while a foot may touch, and a Model-Exchange solver always.
pub fn state_vector(state: &BodyState) -> Vec<f64> {
    let mut x = Vec::with_capacity(state_len(state.motors.len()));
    x.extend_from_slice(&body_values(state));
    x.extend_from_slice(&state.motors);
    x.extend(state.gear_stretch.iter().flatten());
    x
}

/// Writes a [`state_vector`] (of the state's own length) back into `state`.
pub fn set_state_vector(x: &[f64], state: &mut BodyState) {
    let n = state.motors.len();
    debug_assert_eq!(x.len(), state_len(n));
    set_body_values(&x[..BODY], state);
    state.motors.copy_from_slice(&x[BODY..BODY + n]);
    for (i, stretch) in state.gear_stretch.iter_mut().enumerate() {
        *stretch = [x[BODY + n + 2 * i], x[BODY + n + 2 * i + 1]];
    }
}

/// The time derivative of [`state_vector`]: the right-hand side RK4 integrates (with the
/// contact when the ground is on; the bristles do not move without it).
pub fn derivative_vector(
    params: &QuadrotorParams,
    frame: &Frame,
    state: &BodyState,
    command: &Motors,
    air: &Surroundings,
) -> Vec<f64> {
    derivatives(params, frame, state, command, air).to_vec()
}

fn derivative_sized<const L: usize, const C: usize>(
    params: &QuadrotorParams,
    frame: &Frame,
    state: &BodyState,
    command: &Motors,
    air: &Surroundings,
) -> [f64; C] {
    let k = Constants::new(params, frame);
    let c = Coefficients {
        mixing: frame.mixing(),
        k: &k,
    };
    let command = command.padded();
    if params.ground_enabled {
        contact_rates::<L, C>(
            params,
            &c,
            &Gear::new(params),
            &flatten_contact::<L, C>(state),
            command,
            air,
        )
    } else {
        let mut d = [0.0; C];
        d[..L].copy_from_slice(&rates::<L>(params, &c, &flatten::<L>(state), command, air));
        d
    }
}

/// The 13 rigid-body values of a state, in flat order.
#[inline(always)]
fn body_values(s: &BodyState) -> [f64; BODY] {
    let (p, v, q, w) = (s.position, s.velocity, s.attitude, s.body_rates);
    [
        p.x, p.y, p.z, v.x, v.y, v.z, q.w, q.i, q.j, q.k, w.x, w.y, w.z,
    ]
}

#[inline(always)]
fn set_body_values(x: &[f64], s: &mut BodyState) {
    s.position = Vector3::new(x[0], x[1], x[2]);
    s.velocity = Vector3::new(x[3], x[4], x[5]);
    s.attitude = Quaternion::new(x[6], x[7], x[8], x[9]);
    s.body_rates = Vector3::new(x[10], x[11], x[12]);
}

/// A [`BodyState`] as one flat vector of length `L` for the integrator (the rigid body, then
/// L − 13 motor slots): RK4's stage sums become plain loops the compiler vectorises.
#[inline(always)]
fn flatten<const L: usize>(s: &BodyState) -> [f64; L] {
    let mut x = [0.0; L];
    x[..BODY].copy_from_slice(&body_values(s));
    x[BODY..].copy_from_slice(&s.motors.padded()[..L - BODY]);
    x
}

/// Writes a flat state back into `s` (the bristles are left alone).
#[inline(always)]
fn unflatten_into<const L: usize>(x: &[f64; L], s: &mut BodyState) {
    set_body_values(&x[..BODY], s);
    s.motors.padded_mut()[..L - BODY].copy_from_slice(&x[BODY..]);
}

/// The state of a step that may touch the ground: the flat state (L values) followed by the
/// four bristles (x, y each): C = L + 8.
#[inline(always)]
fn flatten_contact<const L: usize, const C: usize>(s: &BodyState) -> [f64; C] {
    let mut x = [0.0; C];
    x[..L].copy_from_slice(&flatten::<L>(s));
    for (i, stretch) in s.gear_stretch.iter().enumerate() {
        x[L + 2 * i] = stretch[0];
        x[L + 2 * i + 1] = stretch[1];
    }
    x
}

#[inline(always)]
fn unflatten_contact<const L: usize, const C: usize>(x: &[f64; C], s: &mut BodyState) {
    let mut body = [0.0; L];
    body.copy_from_slice(&x[..L]);
    unflatten_into(&body, s);
    for (i, stretch) in s.gear_stretch.iter_mut().enumerate() {
        *stretch = [x[L + 2 * i], x[L + 2 * i + 1]];
    }
}

/// The equations of motion on a flat state (module docs).
#[inline(always)]
fn rates<const L: usize>(
    p: &QuadrotorParams,
    c: &Coefficients,
    x: &[f64; L],
    command: &[f64; MAX_ROTORS],
    air: &Surroundings,
) -> [f64; L] {
    let (thrust, torque) = if L == BODY + 4 && c.mixing.quad_x_terms {
        quad_x_sums(c, x)
    } else {
        rotor_sums(c, x)
    };
    let [ax, ay, az] = acceleration(c, x, thrust, air);
    let [alpha_x, alpha_y, alpha_z] = angular_acceleration(p, c, x, torque);
    let [dqw, dqx, dqy, dqz] = attitude_rate(x);
    let mut d = [0.0; L];
    d[..BODY].copy_from_slice(&[
        x[3], x[4], x[5], ax, ay, az, dqw, dqx, dqy, dqz, alpha_x, alpha_y, alpha_z,
    ]);
    for i in 0..L - BODY {
        d[BODY + i] = (command[i] - x[BODY + i]) * c.inv_tau[i];
    }
    d
}

/// The thrust (acceleration along body z) and the rotors' torque (body) of a flat state: the
/// frame's grouped sums of T_i = k m_i² ([`super::mixing`]).
#[inline(always)]
fn rotor_sums<const L: usize>(c: &Coefficients, x: &[f64; L]) -> (f64, [f64; 3]) {
    let mut squares = [0.0; MAX_ROTORS];
    for i in 0..L - BODY {
        squares[i] = x[BODY + i] * x[BODY + i];
    }
    let m = c.mixing;
    let torque = [
        m.roll.sum(&c.roll, &squares),
        m.pitch.sum(&c.pitch, &squares),
        m.yaw.sum(&c.yaw, &squares),
    ];
    (m.thrust.sum(&c.thrust, &squares), torque)
}

/// [`rotor_sums`] of a frame with the quad X's terms, written out: the same operations in
/// the same order, kept in registers.
#[inline(always)]
fn quad_x_sums<const L: usize>(c: &Coefficients, x: &[f64; L]) -> (f64, [f64; 3]) {
    let (m0, m1, m2, m3) = (x[BODY], x[BODY + 1], x[BODY + 2], x[BODY + 3]);
    let (s0, s1, s2, s3) = (m0 * m0, m1 * m1, m2 * m2, m3 * m3);
    let torque = [
        c.roll[0] * ((s1 + s2) - (s0 + s3)),
        c.pitch[0] * ((s1 + s3) - (s0 + s2)),
        c.yaw[0] * ((s2 + s3) - (s0 + s1)),
    ];
    (c.thrust[0] * ((s0 + s1) + (s2 + s3)), torque)
}

/// Acceleration (world) of a flat state with `thrust` (the thrust sum: acceleration along
/// body z): thrust, gravity, quadratic drag on the air-relative velocity, and the push from
/// outside when there is one.
#[inline(always)]
fn acceleration(c: &Coefficients, x: &[f64], thrust: f64, air: &Surroundings) -> [f64; 3] {
    let wind = &air.wind;
    let (vx, vy, vz) = (x[3], x[4], x[5]);
    let (qw, qx, qy, qz) = (x[6], x[7], x[8], x[9]);
    let (bx, by, bz) = (
        2.0 * (qx * qz + qw * qy),
        2.0 * (qy * qz - qw * qx),
        1.0 - 2.0 * (qx * qx + qy * qy),
    );
    let (rx, ry, rz) = (vx - wind.x, vy - wind.y, vz - wind.z);
    let drag = -c.drag_per_mass * (rx * rx + ry * ry + rz * rz).sqrt();
    let mut a = [
        bx * thrust + rx * drag,
        by * thrust + ry * drag,
        bz * thrust + rz * drag - c.gravity,
    ];
    // Added only when present: a vehicle alone runs exactly the operations it always ran.
    if let Some(push) = &air.push {
        a[0] += push.x;
        a[1] += push.y;
        a[2] += push.z;
    }
    a
}

/// Angular acceleration (body) of a flat state with the rotors' `torque` (body, N·m):
/// rotors, damping, optional pendulum; Euler's equation with the gyroscopic term ω × Iω.
#[inline(always)]
fn angular_acceleration(
    p: &QuadrotorParams,
    c: &Coefficients,
    x: &[f64],
    torque: [f64; 3],
) -> [f64; 3] {
    let (wx, wy, wz) = (x[10], x[11], x[12]);
    let damping = p.angular_damping_linear
        + p.angular_damping_quadratic * (wx * wx + wy * wy + wz * wz).sqrt();
    let mut tx = torque[0] - damping * wx;
    let mut ty = torque[1] - damping * wy;
    let tz = torque[2] - damping * wz;
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
fn attitude_rate(x: &[f64]) -> [f64; 4] {
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
fn contact_rates<const L: usize, const C: usize>(
    p: &QuadrotorParams,
    c: &Coefficients,
    gear: &Gear,
    x: &[f64; C],
    command: &[f64; MAX_ROTORS],
    air: &Surroundings,
) -> [f64; C] {
    let mut body = [0.0; L];
    body.copy_from_slice(&x[..L]);
    let mut d = [0.0; C];
    d[..L].copy_from_slice(&rates::<L>(p, c, &body, command, air));
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

/// Advances `state` by `dt` under constant `command` and surroundings `air`, in ceil(dt / max_substep)
/// equal RK4 substeps — ceil(dt / min(max_substep, contact_substep)) when a foot may touch
/// the ground during the step.
pub fn integrate(
    params: &QuadrotorParams,
    frame: &Frame,
    state: &mut BodyState,
    command: &Motors,
    air: &Surroundings,
    dt: f64,
) {
    let k = Constants::new(params, frame);
    integrate_with(params, frame, &k, state, command, air, dt);
}

/// [`integrate`] with the [`Constants`] of `params` on `frame` computed already.
pub fn integrate_with(
    params: &QuadrotorParams,
    frame: &Frame,
    k: &Constants,
    state: &mut BodyState,
    command: &Motors,
    air: &Surroundings,
    dt: f64,
) {
    let c = Coefficients {
        mixing: frame.mixing(),
        k,
    };
    by_size!(
        frame.rotor_count(),
        integrate_sized(params, &c, state, command, air, dt)
    )
}

#[inline(always)]
fn integrate_sized<const L: usize, const C: usize>(
    params: &QuadrotorParams,
    c: &Coefficients,
    state: &mut BodyState,
    command: &Motors,
    air: &Surroundings,
    dt: f64,
) {
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx") {
        // SAFETY: the CPU supports AVX, checked just above.
        return unsafe { integrate_avx::<L, C>(params, c, state, command, air, dt) };
    }
    integrate_portable::<L, C>(params, c, state, command, air, dt)
}

/// [`integrate`] compiled with AVX's three-operand instructions: a third fewer instructions
/// (no register copies) for the same IEEE operations in the same order — no fused
/// multiply-add, no reassociation — so both paths give the same bits (a test checks).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx")]
fn integrate_avx<const L: usize, const C: usize>(
    params: &QuadrotorParams,
    c: &Coefficients,
    state: &mut BodyState,
    command: &Motors,
    air: &Surroundings,
    dt: f64,
) {
    integrate_portable::<L, C>(params, c, state, command, air, dt)
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
    air: &Surroundings,
    dt: f64,
) -> bool {
    let v = &s.velocity;
    let thrust_and_gravity = c.gravity + c.full_thrust_per_mass;
    let speed = v.x.abs() + v.y.abs() + v.z.abs() + thrust_and_gravity * dt;
    let wind = &air.wind;
    let air_speed = speed + wind.x.abs() + wind.y.abs() + wind.z.abs();
    let push = air.push.map_or(0.0, |p| p.x.abs() + p.y.abs() + p.z.abs());
    let acceleration = thrust_and_gravity + push + c.drag_per_mass * air_speed * air_speed;
    s.position.z - speed * dt - acceleration * dt * dt < gear_reach(p)
}

#[inline(always)]
fn integrate_portable<const L: usize, const C: usize>(
    params: &QuadrotorParams,
    c: &Coefficients,
    state: &mut BodyState,
    command: &Motors,
    air: &Surroundings,
    dt: f64,
) {
    let command = command.padded();
    if params.ground_enabled && may_touch(params, c, state, air, dt) {
        let gear = Gear::new(params);
        let substeps = substep_count(dt, params.max_substep.min(params.contact_substep));
        let h = if substeps == 1.0 { dt } else { dt / substeps };
        let mut x = flatten_contact::<L, C>(state);
        for _ in 0..substeps as u64 {
            x = rk4(&x, h, |y| {
                contact_rates::<L, C>(params, c, &gear, y, command, air)
            });
            gear.release_lifted_feet(&mut x);
        }
        unflatten_contact::<L, C>(&x, state);
        return;
    }
    let substeps = substep_count(dt, params.max_substep);
    let h = if substeps == 1.0 { dt } else { dt / substeps };
    let mut x = flatten::<L>(state);
    for _ in 0..substeps as u64 {
        x = rk4(&x, h, |y| rates::<L>(params, c, y, command, air));
    }
    unflatten_into(&x, state);
    // No foot reached the ground: every bristle is released.
    state.gear_stretch = [[0.0; 2]; 4];
}

/// Accelerations at the current state: linear (world, m/s², total force / mass, so 0 in a
/// hover or at rest on the ground) and angular (body, rad/s²), ground contact included.
pub fn accelerations(
    params: &QuadrotorParams,
    frame: &Frame,
    state: &BodyState,
    command: &Motors,
    air: &Surroundings,
) -> (Vector3<f64>, Vector3<f64>) {
    let d = derivatives(params, frame, state, command, air);
    (d.acceleration, d.angular_acceleration)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The grouped sums against r × F and the spin reaction summed rotor by rotor over the
    /// table, for unequal motor states, for every shipped frame and one with its own
    /// coefficients per rotor.
    #[test]
    fn torque_and_thrust_sums_match_the_rotor_tables() {
        let p = QuadrotorParams {
            ground_enabled: false,
            ..QuadrotorParams::default()
        };
        let mut custom = Frame::named("hexa_x").unwrap().table().clone();
        custom.rotors[1].thrust_coefficient = Some(12.0);
        custom.rotors[4].torque_coefficient = Some(0.03);
        custom.rotors[5].time_constant = Some(0.05);
        let frames = crate::quadrotor::frame::shipped_names()
            .map(|n| Frame::named(n).unwrap())
            .chain([Frame::new(custom).unwrap()]);
        for frame in frames {
            let n = frame.rotor_count();
            let motors: Vec<f64> = (0..n).map(|i| 0.3 + 0.07 * i as f64).collect();
            let command = Motors::from_slice(&vec![0.5; n]).unwrap();
            let state = BodyState {
                motors: Motors::from_slice(&motors).unwrap(),
                ..BodyState::at_rest(Vector3::new(0.0, 0.0, 5.0), 0.0, 0.0, 0.0, 0.0)
            };
            let d = derivatives(&p, &frame, &state, &command, &Surroundings::default());
            let mut torque = Vector3::zeros();
            let mut thrust = 0.0;
            for (r, m) in frame.rotors().iter().zip(&motors) {
                let t = r.thrust_coefficient.unwrap_or(p.thrust_coefficient) * m * m;
                let arm = Vector3::new(r.x, r.y, 0.0) * p.arm_length;
                torque += arm.cross(&Vector3::new(0.0, 0.0, t));
                let c = r.torque_coefficient.unwrap_or(p.yaw_torque_coefficient);
                torque.z += r.spin.sign() * c * t;
                thrust += t;
            }
            let name = frame.name();
            let got = d.angular_acceleration.component_mul(&Vector3::new(
                p.inertia_xx,
                p.inertia_yy,
                p.inertia_zz,
            ));
            assert!((got - torque).norm() < 1e-12, "{name}: {got} vs {torque}");
            let az = (d.acceleration.z + p.gravity) * p.mass;
            assert!((az - thrust).abs() < 1e-12, "{name}: {az} vs {thrust}");
            for (i, rate) in d.motor_rates.iter().enumerate() {
                let tau = frame.rotors()[i]
                    .time_constant
                    .unwrap_or(p.motor_time_constant);
                assert!((rate - (0.5 - motors[i]) / tau).abs() < 1e-12, "{name} {i}");
            }
        }
    }

    /// The written-out quad X sums and the grouped ones give the same bits.
    #[test]
    fn quad_x_sums_are_the_grouped_sums() {
        let p = QuadrotorParams::default();
        let f = Frame::quad_x();
        let k = Constants::new(&p, &f);
        let c = Coefficients {
            mixing: f.mixing(),
            k: &k,
        };
        let mut x = [0.0; 17];
        for k in 0..1000 {
            for (i, m) in x[BODY..].iter_mut().enumerate() {
                *m = ((k * 7 + i * 13) % 101) as f64 / 100.0 + 1e-3 * i as f64;
            }
            let (a, b) = (quad_x_sums(&c, &x), rotor_sums(&c, &x));
            assert_eq!(a.0.to_bits(), b.0.to_bits());
            assert_eq!(a.1.map(f64::to_bits), b.1.map(f64::to_bits));
        }
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
        let f = Frame::quad_x();
        let k = Constants::new(&p, &f);
        let c = Coefficients {
            mixing: f.mixing(),
            k: &k,
        };
        let (mut a, mut b) = (start, start);
        let wind = Vector3::new(3.0, -1.0, 0.2);
        for i in 0..500 {
            let m = 0.3 + 0.4 * ((i % 7) as f64 / 7.0);
            let command = Motors::from([m, 0.9 - m, 0.5, 0.45]);
            let dt = if i % 3 == 0 { 0.025 } else { 0.01 };
            integrate_portable::<17, 25>(&p, &c, &mut a, &command, &Surroundings::from(wind), dt);
            // SAFETY: AVX support was checked at the top of the test.
            unsafe {
                integrate_avx::<17, 25>(&p, &c, &mut b, &command, &Surroundings::from(wind), dt)
            };
        }
        let bits = |s: &BodyState| flatten_contact::<17, 25>(s).map(f64::to_bits);
        assert_eq!(bits(&a), bits(&b));
        assert_ne!(bits(&a), bits(&start));
        // The contact path too: a tilted, sliding touchdown that bounces and settles.
        let touchdown = BodyState {
            velocity: Vector3::new(1.0, -0.5, -2.0),
            body_rates: Vector3::new(1.0, 0.5, -2.0),
            ..BodyState::at_rest(Vector3::new(0.0, 0.0, 0.3), 0.4, -0.2, 0.5, 0.0)
        };
        let (mut a, mut b) = (touchdown, touchdown);
        let low = Motors::from([0.1; 4]);
        for _ in 0..200 {
            integrate_portable::<17, 25>(&p, &c, &mut a, &low, &Surroundings::from(wind), 0.01);
            // SAFETY: AVX support was checked at the top of the test.
            unsafe {
                integrate_avx::<17, 25>(&p, &c, &mut b, &low, &Surroundings::from(wind), 0.01)
            };
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
        let f = Frame::quad_x();
        let command = Motors::from([0.5, 0.45, 0.55, 0.5]);
        for _ in 0..100_000 {
            integrate(&p, &f, &mut s, &command, &Surroundings::default(), 0.01);
        }
        assert!(
            (s.attitude.norm() - 1.0).abs() < 1e-14,
            "{}",
            s.attitude.norm()
        );
        s.attitude *= 3.0;
        integrate(
            &p,
            &f,
            &mut s,
            &Motors::from([0.5; 4]),
            &Surroundings::default(),
            0.01,
        );
        assert!(
            (s.attitude.norm() - 1.0).abs() < 1e-14,
            "{}",
            s.attitude.norm()
        );
    }
}
