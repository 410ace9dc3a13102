//! Frame changes the sensors need: the core's world ENU / body FLU into the NED / FRD that
//! sensors (and PX4) report in. Each is a proper rotation: 180° about (1, 1, 0)/√2 for
//! ENU → NED, 180° about x for FLU → FRD.

use nalgebra::Vector3;

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
