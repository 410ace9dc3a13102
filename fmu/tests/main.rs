//! fmu's integration tests, one module per file, linked into one test binary (each file
//! its own binary meant one more link, with LTO in release, per file).
#![allow(clippy::unwrap_used, clippy::expect_used)]

mod support;

mod attitude_controller;
mod fmi3;
mod fmu_state;
mod frame_in_test;
mod lifecycle;
mod misuse;
mod model_description;
mod model_exchange;
mod rate_controller;
mod stepping;
