//! ArduPilot mode (`flyloop-sitl --ardupilot`): flyloop as ArduPilot's external physics, through
//! ArduPilot's JSON interface (`--model JSON` of an ArduPilot SITL build, SIM_JSON.cpp).
//!
//! ArduPilot sends its servo outputs as one binary packet per physics frame to UDP
//! (`--ardupilot-listen`, default 127.0.0.1:9002; ArduPilot instance k sends to 9002 + 10k)
//! and waits for the answer: one JSON line with the state after the frame (IMU, NED position
//! and velocity, attitude). ArduPilot computes GPS, barometer and magnetometer itself.
//!
//! Lockstep as ArduPilot expects it: each new frame count is one physics step of
//! 1 / frame_rate s (the rate ArduPilot puts in the packet) and one reply; the same frame count
//! again (ArduPilot re-sends after a second without an answer) is answered again with the same
//! reply, without stepping; `timestamp` is physics time. `--speed-factor` paces physics time
//! against the wall clock as in PX4 mode (0 = as fast as ArduPilot sends; ArduPilot's own
//! `--speedup` paces it too, and the slower of the two wins).
//!
//! Motors: servo outputs 1–4 drive the core's motors 0–3 (ArduPilot's quad-X order is the
//! core's: front-right, rear-left, front-left, rear-right). Mapping: command = (pwm − 1000) /
//! 1000 µs, clamped to [0, 1]; 0 (an unset output) and anything below 1000 µs is off.
//!
//! Faults: a frame count going back (ArduPilot restarted, or a new one after a kill) is
//! logged, the vehicle goes back to its start state and physics time to 0, and the new one is
//! served; silence is logged once. Malformed packets (wrong magic, wrong length, frame rate 0)
//! are counted, logged once per kind and not answered; absurd PWM (a motor output above
//! [`packet::MAX_PWM`] µs) is counted and logged once, the previous command holds, and the
//! frame is still stepped and answered so ArduPilot's lockstep never stalls.
//!
//! - [`packet`]: the servo packet (16 or 32 channels) and its errors,
//! - [`faulted_imu`]: the IMU through the sensor faults,
//! - [`reply`]: the JSON line,
//! - [`session`]: one vehicle flown by ArduPilot, without sockets,
//! - [`server`]: the UDP socket, pacing and silence.

pub mod faulted_imu;
pub mod packet;
pub mod reply;
pub mod server;
pub mod session;
