//! A world: N multirotors (any frames, mixed) in one air, on one ground, on one physics
//! grid — the shape of PyFlyt's Aviary (a list of drones and one wind field).
//!
//! At every point of the world's grid ([`WorldParams::grid`]) the world
//! - evaluates its wind field ([`wind_field`]: a mean wind and a turbulence field, sampled
//!   every `turbulence_dt` at each vehicle's position) into each vehicle's external wind;
//! - finds the pairs near enough to interact ([`broad_phase`]: sorted columns, O(N log N)) and
//!   sums their contact and downwash forces ([`interaction`]) into each vehicle's external
//!   force; a contact that starts is reported as a [`Collision`];
//!
//! and holds those until the next grid point while every vehicle integrates its own
//! dynamics (ground contact included) over the interval. A step that is not a multiple of
//! the grid ends in a partial interval, and the next step completes it first, as a lone
//! vehicle does.
//!
//! Vehicles are known by name and kept in name order: the world's bits do not depend on the
//! order in which they are listed or given their commands. A world with one vehicle and no
//! wind is that vehicle alone, bit for bit.

pub mod broad_phase;
pub mod interaction;
pub mod params;
mod trig;
pub mod wind_field;

pub use interaction::Shape;
pub use params::WorldParams;
pub use wind_field::WindField;

use crate::error::{CommandError, ParamError};
use crate::params::Parameters;
use crate::rng::SimRng;
use crate::snapshot::{self, SnapshotError};
use crate::vehicle::{AirVehicle, Kinematics};
use interaction::{contact_force, downwash_force, reach};
use nalgebra::Vector3;
use serde::{Deserialize, Serialize};

/// Most vehicles one world holds.
pub const MAX_VEHICLES: usize = 65_536;

/// Two hulls that started to touch.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Collision {
    /// World time of the grid point at which the contact started, s.
    pub time: f64,
    /// Index of the first vehicle (name order; the smaller index).
    pub a: usize,
    /// Index of the second vehicle.
    pub b: usize,
    /// Speed at which the two closed, m/s.
    pub speed: f64,
}

/// Why a world cannot be built or driven.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum WorldError {
    #[error(transparent)]
    Param(#[from] ParamError),
    #[error("two vehicles are named `{0}`: names must be unique")]
    DuplicateName(String),
    #[error("a world holds 1 to {MAX_VEHICLES} vehicles, {0} given")]
    VehicleCount(usize),
    #[error(
        "vehicles `{a}` and `{b}` start inside each other: their centres are {distance:.3} m apart, their hulls need at least {needed:.3} m"
    )]
    Overlap {
        a: String,
        b: String,
        distance: f64,
        needed: f64,
    },
    #[error("no vehicle named `{0}` in this world")]
    UnknownVehicle(String),
    #[error("vehicle `{vehicle}`: {source}")]
    Command {
        vehicle: String,
        source: CommandError,
    },
}

/// N vehicles sharing air, ground and one physics grid (module docs).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct World {
    params: WorldParams,
    names: Vec<String>,
    vehicles: Vec<Box<dyn AirVehicle>>,
    shapes: Vec<Shape>,
    wind: WindField,
    /// The interaction force on each vehicle held since the last grid point, world ENU, N.
    forces: Vec<Vector3<f64>>,
    /// Pairs (i < j) whose hulls touched at the last grid point, sorted.
    touching: Vec<(usize, usize)>,
    /// Contacts that started since [`World::take_collisions`] was last called.
    collisions: Vec<Collision>,
    /// Grid points passed since the start.
    grid_points: u64,
    /// Time since the last grid point, s, in [0, grid).
    grid_phase: f64,
    rng: SimRng,
    #[serde(skip)]
    reach: f64,
    #[serde(skip)]
    columns: broad_phase::Columns,
}

impl World {
    /// A world of `vehicles` (name, vehicle: any [`AirVehicle`], boxed or not) with its wind
    /// drawn from `SimRng::new(seed)`. The wind belongs to the world: each vehicle's own wind
    /// is turned off ([`AirVehicle::join_world`]).
    pub fn new<V: Into<Box<dyn AirVehicle>>>(
        params: WorldParams,
        seed: u64,
        vehicles: impl IntoIterator<Item = (String, V)>,
    ) -> Result<Self, WorldError> {
        params.validate()?;
        let mut listed: Vec<(String, Box<dyn AirVehicle>)> =
            (vehicles.into_iter()).map(|(n, v)| (n, v.into())).collect();
        if listed.is_empty() || listed.len() > MAX_VEHICLES {
            return Err(WorldError::VehicleCount(listed.len()));
        }
        listed.sort_by(|a, b| a.0.cmp(&b.0));
        if let Some(w) = listed.windows(2).find(|w| w[0].0 == w[1].0) {
            return Err(WorldError::DuplicateName(w[0].0.clone()));
        }
        let (names, mut vehicles): (Vec<String>, Vec<Box<dyn AirVehicle>>) =
            listed.into_iter().unzip();
        for v in &mut vehicles {
            v.join_world();
        }
        let shapes = vehicles
            .iter()
            .map(|v| shape(&params, v.as_ref()))
            .collect();
        let mut rng = SimRng::new(seed);
        let wind = WindField::new(&params, &mut rng);
        let n = vehicles.len();
        let mut world = World {
            params,
            names,
            vehicles,
            shapes,
            wind,
            forces: vec![Vector3::zeros(); n],
            touching: Vec::new(),
            collisions: Vec::new(),
            grid_points: 0,
            grid_phase: 0.0,
            rng,
            reach: 0.0,
            columns: broad_phase::Columns::default(),
        };
        world.reach = world.interaction_reach();
        world.check_apart()?;
        Ok(world)
    }

    fn interaction_reach(&self) -> f64 {
        let largest = (self.shapes.iter()).fold(
            Shape {
                hull_radius: 0.0,
                propeller_radius: 0.0,
            },
            |m, s| Shape {
                hull_radius: m.hull_radius.max(s.hull_radius),
                propeller_radius: m.propeller_radius.max(s.propeller_radius),
            },
        );
        reach(&self.params, &largest)
    }

    /// Refuses a world whose vehicles start inside each other.
    fn check_apart(&self) -> Result<(), WorldError> {
        let xy = self.horizontal_positions();
        for (i, j) in broad_phase::candidate_pairs(&xy, self.reach) {
            let (i, j) = (i as usize, j as usize);
            let distance =
                (self.vehicles[i].body().position - self.vehicles[j].body().position).norm();
            let needed = self.shapes[i].hull_radius + self.shapes[j].hull_radius;
            if distance < needed {
                return Err(WorldError::Overlap {
                    a: self.names[i].clone(),
                    b: self.names[j].clone(),
                    distance,
                    needed,
                });
            }
        }
        Ok(())
    }

    fn horizontal_positions(&self) -> Vec<[f64; 2]> {
        (self.vehicles.iter())
            .map(|v| [v.body().position.x, v.body().position.y])
            .collect()
    }

    /// The world's parameters.
    pub fn params(&self) -> &WorldParams {
        &self.params
    }

    /// Number of vehicles.
    pub fn len(&self) -> usize {
        self.vehicles.len()
    }

    /// Always false: a world holds at least one vehicle.
    pub fn is_empty(&self) -> bool {
        self.vehicles.is_empty()
    }

    /// The vehicles' names, in the world's (name) order: index i is vehicle i.
    pub fn names(&self) -> &[String] {
        &self.names
    }

    /// The index of the vehicle named `name`.
    pub fn index(&self, name: &str) -> Result<usize, WorldError> {
        (self.names.binary_search_by(|n| n.as_str().cmp(name)))
            .map_err(|_| WorldError::UnknownVehicle(name.to_string()))
    }

    /// Vehicle `i` (panics past the end, like a slice: indices come from this world).
    pub fn vehicle(&self, i: usize) -> &dyn AirVehicle {
        self.vehicles[i].as_ref()
    }

    /// Vehicle `i`, to change its parameters or state between steps.
    pub fn vehicle_mut(&mut self, i: usize) -> &mut dyn AirVehicle {
        self.vehicles[i].as_mut()
    }

    /// Puts `vehicle` in place of vehicle `i` (a fleet's vehicle back at its start); it
    /// hands its air to the world ([`AirVehicle::join_world`]) and feels the held
    /// interaction force from the next grid point on, as the one it replaces did.
    pub fn replace_vehicle(&mut self, i: usize, mut vehicle: Box<dyn AirVehicle>) {
        vehicle.join_world();
        self.vehicles[i] = vehicle;
    }

    /// Every vehicle, in name order.
    pub fn vehicles(&self) -> &[Box<dyn AirVehicle>] {
        &self.vehicles
    }

    /// Vehicle `i`'s size as the world sees it.
    pub fn shape(&self, i: usize) -> Shape {
        self.shapes[i]
    }

    /// The wind field.
    pub fn wind(&self) -> &WindField {
        &self.wind
    }

    /// Sets vehicle `i`'s actuator commands (one per rotor, each finite, clamped to [0, 1]).
    pub fn set_command(&mut self, i: usize, command: &[f64]) -> Result<(), WorldError> {
        let vehicle = self.vehicles.get_mut(i).ok_or_else(|| {
            WorldError::UnknownVehicle(format!("#{i} (the world has {})", self.names.len()))
        })?;
        (vehicle.set_actuators(command)).map_err(|source| WorldError::Command {
            vehicle: self.names[i].clone(),
            source,
        })
    }

    /// Vehicle `i`'s kinematics (its acceleration includes the forces from the others).
    pub fn kinematics(&self, i: usize) -> Kinematics {
        self.vehicles[i].kinematics()
    }

    /// World time, s.
    pub fn time(&self) -> f64 {
        self.grid_points as f64 * self.params.grid + self.grid_phase
    }

    /// The interaction force held on vehicle `i`, world ENU, N.
    pub fn interaction_force(&self, i: usize) -> Vector3<f64> {
        self.forces[i]
    }

    /// Pairs (i < j) in contact at the last grid point, sorted.
    pub fn touching(&self) -> &[(usize, usize)] {
        &self.touching
    }

    /// The contacts that started since the last call, in time order.
    pub fn take_collisions(&mut self) -> Vec<Collision> {
        std::mem::take(&mut self.collisions)
    }

    /// Advances the world by `dt` seconds (module docs). A `dt` that is not a positive
    /// number does nothing.
    pub fn step(&mut self, dt: f64) {
        let grid = self.params.grid;
        let slack = 1e-9 * grid;
        let mut remaining = dt;
        while remaining > slack {
            if self.grid_phase == 0.0 {
                self.at_grid_point();
            }
            let to_grid = grid - self.grid_phase;
            let at_grid = to_grid <= remaining + slack;
            let piece = if at_grid { to_grid } else { remaining };
            for v in &mut self.vehicles {
                v.advance(piece);
            }
            if at_grid {
                self.grid_phase = 0.0;
                self.grid_points += 1;
            } else {
                self.grid_phase += piece;
            }
            remaining -= piece;
        }
    }

    /// The wind at each vehicle and the forces between them, for the interval that starts.
    fn at_grid_point(&mut self) {
        let per_sample = self.params.steps_per_sample();
        if self.grid_points % per_sample == 0 {
            if self.grid_points > 0 {
                self.wind.sample(&self.params, &mut self.rng);
            }
            for v in &mut self.vehicles {
                let wind = self.wind.at(&v.body().position);
                v.set_external_wind(wind);
            }
        }
        self.interact();
        for (v, f) in self.vehicles.iter_mut().zip(&self.forces) {
            v.set_external_force(*f);
        }
    }

    fn interact(&mut self) {
        let p = &self.params;
        let n = self.vehicles.len();
        self.forces.iter_mut().for_each(|f| *f = Vector3::zeros());
        if n < 2 || !(p.collisions_enabled || p.downwash_enabled) {
            self.touching.clear();
            return;
        }
        let time = self.time();
        let bodies: Vec<Body> = (self.vehicles.iter())
            .map(|v| {
                let (b, p) = (v.body(), v.params());
                Body {
                    position: b.position,
                    velocity: b.velocity,
                    thrust_ratio: v.thrust() / (p.mass * p.gravity),
                }
            })
            .collect();
        let mut touching = Vec::new();
        let xy = self.horizontal_positions();
        for (i, j) in self.columns.candidate_pairs(&xy, self.reach) {
            let (i, j) = (i.min(j) as usize, i.max(j) as usize);
            let (a, b) = (&bodies[i], &bodies[j]);
            let (sa, sb) = (&self.shapes[i], &self.shapes[j]);
            let offset = a.position - b.position;
            let hulls = sa.hull_radius + sb.hull_radius;
            if p.collisions_enabled && offset.norm_squared() < hulls * hulls {
                let on_a = contact_force(
                    p,
                    (&a.position, &a.velocity, sa),
                    (&b.position, &b.velocity, sb),
                );
                if let Some(f) = on_a {
                    self.forces[i] += f;
                    self.forces[j] -= f;
                    touching.push((i, j));
                    if self.touching.binary_search(&(i, j)).is_err() {
                        let normal = offset.try_normalize(1e-12).unwrap_or(Vector3::z());
                        self.collisions.push(Collision {
                            time,
                            a: i,
                            b: j,
                            speed: -(a.velocity - b.velocity).dot(&normal),
                        });
                    }
                }
            }
            if p.downwash_enabled && offset.z != 0.0 {
                let (upper, lower) = if offset.z > 0.0 { (i, j) } else { (j, i) };
                let off_axis = offset.xy().norm();
                let radius = self.shapes[upper].propeller_radius;
                let ratio = bodies[upper].thrust_ratio;
                self.forces[lower].z -= downwash_force(p, offset.z.abs(), off_axis, radius, ratio);
            }
        }
        touching.sort_unstable();
        self.touching = touching;
    }

    /// The whole world as bytes (parameters, vehicles, wind field, held forces, contacts,
    /// RNG); a restored world continues bit for bit, mid-interval too.
    pub fn save(&self) -> Result<Vec<u8>, SnapshotError> {
        snapshot::encode(SNAPSHOT_TAG, self)
    }

    /// A world from [`World::save`] bytes; foreign, damaged or invalid bytes are an error.
    pub fn restore(bytes: &[u8]) -> Result<Self, SnapshotError> {
        let mut world: World = snapshot::decode(SNAPSHOT_TAG, "World", bytes)?;
        let invalid = |e: String| SnapshotError::Invalid(e);
        world
            .params
            .validate()
            .map_err(|e| invalid(e.to_string()))?;
        let n = world.vehicles.len();
        if [world.names.len(), world.shapes.len(), world.forces.len()] != [n; 3]
            || !world.wind.is_finite()
            || !(0.0..world.params.grid).contains(&world.grid_phase)
        {
            return Err(invalid(
                "world arrays of unequal length, a non-finite wind, or a time off its grid".into(),
            ));
        }
        // Each vehicle went through its own checks (finite state, valid parameters, frame)
        // as it was decoded ([`crate::vehicle::air::restore`]).
        for (v, f) in world.vehicles.iter_mut().zip(&world.forces) {
            v.set_external_force(*f);
        }
        world.reach = world.interaction_reach();
        Ok(world)
    }
}

/// A vehicle's hull and propeller radius: the farthest rotor plus a propeller.
pub fn shape(params: &WorldParams, vehicle: &dyn AirVehicle) -> Shape {
    let arm = vehicle.params().arm_length;
    let farthest = (vehicle.frame().rotors().iter())
        .map(|r| (r.x * r.x + r.y * r.y).sqrt())
        .fold(0.0, f64::max);
    let propeller_radius = params.propeller_radius_ratio * arm;
    Shape {
        hull_radius: farthest * arm + propeller_radius,
        propeller_radius,
    }
}

/// What the interactions read of a vehicle at a grid point.
struct Body {
    position: Vector3<f64>,
    velocity: Vector3<f64>,
    /// Rotor thrust / weight: 1 in a hover.
    thrust_ratio: f64,
}

/// Format tag of a World snapshot.
const SNAPSHOT_TAG: &[u8; 8] = b"FLYWLD01";
