//! A multi-agent task served as ONE world (protocol §14): the core's [`MultiFlight`], the
//! world's simulation clock, the commands of the step being gathered (one per vehicle) and
//! the reply of the last step kept for a repeat. No sockets and no MAVLink here: the handler
//! ([`super::world_handler`]) feeds commands in and sends what comes out.
//!
//! Each agent's task frame is the single-agent frame (header, observation, info) followed by
//! [`EXTRA_VALUES`] values: the agent's `active` flag and its reward's f64 bits in four
//! 16-bit pieces (low first), so a client gets the reward the native env computes, bit for
//! bit, though the frame is float32.

use crate::task_frame::HEADER_LEN;
use crate::vehicle::next_seed;
use flyloop_core::tasks::multi::{ACTION_SIZE, MultiConfig, MultiError, MultiFlight, Scenario};
use flyloop_core::tasks::registry::push_info;

/// Values after an agent's info: active, then the reward's bits 0–15, 16–31, 32–47, 48–63.
pub const EXTRA_VALUES: usize = 5;

/// What one agent's command did to the step being gathered.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Gathered {
    /// Kept; the step still waits for other vehicles' commands.
    Waiting,
    /// The last missing command: every vehicle's is in, the world can step.
    Complete,
}

/// The world and its lockstep bookkeeping.
#[derive(Debug)]
pub struct WorldTask {
    pub flight: MultiFlight,
    /// Seed of the current episode.
    pub seed: u64,
    /// Simulation time since start, µs: steps × the control period (never reset).
    pub clock_us: u64,
    dt_us: u64,
    /// Steps since the last reset.
    pub episode_step: u64,
    /// The step being gathered: every agent's command (agent i at `ACTION_SIZE·i`) and
    /// whether it is in.
    commands: Vec<f64>,
    have: Vec<bool>,
    have_count: usize,
    /// The name (`time_usec`) of the step being gathered: its first named command's.
    pending_name: u64,
    /// The name of the last step (≠ 0) and the reply sent for it (protocol §3.1, whole
    /// world): a reset drops the reply but keeps the name.
    pub last_step: Option<u64>,
    pub last_reply: Option<Vec<u8>>,
    values: Vec<f32>,
    /// The configuration of the next reset (PARAM_SET writes here; the running world was
    /// built from `flight.config()`).
    pub config: MultiConfig,
    /// Per agent, how many of its episode's fault events the ground station has been told.
    pub faults_reported: Vec<usize>,
}

impl WorldTask {
    /// `scenario` on `config` (its `num_agents` vehicles), reset with `seed`.
    pub fn new(scenario: Scenario, config: MultiConfig, seed: u64) -> Result<Self, MultiError> {
        let mut flight = MultiFlight::new(scenario, config)?;
        flight.reset(seed)?;
        let n = flight.num_agents();
        let dt_us = ((flight.dt() * 1e6).round() as u64).max(1);
        Ok(WorldTask {
            seed,
            clock_us: 0,
            dt_us,
            episode_step: 0,
            commands: vec![0.0; n * ACTION_SIZE],
            have: vec![false; n],
            have_count: 0,
            pending_name: 0,
            last_step: None,
            last_reply: None,
            values: Vec::new(),
            config: flight.config().clone(),
            faults_reported: vec![0; n],
            flight,
        })
    }

    pub fn num_agents(&self) -> usize {
        self.have.len()
    }

    /// The task frame's name (DEBUG_FLOAT_ARRAY `name`, at most 10 characters).
    pub fn frame_name(&self) -> &'static str {
        match self.flight.scenario() {
            Scenario::MultiHover => "multihover",
            Scenario::Swap => "swap",
        }
    }

    /// The seed a reset request gives the world: its own, or the next of the sequence.
    pub fn seed_for(&self, explicit: Option<u64>) -> u64 {
        explicit.unwrap_or_else(|| next_seed(self.seed))
    }

    /// A new episode with `seed`, first rebuilding the world if a parameter changed; the
    /// commands gathered for a step are dropped.
    pub fn reset(&mut self, seed: u64) -> Result<(), MultiError> {
        if self.config != *self.flight.config() {
            self.flight = MultiFlight::new(self.flight.scenario(), self.config.clone())?;
        }
        self.flight.reset(seed)?;
        self.faults_reported.fill(0);
        self.seed = seed;
        self.episode_step = 0;
        self.drop_pending();
        self.last_reply = None;
        Ok(())
    }

    fn drop_pending(&mut self) {
        self.have.fill(false);
        self.have_count = 0;
        self.pending_name = 0;
    }

    /// Keeps agent `i`'s command (`controls`: its first [`ACTION_SIZE`] channels, finite,
    /// checked by the caller) for the step named `name`; a second command of the same agent
    /// for this step replaces the first.
    pub(crate) fn gather(&mut self, i: usize, controls: &[f32], name: u64) -> Gathered {
        for (slot, &c) in self.commands[i * ACTION_SIZE..(i + 1) * ACTION_SIZE]
            .iter_mut()
            .zip(controls)
        {
            *slot = f64::from(c);
        }
        if self.pending_name == 0 {
            self.pending_name = name;
        }
        if !self.have[i] {
            self.have[i] = true;
            self.have_count += 1;
        }
        if self.have_count == self.have.len() {
            Gathered::Complete
        } else {
            Gathered::Waiting
        }
    }

    /// The name of the step being gathered, once a command of it named one (not 0).
    pub(crate) fn gathering(&self) -> Option<u64> {
        (self.have_count > 0 && self.pending_name != 0).then_some(self.pending_name)
    }

    /// Whether some, not all, commands of a step are in.
    pub fn incomplete(&self) -> bool {
        self.have_count > 0 && self.have_count < self.have.len()
    }

    /// The system ids (1-based) whose command the step being gathered still waits for.
    pub fn missing(&self) -> Vec<usize> {
        (self.have.iter().enumerate())
            .filter(|(_, h)| !**h)
            .map(|(i, _)| i + 1)
            .collect()
    }

    /// Steps the world once with the gathered commands; returns the step's name (0: none).
    pub fn step(&mut self) -> Result<u64, MultiError> {
        let name = self.pending_name;
        let result = self.flight.step(&self.commands);
        self.drop_pending();
        result?;
        self.clock_us += self.dt_us;
        self.episode_step += 1;
        Ok(name)
    }

    /// Agent `i`'s task frame values (module docs), valid until the next call.
    pub fn frame(&mut self, i: usize) -> &[f32] {
        let f = &self.flight;
        let o = f.outcome(i);
        let n_obs = f.observation_size();
        let out = &mut self.values;
        out.clear();
        let flag = |b: bool| if b { 1.0 } else { 0.0 };
        out.extend_from_slice(&[
            o.reward as f32,
            flag(o.terminated),
            flag(o.truncated),
            self.episode_step as f32,
            n_obs as f32,
            0.0,
        ]);
        out.resize(HEADER_LEN + n_obs, 0.0);
        f.write_observation(i, &mut out[HEADER_LEN..]);
        f.visit_info(i, &mut |_, v| push_info(out, v));
        out[5] = (out.len() - HEADER_LEN - n_obs) as f32;
        out.push(flag(f.is_active(i)));
        let bits = o.reward.to_bits();
        out.extend([0, 16, 32, 48].map(|s| ((bits >> s) & 0xFFFF) as f32));
        &self.values
    }
}

/// The f64 a frame's four reward pieces carry (the inverse of [`WorldTask::frame`]'s).
pub fn reward_from_pieces(pieces: &[f32]) -> f64 {
    let bits =
        (pieces.iter().zip([0, 16, 32, 48])).fold(0u64, |acc, (&p, s)| acc | ((p as u64) << s));
    f64::from_bits(bits)
}

/// A multi-agent config for `vehicles` agents from a parameter file's `(core name, value)`
/// pairs and ranges; a file's `num_agents` must agree with `--vehicles`.
pub fn world_config(
    vehicles: u8,
    pairs: &[(String, f64)],
    ranges: Vec<flyloop_core::tasks::randomization::ParamRange>,
) -> Result<MultiConfig, flyloop_core::ParamError> {
    if let Some((_, n)) = pairs.iter().find(|(k, _)| k == "num_agents") {
        if *n != f64::from(vehicles) {
            return Err(flyloop_core::ParamError::Relation {
                name: "num_agents",
                requirement: format!(
                    "the config file says {n} agents but --vehicles is {vehicles}: the world has one agent per vehicle"
                ),
            });
        }
    }
    let agents = ("num_agents", f64::from(vehicles));
    let rest = pairs.iter().filter(|(k, _)| k != "num_agents");
    MultiConfig::from_values(
        std::iter::once(agents).chain(rest.map(|(k, v)| (k.as_str(), *v))),
        ranges,
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    fn world(n: u8) -> WorldTask {
        let config = world_config(n, &[], Vec::new()).unwrap();
        WorldTask::new(Scenario::Swap, config, 7).unwrap()
    }

    #[test]
    fn the_world_steps_only_when_every_command_is_in() {
        let mut w = world(3);
        let hover = [0.5f32; 4];
        assert_eq!(w.gather(2, &hover, 10_000), Gathered::Waiting);
        assert_eq!(w.gather(0, &hover, 10_000), Gathered::Waiting);
        assert!(w.incomplete());
        assert_eq!(w.missing(), vec![2]);
        assert_eq!(
            w.gather(0, &hover, 10_000),
            Gathered::Waiting,
            "a repeat adds nothing"
        );
        assert_eq!(w.gathering(), Some(10_000));
        assert_eq!(w.gather(1, &hover, 10_000), Gathered::Complete);
        assert_eq!(w.step().unwrap(), 10_000);
        assert_eq!((w.clock_us, w.episode_step), (10_000, 1));
        assert!(!w.incomplete());
        assert_eq!(w.gathering(), None);
        assert_eq!(w.gather(0, &hover, 0), Gathered::Waiting);
        assert_eq!(w.gathering(), None, "an unnamed command names no step");
    }

    #[test]
    fn a_frame_carries_the_reward_bits_and_matches_the_core() {
        let mut w = world(2);
        for i in 0..2 {
            w.gather(i, &[0.6, 0.4, 0.5, 0.55], 0);
        }
        w.step().unwrap();
        let core = w.flight.clone();
        let n_obs = core.observation_size();
        let f = w.frame(1).to_vec();
        let reward = core.outcome(1).reward;
        assert_eq!(f[0], reward as f32);
        assert_eq!(f[3], 1.0);
        let mut obs = vec![0f32; n_obs];
        core.write_observation(1, &mut obs);
        assert_eq!(&f[HEADER_LEN..HEADER_LEN + n_obs], &obs[..]);
        let n_info = f[5] as usize;
        let extra = &f[HEADER_LEN + n_obs + n_info..];
        assert_eq!(extra.len(), EXTRA_VALUES);
        assert_eq!(extra[0], 1.0, "active");
        assert_eq!(reward_from_pieces(&extra[1..]).to_bits(), reward.to_bits());
    }

    #[test]
    fn a_config_file_that_disagrees_with_vehicles_names_num_agents() {
        let e = world_config(4, &[("num_agents".into(), 3.0)], Vec::new()).unwrap_err();
        assert!(e.to_string().contains("num_agents"), "{e}");
        let e = world_config(2, &[("swap_radius".into(), -1.0)], Vec::new()).unwrap_err();
        assert!(e.to_string().contains("swap_radius"), "{e}");
    }
}
