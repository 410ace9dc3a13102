//! PX4 mode (`flyloop-sitl --px4`): flyloop as PX4's simulator, the way Gazebo classic and
//! jMAVSim are.
//!
//! The simulator listens on TCP (`--px4-listen`, default 127.0.0.1:4560; PX4 instance k
//! connects to 4560 + k) and speaks MAVLink 2 on the stream: HIL_SENSOR every physics step
//! (IMU, magnetometer, barometer from the core's [`flyloop_core::sensors`]), HIL_GPS at the
//! GPS rate, HIL_STATE_QUATERNION (ground truth) when PX4 asks for it; PX4 answers with
//! HIL_ACTUATOR_CONTROLS whose `controls[0..4]` drive the core's motors 0..3 (the same quad-X
//! order).
//!
//! Lockstep as PX4 expects it: until PX4's first HIL_ACTUATOR_CONTROLS the simulator never
//! waits for PX4 (it steps with the motors off and sends sensors on its own clock, or PX4's
//! start-up would deadlock); from then on each controls message advances the physics by one
//! step (`--px4-step`, 4 ms) and is answered by the sensors of the new time. PX4 has no clock
//! of its own: its time is HIL_SENSOR's `time_usec`. `--speed-factor` paces that time against
//! the wall clock (1 = real time, N = N times real time, 0 = as fast as both can go); PX4 must
//! be started with the same `PX4_SIM_SPEED_FACTOR`.
//!
//! Faults: when PX4 goes away (killed, restarted) the simulator logs it, puts the vehicle and
//! its sensors back to their start state and accepts the next connection; a second
//! connection while one is active is refused with a log line; bad bytes on the stream are
//! counted and skipped; controls with NaN are counted and skipped (the previous command
//! holds, and the step still happens so PX4's lockstep does not stall).
//!
//! - [`messages`]: HIL_SENSOR / HIL_GPS from the core's sensor readings,
//! - [`session`]: one vehicle flown by one PX4 connection, without sockets,
//! - [`server`]: the TCP listener, the pacing and the connection life cycle.

pub mod messages;
pub mod server;
pub mod session;
