//! The fleet's clock: a lockstep barrier over autopilots that step at different rates.
//!
//! Simulation time `now` (whole µs) belongs to the world. Each autopilot i got its last
//! sensors (PX4) or state (ArduPilot) at its own time tᵢ ≤ now and asks for a step of its
//! own length sᵢ (PX4 4000 µs; ArduPilot 1/frame rate, 833 µs at 1200 Hz). An answer
//! (controls, a servo frame) is the command for [tᵢ, tᵢ + sᵢ]. The world advances to the
//! next time any autopilot is due, min(tᵢ + sᵢ), and only once every autopilot in lockstep
//! whose tᵢ = now has answered; at that time the due ones get their sensors and the others
//! keep their command. The grid of world times is so the union of every autopilot's own
//! grid, and which times it holds depends only on the step lengths and the answers, never
//! on the order in which the answers arrive: same seed, same answers ⇒ same bits.
//!
//! An autopilot is in one of four phases ([`Phase`]). Only `Lockstep` ones hold the world
//! back; `Free` ones (PX4 starting up, before its first controls) get their sensors as the
//! world passes their times; `Absent` ones get nothing, `Silent` ones only a reminder now and
//! then (the fleet's server sends it), their motors off.

use std::collections::VecDeque;

/// Where an autopilot stands in the fleet's lockstep.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Phase {
    /// Not connected (never, or gone): motors off, no sensors.
    Absent,
    /// Connected, not answering yet (PX4 starting up): sensors as the world passes its
    /// times; it holds nothing back.
    Free,
    /// Answers every step: the world waits for it.
    Lockstep,
    /// Stopped answering for longer than the timeout: motors off, left out of the barrier
    /// until it answers again.
    Silent,
}

/// One autopilot's place in the clock.
#[derive(Debug, Clone, PartialEq)]
pub struct Slot {
    pub phase: Phase,
    /// Time of its last sensors, µs.
    pub time_us: u64,
    /// Length of its next step, µs (≥ 1).
    pub step_us: u64,
    /// End of the step under way (its command applied); `None` while the world waits for
    /// its answer.
    pub next_us: Option<u64>,
    /// Answers received and not yet stepped, oldest first.
    pub answers: VecDeque<Vec<f64>>,
}

impl Slot {
    fn absent(step_us: u64) -> Self {
        Slot {
            phase: Phase::Absent,
            time_us: 0,
            step_us: step_us.max(1),
            next_us: None,
            answers: VecDeque::new(),
        }
    }
}

/// What the world does next.
#[derive(Debug, Clone, PartialEq)]
pub struct Advance {
    /// Commands to set before the step, (autopilot, command), in autopilot order.
    pub commands: Vec<(usize, Vec<f64>)>,
    /// The step, µs (> 0).
    pub dt_us: u64,
    /// Autopilots whose time the step ends at (their sensors go out), in order.
    pub due: Vec<usize>,
}

/// Why the world does not advance.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Hold {
    /// Waiting for autopilot i's answer (the lowest such i).
    Waiting(usize),
    /// Nobody in lockstep, and free steps not asked for (or nobody connected).
    Idle,
}

/// The barrier over every autopilot of the fleet.
#[derive(Debug, Clone, PartialEq)]
pub struct Lockstep {
    now_us: u64,
    slots: Vec<Slot>,
}

impl Lockstep {
    /// `steps_us[i]`: autopilot i's step before it says otherwise; everyone absent, time 0.
    pub fn new(steps_us: &[u64]) -> Self {
        Lockstep {
            now_us: 0,
            slots: steps_us.iter().map(|&s| Slot::absent(s)).collect(),
        }
    }

    /// World time, µs.
    pub fn now_us(&self) -> u64 {
        self.now_us
    }

    /// Autopilot i's slot.
    pub fn slot(&self, i: usize) -> &Slot {
        &self.slots[i]
    }

    /// Number of autopilots.
    pub fn len(&self) -> usize {
        self.slots.len()
    }

    /// Never: a fleet has an autopilot.
    pub fn is_empty(&self) -> bool {
        self.slots.is_empty()
    }

    /// Whether autopilot i holds the world back and has not answered its time yet.
    pub fn is_awaited(&self, i: usize) -> bool {
        let s = &self.slots[i];
        s.phase == Phase::Lockstep && s.next_us.is_none() && s.answers.is_empty()
    }

    /// Autopilot i connected (or reconnected) now: its first sensors are at `now`, given by
    /// the caller; `lockstep` for one that answers from the start (ArduPilot: its first
    /// servo frame is its answer, given next with [`Lockstep::answer`]).
    pub fn connect(&mut self, i: usize, lockstep: bool) {
        let now = self.now_us;
        let s = &mut self.slots[i];
        s.time_us = now;
        s.answers.clear();
        if lockstep {
            s.phase = Phase::Lockstep;
            s.next_us = None;
        } else {
            s.phase = Phase::Free;
            s.next_us = Some(now + s.step_us);
        }
    }

    /// Autopilot i went away: out of the barrier until it connects again.
    pub fn disconnect(&mut self, i: usize) {
        let s = &mut self.slots[i];
        s.phase = Phase::Absent;
        s.next_us = None;
        s.answers.clear();
    }

    /// Autopilot i kept the world waiting too long: out of the barrier until it answers.
    pub fn silence(&mut self, i: usize) {
        let s = &mut self.slots[i];
        s.phase = Phase::Silent;
        s.next_us = None;
        s.answers.clear();
    }

    /// Autopilot i's next step is `step_us` long (ArduPilot's frame rate may change).
    pub fn set_step(&mut self, i: usize, step_us: u64) {
        self.slots[i].step_us = step_us.max(1);
    }

    /// Autopilot i answered with `command`. Returns the command to set at once (not
    /// queued) when it is free or silent: a free autopilot's first answer puts it in
    /// lockstep for its step under way; a silent one's rejoins from now. An absent one's
    /// answer is dropped (`None` too).
    pub fn answer(&mut self, i: usize, command: Vec<f64>) -> Option<Vec<f64>> {
        let now = self.now_us;
        let s = &mut self.slots[i];
        match s.phase {
            Phase::Absent => None,
            Phase::Lockstep => {
                s.answers.push_back(command);
                None
            }
            Phase::Free => {
                s.phase = Phase::Lockstep;
                Some(command)
            }
            Phase::Silent => {
                s.phase = Phase::Lockstep;
                s.time_us = now;
                s.next_us = Some(now + s.step_us);
                Some(command)
            }
        }
    }

    /// The next step of the world, or why there is none. `free`: step even when nobody is
    /// in lockstep (the free clock of autopilots starting up asks for it on its schedule).
    /// Taking an [`Advance`] moves time: apply its commands, step the world, send the due
    /// autopilots their sensors.
    pub fn advance(&mut self, free: bool) -> Result<Advance, Hold> {
        let in_lockstep = self.slots.iter().any(|s| s.phase == Phase::Lockstep);
        if !in_lockstep && !free {
            return Err(Hold::Idle);
        }
        if let Some(i) = (0..self.slots.len()).find(|&i| self.is_awaited(i)) {
            return Err(Hold::Waiting(i));
        }
        let mut commands = Vec::new();
        for (i, s) in self.slots.iter_mut().enumerate() {
            if s.phase == Phase::Lockstep && s.next_us.is_none() {
                if let Some(command) = s.answers.pop_front() {
                    commands.push((i, command));
                    s.next_us = Some(s.time_us + s.step_us);
                }
            }
        }
        let ends = self.slots.iter().filter_map(|s| match s.phase {
            Phase::Lockstep | Phase::Free => s.next_us,
            Phase::Absent | Phase::Silent => None,
        });
        let Some(to) = ends.min() else {
            return Err(Hold::Idle);
        };
        let dt_us = to - self.now_us;
        self.now_us = to;
        let mut due = Vec::new();
        for (i, s) in self.slots.iter_mut().enumerate() {
            if s.next_us == Some(to) && matches!(s.phase, Phase::Lockstep | Phase::Free) {
                s.time_us = to;
                s.next_us = match s.phase {
                    Phase::Free => Some(to + s.step_us),
                    _ => None,
                };
                due.push(i);
            }
        }
        Ok(Advance {
            commands,
            dt_us,
            due,
        })
    }
}

#[cfg(test)]
mod tests;
