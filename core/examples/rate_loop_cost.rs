//! Runs PX4's rate loop (`flyloop_core::rate_loop`) N ticks on its own, for instruction counts
//! that do not depend on the machine's load (docs/performance.md):
//!
//!     valgrind --tool=callgrind --callgrind-out-file=/dev/null \
//!         target/release/examples/rate_loop_cost N [FRAME]
//!
//! The difference between two N is the cost of the ticks alone: gyro filters, the rate PID,
//! the allocation for FRAME's rotors (quad_x, the default: PX4's none_iris; quad_plus, hexa_x,
//! octo_x) and the output steps. The gyro and the setpoint sweep so that the allocator
//! saturates now and then, as in flight.

use flyloop_core::quadrotor::{Frame, QuadrotorParams};
use flyloop_core::rate_loop::{RateLoop, RateLoopParams, RatesSetpoint, px4_rotors};
use nalgebra::Vector3;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let n: u64 = args.next().map_or(Ok(0), |a| a.parse())?;
    let frame = Frame::named(&args.next().unwrap_or_else(|| "quad_x".into()))?;
    let rotors = px4_rotors(&frame, &QuadrotorParams::default());
    let mut rate_loop = RateLoop::new(RateLoopParams::default(), &rotors)?;
    let mut sum = 0.0;
    for k in 0..n {
        let t = k as f64 * 0.004;
        let setpoint = RatesSetpoint {
            thrust: 0.5 + 0.4 * (0.7 * t).sin(),
            rates: Vector3::new((1.3 * t).sin(), (0.9 * t).cos(), 0.5 * (0.4 * t).sin()),
        };
        let gyro = Vector3::new((1.1 * t).sin(), 0.8 * (0.8 * t).cos(), 0.3 * t.sin());
        let motors = rate_loop.step(&setpoint, std::hint::black_box(&gyro), false);
        sum += motors.iter().sum::<f64>();
    }
    println!("{n} ticks, mean motor sum {:.6}", sum / n.max(1) as f64);
    Ok(())
}
