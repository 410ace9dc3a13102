//! The MAVLink parameter protocol over a vehicle's parameter table
//! ([`crate::param_table`]): PARAM_REQUEST_LIST, PARAM_REQUEST_READ and PARAM_SET, answered
//! with PARAM_VALUE.
//!
//! Values travel as float32 with C-cast encoding (an integer or boolean is its value as a
//! float). A PARAM_SET value is read as the shortest decimal that rounds to the float32 sent,
//! so `0.01` means 0.01, not 0.0099999998. A set takes effect at the vehicle's next reset.
//! A refused set is answered with PARAM_ERROR, a STATUSTEXT naming the parameter and its
//! bound, and PARAM_VALUE with the unchanged value.

use crate::sim::{Link, Sim};
use flyloop_core::ParamError;
use flyloop_core::params::ValueKind;
use flyloop_core::tasks::registry::TaskInstance;
use flyloop_core::tasks::registry::param_rows::{self, ParamEntry};
use mavlink::MavHeader;
use mavlink::dialects::common::{
    MavMessage, MavParamError, MavParamType, MavSeverity, PARAM_ERROR_DATA,
    PARAM_REQUEST_READ_DATA, PARAM_SET_DATA, PARAM_VALUE_DATA,
};
use mavlink::types::CharArray;

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

impl Sim {
    fn param_value(&self, i: usize, index: usize, entry: &ParamEntry, count: usize) -> MavMessage {
        let value =
            param_rows::get(&self.vehicles[i].config, entry.group, entry.name).unwrap_or(f64::NAN);
        MavMessage::PARAM_VALUE(PARAM_VALUE_DATA {
            param_value: value as f32,
            param_count: count as u16,
            param_index: index as u16,
            param_id: CharArray::from(entry.id.as_str()),
            param_type: param_type(entry.kind),
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
        let entries = param_rows::entries(self.options.task);
        for i in targets {
            for (index, e) in entries.iter().enumerate() {
                let m = self.param_value(i, index, e, entries.len());
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
        let entries = param_rows::entries(self.options.task);
        let wanted = param_id(&m.param_id);
        let found = if m.param_index >= 0 {
            entries
                .get(m.param_index as usize)
                .map(|e| (m.param_index as usize, e))
        } else {
            entries.iter().enumerate().find(|(_, e)| e.id == wanted)
        };
        for i in targets {
            match found {
                Some((index, e)) => {
                    let reply = self.param_value(i, index, e, entries.len());
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
        let Some(targets) = self.targets(m.target_system) else {
            return;
        };
        let entries = param_rows::entries(self.options.task);
        let wanted = param_id(&m.param_id);
        let Some((index, entry)) = entries.iter().enumerate().find(|(_, e)| e.id == wanted) else {
            for i in targets {
                let err = ParamError::UnknownName(wanted.clone());
                self.param_refused(link, out, i, requester, &wanted, -1, &err);
            }
            return;
        };
        let value = decimal_value(m.param_value);
        for i in targets {
            let v = &self.vehicles[i];
            let mut candidate = v.config.clone();
            let result = param_rows::set(&mut candidate, entry.group, entry.name, value)
                .and_then(|()| TaskInstance::build(v.kind, &candidate).map(|_| ()));
            match result {
                Ok(()) => {
                    tracing::debug!(
                        system_id = v.system_id,
                        param = entry.name,
                        value,
                        "parameter set"
                    );
                    self.vehicles[i].config = candidate;
                }
                Err(e) => self.param_refused(link, out, i, requester, &wanted, index as i16, &e),
            }
            let reply = self.param_value(i, index, entry, entries.len());
            self.push(link, out, i, &reply);
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
        let text = format!("vehicle {}: {e}", self.vehicles[i].system_id);
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
