//! Magnetometer: the Earth's field at home, from declination, inclination and strength, turned
//! into the body frame, plus white noise. The field is taken as uniform over the flying area.

use crate::frames::{flu_to_frd, ned_to_enu};
use nalgebra::{UnitQuaternion, Vector3};

/// The Earth field in world NED, gauss: horizontal part F·cos I pointing D east of north,
/// vertical part F·sin I down. Angles in degrees.
pub fn earth_field_ned(declination_deg: f64, inclination_deg: f64, strength: f64) -> Vector3<f64> {
    let (d, i) = (declination_deg.to_radians(), inclination_deg.to_radians());
    let horizontal = strength * i.cos();
    Vector3::new(
        horizontal * d.cos(),
        horizontal * d.sin(),
        strength * i.sin(),
    )
}

/// The world NED field `field_ned` seen in body FRD by a body with attitude `attitude`
/// (body FLU → world ENU).
pub fn body_field_frd(attitude: &UnitQuaternion<f64>, field_ned: &Vector3<f64>) -> Vector3<f64> {
    flu_to_frd(&attitude.inverse_transform_vector(&ned_to_enu(field_ned)))
}
