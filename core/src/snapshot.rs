//! Byte snapshots of a whole model or task state (for the Lander2D: rapier world, RNG,
//! battery, counters and contact flags), and the one envelope every byte state of flyloop
//! uses (the FMU's fmi2FMUstate bytes too, under their own tag).
//!
//! Layout: an 8-byte tag naming the format and its version, the payload length (u64 LE), the
//! postcard payload, and an FNV-1a 64 checksum of the payload (u64 LE). postcard stores every
//! f64 as its 8 bytes, so a restored state continues bit-identically; the tag, the length and
//! the checksum turn foreign or damaged bytes into an error before any of them is decoded.

use serde::Serialize;
use serde::de::DeserializeOwned;

/// Why a snapshot could not be written or read back.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum SnapshotError {
    /// The bytes do not start with the expected format tag (another format or version).
    #[error("not a {expected} snapshot (unknown format tag or version)")]
    WrongFormat { expected: &'static str },
    /// The bytes end before the length they announce, or go on past it.
    #[error("snapshot payload announces {announced} bytes but {available} are present")]
    WrongLength { announced: u64, available: u64 },
    /// The payload does not match its checksum.
    #[error("snapshot payload is damaged (checksum mismatch)")]
    Checksum,
    /// The payload does not decode into the state.
    #[error("snapshot payload does not decode: {0}")]
    Decode(String),
    /// The payload decodes but does not describe a usable state.
    #[error("snapshot describes an invalid state: {0}")]
    Invalid(String),
    /// The state could not be encoded.
    #[error("state could not be encoded: {0}")]
    Encode(String),
}

const HEADER: usize = 16;
const TRAILER: usize = 8;

fn fnv1a64(bytes: &[u8]) -> u64 {
    let mut hash: u64 = 0xcbf2_9ce4_8422_2325;
    for &b in bytes {
        hash ^= u64::from(b);
        hash = hash.wrapping_mul(0x0000_0100_0000_01b3);
    }
    hash
}

/// Encodes `value` behind the 8-byte `tag` (name and version of the format).
pub fn encode<T: Serialize>(tag: &[u8; 8], value: &T) -> Result<Vec<u8>, SnapshotError> {
    let payload = postcard::to_stdvec(value).map_err(|e| SnapshotError::Encode(e.to_string()))?;
    let mut out = Vec::with_capacity(HEADER + payload.len() + TRAILER);
    out.extend_from_slice(tag);
    out.extend_from_slice(&(payload.len() as u64).to_le_bytes());
    out.extend_from_slice(&payload);
    out.extend_from_slice(&fnv1a64(&payload).to_le_bytes());
    Ok(out)
}

/// Decodes bytes written by [`encode`] with the same `tag`; `name` goes into the errors.
/// Foreign, short, long or damaged bytes are an error, never a panic.
pub fn decode<T: DeserializeOwned>(
    tag: &[u8; 8],
    name: &'static str,
    bytes: &[u8],
) -> Result<T, SnapshotError> {
    let wrong_format = SnapshotError::WrongFormat { expected: name };
    let (head, rest) = bytes.split_at_checked(HEADER).ok_or(wrong_format.clone())?;
    if &head[..8] != tag {
        return Err(wrong_format);
    }
    let mut length = [0u8; 8];
    length.copy_from_slice(&head[8..]);
    let announced = u64::from_le_bytes(length);
    let available = rest.len().saturating_sub(TRAILER) as u64;
    if rest.len() < TRAILER || announced != available {
        return Err(SnapshotError::WrongLength {
            announced,
            available,
        });
    }
    let (payload, trailer) = rest.split_at(rest.len() - TRAILER);
    let mut sum = [0u8; 8];
    sum.copy_from_slice(trailer);
    if u64::from_le_bytes(sum) != fnv1a64(payload) {
        return Err(SnapshotError::Checksum);
    }
    let (value, unused) =
        postcard::take_from_bytes(payload).map_err(|e| SnapshotError::Decode(e.to_string()))?;
    if !unused.is_empty() {
        return Err(SnapshotError::Decode(format!(
            "{} bytes left over",
            unused.len()
        )));
    }
    Ok(value)
}

#[cfg(test)]
mod tests {
    use super::*;

    const TAG: &[u8; 8] = b"TESTSNP1";

    #[test]
    fn round_trip_keeps_every_bit() {
        let value = (
            0.1f64,
            -0.0f64,
            f64::MAX,
            f64::MIN_POSITIVE,
            5e-324f64,
            f64::INFINITY,
        );
        let bytes = encode(TAG, &value).unwrap();
        let back: (f64, f64, f64, f64, f64, f64) = decode(TAG, "test", &bytes).unwrap();
        assert_eq!(format!("{value:?}"), format!("{back:?}"));
        assert_eq!(back.1.to_bits(), (-0.0f64).to_bits());
    }

    #[test]
    fn foreign_short_long_and_damaged_bytes_are_errors() {
        let bytes = encode(TAG, &(1u32, 2.5f64)).unwrap();
        let decode = |b: &[u8]| decode::<(u32, f64)>(TAG, "test", b);
        assert!(matches!(
            decode(b""),
            Err(SnapshotError::WrongFormat { .. })
        ));
        assert!(matches!(
            decode(b"garbage bytes, not a snapshot"),
            Err(SnapshotError::WrongFormat { .. })
        ));
        assert!(matches!(
            decode(&bytes[..bytes.len() - 1]),
            Err(SnapshotError::WrongLength { .. })
        ));
        let mut longer = bytes.clone();
        longer.push(0);
        assert!(matches!(
            decode(&longer),
            Err(SnapshotError::WrongLength { .. })
        ));
        let mut damaged = bytes.clone();
        damaged[HEADER] ^= 1;
        assert_eq!(decode(&damaged), Err(SnapshotError::Checksum));
        let other = encode(b"OTHERSN1", &(1u32, 2.5f64)).unwrap();
        assert!(matches!(
            decode(&other),
            Err(SnapshotError::WrongFormat { .. })
        ));
        // A well-formed envelope around a payload of the wrong type.
        let wrong = encode(TAG, &1u8).unwrap();
        assert!(matches!(decode(&wrong), Err(SnapshotError::Decode(_))));
    }
}
