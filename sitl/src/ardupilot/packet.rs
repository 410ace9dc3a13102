//! ArduPilot's servo packet (SIM_JSON.h): little-endian `magic: u16, frame_rate: u16,
//! frame_count: u32, pwm: [u16; 16]` (40 bytes, magic 18458), or the same with 32 channels
//! (72 bytes, magic 29569, with `SERVO_32_ENABLE = 1`).

/// Magic of the 16-channel packet.
pub const MAGIC_16: u16 = 18458;
/// Magic of the 32-channel packet.
pub const MAGIC_32: u16 = 29569;
/// Bytes of the 16-channel packet.
pub const LEN_16: usize = 8 + 2 * 16;
/// Bytes of the 32-channel packet.
pub const LEN_32: usize = 8 + 2 * 32;
/// PWM of a motor at rest (and of command 0), µs.
pub const PWM_OFF: u16 = 1000;
/// PWM of full thrust (command 1), µs.
pub const PWM_FULL: u16 = 2000;
/// Above this a motor output is absurd (servo pulses stay well below), µs.
pub const MAX_PWM: u16 = 2500;

/// One servo frame from ArduPilot: what flyloop uses of it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ServoFrame {
    /// Physics rate ArduPilot wants, Hz (> 0).
    pub frame_rate: u16,
    /// ArduPilot's frame counter (from 0 at its start).
    pub frame_count: u32,
    /// Servo outputs 1–16, µs: output n + 1 drives rotor n (ArduPilot's motor order for the
    /// shipped frames is the frame table's; `autopilot_params`).
    pub motors: [u16; 16],
}

/// Why a datagram is not a servo frame.
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
pub enum PacketError {
    #[error(
        "{0} bytes is neither a 16-channel ({LEN_16} bytes) nor a 32-channel ({LEN_32} bytes) servo packet"
    )]
    Length(usize),
    #[error(
        "magic {magic} does not match a {len}-byte servo packet (16 channels: {MAGIC_16}, 32 channels: {MAGIC_32})"
    )]
    Magic { magic: u16, len: usize },
    #[error("frame rate 0 Hz")]
    FrameRate,
}

impl PacketError {
    /// A small index per kind (for logging each kind once).
    pub fn kind(&self) -> usize {
        match self {
            PacketError::Length(_) => 0,
            PacketError::Magic { .. } => 1,
            PacketError::FrameRate => 2,
        }
    }
}

fn u16_at(bytes: &[u8], at: usize) -> u16 {
    u16::from_le_bytes([bytes[at], bytes[at + 1]])
}

/// Decodes a servo packet; the length must be exactly that of its magic.
pub fn parse(bytes: &[u8]) -> Result<ServoFrame, PacketError> {
    let expected = match bytes.len() {
        LEN_16 => MAGIC_16,
        LEN_32 => MAGIC_32,
        n => return Err(PacketError::Length(n)),
    };
    let magic = u16_at(bytes, 0);
    if magic != expected {
        return Err(PacketError::Magic {
            magic,
            len: bytes.len(),
        });
    }
    let frame_rate = u16_at(bytes, 2);
    if frame_rate == 0 {
        return Err(PacketError::FrameRate);
    }
    let frame_count = u32::from_le_bytes([bytes[4], bytes[5], bytes[6], bytes[7]]);
    let motors = std::array::from_fn(|i| u16_at(bytes, 8 + 2 * i));
    Ok(ServoFrame {
        frame_rate,
        frame_count,
        motors,
    })
}

/// The core's motor command of one output: (pwm − 1000) / 1000 µs in [0, 1]; 0 (unset) and
/// anything below 1000 µs is off, 2000 µs and above full.
pub fn motor_command(pwm: u16) -> f64 {
    if pwm <= PWM_OFF {
        return 0.0;
    }
    (f64::from(pwm - PWM_OFF) / f64::from(PWM_FULL - PWM_OFF)).min(1.0)
}

/// A 16-channel packet (for tests and tools).
pub fn encode_16(frame_rate: u16, frame_count: u32, pwm: &[u16; 16]) -> Vec<u8> {
    let mut out = Vec::with_capacity(LEN_16);
    out.extend_from_slice(&MAGIC_16.to_le_bytes());
    out.extend_from_slice(&frame_rate.to_le_bytes());
    out.extend_from_slice(&frame_count.to_le_bytes());
    for p in pwm {
        out.extend_from_slice(&p.to_le_bytes());
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn packets_decode_and_bad_ones_say_why() {
        let mut pwm = [0u16; 16];
        pwm[..6].copy_from_slice(&[1100, 1200, 1300, 1400, 1500, 1600]);
        let p = encode_16(1200, 77, &pwm);
        assert_eq!(p.len(), 40);
        assert_eq!(
            parse(&p),
            Ok(ServoFrame {
                frame_rate: 1200,
                frame_count: 77,
                motors: pwm
            })
        );
        // 32 channels: the same head, 72 bytes.
        let mut p32 = p.clone();
        p32[..2].copy_from_slice(&MAGIC_32.to_le_bytes());
        p32.extend_from_slice(&[0u8; 32]);
        assert_eq!(parse(&p32).map(|f| f.motors), Ok(pwm));
        // A 32-channel magic in 40 bytes, a short packet, frame rate 0.
        let mut wrong = p.clone();
        wrong[..2].copy_from_slice(&MAGIC_32.to_le_bytes());
        assert_eq!(
            parse(&wrong),
            Err(PacketError::Magic {
                magic: MAGIC_32,
                len: 40
            })
        );
        assert_eq!(parse(&p[..39]), Err(PacketError::Length(39)));
        assert_eq!(parse(&[]), Err(PacketError::Length(0)));
        let zero_rate = encode_16(0, 1, &pwm);
        assert_eq!(parse(&zero_rate), Err(PacketError::FrameRate));
        let e = PacketError::Length(3).to_string();
        assert!(e.contains("3 bytes"), "{e}");
    }

    #[test]
    fn pwm_maps_linearly_from_1000_to_2000_us() {
        assert_eq!(motor_command(0), 0.0);
        assert_eq!(motor_command(900), 0.0);
        assert_eq!(motor_command(1000), 0.0);
        assert_eq!(motor_command(1500), 0.5);
        assert_eq!(motor_command(1635), 0.635);
        assert_eq!(motor_command(2000), 1.0);
        assert_eq!(motor_command(2200), 1.0);
    }
}
