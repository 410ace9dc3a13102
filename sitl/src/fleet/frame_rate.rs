//! The physics step an ArduPilot of the fleet asks for with its frame rate, rounded so that
//! its rate can always move.
//!
//! ArduPilot sets its next frame rate from the step it was given: 1 / Δtimestamp, then 1 Hz
//! toward SIM_RATE_HZ, sent truncated to an integer (SIM_JSON.cpp). A step in whole µs is
//! 1 / rate rounded, and the rounding decides whether the ±1 Hz survives the truncation:
//!
//! - climbing needs 1 / step ≥ the rate (step rounded down). An ArduPilot that joins a world
//!   already running gets its join time as its first Δt (from its clock's 0); under 0.1 s
//!   that sets its rate low (joined at t = 0.028 s: 35 Hz), and with the nearest rounding it
//!   stayed there for good (seen: "Gyro 0 rate 52Hz < loop rate", an ArduPilot that would not
//!   arm);
//! - falling needs 1 / step < the rate + 1 (rounded up, from 1000 Hz; below, rounded down
//!   does both). An ArduPilot starts at 1200 Hz whatever SIM_RATE_HZ says and comes down a
//!   hertz a frame.
//!
//! So: rounded down where that does both, else the way the rate last moved. A constant
//! 1200 Hz gives 833 µs and 400 Hz 2500 µs, as the single-vehicle session's nearest rounding.

/// An ArduPilot's last frame rate and which way it last moved.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct FrameRate {
    last: Option<u16>,
    falling: bool,
}

impl FrameRate {
    /// The step of a frame at `rate` Hz, whole µs (at least 1).
    pub fn step_us(&mut self, rate: u16) -> u64 {
        let rate = rate.max(1);
        if let Some(last) = self.last.filter(|&l| l != rate) {
            self.falling = rate < last;
        }
        self.last = Some(rate);
        let r = u64::from(rate);
        let down = 1_000_000 / r;
        // 1 / down < rate + 1 ⇔ down · (rate + 1) > 10⁶: then rounded down lets it fall too.
        if down * (r + 1) > 1_000_000 || !self.falling {
            down.max(1)
        } else {
            1_000_000_u64.div_ceil(r)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::FrameRate;

    /// ArduPilot's next frame rate after a step of `step_us` (SIM_JSON.cpp: `rate_hz =
    /// 1 / Δt` as a float, then one hertz toward `SIM_RATE_HZ`, sent as a truncated u16).
    fn ardupilot_next_rate(step_us: u64, sim_rate_hz: u16) -> u16 {
        let rate = (1.0 / (step_us as f64 * 1e-6)) as f32;
        f32::from(sim_rate_hz).clamp(rate - 1.0, rate + 1.0) as u16
    }

    /// Frames until an ArduPilot at `from` Hz reaches `sim_rate` Hz (and stays), or the rate
    /// it got stuck at.
    fn frames_to(from: u16, sim_rate: u16) -> Result<u32, u16> {
        let mut f = FrameRate::default();
        let mut rate = from;
        let mut frames = 0;
        while rate != sim_rate {
            let next = ardupilot_next_rate(f.step_us(rate), sim_rate);
            if next == rate {
                return Err(rate);
            }
            (rate, frames) = (next, frames + 1);
        }
        assert_eq!(ardupilot_next_rate(f.step_us(rate), sim_rate), rate);
        Ok(frames)
    }

    #[test]
    fn an_ardupilot_rate_climbs_after_a_late_join_and_falls_from_its_start() {
        // Joined 28 ms into its clock (35 Hz), or 19 ms (52 Hz), SIM_RATE_HZ 400 or 1200.
        assert_eq!(frames_to(35, 400), Ok(365));
        assert_eq!(frames_to(35, 1200), Ok(1132));
        assert_eq!(frames_to(52, 1200), Ok(1115));
        // Started at 1200 Hz with SIM_RATE_HZ 400 or 1000; and both ways far apart.
        assert_eq!(frames_to(1200, 400), Ok(767));
        assert_eq!(frames_to(1200, 1000), Ok(167));
        assert!(frames_to(20, 1200).is_ok() && frames_to(1200, 50).is_ok());
        // The nearest rounding sticks climbing, rounded-down-only sticks falling.
        let nearest = |rate: u16| (1e6 / f64::from(rate)).round() as u64;
        assert_eq!(ardupilot_next_rate(nearest(36), 400), 36);
        assert_eq!(ardupilot_next_rate(1_000_000 / 1198, 400), 1198);
        // A constant rate keeps the steps the single-vehicle session gives.
        let mut f = FrameRate::default();
        assert_eq!((f.step_us(1200), f.step_us(1200)), (833, 833));
        assert_eq!((f.step_us(400), f.step_us(0)), (2500, 1_000_000));
    }
}
