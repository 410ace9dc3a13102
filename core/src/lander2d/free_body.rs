//! The drone in free flight, integrated without a rapier world.
//!
//! Far from the ground and the pad nothing can touch the drone, and a rapier step of one body
//! is mostly the fixed cost of the pipeline (broad phase, islands, solver set-up) and a 60 KiB
//! world per env. Here the same integration rapier's solver applies to a body without
//! contacts runs on a few numbers: `num_solver_iterations` substeps, each adding the constant
//! force's velocity increment, capping the speeds as rapier does, turning the rotation by the
//! linearised angle and moving the centre by the new velocity. It agrees with a rapier world
//! to rounding (tested), not bit for bit: which of the two steps the drone is decided on the
//! physics grid alone, so a run's bits still depend on nothing but its inputs.

use rapier2d_f64::prelude::*;
use serde::{Deserialize, Serialize};

use super::drone::{DroneGeometry, DroneState};
use super::params::Lander2dParams;

/// Substeps of one rapier step (rapier's default `num_solver_iterations`).
pub(crate) const SUBSTEPS: usize = 4;
/// rapier's per-substep linear speed cap (`normalized_max_linear_velocity`, length unit 1), m/s.
const MAX_LINEAR_SPEED: f64 = 400.0;
/// rapier's cap on the rotation of one step (its `MAX_ROTATION`), rad.
const MAX_ROTATION_PER_STEP: f64 = std::f64::consts::FRAC_PI_4;

/// Pose and velocities of the drone's body (origin at its centre of mass).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub(crate) struct FreeBody {
    pub translation: [f64; 2],
    /// Unit complex number (cos, sin) of the angle, as rapier keeps it.
    pub rotation: [f64; 2],
    pub linvel: [f64; 2],
    pub angvel: f64,
}

/// Mass and moment of inertia of the drone (frame box and two motor boxes).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct MassProps {
    /// kg.
    pub mass: f64,
    /// About the centre of mass, kg·m².
    pub inertia: f64,
}

impl MassProps {
    /// The composite of the frame (0.2 of the mass) and the two square motors (0.4 each) at
    /// ±motor_x: what rapier derives from the three colliders.
    pub fn of(p: &Lander2dParams) -> Self {
        let g = DroneGeometry::of(p);
        let (a, b) = g.frame_half;
        let c = g.motor_half;
        let frame = g.frame_mass * (a * a + b * b) / 3.0;
        let motor = g.motor_mass * (2.0 * c * c / 3.0 + g.motor_x * g.motor_x);
        MassProps {
            mass: g.frame_mass + 2.0 * g.motor_mass,
            inertia: frame + 2.0 * motor,
        }
    }
}

impl FreeBody {
    pub fn from_state(d: &DroneState) -> Self {
        let r = Rotation::new(d.angle);
        FreeBody {
            translation: [d.x, d.y],
            rotation: [r.re, r.im],
            linvel: [d.vx, d.vy],
            angvel: d.angular_velocity,
        }
    }

    pub fn rotation(&self) -> Rotation {
        Rotation::from_cos_sin_unchecked(self.rotation[0], self.rotation[1])
    }

    pub fn state(&self) -> DroneState {
        DroneState {
            x: self.translation[0],
            y: self.translation[1],
            angle: self.rotation().angle(),
            vx: self.linvel[0],
            vy: self.linvel[1],
            angular_velocity: self.angvel,
        }
    }

    /// One step of `dt` seconds under a constant `force` (N, world frame, at the centre of
    /// mass), `torque` (N·m) and gravity −`gravity` along y.
    pub fn step(&mut self, dt: f64, force: [f64; 2], torque: f64, gravity: f64, m: &MassProps) {
        let h = dt / SUBSTEPS as f64;
        let accel = Vector::new(force[0] / m.mass, force[1] / m.mass - gravity);
        let dv = accel * h;
        let dw = torque / m.inertia * h;
        let max_angvel = MAX_ROTATION_PER_STEP / dt;
        let mut v = Vector::new(self.linvel[0], self.linvel[1]);
        let mut w = self.angvel;
        let mut x = Vector::new(self.translation[0], self.translation[1]);
        let mut r = self.rotation();
        for _ in 0..SUBSTEPS {
            v += dv;
            w += dw;
            let speed = v.length();
            if speed > MAX_LINEAR_SPEED {
                v *= MAX_LINEAR_SPEED / speed;
            }
            if w.abs() > max_angvel {
                w = w.signum() * max_angvel;
            }
            let turn = w * h;
            r = Rotation::from_cos_sin_unchecked(r.re - turn * r.im, r.im + turn * r.re);
            r.normalize_mut();
            x += v * h;
        }
        self.translation = [x.x, x.y];
        self.rotation = [r.re, r.im];
        self.linvel = [v.x, v.y];
        self.angvel = w;
    }
}
