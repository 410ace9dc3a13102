//! Steps a Hover task (quad X, motor interface, wind on) N times at 10 ms with its observation
//! written each step, for instruction counts that do not depend on the machine's load
//! (docs/performance.md, "The vehicle seam's cost"):
//!
//!     valgrind --tool=callgrind --callgrind-out-file=/dev/null \
//!         target/release/examples/hover_task_cost N
//!
//! The difference between two N is the cost of the steps alone.

use flyloop_core::quadrotor::QuadrotorParams;
use flyloop_core::tasks::Task;
use flyloop_core::tasks::flight::FlightParams;
use flyloop_core::tasks::hover::Hover;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let n: u64 = std::env::args().nth(1).map_or(Ok(0), |a| a.parse())?;
    let flight = FlightParams {
        enable_crash_detection: false,
        enable_out_of_bounds_detection: false,
        max_steps: 100_000_000,
        ..FlightParams::default()
    };
    let mut task = Hover::new(QuadrotorParams::default(), flight)?;
    task.reset(1);
    let action = [0.6; 4];
    let mut observation = vec![0.0f32; task.observation_size()];
    let mut total = 0.0;
    for _ in 0..n {
        total += task.step(std::hint::black_box(&action))?.reward;
        task.write_observation(&mut observation);
    }
    println!(
        "return after {n} steps: {total:.6}, observation[0] {}",
        observation[0]
    );
    Ok(())
}
