//! Steps one vehicle N times at 10 ms in flight (wind on, no ground), for instruction counts that do
//! not depend on the machine's load (docs/performance.md):
//!
//!     valgrind --tool=callgrind --callgrind-out-file=/dev/null \
//!         target/release/examples/step_cost N [FRAME]
//!
//! The difference between two N is the cost of the steps alone. FRAME: quad_x (default),
//! quad_plus, hexa_x, octo_x.

use flyloop_core::SimRng;
use flyloop_core::quadrotor::{BodyState, Frame, Quadrotor, QuadrotorParams};
use nalgebra::Vector3;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let n: u64 = args.next().map_or(Ok(0), |a| a.parse())?;
    let frame = Frame::named(&args.next().unwrap_or_else(|| "quad_x".into()))?;
    // In the air all along (no ground to land on): the flight path, not the contact's.
    let params = QuadrotorParams {
        ground_enabled: false,
        ..QuadrotorParams::default()
    };
    let body = BodyState::at_rest(Vector3::new(0.0, 0.0, 1.5), 0.05, -0.03, 0.1, 0.5);
    let mut vehicle = Quadrotor::new(params, body, SimRng::new(1))?.with_frame(frame);
    let hover = vehicle.hover_motor_state().unwrap_or(0.5);
    vehicle.body.motors.iter_mut().for_each(|m| *m = hover);
    vehicle.set_command(vec![hover; vehicle.frame().rotor_count()])?;
    for _ in 0..n {
        vehicle.step(std::hint::black_box(0.01));
    }
    println!("height after {n} steps: {:.6} m", vehicle.body.position.z);
    Ok(())
}
