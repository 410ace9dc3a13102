//! core's integration tests, one module per file, linked into one test binary (each file
//! its own binary meant one more link, with LTO in release, per file).
#![allow(clippy::unwrap_used, clippy::expect_used)]

mod air_vehicle_seam;
mod faults;
mod frame_tasks;
mod lander2d_golden;
mod lander2d_grid;
mod lander2d_landing;
mod lander2d_model;
mod lander2d_reward;
mod multi_agent;
mod multi_agent_faults;
mod multirotor_frames;
mod parameter_reference;
mod quadrotor_golden;
mod quadrotor_grid;
mod quadrotor_ground;
mod quadrotor_physics;
mod quadrotor_rates;
mod quadrotor_tasks;
mod quadrotor_wind_grid;
mod trace_hash;
mod vehicle_seam;
mod world;
