//! Equations of motion and their integration.
//!
//! World ENU, body FLU. Rotor i of PX4's quad-X sits at (±L/√2, ±L/√2): 0 front-right CCW,
//! 1 rear-left CCW, 2 front-left CW, 3 rear-right CW. Thrust T_i = k m_i² along body +z;
//! torques are r_i × F_i plus the spin reaction (a CCW rotor pushes the body toward −z).
//! Body rates are integrated as body rates: q̇ = ½ q ⊗ (0, ω), I ω̇ = τ − ω × I ω.

use super::params::QuadrotorParams;
use super::state::BodyState;
use nalgebra::{Quaternion, Vector3};

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
    lever: f64,
    inv_mass: f64,
    inertia: Vector3<f64>,
    inv_inertia: Vector3<f64>,
    weight: f64,
    half_rho_cda: f64,
    inv_tau: f64,
}

impl Coefficients {
    fn new(p: &QuadrotorParams) -> Self {
        Coefficients {
            lever: p.arm_length * std::f64::consts::FRAC_1_SQRT_2,
            inv_mass: 1.0 / p.mass,
            inertia: Vector3::new(p.inertia_xx, p.inertia_yy, p.inertia_zz),
            inv_inertia: Vector3::new(1.0 / p.inertia_xx, 1.0 / p.inertia_yy, 1.0 / p.inertia_zz),
            weight: p.mass * p.gravity,
            half_rho_cda: 0.5 * p.air_density * p.drag_area,
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
    derivatives_with(params, &Coefficients::new(params), state, command, wind)
}

fn derivatives_with(
    p: &QuadrotorParams,
    c: &Coefficients,
    s: &BodyState,
    command: &[f64; 4],
    wind: &Vector3<f64>,
) -> Derivative {
    let thrust = s.motors.map(|m| p.thrust_coefficient * m * m);
    let total_thrust: f64 = thrust.iter().sum();

    // Forces (world): thrust along body z, gravity, quadratic drag on the air-relative velocity.
    let relative = s.velocity - wind;
    let drag = -c.half_rho_cda * relative.norm() * relative;
    let mut force = s.body_z_axis() * total_thrust + drag;
    force.z -= c.weight;

    // Torques (body): r × F of each rotor, spin reaction, damping, optional pendulum.
    let mut torque = Vector3::zeros();
    for i in 0..4 {
        let (fwd, left) = ROTOR_POSITION[i];
        torque.x += left * c.lever * thrust[i];
        torque.y -= fwd * c.lever * thrust[i];
        torque.z += ROTOR_SPIN[i] * p.yaw_torque_coefficient * thrust[i];
    }
    let w = s.body_rates;
    torque -= (p.angular_damping_linear + p.angular_damping_quadratic * w.norm()) * w;
    if p.pendulum_coefficient != 0.0 {
        let (roll, pitch, _) = s.euler_angles();
        let restoring = p.pendulum_coefficient * c.weight;
        torque.x -= restoring * roll.sin();
        torque.y -= restoring * pitch.sin();
    }
    let gyroscopic = w.cross(&c.inertia.component_mul(&w));
    let angular_acceleration = (torque - gyroscopic).component_mul(&c.inv_inertia);

    let attitude_rate = s.attitude * Quaternion::new(0.0, w.x, w.y, w.z) * 0.5;
    let mut motor_rates = [0.0; 4];
    for i in 0..4 {
        motor_rates[i] = (command[i] - s.motors[i]) * c.inv_tau;
    }
    Derivative {
        velocity: s.velocity,
        acceleration: force * c.inv_mass,
        attitude_rate,
        angular_acceleration,
        motor_rates,
    }
}

fn advanced(s: &BodyState, d: &Derivative, h: f64) -> BodyState {
    let mut motors = s.motors;
    for (m, rate) in motors.iter_mut().zip(d.motor_rates) {
        *m += h * rate;
    }
    BodyState {
        position: s.position + d.velocity * h,
        velocity: s.velocity + d.acceleration * h,
        attitude: s.attitude + d.attitude_rate * h,
        body_rates: s.body_rates + d.angular_acceleration * h,
        motors,
    }
}

/// One classical RK4 step of length `h`; the quaternion is renormalised afterwards.
fn rk4(
    p: &QuadrotorParams,
    c: &Coefficients,
    s: &BodyState,
    command: &[f64; 4],
    wind: &Vector3<f64>,
    h: f64,
) -> BodyState {
    let k1 = derivatives_with(p, c, s, command, wind);
    let k2 = derivatives_with(p, c, &advanced(s, &k1, 0.5 * h), command, wind);
    let k3 = derivatives_with(p, c, &advanced(s, &k2, 0.5 * h), command, wind);
    let k4 = derivatives_with(p, c, &advanced(s, &k3, h), command, wind);
    let sixth = h / 6.0;
    let combine3 = |a: Vector3<f64>, b, cc, d| (a + (b + cc) * 2.0 + d) * sixth;
    let mut motors = s.motors;
    for (i, m) in motors.iter_mut().enumerate() {
        let (a, b, c, d) = (
            k1.motor_rates[i],
            k2.motor_rates[i],
            k3.motor_rates[i],
            k4.motor_rates[i],
        );
        *m += (a + 2.0 * (b + c) + d) * sixth;
    }
    let attitude = s.attitude
        + (k1.attitude_rate + (k2.attitude_rate + k3.attitude_rate) * 2.0 + k4.attitude_rate)
            * sixth;
    BodyState {
        position: s.position + combine3(k1.velocity, k2.velocity, k3.velocity, k4.velocity),
        velocity: s.velocity
            + combine3(
                k1.acceleration,
                k2.acceleration,
                k3.acceleration,
                k4.acceleration,
            ),
        attitude: attitude / attitude.norm(),
        body_rates: s.body_rates
            + combine3(
                k1.angular_acceleration,
                k2.angular_acceleration,
                k3.angular_acceleration,
                k4.angular_acceleration,
            ),
        motors,
    }
}

/// Ground plane z = 0: an inelastic, non-sliding contact. A vehicle that reaches it stops
/// sinking, stops sliding and stops turning; it lifts off as soon as thrust exceeds weight.
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
    let c = Coefficients::new(params);
    let substeps = (dt / params.max_substep).ceil().max(1.0);
    let h = dt / substeps;
    let mut grounded = false;
    for _ in 0..substeps as u64 {
        *state = rk4(params, &c, state, command, wind, h);
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
