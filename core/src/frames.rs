//! The one frames module: the core's world ENU / body FLU into the NED / FRD that sensors,
//! PX4, ArduPilot and MAVLink speak. Each is a proper rotation: 180° about (1, 1, 0)/√2 for
//! ENU → NED, 180° about x for FLU → FRD.

use nalgebra::{Quaternion, UnitQuaternion, Vector3};

/// A world ENU vector in NED: (north, east, down) = (y, x, −z).
pub fn enu_to_ned(v: &Vector3<f64>) -> Vector3<f64> {
    Vector3::new(v.y, v.x, -v.z)
}

/// A world NED vector in ENU (the same swap, its own inverse).
pub fn ned_to_enu(v: &Vector3<f64>) -> Vector3<f64> {
    enu_to_ned(v)
}

/// A body FLU vector in FRD: (x, −y, −z); also FRD → FLU.
pub fn flu_to_frd(v: &Vector3<f64>) -> Vector3<f64> {
    Vector3::new(v.x, -v.y, -v.z)
}

/// ENU → NED as a rotation: 180° about the axis (1, 1, 0)/√2.
fn ned_from_enu() -> UnitQuaternion<f64> {
    let h = std::f64::consts::FRAC_1_SQRT_2;
    UnitQuaternion::new_unchecked(Quaternion::new(0.0, h, h, 0.0))
}

/// FRD → FLU as a rotation: 180° about x.
fn flu_from_frd() -> UnitQuaternion<f64> {
    UnitQuaternion::new_unchecked(Quaternion::new(0.0, 1.0, 0.0, 0.0))
}

/// The attitude body FRD → world NED (what PX4 reports) of an attitude body FLU → world
/// ENU, in the hemisphere w ≥ 0.
pub fn attitude_ned(attitude_enu: &UnitQuaternion<f64>) -> UnitQuaternion<f64> {
    let q = ned_from_enu() * attitude_enu * flu_from_frd();
    if q.w < 0.0 {
        UnitQuaternion::new_unchecked(-q.into_inner())
    } else {
        q
    }
}
