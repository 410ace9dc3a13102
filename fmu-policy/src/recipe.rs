//! A policy's recipe (`recipe.json`, written by examples/train/export_onnx.py): how Policy.fmu
//! builds the network's input from the plant's outputs and turns the network's output into
//! the plant's inputs, exactly as the gym env the policy was trained on does it. Every check
//! names the file and the field it failed on.

use crate::error::PolicyError;
use flyloop_core::tasks::flight::base_observation;
use flyloop_core::tasks::flight_link::ESTIMATE_OBSERVATION;
use serde::Deserialize;
use std::path::Path;

/// The recipe's format tag.
pub const FORMAT: &str = "flyloop-policy-recipe/1";

/// The recipe's file name in a policy folder and in the FMU's resources.
pub const RECIPE_FILE: &str = "recipe.json";

/// Fewest and most rotors of a multirotor plant (the core's frames).
const ROTORS: (usize, usize) = (4, flyloop_core::quadrotor::frame::MAX_ROTORS);

/// The observations a recipe can name: the gym's QuadHover motor interface ("hover-motors"),
/// and its rates interface ("rates-estimate": what PX4's estimator gives, built here from the
/// plant's true state, which is the estimate an FMU system has).
pub const OBSERVATIONS: [&str; 2] = ["hover-motors", "rates-estimate"];

/// How the network's output (clipped into +-action_clip) becomes the FMU's outputs.
pub const ACTION_MAPS: [&str; 2] = ["rescale-action", "bounds"];

/// Which interface a (checked) recipe is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Interface {
    /// Plant outputs in, `motor_command_i` out (the motor interface).
    HoverMotors,
    /// Plant position, velocity, attitude and rates in; RateController.fmu's setpoint
    /// (`thrust roll_rate pitch_rate yaw_rate`) out (the rates interface).
    RatesEstimate,
}

/// The observation groups of the "hover-motors" recipe (the gym's QuadHover motor
/// interface), with their sizes for `rotors` motors: the core's own table, so the two cannot
/// drift apart.
pub fn hover_motors_layout(rotors: usize) -> Vec<(&'static str, usize)> {
    base_observation(rotors).to_vec()
}

/// `recipe.json` as read.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Recipe {
    /// [`FORMAT`].
    pub format: String,
    /// Which observation: one of [`OBSERVATIONS`].
    pub observation: String,
    /// The gym's observation groups (name, size), as the env describes them; must be the
    /// recipe's ([`hover_motors_layout`]).
    pub layout: Vec<(String, usize)>,
    /// Motors of the plant: outputs `motor_command_0..`, inputs `motor_state_0..`
    /// ("hover-motors"; absent or 0 for "rates-estimate", whose outputs are the setpoint).
    #[serde(default)]
    pub rotors: usize,
    /// The gym's control step: the FMU acts every this many seconds, s.
    pub sample_period: f64,
    /// The env's observation bounds (float32): each value is clipped into them.
    pub observation_low: Vec<f64>,
    pub observation_high: Vec<f64>,
    /// The observation normalisation (float64): (o - mean) / sqrt(var + epsilon), clipped
    /// into +-clip, then float32.
    pub observation_mean: Vec<f64>,
    pub observation_var: Vec<f64>,
    pub normalisation_epsilon: f64,
    pub normalisation_clip: f64,
    /// The network's output is clipped into +-this (float32).
    pub action_clip: f64,
    /// One of [`ACTION_MAPS`]; default "rescale-action".
    #[serde(default = "rescale_action")]
    pub action_map: String,
    /// "rescale-action": gymnasium's RescaleAction (float32), command = (a - intercept) /
    /// gradient.
    #[serde(default)]
    pub action_gradient: Vec<f64>,
    #[serde(default)]
    pub action_intercept: Vec<f64>,
    /// "bounds": fast_ppo.py's to_env (float32), command = low + (a + 1) * 0.5 * (high -
    /// low), then clipped into [low, high] in float64 as the env clips an action.
    #[serde(default)]
    pub action_low: Vec<f64>,
    #[serde(default)]
    pub action_high: Vec<f64>,
    /// The ONNX file next to the recipe.
    pub network: String,
    /// Where the policy came from (free text).
    #[serde(default)]
    pub source: String,
}

fn rescale_action() -> String {
    ACTION_MAPS[0].to_string()
}

impl Recipe {
    /// Reads and checks `folder/recipe.json`.
    pub fn read(folder: &Path) -> Result<Recipe, PolicyError> {
        let path = folder.join(RECIPE_FILE);
        let text = std::fs::read_to_string(&path)
            .map_err(|e| PolicyError::file(&path, format!("cannot be read: {e}")))?;
        let recipe: Recipe = serde_json::from_str(&text)
            .map_err(|e| PolicyError::file(&path, format!("is not a policy recipe: {e}")))?;
        recipe.check(&path)?;
        Ok(recipe)
    }

    /// The observation's size.
    pub fn observation_size(&self) -> usize {
        self.layout.iter().map(|(_, n)| n).sum()
    }

    /// The interface the recipe's observation belongs to.
    pub fn interface(&self) -> Interface {
        if self.observation == OBSERVATIONS[1] {
            Interface::RatesEstimate
        } else {
            Interface::HoverMotors
        }
    }

    /// Values the network gives and the FMU outputs: one per motor, or the 4 of a setpoint.
    pub fn action_size(&self) -> usize {
        match self.interface() {
            Interface::HoverMotors => self.rotors,
            Interface::RatesEstimate => ESTIMATE_OBSERVATION[4].1,
        }
    }

    /// The observation groups the recipe's observation has.
    fn expected_layout(&self) -> Vec<(&'static str, usize)> {
        match self.interface() {
            Interface::HoverMotors => hover_motors_layout(self.rotors),
            Interface::RatesEstimate => ESTIMATE_OBSERVATION.to_vec(),
        }
    }

    fn check(&self, path: &Path) -> Result<(), PolicyError> {
        let bad = |field: &str, why: String| Err(PolicyError::field(path, field, why));
        if self.format != FORMAT {
            return bad("format", format!("{:?} is not {FORMAT:?}", self.format));
        }
        if !OBSERVATIONS.contains(&self.observation.as_str()) {
            let why = format!(
                "{:?}: the recipes known are {OBSERVATIONS:?}",
                self.observation
            );
            return bad("observation", why);
        }
        match self.interface() {
            Interface::HoverMotors if !(ROTORS.0..=ROTORS.1).contains(&self.rotors) => {
                let why = format!("{} is not in [{}, {}]", self.rotors, ROTORS.0, ROTORS.1);
                return bad("rotors", why);
            }
            Interface::RatesEstimate if self.rotors != 0 => {
                let why = format!(
                    "{}: a rates-estimate policy commands RateController.fmu, not motors \
                     (leave it out)",
                    self.rotors
                );
                return bad("rotors", why);
            }
            _ => {}
        }
        let want = self.expected_layout();
        let got: Vec<(&str, usize)> = self.layout.iter().map(|(n, k)| (n.as_str(), *k)).collect();
        if got != want {
            let why = format!("{got:?} is not {}'s {want:?}", self.observation);
            return bad("layout", why);
        }
        if !ACTION_MAPS.contains(&self.action_map.as_str()) {
            let why = format!("{:?} is not one of {ACTION_MAPS:?}", self.action_map);
            return bad("action_map", why);
        }
        if !(self.sample_period.is_finite() && self.sample_period > 0.0) {
            return bad(
                "sample_period",
                format!("{} is not > 0 s", self.sample_period),
            );
        }
        let (n, m) = (self.observation_size(), self.action_size());
        // The action map's vectors have one value per action; the other map's are empty.
        let (rescale, bounds) = if self.action_map == ACTION_MAPS[0] {
            (m, 0)
        } else {
            (0, m)
        };
        let vectors: [(&str, &[f64], usize); 8] = [
            ("observation_low", &self.observation_low, n),
            ("observation_high", &self.observation_high, n),
            ("observation_mean", &self.observation_mean, n),
            ("observation_var", &self.observation_var, n),
            ("action_gradient", &self.action_gradient, rescale),
            ("action_intercept", &self.action_intercept, rescale),
            ("action_low", &self.action_low, bounds),
            ("action_high", &self.action_high, bounds),
        ];
        for (field, values, len) in vectors {
            if values.len() != len {
                return bad(
                    field,
                    format!("has {} values, the recipe needs {len}", values.len()),
                );
            }
            if let Some(i) = values.iter().position(|v| !v.is_finite()) {
                return bad(field, format!("value {i} is not finite"));
            }
        }
        if let Some(i) = self.observation_var.iter().position(|v| *v < 0.0) {
            return bad("observation_var", format!("value {i} is negative"));
        }
        if let Some(i) = self.action_gradient.iter().position(|v| *v == 0.0) {
            return bad("action_gradient", format!("value {i} is 0"));
        }
        for (low, high, field, other) in [
            (
                &self.observation_low,
                &self.observation_high,
                "observation_low",
                "observation_high",
            ),
            (
                &self.action_low,
                &self.action_high,
                "action_low",
                "action_high",
            ),
        ] {
            if let Some(i) = low.iter().zip(high).position(|(lo, hi)| lo > hi) {
                return bad(field, format!("value {i} is above {other}'s"));
            }
        }
        for (field, v) in [
            ("normalisation_epsilon", self.normalisation_epsilon),
            ("normalisation_clip", self.normalisation_clip),
            ("action_clip", self.action_clip),
        ] {
            if !(v.is_finite() && v >= 0.0) {
                return bad(field, format!("{v} is not a finite number >= 0"));
            }
        }
        let plain = Path::new(&self.network)
            .file_name()
            .map(|f| f == self.network.as_str());
        if plain != Some(true) {
            let why = format!("{:?} is not a file name in the policy folder", self.network);
            return bad("network", why);
        }
        Ok(())
    }
}
