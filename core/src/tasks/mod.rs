//! Tasks: reset sampling, observation, reward, termination and info on top of a model.
//!
//! Every front end (FMU, SITL, gymnasium adapter) drives a task through [`Task`]; none
//! re-implements a reward or a termination.

/// One value of a task's info dictionary.
#[derive(Debug, Clone, PartialEq)]
pub enum InfoValue {
    Real(f64),
    Integer(i64),
    Flag(bool),
    Vector(Vec<f64>),
}

/// The info dictionary: ordered (name, value) pairs, the same names every step.
pub type Info = Vec<(&'static str, InfoValue)>;

/// One info value lent to a visitor ([`Task::visit_info`]): a vector is borrowed, so a
/// vector env can flatten every env's info each step without allocating.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum InfoRef<'a> {
    Real(f64),
    Integer(i64),
    Flag(bool),
    Vector(&'a [f64]),
}

impl InfoValue {
    pub fn as_ref(&self) -> InfoRef<'_> {
        match self {
            InfoValue::Real(x) => InfoRef::Real(*x),
            InfoValue::Integer(i) => InfoRef::Integer(*i),
            InfoValue::Flag(b) => InfoRef::Flag(*b),
            InfoValue::Vector(v) => InfoRef::Vector(v),
        }
    }
}

impl InfoRef<'_> {
    pub fn to_owned(self) -> InfoValue {
        match self {
            InfoRef::Real(x) => InfoValue::Real(x),
            InfoRef::Integer(i) => InfoValue::Integer(i),
            InfoRef::Flag(b) => InfoValue::Flag(b),
            InfoRef::Vector(v) => InfoValue::Vector(v.to_vec()),
        }
    }
}

/// What [`Task::visit_info`] calls with each (name, value), in order.
pub type InfoVisitor<'v> = dyn FnMut(&'static str, InfoRef<'_>) + 'v;

/// Result of one task step (the observation is read with [`Task::write_observation`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StepOutcome {
    pub reward: f64,
    /// The episode ended inside the MDP (crash, out of bounds, landed, …).
    pub terminated: bool,
    /// The episode was cut short from outside the MDP (time limit, all waypoints done).
    pub truncated: bool,
}

/// An action the task cannot take: wrong length or a non-finite entry.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ActionError {
    #[error("action has {got} values, the task takes {expected}")]
    WrongLength { expected: usize, got: usize },
    #[error("action value {index} is {value}, not a finite number")]
    NotFinite { index: usize, value: f64 },
}

/// Checks an action's length and that every entry is finite.
pub fn check_action(action: &[f64], expected: usize) -> Result<(), ActionError> {
    if action.len() != expected {
        return Err(ActionError::WrongLength {
            expected,
            got: action.len(),
        });
    }
    match action.iter().position(|a| !a.is_finite()) {
        Some(index) => Err(ActionError::NotFinite {
            index,
            value: action[index],
        }),
        None => Ok(()),
    }
}

/// A reinforcement-learning task over one model instance.
pub trait Task {
    /// Number of action values; the action space is [`Task::action_bounds`].
    fn action_size(&self) -> usize;
    /// Inclusive per-value action bounds (actions outside are clipped, not refused).
    fn action_bounds(&self) -> (Vec<f64>, Vec<f64>);
    /// Number of observation values.
    fn observation_size(&self) -> usize;
    /// Inclusive per-value observation bounds; every observation lies inside them.
    fn observation_bounds(&self) -> (Vec<f32>, Vec<f32>);
    /// The observation's consecutive groups: (name, number of values), in order; the
    /// numbers sum to [`Task::observation_size`].
    fn observation_layout(&self) -> Vec<(&'static str, usize)>;
    /// Starts a new episode; the same seed gives the same episode, bit for bit.
    fn reset(&mut self, seed: u64);
    /// Applies `action` for one control period.
    fn step(&mut self, action: &[f64]) -> Result<StepOutcome, ActionError>;
    /// Writes the current observation into `out` (length [`Task::observation_size`]).
    fn write_observation(&self, out: &mut [f32]);
    /// Calls `visit` with each entry of the current step's info dictionary, in order.
    fn visit_info(&self, visit: &mut InfoVisitor<'_>);
    /// Control period, s.
    fn dt(&self) -> f64;

    /// The info dictionary of the current step.
    fn info(&self) -> Info {
        let mut info = Vec::new();
        self.visit_info(&mut |name, value| info.push((name, value.to_owned())));
        info
    }

    /// The current observation as a new vector.
    fn observation(&self) -> Vec<f32> {
        let mut out = vec![0.0; self.observation_size()];
        self.write_observation(&mut out);
        out
    }
}

/// Clips `value` into [lo, hi] and narrows it to f32, staying inside the bounds after rounding.
pub fn clip_f32(value: f64, lo: f32, hi: f32) -> f32 {
    let v = value as f32;
    if v.is_nan() {
        0.0f32.clamp(lo, hi)
    } else {
        v.clamp(lo, hi)
    }
}

pub mod flight;
pub mod flight_faults;
pub mod flight_link;
pub mod flight_vehicle;
pub mod hover;
pub mod landing;
pub mod landing_reward;
pub mod multi;
pub mod randomization;
pub mod registry;
pub mod waypoints;
