//! Where the drone's physics runs: alone in free flight, or in a rapier world near the ground
//! and the pad.
//!
//! A rapier world per lander is ~60 KiB and its step mostly fixed cost, so 1,024 vector envs
//! neither fit in cache nor step fast. Most of an episode is flight far from anything the
//! drone could touch, so the world exists only within reach of a contact: at each physics
//! grid point the scene checks how far the drone is from the ground and the pad, and builds
//! the world when a contact could begin within the next grid step (with margin), drops it
//! when the drone is clear again. Being decided on the grid alone, the choice depends on
//! nothing but the run's own state, so every front end and every step size on the grid get
//! the same bits.

use rapier2d_f64::prelude::*;
use serde::{Deserialize, Serialize};

use super::drone::{DroneGeometry, DroneState};
use super::free_body::{FreeBody, MassProps};
use super::params::Lander2dParams;
use super::world::{self, Handles};

/// Clearance kept beyond what one grid step could close, m.
const SAFETY: f64 = 0.25;
/// Extra clearance before the world is dropped again, so that a drone hovering at the
/// boundary does not rebuild it every grid step, m.
const HYSTERESIS: f64 = 0.5;

#[derive(Serialize, Deserialize)]
pub(crate) enum Scene {
    /// Far from the ground and the pad: the drone integrated alone, the pad moved by hand.
    Free {
        body: FreeBody,
        platform_x: f64,
        platform_vx: f64,
    },
    /// Within reach of a contact: the rapier world decides.
    Contact(Box<ContactWorld>),
}

#[derive(Serialize, Deserialize)]
pub(crate) struct ContactWorld {
    world: PhysicsWorld,
    handles: Handles,
}

impl Scene {
    /// The scene with the drone in `drone` state and the pad at `platform_x` moving at
    /// `platform_vx` (ignored unless the pad moves), in the mode its clearance asks for.
    pub fn new(
        p: &Lander2dParams,
        drone: &DroneState,
        platform_x: f64,
        platform_vx: f64,
        wind: [f64; 2],
    ) -> Self {
        let mut scene = Scene::Free {
            body: FreeBody::from_state(drone),
            platform_x,
            platform_vx: if p.moving_platform { platform_vx } else { 0.0 },
        };
        scene.choose_mode(p, wind);
        scene
    }

    pub fn drone(&self) -> DroneState {
        match self {
            Scene::Free { body, .. } => body.state(),
            Scene::Contact(c) => world::drone_state(c.drone()),
        }
    }

    pub fn velocity(&self) -> [f64; 2] {
        match self {
            Scene::Free { body, .. } => body.linvel,
            Scene::Contact(c) => {
                let v = c.drone().linvel();
                [v.x, v.y]
            }
        }
    }

    pub fn platform_x(&self) -> f64 {
        match self {
            Scene::Free { platform_x, .. } => *platform_x,
            Scene::Contact(c) => c.world.bodies[c.handles.platform].translation().x,
        }
    }

    pub fn platform_vx(&self) -> f64 {
        match self {
            Scene::Free { platform_vx, .. } => *platform_vx,
            Scene::Contact(c) => c.world.bodies[c.handles.platform].linvel().x,
        }
    }

    pub fn set_platform_vx(&mut self, vx: f64) {
        match self {
            Scene::Free { platform_vx, .. } => *platform_vx = vx,
            Scene::Contact(c) => {
                let platform = c.handles.platform;
                c.world.bodies[platform].set_linvel(Vector::new(vx, 0.0), true);
            }
        }
    }

    /// Whether the rapier world is in use (the drone is within reach of a contact).
    pub fn in_contact_world(&self) -> bool {
        matches!(self, Scene::Contact(_))
    }

    /// At a physics grid point: builds the rapier world if a contact could begin within the
    /// next grid step, drops it if the drone is clear by the margin and the hysteresis.
    /// `wind` is the total wind force now, N.
    pub fn choose_mode(&mut self, p: &Lander2dParams, wind: [f64; 2]) {
        let drone = self.drone();
        let clearance = clearance(p, &drone, self.platform_x());
        let margin = reach_in_one_grid_step(p, &drone, wind);
        match self {
            Scene::Free {
                body,
                platform_x,
                platform_vx,
            } if clearance < margin => {
                let (world, handles) = world::build(p, body, *platform_x, *platform_vx);
                *self = Scene::Contact(Box::new(ContactWorld { world, handles }));
            }
            Scene::Contact(c) if clearance > margin + HYSTERESIS => {
                let d = c.drone();
                let (t, r, v) = (d.translation(), d.rotation(), d.linvel());
                let platform = &c.world.bodies[c.handles.platform];
                *self = Scene::Free {
                    body: FreeBody {
                        translation: [t.x, t.y],
                        rotation: [r.re, r.im],
                        linvel: [v.x, v.y],
                        angvel: d.angvel(),
                    },
                    platform_x: platform.translation().x,
                    platform_vx: platform.linvel().x,
                };
            }
            _ => {}
        }
    }

    /// One physics step of `dt` seconds with each motor's `thrust` (N, along the body's +y at
    /// ±motor_x) and the `wind` force at the centre of mass; returns whether the drone touches
    /// (the pad, the ground) after it.
    pub fn step(
        &mut self,
        p: &Lander2dParams,
        dt: f64,
        thrust: [f64; 2],
        wind: [f64; 2],
    ) -> (bool, bool) {
        let motor_x = DroneGeometry::of(p).motor_x;
        match self {
            Scene::Free {
                body,
                platform_x,
                platform_vx,
            } => {
                let r = body.rotation();
                let up = r.transform_vector(Vector::Y);
                let mut force = Vector::ZERO;
                let mut torque = 0.0;
                for (t, x) in thrust.into_iter().zip([-motor_x, motor_x]) {
                    let f = up * t;
                    torque += r.transform_vector(Vector::new(x, 0.0)).perp_dot(f);
                    force += f;
                }
                force += Vector::new(wind[0], wind[1]);
                let m = MassProps::of(p);
                body.step(dt, [force.x, force.y], torque, p.gravity, &m);
                *platform_x += *platform_vx * dt;
                (false, false)
            }
            Scene::Contact(c) => c.step(motor_x, dt, thrust, wind),
        }
    }

    /// Whether a restored scene's world indexes safely.
    pub fn is_valid(&self) -> bool {
        match self {
            Scene::Free { .. } => true,
            Scene::Contact(c) => c.handles.are_valid_in(&c.world),
        }
    }
}

impl ContactWorld {
    // The handles were checked against the world when it was built or restored, and the
    // world is private: indexing cannot miss.
    fn drone(&self) -> &RigidBody {
        &self.world.bodies[self.handles.drone]
    }

    fn step(&mut self, motor_x: f64, dt: f64, thrust: [f64; 2], wind: [f64; 2]) -> (bool, bool) {
        // rapier keeps user forces until reset: last step's are replaced.
        let body = &mut self.world.bodies[self.handles.drone];
        body.reset_forces(false);
        body.reset_torques(false);
        let pose = *body.position();
        let up = pose.rotation.transform_vector(Vector::Y);
        for (t, x) in thrust.into_iter().zip([-motor_x, motor_x]) {
            body.add_force_at_point(up * t, pose.transform_point(Vector::new(x, 0.0)), true);
        }
        body.add_force(Vector::new(wind[0], wind[1]), true);
        let nominal = self.world.integration_parameters.dt;
        self.world.integration_parameters.dt = dt;
        self.world.step();
        self.world.integration_parameters.dt = nominal;
        let h = &self.handles;
        (
            h.drone_touches(&self.world, h.platform_collider),
            h.drone_touches(&self.world, h.ground_collider),
        )
    }
}

/// Distance from the drone's bounding circle to the ground and to the pad, whichever is
/// nearer, m (negative when the circle reaches into either).
fn clearance(p: &Lander2dParams, drone: &DroneState, platform_x: f64) -> f64 {
    let to_ground = drone.y - p.ground_height;
    let dx = ((drone.x - platform_x).abs() - p.platform_width / 2.0).max(0.0);
    let dy = (drone.y - p.platform_top()).max(0.0);
    to_ground.min(dx.hypot(dy)) - DroneGeometry::of(p).reach()
}

/// How far the drone's outline and the pad can close on each other within one grid step, with
/// a factor 2 and a safety margin, m: the drone's speed (its rotation's included), the pad's,
/// and the most the thrust (also turning the drone), wind and gravity can add.
fn reach_in_one_grid_step(p: &Lander2dParams, drone: &DroneState, wind: [f64; 2]) -> f64 {
    let step = p.physics_step;
    let g = DroneGeometry::of(p);
    let m = MassProps::of(p);
    let reach = g.reach();
    let pad_speed = if p.moving_platform {
        p.platform_speed
    } else {
        0.0
    };
    let speed = drone.vx.hypot(drone.vy) + drone.angular_velocity.abs() * reach + pad_speed;
    let accel = (2.0 * p.max_thrust + wind[0].hypot(wind[1])) / m.mass
        + p.gravity
        + 2.0 * p.max_thrust * g.motor_x / m.inertia * reach;
    SAFETY + 2.0 * (speed * step + accel * step * step)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn forced_world(p: &Lander2dParams, drone: &DroneState) -> Scene {
        let (world, handles) = world::build(p, &FreeBody::from_state(drone), 25.0, 0.0);
        Scene::Contact(Box::new(ContactWorld { world, handles }))
    }

    #[test]
    fn free_flight_integrates_as_the_rapier_world_does() {
        // High above everything, a weave of thrusts with wind: the free integrator and a
        // rapier world given the same forces stay together to rounding over 4 s.
        let p = Lander2dParams::default();
        let start = DroneState {
            x: 25.0,
            y: 40.0,
            angle: 0.1,
            vx: 1.0,
            vy: -0.5,
            angular_velocity: 0.3,
        };
        let mut free = Scene::new(&p, &start, 25.0, 0.0, [0.0; 2]);
        assert!(!free.in_contact_world());
        let mut rapier = forced_world(&p, &start);
        let hover = p.drone_mass * p.gravity / 2.0;
        for k in 0..200 {
            let t = k as f64 * p.physics_step;
            let weave = 0.05 * (3.0 * t).sin();
            let thrust = [hover * (1.1 + weave), hover * (1.1 - weave)];
            let wind = [0.8, -0.2];
            assert_eq!(free.step(&p, p.physics_step, thrust, wind), (false, false));
            rapier.step(&p, p.physics_step, thrust, wind);
        }
        let (a, b) = (free.drone(), rapier.drone());
        let worst = [
            a.x - b.x,
            a.y - b.y,
            a.angle - b.angle,
            a.vx - b.vx,
            a.vy - b.vy,
            a.angular_velocity - b.angular_velocity,
        ]
        .map(f64::abs)
        .into_iter()
        .fold(0.0, f64::max);
        assert!(worst < 1e-9, "free {a:?}\nrapier {b:?}");
        // It flew: a test that cannot pass by standing still.
        assert!(
            (a.x - start.x).abs() > 1.0 && (a.angle - start.angle).abs() > 0.1,
            "{a:?}"
        );
    }

    #[test]
    fn mass_properties_are_those_rapier_derives_from_the_colliders() {
        let p = Lander2dParams::default();
        let Scene::Contact(c) = forced_world(&p, &DroneState::default()) else {
            unreachable!()
        };
        let body = c.drone();
        let m = MassProps::of(&p);
        assert!((body.mass() - m.mass).abs() < 1e-12);
        let inertia = body.mass_properties().local_mprops.principal_inertia();
        assert!(
            (inertia - m.inertia).abs() < 1e-12,
            "{inertia} vs {}",
            m.inertia
        );
    }

    #[test]
    fn the_world_exists_only_within_reach_of_a_contact() {
        let p = Lander2dParams::default();
        let at = |y: f64, vy: f64| DroneState {
            x: 25.0,
            y,
            vy,
            ..Default::default()
        };
        // Pad top at 10.5, drone reach 0.51: at rest 1 m above the pad there is no world...
        assert!(!Scene::new(&p, &at(12.0, 0.0), 25.0, 0.0, [0.0; 2]).in_contact_world());
        // ...falling at 20 m/s there is (it closes 0.4 m per grid step).
        assert!(Scene::new(&p, &at(11.5, -20.0), 25.0, 0.0, [0.0; 2]).in_contact_world());
        assert!(Scene::new(&p, &at(10.6, 0.0), 25.0, 0.0, [0.0; 2]).in_contact_world());
        // Leaving again: dropped only beyond the hysteresis.
        let mut s = Scene::new(&p, &at(10.6, 0.0), 25.0, 0.0, [0.0; 2]);
        s.choose_mode(&p, [0.0; 2]);
        assert!(s.in_contact_world());
        let mut high = forced_world(&p, &at(14.0, 0.0));
        high.choose_mode(&p, [0.0; 2]);
        assert!(!high.in_contact_world());
        assert_eq!(high.drone().y, 14.0);
    }
}
