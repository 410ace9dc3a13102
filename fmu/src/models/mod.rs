//! The two models this one library serves, and the choice between them by GUID.

mod lander2d;
mod quadrotor;

use crate::error::FmuError;
use crate::model::{FmuModel, ModelTable};
use crate::simulation::{Engine, Simulation};
use flyloop_core::lander2d::Lander2d;
use flyloop_core::quadrotor::Quadrotor;

/// The tables of every model, Quadrotor first.
pub fn tables() -> [&'static ModelTable; 2] {
    [Quadrotor::table(), Lander2d::table()]
}

/// A fresh simulation of the model whose GUID is `guid`, or `None` for an unknown GUID.
pub fn simulation_for(guid: &str) -> Option<Result<Box<dyn Simulation>, FmuError>> {
    if guid == Quadrotor::table().guid {
        Some(Engine::<Quadrotor>::new().map(|e| Box::new(e) as Box<dyn Simulation>))
    } else if guid == Lander2d::table().guid {
        Some(Engine::<Lander2d>::new().map(|e| Box::new(e) as Box<dyn Simulation>))
    } else {
        None
    }
}
