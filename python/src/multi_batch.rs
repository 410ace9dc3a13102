//! [`MultiBatch`]: W worlds of N agents of one multi-agent task (the core's
//! [`MultiFlight`]) stepped in one call, writing into numpy arrays the caller allocated once.
//!
//! Rows are agents, world after world: row `w·N + i` is agent i of world w. The GIL is
//! released while the worlds step; with more than one thread the worlds are shared out over
//! a rayon pool. A world only touches its own rows, so the results do not depend on the
//! number of threads.

use crate::batch::{mut_of, mut_of1, slice_of, slice_of1};
use flyloop_core::tasks::InfoRef;
use flyloop_core::tasks::multi::{AgentFaults, MultiConfig, MultiFlight, Scenario};
use flyloop_core::tasks::randomization::ParamRange;
use flyloop_core::tasks::registry::push_info;
use numpy::{PyArray1, PyReadonlyArray1, PyReadonlyArray2, PyReadwriteArray1, PyReadwriteArray2};
use pyo3::exceptions::{PyRuntimeError, PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};
use rayon::prelude::*;

/// Prefix of a key that holds a randomisation range (as the single-agent tasks').
const RANGE_PREFIX: &str = "randomize.";
/// Key of the agents' fault tables: the TOML text of `[[faults]]` / `[[fault_randomization]]`
/// tables with an optional `agent` (as a SITL config file holds them).
const FAULTS_KEY: &str = "faults";

/// A flat float64 array handed to Python.
type Flat<'py> = Bound<'py, PyArray1<f64>>;

/// W worlds of one multi-agent task with one parameter set.
#[pyclass(module = "flyloop._native")]
pub struct MultiBatch {
    worlds: Vec<MultiFlight>,
    n_agents: usize,
    n_obs: usize,
    /// (name, number of values, kind: "real", "integer", "flag" or "vector").
    info_layout: Vec<(&'static str, usize, &'static str)>,
    n_info: usize,
    num_threads: usize,
    pool: Option<rayon::ThreadPool>,
}

impl std::fmt::Debug for MultiBatch {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("MultiBatch")
            .field("num_worlds", &self.worlds.len())
            .field("num_agents", &self.n_agents)
            .finish()
    }
}

/// One world and its rows of every array.
struct WorldRows<'a> {
    world: &'a mut MultiFlight,
    actions: &'a [f32],
    reset: bool,
    seed: u64,
    obs: &'a mut [f32],
    info: &'a mut [f32],
    rewards: &'a mut [f64],
    terminated: &'a mut [bool],
    truncated: &'a mut [bool],
    active: &'a mut [bool],
}

/// The config of a multi-agent task from `{core name: number}`,
/// `{"randomize.<name>": (low, high)}` and `{"faults": TOML text}`; errors carry the core's
/// message.
fn multi_config(params: Option<&Bound<'_, PyDict>>) -> PyResult<MultiConfig> {
    let mut pairs: Vec<(String, f64)> = Vec::new();
    let mut ranges = Vec::new();
    let mut faults = AgentFaults::default();
    for (key, value) in params.into_iter().flat_map(|p| p.iter()) {
        let name: String = key
            .extract()
            .map_err(|_| PyTypeError::new_err(format!("parameter names are strings, got {key}")))?;
        if name == FAULTS_KEY {
            let text: String = value.extract().map_err(|_| {
                PyTypeError::new_err(format!(
                    "`{FAULTS_KEY}` must be the TOML text of [[faults]] / [[fault_randomization]] tables, got {value}"
                ))
            })?;
            faults = AgentFaults::from_toml_str(&text)
                .map_err(|e| PyValueError::new_err(e.to_string()))?;
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
    MultiConfig::from_values(pairs.iter().map(|(n, v)| (n.as_str(), *v)), ranges)
        .and_then(|c| c.with_faults(faults))
        .map_err(|e| PyValueError::new_err(e.to_string()))
}

/// Resets or steps one world, then writes its agents' rows.
fn run_world(rows: WorldRows<'_>, n_obs: usize, n_info: usize) -> Result<(), String> {
    let world = rows.world;
    if rows.reset {
        world.reset(rows.seed).map_err(|e| e.to_string())?;
    } else {
        let actions: Vec<f64> = rows.actions.iter().map(|&a| f64::from(a)).collect();
        world.step(&actions).map_err(|e| e.to_string())?;
    }
    let mut values = Vec::with_capacity(n_info);
    for i in 0..world.num_agents() {
        let o = world.outcome(i);
        rows.rewards[i] = o.reward;
        rows.terminated[i] = o.terminated;
        rows.truncated[i] = o.truncated;
        rows.active[i] = rows.reset || world.is_active(i);
        world.write_observation(i, &mut rows.obs[i * n_obs..(i + 1) * n_obs]);
        values.clear();
        world.visit_info(i, &mut |_, v| push_info(&mut values, v));
        if values.len() != n_info {
            return Err(format!(
                "agent {i}'s info has {} values, expected {n_info}",
                values.len()
            ));
        }
        rows.info[i * n_info..(i + 1) * n_info].copy_from_slice(&values);
    }
    Ok(())
}

#[pymethods]
impl MultiBatch {
    /// `num_worlds` worlds of `task` ("multi_hover", "swap") built from `params` ({core
    /// name: number}, "randomize.<name>": (low, high); checked by the core), stepped over
    /// `num_threads` threads.
    #[new]
    #[pyo3(signature = (task, params=None, num_worlds=1, num_threads=1))]
    fn new(
        task: &str,
        params: Option<&Bound<'_, PyDict>>,
        num_worlds: usize,
        num_threads: usize,
    ) -> PyResult<Self> {
        let scenario = Scenario::from_name(task).ok_or_else(|| {
            PyValueError::new_err(format!(
                "task must be 'multi_hover' or 'swap', got {task:?}"
            ))
        })?;
        if num_worlds == 0 || num_threads == 0 {
            return Err(PyValueError::new_err(format!(
                "num_worlds and num_threads must be at least 1, got {num_worlds} and {num_threads}"
            )));
        }
        let config = multi_config(params)?;
        let first =
            MultiFlight::new(scenario, config).map_err(|e| PyValueError::new_err(e.to_string()))?;
        let mut info_layout = Vec::new();
        first.visit_info(0, &mut |name, v| {
            let mut values = Vec::new();
            push_info(&mut values, v);
            let kind = match v {
                InfoRef::Real(_) => "real",
                InfoRef::Integer(_) => "integer",
                InfoRef::Flag(_) => "flag",
                InfoRef::Vector(_) => "vector",
            };
            info_layout.push((name, values.len(), kind));
        });
        let n_info = info_layout.iter().map(|(_, n, _)| n).sum();
        let threads = num_threads.min(num_worlds);
        let pool = if threads > 1 {
            Some(
                rayon::ThreadPoolBuilder::new()
                    .num_threads(threads)
                    .thread_name(|i| format!("flyloop-world-{i}"))
                    .build()
                    .map_err(|e| PyRuntimeError::new_err(format!("cannot start threads: {e}")))?,
            )
        } else {
            None
        };
        Ok(MultiBatch {
            n_agents: first.num_agents(),
            n_obs: first.observation_size(),
            worlds: vec![first; num_worlds],
            info_layout,
            n_info,
            num_threads: threads,
            pool,
        })
    }

    #[getter]
    fn num_worlds(&self) -> usize {
        self.worlds.len()
    }

    #[getter]
    fn num_agents(&self) -> usize {
        self.n_agents
    }

    #[getter]
    fn num_threads(&self) -> usize {
        self.num_threads
    }

    #[getter]
    fn observation_size(&self) -> usize {
        self.n_obs
    }

    #[getter]
    fn action_size(&self) -> usize {
        flyloop_core::tasks::multi::ACTION_SIZE
    }

    #[getter]
    fn info_size(&self) -> usize {
        self.n_info
    }

    /// The spaces and layouts: {"observation_low", "observation_high", "action_low",
    /// "action_high" (arrays), "observation_layout" ([(name, size)]), "info_layout" ([(name, size, kind)]), "dt"}.
    fn describe<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let w = &self.worlds[0];
        let d = PyDict::new(py);
        let (olo, ohi) = w.observation_bounds();
        let (alo, ahi) = w.action_bounds();
        d.set_item("observation_low", PyArray1::from_vec(py, olo))?;
        d.set_item("observation_high", PyArray1::from_vec(py, ohi))?;
        d.set_item("action_low", PyArray1::from_vec(py, alo))?;
        d.set_item("action_high", PyArray1::from_vec(py, ahi))?;
        d.set_item(
            "observation_layout",
            PyList::new(py, w.observation_layout())?,
        )?;
        d.set_item("info_layout", PyList::new(py, self.info_layout.clone())?)?;
        d.set_item("dt", w.dt())?;
        Ok(d)
    }

    /// Agent positions and targets of world `w` (ENU, m): two (N, 3) arrays, for rendering.
    fn positions<'py>(&self, py: Python<'py>, w: usize) -> PyResult<(Flat<'py>, Flat<'py>)> {
        let world = self.worlds.get(w).ok_or_else(|| {
            PyValueError::new_err(format!(
                "world {w} out of range: {} worlds",
                self.worlds.len()
            ))
        })?;
        let n = world.num_agents();
        let mut p = Vec::with_capacity(3 * n);
        let mut t = Vec::with_capacity(3 * n);
        for i in 0..n {
            p.extend(world.world().vehicle(i).body().position.iter());
            t.extend(world.target(i).iter());
        }
        Ok((PyArray1::from_vec(py, p), PyArray1::from_vec(py, t)))
    }

    /// Steps every world with its agents' rows of `actions` (float32, (W·N, 4); non-finite
    /// values refuse the whole step with ValueError and change nothing; a done agent's row is
    /// ignored) — except worlds whose `reset` entry is set: they start a new episode with
    /// their entry of `seeds`. Writes obs (W·N, n_obs) float32, info (W·N, info_size)
    /// float32, rewards (W·N,) float64, terminated, truncated and active (W·N,) bool (active:
    /// the agent took part in this step or its world was reset).
    #[allow(clippy::too_many_arguments)]
    fn step(
        &mut self,
        py: Python<'_>,
        actions: PyReadonlyArray2<'_, f32>,
        reset: PyReadonlyArray1<'_, bool>,
        seeds: PyReadonlyArray1<'_, u64>,
        mut obs: PyReadwriteArray2<'_, f32>,
        mut info: PyReadwriteArray2<'_, f32>,
        mut rewards: PyReadwriteArray1<'_, f64>,
        mut terminated: PyReadwriteArray1<'_, bool>,
        mut truncated: PyReadwriteArray1<'_, bool>,
        mut active: PyReadwriteArray1<'_, bool>,
    ) -> PyResult<()> {
        let (w, n) = (self.worlds.len(), self.n_agents);
        let rows = w * n;
        let n_act = flyloop_core::tasks::multi::ACTION_SIZE;
        let actions = slice_of("actions", &actions, [rows, n_act])?;
        let reset = slice_of1("reset", &reset, w)?;
        let seeds = slice_of1("seeds", &seeds, w)?;
        let obs = mut_of("obs", &mut obs, [rows, self.n_obs])?;
        let info = mut_of("info", &mut info, [rows, self.n_info])?;
        let rewards = mut_of1("rewards", &mut rewards, rows)?;
        let terminated = mut_of1("terminated", &mut terminated, rows)?;
        let truncated = mut_of1("truncated", &mut truncated, rows)?;
        let active = mut_of1("active", &mut active, rows)?;
        for (r, row) in actions.chunks_exact(n_act).enumerate() {
            if reset[r / n] {
                continue;
            }
            if let Some(j) = row.iter().position(|a| !a.is_finite()) {
                return Err(PyValueError::new_err(format!(
                    "actions[{r}, {j}] = {} (world {}, agent {}): actions must be finite; step refused",
                    row[j],
                    r / n,
                    r % n
                )));
            }
        }
        let (n_obs, n_info) = (self.n_obs, self.n_info);
        let parts: Vec<WorldRows<'_>> = (self.worlds.iter_mut())
            .zip(actions.chunks_exact(n * n_act))
            .zip(obs.chunks_exact_mut(n * n_obs))
            .zip(info.chunks_exact_mut(n * n_info))
            .zip(rewards.chunks_exact_mut(n))
            .zip(terminated.chunks_exact_mut(n))
            .zip(truncated.chunks_exact_mut(n))
            .zip(active.chunks_exact_mut(n))
            .enumerate()
            .map(
                |(
                    k,
                    (((((((world, actions), obs), info), rewards), terminated), truncated), active),
                )| {
                    WorldRows {
                        world,
                        actions,
                        reset: reset[k],
                        seed: seeds[k],
                        obs,
                        info,
                        rewards,
                        terminated,
                        truncated,
                        active,
                    }
                },
            )
            .collect();
        let pool = self.pool.as_ref();
        py.detach(move || match pool {
            Some(pool) => pool.install(|| {
                parts
                    .into_par_iter()
                    .try_for_each(|rows| run_world(rows, n_obs, n_info))
            }),
            None => parts
                .into_iter()
                .try_for_each(|rows| run_world(rows, n_obs, n_info)),
        })
        .map_err(|e| PyRuntimeError::new_err(format!("step failed: {e}")))
    }
}
