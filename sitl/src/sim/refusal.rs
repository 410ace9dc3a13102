//! Controls this SITL will not act on, and how their sender hears of it (protocol §12): each
//! refusal is counted under its own counter and answered with a STATUSTEXT (WARNING) to the
//! peer that sent it, at most [`TEXTS_PER_WINDOW`] per peer per [`TEXT_WINDOW`], so a flood
//! of refused commands is answered without being echoed back as a flood. The first text
//! after a held-back run says how many refusals went unanswered.

use crate::stats::Stats;
use flyloop_core::tasks::registry::ControlError;
use std::net::SocketAddr;
use std::time::{Duration, Instant};

/// Why a HIL_ACTUATOR_CONTROLS was not stepped (nor, in real time, set).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum Refusal {
    /// Its header system id is no vehicle's (vehicles are 1..=`vehicles`).
    UnknownVehicle { system_id: u8, vehicles: usize },
    /// Lockstep mode, and the LOCKSTEP flag (bit 0 of `flags`) is not set.
    NotLockstep { flags: u64 },
    /// A used channel is NaN or infinite.
    BadValue(ControlError),
    /// It names a step older than the vehicle's clock (`clock_us`): a late duplicate.
    LateDuplicate { step: u64, clock_us: u64 },
    /// It names the vehicle's last step, which a reset has since ended.
    BeforeReset { step: u64 },
    /// A multi-agent world: it names another step than the one whose commands are being
    /// gathered (`gathering`, named by an earlier command of the step).
    OtherStep { step: u64, gathering: u64 },
    /// It came in on the ground-station link, which flies nothing.
    GcsLink,
    /// An intact MAVLink 1 frame from `system_id` (this SITL reads MAVLink 2 only).
    MavlinkV1 { system_id: u8 },
}

impl Refusal {
    /// Counts this refusal in `stats`.
    pub(crate) fn count(&self, stats: &mut Stats) {
        match self {
            Refusal::UnknownVehicle { .. } => stats.unknown_vehicle += 1,
            Refusal::NotLockstep { .. } => stats.unflagged_controls += 1,
            Refusal::BadValue(_) => stats.refused_controls += 1,
            Refusal::LateDuplicate { .. }
            | Refusal::BeforeReset { .. }
            | Refusal::OtherStep { .. } => stats.stale_controls += 1,
            Refusal::GcsLink => stats.gcs_controls += 1,
            // Counted with every MAVLink 1 frame (`mavlink1`) when it was skipped.
            Refusal::MavlinkV1 { .. } => {}
        }
    }

    /// What the STATUSTEXT says: which system, why, and that nothing was stepped.
    pub(crate) fn text(&self, system_id: u8) -> String {
        let why = match *self {
            Refusal::UnknownVehicle {
                system_id,
                vehicles,
            } => {
                return format!(
                    "system {system_id}: no such vehicle (system ids 1..{vehicles}): step refused"
                );
            }
            Refusal::MavlinkV1 { system_id } => {
                return format!(
                    "system {system_id}: controls in MAVLink 1, which this SITL does not read \
                     (pymavlink: set MAVLINK20=1): step refused"
                );
            }
            Refusal::NotLockstep { flags } => {
                format!("controls without the LOCKSTEP flag (flags = {flags}) in lockstep mode")
            }
            // The core's message already ends in ": step refused".
            Refusal::BadValue(e) => return format!("vehicle {system_id}: {e}"),
            Refusal::LateDuplicate { step, clock_us } => {
                format!(
                    "time_usec {step} is older than the clock, {clock_us} us (a late duplicate)"
                )
            }
            Refusal::BeforeReset { step } => {
                format!("time_usec {step} names the last step before a reset (a late duplicate)")
            }
            Refusal::OtherStep { step, gathering } => {
                format!(
                    "time_usec {step} is not the step being gathered, {gathering} (every \
                     vehicle's command of a step names it alike)"
                )
            }
            Refusal::GcsLink => {
                "controls on the ground-station link are not flown (send them to --listen)".into()
            }
        };
        format!("vehicle {system_id}: {why}: step refused")
    }
}

/// Refusal texts one peer gets per window at most.
pub const TEXTS_PER_WINDOW: u32 = 5;
/// The rate limit's window: [`TEXTS_PER_WINDOW`] texts per peer per second.
pub const TEXT_WINDOW: Duration = Duration::from_secs(1);
/// Peers whose budget is remembered at once (the one with the oldest window is forgotten).
const MAX_PEERS: usize = 64;

/// One peer's refusal texts in its current window.
#[derive(Debug, Clone, Copy)]
struct PeerBudget {
    addr: SocketAddr,
    window_start: Instant,
    sent: u32,
    /// Refusals not answered since the peer's last text.
    held: u64,
}

/// The per-peer rate limit of refusal texts (wall clock: it only thins out answers to
/// refused input, never a step's reply, so the lockstep stays deterministic).
#[derive(Debug, Default)]
pub(crate) struct TextBudget {
    peers: Vec<PeerBudget>,
}

impl TextBudget {
    /// Whether a refusal may be answered to `addr` at `now`: `Some(held)` with the number of
    /// refusals held back since its last text, or `None` (this one is held back).
    pub(crate) fn take(&mut self, addr: SocketAddr, now: Instant) -> Option<u64> {
        let i = match self.peers.iter().position(|p| p.addr == addr) {
            Some(i) => i,
            None => {
                if self.peers.len() >= MAX_PEERS {
                    let oldest = (0..self.peers.len()).min_by_key(|&i| self.peers[i].window_start);
                    if let Some(oldest) = oldest {
                        self.peers.swap_remove(oldest);
                    }
                }
                self.peers.push(PeerBudget {
                    addr,
                    window_start: now,
                    sent: 0,
                    held: 0,
                });
                self.peers.len() - 1
            }
        };
        let p = &mut self.peers[i];
        if now.saturating_duration_since(p.window_start) >= TEXT_WINDOW {
            p.window_start = now;
            p.sent = 0;
        }
        if p.sent >= TEXTS_PER_WINDOW {
            p.held += 1;
            return None;
        }
        p.sent += 1;
        Some(std::mem::take(&mut p.held))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn five_texts_per_peer_per_second_and_the_next_says_how_many_were_held() {
        let mut budget = TextBudget::default();
        let a: SocketAddr = "127.0.0.1:1000".parse().unwrap();
        let b: SocketAddr = "127.0.0.1:1001".parse().unwrap();
        let t0 = Instant::now();
        let answered = (0..100).filter(|_| budget.take(a, t0).is_some()).count();
        assert_eq!(answered, 5);
        // Another peer has its own budget.
        assert_eq!(budget.take(b, t0), Some(0));
        assert_eq!(budget.take(a, t0 + Duration::from_millis(999)), None);
        // A new window: the first text counts the 96 held back.
        assert_eq!(budget.take(a, t0 + TEXT_WINDOW), Some(96));
        assert_eq!(budget.take(a, t0 + TEXT_WINDOW), Some(0));
    }

    #[test]
    fn every_refusal_names_its_system_and_says_the_step_was_refused() {
        let refusals = [
            Refusal::UnknownVehicle {
                system_id: 7,
                vehicles: 2,
            },
            Refusal::NotLockstep { flags: 0 },
            Refusal::BadValue(ControlError::NotFinite {
                channel: 2,
                value: f32::NAN,
            }),
            Refusal::LateDuplicate {
                step: 10_000,
                clock_us: 30_000,
            },
            Refusal::BeforeReset { step: 30_000 },
            Refusal::GcsLink,
            Refusal::MavlinkV1 { system_id: 1 },
        ];
        let texts: Vec<String> = refusals.iter().map(|r| r.text(1)).collect();
        assert_eq!(
            texts[0],
            "system 7: no such vehicle (system ids 1..2): step refused"
        );
        assert_eq!(texts[2], "vehicle 1: controls[2] = NaN: step refused");
        assert_eq!(
            texts[3],
            "vehicle 1: time_usec 10000 is older than the clock, 30000 us (a late duplicate): \
             step refused"
        );
        assert!(texts.iter().all(|t| t.ends_with(": step refused")));
        let mut stats = Stats::default();
        for r in &refusals {
            r.count(&mut stats);
        }
        let counted = (
            stats.unknown_vehicle,
            stats.unflagged_controls,
            stats.refused_controls,
            stats.stale_controls,
            stats.gcs_controls,
        );
        assert_eq!(counted, (1, 1, 1, 2, 1));
    }
}
