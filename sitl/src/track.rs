//! The flight track of the autopilot modes (`--track FILE`): ground truth as CSV, one row
//! every `--track-interval-us` of simulation time ([`TRACK_INTERVAL_US`] by default), for
//! plots and for checking the autopilot's estimate.
//!
//! Columns: `connection` (1 for the first autopilot, 2 after a reconnect or restart, …),
//! `time_us` (simulation time = the autopilot's clock), `north,east,down` (m from home), `vn,ve,vd` (m/s),
//! `roll,pitch,yaw` (rad, FRD → NED), `m0..m{n-1}` (motor states in [0, 1], one per rotor),
//! `grounded` (0/1),
//! `p,q,r` (body rates, rad/s, FRD),
//! `faults`: the faults that fired or cleared since the previous row, space-separated, each
//! `+label@time` (fired) or `-label@time` (cleared), time in s (`+sensor_off:gps@30.000`,
//! `-link_loss@32.004`); empty when none did.

use crate::autopilot_record::{AutopilotRecorder, Sent};
use crate::kinematics::attitude_ned;
use flyloop_core::faults::FaultEvent;
use flyloop_core::vehicle::Vehicle;
use mavlink::dialects::common::{MavMessage, MavSeverity};
use std::fs::File;
use std::io::{self, BufWriter, Write};
use std::path::Path;

/// Simulation time between two rows by default, µs (50 Hz).
pub const TRACK_INTERVAL_US: u64 = 20_000;

/// The CSV header line of a vehicle with `rotors` rotors.
pub fn header(rotors: usize) -> String {
    format!("connection,time_us,{}", state_header(rotors))
}

/// The columns of a vehicle's state (after `connection,time_us`), `rotors` motor columns,
/// and the fault events.
pub fn state_header(rotors: usize) -> String {
    let motors: Vec<String> = (0..rotors).map(|i| format!("m{i}")).collect();
    format!(
        "north,east,down,vn,ve,vd,roll,pitch,yaw,{},grounded,p,q,r,faults",
        motors.join(",")
    )
}

/// A fault event as the `faults` column writes it: `+label@time` (fired) or `-label@time`
/// (cleared), time in s.
pub fn fault_event(e: &FaultEvent) -> String {
    let sign = if e.fired { '+' } else { '-' };
    format!("{sign}{}@{:.3}", e.label, e.time)
}

/// `vehicle`'s state as the columns of [`state_header`]`(rotors)`, each after a comma (a
/// vehicle with fewer rotors leaves the last motor columns empty), `events` (the `faults`
/// column) and the line's end.
pub fn write_state(
    out: &mut impl Write,
    vehicle: &dyn Vehicle,
    rotors: usize,
    events: &str,
) -> io::Result<()> {
    let k = vehicle.kinematics();
    let p = k.position_ned();
    let v = k.velocity_ned();
    let (roll, pitch, yaw) = attitude_ned(&k.attitude).euler_angles();
    let w = k.body_rates_frd();
    write!(
        out,
        ",{:.4},{:.4},{:.4},{:.4},{:.4},{:.4},{:.5},{:.5},{:.5}",
        p.x, p.y, p.z, v.x, v.y, v.z, roll, pitch, yaw,
    )?;
    let motors = vehicle.actuator_states();
    for m in &motors {
        write!(out, ",{m:.4}")?;
    }
    for _ in motors.len()..rotors {
        write!(out, ",")?;
    }
    writeln!(
        out,
        ",{},{:.5},{:.5},{:.5},{events}",
        u8::from(vehicle.is_grounded()),
        w.x,
        w.y,
        w.z
    )
}

/// A track file being written.
#[derive(Debug)]
pub struct Track {
    out: BufWriter<File>,
    next_us: u64,
    interval_us: u64,
    connection: u32,
    /// Fault events since the last row (the `faults` column).
    events: String,
}

impl Track {
    /// Creates (truncates) `path` and writes the header of a vehicle with `rotors` rotors; a
    /// row every `interval_us`.
    pub fn create(path: &Path, interval_us: u64, rotors: usize) -> io::Result<Self> {
        let mut out = BufWriter::new(File::create(path)?);
        writeln!(out, "{}", header(rotors))?;
        Ok(Track {
            out,
            next_us: 0,
            interval_us,
            connection: 0,
            events: String::new(),
        })
    }

    /// A new autopilot connection: rows from now on carry its number.
    pub fn connect(&mut self) -> io::Result<()> {
        self.connection += 1;
        self.next_us = 0;
        self.out.flush()
    }

    /// Appends a row for `vehicle` at `time_us` when one is due.
    pub fn record(&mut self, time_us: u64, vehicle: &dyn Vehicle) -> io::Result<()> {
        if time_us < self.next_us {
            return Ok(());
        }
        self.next_us = time_us + self.interval_us;
        write!(self.out, "{},{time_us}", self.connection)?;
        write_state(&mut self.out, vehicle, 0, &self.events)?;
        self.events.clear();
        Ok(())
    }

    /// A fault fired or cleared: in the next row's `faults` column.
    pub fn fault_event(&mut self, e: &FaultEvent) {
        if !self.events.is_empty() {
            self.events.push(' ');
        }
        self.events.push_str(&fault_event(e));
    }

    /// Writes buffered rows out.
    pub fn flush(&mut self) -> io::Result<()> {
        self.out.flush()
    }
}

/// What a session writes beside the flight: its track (none, or one being written until a
/// write fails: logged, and the track ends; the flight goes on), the live view's stream
/// (`--view`) and the recording (`--record`), each if asked for.
#[derive(Debug, Default)]
pub struct SessionTrack {
    track: Option<Track>,
    view: Option<crate::view_stream::ViewStream>,
    recording: Option<AutopilotRecorder>,
}

impl SessionTrack {
    /// Writes the ground truth to `track` from now on.
    pub fn set(&mut self, track: Track) {
        self.track = Some(track);
    }

    /// Sends the ground truth to a live view from now on.
    pub fn set_view(&mut self, view: crate::view_stream::ViewStream) {
        self.view = Some(view);
    }

    /// Records every step from now on.
    pub fn set_recording(&mut self, recording: AutopilotRecorder) {
        self.recording = Some(recording);
    }

    /// Whether a recording is made (what only it needs is built only then).
    pub fn is_recording(&self) -> bool {
        self.recording.is_some()
    }

    /// A new autopilot connection (see [`Track::connect`]).
    pub fn connect(&mut self) {
        self.write(Track::connect);
        if let Some(view) = &mut self.view {
            view.connect();
        }
        if let Some(recording) = &mut self.recording {
            recording.connect();
        }
    }

    /// Fault events, into the track's next row.
    pub fn fault_events(&mut self, events: &[FaultEvent]) {
        if let Some(track) = &mut self.track {
            for e in events {
                track.fault_event(e);
            }
        }
    }

    /// A message the autopilot sent, at `time_us`, into the recording.
    pub fn received(&mut self, time_us: u64, system_id: u8, message: &MavMessage) {
        if let Some(recording) = &mut self.recording {
            recording.received(time_us, system_id, message);
        }
    }

    /// A line the session logged at `time_us` (the autopilot in lockstep) into the
    /// recording, as STATUSTEXT (INFO).
    pub fn info(&mut self, time_us: u64, text: &str) {
        if let Some(recording) = &mut self.recording {
            recording.line(time_us, MavSeverity::MAV_SEVERITY_INFO, text);
        }
    }

    /// The lines of faults that fired or cleared at `time_us` into the recording, as
    /// STATUSTEXT (WARNING, as on the control link).
    pub fn fault_lines(&mut self, time_us: u64, lines: &[String]) {
        if let Some(recording) = &mut self.recording {
            for text in lines {
                recording.line(time_us, MavSeverity::MAV_SEVERITY_WARNING, text);
            }
        }
    }

    /// A row for `vehicle` at `time_us` when one is due (and the view's state); the step and
    /// what was `sent` into the recording.
    pub fn record(&mut self, time_us: u64, vehicle: &dyn Vehicle, sent: Sent<'_>) {
        self.write(|track| track.record(time_us, vehicle));
        if let Some(view) = &mut self.view {
            view.send(time_us, vehicle);
        }
        if let Some(recording) = &mut self.recording {
            recording.step(time_us, vehicle, sent);
        }
    }

    /// Writes out buffered rows and recording (on disconnect, silence and shutdown).
    pub fn flush(&mut self) {
        self.write(Track::flush);
        if let Some(recording) = &mut self.recording {
            recording.flush();
        }
    }

    fn write(&mut self, write: impl FnOnce(&mut Track) -> io::Result<()>) {
        let Some(track) = &mut self.track else {
            return;
        };
        if let Err(e) = write(track) {
            tracing::error!(error = %e, "writing the track failed: track stopped");
            self.track = None;
        }
    }
}
