//! Reading COMMAND_LONG parameters: the reset command's seed, a message id and an injected
//! failure's PX4 code.
//!
//! COMMAND_LONG carries float32 parameters, which hold integers exactly only up to 2^24, so
//! the 64-bit seed travels in four 16-bit pieces: param1 = bits 0–15, param2 = bits 16–31,
//! param3 = bits 32–47, param4 = bits 48–63, each an integer in [0, 65535]. param5 = 0 uses
//! that seed; param5 = 1 ignores it and takes the vehicle's next seed (SplitMix64 of the
//! previous one). A reset for all vehicles (target_system 0) with an explicit seed gives
//! vehicle k the seed `seed + k − 1` (wrapping).

use crate::vehicle::{Vehicle, next_seed};
use mavlink::dialects::common::{COMMAND_LONG_DATA, MavResult, MavSeverity};

/// Why a reset command was refused.
#[derive(Debug, Clone, Copy, PartialEq, thiserror::Error)]
pub enum ResetError {
    /// param1..4 must each be an integer in [0, 65535].
    #[error("param{param} = {value} is not a 16-bit seed piece (an integer in [0, 65535])")]
    SeedPiece { param: usize, value: f32 },
    /// param5 must be 0 (use the seed) or 1 (next seed).
    #[error("param5 = {value} must be 0 (use the seed) or 1 (next seed)")]
    SeedMode { value: f32 },
}

/// A decoded reset command.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ResetRequest {
    Seed(u64),
    NextSeed,
}

impl ResetRequest {
    /// The seed vehicle `v` is reset with (`all`: the command addressed every vehicle).
    pub fn seed_for(&self, v: &Vehicle, all: bool) -> u64 {
        match *self {
            ResetRequest::Seed(seed) if all => seed.wrapping_add(u64::from(v.system_id) - 1),
            ResetRequest::Seed(seed) => seed,
            ResetRequest::NextSeed => next_seed(v.seed),
        }
    }
}

/// The four float parameters that carry `seed` (for clients and tests).
pub fn seed_params(seed: u64) -> [f32; 4] {
    [0, 16, 32, 48].map(|shift| ((seed >> shift) & 0xFFFF) as f32)
}

/// Decodes a reset command's parameters.
pub fn reset_request(c: &COMMAND_LONG_DATA) -> Result<ResetRequest, ResetError> {
    if c.param5 == 1.0 {
        return Ok(ResetRequest::NextSeed);
    }
    if c.param5 != 0.0 {
        return Err(ResetError::SeedMode { value: c.param5 });
    }
    let mut seed = 0u64;
    for (index, value) in [c.param1, c.param2, c.param3, c.param4]
        .into_iter()
        .enumerate()
    {
        if !(0.0..=65535.0).contains(&value) || value.fract() != 0.0 {
            return Err(ResetError::SeedPiece {
                param: index + 1,
                value,
            });
        }
        seed |= (value as u64) << (16 * index);
    }
    Ok(ResetRequest::Seed(seed))
}

/// A message id carried in a float parameter (an integer in [0, 2^24)).
pub fn message_id(value: f32) -> Option<u32> {
    ((0.0..16_777_216.0).contains(&value) && value.fract() == 0.0).then_some(value as u32)
}

/// The PX4 failure code of MAV_CMD_INJECT_FAILURE: (FAILURE_UNIT from param1, FAILURE_TYPE
/// from param2, instance from param3), each an integer in [0, 255]; the error names the
/// parameter.
pub fn failure_code(c: &COMMAND_LONG_DATA) -> Result<(u8, u8, u8), String> {
    let byte = |name: &str, value: f32| {
        if value.fract() == 0.0 && (0.0..=255.0).contains(&value) {
            Ok(value as u8)
        } else {
            Err(format!("{name} = {value} must be an integer in [0, 255]"))
        }
    };
    Ok((
        byte("param1 (failure_unit)", c.param1)?,
        byte("param2 (failure_type)", c.param2)?,
        byte("param3 (instance)", c.param3)?,
    ))
}

/// The answer to MAV_CMD_INJECT_FAILURE `c`, on every link that takes it: `inject` fires or
/// clears PX4's code (unit, type, instance) and says what it did (ACCEPTED, a WARNING
/// STATUSTEXT), or names the field the catalogue has no fault for (UNSUPPORTED); a parameter
/// that is no integer code is DENIED. The text is the STATUSTEXT to send with the ack.
pub fn inject_outcome(
    c: &COMMAND_LONG_DATA,
    inject: impl FnOnce(u8, u8, u8) -> Result<String, flyloop_core::ParamError>,
) -> (MavResult, MavSeverity, String) {
    match failure_code(c) {
        Err(e) => (
            MavResult::MAV_RESULT_DENIED,
            MavSeverity::MAV_SEVERITY_ERROR,
            format!("inject failure refused: {e}"),
        ),
        Ok((unit, failure, instance)) => match inject(unit, failure, instance) {
            Ok(done) => (
                MavResult::MAV_RESULT_ACCEPTED,
                MavSeverity::MAV_SEVERITY_WARNING,
                done,
            ),
            Err(e) => (
                MavResult::MAV_RESULT_UNSUPPORTED,
                MavSeverity::MAV_SEVERITY_ERROR,
                format!("inject failure refused: {e}"),
            ),
        },
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn command(p: [f32; 5]) -> COMMAND_LONG_DATA {
        COMMAND_LONG_DATA {
            param1: p[0],
            param2: p[1],
            param3: p[2],
            param4: p[3],
            param5: p[4],
            ..Default::default()
        }
    }

    #[test]
    fn a_64_bit_seed_round_trips_through_four_float_pieces() {
        for seed in [0, 1, 0xFFFF, 0x1_0000, 0xDEAD_BEEF_CAFE_F00D, u64::MAX] {
            let [a, b, c, d] = seed_params(seed);
            assert_eq!(
                reset_request(&command([a, b, c, d, 0.0])),
                Ok(ResetRequest::Seed(seed))
            );
        }
        assert_eq!(
            reset_request(&command([9.0, 9.0, 9.0, 9.0, 1.0])),
            Ok(ResetRequest::NextSeed)
        );
    }

    #[test]
    fn bad_pieces_are_refused_naming_the_parameter() {
        let e = reset_request(&command([0.0, 65536.0, 0.0, 0.0, 0.0])).unwrap_err();
        assert_eq!(
            e,
            ResetError::SeedPiece {
                param: 2,
                value: 65536.0
            }
        );
        assert!(reset_request(&command([0.5, 0.0, 0.0, 0.0, 0.0])).is_err());
        assert!(reset_request(&command([f32::NAN, 0.0, 0.0, 0.0, 0.0])).is_err());
        assert!(reset_request(&command([-1.0, 0.0, 0.0, 0.0, 0.0])).is_err());
        assert_eq!(reset_request(&command([0.0; 5])), Ok(ResetRequest::Seed(0)));
        assert!(
            reset_request(&command([0.0, 0.0, 0.0, 0.0, 2.0]))
                .unwrap_err()
                .to_string()
                .contains("param5")
        );
    }

    #[test]
    fn message_ids_must_be_whole_numbers() {
        assert_eq!(message_id(350.0), Some(350));
        assert_eq!(message_id(1.5), None);
        assert_eq!(message_id(-1.0), None);
        assert_eq!(message_id(f32::INFINITY), None);
    }
}
