//! Steps a world of V hovering quads (1 m lattice, every third 0.5 m higher; wind field,
//! contact and downwash on) N times at 10 ms — or, with `alone`, the same V vehicles each
//! stepped by itself — for instruction counts that do not depend on the machine's load
//! (docs/performance.md):
//!
//!     valgrind --tool=callgrind --callgrind-out-file=/dev/null \
//!         target/release/examples/world_cost N V [alone]
//!
//! The difference between two N, divided by N·V, is the cost of one vehicle-step.

use flyloop_core::SimRng;
use flyloop_core::quadrotor::{BodyState, Quadrotor, QuadrotorParams};
use flyloop_core::world::{World, WorldParams};
use nalgebra::Vector3;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let n: u64 = args.next().map_or(Ok(0), |a| a.parse())?;
    let count: usize = args.next().map_or(Ok(64), |a| a.parse())?;
    let alone = args.next().as_deref() == Some("alone");
    let side = (count as f64).sqrt().ceil() as usize;
    let params = QuadrotorParams {
        ground_enabled: false,
        ..QuadrotorParams::default()
    };
    let hover = params.hover_motor_state().unwrap_or(0.5);
    let mut fleet = Vec::with_capacity(count);
    for k in 0..count {
        let z = 5.0 + 0.5 * (k % 3) as f64;
        let position = Vector3::new((k % side) as f64, (k / side) as f64, z);
        let body = BodyState::at_rest(position, 0.0, 0.0, 0.0, hover);
        let mut quad = Quadrotor::new(params.clone(), body, SimRng::new(k as u64))?;
        quad.set_command([hover; 4])?;
        fleet.push((format!("v{k:05}"), quad));
    }
    if alone {
        let mut vehicles: Vec<Quadrotor> = fleet.into_iter().map(|(_, q)| q).collect();
        for _ in 0..n {
            vehicles
                .iter_mut()
                .for_each(|q| q.step(std::hint::black_box(0.01)));
        }
        println!(
            "height of the first after {n} steps: {:.6} m",
            vehicles[0].body.position.z
        );
    } else {
        let mut world = World::new(WorldParams::default(), 1, fleet)?;
        for _ in 0..n {
            world.step(std::hint::black_box(0.01));
        }
        println!(
            "height of the first after {n} steps: {:.6} m",
            world.vehicle(0).body().position.z
        );
    }
    Ok(())
}
