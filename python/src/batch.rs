//! [`Batch`]: N core task instances stepped together.
//!
//! Every call writes into numpy arrays the caller allocated once (no per-env Python object);
//! the GIL is released while the envs step, and with more than one thread the envs are split
//! into contiguous chunks over a rayon pool. Each env only ever touches its own rows, so the
//! results do not depend on the number of threads.

use crate::tables::{task_config, task_kind};
use flyloop_core::tasks::InfoValue;
use flyloop_core::tasks::registry::{TaskInstance, clamp_controls, push_infos};
use numpy::{PyArray1, PyReadonlyArray1, PyReadonlyArray2, PyReadwriteArray1, PyReadwriteArray2};
use pyo3::exceptions::{PyRuntimeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use rayon::prelude::*;

/// Below this many envs per thread a step runs in the calling thread: handing work to the
/// pool costs more than it saves.
const MIN_ENVS_PER_THREAD: usize = 32;

/// N instances of one task with one parameter set.
#[pyclass(module = "flyloop._native")]
pub struct Batch {
    envs: Vec<TaskInstance>,
    lo: Vec<f64>,
    hi: Vec<f64>,
    n_obs: usize,
    n_info: usize,
    num_threads: usize,
    pool: Option<rayon::ThreadPool>,
    closed: bool,
}

impl std::fmt::Debug for Batch {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Batch")
            .field("num_envs", &self.envs.len())
            .field("num_threads", &self.num_threads)
            .finish()
    }
}

/// One contiguous run of envs and the rows of every array that belong to them.
struct Rows<'a> {
    envs: &'a mut [TaskInstance],
    actions: &'a [f32],
    reset: &'a [bool],
    seeds: &'a [u64],
    obs: &'a mut [f32],
    info: &'a mut [f32],
    rewards: &'a mut [f64],
    terminated: &'a mut [bool],
    truncated: &'a mut [bool],
}

/// The fixed sizes a chunk needs.
#[derive(Clone, Copy)]
struct Sizes<'a> {
    n_act: usize,
    n_obs: usize,
    n_info: usize,
    lo: &'a [f64],
    hi: &'a [f64],
}

/// Steps (or resets, where `reset` is set) every env of `rows`.
fn run_rows(rows: Rows<'_>, sizes: Sizes<'_>) -> Result<(), String> {
    let mut command = Vec::with_capacity(sizes.n_act);
    let mut info = Vec::with_capacity(sizes.n_info);
    for (i, env) in rows.envs.iter_mut().enumerate() {
        if rows.reset[i] {
            env.reset(rows.seeds[i]);
            rows.rewards[i] = 0.0;
            rows.terminated[i] = false;
            rows.truncated[i] = false;
        } else {
            let action = &rows.actions[i * sizes.n_act..(i + 1) * sizes.n_act];
            clamp_controls(action, sizes.lo, sizes.hi, &mut command).map_err(|e| e.to_string())?;
            let outcome = env.step(&command).map_err(|e| e.to_string())?;
            rows.rewards[i] = outcome.reward;
            rows.terminated[i] = outcome.terminated;
            rows.truncated[i] = outcome.truncated;
        }
        env.write_observation(&mut rows.obs[i * sizes.n_obs..(i + 1) * sizes.n_obs]);
        info.clear();
        push_infos(env, &mut info);
        if info.len() != sizes.n_info {
            return Err(format!(
                "the task's info has {} values, expected {}",
                info.len(),
                sizes.n_info
            ));
        }
        rows.info[i * sizes.n_info..(i + 1) * sizes.n_info].copy_from_slice(&info);
    }
    Ok(())
}

/// Splits `rows` into `parts` contiguous chunks of (nearly) equal size.
fn split<'a>(mut rows: Rows<'a>, sizes: Sizes<'_>, parts: usize) -> Vec<Rows<'a>> {
    let n = rows.envs.len();
    let per = n.div_ceil(parts.max(1)).max(1);
    let mut out = Vec::with_capacity(parts);
    while !rows.envs.is_empty() {
        let k = per.min(rows.envs.len());
        let (envs, envs_rest) = std::mem::take(&mut rows.envs).split_at_mut(k);
        let (actions, actions_rest) = rows.actions.split_at(k * sizes.n_act);
        let (reset, reset_rest) = rows.reset.split_at(k);
        let (seeds, seeds_rest) = rows.seeds.split_at(k);
        let (obs, obs_rest) = std::mem::take(&mut rows.obs).split_at_mut(k * sizes.n_obs);
        let (info, info_rest) = std::mem::take(&mut rows.info).split_at_mut(k * sizes.n_info);
        let (rewards, rewards_rest) = std::mem::take(&mut rows.rewards).split_at_mut(k);
        let (terminated, term_rest) = std::mem::take(&mut rows.terminated).split_at_mut(k);
        let (truncated, trunc_rest) = std::mem::take(&mut rows.truncated).split_at_mut(k);
        out.push(Rows {
            envs,
            actions,
            reset,
            seeds,
            obs,
            info,
            rewards,
            terminated,
            truncated,
        });
        rows = Rows {
            envs: envs_rest,
            actions: actions_rest,
            reset: reset_rest,
            seeds: seeds_rest,
            obs: obs_rest,
            info: info_rest,
            rewards: rewards_rest,
            terminated: term_rest,
            truncated: trunc_rest,
        };
    }
    out
}

/// Runs every env of `rows`: over `pool` in up to `threads` contiguous chunks of (nearly) equal
/// size, no more chunks than [`MIN_ENVS_PER_THREAD`] envs each allow, when there are envs for
/// two; in the calling thread otherwise.
fn run_all(
    rows: Rows<'_>,
    sizes: Sizes<'_>,
    pool: Option<&rayon::ThreadPool>,
    threads: usize,
) -> Result<(), String> {
    let n = rows.envs.len();
    match pool {
        Some(pool) if n >= MIN_ENVS_PER_THREAD * 2 => {
            let parts = threads.min(n / MIN_ENVS_PER_THREAD).max(1);
            let chunks = split(rows, sizes, parts);
            pool.install(|| {
                chunks
                    .into_par_iter()
                    .try_for_each(|rows| run_rows(rows, sizes))
            })
        }
        _ => run_rows(rows, sizes),
    }
}

/// ValueError naming the first non-finite action of an env that is not reset.
fn refuse_non_finite(actions: &[f32], reset: &[bool], n_act: usize) -> PyResult<()> {
    for (i, row) in actions.chunks_exact(n_act.max(1)).enumerate() {
        if reset[i] {
            continue;
        }
        if let Some(j) = row.iter().position(|a| !a.is_finite()) {
            return Err(PyValueError::new_err(format!(
                "actions[{i}, {j}] = {}: actions must be finite; step refused",
                row[j]
            )));
        }
    }
    Ok(())
}

fn shape_error(what: &str, expected: &[usize], got: &[usize]) -> PyErr {
    PyValueError::new_err(format!("{what} must have shape {expected:?}, got {got:?}"))
}

pub(crate) fn slice_of<'a, T: numpy::Element>(
    what: &str,
    array: &'a PyReadonlyArray2<'_, T>,
    expected: [usize; 2],
) -> PyResult<&'a [T]> {
    use numpy::PyUntypedArrayMethods;
    if array.shape() != expected {
        return Err(shape_error(what, &expected, array.shape()));
    }
    array
        .as_slice()
        .map_err(|_| PyValueError::new_err(format!("{what} must be a C-contiguous array")))
}

pub(crate) fn slice_of1<'a, T: numpy::Element>(
    what: &str,
    array: &'a PyReadonlyArray1<'_, T>,
    n: usize,
) -> PyResult<&'a [T]> {
    use numpy::PyUntypedArrayMethods;
    if array.shape() != [n] {
        return Err(shape_error(what, &[n], array.shape()));
    }
    array
        .as_slice()
        .map_err(|_| PyValueError::new_err(format!("{what} must be a C-contiguous array")))
}

pub(crate) fn mut_of<'a, T: numpy::Element>(
    what: &str,
    array: &'a mut PyReadwriteArray2<'_, T>,
    expected: [usize; 2],
) -> PyResult<&'a mut [T]> {
    use numpy::PyUntypedArrayMethods;
    if array.shape() != expected {
        return Err(shape_error(what, &expected, array.shape()));
    }
    array
        .as_slice_mut()
        .map_err(|_| PyValueError::new_err(format!("{what} must be a C-contiguous array")))
}

pub(crate) fn mut_of1<'a, T: numpy::Element>(
    what: &str,
    array: &'a mut PyReadwriteArray1<'_, T>,
    n: usize,
) -> PyResult<&'a mut [T]> {
    use numpy::PyUntypedArrayMethods;
    if array.shape() != [n] {
        return Err(shape_error(what, &[n], array.shape()));
    }
    array
        .as_slice_mut()
        .map_err(|_| PyValueError::new_err(format!("{what} must be a C-contiguous array")))
}

/// The info dict of one env as the SITL backend delivers it: every value rounded through
/// float32 as the task frame carries it (reals as float, integers as int, flags as bool,
/// vectors as float64 arrays).
fn info_dict<'py>(py: Python<'py>, env: &TaskInstance) -> PyResult<Bound<'py, PyDict>> {
    let dict = PyDict::new(py);
    for (name, value) in env.info() {
        match value {
            InfoValue::Real(x) => dict.set_item(name, f64::from(x as f32))?,
            InfoValue::Integer(i) => dict.set_item(name, (i as f32) as i64)?,
            InfoValue::Flag(b) => dict.set_item(name, b)?,
            InfoValue::Vector(v) => {
                let v: Vec<f64> = v.iter().map(|x| f64::from(*x as f32)).collect();
                dict.set_item(name, PyArray1::from_vec(py, v))?
            }
        }
    }
    Ok(dict)
}

impl Batch {
    fn open(&self) -> PyResult<()> {
        if self.closed {
            return Err(PyRuntimeError::new_err(
                "this env is closed; make a new one to go on",
            ));
        }
        Ok(())
    }

    fn env0(&mut self) -> PyResult<&mut TaskInstance> {
        self.open()?;
        self.envs
            .first_mut()
            .ok_or_else(|| PyRuntimeError::new_err("the batch holds no env"))
    }
}

#[pymethods]
impl Batch {
    /// `num_envs` instances of `task` ("hover", "waypoints", "landing") built from `params`
    /// ({core name: number}, checked by the core), stepped over `num_threads` threads.
    #[new]
    #[pyo3(signature = (task, params=None, num_envs=1, num_threads=1))]
    fn new(
        task: &str,
        params: Option<&Bound<'_, PyDict>>,
        num_envs: usize,
        num_threads: usize,
    ) -> PyResult<Self> {
        if num_envs == 0 {
            return Err(PyValueError::new_err("num_envs must be at least 1, got 0"));
        }
        if num_threads == 0 {
            return Err(PyValueError::new_err(
                "num_threads must be at least 1, got 0",
            ));
        }
        let kind = task_kind(task)?;
        let config = task_config(kind, params)?;
        let mut envs = Vec::with_capacity(num_envs);
        for _ in 0..num_envs {
            envs.push(
                TaskInstance::build(kind, &config)
                    .map_err(|e| PyValueError::new_err(e.to_string()))?,
            );
        }
        let (lo, hi) = envs[0].action_bounds();
        let n_obs = envs[0].observation_size();
        let mut info = Vec::new();
        push_infos(&envs[0], &mut info);
        let threads = num_threads.min(num_envs);
        let pool = if threads > 1 {
            Some(
                rayon::ThreadPoolBuilder::new()
                    .num_threads(threads)
                    .thread_name(|i| format!("flyloop-env-{i}"))
                    .build()
                    .map_err(|e| PyRuntimeError::new_err(format!("cannot start threads: {e}")))?,
            )
        } else {
            None
        };
        Ok(Batch {
            envs,
            lo,
            hi,
            n_obs,
            n_info: info.len(),
            num_threads: threads,
            pool,
            closed: false,
        })
    }

    #[getter]
    fn num_envs(&self) -> usize {
        self.envs.len()
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
        self.lo.len()
    }

    #[getter]
    fn info_size(&self) -> usize {
        self.n_info
    }

    #[getter]
    fn closed(&self) -> bool {
        self.closed
    }

    /// Frees the instances; every later call raises RuntimeError.
    fn close(&mut self) {
        self.closed = true;
        self.envs = Vec::new();
        self.pool = None;
    }

    /// Steps every env with its row of `actions` (float32, (N, action_size); non-finite
    /// values refuse the whole step with ValueError and change nothing; others are clamped
    /// into the action bounds) — except where `reset` is set: those envs start a new episode
    /// with their entry of `seeds`, their action is ignored and their reward and flags are 0.
    /// Writes observations (N, n_obs) float32, info values (N, info_size) float32 (the task
    /// frame's layout), rewards (N,) float64 and the flags (N,) bool.
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
    ) -> PyResult<()> {
        self.open()?;
        let n = self.envs.len();
        let n_act = self.lo.len();
        let actions = slice_of("actions", &actions, [n, n_act])?;
        let reset = slice_of1("reset", &reset, n)?;
        let seeds = slice_of1("seeds", &seeds, n)?;
        let obs = mut_of("obs", &mut obs, [n, self.n_obs])?;
        let info = mut_of("info", &mut info, [n, self.n_info])?;
        let rewards = mut_of1("rewards", &mut rewards, n)?;
        let terminated = mut_of1("terminated", &mut terminated, n)?;
        let truncated = mut_of1("truncated", &mut truncated, n)?;
        // Refuse before anything moves: a bad row must not leave the others stepped.
        refuse_non_finite(actions, reset, n_act)?;
        let sizes = Sizes {
            n_act,
            n_obs: self.n_obs,
            n_info: self.n_info,
            lo: &self.lo,
            hi: &self.hi,
        };
        let rows = Rows {
            envs: &mut self.envs,
            actions,
            reset,
            seeds,
            obs,
            info,
            rewards,
            terminated,
            truncated,
        };
        let pool = self.pool.as_ref();
        let threads = self.num_threads;
        py.detach(move || run_all(rows, sizes, pool, threads))
            .map_err(|e| PyRuntimeError::new_err(format!("step failed: {e}")))
    }

    /// Starts a new episode, with its entry of `seeds`, in every env where `reset` is set and
    /// leaves the others untouched; writes the new episodes' observations and info values
    /// into their rows of `obs` and `info`. `step` resets only alongside a step of the rest;
    /// this is the reset of an autoreset in the same step (stable-baselines3's VecEnv). In
    /// the calling thread: only the few envs whose episode just ended are reset.
    fn reset_rows(
        &mut self,
        reset: PyReadonlyArray1<'_, bool>,
        seeds: PyReadonlyArray1<'_, u64>,
        mut obs: PyReadwriteArray2<'_, f32>,
        mut info: PyReadwriteArray2<'_, f32>,
    ) -> PyResult<()> {
        self.open()?;
        let n = self.envs.len();
        let reset = slice_of1("reset", &reset, n)?;
        let seeds = slice_of1("seeds", &seeds, n)?;
        let obs = mut_of("obs", &mut obs, [n, self.n_obs])?;
        let info = mut_of("info", &mut info, [n, self.n_info])?;
        let (n_obs, n_info) = (self.n_obs, self.n_info);
        let mut values = Vec::with_capacity(n_info);
        for (i, env) in self.envs.iter_mut().enumerate() {
            if !reset[i] {
                continue;
            }
            env.reset(seeds[i]);
            env.write_observation(&mut obs[i * n_obs..(i + 1) * n_obs]);
            values.clear();
            push_infos(env, &mut values);
            info[i * n_info..(i + 1) * n_info].copy_from_slice(&values);
        }
        Ok(())
    }

    /// Single env: starts a new episode of env 0 with `seed`; returns (observation, info).
    fn reset_one<'py>(
        &mut self,
        py: Python<'py>,
        seed: u64,
    ) -> PyResult<(Bound<'py, PyArray1<f32>>, Bound<'py, PyDict>)> {
        let env = self.env0()?;
        env.reset(seed);
        let obs = PyArray1::from_vec(py, env.observation());
        Ok((obs, info_dict(py, env)?))
    }

    /// Single env: one step of env 0 with `action` (float32, (action_size,)); returns
    /// (observation, reward, terminated, truncated, info) as the SITL backend's step does.
    #[allow(clippy::type_complexity)]
    fn step_one<'py>(
        &mut self,
        py: Python<'py>,
        action: PyReadonlyArray1<'_, f32>,
    ) -> PyResult<(
        Bound<'py, PyArray1<f32>>,
        f64,
        bool,
        bool,
        Bound<'py, PyDict>,
    )> {
        let n_act = self.lo.len();
        let action = slice_of1("action", &action, n_act)?;
        let mut command = Vec::with_capacity(n_act);
        clamp_controls(action, &self.lo, &self.hi, &mut command)
            .map_err(|e| PyValueError::new_err(format!("action must be finite: {e}")))?;
        let env = self.env0()?;
        let outcome = env
            .step(&command)
            .map_err(|e| PyRuntimeError::new_err(format!("step failed: {e}")))?;
        let obs = PyArray1::from_vec(py, env.observation());
        Ok((
            obs,
            outcome.reward,
            outcome.terminated,
            outcome.truncated,
            info_dict(py, env)?,
        ))
    }
}
