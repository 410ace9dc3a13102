//! Cost of one Policy.fmu control step through the C ABI (FMI 3.0): set the 28 plant outputs
//! of the hexa hover policy, read its 6 motor commands (one network evaluation by tract),
//! doStep 20 ms; and of the network evaluation alone.
//!
//!     cargo bench -p flyloop-fmu-policy --bench policy_do_step
// Bench code: a failed setup is a failed benchmark.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use criterion::{Criterion, criterion_group, criterion_main};
use flyloop_fmu::exports::*;
use flyloop_fmu::fmi3_types::{fmi3Instance, fmi3Status};
use flyloop_fmu_policy::catalog::table_for;
use std::ffi::CString;
use std::hint::black_box;
use std::path::{Path, PathBuf};

#[path = "../../fmu/benches/common/mod.rs"]
mod common;

fn folder() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../policies/hexa_hover")
}

fn instance() -> fmi3Instance {
    flyloop_fmu_policy::register();
    let table = &table_for(&folder()).unwrap().table;
    let resources = CString::new(folder().display().to_string()).unwrap();
    let c = common::initializing3(table, Some(&resources));
    // SAFETY: a live instance.
    assert_eq!(unsafe { fmi3ExitInitializationMode(c) }, fmi3Status::fmi3OK);
    c
}

fn bench(c: &mut Criterion) {
    let table = &table_for(&folder()).unwrap().table;
    let vr = |name: &str| table.by_name(name).unwrap().value_reference;
    let inputs: Vec<&str> = table
        .variables
        .iter()
        .filter(|v| v.causality == flyloop_core::variables::Causality::Input)
        .map(|v| v.name)
        .collect();
    let input_vrs: Vec<u32> = inputs.iter().map(|n| vr(n)).collect();
    // Level at 1.5 m, motors at the hexa's hover state.
    let hover = (9.81f64 / 60.0).sqrt();
    let values: Vec<f64> = inputs
        .iter()
        .map(|n| match *n {
            "z" => 1.5,
            "qw" => 1.0,
            m if m.starts_with("motor_state") => hover,
            _ => 0.0,
        })
        .collect();
    // FMI 3.0: the array motor_command has the value reference of motor_command_0.
    let output_vrs = [vr("motor_command_0")];
    let instance = instance();
    let mut t = 0.0;
    let mut commands = [0.0; 6];
    c.bench_function("policy_fmu_set_get_do_step_20ms", |b| {
        b.iter(|| {
            // SAFETY: a live instance, arrays of the lengths passed.
            unsafe {
                let set = fmi3SetFloat64(instance, input_vrs.as_ptr(), 28, values.as_ptr(), 28);
                assert_eq!(set, fmi3Status::fmi3OK);
                let got =
                    fmi3GetFloat64(instance, output_vrs.as_ptr(), 1, commands.as_mut_ptr(), 6);
                assert_eq!(got, fmi3Status::fmi3OK);
                let (mut event, mut terminate, mut early, mut last) = (0, 0, 0, 0.0);
                let status = fmi3DoStep(
                    instance,
                    t,
                    0.02,
                    1,
                    &mut event,
                    &mut terminate,
                    &mut early,
                    &mut last,
                );
                assert_eq!(status, fmi3Status::fmi3OK);
            }
            t += 0.02;
            black_box(commands)
        })
    });
    let loaded = flyloop_fmu_policy::catalog::load(&folder()).unwrap();
    let observation = vec![0.1f32; 37];
    c.bench_function("policy_network_tract_37_to_6", |b| {
        b.iter(|| black_box(loaded.network.run(black_box(&observation)).unwrap()))
    });
}

criterion_group!(benches, bench);
criterion_main!(benches);
