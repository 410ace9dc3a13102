//! Many vehicles in one world (issue 34): a lone vehicle is itself, the listing order changes
//! no bit, hulls collide with momentum conserved and are reported once, a wake pushes the
//! vehicle below as the downwash model says, a saved world continues bit for bit, and a
//! thousand vehicles step.

use flyloop_core::quadrotor::{BodyState, Frame, Quadrotor, QuadrotorParams};
use flyloop_core::rng::SimRng;
use flyloop_core::vehicle::AirVehicle;
use flyloop_core::world::{World, WorldError, WorldParams};
use nalgebra::Vector3;

fn still_air() -> QuadrotorParams {
    QuadrotorParams {
        wind_enabled: false,
        ground_enabled: false,
        drag_area: 0.0,
        ..QuadrotorParams::default()
    }
}

/// A vehicle of `frame` at `position` moving at `velocity`, its motors at the hover state.
fn hovering(
    frame: &str,
    params: QuadrotorParams,
    position: [f64; 3],
    velocity: [f64; 3],
) -> Quadrotor {
    let mut body = BodyState::at_rest(Vector3::from(position), 0.0, 0.0, 0.0, 0.0);
    body.velocity = Vector3::from(velocity);
    let mut quad = Quadrotor::new(params, body, SimRng::new(1))
        .unwrap()
        .with_frame(Frame::named(frame).unwrap());
    let hover = quad.hover_motor_state().unwrap();
    quad.body.motors.iter_mut().for_each(|m| *m = hover);
    let n = quad.frame().rotor_count();
    quad.set_command(vec![hover; n]).unwrap();
    quad
}

fn bits(q: &dyn AirVehicle) -> Vec<u64> {
    let b = q.body();
    (b.position
        .iter()
        .chain(&b.velocity)
        .chain(b.attitude.coords.iter()))
    .chain(&b.body_rates)
    .chain(b.motors.iter())
    .map(|v| v.to_bits())
    .collect()
}

fn calm_world() -> WorldParams {
    WorldParams {
        wind_enabled: false,
        ..WorldParams::default()
    }
}

/// Commands that change every step: a sway around the hover state.
fn sway(step: usize, rotor: usize, hover: f64) -> f64 {
    hover + 0.05 * ((step * 7 + rotor * 3) % 11) as f64 / 11.0 - 0.02
}

#[test]
fn a_lone_vehicle_in_a_calm_world_is_the_vehicle_alone() {
    let params = QuadrotorParams {
        wind_enabled: false,
        ..QuadrotorParams::default()
    };
    for dt in [0.004, 0.005, 0.01] {
        let alone = Quadrotor::standing(params.clone(), 3).unwrap();
        let mut world = World::new(calm_world(), 9, [("solo".to_string(), alone.clone())]).unwrap();
        let mut alone = alone;
        let hover = alone.hover_motor_state().unwrap();
        for step in 0..300 {
            let command: Vec<f64> = (0..4).map(|r| sway(step, r, hover) + 0.1).collect();
            alone.set_command(&command).unwrap();
            world.set_command(0, &command).unwrap();
            alone.step(dt);
            world.step(dt);
            assert_eq!(bits(world.vehicle(0)), bits(&alone), "dt {dt} step {step}");
        }
        assert!(
            alone.body.position.z > 0.5,
            "it took off: {}",
            alone.body.position.z
        );
    }
}

fn mixed_fleet(params: &QuadrotorParams) -> Vec<(String, Quadrotor)> {
    vec![
        (
            "alpha".into(),
            hovering("quad_x", params.clone(), [0.0, 0.0, 5.0], [1.5, 0.0, 0.0]),
        ),
        (
            "bravo".into(),
            hovering("hexa_x", params.clone(), [1.0, 0.0, 5.0], [-1.5, 0.0, 0.0]),
        ),
        (
            "charlie".into(),
            hovering("octo_x", params.clone(), [0.0, 3.0, 6.0], [0.0, 0.0, 0.0]),
        ),
        (
            "delta".into(),
            hovering(
                "quad_plus",
                params.clone(),
                [0.02, 3.0, 5.2],
                [0.0, 0.0, 0.0],
            ),
        ),
        (
            "echo".into(),
            hovering("quad_x", params.clone(), [30.0, 0.0, 5.0], [0.0, 0.0, 0.0]),
        ),
    ]
}

#[test]
fn the_order_vehicles_are_listed_and_commanded_in_changes_no_bit() {
    let params = QuadrotorParams {
        ground_enabled: false,
        ..QuadrotorParams::default()
    };
    let fleet = mixed_fleet(&params);
    let mut reversed = fleet.clone();
    reversed.reverse();
    let wind = WorldParams::default();
    let mut a = World::new(wind.clone(), 77, fleet).unwrap();
    let mut b = World::new(wind, 77, reversed).unwrap();
    let names = a.names().to_vec();
    for step in 0..200 {
        let order: Vec<&String> = if step % 2 == 0 {
            names.iter().collect()
        } else {
            names.iter().rev().collect()
        };
        for (k, name) in order.iter().enumerate() {
            for world in [&mut a, &mut b] {
                let i = world.index(name).unwrap();
                let n = world.vehicle(i).frame().rotor_count();
                let hover = world.vehicle(i).hover_motor_state().unwrap();
                let command: Vec<f64> = (0..n).map(|r| sway(step + k, r, hover)).collect();
                world.set_command(i, &command).unwrap();
            }
        }
        a.step(0.01);
        b.step(0.01);
    }
    for name in &names {
        let (i, j) = (a.index(name).unwrap(), b.index(name).unwrap());
        assert_eq!(bits(a.vehicle(i)), bits(b.vehicle(j)), "{name}");
    }
    let (ca, cb) = (a.take_collisions(), b.take_collisions());
    assert_eq!(ca, cb);
    assert!(!ca.is_empty(), "alpha and bravo were sent into each other");
}

#[test]
fn a_head_on_collision_bounces_conserves_momentum_and_is_reported_once() {
    let p = still_air();
    let fleet = [
        (
            "a".to_string(),
            hovering("quad_x", p.clone(), [0.0, 0.0, 10.0], [2.0, 0.0, 0.0]),
        ),
        (
            "b".to_string(),
            hovering("quad_x", p.clone(), [1.0, 0.0, 10.0], [-2.0, 0.0, 0.0]),
        ),
    ];
    let params = WorldParams {
        downwash_enabled: false,
        ..calm_world()
    };
    let mut world = World::new(params, 1, fleet).unwrap();
    // Hull radius 0.1 m · 1 (rotor distance) + 0.05 m propeller = 0.15 m.
    assert!((world.shape(0).hull_radius - 0.15).abs() < 1e-12);
    for _ in 0..100 {
        world.step(0.01);
    }
    let collisions = world.take_collisions();
    assert_eq!(collisions.len(), 1, "{collisions:?}");
    let c = collisions[0];
    assert_eq!((c.a, c.b), (0, 1));
    assert!((c.speed - 4.0).abs() < 1e-9, "closing speed {}", c.speed);
    // They met when 0.3 m apart: after (1 − 0.3) / 4 = 0.175 s, at the grid point after.
    assert!((0.175..0.185).contains(&c.time), "{}", c.time);
    let (va, vb) = (
        world.vehicle(0).body().velocity,
        world.vehicle(1).body().velocity,
    );
    assert!(va.x < -0.5 && vb.x > 0.5, "bounced: {va} {vb}");
    assert!((va.x + vb.x).abs() < 1e-9, "momentum {}", va.x + vb.x);
    let restitution = (vb.x - va.x) / 4.0;
    assert!(
        (0.2..1.0).contains(&restitution),
        "restitution {restitution}"
    );
    assert!(world.touching().is_empty());
}

#[test]
fn a_wake_pushes_the_vehicle_below_as_the_downwash_model_says() {
    let p = still_air();
    let fleet = [
        (
            "upper".to_string(),
            hovering("quad_x", p.clone(), [0.0, 0.0, 11.0], [0.0; 3]),
        ),
        (
            "lower".to_string(),
            hovering("quad_x", p.clone(), [0.0, 0.0, 10.0], [0.0; 3]),
        ),
    ];
    let mut world = World::new(calm_world(), 1, fleet).unwrap();
    let (lower, upper) = (world.index("lower").unwrap(), world.index("upper").unwrap());
    let t = 0.2;
    for _ in 0..20 {
        world.step(0.01);
    }
    // F = c₁ (r / 4Δz)² at hover thrust, r = 0.5 · 0.1 m, Δz = 1 m; on 1 kg.
    let force = 2267.18 * (0.05_f64 / 4.0).powi(2);
    let expected = 0.5 * force * t * t;
    let drop = 10.0 - world.vehicle(lower).body().position.z;
    assert!(
        (drop - expected).abs() < 0.02 * expected,
        "drop {drop} vs {expected}"
    );
    assert!((world.vehicle(upper).body().position.z - 11.0).abs() < 1e-9);
    // The wake weakens as (1/Δz)²: held at the last grid point, with Δz = 1 m + the drop.
    let now = force / (1.0 + drop).powi(2);
    let held = world.interaction_force(lower).z;
    assert!((held + now).abs() < 0.005 * now, "{held} vs {now}");
}

#[test]
fn a_saved_world_continues_bit_for_bit_even_between_grid_points() {
    let params = QuadrotorParams {
        ground_enabled: false,
        ..QuadrotorParams::default()
    };
    let mut world = World::new(WorldParams::default(), 5, mixed_fleet(&params)).unwrap();
    for _ in 0..7 {
        world.step(0.004);
    }
    let mut restored = World::restore(&world.save().unwrap()).unwrap();
    assert_eq!(restored, world);
    for _ in 0..100 {
        world.step(0.004);
        restored.step(0.004);
    }
    for i in 0..world.len() {
        assert_eq!(bits(world.vehicle(i)), bits(restored.vehicle(i)));
    }
    assert_eq!(world.take_collisions(), restored.take_collisions());
    let mut bytes = world.save().unwrap();
    let last = bytes.len() - 20;
    bytes[last] ^= 1;
    assert!(World::restore(&bytes).is_err());
}

#[test]
fn bad_worlds_are_errors_that_name_the_vehicles() {
    let p = still_air();
    let two = |b: [f64; 3]| {
        [
            (
                "one".to_string(),
                hovering("quad_x", p.clone(), [0.0, 0.0, 5.0], [0.0; 3]),
            ),
            (
                "two".to_string(),
                hovering("hexa_x", p.clone(), b, [0.0; 3]),
            ),
        ]
    };
    let e = World::new(WorldParams::default(), 1, two([0.1, 0.0, 5.0])).unwrap_err();
    assert!(matches!(e, WorldError::Overlap { .. }), "{e}");
    let text = e.to_string();
    assert!(
        text.contains("`one`") && text.contains("`two`") && text.contains("0.100"),
        "{text}"
    );
    let dup = [
        (
            "x".to_string(),
            hovering("quad_x", p.clone(), [0.0, 0.0, 5.0], [0.0; 3]),
        ),
        (
            "x".to_string(),
            hovering("quad_x", p.clone(), [5.0, 0.0, 5.0], [0.0; 3]),
        ),
    ];
    let e = World::new(WorldParams::default(), 1, dup).unwrap_err();
    assert_eq!(e, WorldError::DuplicateName("x".into()));
    assert!(World::new(WorldParams::default(), 1, Vec::<(String, Quadrotor)>::new()).is_err());
    let mut world = World::new(WorldParams::default(), 1, two([3.0, 0.0, 5.0])).unwrap();
    let e = world.set_command(1, &[0.5; 4]).unwrap_err().to_string();
    assert!(
        e.contains("`two`") && e.contains('6') && e.contains('4'),
        "{e}"
    );
    assert!(world.index("three").is_err());
    let before = world.clone();
    world.step(f64::NAN);
    world.step(-1.0);
    assert_eq!(world, before);
}

#[test]
fn a_thousand_vehicles_share_one_world() {
    let params = QuadrotorParams {
        ground_enabled: false,
        ..QuadrotorParams::default()
    };
    let fleet = (0..1024).map(|k| {
        let (x, y) = ((k % 32) as f64, (k / 32) as f64);
        let z = 5.0 + 0.5 * (k % 3) as f64;
        (
            format!("v{k:04}"),
            hovering("quad_x", params.clone(), [x, y, z], [0.0; 3]),
        )
    });
    let mut world = World::new(WorldParams::default(), 2, fleet).unwrap();
    for _ in 0..20 {
        world.step(0.01);
    }
    assert_eq!(world.len(), 1024);
    assert!((0..world.len()).all(|i| {
        world
            .vehicle(i)
            .body()
            .position
            .iter()
            .all(|v| v.is_finite())
    }));
    assert!(world.take_collisions().is_empty());
}
