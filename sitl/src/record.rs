//! The recording of the MAVLink modes (`--record FILE`): a MAVLink telemetry log (`.tlog`,
//! the format MAVProxy, MAVExplorer, QGroundControl and pymavlink read): each frame is
//! preceded by 8 bytes, the vehicle's simulation time in µs (big-endian). Per step and
//! vehicle: the ground truth (HIL_STATE_QUATERNION), the motor command (SERVO_OUTPUT_RAW),
//! the wind (WIND_COV) and the task frame (DEBUG_FLOAT_ARRAY: reward, termination,
//! observation, info). Each line announced to the ground station and the controllers (real
//! time: a failsafe, an episode's reset) as STATUSTEXT from its vehicle. The same seeds and
//! commands give the same bytes.

use crate::kinematics::Home;
use crate::telemetry;
use crate::vehicle::Vehicle;
use crate::wire::Encoder;
use mavlink::dialects::common::{MavMessage, MavSeverity};
use std::fs::File;
use std::io::{self, BufWriter, Write};
use std::path::Path;

/// The unsigned MAVLink 2 frames packed back to back in `bytes` (this SITL's own output).
pub(crate) fn frames_of(bytes: &[u8]) -> impl Iterator<Item = &[u8]> {
    let mut rest = bytes;
    std::iter::from_fn(move || {
        let len = 12 + usize::from(*rest.get(1)?);
        let (frame, tail) = rest.split_at(len.min(rest.len()));
        rest = tail;
        Some(frame)
    })
}

/// The message id of a MAVLink 2 frame (bytes 7..10, little-endian).
pub(crate) fn message_id(frame: &[u8]) -> u32 {
    match frame.get(7..10) {
        Some(id) => u32::from_le_bytes([id[0], id[1], id[2], 0]),
        None => u32::MAX,
    }
}

/// A telemetry log file being written: after the first write error nothing more is written
/// (logged once); what is buffered is written when it is dropped.
#[derive(Debug)]
pub struct TlogFile {
    out: BufWriter<File>,
    failed: bool,
}

impl TlogFile {
    /// Creates (truncates) `path`.
    pub fn create(path: &Path) -> io::Result<Self> {
        Ok(TlogFile {
            out: BufWriter::with_capacity(1 << 16, File::create(path)?),
            failed: false,
        })
    }

    /// Appends `bytes` (time-stamped frames).
    pub fn write(&mut self, bytes: &[u8]) {
        if self.failed {
            return;
        }
        if let Err(e) = self.out.write_all(bytes) {
            self.failed = true;
            tracing::error!(error = %e, "cannot write the recording: recording stopped");
        }
    }

    /// Writes what is buffered.
    pub fn flush(&mut self) {
        if let Err(e) = self.out.flush() {
            tracing::error!(error = %e, "cannot write the recording");
        }
    }
}

impl Drop for TlogFile {
    fn drop(&mut self) {
        self.flush();
    }
}

/// A recording being written.
#[derive(Debug)]
pub struct Recorder {
    out: TlogFile,
    encoder: Encoder,
    frame: Vec<u8>,
    /// The last STATUSTEXT id (a long line's chunks share one).
    texts: u16,
}

impl Recorder {
    /// Creates (truncates) `path`.
    pub fn create(path: &Path) -> io::Result<Self> {
        Ok(Recorder {
            out: TlogFile::create(path)?,
            encoder: Encoder::default(),
            frame: Vec::with_capacity(512),
            texts: 0,
        })
    }

    /// Appends a line announced for vehicle `v` (STATUSTEXT, chunked if long, from its system
    /// id at its simulation time).
    pub fn line(&mut self, v: &Vehicle, severity: MavSeverity, text: &str) {
        self.frame.clear();
        self.texts = self.texts.wrapping_add(1).max(1);
        for m in telemetry::statustext(severity, text, self.texts) {
            self.frame.extend_from_slice(&v.clock_us.to_be_bytes());
            self.encoder.push(&mut self.frame, v.system_id, &m);
        }
        self.out.write(&self.frame);
    }

    /// Appends what vehicle `v` did in the step that just ended (or the state a reset made).
    /// `reply`: frames already encoded for this step (a lockstep reply: its
    /// HIL_STATE_QUATERNION and task frame are recorded as they are, not encoded again);
    /// what it lacks is encoded here.
    pub fn step(&mut self, v: &mut Vehicle, home: &Home, reply: &[u8]) {
        self.frame.clear();
        let (time, system_id) = (v.clock_us.to_be_bytes(), v.system_id);
        let (mut has_state, mut has_frame) = (false, false);
        for frame in frames_of(reply) {
            has_state |= message_id(frame) == telemetry::id::HIL_STATE_QUATERNION;
            has_frame |= message_id(frame) == telemetry::id::DEBUG_FLOAT_ARRAY;
            self.frame.extend_from_slice(&time);
            self.frame.extend_from_slice(frame);
        }
        let mut push = |out: &mut Vec<u8>, m: &MavMessage| {
            out.extend_from_slice(&time);
            self.encoder.push(out, system_id, m);
        };
        if !has_state {
            push(&mut self.frame, &telemetry::hil_state_quaternion(v, home));
        }
        push(&mut self.frame, &telemetry::servo_output_raw(v));
        push(&mut self.frame, &telemetry::wind_cov(v));
        if !has_frame {
            let (name, clock) = (v.kind.frame_name(), v.clock_us);
            for m in crate::task_frame::messages(name, clock, v.frame()) {
                push(&mut self.frame, &m);
            }
        }
        self.out.write(&self.frame);
    }

    /// Writes what is buffered (at the stop).
    pub fn flush(&mut self) {
        self.out.flush();
    }
}
