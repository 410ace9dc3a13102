//! Cost of RateController.fmu through the C ABI: one 4 ms fmi2DoStep (one tick of PX4's rate
//! loop and allocation), and the co-simulation step a master makes each tick (set the 4
//! setpoints and 3 body rates, read the 4 motor commands, doStep). The engines' cost per
//! simulated second of a whole SSP system is measured by benchmarks/ssp_engines.py.
//!
//!     cargo bench -p flyloop-fmu --bench rate_controller_do_step
// Bench code: a failed setup is a failed benchmark.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use criterion::{Criterion, criterion_group, criterion_main};
use flyloop_fmu::exports::*;
use flyloop_fmu::fmi2_types::*;
use flyloop_fmu::models::tables;
use std::hint::black_box;

mod common;

const TICK: f64 = 0.004;

/// An initialised RateController instance.
fn rate_controller() -> fmi2Component {
    let table = tables()[3];
    assert_eq!(table.info.identifier, "RateController");
    let c = common::initializing2(table);
    // SAFETY: a live instance.
    assert_eq!(unsafe { fmi2ExitInitializationMode(c) }, fmi2Status::fmi2OK);
    c
}

fn do_step(c: &mut Criterion) {
    let table = tables()[3];
    let vr = |name: &str| table.by_name(name).unwrap().value_reference;

    let fmu = rate_controller();
    let mut n = 0u64;
    c.bench_function("fmi2DoStep_rate_controller_4ms", |b| {
        b.iter(|| {
            // SAFETY: live instance; t is the instance's own grid time.
            let status = unsafe { fmi2DoStep(fmu, black_box(n as f64 * TICK), TICK, 0) };
            debug_assert_eq!(status, fmi2Status::fmi2OK);
            n += 1;
        })
    });

    let fmu = rate_controller();
    let names = [
        "thrust",
        "roll_rate",
        "pitch_rate",
        "yaw_rate",
        "wx",
        "wy",
        "wz",
    ];
    let inputs = names.map(vr);
    let outputs = [
        "motor_command_0",
        "motor_command_1",
        "motor_command_2",
        "motor_command_3",
    ]
    .map(vr);
    let mut values = [0.0; 4];
    let mut n = 0u64;
    c.bench_function("set7_get4_doStep_rate_controller_4ms", |b| {
        b.iter(|| {
            // Rates that swing, so the filters and the PID see changing inputs.
            let t = n as f64 * TICK;
            let set = [0.5, 0.3 * t.sin(), -0.2, 0.1, 0.05 * t.cos(), 0.01, -0.02];
            // SAFETY: live instance, arrays of the given lengths.
            unsafe {
                fmi2SetReal(fmu, inputs.as_ptr(), 7, set.as_ptr());
                fmi2GetReal(fmu, outputs.as_ptr(), 4, values.as_mut_ptr());
                fmi2DoStep(fmu, t, TICK, 0);
            }
            black_box(&values);
            n += 1;
        })
    });
}

criterion_group!(benches, do_step);
criterion_main!(benches);
