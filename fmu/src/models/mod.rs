//! The FMUs this one library serves, and the choice between them by GUID: each is a
//! declaration (a name, and for the multirotor its frame) whose table is built on first use.

mod attitude_controller;
mod lander2d;
mod multirotor;
mod px4_rate_params;
mod quadrotor;
mod rate_controller;

pub use attitude_controller::AttitudeController;
pub use multirotor::Multirotor;
pub use rate_controller::RateController;

use crate::api::Api;
use crate::engine::{Engine, Simulation};
use crate::error::FmuError;
use crate::model::{FmuModel, Table};
use crate::table::ModelTable;
use flyloop_core::lander2d::Lander2d;
use flyloop_core::quadrotor::{Frame, Quadrotor};
use std::path::Path;
use std::sync::{LazyLock, OnceLock};

/// A shipped frame by name (the crate's tests build every declared FMU).
fn shipped(name: &str) -> Frame {
    Frame::named(name).unwrap_or_else(|e| unreachable!("{name} is shipped: {e}"))
}

/// Quadrotor.fmu: the quad X.
static QUADROTOR: LazyLock<Table<Quadrotor>> = LazyLock::new(|| {
    let frame = shipped("quad_x");
    Multirotor {
        identifier: "Quadrotor",
        noun: "quadrotor",
        frame,
    }
    .table()
});

/// Lander2D.fmu.
static LANDER2D: LazyLock<Table<Lander2d>> = LazyLock::new(lander2d::table);

/// Hexacopter.fmu: the same model with the hexa X's rotor table (PX4's 6001 motor order).
static HEXACOPTER: LazyLock<Table<Quadrotor>> = LazyLock::new(|| {
    let frame = shipped("hexa_x");
    Multirotor {
        identifier: "Hexacopter",
        noun: "hexacopter",
        frame,
    }
    .table()
});

/// RateController.fmu: the core's PX4 rate loop and allocation.
static RATE_CONTROLLER: LazyLock<Table<RateController>> = LazyLock::new(rate_controller::table);

/// AttitudeController.fmu: a PD attitude controller over RateController.fmu (examples/ssp).
static ATTITUDE_CONTROLLER: LazyLock<Table<AttitudeController>> =
    LazyLock::new(attitude_controller::table);

/// The tables of every FMU: Quadrotor, Lander2D, Hexacopter, RateController,
/// AttitudeController.
pub fn tables() -> [&'static ModelTable; 5] {
    [
        &QUADROTOR.table,
        &LANDER2D.table,
        &HEXACOPTER.table,
        &RATE_CONTROLLER.table,
        &ATTITUDE_CONTROLLER.table,
    ]
}

/// FMUs of another library built on this FMI layer, whose models are read from the FMU's
/// resources (Policy.fmu: `flyloop-fmu-policy`). That library's cdylib carries these exports
/// too and registers its catalog when it is loaded; the plant library registers none.
pub trait Catalog: Sync {
    /// A fresh simulation of the FMU in `resources` (the unpacked FMU's `resources/` folder)
    /// whose token is `token`; `None` when it is not one of this catalog's.
    fn simulation_for(
        &self,
        api: Api,
        token: &str,
        resources: Option<&Path>,
    ) -> Option<Result<Box<dyn Simulation>, FmuError>>;
}

static CATALOG: OnceLock<&'static dyn Catalog> = OnceLock::new();

/// Registers the library's extra catalog (once; a second one is refused with `false`).
pub fn register_catalog(catalog: &'static dyn Catalog) -> bool {
    CATALOG.set(catalog).is_ok()
}

/// The simulation for `token`: one of [`tables`], else one of the registered catalog's.
pub fn simulation_in(
    api: Api,
    token: &str,
    resources: Option<&Path>,
) -> Option<Result<Box<dyn Simulation>, FmuError>> {
    simulation_for(api, token).or_else(|| {
        CATALOG
            .get()
            .and_then(|c| c.simulation_for(api, token, resources))
    })
}

/// A fresh simulation of the FMU whose GUID (FMI 2.0) or instantiation token (FMI 3.0) is
/// `token`, or `None` for an unknown one.
pub fn simulation_for(api: Api, token: &str) -> Option<Result<Box<dyn Simulation>, FmuError>> {
    fn of<M: FmuModel>(
        table: &'static Table<M>,
        api: Api,
        token: &str,
    ) -> Option<Result<Box<dyn Simulation>, FmuError>> {
        (token == table.table.token(api)).then(|| Engine::start(table))
    }
    of(&QUADROTOR, api, token)
        .or_else(|| of(&LANDER2D, api, token))
        .or_else(|| of(&HEXACOPTER, api, token))
        .or_else(|| of(&RATE_CONTROLLER, api, token))
        .or_else(|| of(&ATTITUDE_CONTROLLER, api, token))
}
