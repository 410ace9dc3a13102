//! What a fleet is made of: each vehicle's autopilot, port, system id, start position and
//! vehicle, and the world they share. Read from a fleet file (`--fleet FILE`, TOML) or made
//! from `--px4 --vehicles N` / `--ardupilot --vehicles N`; checked before any socket opens.

use crate::config::AutopilotVehicle;
use flyloop_core::faults::catalogue::Target;
use flyloop_core::faults::plan::FAULTS_TABLE;
use flyloop_core::faults::{FaultKind, Reach};
use flyloop_core::quadrotor::Frame;
use flyloop_core::world::WorldParams;
use serde::Deserialize;
use std::net::{IpAddr, Ipv4Addr, SocketAddr};
use std::path::Path;

/// The autopilot flying one vehicle.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Autopilot {
    /// PX4 SITL over TCP (simulator_mavlink); its step is `--px4-step` (4 ms).
    Px4,
    /// ArduPilot SITL with `--model JSON` over UDP; its step is 1 / its frame rate.
    Ardupilot,
}

impl Autopilot {
    /// Its name in logs and fleet files.
    pub fn name(self) -> &'static str {
        match self {
            Autopilot::Px4 => "px4",
            Autopilot::Ardupilot => "ardupilot",
        }
    }

    /// The simulator port of instance `i`: PX4 connects to TCP 4560 + i, ArduPilot sends its
    /// servo packets to UDP 9002 + 10·i.
    pub fn default_port(self, instance: u16) -> Option<u16> {
        match self {
            Autopilot::Px4 => 4560u16.checked_add(instance),
            Autopilot::Ardupilot => instance.checked_mul(10).and_then(|p| p.checked_add(9002)),
        }
    }
}

/// One vehicle of the fleet.
#[derive(Debug, Clone, PartialEq)]
pub struct FleetVehicle {
    /// Its name in the world (vehicles are kept in name order) and in logs.
    pub name: String,
    pub autopilot: Autopilot,
    /// Where flyloop listens for its autopilot (PX4: TCP; ArduPilot: UDP).
    pub listen: SocketAddr,
    /// The autopilot's MAVLink system id: PX4 instance i sets i + 1 itself; ArduPilot is
    /// started with `--sysid` (default instance + 1).
    pub sysid: u8,
    /// Start position, m east and north of home (standing on its gear).
    pub position: [f64; 2],
    /// Its parameters, sensors and frame.
    pub vehicle: AutopilotVehicle,
}

/// A fleet: the world's parameters and its vehicles (in the file's order).
#[derive(Debug, Clone, PartialEq)]
pub struct FleetSpec {
    pub world: WorldParams,
    pub vehicles: Vec<FleetVehicle>,
}

/// Why a fleet cannot be flown: the item named.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{0}")]
pub struct FleetError(pub String);

/// A `[[vehicle]]` table as written.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct VehicleEntry {
    name: Option<String>,
    autopilot: Autopilot,
    instance: u16,
    port: Option<u16>,
    sysid: Option<u16>,
    #[serde(default)]
    position: [f64; 2],
    config: Option<String>,
    frame: Option<String>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct FileEntries {
    #[serde(default)]
    world: Option<toml::Table>,
    #[serde(default)]
    vehicle: Vec<VehicleEntry>,
    /// `[[faults]]` tables, each naming its vehicle (`vehicle = "px4-001"`).
    #[serde(default)]
    faults: Vec<toml::Table>,
}

/// Loopback: the autopilots run on this machine.
const LOCALHOST: IpAddr = IpAddr::V4(Ipv4Addr::LOCALHOST);
/// Most vehicles in one fleet (PX4's system ids run to 255 = instance 254).
pub const MAX_FLEET: usize = 254;

/// World parameters of a fleet: the core's defaults, except that the wind is off unless the
/// `[world]` table turns it on (an autopilot's single-vehicle flights have none either).
pub fn world_params(table: Option<toml::Table>) -> Result<WorldParams, FleetError> {
    let mut table = table.unwrap_or_default();
    table
        .entry("wind_enabled")
        .or_insert(toml::Value::Boolean(false));
    let params: WorldParams = table
        .try_into()
        .map_err(|e| FleetError(format!("[world]: {e}")))?;
    use flyloop_core::params::Parameters;
    params
        .validate()
        .map_err(|e| FleetError(format!("[world]: {e}")))?;
    Ok(params)
}

/// `n` vehicles flown by `autopilot` instances 0..n, their ports counted from `base`
/// (PX4: base + i, ArduPilot: base + 10·i), in a row `spacing` m apart going east.
pub fn row(
    autopilot: Autopilot,
    n: usize,
    base: SocketAddr,
    spacing: f64,
    vehicle: &AutopilotVehicle,
) -> Result<FleetSpec, FleetError> {
    if n == 0 || n > MAX_FLEET {
        return Err(FleetError(format!(
            "--vehicles: a fleet holds 1 to {MAX_FLEET} vehicles, {n} given"
        )));
    }
    let stride = match autopilot {
        Autopilot::Px4 => 1,
        Autopilot::Ardupilot => 10,
    };
    let vehicles = (0..n)
        .map(|i| {
            // Port 0: every vehicle on an ephemeral port of its own (the ready line says which).
            let port = match base.port() {
                0 => 0,
                first => u16::try_from(usize::from(first) + stride * i).map_err(|_| {
                    FleetError(format!(
                        "--vehicles {n}: vehicle {i}'s port {first} + {} is past 65535",
                        stride * i
                    ))
                })?,
            };
            // The instance whose default port this is sets (PX4) or is given (ArduPilot)
            // system id instance + 1; off the default ports, vehicle i's is i + 1.
            let instance = match autopilot {
                Autopilot::Px4 => port.checked_sub(4560),
                Autopilot::Ardupilot => port
                    .checked_sub(9002)
                    .filter(|p| p % 10 == 0)
                    .map(|p| p / 10),
            };
            let sysid = instance
                .and_then(|k| u8::try_from(k + 1).ok())
                .unwrap_or((i + 1) as u8);
            Ok(FleetVehicle {
                name: format!("{}-{i:03}", autopilot.name()),
                autopilot,
                listen: SocketAddr::new(base.ip(), port),
                sysid,
                position: [spacing * i as f64, 0.0],
                vehicle: vehicle.clone(),
            })
        })
        .collect::<Result<Vec<_>, FleetError>>()?;
    let spec = FleetSpec {
        world: world_params(None)?,
        vehicles,
    };
    spec.check()?;
    Ok(spec)
}

/// A fleet file's text; `dir` is where relative `config` paths start.
pub fn parse(text: &str, dir: &Path) -> Result<FleetSpec, FleetError> {
    let file: FileEntries = toml::from_str(text).map_err(|e| FleetError(e.to_string()))?;
    if file.vehicle.is_empty() || file.vehicle.len() > MAX_FLEET {
        return Err(FleetError(format!(
            "a fleet file holds 1 to {MAX_FLEET} [[vehicle]] tables, {} given",
            file.vehicle.len()
        )));
    }
    let mut vehicles = (file.vehicle.into_iter().enumerate())
        .map(|(i, entry)| vehicle(i, entry, dir))
        .collect::<Result<Vec<_>, FleetError>>()?;
    for (i, table) in file.faults.into_iter().enumerate() {
        add_fault(&mut vehicles, i, table)?;
    }
    let spec = FleetSpec {
        world: world_params(file.world)?,
        vehicles,
    };
    spec.check()?;
    Ok(spec)
}

/// One `[[vehicle]]` (index `i` in the file).
fn vehicle(i: usize, e: VehicleEntry, dir: &Path) -> Result<FleetVehicle, FleetError> {
    let name =
        (e.name.clone()).unwrap_or_else(|| format!("{}-{:03}", e.autopilot.name(), e.instance));
    let item = |what: String| FleetError(format!("vehicle {i} (`{name}`): {what}"));
    let port = match e.port {
        Some(p) => p,
        None => e
            .autopilot
            .default_port(e.instance)
            .ok_or_else(|| item(format!("instance {} puts its port past 65535", e.instance)))?,
    };
    if port == 0 {
        return Err(item("port must be 1 to 65535, 0 given".into()));
    }
    let own = e.instance.checked_add(1).filter(|&s| s <= 255);
    let sysid = match (e.autopilot, e.sysid, own) {
        (_, Some(s), _) if !(1..=255).contains(&s) => {
            return Err(item(format!("sysid must be 1 to 255, {s} given")));
        }
        (Autopilot::Px4, Some(s), Some(o)) if s != o => {
            return Err(item(format!(
                "sysid {s}: PX4 instance {} sets its MAV_SYS_ID to {o} itself (leave sysid out or give {o})",
                e.instance
            )));
        }
        (_, Some(s), _) => s as u8,
        (_, None, Some(o)) => o as u8,
        (_, None, None) => {
            return Err(item(format!(
                "instance {} has no system id of its own (instances run 0 to 254)",
                e.instance
            )));
        }
    };
    if !e.position.iter().all(|x| x.is_finite()) {
        return Err(item(format!(
            "position {:?} must be two finite numbers [east, north] in m",
            e.position
        )));
    }
    let mut vehicle = match &e.config {
        None => AutopilotVehicle::iris(),
        Some(path) => crate::config::load_autopilot_vehicle(&dir.join(path))
            .map_err(|err| item(format!("config: {err}")))?,
    };
    if let Some(frame) = &e.frame {
        vehicle.frame = Frame::named(frame).map_err(|err| item(format!("frame: {err}")))?;
    }
    Ok(FleetVehicle {
        name,
        autopilot: e.autopilot,
        listen: SocketAddr::new(LOCALHOST, port),
        sysid,
        position: e.position,
        vehicle,
    })
}

/// The key of a fleet file's `[[faults]]` table that names its vehicle.
pub const VEHICLE_KEY: &str = "vehicle";

/// Fleet file `[[faults]]` table `i`: added to the plan of the vehicle its `vehicle` names.
fn add_fault(
    vehicles: &mut [FleetVehicle],
    i: usize,
    mut table: toml::Table,
) -> Result<(), FleetError> {
    let names: Vec<&str> = vehicles.iter().map(|v| v.name.as_str()).collect();
    let names = names.join("`, `");
    let name = match table.remove(VEHICLE_KEY) {
        Some(toml::Value::String(name)) => name,
        _ => {
            return Err(FleetError(format!(
                "[[faults]] {i}: needs `{VEHICLE_KEY}`, the name of the vehicle it is for (`{names}`)"
            )));
        }
    };
    let Some(v) = vehicles.iter_mut().find(|v| v.name == name) else {
        return Err(FleetError(format!(
            "[[faults]] {i}: vehicle `{name}` is not in the fleet; its vehicles: `{names}`"
        )));
    };
    (v.vehicle.faults)
        .add(FAULTS_TABLE, &toml::Value::Table(table))
        .map_err(|e| FleetError(format!("[[faults]] {i} (vehicle `{name}`): {e}")))
}

/// Rotor count of `v`'s frame.
fn rotors_of(v: &FleetVehicle) -> usize {
    v.vehicle.frame.rotor_count()
}

/// Refuses faults a fleet vehicle cannot have: a motor its frame lacks, an air fault (the
/// world's wind field sets every vehicle's wind), a link fault (the fleet's barrier holds
/// the world for every autopilot: not yet).
fn check_faults(vehicle: &AutopilotVehicle, rotors: usize) -> Result<(), String> {
    let plan = &vehicle.faults;
    plan.check(&Reach {
        duration: None,
        waypoints: None,
        rotors,
    })
    .map_err(|e| format!("faults: {e}"))?;
    let kinds =
        (plan.faults.iter().map(|f| f.kind)).chain(plan.draws.iter().flat_map(|d| d.kinds.clone()));
    for kind in kinds {
        let refused = match kind.spec().target {
            Target::Link => Some("link faults are not flown in fleet mode yet"),
            _ if matches!(kind, FaultKind::Gust | FaultKind::WindShear) => Some(
                "the world's wind field sets every vehicle's wind in fleet mode (use [world]'s wind)",
            ),
            _ => None,
        };
        if let Some(why) = refused {
            return Err(format!("faults: `{}`: {why}", kind.name()));
        }
    }
    Ok(())
}

impl FleetSpec {
    /// Refuses duplicate names, ports (of one transport) and system ids, and faults a
    /// vehicle cannot have.
    pub fn check(&self) -> Result<(), FleetError> {
        let v = &self.vehicles;
        for (i, v) in v.iter().enumerate() {
            check_faults(&v.vehicle, rotors_of(v))
                .map_err(|what| FleetError(format!("vehicle {i} (`{}`): {what}", v.name)))?;
        }
        for (j, b) in v.iter().enumerate() {
            for (i, a) in v[..j].iter().enumerate() {
                let clash = if a.name == b.name {
                    Some(format!("name `{}`", b.name))
                } else if a.listen.port() == b.listen.port()
                    && a.listen.port() != 0
                    && a.autopilot == b.autopilot
                {
                    Some(format!("port {}", b.listen.port()))
                } else if a.sysid == b.sysid {
                    Some(format!("sysid {}", b.sysid))
                } else {
                    None
                };
                if let Some(what) = clash {
                    return Err(FleetError(format!(
                        "vehicle {j} (`{}`): {what} is also vehicle {i}'s (`{}`)",
                        b.name, a.name
                    )));
                }
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests;
