//! The task registry: which tasks exist ([`TaskKind`]), the parameter sets one is built from
//! ([`TaskConfig`], by name through [`param_rows`] and [`from_values`]), the built instance
//! ([`TaskInstance`]), and how every front end treats actions ([`clamp_controls`]) and
//! flattens info ([`push_infos`]). The SITL and the Python extension both come through here,
//! so an env and a SITL vehicle with the same parameters fly the same task.

mod config;
mod controls;
mod from_values;
mod info;
mod instance;
mod kind;
pub mod param_rows;

pub use config::TaskConfig;
pub use controls::{ControlError, clamp_controls};
pub use from_values::{from_values, from_values_and_ranges, from_values_ranges_and_faults};
pub use info::{push_info, push_infos};
pub use instance::TaskInstance;
pub use kind::{ModelKind, TaskKind};
