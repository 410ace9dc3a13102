//! The MAVLink parameter protocol over a vehicle's parameter table
//! ([`crate::param_table`]) or a multi-agent world's ([`crate::world_params`], one table every
//! vehicle of the world serves): PARAM_REQUEST_LIST, PARAM_REQUEST_READ and PARAM_SET,
//! answered with PARAM_VALUE.
//!
//! Values travel as float32 with C-cast encoding (an integer or boolean is its value as a
//! float). A PARAM_SET value is read as the shortest decimal that rounds to the float32 sent,
//! so `0.01` means 0.01, not 0.0099999998. A set takes effect at the vehicle's next reset
//! (a world's at the world's next reset; every vehicle of it answers with the new value).
//! A refused set is answered with PARAM_ERROR, a STATUSTEXT naming the parameter and its
//! bound, and PARAM_VALUE with the unchanged value.

use crate::sim::{Link, Sim};
use crate::world_params::{self, WorldParamRow};
use flyloop_core::ParamError;
use flyloop_core::params::ValueKind;
use flyloop_core::tasks::multi::{MultiError, MultiFlight};
use flyloop_core::tasks::registry::TaskInstance;
use flyloop_core::tasks::registry::param_rows::{self, ParamEntry};
use mavlink::MavHeader;
use mavlink::dialects::common::{
    MavMessage, MavParamError, MavParamType, MavSeverity, PARAM_ERROR_DATA,
    PARAM_REQUEST_READ_DATA, PARAM_SET_DATA, PARAM_VALUE_DATA,
};
use mavlink::types::CharArray;
use std::ops::Range;

/// The param_id as text (up to the first NUL).
fn param_id(id: &CharArray<16>) -> String {
    let bytes: &[u8] = id.as_slice();
    let end = bytes.iter().position(|&b| b == 0).unwrap_or(bytes.len());
    String::from_utf8_lossy(&bytes[..end]).into_owned()
}

fn param_type(kind: ValueKind) -> MavParamType {
    match kind {
        ValueKind::Real => MavParamType::MAV_PARAM_TYPE_REAL32,
        ValueKind::Integer => MavParamType::MAV_PARAM_TYPE_INT32,
        ValueKind::Boolean => MavParamType::MAV_PARAM_TYPE_UINT8,
    }
}

/// The f64 a float32 parameter value stands for: the shortest decimal that rounds to it.
pub fn decimal_value(value: f32) -> f64 {
    format!("{value}")
        .parse::<f64>()
        .unwrap_or(f64::from(value))
}

fn error_code(e: &ParamError) -> MavParamError {
    match e {
        ParamError::UnknownName(_) | ParamError::UnknownValueReference(_) => {
            MavParamError::MAV_PARAM_ERROR_DOES_NOT_EXIST
        }
        ParamError::NotSettable(_) => MavParamError::MAV_PARAM_ERROR_READ_ONLY,
        _ => MavParamError::MAV_PARAM_ERROR_VALUE_OUT_OF_RANGE,
    }
}

/// The rows a parameter request reads: a vehicle task's, or a world's (shared by its
/// vehicles).
enum Table {
    Task(Vec<ParamEntry>),
    World(Vec<WorldParamRow>),
}

impl Table {
    fn len(&self) -> usize {
        match self {
            Table::Task(rows) => rows.len(),
            Table::World(rows) => rows.len(),
        }
    }

    fn id(&self, index: usize) -> &str {
        match self {
            Table::Task(rows) => &rows[index].id,
            Table::World(rows) => &rows[index].id,
        }
    }

    fn kind(&self, index: usize) -> ValueKind {
        match self {
            Table::Task(rows) => rows[index].kind,
            Table::World(rows) => rows[index].kind,
        }
    }

    /// The index of the row whose `param_id` is `id`.
    fn position(&self, id: &str) -> Option<usize> {
        (0..self.len()).find(|&k| self.id(k) == id)
    }
}

/// A world that cannot be built from a configuration, as a parameter error.
fn as_param_error(e: MultiError) -> ParamError {
    match e {
        MultiError::Param(p) => p,
        other => ParamError::Parse(other.to_string()),
    }
}

impl Sim {
    fn param_table(&self) -> Table {
        match &self.world {
            Some(_) => Table::World(world_params::rows()),
            None => Table::Task(param_rows::entries(self.options.task)),
        }
    }

    /// Parameter `index` of `table` as vehicle `i` has it (for its next reset).
    fn param_get(&self, table: &Table, i: usize, index: usize) -> f64 {
        let value = match (table, &self.world) {
            (Table::World(rows), Some(w)) => world_params::get(&w.config, &rows[index]),
            (Table::Task(rows), _) => {
                let e = &rows[index];
                param_rows::get(&self.vehicles[i].config, e.group, e.name)
            }
            (Table::World(_), None) => return f64::NAN,
        };
        value.unwrap_or(f64::NAN)
    }

    /// Sets parameter `index` of `table` to `value` for vehicle `i`'s next reset (a world's
    /// for its next reset), if the task (world) builds with it; on error nothing changes.
    fn param_put(
        &mut self,
        table: &Table,
        i: usize,
        index: usize,
        value: f64,
    ) -> Result<(), ParamError> {
        match (table, &mut self.world) {
            (Table::World(rows), Some(w)) => {
                let mut candidate = w.config.clone();
                let n = w.num_agents();
                world_params::set(&mut candidate, &rows[index], value, n)?;
                MultiFlight::new(w.flight.scenario(), candidate.clone()).map_err(as_param_error)?;
                w.config = candidate;
                Ok(())
            }
            (Table::Task(rows), _) => {
                let e = &rows[index];
                let v = &mut self.vehicles[i];
                let mut candidate = v.config.clone();
                param_rows::set(&mut candidate, e.group, e.name, value)?;
                TaskInstance::build(v.kind, &candidate)?;
                v.config = candidate;
                Ok(())
            }
            (Table::World(_), None) => Err(ParamError::Parse("no world".to_string())),
        }
    }

    /// The vehicles whose parameters are vehicle `i`'s: a world's all share one table.
    fn param_sharers(&self, i: usize) -> Range<usize> {
        match &self.world {
            Some(w) => 0..w.num_agents(),
            None => i..i + 1,
        }
    }

    fn param_value(&self, table: &Table, i: usize, index: usize) -> MavMessage {
        MavMessage::PARAM_VALUE(PARAM_VALUE_DATA {
            param_value: self.param_get(table, i, index) as f32,
            param_count: table.len() as u16,
            param_index: index as u16,
            param_id: CharArray::from(table.id(index)),
            param_type: param_type(table.kind(index)),
        })
    }

    pub(crate) fn on_param_request_list(
        &mut self,
        link: Link,
        target_system: u8,
        out: &mut Vec<u8>,
    ) {
        let Some(targets) = self.targets(target_system) else {
            return;
        };
        let table = self.param_table();
        for i in targets {
            for index in 0..table.len() {
                let m = self.param_value(&table, i, index);
                self.push(link, out, i, &m);
            }
        }
    }

    pub(crate) fn on_param_request_read(
        &mut self,
        link: Link,
        requester: MavHeader,
        m: &PARAM_REQUEST_READ_DATA,
        out: &mut Vec<u8>,
    ) {
        let Some(targets) = self.targets(m.target_system) else {
            return;
        };
        let table = self.param_table();
        let wanted = param_id(&m.param_id);
        let found = if m.param_index >= 0 {
            Some(m.param_index as usize).filter(|&k| k < table.len())
        } else {
            table.position(&wanted)
        };
        for i in targets {
            match found {
                Some(index) => {
                    let reply = self.param_value(&table, i, index);
                    self.push(link, out, i, &reply);
                }
                None => {
                    let err = ParamError::UnknownName(wanted.clone());
                    self.param_refused(link, out, i, requester, &wanted, m.param_index, &err);
                }
            }
        }
    }

    pub(crate) fn on_param_set(
        &mut self,
        link: Link,
        requester: MavHeader,
        m: &PARAM_SET_DATA,
        out: &mut Vec<u8>,
    ) {
        let Some(mut targets) = self.targets(m.target_system) else {
            return;
        };
        let table = self.param_table();
        let wanted = param_id(&m.param_id);
        let Some(index) = table.position(&wanted) else {
            for i in targets {
                let err = ParamError::UnknownName(wanted.clone());
                self.param_refused(link, out, i, requester, &wanted, -1, &err);
            }
            return;
        };
        if self.world.is_some() {
            // One table for the whole world: set it once, every vehicle then reports it.
            targets = targets.start..(targets.start + 1).min(targets.end);
        }
        let value = decimal_value(m.param_value);
        for i in targets {
            match self.param_put(&table, i, index, value) {
                Ok(()) => tracing::debug!(
                    system_id = self.system_id_of(i),
                    param = table.id(index),
                    value,
                    "parameter set"
                ),
                Err(e) => self.param_refused(link, out, i, requester, &wanted, index as i16, &e),
            }
            for k in self.param_sharers(i) {
                let reply = self.param_value(&table, k, index);
                self.push(link, out, k, &reply);
            }
        }
    }

    // The refusal's context travels together; a struct for one call site would only rename it.
    #[allow(clippy::too_many_arguments)]
    fn param_refused(
        &mut self,
        link: Link,
        out: &mut Vec<u8>,
        i: usize,
        requester: MavHeader,
        id: &str,
        index: i16,
        e: &ParamError,
    ) {
        self.stats.refused_requests += 1;
        tracing::debug!(param = id, error = %e, "parameter request refused");
        let m = MavMessage::PARAM_ERROR(PARAM_ERROR_DATA {
            param_index: index,
            target_system: requester.system_id,
            target_component: requester.component_id,
            param_id: CharArray::from(id),
            error: error_code(e),
        });
        self.push(link, out, i, &m);
        let text = format!("vehicle {}: {e}", self.system_id_of(i).unwrap_or(0));
        self.push_text(link, out, i, MavSeverity::MAV_SEVERITY_ERROR, &text);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn float32_values_mean_the_decimal_a_user_typed() {
        assert_eq!(decimal_value(0.01), 0.01);
        assert_eq!(decimal_value(1.1), 1.1);
        assert_eq!(decimal_value(100_000_000.0), 1e8);
        assert_eq!(decimal_value(3.0), 3.0);
        assert!(decimal_value(f32::NAN).is_nan());
        assert_eq!(decimal_value(f32::INFINITY), f64::INFINITY);
    }
}
