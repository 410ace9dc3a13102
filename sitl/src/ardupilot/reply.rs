//! The JSON line ArduPilot reads after each frame (SIM_JSON.cpp): compact, numbers only,
//! framed by newlines: `\n{"timestamp":T,"imu":{"gyro":[p,q,r],"accel_body":[x,y,z]},
//! "position":[n,e,d],"velocity":[vn,ve,vd],"quaternion":[w,x,y,z]}\n`.
//!
//! ArduPilot's parser finds each key with `strstr` and reads the value right after `":`, so
//! there are no spaces and no other keys that contain these names. Fields ArduPilot stores
//! as floats are written as f32 (shortest exact form); `timestamp` and `position` as f64.

use std::io::Write;

/// The state of one frame, in ArduPilot's frames and units.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct State {
    /// Physics time, s.
    pub timestamp: f64,
    /// Body rates, FRD, rad/s.
    pub gyro: [f64; 3],
    /// Specific force, FRD, m/s² (level at rest: [0, 0, −g]).
    pub accel_body: [f64; 3],
    /// Position from home, NED, m.
    pub position: [f64; 3],
    /// Velocity, NED, m/s.
    pub velocity: [f64; 3],
    /// Attitude body FRD → NED, [w, x, y, z].
    pub quaternion: [f64; 4],
}

/// A finite value, or 0 (ArduPilot would read "NaN" as a number).
fn finite(v: f64) -> f64 {
    if v.is_finite() { v } else { 0.0 }
}

fn floats(out: &mut Vec<u8>, values: &[f64]) {
    out.push(b'[');
    for (i, v) in values.iter().enumerate() {
        if i > 0 {
            out.push(b',');
        }
        // Writing into a Vec cannot fail.
        let _ = write!(out, "{}", finite(*v) as f32);
    }
    out.push(b']');
}

fn doubles(out: &mut Vec<u8>, values: &[f64]) {
    out.push(b'[');
    for (i, v) in values.iter().enumerate() {
        if i > 0 {
            out.push(b',');
        }
        let _ = write!(out, "{}", finite(*v));
    }
    out.push(b']');
}

/// Whether every value of `s` is finite (what is written otherwise is 0).
pub fn is_finite(s: &State) -> bool {
    std::iter::once(s.timestamp)
        .chain(s.gyro)
        .chain(s.accel_body)
        .chain(s.position)
        .chain(s.velocity)
        .chain(s.quaternion)
        .all(f64::is_finite)
}

/// Replaces `out` with the JSON line of `s`.
pub fn write(out: &mut Vec<u8>, s: &State) {
    out.clear();
    let _ = write!(out, "\n{{\"timestamp\":{}", finite(s.timestamp));
    out.extend_from_slice(b",\"imu\":{\"gyro\":");
    floats(out, &s.gyro);
    out.extend_from_slice(b",\"accel_body\":");
    floats(out, &s.accel_body);
    out.extend_from_slice(b"},\"position\":");
    doubles(out, &s.position);
    out.extend_from_slice(b",\"velocity\":");
    floats(out, &s.velocity);
    out.extend_from_slice(b",\"quaternion\":");
    floats(out, &s.quaternion);
    out.extend_from_slice(b"}\n");
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_line_is_compact_framed_and_finite() {
        let s = State {
            timestamp: 1.0 / 1200.0,
            gyro: [0.5, -0.25, 0.0],
            accel_body: [0.0, 0.0, -9.81],
            position: [1.25, -2.0, -0.0538],
            velocity: [0.0, f64::NAN, 1e-3],
            quaternion: [1.0, 0.0, 0.0, 0.0],
        };
        let mut out = vec![b'x'];
        write(&mut out, &s);
        let text = std::str::from_utf8(&out).unwrap();
        assert_eq!(
            text,
            "\n{\"timestamp\":0.0008333333333333334,\"imu\":{\"gyro\":[0.5,-0.25,0],\"accel_body\":[0,0,-9.81]},\
             \"position\":[1.25,-2,-0.0538],\"velocity\":[0,0,0.001],\"quaternion\":[1,0,0,0]}\n"
        );
        assert!(!is_finite(&s));
        assert!(!text.contains(' ') && !text.contains("NaN"));
    }
}
