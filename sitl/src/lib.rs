//! flyloop's MAVLink 2 SITL: flies the core's models (flyloop-core) for any MAVLink peer over
//! UDP. The core does all physics; this crate holds the vehicles, speaks MAVLink and keeps the
//! clock. The protocol is documented in docs/protocol.md.
//!
//! - [`sim`]: the datagram handler and the real-time clock's steps (no sockets),
//! - [`server`]: the tokio loop with the sockets and signals,
//! - [`wire`]: frames in and out of datagrams,
//! - [`kinematics`]: the one place where ENU/FLU becomes NED/FRD,
//! - [`task_frame`]: the task frame layout (DEBUG_FLOAT_ARRAY),
//! - [`param_table`], [`param_protocol`]: parameters over MAVLink (the task registry itself is
//!   the core's `flyloop_core::tasks::registry`; a multi-agent world's rows: [`world_params`]),
//! - [`config`]: the parameter file of every mode (the task's, or the autopilot modes' vehicle),
//! - [`px4`]: PX4 mode, flyloop as PX4's simulator over TCP,
//! - [`ardupilot`]: ArduPilot mode, flyloop as ArduPilot's JSON physics backend over UDP,
//! - [`fleet`]: fleet mode, PX4s and ArduPilots flying the vehicles of one world,
//! - [`pacer`]: the wall-clock pacer of both autopilot modes,
//! - [`track`]: their ground-truth track file (`--track`),
//! - [`speed`]: their simulated time and real-time factor in the log.

pub mod app;
pub mod ardupilot;
pub mod autopilot_params;
pub mod autopilot_record;
pub mod cli;
pub mod commands;
pub mod config;
pub mod control_link;
pub mod fleet;
pub mod fuzz;
pub mod gcs_streams;
pub mod kinematics;
pub mod link_line;
pub mod pacer;
pub mod param_protocol;
pub mod param_table;
pub mod px4;
pub mod record;
pub mod server;
pub mod session_faults;
pub mod sim;
pub mod speed;
pub mod starter_config;
pub mod stats;
pub mod task_frame;
pub mod telemetry;
pub mod track;
pub mod vehicle;
pub mod view_stream;
pub mod wire;
pub mod world_params;
