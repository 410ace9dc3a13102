//! Fleet mode: PX4s and ArduPilots flying the vehicles of one [`World`] in one process
//! (`flyloop-sitl --px4 --vehicles N`, `--ardupilot --vehicles N`, `--fleet FILE`;
//! docs/fleet.md).
//!
//! - [`file`]: the fleet (autopilots, ports, system ids, start positions, vehicles),
//! - [`lockstep`]: the barrier that lets autopilots of different step lengths share the
//!   world's clock,
//! - [`px4_member`], [`ardupilot_member`]: each autopilot's protocol, without sockets
//!   ([`frame_rate`]: the step an ArduPilot's frame rate asks for),
//! - [`server`]: the sockets, the wall clock, the timeouts,
//! - [`outputs`], [`track`]: what is written beside the flight (`--track`),
//! - [`view_record`]: the live view's stream and the recording (`--view`, `--record`).
//!
//! [`Fleet`] ties them together without sockets: bytes from autopilot i in, bytes for it
//! out, so the tests drive it directly.

pub mod ardupilot_member;
pub mod file;
pub mod frame_rate;
pub mod lockstep;
pub mod outputs;
pub mod px4_member;
pub mod server;
pub mod sockets;
pub mod track;
pub mod uring;
pub mod view_record;

use crate::control_link::ControlLink;
use ardupilot_member::{ArduPilotMember, Frame};
use file::{Autopilot, FleetSpec};
use flyloop_core::ParamError;
use flyloop_core::faults::{FaultEvent, FaultPlan, VehicleFaults};
use flyloop_core::quadrotor::standing_multirotor_at;
use flyloop_core::sensors::Sensors;
use flyloop_core::vehicle::AirVehicleStart;
use flyloop_core::world::{World, WorldError};
use lockstep::{Advance, Hold, Lockstep, Phase};
use mavlink::dialects::common::MavSeverity;
use px4_member::{Px4Member, Said};
use std::net::SocketAddr;
use view_record::{Sample, ViewRecord};

/// Why a fleet cannot start.
#[derive(Debug, thiserror::Error)]
pub enum FleetStartError {
    #[error("vehicle `{name}`: {source}")]
    Vehicle { name: String, source: ParamError },
    #[error("{0}")]
    World(#[from] WorldError),
}

/// One autopilot's protocol state.
#[derive(Debug, Clone)]
pub enum Link {
    Px4(Box<Px4Member>),
    ArduPilot(Box<ArduPilotMember>),
}

/// One vehicle of the fleet and its autopilot.
#[derive(Debug, Clone)]
pub struct Member {
    pub name: String,
    pub autopilot: Autopilot,
    pub sysid: u8,
    pub listen: SocketAddr,
    pub link: Link,
    /// Bytes waiting to go to the autopilot (PX4's stream; ArduPilot's reply is
    /// [`ArduPilotMember::reply`], flagged here by one byte).
    pub out: Vec<u8>,
    /// Rotor count of its vehicle.
    rotors: usize,
    /// Connections of its autopilot so far (a reconnect or restart counts again).
    pub connections: u32,
    /// Its faults (`[[faults]]` of its config or of the fleet file; none: healthy, stepped
    /// exactly as without), restarted with each connection.
    faults: Option<VehicleFaults>,
    /// Seed of its vehicle, sensors and fault draws.
    seed: u64,
    /// Mass of its vehicle, kg (for faults injected at run time).
    mass: f64,
    /// Every fault that fired or cleared, in order (the track's `faults` column).
    pub fault_log: Vec<FaultEvent>,
}

/// Something worth a log line and a STATUSTEXT.
#[derive(Debug, Clone, PartialEq)]
pub struct Notice {
    pub severity: MavSeverity,
    pub text: String,
}

/// The world, its autopilots and the barrier between them.
#[derive(Debug)]
pub struct Fleet {
    world: World,
    lockstep: Lockstep,
    members: Vec<Member>,
    /// Each vehicle as it started (standing at its start position).
    start: Vec<AirVehicleStart>,
    notices: Vec<Notice>,
    /// Contacts reported.
    pub collisions: u64,
    /// PX4 controls that answered older sensors (dropped; see `is_stale`).
    pub stale_controls: u64,
    /// UNIX time of world time 0 (HIL_GPS stamps), µs.
    pub gps_epoch_us: u64,
    /// The live view's stream and the recording, if asked for.
    pub view_record: ViewRecord,
    /// `--control`: MAV_CMD_INJECT_FAILURE addressed to each vehicle's sysid (0 = all).
    control: Option<ControlLink>,
    /// World time of the next look at the control link, µs.
    next_poll_us: u64,
}

/// World time between two looks at the control link, µs.
const CONTROL_POLL_US: u64 = 10_000;

/// PX4's simulator step, µs (`--px4-step`).
pub const PX4_STEP_US: u64 = 4000;
/// ArduPilot's step until its first frame says its rate (1200 Hz).
const ARDUPILOT_STEP_US: u64 = 833;

impl Fleet {
    /// The world of `spec`'s vehicles (kept in name order: member i is world vehicle i),
    /// each standing at its start position; vehicle i's and its sensors' seed: seed + i.
    pub fn new(spec: &FleetSpec, seed: u64, px4_step_us: u64) -> Result<Self, FleetStartError> {
        let mut listed = spec.vehicles.clone();
        listed.sort_by(|a, b| a.name.cmp(&b.name));
        let mut vehicles = Vec::with_capacity(listed.len());
        let mut members = Vec::with_capacity(listed.len());
        let mut steps = Vec::with_capacity(listed.len());
        let mut starts = Vec::with_capacity(listed.len());
        for (i, v) in listed.iter().enumerate() {
            let err = |source| FleetStartError::Vehicle {
                name: v.name.clone(),
                source,
            };
            let s = seed.wrapping_add(i as u64);
            let c = &v.vehicle;
            let start = standing_multirotor_at(c.quadrotor.clone(), c.frame.clone(), s, v.position)
                .map_err(err)?;
            let sensors = Sensors::new(c.sensors.clone(), s).map_err(err)?;
            let (link, step) = match v.autopilot {
                Autopilot::Px4 => (Link::Px4(Box::new(Px4Member::new(sensors))), px4_step_us),
                Autopilot::Ardupilot => (
                    Link::ArduPilot(Box::new(ArduPilotMember::new(sensors))),
                    ARDUPILOT_STEP_US,
                ),
            };
            steps.push(step);
            let rotors = c.frame.rotor_count();
            let faults = (!c.faults.is_empty())
                .then(|| VehicleFaults::new(c.faults.clone(), rotors, c.quadrotor.mass, s))
                .transpose()
                .map_err(err)?;
            members.push(Member {
                name: v.name.clone(),
                autopilot: v.autopilot,
                sysid: v.sysid,
                listen: v.listen,
                link,
                out: Vec::new(),
                rotors,
                connections: 0,
                faults,
                seed: s,
                mass: c.quadrotor.mass,
                fault_log: Vec::new(),
            });
            vehicles.push((v.name.clone(), start.take()));
            starts.push(start);
        }
        let world = World::new(spec.world.clone(), seed, vehicles)?;
        Ok(Fleet {
            world,
            lockstep: Lockstep::new(&steps),
            members,
            start: starts,
            notices: Vec::new(),
            collisions: 0,
            stale_controls: 0,
            gps_epoch_us: 0,
            view_record: ViewRecord::default(),
            control: None,
            next_poll_us: 0,
        })
    }

    pub fn world(&self) -> &World {
        &self.world
    }

    pub fn lockstep(&self) -> &Lockstep {
        &self.lockstep
    }

    pub fn members(&self) -> &[Member] {
        &self.members
    }

    pub fn member_mut(&mut self, i: usize) -> &mut Member {
        &mut self.members[i]
    }

    /// Vehicle i's truth (member i flies it).
    pub fn vehicle(&self, i: usize) -> &dyn flyloop_core::vehicle::Vehicle {
        self.world.vehicle(i)
    }

    /// The notices since the last call.
    pub fn take_notices(&mut self) -> Vec<Notice> {
        std::mem::take(&mut self.notices)
    }

    fn notice(&mut self, severity: MavSeverity, text: String) {
        match severity {
            MavSeverity::MAV_SEVERITY_INFO | MavSeverity::MAV_SEVERITY_NOTICE => {
                tracing::info!("{text}")
            }
            _ => tracing::warn!("{text}"),
        }
        (self.view_record).notice(self.lockstep.now_us(), severity, &text);
        self.notices.push(Notice { severity, text });
    }

    fn motors_off(&mut self, i: usize) {
        let zeros = vec![0.0; self.members[i].rotors];
        // A command of zeros of the vehicle's own length is always accepted.
        let _ = self.world.set_command(i, &zeros);
    }

    fn set_command(&mut self, i: usize, command: &[f64]) {
        if let Err(e) = self.world.set_command(i, command) {
            tracing::warn!("{e}: previous command held");
        }
    }

    /// Vehicle i back at its start (standing at its start position, motors off).
    fn reset_vehicle(&mut self, i: usize) {
        self.world.replace_vehicle(i, self.start[i].take());
    }

    /// Takes MAV_CMD_INJECT_FAILURE on `control` from now on, for each vehicle's sysid.
    pub fn set_control(&mut self, mut control: ControlLink) {
        control.set_systems(self.members.iter().map(|m| m.sysid).collect());
        self.control = Some(control);
    }

    /// Reads the control link when due: a fault injected into the vehicle the command
    /// addresses (0: every vehicle), now.
    fn poll_control(&mut self) {
        let now = self.lockstep.now_us();
        let Some(control) = &mut self.control else {
            return;
        };
        if now < self.next_poll_us {
            return;
        }
        self.next_poll_us = now + CONTROL_POLL_US;
        let members = &mut self.members;
        control.poll_addressed(|target, unit, failure, instance| {
            let mut done = Vec::new();
            for m in members
                .iter_mut()
                .filter(|m| target == 0 || m.sysid == target)
            {
                let f = match &mut m.faults {
                    Some(f) => f,
                    None => m.faults.insert(VehicleFaults::new(
                        FaultPlan::default(),
                        m.rotors,
                        m.mass,
                        m.seed,
                    )?),
                };
                let did = f.inject_px4(unit, failure, instance, m.rotors, now as f64 * 1e-6)?;
                done.push(format!("{}: {did}", m.name));
            }
            Ok(done.join("; "))
        });
    }

    /// Vehicle i's faults start again (a new connection: nothing fired).
    fn restart_faults(&mut self, i: usize) {
        let m = &mut self.members[i];
        if let Some(f) = &mut m.faults {
            f.restart(m.seed);
        }
    }

    /// PX4 i connected: its vehicle back at its start, the first HIL_SENSOR queued in its
    /// `out`.
    pub fn px4_connected(&mut self, i: usize) {
        self.reset_vehicle(i);
        self.restart_faults(i);
        self.lockstep.connect(i, false);
        self.members[i].connections += 1;
        let now = self.lockstep.now_us();
        let epoch = self.gps_epoch_us;
        let k = self.world.kinematics(i);
        let motors = self.world.vehicle(i).actuator_states();
        let m = &mut self.members[i];
        m.out.clear();
        if let Link::Px4(p) = &mut m.link {
            p.connect(now, epoch);
            let faults = m.faults.as_mut().map(|f| (f, motors.as_slice()));
            p.emit(&k, now, &mut m.out, faults);
        }
        let text = format!(
            "{}: PX4 connected at t={:.3} s, vehicle at its start",
            m.name,
            now as f64 * 1e-6
        );
        self.notice(MavSeverity::MAV_SEVERITY_INFO, text);
    }

    /// PX4 i's connection ended: motors off, out of the barrier.
    pub fn px4_closed(&mut self, i: usize, why: &str) {
        self.lockstep.disconnect(i);
        self.motors_off(i);
        self.members[i].out.clear();
        let text = format!(
            "{}: PX4 gone ({why}) at t={:.3} s: motors off until it reconnects",
            self.members[i].name,
            self.lockstep.now_us() as f64 * 1e-6
        );
        self.notice(MavSeverity::MAV_SEVERITY_WARNING, text);
    }

    /// Bytes on PX4 i's stream.
    pub fn px4_bytes(&mut self, i: usize, bytes: &[u8]) {
        let rotors = self.members[i].rotors;
        let said = match &mut self.members[i].link {
            Link::Px4(p) => p.receive(bytes, rotors),
            Link::ArduPilot(_) => return,
        };
        for s in said {
            let (command, time_usec) = match s {
                Said::Controls(c, t) => (c, t),
                Said::BadControls(t) => (self.world.vehicle(i).actuators(), t),
                Said::Heartbeat(sysid) => {
                    self.check_sysid(i, sysid);
                    continue;
                }
            };
            if self.is_stale(i, time_usec) {
                self.stale_controls += 1;
                continue;
            }
            self.answer(i, command);
        }
    }

    /// Whether PX4 i's controls stamped `time_usec` answer a HIL_SENSOR older than the last
    /// one it was sent, or one already answered. PX4 answers every HIL_SENSOR it gets, and a
    /// PX4 that starts up free gets many before its first controls: counting each of those
    /// answers as a step would keep that many steps in flight for good, every command
    /// applied that many steps late (enough to flip a vehicle on takeoff). In lockstep only
    /// the answer to the last sensors is a step.
    fn is_stale(&self, i: usize, time_usec: u64) -> bool {
        let s = self.lockstep.slot(i);
        s.phase == Phase::Lockstep
            && (time_usec < s.time_us.max(1) || s.next_us.is_some() || !s.answers.is_empty())
    }

    fn check_sysid(&mut self, i: usize, sysid: u8) {
        let m = &self.members[i];
        if sysid != m.sysid {
            let text = format!(
                "{}: PX4 on port {} has MAV_SYS_ID {sysid}, the fleet expects {} (started with `px4 -i {}`?)",
                m.name,
                m.listen.port(),
                m.sysid,
                m.sysid.saturating_sub(1)
            );
            self.notice(MavSeverity::MAV_SEVERITY_WARNING, text);
            self.members[i].sysid = sysid;
        }
    }

    fn answer(&mut self, i: usize, command: Vec<f64>) {
        let was = self.lockstep.slot(i).phase;
        if let Some(now) = self.lockstep.answer(i, command) {
            self.set_command(i, &now);
            let name = &self.members[i].name;
            let t = self.lockstep.now_us() as f64 * 1e-6;
            let text = match was {
                Phase::Silent => format!("{name}: answers again at t={t:.3} s: back in lockstep"),
                _ => format!("{name}: first controls at t={t:.3} s: in lockstep"),
            };
            self.notice(MavSeverity::MAV_SEVERITY_INFO, text);
        }
    }

    /// A datagram for ArduPilot i from `from`; returns whether its reply is to be sent now
    /// (a repeat of a frame already answered).
    pub fn ardupilot_datagram(&mut self, i: usize, bytes: &[u8], from: SocketAddr) -> bool {
        let rotors = self.members[i].rotors;
        let now = self.lockstep.now_us();
        let frame = match &mut self.members[i].link {
            Link::ArduPilot(a) => a.receive(bytes, from, rotors, now),
            Link::Px4(_) => return false,
        };
        match frame {
            Frame::Skipped => false,
            Frame::Repeat { answered } => answered,
            Frame::New {
                command,
                step_us,
                first,
            } => {
                if first {
                    let restarted = self.lockstep.slot(i).phase != Phase::Absent;
                    self.reset_vehicle(i);
                    self.restart_faults(i);
                    self.lockstep.connect(i, true);
                    self.members[i].connections += 1;
                    let text = format!(
                        "{}: ArduPilot {} at t={:.3} s from {from}, vehicle at its start",
                        self.members[i].name,
                        if restarted { "restarted" } else { "connected" },
                        now as f64 * 1e-6
                    );
                    self.notice(MavSeverity::MAV_SEVERITY_INFO, text);
                }
                self.lockstep.set_step(i, step_us);
                let command = command.unwrap_or_else(|| self.world.vehicle(i).actuators());
                self.answer(i, command);
                false
            }
        }
    }

    /// Autopilot i kept the world waiting longer than the timeout: motors off, out of the
    /// barrier until it answers again.
    pub fn silence(&mut self, i: usize, waited: std::time::Duration) {
        self.lockstep.silence(i);
        self.motors_off(i);
        let m = &self.members[i];
        let text = format!(
            "{}: {} silent for {:.1} s at t={:.3} s: motors off, the others go on",
            m.name,
            m.autopilot.name(),
            waited.as_secs_f64(),
            self.lockstep.now_us() as f64 * 1e-6
        );
        self.notice(MavSeverity::MAV_SEVERITY_WARNING, text);
    }

    /// Silent PX4 i, still connected, is sent sensors at the world's time (in its `out`):
    /// a PX4 that waits for sensors — ones it never got, or it answered and the answer was
    /// not heard — would otherwise never answer, and never rejoin (regression: a PX4
    /// silenced under load said "poll timeout" for good). Its answer to them rejoins it.
    /// Returns whether it was sent any (false for any other autopilot or phase).
    pub fn remind(&mut self, i: usize) -> bool {
        if self.lockstep.slot(i).phase != Phase::Silent {
            return false;
        }
        let now = self.lockstep.now_us();
        let k = self.world.kinematics(i);
        let motors = self.world.vehicle(i).actuator_states();
        let m = &mut self.members[i];
        let Link::Px4(p) = &mut m.link else {
            return false;
        };
        let faults = m.faults.as_mut().map(|f| (f, motors.as_slice()));
        p.emit(&k, now, &mut m.out, faults);
        true
    }

    /// One step of the world if the barrier lets it (`free`: also with nobody in
    /// lockstep); the autopilots due get their sensors in their `out` (PX4) or reply
    /// (ArduPilot). Returns the autopilots due.
    pub fn advance(&mut self, free: bool) -> Result<Vec<usize>, Hold> {
        let Advance {
            commands,
            dt_us,
            due,
        } = self.lockstep.advance(free)?;
        self.poll_control();
        for (i, command) in commands {
            self.set_command(i, &command);
        }
        let dt = dt_us as f64 * 1e-6;
        let held = self.faults_before_step(dt);
        self.world.step(dt);
        self.faults_after_step(held);
        let now = self.lockstep.now_us();
        let mut sent = Vec::new();
        for &i in &due {
            let k = self.world.kinematics(i);
            let m = &mut self.members[i];
            let from = m.out.len();
            let motors = self.world.vehicle(i).actuator_states();
            let faults = m.faults.as_mut().map(|f| (f, motors.as_slice()));
            let sample = match &mut m.link {
                Link::Px4(p) => {
                    p.emit(&k, now, &mut m.out, faults);
                    Sample::Px4From(from)
                }
                Link::ArduPilot(a) => Sample::Imu(a.answer(&k, now, faults)),
            };
            if self.view_record.is_on() {
                sent.push((i, sample));
            }
        }
        if self.view_record.is_on() {
            (self.view_record).step(now, &self.world, &self.members, &sent);
        }
        for c in self.world.take_collisions() {
            self.collisions += 1;
            let (a, b) = (self.members[c.a].sysid, self.members[c.b].sysid);
            self.view_record.collision(now, c.time, a, b, c.speed);
            let text = format!(
                "collision {} {} at t={:.3} s, closing at {:.2} m/s",
                self.members[c.a].name, self.members[c.b].name, c.time, c.speed
            );
            self.notice(MavSeverity::MAV_SEVERITY_CRITICAL, text);
        }
        Ok(due)
    }

    /// Before the world steps by `dt`: each faulted vehicle's faults due fire, and its motors
    /// get the actuator path's commands; returns its autopilot's, to hold again after.
    fn faults_before_step(&mut self, dt: f64) -> Vec<(usize, Option<Vec<f64>>)> {
        let time = self.lockstep.now_us() as f64 * 1e-6;
        let mut held = Vec::new();
        for (i, m) in self.members.iter_mut().enumerate() {
            if let Some(f) = &mut m.faults {
                let v = self.world.vehicle_mut(i);
                f.fire_due(time, v);
                held.push((i, f.before_advance(v, dt)));
            }
        }
        held
    }

    /// After the world stepped: the autopilots' commands held again, and every fault that
    /// fired or cleared a notice (log, STATUSTEXT) and a track event.
    fn faults_after_step(&mut self, held: Vec<(usize, Option<Vec<f64>>)>) {
        for (i, commanded) in held {
            VehicleFaults::after_advance(self.world.vehicle_mut(i), commanded);
            let m = &mut self.members[i];
            let Some(f) = &mut m.faults else { continue };
            let events = f.new_events().to_vec();
            let name = m.name.clone();
            for e in events {
                let verb = if e.fired { "fired" } else { "cleared" };
                let text = format!("{name}: fault {verb}: {} at {:.3} s", e.label, e.time);
                self.members[i].fault_log.push(e);
                self.notice(MavSeverity::MAV_SEVERITY_WARNING, text);
            }
        }
    }
}

#[cfg(test)]
mod fault_tests;
#[cfg(test)]
mod tests;
