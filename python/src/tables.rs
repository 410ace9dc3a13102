//! The core's tables for Python: task names, parameter sets built from `{name: value}`, and
//! [`describe`], everything the Python package needs to declare spaces and check arguments.

use flyloop_core::faults::FaultPlan;
use flyloop_core::params::ValueKind;
use flyloop_core::quadrotor::Frame;
use flyloop_core::quadrotor::frame::shipped_names;
use flyloop_core::tasks::InfoValue;
use flyloop_core::tasks::randomization::ParamRange;
use flyloop_core::tasks::registry::param_rows;
use flyloop_core::tasks::registry::{
    ModelKind, TaskConfig, TaskInstance, TaskKind, from_values_ranges_and_faults,
};
use numpy::PyArray1;
use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};

/// The task named `name` (the SITL's `--task`).
pub fn task_kind(name: &str) -> PyResult<TaskKind> {
    TaskKind::from_name(name).ok_or_else(|| {
        PyValueError::new_err(format!(
            "task must be 'hover', 'waypoints' or 'landing', got {name:?}"
        ))
    })
}

/// Prefix of a config key that holds a randomisation range: `"randomize.mass": (1.2, 1.8)`
/// (the SITL's config file has them in its `[randomize]` table).
const RANGE_PREFIX: &str = "randomize.";

/// Config key of the fault plan: the TOML text of its `[[faults]]` and
/// `[[fault_randomization]]` tables, exactly as the SITL's config file holds them.
const FAULTS_KEY: &str = "faults";

/// The parameter sets of `task` from `{core name or param_id: number}` and
/// `{"randomize.<name>": (low, high)}`, checked by the core exactly as the SITL checks its
/// parameter file; errors are ValueErrors carrying the core's message (it names the parameter
/// and its bound).
pub fn task_config(task: TaskKind, params: Option<&Bound<'_, PyDict>>) -> PyResult<TaskConfig> {
    let mut pairs: Vec<(String, f64)> = Vec::new();
    let mut ranges = Vec::new();
    let mut faults = FaultPlan::default();
    let mut frame = None;
    if let Some(params) = params {
        for (key, value) in params.iter() {
            let name: String = key.extract().map_err(|_| {
                PyTypeError::new_err(format!("parameter names are strings, got {key}"))
            })?;
            if name == FAULTS_KEY {
                let text: String = value.extract().map_err(|_| {
                    PyTypeError::new_err(format!(
                        "`{FAULTS_KEY}` must be the TOML text of [[faults]] / [[fault_randomization]] tables, got {value}"
                    ))
                })?;
                faults = FaultPlan::from_toml_str(&text)
                    .map_err(|e| PyValueError::new_err(e.to_string()))?;
                continue;
            }
            if name == FRAME_KEY {
                frame = Some(frame_named(&value)?);
                continue;
            }
            if let Some(param) = name.strip_prefix(RANGE_PREFIX) {
                let (low, high): (f64, f64) = value.extract().map_err(|_| {
                    PyTypeError::new_err(format!(
                        "randomisation range `{param}` must be a pair of numbers (low, high), got {value}"
                    ))
                })?;
                ranges.push(ParamRange {
                    name: param.to_string(),
                    low,
                    high,
                });
                continue;
            }
            let number: f64 = value.extract().map_err(|_| {
                PyTypeError::new_err(format!(
                    "parameter `{name}` must be a number or a boolean, got {value}"
                ))
            })?;
            pairs.push((name, number));
        }
    }
    from_values_ranges_and_faults(
        task,
        pairs.iter().map(|(k, v)| (k.as_str(), *v)),
        ranges,
        frame,
        faults,
    )
    .map_err(|e| PyValueError::new_err(e.to_string()))
}

/// The config key that names the flight tasks' frame: `"frame": "hexa_x"` (the SITL's config
/// file has it as its `[frame]` table).
const FRAME_KEY: &str = "frame";

/// The shipped frame named by `value`; the error lists the names.
fn frame_named(value: &Bound<'_, PyAny>) -> PyResult<Frame> {
    let names = shipped_names().collect::<Vec<_>>().join("', '");
    let name: String = value.extract().map_err(|_| {
        PyTypeError::new_err(format!(
            "frame must be a frame name ('{names}'), got {value}"
        ))
    })?;
    Frame::named(&name)
        .map_err(|_| PyValueError::new_err(format!("frame must be one of '{names}', got {name:?}")))
}

fn kind_name(kind: ValueKind) -> &'static str {
    match kind {
        ValueKind::Real => "real",
        ValueKind::Integer => "integer",
        ValueKind::Boolean => "boolean",
    }
}

/// The info layout of a task: (name, kind, number of values), kinds "real", "integer",
/// "flag", "vector".
pub fn info_layout(task: &TaskInstance) -> Vec<(&'static str, &'static str, usize)> {
    task.info()
        .into_iter()
        .map(|(name, value)| match value {
            InfoValue::Real(_) => (name, "real", 1),
            InfoValue::Integer(_) => (name, "integer", 1),
            InfoValue::Flag(_) => (name, "flag", 1),
            InfoValue::Vector(v) => (name, "vector", v.len()),
        })
        .collect()
}

/// Everything Python declares about `task` with parameters `params`: a dict with
/// `observation_low`/`observation_high` (float32 arrays), `observation` (its layout: list of
/// (name, count)), `action_low`/`action_high` (float64), `dt` (s), `info` (list of (name,
/// kind, count)), `parameters` (list of dicts: name, id, group, kind, unit, min, max,
/// default, value, description), `model`, `task`, and for the flight tasks `frame` (its name)
/// and `rotors` (its rotor count).
#[pyfunction]
#[pyo3(signature = (task, params=None))]
pub fn describe<'py>(
    py: Python<'py>,
    task: &str,
    params: Option<&Bound<'py, PyDict>>,
) -> PyResult<Bound<'py, PyDict>> {
    let kind = task_kind(task)?;
    let config = task_config(kind, params)?;
    let instance =
        TaskInstance::build(kind, &config).map_err(|e| PyValueError::new_err(e.to_string()))?;
    let out = PyDict::new(py);
    out.set_item("task", kind.frame_name())?;
    out.set_item("model", kind.model().name())?;
    let (lo, hi) = instance.observation_bounds();
    out.set_item("observation_low", PyArray1::from_slice(py, &lo))?;
    out.set_item("observation_high", PyArray1::from_slice(py, &hi))?;
    let (lo, hi) = instance.action_bounds();
    out.set_item("action_low", PyArray1::from_slice(py, &lo))?;
    out.set_item("action_high", PyArray1::from_slice(py, &hi))?;
    out.set_item("observation", instance.observation_layout())?;
    out.set_item("dt", instance.dt())?;
    out.set_item("info", info_layout(&instance))?;
    if kind.model() == ModelKind::Quadrotor {
        out.set_item("frame", config.frame.name())?;
        out.set_item("rotors", config.frame.rotor_count())?;
    }
    let defaults = TaskConfig::default();
    let rows = PyList::empty(py);
    for e in param_rows::entries(kind) {
        let row = PyDict::new(py);
        row.set_item("name", e.name)?;
        row.set_item("id", &e.id)?;
        row.set_item("group", e.group.label())?;
        row.set_item("kind", kind_name(e.kind))?;
        row.set_item("unit", e.unit)?;
        row.set_item("min", e.min)?;
        row.set_item("max", e.max)?;
        let get = |c: &TaskConfig| {
            param_rows::get(c, e.group, e.name)
                .map_err(|err| PyValueError::new_err(err.to_string()))
        };
        row.set_item("default", get(&defaults)?)?;
        row.set_item("value", get(&config)?)?;
        row.set_item("description", e.description)?;
        rows.append(row)?;
    }
    out.set_item("parameters", rows)?;
    Ok(out)
}

/// The core's shipped frames (`core/src/quadrotor/frame.rs`), so no Python module keeps a
/// copy of a rotor table: `{name: [(x, y, spin), ...]}`, each rotor's position forward and left
/// in arm lengths (body FLU) and its spin (+1 clockwise, −1 counter-clockwise seen from
/// above), in motor order.
#[pyfunction]
pub fn frames(py: Python<'_>) -> PyResult<Bound<'_, PyDict>> {
    let out = PyDict::new(py);
    for name in shipped_names() {
        let frame = Frame::named(name).map_err(|e| PyValueError::new_err(e.to_string()))?;
        let rotors: Vec<(f64, f64, i8)> = (frame.rotors().iter())
            .map(|r| (r.x, r.y, r.spin.sign() as i8))
            .collect();
        out.set_item(name, rotors)?;
    }
    Ok(out)
}

/// The core's fault catalogue: a list of dicts (`name`, `target`: "motor" / "sensor" /
/// "vehicle", `effect`, `fields`: list of dicts name, unit, min, max, default, description)
/// in the catalogue's order (a task's `fault_kind` info value is an index into it), and the
/// sensors' names in their `fault_target` order.
#[pyfunction]
pub fn fault_catalogue(py: Python<'_>) -> PyResult<(Bound<'_, PyList>, Vec<&'static str>)> {
    use flyloop_core::faults::catalogue::{CATALOGUE, SensorId, Target};
    let kinds = PyList::empty(py);
    for k in CATALOGUE.iter() {
        let row = PyDict::new(py);
        row.set_item("name", k.name)?;
        let target = match k.target {
            Target::Motor => "motor",
            Target::Sensor => "sensor",
            Target::Vehicle => "vehicle",
            Target::Link => "link",
        };
        row.set_item("target", target)?;
        row.set_item("effect", k.effect)?;
        let fields = PyList::empty(py);
        for f in k.fields {
            let d = PyDict::new(py);
            d.set_item("name", f.name)?;
            d.set_item("unit", f.unit)?;
            d.set_item("min", f.min)?;
            d.set_item("max", f.max)?;
            d.set_item("default", f.default)?;
            d.set_item("description", f.description)?;
            fields.append(d)?;
        }
        row.set_item("fields", fields)?;
        kinds.append(row)?;
    }
    Ok((kinds, SensorId::ALL.iter().map(|s| s.name()).collect()))
}
