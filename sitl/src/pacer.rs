//! Every wall-clock pacer of the SITL. The autopilot modes (PX4, ArduPilot) run simulation
//! time `speed_factor` times the wall clock, or as fast as the autopilot answers (0)
//! ([`Pacing`], [`Anchor`]); real-time mode's vehicles and the ground-station streams tick at
//! fixed periods ([`Cadence`]).

use std::time::{Duration, Instant};

/// Wall-clock pacing of simulation time.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Pacing {
    /// Simulation seconds per wall second; 0 = as fast as the autopilot answers.
    pub speed_factor: f64,
}

/// Simulation time a paced run may fall behind the wall clock before it stops trying to
/// catch up (a stall does not turn into a burst).
pub const MAX_LAG: Duration = Duration::from_millis(100);
/// Before lockstep at `--speed-factor 0`: free steps this many times faster than real time.
const FREE_RUN_SPEED: f64 = 10.0;

impl Pacing {
    /// Wall time of one step before lockstep.
    pub fn free_step(&self, step_us: u64) -> Duration {
        let speed = if self.speed_factor > 0.0 {
            self.speed_factor
        } else {
            FREE_RUN_SPEED
        };
        Duration::from_secs_f64(step_us as f64 * 1e-6 / speed)
    }

    /// Whether the wall clock paces at all.
    pub fn is_paced(&self) -> bool {
        self.speed_factor > 0.0
    }
}

/// Where the wall clock and simulation time were lined up last.
#[derive(Debug, Clone, Copy)]
pub struct Anchor {
    pub wall: Instant,
    pub sim_us: u64,
}

impl Anchor {
    /// When simulation time `sim_us` is due on the wall clock; re-anchors when far behind
    /// (or when simulation time went back, as after a reset).
    pub fn due(&mut self, sim_us: u64, speed: f64, now: Instant) -> Instant {
        if sim_us < self.sim_us {
            *self = Anchor { wall: now, sim_us };
            return now;
        }
        let ahead = (sim_us - self.sim_us) as f64 * 1e-6 / speed;
        let due = self.wall + Duration::from_secs_f64(ahead);
        if now > due + MAX_LAG {
            *self = Anchor { wall: now, sim_us };
            return now;
        }
        due
    }
}

/// Sleeps until simulation time `sim_us` is due (anchored at the first call), when paced.
pub fn wait_for(pacing: Pacing, anchor: &mut Option<Anchor>, sim_us: u64, start: Instant) {
    if !pacing.is_paced() {
        return;
    }
    let a = anchor.get_or_insert(Anchor {
        wall: start,
        sim_us,
    });
    let now = Instant::now();
    let due = a.due(sim_us, pacing.speed_factor, now);
    if due > now {
        std::thread::sleep(due - now);
    }
}

/// A fixed-period schedule on the wall clock: due once per period, and when it falls a
/// period behind it skips ahead instead of bursting.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Cadence {
    next: Instant,
}

impl Cadence {
    /// First due at `at`.
    pub fn starting(at: Instant) -> Self {
        Cadence { next: at }
    }

    /// When the next tick is due.
    pub fn next(&self) -> Instant {
        self.next
    }

    /// Whether a tick is due at `now`; a due tick is taken (the next one is a period later).
    pub fn take(&mut self, now: Instant, period: Duration) -> bool {
        let due = self.next <= now;
        if due {
            self.next += period;
        }
        due
    }

    /// Still due at `now` after the ticks taken: the next tick a period from now.
    pub fn skip_if_behind(&mut self, now: Instant, period: Duration) {
        if self.next <= now {
            self.next = now + period;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_anchor_paces_catches_up_and_follows_a_reset() {
        let t0 = Instant::now();
        let mut a = Anchor {
            wall: t0,
            sim_us: 1_000_000,
        };
        // 0.5 s of simulation at 2x is due 0.25 s after the anchor.
        let due = a.due(1_500_000, 2.0, t0);
        assert_eq!(due, t0 + Duration::from_millis(250));
        // Far behind: re-anchored now instead of a burst.
        let late = t0 + Duration::from_secs(5);
        assert_eq!(a.due(1_600_000, 2.0, late), late);
        assert_eq!(a.sim_us, 1_600_000);
        // Time back (a reset): re-anchored.
        assert_eq!(a.due(10, 2.0, late), late);
        assert_eq!(a.sim_us, 10);
    }

    #[test]
    fn a_cadence_ticks_once_per_period_and_skips_ahead_when_behind() {
        let t0 = Instant::now();
        let period = Duration::from_millis(10);
        let mut c = Cadence::starting(t0);
        assert!(c.take(t0, period));
        assert!(!c.take(t0, period), "the next tick is a period later");
        assert_eq!(c.next(), t0 + period);
        let late = t0 + Duration::from_millis(35);
        assert!(c.take(late, period));
        assert!(c.take(late, period));
        c.skip_if_behind(late, period);
        assert_eq!(c.next(), late + period, "behind: skipped ahead");
        c.skip_if_behind(late, period);
        assert_eq!(c.next(), late + period, "not behind: unchanged");
    }
}
