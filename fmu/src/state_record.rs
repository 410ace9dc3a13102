//! The bytes of an FMU state (fmi2GetFMUstate / fmi2SerializeFMUstate): an 8-byte format tag,
//! the payload length (u64 LE), the postcard payload and an FNV-1a 64 checksum (u64 LE).
//! The payload holds the model's own snapshot (the core's format, with its own checks) plus
//! the FMU's bookkeeping: stage, experiment, time grid and start values.

use flyloop_core::SnapshotError;
use serde::Serialize;
use serde::de::DeserializeOwned;

const TAG: &[u8; 8] = b"FLYFMI01";
const HEADER: usize = 16;
const TRAILER: usize = 8;
const NAME: &str = "flyloop FMU state";

fn fnv1a64(bytes: &[u8]) -> u64 {
    bytes.iter().fold(0xcbf2_9ce4_8422_2325, |hash, &b| {
        (hash ^ u64::from(b)).wrapping_mul(0x0000_0100_0000_01b3)
    })
}

/// Encodes `record` in the envelope.
pub fn encode<T: Serialize>(record: &T) -> Result<Vec<u8>, SnapshotError> {
    let payload = postcard::to_stdvec(record).map_err(|e| SnapshotError::Encode(e.to_string()))?;
    let mut out = Vec::with_capacity(HEADER + payload.len() + TRAILER);
    out.extend_from_slice(TAG);
    out.extend_from_slice(&(payload.len() as u64).to_le_bytes());
    out.extend_from_slice(&payload);
    out.extend_from_slice(&fnv1a64(&payload).to_le_bytes());
    Ok(out)
}

/// Decodes bytes written by [`encode`]; anything else is an error, never a panic.
pub fn decode<T: DeserializeOwned>(bytes: &[u8]) -> Result<T, SnapshotError> {
    let wrong_format = SnapshotError::WrongFormat { expected: NAME };
    let (head, rest) = bytes.split_at_checked(HEADER).ok_or(wrong_format.clone())?;
    let (tag, length) = head.split_at(8);
    if tag != TAG {
        return Err(wrong_format);
    }
    let announced = length
        .try_into()
        .map(u64::from_le_bytes)
        .map_err(|_| wrong_format)?;
    let available = rest.len().saturating_sub(TRAILER) as u64;
    if rest.len() < TRAILER || announced != available {
        return Err(SnapshotError::WrongLength {
            announced,
            available,
        });
    }
    let (payload, trailer) = rest.split_at(rest.len() - TRAILER);
    let sum = trailer
        .try_into()
        .map(u64::from_le_bytes)
        .map_err(|_| SnapshotError::Checksum)?;
    if sum != fnv1a64(payload) {
        return Err(SnapshotError::Checksum);
    }
    let (record, unused) =
        postcard::take_from_bytes(payload).map_err(|e| SnapshotError::Decode(e.to_string()))?;
    if !unused.is_empty() {
        return Err(SnapshotError::Decode(format!(
            "{} bytes left over",
            unused.len()
        )));
    }
    Ok(record)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_trip_and_every_kind_of_damage() {
        let value = (7u8, -0.0f64, String::from("Quadrotor"), vec![1u8, 2, 3]);
        let bytes = encode(&value).unwrap();
        let back: (u8, f64, String, Vec<u8>) = decode(&bytes).unwrap();
        assert_eq!(back.1.to_bits(), (-0.0f64).to_bits());
        assert_eq!(
            (back.0, back.2.as_str(), back.3),
            (7, "Quadrotor", vec![1, 2, 3])
        );
        type T = (u8, f64, String, Vec<u8>);
        assert!(matches!(
            decode::<T>(b"garbage"),
            Err(SnapshotError::WrongFormat { .. })
        ));
        assert!(matches!(
            decode::<T>(&bytes[..bytes.len() - 1]),
            Err(SnapshotError::WrongLength { .. })
        ));
        let mut damaged = bytes.clone();
        damaged[HEADER + 2] ^= 0x40;
        assert_eq!(decode::<T>(&damaged), Err(SnapshotError::Checksum));
        let wrong = encode(&1u8).unwrap();
        assert!(matches!(decode::<T>(&wrong), Err(SnapshotError::Decode(_))));
    }
}
