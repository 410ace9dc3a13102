//! The rapier2d scene of one lander: ground, landing platform and the drone as ONE rigid body with
//! three colliders. The reference (docs/reference/lander2d.md) joined three bodies with pivot
//! joints and stayed rigid only because the parts collided with each other; a single body is rigid
//! by construction.

use super::drone::{DroneGeometry, DroneState};
use super::free_body::FreeBody;
use super::params::Lander2dParams;
use rapier2d_f64::prelude::*;
use serde::{Deserialize, Serialize};

/// Handles of the scene's bodies and colliders inside its [`PhysicsWorld`].
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub(crate) struct Handles {
    pub drone: RigidBodyHandle,
    /// Frame, left motor, right motor.
    pub drone_parts: [ColliderHandle; 3],
    pub platform: RigidBodyHandle,
    pub platform_collider: ColliderHandle,
    pub ground_collider: ColliderHandle,
}

/// Builds the world with the drone's body in `drone` state and the platform centred at
/// `platform_x` moving at `platform_vx` (ignored unless the platform moves).
pub(crate) fn build(
    p: &Lander2dParams,
    drone: &FreeBody,
    platform_x: f64,
    platform_vx: f64,
) -> (PhysicsWorld, Handles) {
    let mut world = empty_world(p);
    // The insertion order fixes the handles, and with them the order in which rapier
    // visits the pairs: every trajectory depends on it.
    let ground_collider = insert_ground(&mut world, p);
    let (platform, platform_collider) = insert_platform(&mut world, p, platform_x, platform_vx);
    let (drone, drone_parts) = insert_drone(&mut world, p, drone);
    let handles = Handles {
        drone,
        drone_parts,
        platform,
        platform_collider,
        ground_collider,
    };
    (world, handles)
}

/// The world's gravity and integration settings, with nothing in it yet.
fn empty_world(p: &Lander2dParams) -> PhysicsWorld {
    let mut world = PhysicsWorld::new();
    world.gravity = Vector::new(0.0, -p.gravity);
    world.integration_parameters.dt = p.physics_step;
    // Recycled contacts may be up to 5 cm stale; touch-down classification needs fresh ones,
    // and with six candidate pairs the full update costs next to nothing.
    world.integration_parameters.contact_recycling = false;
    world
}

/// Product combination, as in Chipmunk: the pad's 1.0 and the ground's 0.8 apply unchanged
/// against the drone's default 1.0.
fn material(b: ColliderBuilder, friction: f64) -> ColliderBuilder {
    b.friction(friction)
        .friction_combine_rule(CoefficientCombineRule::Multiply)
        .restitution(0.0)
}

/// The ground: a thick box rather than the reference's line, so nothing tunnels through it.
fn insert_ground(world: &mut PhysicsWorld, p: &Lander2dParams) -> ColliderHandle {
    let ground = material(
        ColliderBuilder::cuboid(p.world_width, 0.5)
            .translation(Vector::new(p.world_width / 2.0, p.ground_height - 0.5)),
        p.ground_friction,
    );
    world.insert_collider(ground, None)
}

/// The landing platform, fixed or (moving platform) kinematic at `vx`, centred at `x`.
fn insert_platform(
    world: &mut PhysicsWorld,
    p: &Lander2dParams,
    x: f64,
    vx: f64,
) -> (RigidBodyHandle, ColliderHandle) {
    let body = if p.moving_platform {
        RigidBodyBuilder::kinematic_velocity_based().linvel(Vector::new(vx, 0.0))
    } else {
        RigidBodyBuilder::fixed()
    };
    let body = body.translation(Vector::new(x, p.ground_height + p.platform_height / 2.0));
    let shape = material(
        ColliderBuilder::cuboid(p.platform_width / 2.0, p.platform_height / 2.0),
        p.platform_friction,
    );
    world.insert(body, shape)
}

/// The drone: one dynamic body in `drone` state, then its frame, left and right motor.
fn insert_drone(
    world: &mut PhysicsWorld,
    p: &Lander2dParams,
    drone: &FreeBody,
) -> (RigidBodyHandle, [ColliderHandle; 3]) {
    let g = DroneGeometry::of(p);
    let [x, y] = drone.translation;
    let pose = Pose::from_parts(Vector::new(x, y), drone.rotation());
    let body = RigidBodyBuilder::dynamic()
        .pose(pose)
        .linvel(Vector::new(drone.linvel[0], drone.linvel[1]))
        .angvel(drone.angvel)
        // A hovering drone is nearly at rest; asleep it would ignore its next command.
        .can_sleep(false)
        .ccd_enabled(true);
    let drone_body = world.insert_body(body);
    let mut part = |hx: f64, hy: f64, x: f64, mass: f64| {
        let shape = ColliderBuilder::cuboid(hx, hy)
            .translation(Vector::new(x, 0.0))
            .mass(mass);
        world.insert_collider(material(shape, p.drone_friction), Some(drone_body))
    };
    let frame = part(g.frame_half.0, g.frame_half.1, 0.0, g.frame_mass);
    let left = part(g.motor_half, g.motor_half, -g.motor_x, g.motor_mass);
    let right = part(g.motor_half, g.motor_half, g.motor_x, g.motor_mass);
    (drone_body, [frame, left, right])
}

impl Handles {
    /// Whether every handle names an object of the right kind in `world` (a restored world
    /// must, before anything indexes it).
    pub fn are_valid_in(&self, world: &PhysicsWorld) -> bool {
        let drone_ok = world.bodies.get(self.drone).is_some_and(|b| b.is_dynamic());
        let platform_ok = world.bodies.get(self.platform).is_some();
        let parts_ok = self.drone_parts.iter().all(|&c| {
            world
                .colliders
                .get(c)
                .is_some_and(|c| c.parent() == Some(self.drone))
        });
        let platform_collider_ok = world
            .colliders
            .get(self.platform_collider)
            .is_some_and(|c| c.parent() == Some(self.platform));
        let ground_ok = world.colliders.get(self.ground_collider).is_some();
        drone_ok && platform_ok && parts_ok && platform_collider_ok && ground_ok
    }

    /// Whether any drone part has an active contact with `other` (speculative contacts within
    /// rapier's 2 cm prediction distance included: they are what stops the drone).
    pub fn drone_touches(&self, world: &PhysicsWorld, other: ColliderHandle) -> bool {
        self.drone_parts.iter().any(|&part| {
            world
                .narrow_phase
                .contact_pair(part, other)
                .is_some_and(|pair| pair.has_any_active_contact())
        })
    }
}

/// Reads the drone's kinematic state.
pub(crate) fn drone_state(body: &RigidBody) -> DroneState {
    let t = body.translation();
    let v = body.linvel();
    DroneState {
        x: t.x,
        y: t.y,
        angle: body.rotation().angle(),
        vx: v.x,
        vy: v.y,
        angular_velocity: body.angvel(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn composite_inertia_comes_from_the_collider_mass_properties() {
        let p = Lander2dParams::default();
        let start = DroneState {
            x: 25.0,
            y: 40.0,
            ..Default::default()
        };
        let (world, h) = build(&p, &FreeBody::from_state(&start), 25.0, 0.0);
        let body = &world.bodies[h.drone];
        let mprops = body.mass_properties().local_mprops;
        // Frame 0.3·(0.8² + 0.1²)/12 = 0.01625; each motor 0.6·(0.2² + 0.2²)/12 + 0.6·0.4² = 0.1.
        assert!(
            (mprops.principal_inertia() - 0.21625).abs() < 1e-12,
            "{}",
            mprops.principal_inertia()
        );
        assert!((body.mass() - 1.5).abs() < 1e-12);
        assert!(
            mprops.local_com.length() < 1e-12,
            "centre of mass {:?}",
            mprops.local_com
        );
        let masses: Vec<f64> = h
            .drone_parts
            .iter()
            .map(|&c| world.colliders[c].mass())
            .collect();
        for (got, want) in masses.iter().zip([0.3, 0.6, 0.6]) {
            assert!((got - want).abs() < 1e-12, "{masses:?}");
        }
        assert!(h.are_valid_in(&world));
    }

    #[test]
    fn default_parts_are_the_reference_shapes() {
        let g = DroneGeometry::of(&Lander2dParams::default());
        assert_eq!(g.motor_x, 0.4);
        assert_eq!(g.frame_half, (0.4, 0.05));
        assert_eq!(g.motor_half, 0.1);
    }

    #[test]
    fn drone_is_one_rigid_body_not_a_joint_assembly() {
        // The reference's three jointed bodies stayed rigid only through self-collision.
        let p = Lander2dParams::default();
        let start = DroneState {
            x: 25.0,
            y: 40.0,
            angle: 0.3,
            ..Default::default()
        };
        let (world, h) = build(&p, &FreeBody::from_state(&start), 25.0, 0.0);
        assert_eq!(world.impulse_joints.len(), 0);
        assert_eq!(world.multibody_joints.multibodies().count(), 0);
        assert_eq!(
            world.bodies.iter().filter(|(_, b)| b.is_dynamic()).count(),
            1
        );
        assert_eq!(world.bodies[h.drone].colliders(), &h.drone_parts);
    }
}
