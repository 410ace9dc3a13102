//! A fault plan: the faults written out (`[[faults]]`) and the faults drawn per episode
//! (`[[fault_randomization]]`), read from one TOML text that every front end passes as is
//! (the SITL's config file holds it; the gym writes it), checked against the flight.

use super::catalogue::Target;
use super::draw::FaultDraw;
use super::spec::FaultSpec;
use super::trigger::Reach;
use crate::error::ParamError;
use crate::rng::SimRng;
use serde::{Deserialize, Serialize};

/// Table of the written faults in a config file.
pub const FAULTS_TABLE: &str = "faults";
/// Table of the drawn faults in a config file.
pub const RANDOMIZATION_TABLE: &str = "fault_randomization";

/// Salt of the fault draws' generator: its draws disturb neither the episode's own stream
/// nor the domain randomisation's.
const FAULT_STREAM: u64 = 0x0fa1_7500_d0d0_0003;

/// The faults of a flight; empty (the default) = a healthy vehicle.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct FaultPlan {
    pub faults: Vec<FaultSpec>,
    pub draws: Vec<FaultDraw>,
}

impl FaultPlan {
    pub fn is_empty(&self) -> bool {
        self.faults.is_empty() && self.draws.is_empty()
    }

    /// Slots of an episode's schedule: one per written fault, then one per draw.
    pub fn slots(&self) -> usize {
        self.faults.len() + self.draws.len()
    }

    /// The plan in `text`: `[[faults]]` and `[[fault_randomization]]` arrays of tables (other
    /// keys are refused).
    pub fn from_toml_str(text: &str) -> Result<FaultPlan, ParamError> {
        let table: toml::Table = toml::from_str(text)?;
        let mut plan = FaultPlan::default();
        for (key, value) in &table {
            plan.add(key, value)?;
        }
        Ok(plan)
    }

    /// Adds the config file entry `key` = `value` (`faults` or `fault_randomization`: an
    /// array of tables, or one table).
    pub fn add(&mut self, key: &str, value: &toml::Value) -> Result<(), ParamError> {
        let tables: Vec<&toml::Table> = match value {
            toml::Value::Array(a) => a.iter().filter_map(toml::Value::as_table).collect(),
            toml::Value::Table(t) => vec![t],
            _ => Vec::new(),
        };
        let count = match value {
            toml::Value::Array(a) => a.len(),
            _ => 1,
        };
        if tables.len() != count || tables.is_empty() && count == 1 {
            return Err(ParamError::Parse(format!(
                "`{key}` must be tables (`[[{key}]]` entries)"
            )));
        }
        match key {
            FAULTS_TABLE => {
                for t in tables {
                    self.faults.push(FaultSpec::from_toml(t)?);
                }
            }
            RANDOMIZATION_TABLE => {
                for t in tables {
                    self.draws.push(FaultDraw::from_toml(t)?);
                }
            }
            _ => {
                return Err(ParamError::UnknownName(format!(
                    "{key}` in a fault plan; expected `{FAULTS_TABLE}` or `{RANDOMIZATION_TABLE}"
                )));
            }
        }
        Ok(())
    }

    /// Refuses faults the flight cannot have (a motor the frame lacks, a trigger that can
    /// never fire).
    pub fn check(&self, reach: &Reach) -> Result<(), ParamError> {
        for f in &self.faults {
            f.check(reach)?;
        }
        for d in &self.draws {
            d.check(reach)?;
        }
        Ok(())
    }

    /// Refuses link faults, naming the kind: `front_end` has no link for them.
    pub fn refuse_link(&self, front_end: &str) -> Result<(), ParamError> {
        match self
            .faults
            .iter()
            .find(|f| f.kind.spec().target == Target::Link)
        {
            Some(f) => Err(ParamError::Relation {
                name: "kind",
                requirement: format!(
                    "`{}` acts on a link of flyloop-sitl (the lockstep link, PX4's, ArduPilot's); {front_end} has none",
                    f.kind.name()
                ),
            }),
            None => Ok(()),
        }
    }

    /// The schedule of the episode with `seed`: the written faults, then one drawn fault
    /// (or none) per draw. No draws: the written faults, nothing drawn.
    pub fn schedule(&self, seed: u64, rotors: usize) -> Vec<Option<FaultSpec>> {
        let mut out: Vec<Option<FaultSpec>> = self.faults.iter().cloned().map(Some).collect();
        if !self.draws.is_empty() {
            let mut rng = SimRng::new(seed ^ FAULT_STREAM);
            out.extend(self.draws.iter().map(|d| d.draw(&mut rng, rotors)));
        }
        out
    }
}
