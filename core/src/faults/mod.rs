//! Faults: a seeded fault library every front end shares.
//!
//! A fault acts in ONE actuator path — between the commands a controller sends and the motors
//! ([`actuator`], with the [`battery`]'s sag) — in the air the vehicle flies through
//! ([`air`]: gusts and wind shear), and in ONE sensor path after the sensor models
//! ([`sensor`], [`FaultState::gps`], the propeller imbalance the accelerometer sees). The
//! [`catalogue`] lists every kind with its parameters, units and bounds; a [`FaultSpec`] is
//! one fault with its [`trigger`]; [`draw`] draws faults per episode from ranges, seeded by
//! the episode's seed; a [`FaultPlan`] holds both, read from TOML (`[[faults]]`,
//! `[[fault_randomization]]`); a [`FaultState`] runs them over an episode and records when
//! each fired. [`px4`] maps PX4's MAV_CMD_INJECT_FAILURE codes onto the catalogue.
//!
//! No faults ⇒ none of this runs: the vehicle flies today's bits.

pub mod actuator;
pub mod air;
pub mod battery;
pub mod catalogue;
pub mod draw;
pub mod on_vehicle;
pub mod plan;
pub mod px4;
pub mod sensor;
pub mod spec;
pub mod state;
pub mod trigger;

pub use catalogue::{CATALOGUE, FaultKind, SensorId};
pub use on_vehicle::{Delivered, VehicleFaults};
pub use plan::FaultPlan;
pub use spec::FaultSpec;
pub use state::{FaultEvent, FaultState, LinkCondition};
pub use trigger::{Conditions, Reach, Trigger};
