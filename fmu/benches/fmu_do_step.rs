//! Rust-side cost of one 10 ms fmi2DoStep / fmi3DoStep of Quadrotor through the C ABI, next
//! to the core's own step (the difference is the FMI layer), and of a typical co-simulation
//! step (set 4 inputs, doStep, get 13 outputs) in both FMI versions. The importer's own cost
//! (fmpy) is measured by benchmarks/fmu_fmpy.py.
//!
//!     cargo bench -p flyloop-fmu --bench fmu_do_step
// Bench code: a failed setup is a failed benchmark.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use criterion::{Criterion, criterion_group, criterion_main};
use flyloop_core::quadrotor::{Quadrotor, QuadrotorInitial, QuadrotorParams};
use flyloop_fmu::exports::*;
use flyloop_fmu::fmi2_types::*;
use flyloop_fmu::fmi3_types::{fmi3Instance, fmi3Status};
use flyloop_fmu::models::tables;
use std::hint::black_box;

mod common;

fn instance(hover: f64) -> fmi2Component {
    let table = tables()[0];
    let vr = |name: &str| table.by_name(name).unwrap().value_reference;
    let c = common::initializing2(table);
    let vrs = ["initial_motor", "seed"].map(vr);
    // SAFETY: a live instance, arrays of the lengths passed.
    unsafe {
        assert_eq!(fmi2SetReal(c, vrs.as_ptr(), 1, &hover), fmi2Status::fmi2OK);
        assert_eq!(
            fmi2SetInteger(c, vrs[1..].as_ptr(), 1, &1),
            fmi2Status::fmi2OK
        );
        assert_eq!(fmi2ExitInitializationMode(c), fmi2Status::fmi2OK);
    }
    c
}

fn instance3(hover: f64) -> fmi3Instance {
    let table = tables()[0];
    let vr = |name: &str| table.by_name(name).unwrap().value_reference;
    let c = common::initializing3(table, None);
    let (motor, seed) = (vr("initial_motor"), vr("seed"));
    // SAFETY: a live instance, one value each.
    unsafe {
        assert_eq!(fmi3SetFloat64(c, &motor, 1, &hover, 1), fmi3Status::fmi3OK);
        assert_eq!(fmi3SetInt32(c, &seed, 1, &1, 1), fmi3Status::fmi3OK);
        assert_eq!(fmi3ExitInitializationMode(c), fmi3Status::fmi3OK);
    }
    c
}

fn do_step3(c: &mut Criterion, hover: f64, outputs: &[u32]) {
    let fmu = instance3(hover);
    let mut n = 0u64;
    let (mut flag, mut last) = (0u8, 0.0);
    c.bench_function("fmi3DoStep_quadrotor_10ms", |b| {
        b.iter(|| {
            // SAFETY: live instance, writable outputs; t is the instance's own grid time.
            let status = unsafe {
                fmi3DoStep(
                    fmu,
                    black_box(n as f64 * 0.01),
                    0.01,
                    0,
                    &mut flag,
                    &mut flag,
                    &mut flag,
                    &mut last,
                )
            };
            debug_assert_eq!(status, fmi3Status::fmi3OK);
            n += 1;
        })
    });

    let fmu = instance3(hover);
    let command = [hover; 4];
    let mut values = [0.0; 13];
    let mut n = 0u64;
    c.bench_function("fmi3_set4_doStep_get13_quadrotor_10ms", |b| {
        b.iter(|| {
            // SAFETY: live instance, arrays of the given lengths (motor_command is one
            // array variable of 4).
            unsafe {
                fmi3SetFloat64(fmu, &0, 1, command.as_ptr(), 4);
                fmi3DoStep(
                    fmu,
                    n as f64 * 0.01,
                    0.01,
                    0,
                    &mut flag,
                    &mut flag,
                    &mut flag,
                    &mut last,
                );
                fmi3GetFloat64(fmu, outputs.as_ptr(), 13, values.as_mut_ptr(), 13);
            }
            black_box(&values);
            n += 1;
        })
    });
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

    do_step3(c, hover, &outputs);

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
