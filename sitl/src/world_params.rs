//! The parameter table of a multi-agent world (`--task multi_hover|swap`): the rows of every
//! set a [`MultiConfig`] is built from, in the order its parameter file looks names up (the
//! task's, the world's, the flight's, the quadrotor's, the rate loop's). A quadrotor name the
//! world also has (its wind's) is the world's and listed once. The vehicles of a world share
//! one configuration, so every vehicle's system id serves this same table.
//!
//! Ids follow the core's [`short_id`] rule, as the single-vehicle table's do.

use flyloop_core::ParamError;
use flyloop_core::params::{ParamSpec, Parameters, ValueKind};
use flyloop_core::quadrotor::QuadrotorParams;
use flyloop_core::rate_loop::RateLoopParams;
use flyloop_core::tasks::flight::FlightParams;
use flyloop_core::tasks::multi::{MultiConfig, MultiParams};
use flyloop_core::tasks::registry::param_rows::short_id;
use flyloop_core::world::WorldParams;

/// Which set of a [`MultiConfig`] a row belongs to.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum WorldSet {
    Multi,
    World,
    Flight,
    Quadrotor,
    RateLoop,
}

/// One parameter of the world's table.
#[derive(Debug, Clone, PartialEq)]
pub struct WorldParamRow {
    /// The MAVLink `param_id` (at most 16 characters).
    pub id: String,
    /// The core's name.
    pub name: &'static str,
    pub set: WorldSet,
    pub kind: ValueKind,
}

/// The parameter the world's vehicle count is; fixed by `--vehicles`.
const NUM_AGENTS: &str = "num_agents";

fn rows_of<P: Parameters>(set: WorldSet, out: &mut Vec<WorldParamRow>) {
    for s in P::specs() {
        let s: &ParamSpec<P> = s;
        if out.iter().any(|r| r.name == s.name) {
            continue;
        }
        out.push(WorldParamRow {
            id: short_id(s.name),
            name: s.name,
            set,
            kind: s.kind,
        });
    }
}

/// Every parameter of a world, in protocol index order.
pub fn rows() -> Vec<WorldParamRow> {
    let mut out = Vec::new();
    rows_of::<MultiParams>(WorldSet::Multi, &mut out);
    rows_of::<WorldParams>(WorldSet::World, &mut out);
    rows_of::<FlightParams>(WorldSet::Flight, &mut out);
    rows_of::<QuadrotorParams>(WorldSet::Quadrotor, &mut out);
    rows_of::<RateLoopParams>(WorldSet::RateLoop, &mut out);
    out
}

/// The value of `row` in `config`.
pub fn get(config: &MultiConfig, row: &WorldParamRow) -> Result<f64, ParamError> {
    match row.set {
        WorldSet::Multi => config.multi.get(row.name),
        WorldSet::World => config.world.get(row.name),
        WorldSet::Flight => config.flight.get(row.name),
        WorldSet::Quadrotor => config.quadrotor.get(row.name),
        WorldSet::RateLoop => config.rate_loop.get(row.name),
    }
}

/// Sets `row` to `value` in `config`, checked against its row, its set's relations and the
/// whole configuration (randomisation ranges, faults); on error `config` is unchanged. The
/// vehicle count is refused: it is `vehicles`, the world's system ids.
pub fn set(
    config: &mut MultiConfig,
    row: &WorldParamRow,
    value: f64,
    vehicles: usize,
) -> Result<(), ParamError> {
    if row.name == NUM_AGENTS && value != vehicles as f64 {
        return Err(ParamError::Relation {
            name: NUM_AGENTS,
            requirement: format!(
                "is the world's vehicle count, {vehicles}, fixed by --vehicles (one system id per vehicle)"
            ),
        });
    }
    let mut candidate = config.clone();
    match row.set {
        WorldSet::Multi => candidate.multi.set(row.name, value),
        WorldSet::World => candidate.world.set(row.name, value),
        WorldSet::Flight => candidate.flight.set(row.name, value),
        WorldSet::Quadrotor => candidate.quadrotor.set(row.name, value),
        WorldSet::RateLoop => candidate.rate_loop.set(row.name, value),
    }?;
    candidate.validate()?;
    *config = candidate;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use flyloop_core::tasks::registry::param_rows::PARAM_ID_LEN;

    #[test]
    fn ids_are_unique_short_and_every_row_reads() {
        let rows = rows();
        let config = MultiConfig::default();
        for (k, r) in rows.iter().enumerate() {
            assert!(r.id.len() <= PARAM_ID_LEN, "{}", r.id);
            assert!(rows[..k].iter().all(|o| o.id != r.id), "{}", r.id);
            assert!(get(&config, r).unwrap().is_finite(), "{}", r.name);
        }
        // The wind is the world's, listed once.
        let wind: Vec<_> = rows.iter().filter(|r| r.name == "wind_enabled").collect();
        assert_eq!(wind.len(), 1);
        assert_eq!(wind[0].set, WorldSet::World);
        assert!(rows.iter().any(|r| r.name == "swap_radius"));
        assert!(rows.iter().any(|r| r.name == "mass"));
    }

    #[test]
    fn a_set_is_checked_and_names_the_parameter() {
        let rows = rows();
        let row = |name: &str| rows.iter().find(|r| r.name == name).unwrap().clone();
        let mut config = MultiConfig::default();
        set(&mut config, &row("mass"), 1.2, 2).unwrap();
        assert_eq!(config.quadrotor.mass, 1.2);
        let before = config.clone();
        let e = set(&mut config, &row("mass"), -1.0, 2).unwrap_err();
        assert!(e.to_string().contains("`mass`"), "{e}");
        let e = set(&mut config, &row("num_agents"), 3.0, 2).unwrap_err();
        assert!(e.to_string().contains("num_agents"), "{e}");
        assert_eq!(config, before, "a refused set changes nothing");
        set(&mut config, &row("num_agents"), 2.0, 2).unwrap();
    }
}
