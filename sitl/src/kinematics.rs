//! The one place where the models' frames become MAVLink's: the quadrotor's (world ENU,
//! body FLU) and the lander's plane (mapped into ENU/FLU here) become world NED and body
//! FRD, and local metres become latitude / longitude / altitude around the home point.

use nalgebra::{UnitQuaternion, Vector3};

/// Standard gravity for milli-g units (mG), m/s².
pub const STANDARD_GRAVITY: f64 = 9.80665;
use flyloop_core::sensors::Geodetic;
pub use flyloop_core::sensors::gps::EARTH_RADIUS;

/// A vehicle's state in the core's frames (the core's vehicle seam).
pub use flyloop_core::vehicle::Kinematics;

pub use flyloop_core::frames::{attitude_ned, enu_to_ned, flu_to_frd};

/// Roll, pitch, yaw (ZYX) of the NED/FRD attitude, rad; yaw in (−π, π], 0 = north.
pub fn euler_ned(attitude_enu: &UnitQuaternion<f64>) -> (f64, f64, f64) {
    attitude_ned(attitude_enu).euler_angles()
}

/// The home point: the local origin's latitude, longitude (deg) and altitude (m above MSL).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Home {
    pub latitude_deg: f64,
    pub longitude_deg: f64,
    pub altitude_m: f64,
}

impl Default for Home {
    /// PX4's default SITL home (Zürich).
    fn default() -> Self {
        Home {
            latitude_deg: 47.397742,
            longitude_deg: 8.545594,
            altitude_m: 488.0,
        }
    }
}

/// A global position in MAVLink integer units.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct GlobalPosition {
    /// Latitude, degE7.
    pub lat: i32,
    /// Longitude, degE7.
    pub lon: i32,
    /// Altitude above MSL, mm.
    pub alt_mm: i32,
    /// Altitude above home, mm.
    pub relative_alt_mm: i32,
}

impl Home {
    /// Flat-earth (equirectangular) projection of a local ENU position around home:
    /// lat = lat0 + deg(north / R), lon = lon0 + deg(east / (R cos lat0)), alt = alt0 + up,
    /// with R = [`EARTH_RADIUS`]; each rounded to the nearest integer unit.
    pub fn global(&self, position_enu: &Vector3<f64>) -> GlobalPosition {
        let origin = Geodetic {
            latitude_deg: self.latitude_deg,
            longitude_deg: self.longitude_deg,
            altitude_m: self.altitude_m,
        };
        let g = origin.offset(position_enu);
        GlobalPosition {
            lat: round_i32(g.latitude_deg * 1e7),
            lon: round_i32(g.longitude_deg * 1e7),
            alt_mm: round_i32(g.altitude_m * 1000.0),
            relative_alt_mm: round_i32(position_enu.z * 1000.0),
        }
    }
}

/// Nearest integer, saturating at the type's range (NaN → 0).
pub fn round_i32(x: f64) -> i32 {
    x.round() as i32
}

/// Nearest integer, saturating at the type's range (NaN → 0).
pub fn round_i16(x: f64) -> i16 {
    x.round() as i16
}

/// Nearest integer, saturating at the type's range (NaN → 0).
pub fn round_u16(x: f64) -> u16 {
    x.round() as u16
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::{FRAC_PI_2, FRAC_PI_4};

    fn close(a: f64, b: f64) -> bool {
        (a - b).abs() < 1e-12
    }

    #[test]
    fn level_and_facing_east_is_yaw_plus_90_in_ned() {
        let q = attitude_ned(&UnitQuaternion::identity());
        let h = std::f64::consts::FRAC_1_SQRT_2;
        assert!(
            close(q.w, h) && close(q.i, 0.0) && close(q.j, 0.0) && close(q.k, h),
            "{q:?}"
        );
        let (roll, pitch, yaw) = q.euler_angles();
        assert!(close(roll, 0.0) && close(pitch, 0.0) && close(yaw, FRAC_PI_2));
    }

    #[test]
    fn hand_built_attitudes_keep_their_meaning() {
        // ENU yaw is counter-clockwise from east; NED yaw is clockwise from north.
        for (yaw_enu, yaw_ned) in [
            (FRAC_PI_2, 0.0),
            (0.3, FRAC_PI_2 - 0.3),
            (-FRAC_PI_4, 3.0 * FRAC_PI_4),
        ] {
            let q = UnitQuaternion::from_euler_angles(0.0, 0.0, yaw_enu);
            let (r, p, y) = euler_ned(&q);
            assert!(
                close(r, 0.0) && close(p, 0.0) && close(y, yaw_ned),
                "{yaw_enu}: {y}"
            );
        }
        // Facing north (ENU yaw 90°). FLU roll +φ lifts the left side, which is the right
        // side going down: FRD roll +φ too, so roll keeps its sign.
        let q = UnitQuaternion::from_euler_angles(0.2, 0.0, FRAC_PI_2);
        let (r, p, y) = euler_ned(&q);
        assert!(
            close(r, 0.2) && close(p, 0.0) && close(y, 0.0),
            "{r} {p} {y}"
        );
        // FLU pitch +θ about y-left puts the nose down; FRD pitch +θ is nose up.
        let q = UnitQuaternion::from_euler_angles(0.0, 0.25, FRAC_PI_2);
        let (r, p, y) = euler_ned(&q);
        assert!(
            close(r, 0.0) && close(p, -0.25) && close(y, 0.0),
            "{r} {p} {y}"
        );
        // Nose direction check independent of Euler conventions: the body x axis maps to the
        // same physical direction in both frames.
        let q = UnitQuaternion::from_euler_angles(0.1, -0.3, 1.1);
        let forward_enu = q * Vector3::x();
        let forward_ned = attitude_ned(&q) * Vector3::x();
        assert!((enu_to_ned(&forward_enu) - forward_ned).norm() < 1e-12);
        let down_body_enu = q * Vector3::new(0.0, 0.0, -1.0);
        let down_ned = attitude_ned(&q) * Vector3::z();
        assert!((enu_to_ned(&down_body_enu) - down_ned).norm() < 1e-12);
    }

    #[test]
    fn a_level_hover_measures_minus_one_g_on_body_z() {
        let k = Kinematics {
            position: Vector3::new(1.0, 2.0, 3.0),
            velocity: Vector3::new(0.5, -0.25, 1.0),
            attitude: UnitQuaternion::from_euler_angles(0.0, 0.0, 0.7),
            body_rates: Vector3::new(0.1, 0.2, 0.3),
            acceleration: Vector3::zeros(),
            gravity: 9.81,
            air_velocity: Vector3::new(3.0, 4.0, 0.0),
        };
        assert!((k.specific_force_frd() - Vector3::new(0.0, 0.0, -9.81)).norm() < 1e-12);
        assert_eq!(k.position_ned(), Vector3::new(2.0, 1.0, -3.0));
        assert_eq!(k.velocity_ned(), Vector3::new(-0.25, 0.5, -1.0));
        assert_eq!(k.body_rates_frd(), Vector3::new(0.1, -0.2, -0.3));
        assert_eq!(k.airspeed(), 5.0);
    }

    #[test]
    fn a_lander_tilted_counter_clockwise_pitches_nose_up_in_frd() {
        use flyloop_core::lander2d::{Lander2d, Lander2dInitial, Lander2dParams};
        for angle in [0.3, -0.3] {
            let initial = Lander2dInitial {
                initial_x: 12.0,
                initial_y: 30.0,
                initial_angle: angle,
                initial_angular_velocity: 0.5 * angle,
                ..Lander2dInitial::default()
            };
            let lander = Lander2d::from_initial(Lander2dParams::default(), &initial).unwrap();
            let k = lander.kinematics();
            // The nose (body x forward) points east and, for a positive angle, up.
            let nose = k.attitude * Vector3::x();
            assert!(
                close(nose.x, angle.cos()) && close(nose.z, angle.sin()),
                "{nose:?}"
            );
            assert!(close(nose.y, 0.0));
            // In MAVLink's frames that is pitch = +angle (nose up), facing east (yaw 90°),
            // the pitch rate following the angular velocity.
            let (roll, pitch, yaw) = euler_ned(&k.attitude);
            assert!(close(roll, 0.0) && close(pitch, angle) && close(yaw, FRAC_PI_2));
            assert!(
                close(k.body_rates_frd().y, 0.5 * angle),
                "{:?}",
                k.body_rates_frd()
            );
            // The plane is east–up: x east, height up, north 0.
            assert_eq!(k.position, Vector3::new(12.0, 0.0, 30.0));
            assert_eq!(k.position_ned(), Vector3::new(0.0, 12.0, -30.0));
        }
    }

    #[test]
    fn flat_earth_projection_round_trips_to_the_centimetre() {
        let home = Home::default();
        let p = Vector3::new(120.0, -35.5, 12.25);
        let g = home.global(&p);
        let north = (f64::from(g.lat) / 1e7 - home.latitude_deg).to_radians() * EARTH_RADIUS;
        let east = (f64::from(g.lon) / 1e7 - home.longitude_deg).to_radians()
            * EARTH_RADIUS
            * home.latitude_deg.to_radians().cos();
        assert!(
            (north - p.y).abs() < 0.012 && (east - p.x).abs() < 0.012,
            "{north} {east}"
        );
        assert_eq!((g.alt_mm, g.relative_alt_mm), (500_250, 12_250));
        assert_eq!(home.global(&Vector3::zeros()).lat, 473_977_420);
    }

    #[test]
    fn integer_units_saturate_instead_of_wrapping() {
        assert_eq!(round_i16(1e9), i16::MAX);
        assert_eq!(round_i16(-1e9), i16::MIN);
        assert_eq!(round_i16(f64::NAN), 0);
        assert_eq!(round_u16(-5.0), 0);
    }
}
