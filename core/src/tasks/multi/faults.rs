//! Faults in a multi-agent task: the single-agent fault tables (`[[faults]]`,
//! `[[fault_randomization]]`, [`crate::faults`]) with one more key, `agent` (the agent's
//! index, 0 = `drone_0`), that addresses a table to one agent; a table without it is every
//! agent's. Each agent flies the tables addressed to it as its own [`FaultPlan`], drawn from
//! its own seed (forked from the episode's), so the same seed gives the same faults.
//!
//! Every agent reports the same info slots — one per table, written ones first, in the order
//! they were given — so that all agents' info rows have one layout: a slot whose table is
//! another agent's reads as a slot with no fault drawn (kind −1, never fired).
//!
//! The air faults (gust, wind shear) are refused here: the world's wind field sets each
//! vehicle's wind, so a per-vehicle fault wind has no place yet.

use crate::error::ParamError;
use crate::faults::catalogue::FaultKind;
use crate::faults::draw::FaultDraw;
use crate::faults::plan::{FAULTS_TABLE, RANDOMIZATION_TABLE};
use crate::faults::{FaultPlan, FaultSpec, Reach};
use crate::tasks::InfoRef;

/// The key that addresses a fault table to one agent.
pub const AGENT_KEY: &str = "agent";

/// The info entries of a fault slot, in the order a flight link visits them.
const INFO_NAMES: [&str; 4] = ["fault_kind", "fault_target", "fault_time", "fault_active"];
/// What a slot of another agent's table reads (kind, target, time, active).
const EMPTY_SLOT: [f64; 4] = [-1.0, 0.0, -1.0, 0.0];

/// The fault tables of a multi-agent task, each with the agent it is for (`None`: all).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct AgentFaults {
    written: Vec<(Option<u32>, FaultSpec)>,
    drawn: Vec<(Option<u32>, FaultDraw)>,
}

impl AgentFaults {
    pub fn is_empty(&self) -> bool {
        self.written.is_empty() && self.drawn.is_empty()
    }

    /// Info slots every agent reports: one per table.
    pub fn slots(&self) -> usize {
        self.written.len() + self.drawn.len()
    }

    /// The tables in `text` (`[[faults]]` and `[[fault_randomization]]`, each with an
    /// optional `agent`); other keys are refused.
    pub fn from_toml_str(text: &str) -> Result<AgentFaults, ParamError> {
        let table: toml::Table = toml::from_str(text)?;
        let mut faults = AgentFaults::default();
        for (key, value) in &table {
            faults.add(key, value)?;
        }
        Ok(faults)
    }

    /// Adds the config file entry `key` = `value` (`faults` or `fault_randomization`: an
    /// array of tables or one table), as [`FaultPlan::add`] does, each table with its
    /// `agent` taken out.
    pub fn add(&mut self, key: &str, value: &toml::Value) -> Result<(), ParamError> {
        let tables: Vec<toml::Value> = match value {
            toml::Value::Array(a) => a.clone(),
            other => vec![other.clone()],
        };
        for table in tables {
            let (agent, table) = take_agent(key, table)?;
            // The single-agent reader checks the rest of the table and names what it refuses.
            let mut one = FaultPlan::default();
            one.add(key, &table)?;
            one.refuse_link("a multi-agent task")?;
            if let Some(spec) = one.faults.pop() {
                refuse_air(std::slice::from_ref(&spec.kind))?;
                self.written.push((agent, spec));
            }
            if let Some(draw) = one.draws.pop() {
                refuse_air(&draw.kinds)?;
                self.drawn.push((agent, draw));
            }
        }
        Ok(())
    }

    /// Refuses an `agent` the task lacks, and faults the flight cannot have (`reach`: the
    /// episode's length, the frame's rotors; multi-agent tasks have no waypoints).
    pub fn check(&self, num_agents: u32, reach: &Reach) -> Result<(), ParamError> {
        let agents = (self.written.iter().map(|(a, _)| a)).chain(self.drawn.iter().map(|(a, _)| a));
        for &agent in agents.flatten() {
            if agent >= num_agents {
                return Err(ParamError::OutOfRange {
                    role: crate::error::Role::Parameter,
                    name: AGENT_KEY,
                    value: f64::from(agent),
                    min: 0.0,
                    max: f64::from(num_agents) - 1.0,
                    unit: "",
                });
            }
        }
        for (_, spec) in &self.written {
            spec.check(reach)?;
        }
        for (_, draw) in &self.drawn {
            draw.check(reach)?;
        }
        Ok(())
    }

    /// Agent `agent`'s plan: the tables addressed to it or to every agent, in their order.
    pub fn plan(&self, agent: u32) -> FaultPlan {
        let mine = |a: &Option<u32>| a.is_none_or(|a| a == agent);
        FaultPlan {
            faults: (self.written.iter().filter(|(a, _)| mine(a)))
                .map(|(_, s)| s.clone())
                .collect(),
            draws: (self.drawn.iter().filter(|(a, _)| mine(a)))
                .map(|(_, d)| d.clone())
                .collect(),
        }
    }

    /// For each of the task's slots, agent `agent`'s own slot in its plan (`None`: the
    /// table is another agent's).
    pub fn slot_map(&self, agent: u32) -> Vec<Option<usize>> {
        let agents =
            (self.written.iter().map(|(a, _)| *a)).chain(self.drawn.iter().map(|(a, _)| *a));
        let mut own = 0;
        agents
            .map(|a| {
                a.is_none_or(|a| a == agent).then(|| {
                    own += 1;
                    own - 1
                })
            })
            .collect()
    }
}

/// Takes `agent` out of one table (a whole number ≥ 0); the rest is the single-agent table.
fn take_agent(key: &str, table: toml::Value) -> Result<(Option<u32>, toml::Value), ParamError> {
    let toml::Value::Table(mut t) = table else {
        return Err(ParamError::Parse(format!(
            "`{key}` must be tables (`[[{key}]]` entries)"
        )));
    };
    let agent = match t.remove(AGENT_KEY) {
        None => None,
        Some(v) => match v.as_integer().and_then(|i| u32::try_from(i).ok()) {
            Some(i) => Some(i),
            None => {
                return Err(ParamError::Parse(format!(
                    "{key}: `{AGENT_KEY}` must be an agent's index (a whole number >= 0: 0 is drone_0), got {v}"
                )));
            }
        },
    };
    Ok((agent, toml::Value::Table(t)))
}

fn refuse_air(kinds: &[FaultKind]) -> Result<(), ParamError> {
    for kind in kinds {
        if matches!(kind, FaultKind::Gust | FaultKind::WindShear) {
            return Err(ParamError::Relation {
                name: "kind",
                requirement: format!(
                    "`{}` is not available in a multi-agent task yet: the world's wind field sets every vehicle's wind (use the world's wind parameters)",
                    kind.spec().name
                ),
            });
        }
    }
    Ok(())
}

/// Writes one agent's fault info: the four slot vectors of the task's layout, from the
/// values its flight link visits (`own`: name → its own slots) through `map`
/// ([`AgentFaults::slot_map`]).
pub fn visit_slots(
    map: &[Option<usize>],
    own: &[(&'static str, Vec<f64>)],
    scratch: &mut Vec<f64>,
    visit: &mut crate::tasks::InfoVisitor<'_>,
) {
    for (k, name) in INFO_NAMES.into_iter().enumerate() {
        let values = own.iter().find(|(n, _)| *n == name).map(|(_, v)| v);
        scratch.clear();
        scratch.extend(map.iter().map(|slot| match (slot, values) {
            (Some(s), Some(v)) => v.get(*s).copied().unwrap_or(EMPTY_SLOT[k]),
            _ => EMPTY_SLOT[k],
        }));
        visit(name, InfoRef::Vector(scratch));
    }
}

/// Whether an info entry's name is one of the fault slots'.
pub fn is_slot_entry(name: &str) -> bool {
    INFO_NAMES.contains(&name)
}

/// The tables' keys (a front end reading a config file routes these entries to
/// [`AgentFaults::add`]).
pub const TABLES: [&str; 2] = [FAULTS_TABLE, RANDOMIZATION_TABLE];
