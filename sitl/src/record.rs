//! The recording of the MAVLink modes (`--record FILE`): a MAVLink telemetry log (`.tlog`,
//! the format MAVProxy, MAVExplorer, QGroundControl and pymavlink read): each frame is
//! preceded by 8 bytes, the vehicle's simulation time in µs (big-endian). Per step and
//! vehicle: the ground truth (HIL_STATE_QUATERNION), the motor command (SERVO_OUTPUT_RAW),
//! the wind (WIND_COV) and the task frame (DEBUG_FLOAT_ARRAY: reward, termination,
//! observation, info). The same seeds and commands give the same bytes.

use crate::kinematics::Home;
use crate::telemetry;
use crate::vehicle::Vehicle;
use crate::wire::Encoder;
use std::fs::File;
use std::io::{self, BufWriter, Write};
use std::path::Path;

/// A recording being written.
#[derive(Debug)]
pub struct Recorder {
    out: BufWriter<File>,
    encoder: Encoder,
    frame: Vec<u8>,
    /// The first write error (later steps are not recorded; logged once).
    failed: bool,
}

impl Recorder {
    /// Creates (truncates) `path`.
    pub fn create(path: &Path) -> io::Result<Self> {
        Ok(Recorder {
            out: BufWriter::with_capacity(1 << 16, File::create(path)?),
            encoder: Encoder::default(),
            frame: Vec::with_capacity(512),
            failed: false,
        })
    }

    /// Appends what vehicle `v` did in the step that just ended (or the state a reset made).
    pub fn step(&mut self, v: &mut Vehicle, home: &Home) {
        if self.failed {
            return;
        }
        let time = v.clock_us.to_be_bytes();
        self.frame.clear();
        let mut messages = vec![
            telemetry::hil_state_quaternion(v, home),
            telemetry::servo_output_raw(v),
            telemetry::wind_cov(v),
        ];
        let (name, clock) = (v.kind.frame_name(), v.clock_us);
        messages.extend(crate::task_frame::messages(name, clock, v.frame()));
        let mut result = Ok(());
        for m in &messages {
            self.frame.clear();
            self.encoder.push(&mut self.frame, v.system_id, m);
            result = result
                .and_then(|()| self.out.write_all(&time))
                .and_then(|()| self.out.write_all(&self.frame));
        }
        if let Err(e) = result {
            self.failed = true;
            tracing::error!(error = %e, "cannot write the recording: recording stopped");
        }
    }

    /// Writes what is buffered (at the stop).
    pub fn flush(&mut self) {
        if let Err(e) = self.out.flush() {
            tracing::error!(error = %e, "cannot write the recording");
        }
    }
}

impl Drop for Recorder {
    fn drop(&mut self) {
        self.flush();
    }
}
