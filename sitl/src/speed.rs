//! How fast the autopilot modes run: simulated time and the real-time factor, logged at info
//! level every [`PERIOD`] of wall time while an autopilot steps, and summed for the stop line.

use std::fmt;
use std::time::{Duration, Instant};

/// Wall time between two speed lines.
pub const PERIOD: Duration = Duration::from_secs(5);
/// The clock is read on every this many observations only: an observation is one step or
/// frame (up to thousands per second), a line is due every few seconds.
const CHECK_EVERY: u32 = 64;

/// Simulated time against wall time, in windows of about [`PERIOD`]. The session's clock goes
/// back to its start when an autopilot reconnects: the wall time between the last step
/// before and the first after is not counted.
#[derive(Debug, Clone, Default)]
pub struct SpeedLog {
    /// Counted so far: simulated µs and wall time of the closed windows.
    simulated_us: u64,
    wall: Duration,
    /// The open window's start and the last observation (wall, simulated µs).
    start: Option<(Instant, u64)>,
    last: Option<(Instant, u64)>,
    /// Observations until the next look at the clock.
    calls: u32,
}

impl SpeedLog {
    /// The session's clock after a step; a line goes to the log when one is due.
    pub fn observe(&mut self, time_us: u64) {
        self.calls = self.calls.saturating_sub(1);
        if self.start.is_none() || self.calls == 0 {
            self.calls = CHECK_EVERY;
            if let Some(line) = self.observe_at(time_us, Instant::now()) {
                tracing::info!("{line}");
            }
        }
    }

    /// [`Self::observe`] at wall time `now`; returns the line when one is due.
    pub fn observe_at(&mut self, time_us: u64, now: Instant) -> Option<String> {
        let here = Some((now, time_us));
        let (wall_start, start_us) = match (self.start, self.last) {
            (Some(start), Some((_, last_us))) if time_us >= last_us => start,
            // The first step, or the clock went back (a new connection): a new window.
            _ => {
                self.close_window();
                (self.start, self.last) = (here, here);
                return None;
            }
        };
        self.last = here;
        let wall = now.saturating_duration_since(wall_start);
        if wall < PERIOD {
            return None;
        }
        let window_s = (time_us - start_us) as f64 * 1e-6;
        self.close_window();
        (self.start, self.last) = (here, here);
        Some(format!(
            "simulated {:.1} s, {:.1}x real time over the last {:.1} s (overall {:.1}x)",
            self.simulated_us as f64 * 1e-6,
            window_s / wall.as_secs_f64(),
            wall.as_secs_f64(),
            self.factor(),
        ))
    }

    /// Adds the open window (start to last observation) to the totals.
    fn close_window(&mut self) {
        if let (Some((w0, t0)), Some((w1, t1))) = (self.start, self.last) {
            self.simulated_us += t1.saturating_sub(t0);
            self.wall += w1.saturating_duration_since(w0);
        }
        self.start = None;
        self.last = None;
    }

    /// Simulated seconds per wall second over the closed windows (0 before any).
    fn factor(&self) -> f64 {
        let wall = self.wall.as_secs_f64();
        if wall > 0.0 {
            self.simulated_us as f64 * 1e-6 / wall
        } else {
            0.0
        }
    }

    /// The totals for the stop line, the open window included.
    pub fn summary(&self) -> SpeedLog {
        let mut all = self.clone();
        all.close_window();
        all
    }
}

impl fmt::Display for SpeedLog {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "simulated_s={:.3} wall_s={:.3} real_time_factor={:.2}",
            self.simulated_us as f64 * 1e-6,
            self.wall.as_secs_f64(),
            self.factor()
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn at(t0: Instant, ms: u64) -> Instant {
        t0 + Duration::from_millis(ms)
    }

    #[test]
    fn a_line_every_period_with_the_window_and_overall_factors() {
        let t0 = Instant::now();
        let mut log = SpeedLog::default();
        assert_eq!(log.observe_at(4_000, t0), None);
        assert_eq!(log.observe_at(2_004_000, at(t0, 1_000)), None);
        // 5 s of wall time, 50 s simulated: 10x.
        let line = log.observe_at(50_004_000, at(t0, 5_000)).unwrap();
        assert_eq!(
            line,
            "simulated 50.0 s, 10.0x real time over the last 5.0 s (overall 10.0x)"
        );
        // Then 5 s at 2x: the window 2x, overall 6x.
        let line = log.observe_at(60_004_000, at(t0, 10_000)).unwrap();
        assert!(
            line.contains("2.0x real time") && line.contains("overall 6.0x"),
            "{line}"
        );
        assert_eq!(
            log.summary().to_string(),
            "simulated_s=60.000 wall_s=10.000 real_time_factor=6.00"
        );
    }

    #[test]
    fn a_reconnection_does_not_count_the_wall_time_in_between() {
        let t0 = Instant::now();
        let mut log = SpeedLog::default();
        log.observe_at(0, t0);
        log.observe_at(3_000_000, at(t0, 1_000)); // 3x for a second, then PX4 goes away
        log.observe_at(4_000, at(t0, 60_000)); // a new PX4, a minute later
        log.observe_at(3_004_000, at(t0, 61_000));
        let s = log.summary();
        assert_eq!(
            s.to_string(),
            "simulated_s=6.000 wall_s=2.000 real_time_factor=3.00"
        );
        // Nothing observed: zeros, no division by zero.
        assert_eq!(
            SpeedLog::default().summary().to_string(),
            "simulated_s=0.000 wall_s=0.000 real_time_factor=0.00"
        );
    }
}
