//! sitl's integration tests, one module per file, linked into one test binary (each file
//! its own binary meant one more link, with LTO in release, per file).
#![allow(clippy::unwrap_used, clippy::expect_used)]

mod fleet_paced_start;
mod fleet_waits_for_every_px4;
mod handler_fuzz;
mod inject_failure;
mod link_faults;
mod lockstep_over_udp;
mod lockstep_resend;
mod refused_controls;
mod world_gcs;
mod world_lockstep;
