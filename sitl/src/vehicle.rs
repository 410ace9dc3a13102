//! One simulated vehicle: its system id, its parameter sets, its core task instance, its
//! simulation clock and seed sequence.

use crate::link_line::ReplyLine;
use crate::task_frame::FrameHeader;
use flyloop_core::ParamError;
use flyloop_core::faults::LinkCondition;
use flyloop_core::tasks::registry::{
    ControlError, TaskConfig, TaskInstance, TaskKind, clamp_controls,
};

/// The next seed of a vehicle's sequence: the SplitMix64 output of the previous seed.
pub fn next_seed(seed: u64) -> u64 {
    let mut z = seed.wrapping_add(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// A vehicle of the simulation.
#[derive(Debug)]
pub struct Vehicle {
    pub system_id: u8,
    pub kind: TaskKind,
    /// Parameters for the next reset (PARAM_SET writes here).
    pub config: TaskConfig,
    /// The parameters the running task was built from.
    built_from: TaskConfig,
    pub task: TaskInstance,
    /// Seed of the current episode.
    pub seed: u64,
    /// Simulation time since start, µs (never reset, so it is monotonic across episodes).
    pub clock_us: u64,
    /// Outcome of the last step or reset.
    pub last: FrameHeader,
    /// The command in effect (held in real time), clamped to the action bounds.
    pub command: Vec<f64>,
    /// The task's action bounds (low, high), kept so a step allocates nothing for them.
    bounds: (Vec<f64>, Vec<f64>),
    pub frame_values: Vec<f32>,
    /// The lockstep step last done by a command that named it (its `time_usec`, ≠ 0), and
    /// the reply bytes sent for it: a repeat of that command gets them again (protocol §3).
    /// A reset drops the reply but keeps the name, so a late copy of that command is not
    /// taken for the new episode's first step.
    pub last_step: Option<u64>,
    pub last_reply: Option<Vec<u8>>,
    /// The replies through the task's link faults (used only while it has faults).
    pub link_line: ReplyLine,
}

/// What one step did.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StepReport {
    /// Some controls were outside the action bounds and were clamped.
    pub clamped: bool,
}

impl Vehicle {
    /// A vehicle reset with `seed`.
    pub fn new(
        system_id: u8,
        kind: TaskKind,
        config: TaskConfig,
        seed: u64,
    ) -> Result<Self, ParamError> {
        let task = TaskInstance::build(kind, &config)?;
        let command = task.motors_off();
        let bounds = task.action_bounds();
        let mut v = Vehicle {
            system_id,
            kind,
            built_from: config.clone(),
            config,
            task,
            seed,
            clock_us: 0,
            last: FrameHeader::default(),
            command,
            bounds,
            frame_values: Vec::new(),
            last_step: None,
            last_reply: None,
            link_line: ReplyLine::default(),
        };
        v.reset(seed)?;
        Ok(v)
    }

    /// Starts a new episode with `seed`, first rebuilding the task if a parameter changed.
    pub fn reset(&mut self, seed: u64) -> Result<(), ParamError> {
        if self.config != self.built_from {
            self.task = TaskInstance::build(self.kind, &self.config)?;
            self.built_from = self.config.clone();
            self.bounds = self.task.action_bounds();
        }
        self.task.reset(seed);
        self.seed = seed;
        self.last = FrameHeader::default();
        self.command = self.task.motors_off();
        self.last_reply = None;
        self.link_line.clear();
        Ok(())
    }

    /// What the task's link faults do to the lockstep link now (`None`: the task has no
    /// faults, the link is untouched).
    pub fn link(&self) -> Option<LinkCondition> {
        self.task.fault_state().map(|f| f.link())
    }

    /// The task's control period in whole microseconds.
    pub fn dt_us(&self) -> u64 {
        (self.task.dt() * 1e6).round() as u64
    }

    /// Validates `controls` (the first action-size channels are used; each must be finite)
    /// and clamps them into the action bounds as the command in effect.
    pub fn set_controls(&mut self, controls: &[f32]) -> Result<StepReport, ControlError> {
        let (lo, hi) = &self.bounds;
        let clamped = clamp_controls(controls, lo, hi, &mut self.command)?;
        Ok(StepReport { clamped })
    }

    /// Advances the task by one control period with the command in effect.
    pub fn step(&mut self) {
        // The command has the task's length and is finite, so the task accepts it.
        if let Ok(outcome) = self.task.step(&self.command) {
            self.last = FrameHeader {
                reward: outcome.reward,
                terminated: outcome.terminated,
                truncated: outcome.truncated,
                step: self.last.step + 1,
            };
        }
        self.clock_us += self.dt_us();
    }

    /// Switches the motors off (the failsafe).
    pub fn motors_off(&mut self) {
        self.command = self.task.motors_off();
    }

    /// The current task frame's values.
    pub fn frame(&mut self) -> &[f32] {
        crate::task_frame::values(&self.task, &self.last, &mut self.frame_values);
        &self.frame_values
    }

    /// Milliseconds of simulation time (MAVLink's time_boot_ms), wrapping like a u32 clock.
    pub fn time_boot_ms(&self) -> u32 {
        (self.clock_us / 1000) as u32
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_reset_with_the_same_seed_replays_the_episode() {
        let mut v = Vehicle::new(1, TaskKind::Hover, TaskConfig::default(), 42).unwrap();
        let run = |v: &mut Vehicle| {
            let mut out = Vec::new();
            for i in 0..20 {
                v.set_controls(&[0.5, 0.5, 0.5, 0.5 + 0.01 * i as f32])
                    .unwrap();
                v.step();
                out.push(v.frame().to_vec());
            }
            out
        };
        let first = run(&mut v);
        v.reset(42).unwrap();
        assert_eq!(v.last.step, 0);
        assert_eq!(run(&mut v), first);
        assert_eq!(
            v.clock_us,
            40 * 10_000,
            "the clock keeps running across episodes"
        );
    }

    #[test]
    fn non_finite_controls_are_refused_and_out_of_range_ones_clamped() {
        let mut v = Vehicle::new(2, TaskKind::Landing, TaskConfig::default(), 1).unwrap();
        let err = v.set_controls(&[0.0, f32::NAN]).unwrap_err();
        assert!(matches!(err, ControlError::NotFinite { channel: 1, value } if value.is_nan()));
        assert_eq!(err.to_string(), "controls[1] = NaN: step refused");
        assert_eq!(
            v.command,
            vec![-1.0, -1.0],
            "a refused command changes nothing"
        );
        assert_eq!(
            v.set_controls(&[3.0, -0.5, f32::NAN]),
            Ok(StepReport { clamped: true })
        );
        assert_eq!(
            v.command,
            vec![1.0, -0.5],
            "channels past the action size are ignored"
        );
    }

    #[test]
    fn a_parameter_change_applies_at_the_next_reset() {
        let mut v = Vehicle::new(1, TaskKind::Hover, TaskConfig::default(), 0).unwrap();
        v.config.flight.max_steps = 3;
        v.set_controls(&[0.5; 4]).unwrap();
        for _ in 0..3 {
            v.step();
        }
        assert!(!v.last.truncated, "still the old task");
        v.reset(0).unwrap();
        v.set_controls(&[0.5; 4]).unwrap();
        for _ in 0..3 {
            v.step();
        }
        assert!(v.last.truncated);
    }

    #[test]
    fn the_seed_sequence_is_splitmix64() {
        assert_eq!(next_seed(0), 0xE220_A839_7B1D_CDAF);
        assert_ne!(next_seed(1), next_seed(2));
    }
}
