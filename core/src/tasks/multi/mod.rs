//! Multi-agent flight tasks on one [`World`]: N quadrotors share the air (its wind, hull
//! contact, downwash), each flown by an agent through the single-agent flight interface
//! ([`FlightLink`]: motor commands, or thrust + body rates through PX4's rate loop; the same
//! per-agent domain randomisation) and rewarded as the single-agent Hover rewards.
//!
//! **Scenarios** ([`Scenario`]): `MultiHover` (each agent its own target; a collision ends the
//! episode for both agents in it) and `Swap` (the agents exchange places across a circle; a
//! collision or crash ends it for all; success = all arrived, no collision).
//!
//! **Observation** per agent: the single-agent observation of its own vehicle and target (33
//! values on the motor interface, 16 on the rates interface; [`crate::tasks::hover`]), then
//! its k nearest neighbours (7 values each, [`neighbours`]). Bounds are declared per value.
//!
//! **Reward** per agent and step: Hover's reward towards its own target
//! ([`hover_reward`]), minus `collision_penalty` on a step its hull starts touching another.
//! **Termination**: crashed, out of bounds (distance to the target beyond
//! [`Scenario::out_of_bounds`]), a collision — and for Swap any of these of any agent; an
//! agent that ended (terminated or truncated) is *done*: its motors are off, its actions are
//! ignored, its vehicle stays in the world (others can hit it). **Truncation**: `max_steps`.
//!
//! **Seeds**: `reset(seed)` draws the world's seed, the episode's turn (Swap) and one seed
//! per agent (its vehicle draw, start attitude, target, observation noise) from
//! `SimRng::new(seed)`; agents are world vehicles named by their zero-padded index, so the
//! world's name order is the agent order. Same seed ⇒ same episode, bit for bit.

pub mod config;
pub mod faults;
pub mod neighbours;
pub mod params;
pub mod scenario;

pub use config::MultiConfig;
pub use faults::AgentFaults;
pub use params::MultiParams;
pub use scenario::Scenario;

use crate::error::ParamError;
use crate::faults::FaultEvent;
use crate::quadrotor::{BodyState, QuadrotorParams, multirotor_at};
use crate::rng::SimRng;
use crate::tasks::flight::{
    FlightStatus, is_crashed, sample_start, sample_target, visit_flight_info, wind_bound,
};
use crate::tasks::flight_link::FlightLink;
use crate::tasks::hover::hover_reward;
use crate::tasks::{ActionError, InfoRef, InfoVisitor, StepOutcome, check_action};
use crate::vehicle::AirVehicle;
use crate::world::{Collision, World, WorldError, shape};
use nalgebra::Vector3;
use neighbours::NEIGHBOUR_VALUES;
use std::sync::OnceLock;

/// Values per agent action (thrust or motors, as the single-agent flight tasks).
pub const ACTION_SIZE: usize = 4;
/// Times closer than this are the same instant on the rate loops' grids, s.
const TIME_TOLERANCE: f64 = 1e-9;
/// Offset of the wind in the motor interface's observation (its 3 values).
const WIND_SLOT: usize = 22;

/// Why a multi-agent task cannot be built, reset or stepped.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum MultiError {
    #[error(transparent)]
    Param(#[from] ParamError),
    #[error(transparent)]
    World(#[from] WorldError),
    #[error("agent {agent}: {source}")]
    Action { agent: usize, source: ActionError },
    #[error("actions have {got} values, the task takes {expected} ({agents} agents × 4)")]
    ActionsLength {
        expected: usize,
        got: usize,
        agents: usize,
    },
}

/// One agent's episode bookkeeping.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
struct AgentStatus {
    flight: FlightStatus,
    /// Ended (terminated or truncated) on an earlier step.
    done: bool,
    /// Took part in this step (not done before it).
    active: bool,
    collided: bool,
    /// Largest closing speed of the collisions that started this step, m/s.
    collision_speed: f64,
    /// Collisions this episode.
    collisions: u32,
    arrived: bool,
    outcome: Option<StepOutcome>,
}

/// A multi-agent flight task (module docs).
#[derive(Debug, Clone)]
pub struct MultiFlight {
    scenario: Scenario,
    config: MultiConfig,
    links: Vec<FlightLink>,
    /// The nominal vehicle every agent's episode starts from.
    template: Box<dyn AirVehicle>,
    world: World,
    targets: Vec<Vector3<f64>>,
    status: Vec<AgentStatus>,
    steps: u32,
    /// Some agent collided or crashed this episode.
    failed: bool,
    out_of_bounds: f64,
    obs_low: Vec<f32>,
    obs_high: Vec<f32>,
    /// Per agent, its own fault slot for each of the task's (empty without faults).
    fault_slots: Vec<Vec<Option<usize>>>,
    /// Every agent's nearest neighbours now ([`neighbours::all_nearest`]), found once for all
    /// agents on the first observation after a change; emptied by every `&mut self` method.
    nearest: OnceLock<Vec<u32>>,
    /// The collisions that started in the last step (for the front ends' reports).
    collisions: Vec<Collision>,
}

impl MultiFlight {
    /// The task `scenario` on `config` (validated; starts that would overlap are refused),
    /// reset with seed 0.
    pub fn new(scenario: Scenario, config: MultiConfig) -> Result<Self, MultiError> {
        config.validate()?;
        let n = config.multi.num_agents as usize;
        let vehicle = config.vehicle();
        let (link, template) = FlightLink::new(vehicle.clone(), config.randomize.clone())?;
        // Each agent flies its own fault plan; without faults they share the one link.
        let links = if config.faults.is_empty() {
            vec![link.clone(); n]
        } else {
            (0..config.multi.num_agents)
                .map(|i| {
                    let v = config.agent_vehicle(i);
                    FlightLink::new(v, config.randomize.clone()).map(|(l, _)| l)
                })
                .collect::<Result<Vec<_>, _>>()?
        };
        let fault_slots = if config.faults.is_empty() {
            Vec::new()
        } else {
            (0..config.multi.num_agents)
                .map(|i| config.faults.slot_map(i))
                .collect()
        };
        check_separation(scenario, &config)?;
        let out_of_bounds = scenario.out_of_bounds(&config.multi, &config.flight);
        let (mut obs_low, mut obs_high) = link.observation_bounds(out_of_bounds);
        if !link.rates_interface() && config.world.wind_enabled {
            let w = &config.world;
            let wind = wind_bound(&QuadrotorParams {
                wind_enabled: true,
                wind_speed_max: w.wind_speed_max,
                turbulence_sigma: w.turbulence_sigma,
                turbulence_theta: w.turbulence_theta,
                ..QuadrotorParams::default()
            }) as f32;
            obs_low[WIND_SLOT..WIND_SLOT + 3].fill(-wind);
            obs_high[WIND_SLOT..WIND_SLOT + 3].fill(wind);
        }
        let k = config.multi.neighbours as usize;
        let (nlo, nhi) = neighbours::bounds(k, 2.0 * out_of_bounds);
        obs_low.extend(nlo);
        obs_high.extend(nhi);
        let world = World::new(config.world.clone(), 0, [(agent_name(0), template.clone())])?;
        let mut task = MultiFlight {
            scenario,
            links,
            fault_slots,
            template,
            world,
            targets: vec![Vector3::zeros(); n],
            status: vec![AgentStatus::default(); n],
            steps: 0,
            failed: false,
            out_of_bounds,
            obs_low,
            obs_high,
            config,
            nearest: OnceLock::new(),
            collisions: Vec::new(),
        };
        task.reset(0)?;
        Ok(task)
    }

    pub fn scenario(&self) -> Scenario {
        self.scenario
    }

    pub fn config(&self) -> &MultiConfig {
        &self.config
    }

    pub fn num_agents(&self) -> usize {
        self.links.len()
    }

    /// The world the agents fly in (vehicle i is agent i).
    pub fn world(&self) -> &World {
        &self.world
    }

    /// The world, to place or push vehicles by hand between steps (tests, front ends).
    pub fn world_mut(&mut self) -> &mut World {
        self.nearest.take();
        &mut self.world
    }

    /// Agent `i`'s target, world ENU, m.
    pub fn target(&self, i: usize) -> Vector3<f64> {
        self.targets[i]
    }

    /// Control period, s.
    pub fn dt(&self) -> f64 {
        self.config.flight.dt
    }

    /// Number of action values per agent.
    pub fn action_size(&self) -> usize {
        ACTION_SIZE
    }

    /// Inclusive per-value action bounds of one agent (outside values are clipped).
    pub fn action_bounds(&self) -> (Vec<f64>, Vec<f64>) {
        self.links[0].action_bounds()
    }

    /// Number of observation values per agent.
    pub fn observation_size(&self) -> usize {
        self.obs_low.len()
    }

    /// Inclusive per-value observation bounds of one agent.
    pub fn observation_bounds(&self) -> (Vec<f32>, Vec<f32>) {
        (self.obs_low.clone(), self.obs_high.clone())
    }

    /// One agent's observation groups: (name, number of values), in order.
    pub fn observation_layout(&self) -> Vec<(&'static str, usize)> {
        let mut layout = self.links[0].observation_layout();
        let k = self.config.multi.neighbours as usize;
        layout.push(("neighbours", NEIGHBOUR_VALUES * k));
        layout
    }

    /// Starts a new episode (module docs); the same seed gives the same episode, bit for bit.
    pub fn reset(&mut self, seed: u64) -> Result<(), MultiError> {
        self.nearest.take();
        let n = self.links.len();
        let mut master = SimRng::new(seed);
        let world_seed = master.fork_seed();
        let turn = master.uniform(0.0, std::f64::consts::TAU);
        let flight = &self.config.flight;
        let mut vehicles = Vec::with_capacity(n);
        for (i, link) in self.links.iter_mut().enumerate() {
            let agent_seed = master.fork_seed();
            let mut quad = self.template.clone();
            link.draw(quad.as_mut(), agent_seed);
            quad.params_mut().wind_enabled = false;
            let mut rng = SimRng::new(agent_seed);
            let hover = quad.hover_motor_state().unwrap_or(0.0);
            let mut body = sample_start(flight, hover, &mut rng);
            let local = body.position;
            let point = self.scenario.start_point(&self.config.multi, i, n, turn);
            body.position.x += point.x;
            body.position.y += point.y;
            body.position.z += self.scenario.layer_offset(&self.config.multi, i, n);
            self.targets[i] = match self.scenario {
                Scenario::MultiHover => {
                    let t = sample_target(flight, &local, &mut rng);
                    Vector3::new(t.x + point.x, t.y + point.y, t.z)
                }
                Scenario::Swap => Vector3::new(-body.position.x, -body.position.y, body.position.z),
            };
            link.restart(quad.as_mut(), body, rng, agent_seed);
            vehicles.push((agent_name(i), quad));
        }
        self.world = World::new(self.config.world.clone(), world_seed, vehicles)?;
        self.steps = 0;
        self.failed = false;
        self.collisions.clear();
        for (i, s) in self.status.iter_mut().enumerate() {
            let start = self.world.vehicle(i).body().position;
            *s = AgentStatus {
                flight: FlightStatus {
                    initial_distance: (self.targets[i] - start).norm(),
                    ..FlightStatus::default()
                },
                active: true,
                ..AgentStatus::default()
            };
        }
        Ok(())
    }

    /// Whether agent `i` has ended its episode (before or on the last step).
    pub fn is_done(&self, i: usize) -> bool {
        self.status[i].done
    }

    /// Whether every agent has ended its episode.
    pub fn all_done(&self) -> bool {
        self.status.iter().all(|s| s.done)
    }

    /// Whether agent `i` took part in the last step (it was not done before it).
    pub fn is_active(&self, i: usize) -> bool {
        self.status[i].active
    }

    /// Agent `i`'s result of the last step: zero reward and neither flag for an agent that
    /// was done before it (and after a reset).
    pub fn outcome(&self, i: usize) -> StepOutcome {
        self.status[i].outcome.unwrap_or(StepOutcome {
            reward: 0.0,
            terminated: false,
            truncated: false,
        })
    }

    /// Applies every agent's action (`actions[4i..4i+4]` is agent i's; a done agent's is
    /// ignored) for one control period. Nothing changes on an error.
    pub fn step(&mut self, actions: &[f64]) -> Result<(), MultiError> {
        let n = self.links.len();
        if actions.len() != n * ACTION_SIZE {
            return Err(MultiError::ActionsLength {
                expected: n * ACTION_SIZE,
                got: actions.len(),
                agents: n,
            });
        }
        for (i, action) in actions.chunks(ACTION_SIZE).enumerate() {
            if !self.status[i].done {
                check_action(action, ACTION_SIZE)
                    .map_err(|source| MultiError::Action { agent: i, source })?;
            }
        }
        self.advance(actions);
        self.judge();
        Ok(())
    }

    /// Flies every vehicle through one control period: the live agents' rate loops tick on
    /// their grids (the world stepped from tick to tick), the done agents' motors are off.
    fn advance(&mut self, actions: &[f64]) {
        self.nearest.take();
        let dt = self.config.flight.dt;
        for (i, action) in actions.chunks(ACTION_SIZE).enumerate() {
            self.status[i].active = !self.status[i].done;
            if self.status[i].done {
                let _ = self.world.set_command(i, &[0.0; ACTION_SIZE]);
            } else {
                let quad = self.world.vehicle_mut(i);
                // The world sets each vehicle's wind (a link's faults would set their own:
                // air faults are refused in multi-agent tasks).
                let wind = quad.external_wind();
                // Checked in `step`: finite and 4 values.
                let _ = self.links[i].begin(quad, action, dt);
                quad.set_external_wind(wind);
            }
        }
        let (mut now, end) = self.links[0].window(dt);
        loop {
            let next = (self.links.iter().zip(&self.status))
                .filter(|(_, s)| s.active)
                .filter_map(|(l, _)| l.next_tick(end))
                .fold(None, |m: Option<f64>, t| Some(m.map_or(t, |m| m.min(t))));
            let Some(tick) = next else { break };
            if tick > now {
                self.step_world(tick - now);
                now = tick;
            }
            for (i, link) in self.links.iter_mut().enumerate() {
                let due = link
                    .next_tick(end)
                    .is_some_and(|t| t <= now + TIME_TOLERANCE);
                if self.status[i].active && due {
                    link.tick(self.world.vehicle_mut(i));
                }
            }
        }
        if end > now {
            self.step_world(end - now);
        }
        self.steps += 1;
        for (i, link) in self.links.iter_mut().enumerate() {
            if self.status[i].active {
                link.finish(self.world.vehicle(i));
            }
        }
    }

    /// Steps the world by `dt`, the live agents' motors through their actuator fault paths
    /// (without faults: the world's step alone).
    fn step_world(&mut self, dt: f64) {
        if self.fault_slots.is_empty() {
            self.world.step(dt);
            return;
        }
        for (i, link) in self.links.iter_mut().enumerate() {
            if self.status[i].active {
                link.before_advance(self.world.vehicle_mut(i), dt);
            }
        }
        self.world.step(dt);
        for (i, link) in self.links.iter_mut().enumerate() {
            if self.status[i].active {
                link.after_advance(self.world.vehicle_mut(i));
            }
        }
    }

    /// Rewards, collisions and ends of the step just flown.
    fn judge(&mut self) {
        for s in &mut self.status {
            s.collided = false;
            s.collision_speed = 0.0;
            s.outcome = None;
        }
        self.collisions = self.world.take_collisions();
        for c in &self.collisions {
            for k in [c.a, c.b] {
                let s = &mut self.status[k];
                s.collided = true;
                s.collisions += 1;
                s.collision_speed = s.collision_speed.max(c.speed);
            }
        }
        let (flight, multi) = (&self.config.flight, &self.config.multi);
        let mut any_failed = false;
        for (i, s) in self.status.iter_mut().enumerate() {
            if !s.active {
                continue;
            }
            let quad = self.world.vehicle(i);
            let body = quad.body();
            let target = &self.targets[i];
            let distance = (target - body.position).norm();
            s.flight.step_count += 1;
            s.flight.crashed =
                flight.enable_crash_detection && is_crashed(flight, quad.params(), body);
            s.flight.out_of_bounds =
                flight.enable_out_of_bounds_detection && distance > self.out_of_bounds;
            s.arrived = distance <= multi.arrival_radius;
            let penalty = if s.collided {
                multi.collision_penalty
            } else {
                0.0
            };
            let terminated = s.flight.crashed || s.flight.out_of_bounds || s.collided;
            any_failed |= terminated;
            s.outcome = Some(StepOutcome {
                reward: hover_reward(flight, body, target) - penalty,
                terminated,
                truncated: self.steps >= flight.max_steps,
            });
        }
        self.failed |= any_failed;
        let end_all = any_failed && self.scenario.ends_together();
        for s in &mut self.status {
            if let Some(o) = &mut s.outcome {
                o.terminated |= end_all;
                s.done = o.terminated || o.truncated;
            }
        }
    }

    /// Writes agent `i`'s observation into `out` (length [`MultiFlight::observation_size`]).
    pub fn write_observation(&self, i: usize, out: &mut [f32]) {
        let link = &self.links[i];
        let base = link.observation_size();
        let (lo, hi) = (&self.obs_low, &self.obs_high);
        let quad = self.world.vehicle(i);
        link.write_observation(
            quad,
            &self.targets[i],
            &lo[..base],
            &hi[..base],
            &mut out[..base],
        );
        let k = self.config.multi.neighbours as usize;
        let vehicles = self.world.vehicles();
        let nearest = self
            .nearest
            .get_or_init(|| neighbours::all_nearest(vehicles, k));
        neighbours::write(
            link,
            vehicles,
            i,
            &nearest[i * k..(i + 1) * k],
            &lo[base..],
            &hi[base..],
            &mut out[base..],
        );
    }

    /// Writes every agent's observation, agent after agent, into `out`.
    pub fn write_observations(&self, out: &mut [f32]) {
        let size = self.observation_size();
        for (i, chunk) in out.chunks_mut(size).take(self.links.len()).enumerate() {
            self.write_observation(i, chunk);
        }
    }

    /// The collisions that started in the last step (agents by index), in the world's order.
    pub fn last_collisions(&self) -> &[Collision] {
        &self.collisions
    }

    /// Agent `i`'s fault events (firings, clearings) of this episode so far, in order; none
    /// for a healthy agent.
    pub fn fault_events(&self, i: usize) -> &[FaultEvent] {
        self.links[i].faults().map_or(&[], |f| f.state().events())
    }

    /// Whether every agent is within `arrival_radius` of its target now.
    pub fn all_arrived(&self) -> bool {
        self.status.iter().all(|s| s.arrived)
    }

    /// Calls `visit` with agent `i`'s info entries, in order: the single-agent flight info
    /// (distance_to_target, position, target_position, step_count, episode_time,
    /// distance_progress, crashed, out_of_bounds), then collided (this step), collision_speed
    /// (m/s, largest closing speed of this step's collisions), collisions (this episode),
    /// arrived, all_arrived, success (Swap: every agent arrived and no agent collided or
    /// crashed this episode; MultiHover: this agent arrived and never collided), and the
    /// randomised values when randomisation is on, and with faults the fault slots
    /// (`fault_kind`, `fault_target`, `fault_time`, `fault_active`: one value per table, see
    /// [`faults`]).
    pub fn visit_info(&self, i: usize, visit: &mut InfoVisitor<'_>) {
        let s = &self.status[i];
        let quad = self.world.vehicle(i);
        visit_flight_info(quad, &self.targets[i], &s.flight, self.dt(), visit);
        visit("collided", InfoRef::Flag(s.collided));
        visit("collision_speed", InfoRef::Real(s.collision_speed));
        visit("collisions", InfoRef::Integer(i64::from(s.collisions)));
        visit("arrived", InfoRef::Flag(s.arrived));
        let all_arrived = self.all_arrived();
        visit("all_arrived", InfoRef::Flag(all_arrived));
        let success = match self.scenario {
            Scenario::Swap => all_arrived && !self.failed,
            Scenario::MultiHover => s.arrived && s.collisions == 0,
        };
        visit("success", InfoRef::Flag(success));
        let Some(slots) = self.fault_slots.get(i) else {
            self.links[i].visit_info(visit);
            return;
        };
        // Every agent reports every table's slot (module `faults`).
        let mut own = Vec::new();
        self.links[i].visit_info(&mut |name, value| match value {
            InfoRef::Vector(v) if faults::is_slot_entry(name) => own.push((name, v.to_vec())),
            other => visit(name, other),
        });
        faults::visit_slots(slots, &own, &mut Vec::new(), visit);
    }
}

/// The world's name of agent `i`: its zero-padded index, so name order is agent order.
pub fn agent_name(i: usize) -> String {
    format!("{i:06}")
}

/// Refuses starts closer than two hulls (of the largest vehicle the randomisation can draw).
fn check_separation(scenario: Scenario, config: &MultiConfig) -> Result<(), ParamError> {
    let n = config.multi.num_agents as usize;
    let nominal = config.vehicle();
    let largest = [0.0, 1.0]
        .iter()
        .map(|&f| config.randomize.corner(&nominal, f).0.quadrotor)
        .filter_map(|p| {
            multirotor_at(
                p,
                nominal.frame.clone(),
                BodyState::at_rest(Vector3::zeros(), 0.0, 0.0, 0.0, 0.0),
                SimRng::new(0),
            )
            .ok()
        })
        .map(|q| shape(&config.world, q.as_ref()).hull_radius)
        .fold(0.0, f64::max);
    let lowest = config.flight.start_height + scenario.layer_offset(&config.multi, 0, n);
    if lowest <= largest {
        return Err(ParamError::Relation {
            name: "swap_layer",
            requirement: format!(
                "the lowest of {n} layers {} m apart starts at {lowest:.3} m, inside the ground for a {largest:.3} m hull: lower swap_layer or raise start_height",
                config.multi.swap_layer
            ),
        });
    }
    let separation = scenario.start_separation(&config.multi, n);
    if separation <= 2.0 * largest {
        let name = match scenario {
            Scenario::MultiHover => "hover_spacing",
            Scenario::Swap => "swap_radius",
        };
        return Err(ParamError::Relation {
            name,
            requirement: format!(
                "{n} agents start {separation:.3} m apart, their hulls need more than {:.3} m: raise {name} or use fewer agents",
                2.0 * largest
            ),
        });
    }
    Ok(())
}
