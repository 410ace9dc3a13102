//! MAVLink 2 frames in and out of UDP datagrams. The `mavlink` crate encodes and decodes
//! payloads; splitting a datagram into frames, and refusing what is not a valid MAVLink 2
//! frame of the common dialect, happens here.

use mavlink::dialects::common::MavMessage;
use mavlink::{MAVLinkV2MessageRaw, MavHeader, MavlinkVersion, Message, MessageData};

const STX_V1: u8 = 0xFE;
const STX_V2: u8 = 0xFD;
const V2_HEADER: usize = 10;
const CHECKSUM: usize = 2;
const SIGNATURE: usize = 13;
const V1_OVERHEAD: usize = 8;
const IFLAG_SIGNED: u8 = 0x01;

/// Why a frame (or the rest of a datagram) was skipped.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FrameError {
    /// The datagram ends inside a frame.
    Truncated,
    /// The checksum does not match.
    BadCrc { message_id: u32 },
    /// A MAVLink 1 frame (this SITL speaks MAVLink 2 only). `controls_from`: the sender's
    /// system id when the frame is an intact HIL_ACTUATOR_CONTROLS (its checksum holds): a
    /// client that forgot MAVLink 2 is told so rather than met with silence.
    MavlinkV1 { controls_from: Option<u8> },
    /// A message id outside the common dialect.
    UnknownMessage { message_id: u32 },
    /// A known message whose payload does not decode (e.g. an enum value out of range), or
    /// an incompatibility flag this SITL does not support.
    Malformed { message_id: u32 },
    /// Bytes that do not start a frame; the rest of the datagram is skipped.
    Garbage,
}

/// A decoded frame.
#[derive(Debug, Clone, PartialEq)]
pub struct Incoming {
    pub header: MavHeader,
    pub message: MavMessage,
}

/// The frames of a datagram, in order, each decoded or with why it was skipped. Frames are
/// packed back to back; after bytes that do not start a frame, or a frame cut short, the rest
/// of the datagram is skipped.
#[derive(Debug, Clone)]
pub struct Frames<'a> {
    rest: &'a [u8],
}

/// Iterates over the frames of `datagram`.
pub fn frames(datagram: &[u8]) -> Frames<'_> {
    Frames { rest: datagram }
}

impl Iterator for Frames<'_> {
    type Item = Result<Incoming, FrameError>;

    fn next(&mut self) -> Option<Self::Item> {
        let rest = self.rest;
        let first = *rest.first()?;
        let (result, used) = match first {
            STX_V2 => decode_v2(rest),
            STX_V1 => match rest.get(1).map(|&len| usize::from(len) + V1_OVERHEAD) {
                Some(n) if n <= rest.len() => (Err(v1_frame(&rest[..n])), Some(n)),
                _ => (Err(FrameError::Truncated), None),
            },
            _ => (Err(FrameError::Garbage), None),
        };
        self.rest = match used {
            Some(n) => &rest[n..],
            None => &[],
        };
        Some(result)
    }
}

/// The error for the whole MAVLink 1 frame `frame` (STX, len, seq, sysid, compid, msgid,
/// payload, checksum): whether it is intact controls, and from whom.
fn v1_frame(frame: &[u8]) -> FrameError {
    use mavlink::dialects::common::HIL_ACTUATOR_CONTROLS_DATA;
    let (id, crc_end) = (
        HIL_ACTUATOR_CONTROLS_DATA::ID,
        frame.len().saturating_sub(CHECKSUM),
    );
    let intact = frame.len() > 6
        && u32::from(frame[5]) == id
        && frame[crc_end..]
            == mavlink::calculate_crc(&frame[1..crc_end], MavMessage::extra_crc(id)).to_le_bytes();
    FrameError::MavlinkV1 {
        controls_from: intact.then(|| frame[3]),
    }
}

/// Decodes the MAVLink 2 frame at the start of `bytes`; also returns its length (None when the
/// datagram ends inside it).
fn decode_v2(bytes: &[u8]) -> (Result<Incoming, FrameError>, Option<usize>) {
    if bytes.len() < V2_HEADER + CHECKSUM {
        return (Err(FrameError::Truncated), None);
    }
    let payload_len = usize::from(bytes[1]);
    let incompat = bytes[2];
    let signature = if incompat & IFLAG_SIGNED != 0 {
        SIGNATURE
    } else {
        0
    };
    let total = V2_HEADER + payload_len + CHECKSUM + signature;
    if bytes.len() < total {
        return (Err(FrameError::Truncated), None);
    }
    let message_id = u32::from_le_bytes([bytes[7], bytes[8], bytes[9], 0]);
    let used = Some(total);
    if MavMessage::default_message_from_id(message_id).is_none() {
        return (Err(FrameError::UnknownMessage { message_id }), used);
    }
    let crc_end = V2_HEADER + payload_len;
    let crc = u16::from_le_bytes([bytes[crc_end], bytes[crc_end + 1]]);
    if crc != mavlink::calculate_crc(&bytes[1..crc_end], MavMessage::extra_crc(message_id)) {
        return (Err(FrameError::BadCrc { message_id }), used);
    }
    if incompat & !IFLAG_SIGNED != 0 {
        return (Err(FrameError::Malformed { message_id }), used);
    }
    let header = MavHeader {
        system_id: bytes[5],
        component_id: bytes[6],
        sequence: bytes[4],
    };
    match MavMessage::parse(MavlinkVersion::V2, message_id, &bytes[V2_HEADER..crc_end]) {
        Ok(message) => (Ok(Incoming { header, message }), used),
        Err(_) => (Err(FrameError::Malformed { message_id }), used),
    }
}

/// Reassembles MAVLink 2 frames from a byte stream (PX4's TCP link), where frames may be
/// split across reads. Bytes that do not start a frame are skipped up to the next start
/// marker (one [`FrameError::Garbage`] per run of them); a frame with a bad checksum or an
/// unknown id is skipped by its start byte only, so a damaged length field cannot swallow the
/// good frames after it.
#[derive(Debug, Clone, Default)]
pub struct StreamDecoder {
    pending: Vec<u8>,
}

/// Bytes kept waiting for the rest of a frame at most (a MAVLink 2 frame is at most 280).
const MAX_PENDING: usize = 1 << 16;

impl StreamDecoder {
    /// Appends bytes read from the stream.
    pub fn push(&mut self, bytes: &[u8]) {
        self.pending.extend_from_slice(bytes);
        if self.pending.len() > MAX_PENDING {
            // Only reachable when the peer floods garbage faster than frames are taken out.
            let cut = self.pending.len() - MAX_PENDING;
            self.pending.drain(..cut);
        }
    }

    /// Bytes waiting for the rest of their frame.
    pub fn pending(&self) -> usize {
        self.pending.len()
    }

    /// Forgets everything buffered (a new connection starts clean).
    pub fn clear(&mut self) {
        self.pending.clear();
    }

    /// The next complete frame (or why bytes were skipped); `None` until more bytes arrive.
    pub fn next_frame(&mut self) -> Option<Result<Incoming, FrameError>> {
        let start = self
            .pending
            .iter()
            .position(|&b| b == STX_V2 || b == STX_V1);
        match start {
            Some(0) => {}
            Some(n) => {
                self.pending.drain(..n);
                return Some(Err(FrameError::Garbage));
            }
            None if self.pending.is_empty() => return None,
            None => {
                self.pending.clear();
                return Some(Err(FrameError::Garbage));
            }
        }
        let (result, used) = if self.pending[0] == STX_V2 {
            decode_v2(&self.pending)
        } else {
            match self
                .pending
                .get(1)
                .map(|&len| usize::from(len) + V1_OVERHEAD)
            {
                Some(n) if n <= self.pending.len() => (Err(v1_frame(&self.pending[..n])), Some(n)),
                _ => (Err(FrameError::Truncated), None),
            }
        };
        let skip = match (&result, used) {
            // Wait for the rest of the frame.
            (Err(FrameError::Truncated), None) => return None,
            (Err(FrameError::BadCrc { .. } | FrameError::UnknownMessage { .. }), _) => 1,
            (_, Some(n)) => n,
            (_, None) => 1,
        };
        self.pending.drain(..skip);
        Some(result)
    }
}

/// Largest datagram this SITL sends; a longer reply is split at frame boundaries.
pub const MAX_DATAGRAM: usize = 60_000;

/// Splits encoded output (unsigned MAVLink 2 frames back to back) into datagrams of at most
/// [`MAX_DATAGRAM`] bytes, at frame boundaries.
pub fn datagrams(bytes: &[u8]) -> impl Iterator<Item = &[u8]> {
    let mut rest = bytes;
    std::iter::from_fn(move || {
        if rest.is_empty() {
            return None;
        }
        let mut end = 0;
        while end < rest.len() {
            let frame = V2_HEADER + CHECKSUM + usize::from(rest.get(end + 1).copied().unwrap_or(0));
            if end > 0 && end + frame > MAX_DATAGRAM {
                break;
            }
            end = (end + frame).min(rest.len());
        }
        let (head, tail) = rest.split_at(end);
        rest = tail;
        Some(head)
    })
}

/// Encodes outgoing frames, with one sequence counter per sending system id, so that the
/// bytes on one link do not depend on traffic on another.
#[derive(Debug, Clone)]
pub struct Encoder {
    sequence: [u8; 256],
    raw: MAVLinkV2MessageRaw,
}

impl Default for Encoder {
    fn default() -> Self {
        Encoder {
            sequence: [0; 256],
            raw: MAVLinkV2MessageRaw::new(),
        }
    }
}

/// The component id every vehicle message is sent from (MAV_COMP_ID_AUTOPILOT1).
pub const VEHICLE_COMPONENT: u8 = 1;

impl Encoder {
    /// Appends `message` from vehicle `system_id` to `out`.
    pub fn push(&mut self, out: &mut Vec<u8>, system_id: u8, message: &MavMessage) {
        let slot = &mut self.sequence[usize::from(system_id)];
        let header = MavHeader {
            system_id,
            component_id: VEHICLE_COMPONENT,
            sequence: *slot,
        };
        *slot = slot.wrapping_add(1);
        self.raw.serialize_message(header, message);
        out.extend_from_slice(self.raw.raw_bytes());
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use mavlink::dialects::common::{
        HEARTBEAT_DATA, HIL_ACTUATOR_CONTROLS_DATA, HilActuatorControlsFlags,
    };

    fn frame(system_id: u8, message: &MavMessage) -> Vec<u8> {
        let mut out = Vec::new();
        Encoder::default().push(&mut out, system_id, message);
        out
    }

    fn controls() -> MavMessage {
        MavMessage::HIL_ACTUATOR_CONTROLS(HIL_ACTUATOR_CONTROLS_DATA {
            controls: [0.5; 16],
            flags: HilActuatorControlsFlags::HIL_ACTUATOR_CONTROLS_FLAGS_LOCKSTEP,
            ..Default::default()
        })
    }

    fn collect(bytes: &[u8]) -> Vec<Result<Incoming, FrameError>> {
        frames(bytes).collect()
    }

    #[test]
    fn several_frames_in_one_datagram_decode_in_order() {
        let mut bytes = frame(3, &controls());
        bytes.extend(frame(7, &MavMessage::HEARTBEAT(HEARTBEAT_DATA::default())));
        let got = collect(&bytes);
        assert_eq!(got.len(), 2);
        let first = got[0].as_ref().unwrap();
        assert_eq!(first.header.system_id, 3);
        assert_eq!(first.message, controls());
        assert_eq!(got[1].as_ref().unwrap().header.system_id, 7);
    }

    #[test]
    fn every_kind_of_bad_frame_is_named_and_the_next_good_frame_survives() {
        let good = frame(1, &controls());
        let mut bad_crc = good.clone();
        let n = bad_crc.len();
        bad_crc[n - 1] ^= 0x55;
        let mut unknown = good.clone();
        unknown[7] = 0xEE;
        unknown[8] = 0xEE;
        let mut v1 = vec![STX_V1, 2, 0, 1, 1, 0, 9, 9, 0, 0];
        v1.extend(&good);
        let mut bytes = bad_crc.clone();
        bytes.extend(&unknown);
        bytes.extend(&v1);
        let got = collect(&bytes);
        assert_eq!(got[0], Err(FrameError::BadCrc { message_id: 93 }));
        assert_eq!(
            got[1],
            Err(FrameError::UnknownMessage { message_id: 0xEEEE })
        );
        assert_eq!(
            got[2],
            Err(FrameError::MavlinkV1 {
                controls_from: None
            })
        );
        assert_eq!(got[3].as_ref().unwrap().message, controls());
        assert_eq!(
            collect(&good[..good.len() - 1]),
            vec![Err(FrameError::Truncated)]
        );
        assert_eq!(collect(&[0x00, 0xFD]), vec![Err(FrameError::Garbage)]);
        assert_eq!(collect(&[STX_V2]), vec![Err(FrameError::Truncated)]);
        assert!(collect(&[]).is_empty());
    }

    #[test]
    fn long_output_is_split_into_datagrams_at_frame_boundaries() {
        let mut enc = Encoder::default();
        let mut out = Vec::new();
        let m = controls();
        while out.len() < 3 * MAX_DATAGRAM {
            enc.push(&mut out, 1, &m);
        }
        let parts: Vec<&[u8]> = datagrams(&out).collect();
        assert_eq!(parts.len(), 4);
        let mut total = 0;
        for p in &parts {
            assert!(p.len() <= MAX_DATAGRAM);
            assert!(frames(p).all(|f| f.is_ok()));
            total += frames(p).count();
        }
        assert_eq!(total, frames(&out).count());
        assert_eq!(datagrams(&[]).count(), 0);
    }

    #[test]
    fn sequence_numbers_count_per_sending_system() {
        let mut enc = Encoder::default();
        let mut out = Vec::new();
        let m = MavMessage::HEARTBEAT(HEARTBEAT_DATA::default());
        enc.push(&mut out, 1, &m);
        enc.push(&mut out, 2, &m);
        enc.push(&mut out, 1, &m);
        let seqs: Vec<(u8, u8)> = collect(&out)
            .into_iter()
            .map(|r| {
                let h = r.unwrap().header;
                (h.system_id, h.sequence)
            })
            .collect();
        assert_eq!(seqs, vec![(1, 0), (2, 0), (1, 1)]);
    }

    #[test]
    fn a_stream_reassembles_split_frames_and_resyncs_after_damage() {
        let good = frame(1, &controls());
        let mut bad_crc = good.clone();
        let n = bad_crc.len();
        bad_crc[n - 1] ^= 0x55;
        let mut bytes = vec![0x00, 0x11, 0x22];
        bytes.extend(&good);
        bytes.extend(&bad_crc);
        bytes.extend(&good);
        let mut decoder = StreamDecoder::default();
        let mut got = Vec::new();
        // Fed one byte at a time: frames split anywhere still come out whole.
        for b in &bytes {
            decoder.push(std::slice::from_ref(b));
            while let Some(f) = decoder.next_frame() {
                got.push(f);
            }
        }
        let good_frames = got.iter().filter(|f| f.is_ok()).count();
        assert_eq!(good_frames, 2, "{got:?}");
        assert_eq!(got[0], Err(FrameError::Garbage));
        assert!(got.contains(&Err(FrameError::BadCrc { message_id: 93 })));
        // A frame cut short waits for its end instead of being an error.
        decoder.push(&good[..good.len() - 3]);
        assert_eq!(decoder.next_frame(), None);
        decoder.push(&good[good.len() - 3..]);
        assert_eq!(decoder.next_frame().unwrap().unwrap().message, controls());
        assert_eq!(decoder.pending(), 0);
    }
}
