//! What the FMI layer needs from a model, and nothing about physics: [`FmuModel`] over the
//! core's variable table, and an FMU's [`Table`]: the model's shape (a multirotor's frame),
//! the FMI table made for it plus, at the same positions, the core rows that read and write
//! each variable. One model type serves as many FMUs as it has tables.

use crate::error::FmuError;
use crate::table::{ModelExchangeTable, ModelInfo, ModelTable};
use flyloop_core::ParamError;
use flyloop_core::SnapshotError;
use flyloop_core::variables::{Row, Rows, Variable, VariableTable};
use std::fmt;

/// How the FMU reaches a variable in the model.
#[derive(Debug)]
pub enum Access<M: FmuModel> {
    Core(Row<M>),
    /// A read-only value the core's table does not hold (Model Exchange's extra states and
    /// derivatives): `read(model, at)`.
    Local {
        read: fn(&M, usize) -> f64,
        at: usize,
    },
}

/// An FMU's table: the shape its instances have, the FMI table, the core's rows for that
/// shape and the access to each variable, at the FMI table's positions.
#[derive(Debug)]
pub struct Table<M: FmuModel> {
    pub shape: M::Shape,
    pub table: ModelTable,
    pub rows: Rows<M>,
    pub access: Vec<Access<M>>,
}

impl<M: FmuModel> Table<M> {
    /// The core's variables of `M` for `shape` (`rows`), then `locals`.
    pub fn new(
        info: ModelInfo,
        shape: M::Shape,
        rows: Rows<M>,
        locals: Vec<(Variable, Access<M>)>,
        model_exchange: Option<ModelExchangeTable>,
    ) -> Self {
        let core = rows.variables().into_iter().filter_map(|v| {
            let row = rows.row(v.value_reference).ok()?;
            Some((v, Access::Core(row)))
        });
        let (variables, access): (Vec<Variable>, Vec<Access<M>>) = core.chain(locals).unzip();
        Table {
            shape,
            table: ModelTable::new(info, variables, model_exchange),
            rows,
            access,
        }
    }
}

/// A model behind the FMU, over its core variable table.
pub trait FmuModel:
    VariableTable<Initial: fmt::Debug, Params: fmt::Debug, Shape: fmt::Debug + PartialEq> + fmt::Debug
{
    /// A fresh model of `shape` from `initial`, with the physical parameters of `previous`
    /// (or the defaults when there is none).
    fn build(
        shape: &Self::Shape,
        previous: Option<&Self>,
        initial: &Self::Initial,
    ) -> Result<Self, ParamError>;

    /// How many internal steps [`advance`](Self::advance) would take (to refuse steps that
    /// would run for hours).
    fn internal_steps(&self, end: f64, h: f64) -> f64;

    /// One communication step of `h` seconds, ending `end` seconds after the start time t0:
    /// the FMU's grid time `t0 + n·h` (never a running sum) less t0, so a model with its own
    /// fixed step can count whole steps.
    fn advance(&mut self, end: f64, h: f64);

    /// Whether the state holds only finite numbers (false once the dynamics diverged).
    fn is_finite(&self) -> bool;

    /// The whole state as bytes (RNG and physics world included).
    fn save(&self) -> Result<Vec<u8>, SnapshotError>;

    /// Foreign or damaged bytes are an error.
    fn restore(bytes: &[u8]) -> Result<Self, SnapshotError>;

    /// The model as a hybrid system for Model Exchange; `None` for Co-Simulation only.
    fn hybrid(&self) -> Option<&dyn Hybrid> {
        None
    }

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
    /// The discrete changes of an event `elapsed` seconds after the previous one; whether
    /// they changed a continuous state (bit for bit).
    fn event_update(&mut self, elapsed: f64) -> bool;
}
