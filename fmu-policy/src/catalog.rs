//! Policy.fmu's catalog: the policies this library has loaded (from an FMU's resources or a
//! policy folder), each with its FMI table, found again by the folder they came from. The
//! library registers it with flyloop-fmu's FMI layer when it is loaded ([`crate::register`]).

use crate::error::PolicyError;
use crate::model::{Loaded, Policy, Shape};
use crate::network::Network;
use crate::recipe::{Interface, Recipe};
use flyloop_core::variables::Rows;
use flyloop_fmu::api::Api;
use flyloop_fmu::engine::{Engine, Simulation};
use flyloop_fmu::error::FmuError;
use flyloop_fmu::model::Table;
use flyloop_fmu::models::Catalog;
use flyloop_fmu::table::{Array, ModelInfo};
use std::borrow::Cow;
use std::path::Path;
use std::sync::{Arc, Mutex, PoisonError};

/// Every Policy.fmu's modelIdentifier (its binary is `binaries/<platform>/Policy.so`).
pub const IDENTIFIER: &str = "Policy";

/// The tables of the policies loaded so far, by key. Tables live as long as the library
/// (FMI needs `'static` tables; a process loads a handful of policies).
static LOADED: Mutex<Vec<&'static Table<Policy>>> = Mutex::new(Vec::new());

/// The key of a policy folder: its canonical path.
fn key_of(folder: &Path) -> String {
    let canonical = folder
        .canonicalize()
        .unwrap_or_else(|_| folder.to_path_buf());
    canonical.display().to_string()
}

/// The loaded policy of `key`, if this process loaded it.
pub fn loaded(key: &str) -> Option<Arc<Loaded>> {
    let tables = LOADED.lock().unwrap_or_else(PoisonError::into_inner);
    let table = tables.iter().find(|t| t.shape.0.key == key)?;
    Some(table.shape.0.clone())
}

/// Reads the recipe and the network of `folder`, checking them against each other.
pub fn load(folder: &Path) -> Result<Loaded, PolicyError> {
    let recipe = Recipe::read(folder)?;
    let network = Network::load(
        &folder.join(&recipe.network),
        recipe.observation_size(),
        recipe.action_size(),
    )?;
    Ok(Loaded {
        key: key_of(folder),
        recipe,
        network,
    })
}

/// The table of the policy in `folder`, loading it on first use.
pub fn table_for(folder: &Path) -> Result<&'static Table<Policy>, PolicyError> {
    let key = key_of(folder);
    let mut tables = LOADED.lock().unwrap_or_else(PoisonError::into_inner);
    if let Some(table) = tables.iter().find(|t| t.shape.0.key == key) {
        return Ok(table);
    }
    let table: &'static Table<Policy> = Box::leak(Box::new(table_of(load(folder)?)));
    tables.push(table);
    Ok(table)
}

/// The FMI table of a loaded policy.
pub fn table_of(loaded: Loaded) -> Table<Policy> {
    let shape = Shape(Arc::new(loaded));
    let rows = Rows::of(&shape);
    let inputs: &'static [&'static str] = Box::leak(
        rows.inputs
            .iter()
            .map(|r| r.name)
            .collect::<Vec<_>>()
            .into_boxed_slice(),
    );
    let feedthrough: Vec<(&'static str, &'static [&'static str])> =
        rows.outputs.iter().map(|r| (r.name, inputs)).collect();
    let recipe = &shape.0.recipe;
    let (what, out) = match recipe.interface() {
        Interface::HoverMotors => (
            format!("{} motors", recipe.rotors),
            "the plant's motor commands",
        ),
        Interface::RatesEstimate => (
            "thrust and body rates".to_string(),
            "RateController's setpoint (thrust roll_rate pitch_rate yaw_rate)",
        ),
    };
    // FMI 3.0 gathers the motor commands into one array; a setpoint stays four scalars.
    let arrays = match recipe.interface() {
        Interface::HoverMotors => vec![Array {
            name: "motor_command",
            description: Cow::Owned(format!(
                "Commands of the {} motors, 0 .. 1 each (the plant's motor_command)",
                recipe.rotors
            )),
            first: "motor_command_0",
            len: recipe.rotors,
        }],
        Interface::RatesEstimate => Vec::new(),
    };
    let info = ModelInfo {
        identifier: IDENTIFIER,
        description: Cow::Owned(format!(
            "flyloop Policy: a trained policy ({} observation, {what}; ONNX evaluated by \
             tract) acting every {} s on the plant's outputs (inputs of the same names) \
             toward the target target_x/y/z; {out} out. From: {}",
            recipe.observation, recipe.sample_period, recipe.source
        )),
        default_experiment: (0.0, 10.0, recipe.sample_period),
        // A tick at a communication point reads the inputs set there.
        direct_feedthrough: Box::leak(feedthrough.into_boxed_slice()),
        state_free_outputs: &[],
        arrays,
        event_indicators: &[],
        descriptions: Vec::new(),
    };
    Table::new(info, shape, rows, Vec::new(), None)
}

/// The policies of this library, as flyloop-fmu's FMI layer asks for them.
#[derive(Debug)]
pub struct Policies;

impl Catalog for Policies {
    fn simulation_for(
        &self,
        api: Api,
        token: &str,
        resources: Option<&Path>,
    ) -> Option<Result<Box<dyn Simulation>, FmuError>> {
        let table = match table_for(resources?) {
            Ok(table) => table,
            Err(e) => return Some(Err(FmuError::InvalidArgument(format!("Policy.fmu: {e}")))),
        };
        (token == table.table.token(api)).then(|| Engine::start(table))
    }
}
