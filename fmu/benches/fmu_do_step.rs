//! Rust-side cost of one 10 ms fmi2DoStep of Quadrotor through the C ABI, next to the
//! core's own step (the difference is the FMI layer), and of a typical co-simulation step
//! (set 4 inputs, doStep, get 13 outputs). The importer's own cost (fmpy) is measured by
//! benchmarks/fmu_fmpy.py.
//!
//!     cargo bench -p flyloop-fmu --bench fmu_do_step
// Bench code: a failed setup is a failed benchmark.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use criterion::{Criterion, criterion_group, criterion_main};
use flyloop_core::quadrotor::{Quadrotor, QuadrotorInitial, QuadrotorParams};
use flyloop_fmu::exports::*;
use flyloop_fmu::fmi2_types::*;
use flyloop_fmu::importer_logger;
use flyloop_fmu::models::tables;
use std::hint::black_box;

fn instance(hover: f64) -> fmi2Component {
    let callbacks = Box::leak(Box::new(importer_logger::callbacks(
        importer_logger::quiet,
        std::ptr::null_mut(),
    )));
    let table = tables()[0];
    let vr = |name: &str| table.by_name(name).unwrap().value_reference;
    // SAFETY: valid strings, callbacks leaked for the process's lifetime.
    unsafe {
        let c = fmi2Instantiate(
            c"bench".as_ptr(),
            fmi2CoSimulation,
            table.guid_c.as_ptr(),
            std::ptr::null(),
            callbacks,
            fmi2False,
            fmi2False,
        );
        assert!(!c.is_null());
        assert_eq!(
            fmi2SetupExperiment(c, 0, 0.0, 0.0, 0, 0.0),
            fmi2Status::fmi2OK
        );
        assert_eq!(fmi2EnterInitializationMode(c), fmi2Status::fmi2OK);
        let names = ["initial_motor", "seed"];
        let vrs = names.map(vr);
        assert_eq!(fmi2SetReal(c, vrs.as_ptr(), 1, &hover), fmi2Status::fmi2OK);
        assert_eq!(
            fmi2SetInteger(c, vrs[1..].as_ptr(), 1, &1),
            fmi2Status::fmi2OK
        );
        assert_eq!(fmi2ExitInitializationMode(c), fmi2Status::fmi2OK);
        c
    }
}

fn do_step(c: &mut Criterion) {
    let hover = QuadrotorParams::default().hover_motor_state().unwrap();
    let table = tables()[0];

    let fmu = instance(hover);
    let mut n = 0u64;
    c.bench_function("fmi2DoStep_quadrotor_10ms", |b| {
        b.iter(|| {
            // SAFETY: live instance; t is the instance's own grid time.
            let status = unsafe { fmi2DoStep(fmu, black_box(n as f64 * 0.01), 0.01, 0) };
            debug_assert_eq!(status, fmi2Status::fmi2OK);
            n += 1;
        })
    });

    let fmu = instance(hover);
    let inputs: Vec<u32> = (0..4).collect();
    let outputs: Vec<u32> = [
        "x", "y", "z", "vx", "vy", "vz", "qw", "qx", "qy", "qz", "wx", "wy", "wz",
    ]
    .iter()
    .map(|name| table.by_name(name).unwrap().value_reference)
    .collect();
    let command = [hover; 4];
    let mut values = [0.0; 13];
    let mut n = 0u64;
    c.bench_function("set4_doStep_get13_quadrotor_10ms", |b| {
        b.iter(|| {
            // SAFETY: live instance, arrays of the given lengths.
            unsafe {
                fmi2SetReal(fmu, inputs.as_ptr(), 4, command.as_ptr());
                fmi2DoStep(fmu, n as f64 * 0.01, 0.01, 0);
                fmi2GetReal(fmu, outputs.as_ptr(), 13, values.as_mut_ptr());
            }
            black_box(&values);
            n += 1;
        })
    });

    let initial = QuadrotorInitial {
        seed: 1,
        initial_motor: hover,
        ..Default::default()
    };
    let mut quad = Quadrotor::from_initial(QuadrotorParams::default(), &initial).unwrap();
    c.bench_function("core_quadrotor_step_10ms", |b| {
        b.iter(|| quad.step(black_box(0.01)))
    });
}

criterion_group!(benches, do_step);
criterion_main!(benches);
