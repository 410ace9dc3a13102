//! GPS receiver: latitude / longitude / altitude from the local ENU position around home
//! (flat-earth projection, exact to millimetres over kilometres), NED velocity, course, a
//! 3D fix, noise, a fixed rate and an optional delivery delay (a delay line of fixes).

use crate::frames::enu_to_ned;
use nalgebra::Vector3;
use serde::{Deserialize, Serialize};
use std::collections::VecDeque;

/// Earth radius of the flat-earth projection (WGS-84 equatorial radius), m.
pub const EARTH_RADIUS: f64 = 6_378_137.0;
/// Below this ground speed the course is unknown, m/s.
pub const MIN_COURSE_SPEED: f64 = 0.1;

/// A geodetic position: latitude and longitude in degrees, altitude above MSL in metres.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Geodetic {
    pub latitude_deg: f64,
    pub longitude_deg: f64,
    pub altitude_m: f64,
}

impl Geodetic {
    /// Flat-earth (equirectangular) projection of `enu` (m) around this point as origin:
    /// lat = lat₀ + deg(north / R), lon = lon₀ + deg(east / (R cos lat₀)), alt = alt₀ + up.
    pub fn offset(&self, enu: &Vector3<f64>) -> Geodetic {
        Geodetic {
            latitude_deg: self.latitude_deg + (enu.y / EARTH_RADIUS).to_degrees(),
            longitude_deg: self.longitude_deg
                + (enu.x / (EARTH_RADIUS * self.latitude_deg.to_radians().cos())).to_degrees(),
            altitude_m: self.altitude_m + enu.z,
        }
    }
}

/// One GPS fix (always a 3D fix).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct GpsFix {
    /// Simulation time the fix describes, s.
    pub measured_at: f64,
    pub position: Geodetic,
    /// Velocity north, east, down, m/s.
    pub velocity_ned: Vector3<f64>,
    /// Horizontal speed, m/s.
    pub ground_speed: f64,
    /// Course over ground, deg in [0, 360) clockwise from north; `None` below
    /// [`MIN_COURSE_SPEED`].
    pub course_deg: Option<f64>,
    /// Reported horizontal and vertical accuracy, m.
    pub eph: f64,
    pub epv: f64,
    pub satellites: u8,
}

/// A fix from a (noisy) local ENU position and velocity.
pub fn fix(
    home: &Geodetic,
    measured_at: f64,
    position_enu: &Vector3<f64>,
    velocity_enu: &Vector3<f64>,
    accuracy: (f64, f64),
    satellites: u8,
) -> GpsFix {
    let velocity_ned = enu_to_ned(velocity_enu);
    let ground_speed = velocity_ned.xy().norm();
    let course_deg = (ground_speed >= MIN_COURSE_SPEED).then(|| {
        velocity_ned
            .y
            .atan2(velocity_ned.x)
            .to_degrees()
            .rem_euclid(360.0)
    });
    GpsFix {
        measured_at,
        position: home.offset(position_enu),
        velocity_ned,
        ground_speed,
        course_deg,
        eph: accuracy.0,
        epv: accuracy.1,
        satellites,
    }
}

/// The receiver's timing: when the next fix is taken, and fixes taken but not yet delivered.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct GpsTiming {
    /// Simulation time of the next fix, s.
    pub next_fix: f64,
    /// Fixes in flight, oldest first.
    pub pending: VecDeque<GpsFix>,
}

impl GpsTiming {
    /// Whether a fix is due at `time` (s); if so the next one is scheduled one period later.
    /// Times are compared with a tolerance of a microsecond, so 0.1 s periods do not slip.
    pub fn take_due(&mut self, time: f64, rate: f64) -> bool {
        if time + 1e-6 < self.next_fix {
            return false;
        }
        let period = 1.0 / rate;
        // A long pause (or a lower rate) skips missed fixes instead of catching up.
        self.next_fix = (self.next_fix + period).max(time + period - 1e-6);
        true
    }

    /// The oldest pending fix if it is at least `delay` s old at `time`.
    pub fn deliver(&mut self, time: f64, delay: f64) -> Option<GpsFix> {
        let ready = self
            .pending
            .front()
            .is_some_and(|f| f.measured_at + delay <= time + 1e-6);
        if ready {
            self.pending.pop_front()
        } else {
            None
        }
    }
}
