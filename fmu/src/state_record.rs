//! The bytes of an FMU state (fmi2GetFMUstate / fmi2SerializeFMUstate): the core's snapshot
//! envelope ([`flyloop_core::snapshot`]: tag, length, checksum) under the FMU's own tag.
//! The payload holds the model's own snapshot (the core's format, with its own checks) plus
//! the FMU's bookkeeping: stage, experiment, time grid and start values.

use flyloop_core::SnapshotError;
use flyloop_core::snapshot;
use serde::Serialize;
use serde::de::DeserializeOwned;

const TAG: &[u8; 8] = b"FLYFMI01";
const NAME: &str = "flyloop FMU state";

/// Encodes `record` in the envelope.
pub fn encode<T: Serialize>(record: &T) -> Result<Vec<u8>, SnapshotError> {
    snapshot::encode(TAG, record)
}

/// Decodes bytes written by [`encode`]; anything else is an error, never a panic.
pub fn decode<T: DeserializeOwned>(bytes: &[u8]) -> Result<T, SnapshotError> {
    snapshot::decode(TAG, NAME, bytes)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_trip_under_the_fmu_tag_and_no_other() {
        let value = (7u8, -0.0f64, String::from("Quadrotor"), vec![1u8, 2, 3]);
        let bytes = encode(&value).unwrap();
        assert_eq!(&bytes[..8], TAG);
        let back: (u8, f64, String, Vec<u8>) = decode(&bytes).unwrap();
        assert_eq!(back.1.to_bits(), (-0.0f64).to_bits());
        assert_eq!(
            (back.0, back.2.as_str(), back.3),
            (7, "Quadrotor", vec![1, 2, 3])
        );
        // A core snapshot (another tag) is not an FMU state.
        let foreign = snapshot::encode(b"FLYQUA01", &value).unwrap();
        assert_eq!(
            decode::<(u8, f64, String, Vec<u8>)>(&foreign),
            Err(SnapshotError::WrongFormat { expected: NAME })
        );
    }
}
