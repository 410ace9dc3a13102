//! The two models this one library serves, and the choice between them by GUID.

mod lander2d;
mod quadrotor;

use crate::api::Api;
use crate::engine::{Engine, Simulation};
use crate::error::FmuError;
use crate::model::FmuModel;
use crate::table::ModelTable;
use flyloop_core::lander2d::Lander2d;
use flyloop_core::quadrotor::Quadrotor;

/// The tables of every model, Quadrotor first.
pub fn tables() -> [&'static ModelTable; 2] {
    [&Quadrotor::table().table, &Lander2d::table().table]
}

/// A fresh simulation of the model whose GUID (FMI 2.0) or instantiation token (FMI 3.0) is
/// `token`, or `None` for an unknown one.
pub fn simulation_for(api: Api, token: &str) -> Option<Result<Box<dyn Simulation>, FmuError>> {
    if token == Quadrotor::table().table.token(api) {
        let built = <Quadrotor as FmuModel>::build(None, &Default::default());
        Some(built.map(Engine::boxed).map_err(FmuError::from))
    } else if token == Lander2d::table().table.token(api) {
        let built = <Lander2d as FmuModel>::build(None, &Default::default());
        Some(built.map(Engine::boxed).map_err(FmuError::from))
    } else {
        None
    }
}
