//! The quadrotor's state: rigid body, motors and wind. Plain data, serde.

use super::frame::MAX_ROTORS;
use nalgebra::{Quaternion, UnitQuaternion, Vector3};
use serde::{Deserialize, Deserializer, Serialize, Serializer};
use std::fmt;
use std::ops::{Deref, DerefMut};

/// One value per rotor (motor states, motor commands), in the frame's motor order: as many
/// as the frame has rotors, at most [`MAX_ROTORS`]. Plain data (`Copy`), so a state with it
/// stays a value; it reads as a slice.
#[derive(Clone, Copy)]
pub struct Motors {
    values: [f64; MAX_ROTORS],
    len: u8,
}

impl Motors {
    /// `count` values of `value` (`count` ≤ [`MAX_ROTORS`], else `None`).
    pub fn uniform(count: usize, value: f64) -> Option<Self> {
        (count <= MAX_ROTORS).then(|| {
            let mut values = [0.0; MAX_ROTORS];
            values[..count].fill(value);
            Motors {
                values,
                len: count as u8,
            }
        })
    }

    /// `count` zeros, `count` capped at [`MAX_ROTORS`] (a frame's count never exceeds it).
    pub(crate) fn zeros(count: usize) -> Self {
        Motors {
            values: [0.0; MAX_ROTORS],
            len: count.min(MAX_ROTORS) as u8,
        }
    }

    /// The values of `slice` (at most [`MAX_ROTORS`], else `None`).
    pub fn from_slice(slice: &[f64]) -> Option<Self> {
        let mut m = Motors::uniform(slice.len(), 0.0)?;
        m.values[..slice.len()].copy_from_slice(slice);
        Some(m)
    }

    /// Every slot, the unused ones (after `len`) zero: what the integrator reads.
    pub(crate) fn padded(&self) -> &[f64; MAX_ROTORS] {
        &self.values
    }

    pub(crate) fn padded_mut(&mut self) -> &mut [f64; MAX_ROTORS] {
        &mut self.values
    }
}

impl<const N: usize> From<[f64; N]> for Motors {
    /// A fixed-size array of at most [`MAX_ROTORS`] values (more is a compile-time mistake in
    /// the caller's code, caught by this assertion in every test that builds it).
    fn from(values: [f64; N]) -> Self {
        const { assert!(N <= MAX_ROTORS) };
        let mut m = Motors {
            values: [0.0; MAX_ROTORS],
            len: N as u8,
        };
        m.values[..N].copy_from_slice(&values);
        m
    }
}

impl Deref for Motors {
    type Target = [f64];
    fn deref(&self) -> &[f64] {
        &self.values[..self.len as usize]
    }
}

impl DerefMut for Motors {
    fn deref_mut(&mut self) -> &mut [f64] {
        &mut self.values[..self.len as usize]
    }
}

impl IntoIterator for Motors {
    type Item = f64;
    type IntoIter = std::iter::Take<std::array::IntoIter<f64, MAX_ROTORS>>;
    fn into_iter(self) -> Self::IntoIter {
        self.values.into_iter().take(self.len as usize)
    }
}

impl<'a> IntoIterator for &'a Motors {
    type Item = &'a f64;
    type IntoIter = std::slice::Iter<'a, f64>;
    fn into_iter(self) -> Self::IntoIter {
        self.iter()
    }
}

impl PartialEq for Motors {
    fn eq(&self, other: &Motors) -> bool {
        **self == **other
    }
}

impl<const N: usize> PartialEq<[f64; N]> for Motors {
    fn eq(&self, other: &[f64; N]) -> bool {
        **self == other[..]
    }
}

impl fmt::Debug for Motors {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        (**self).fmt(f)
    }
}

impl Serialize for Motors {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        (**self).serialize(s)
    }
}

impl<'de> Deserialize<'de> for Motors {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let values = Vec::<f64>::deserialize(d)?;
        Motors::from_slice(&values).ok_or_else(|| {
            serde::de::Error::custom(format!(
                "{} motor values: a frame has at most {MAX_ROTORS}",
                values.len()
            ))
        })
    }
}

/// Rigid body and motor state, in the world ENU / body FLU frames.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct BodyState {
    /// Position of the centre of mass in the world (ENU), m.
    pub position: Vector3<f64>,
    /// Velocity in the world (ENU), m/s.
    pub velocity: Vector3<f64>,
    /// Attitude, body (FLU) → world (ENU), unit quaternion `[w, x, y, z]`.
    pub attitude: Quaternion<f64>,
    /// Angular velocity in the BODY frame (FLU), rad/s.
    pub body_rates: Vector3<f64>,
    /// Lagged motor states in [0, 1], one per rotor in the frame's motor order (the quad X:
    /// front-right, rear-left, front-left, rear-right, PX4's order).
    pub motors: Motors,
    /// Stretch of each foot's friction bristle along the ground (world x, y), m: the
    /// stick-slip state of Coulomb friction (see `contact`). Zero for a foot off the ground.
    pub gear_stretch: [[f64; 2]; 4],
}

impl BodyState {
    /// At rest at `position` with attitude from roll/pitch/yaw (ZYX, rad) and four motors at
    /// `motor` (a vehicle of another frame takes as many as it has rotors, each at `motor`:
    /// [`BodyState::with_motor_count`]).
    pub fn at_rest(position: Vector3<f64>, roll: f64, pitch: f64, yaw: f64, motor: f64) -> Self {
        BodyState {
            position,
            velocity: Vector3::zeros(),
            attitude: *UnitQuaternion::from_euler_angles(roll, pitch, yaw).quaternion(),
            body_rates: Vector3::zeros(),
            motors: Motors::from([motor; 4]),
            gear_stretch: [[0.0; 2]; 4],
        }
    }

    /// This state with `count` motors, each at the first motor's state (unchanged when it has
    /// that many already).
    pub fn with_motor_count(mut self, count: usize) -> Option<Self> {
        if self.motors.len() != count {
            self.motors = Motors::uniform(count, self.motors.first().copied().unwrap_or(0.0))?;
        }
        Some(self)
    }

    /// Roll, pitch, yaw (ZYX Tait–Bryan), rad.
    pub fn euler_angles(&self) -> (f64, f64, f64) {
        UnitQuaternion::new_unchecked(self.attitude).euler_angles()
    }

    /// The body z axis (thrust direction) in the world frame.
    pub fn body_z_axis(&self) -> Vector3<f64> {
        let q = &self.attitude;
        let (w, x, y, z) = (q.w, q.i, q.j, q.k);
        Vector3::new(
            2.0 * (x * z + w * y),
            2.0 * (y * z - w * x),
            1.0 - 2.0 * (x * x + y * y),
        )
    }
}

/// Wind at the vehicle: a mean drawn per episode plus Ornstein–Uhlenbeck turbulence.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct WindState {
    /// Mean wind for the episode (world ENU), m/s.
    pub mean: Vector3<f64>,
    /// Turbulence (world ENU), m/s, held since the last sample.
    pub turbulence: Vector3<f64>,
    /// Time since the last turbulence sample, s, in [0, turbulence_dt).
    pub since_sample: f64,
}

impl WindState {
    /// Total wind velocity (world ENU), m/s.
    pub fn velocity(&self) -> Vector3<f64> {
        self.mean + self.turbulence
    }
}
