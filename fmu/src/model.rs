//! What the FMI layer needs from a model, and nothing about physics: the [`FmuModel`] trait,
//! implemented for the quadrotor and the lander in [`crate::models`], and the [`ModelTable`]
//! each model derives from its core variable table (lookup by value reference, GUID).

use crate::error::FmuError;
use crate::fmi3_variables::Layout3;
use crate::guid;
use crate::instance::Api;
use flyloop_core::params::ValueKind;
use flyloop_core::variables::{Causality, Variability, Variable};
use flyloop_core::{ParamError, SnapshotError};
use serde::Serialize;
use serde::de::DeserializeOwned;
use std::ffi::CString;

/// One communication step as the model sees it. Times are on the FMU's grid
/// (`t0 + n·h`, never summed), so a model with its own fixed step can count whole steps.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StepRequest {
    /// Start time of the experiment (fmi2SetupExperiment), s.
    pub start_time: f64,
    /// Communication point at the end of this step, s.
    pub end_time: f64,
    /// Communication step size h, s.
    pub step_size: f64,
}

/// Facts about a model that its variable table does not hold.
#[derive(Debug)]
pub struct ModelInfo {
    /// modelIdentifier and modelName: the FMU is `<identifier>.fmu`, its binary
    /// `binaries/linux64/<identifier>.so`.
    pub identifier: &'static str,
    pub description: &'static str,
    /// DefaultExperiment: start, stop, step size (s).
    pub default_experiment: (f64, f64, f64),
    /// Inputs (by name) each output depends on directly, without a step in between
    /// (ModelStructure/Outputs/Unknown/@dependencies). Outputs not listed depend on none.
    pub direct_feedthrough: &'static [(&'static str, &'static [&'static str])],
    /// Outputs that do not depend on the continuous states (Model Exchange dependencies).
    pub state_free_outputs: &'static [&'static str],
    /// FMI 3.0: runs of variables `P_0 .. P_n-1` shown as one array `P`, with the array's
    /// description.
    pub arrays: &'static [(&'static str, &'static str)],
    /// FMI 3.0: a variable for each event indicator (name, unit, description), in order.
    pub event_indicators: &'static [(&'static str, &'static str, &'static str)],
}

/// What a Model-Exchange capable model adds to its table: its continuous states and their
/// derivatives as variables (value references in state-vector order) and its number of event
/// indicators.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ModelExchangeTable {
    pub states: Vec<u32>,
    pub derivatives: Vec<u32>,
    pub event_indicators: usize,
}

/// A model behind the FMU: built from start values, read and written by value reference,
/// advanced by communication steps, saved to and restored from bytes.
pub trait FmuModel: Sized + 'static {
    /// The start values that are not physical parameters (seed, initial pose...).
    type Initial: Clone + Default + Serialize + DeserializeOwned;

    /// The model's table, built once.
    fn table() -> &'static ModelTable;

    /// A fresh model from `initial`, with the physical parameters of `previous` (or the
    /// defaults when there is none).
    fn build(previous: Option<&Self>, initial: &Self::Initial) -> Result<Self, ParamError>;

    /// Reads variable `vr` (value as `f64`; integers and booleans are exact).
    fn get(&self, initial: &Self::Initial, vr: u32) -> Result<f64, ParamError>;

    /// Writes variable `vr`, range-checked; nothing changes when it is refused.
    fn set(&mut self, initial: &mut Self::Initial, vr: u32, value: f64) -> Result<(), ParamError>;

    /// How many internal steps `step` would take (to refuse steps that would run for hours).
    fn internal_steps(&self, step: &StepRequest) -> f64;

    /// Advances to `step.end_time`.
    fn advance(&mut self, step: &StepRequest);

    /// Whether the state holds only finite numbers (false once the dynamics diverged).
    fn is_finite(&self) -> bool;

    /// The whole state as bytes (RNG and physics world included).
    fn save(&self) -> Result<Vec<u8>, SnapshotError>;

    /// A model from [`FmuModel::save`] bytes; foreign or damaged bytes are an error.
    fn restore(bytes: &[u8]) -> Result<Self, SnapshotError>;

    /// The model as a hybrid system for Model Exchange, or `None` (the default) for a model
    /// that is Co-Simulation only.
    fn hybrid(&self) -> Option<&dyn Hybrid> {
        None
    }

    /// [`FmuModel::hybrid`], mutable.
    fn hybrid_mut(&mut self) -> Option<&mut dyn Hybrid> {
        None
    }
}

/// A model as Model Exchange sees it: a state vector the importer's solver integrates, its
/// derivative, event indicators and the discrete changes at events. Slices have the lengths
/// of the model's [`ModelExchangeTable`] (the engine checks the importer's lengths).
pub trait Hybrid {
    fn states(&self, x: &mut [f64]);
    /// Sets the states; a non-finite value is refused and nothing changes.
    fn set_states(&mut self, x: &[f64]) -> Result<(), FmuError>;
    fn derivatives(&self, dx: &mut [f64]);
    fn event_indicators(&self, z: &mut [f64]);
    /// Seconds from the last event to the next time event, if there is one.
    fn time_event_after(&self) -> Option<f64>;
    /// The discrete changes of an event `elapsed` seconds after the previous one.
    fn event_update(&mut self, elapsed: f64);
}

/// Value reference → position in a variable list, in O(1): a dense table up to the largest
/// value reference (about a thousand entries here). Every get and set looks up through it.
#[derive(Debug, Default)]
pub struct VrIndex(Vec<u32>);

impl VrIndex {
    const NONE: u32 = u32::MAX;

    /// The index of `vrs`, the i-th value reference at position i.
    pub fn new(vrs: impl Iterator<Item = u32> + Clone) -> Self {
        let len = vrs.clone().max().map_or(0, |m| m as usize + 1);
        let mut table = vec![Self::NONE; len];
        for (i, vr) in vrs.enumerate() {
            table[vr as usize] = i as u32;
        }
        VrIndex(table)
    }

    /// The position of `vr`, if it is there.
    pub fn get(&self, vr: u32) -> Option<usize> {
        let at = *self.0.get(vr as usize)?;
        (at != Self::NONE).then_some(at as usize)
    }
}

/// The variable table of a model with what the FMI layer looks up on every call.
#[derive(Debug)]
pub struct ModelTable {
    pub info: &'static ModelInfo,
    /// Every variable in value-reference order (the modelDescription's order).
    pub variables: Vec<Variable>,
    pub guid: String,
    pub guid_c: CString,
    /// FMI 3.0's instantiationToken (its own interface: arrays, `time`, event indicators).
    pub token3: String,
    pub token3_c: CString,
    /// The FMI 3.0 variables.
    pub fmi3: Layout3,
    /// Value reference → position in `variables`.
    by_vr: VrIndex,
    /// States and derivatives, for a model that offers Model Exchange.
    pub model_exchange: Option<ModelExchangeTable>,
}

impl ModelTable {
    /// The table of `info` over the core's `variables`.
    pub fn new(info: &'static ModelInfo, variables: Vec<Variable>) -> Self {
        Self::with_model_exchange(info, variables, None)
    }

    /// The table of a model that may offer Model Exchange (`variables` include the states and
    /// derivatives `model_exchange` names).
    pub fn with_model_exchange(
        info: &'static ModelInfo,
        variables: Vec<Variable>,
        model_exchange: Option<ModelExchangeTable>,
    ) -> Self {
        let guid = guid::of_interface(info.identifier, &variables);
        let token3 = guid::of_fmi3_interface(info.identifier, &variables);
        let by_vr = VrIndex::new(variables.iter().map(|v| v.value_reference));
        // A GUID is hex digits, dashes and braces: it never holds a NUL.
        let guid_c = CString::new(guid.clone()).unwrap_or_default();
        let token3_c = CString::new(token3.clone()).unwrap_or_default();
        let mut table = ModelTable {
            info,
            variables,
            guid,
            guid_c,
            token3,
            token3_c,
            fmi3: Layout3::empty(),
            by_vr,
            model_exchange,
        };
        table.fmi3 = Layout3::new(&table);
        table
    }

    /// The GUID (FMI 2.0) or instantiation token (FMI 3.0).
    pub fn token(&self, api: Api) -> &str {
        match api {
            Api::Fmi2 => &self.guid,
            Api::Fmi3 => &self.token3,
        }
    }

    /// The variable with value reference `vr`.
    pub fn variable(&self, vr: u32) -> Option<&Variable> {
        self.variables.get(self.by_vr.get(vr)?)
    }

    /// The variable named `name`.
    pub fn by_name(&self, name: &str) -> Option<&Variable> {
        self.variables.iter().find(|v| v.name == name)
    }

    /// The inputs output `output` depends on directly (see [`ModelInfo::direct_feedthrough`]).
    pub fn direct_feedthrough(&self, output: &str) -> &'static [&'static str] {
        self.info
            .direct_feedthrough
            .iter()
            .find(|(name, _)| *name == output)
            .map_or(&[], |(_, inputs)| inputs)
    }

    /// Input value references, in order.
    pub fn inputs(&self) -> impl Iterator<Item = u32> + '_ {
        self.variables
            .iter()
            .filter(|v| v.causality == Causality::Input)
            .map(|v| v.value_reference)
    }
}

/// The FMI type name of a value kind (for messages and the modelDescription).
pub fn type_name(kind: ValueKind) -> &'static str {
    match kind {
        ValueKind::Real => "Real",
        ValueKind::Integer => "Integer",
        ValueKind::Boolean => "Boolean",
    }
}

/// Whether a variable of `variability` and `causality` may be set once initialised.
pub fn settable_after_initialisation(causality: Causality, variability: Variability) -> bool {
    causality == Causality::Input
        || (causality == Causality::Parameter && variability == Variability::Tunable)
}
