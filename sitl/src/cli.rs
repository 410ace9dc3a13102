//! Command-line options.

use crate::kinematics::Home;
use crate::sim::Mode;
use clap::Parser;
use clap::builder::{PossibleValuesParser, TypedValueParser};
use flyloop_core::tasks::multi::Scenario;
use flyloop_core::tasks::registry::{ModelKind, TaskKind};
use std::net::SocketAddr;
use std::path::PathBuf;
use std::time::Duration;

/// MAVLink 2 SITL of flyloop: flies the core's quadrotor or 2D lander for any MAVLink peer.
///
/// On start it prints one line on stdout:
/// `flyloop-sitl ready listen=<addr> gcs=<local>-><target>|off mode=<mode> model=<model>
/// task=<task> vehicles=<n> seed=<seed>`; logs go to stderr. The protocol is described in
/// docs/protocol.md.
#[derive(Debug, Parser)]
#[command(name = "flyloop-sitl", version)]
pub struct Args {
    /// Vehicle model [default: the task's model, else quadrotor].
    #[arg(long, value_parser = model_parser())]
    pub model: Option<ModelKind>,

    /// Task flown on the model [default: hover for quadrotor, landing for lander2d]; the
    /// multi-agent tasks `multi_hover` and `swap` fly `--vehicles` quadrotors in ONE world
    /// (lockstep; docs/protocol.md section 14).
    #[arg(long, value_parser = task_parser())]
    pub task: Option<TaskArg>,

    /// Controller link: UDP address to listen on (port 0 picks a free port; see the first
    /// stdout line).
    #[arg(long, default_value = "127.0.0.1:14560")]
    pub listen: SocketAddr,

    /// Ground-station link: UDP address telemetry is sent to, or `off`.
    #[arg(long, default_value = "127.0.0.1:14550", value_parser = parse_gcs)]
    pub gcs: GcsTarget,

    /// Local address of the ground-station socket.
    #[arg(long, default_value = "0.0.0.0:0")]
    pub gcs_bind: SocketAddr,

    /// Pacing: `lockstep` (one step per command, no wall clock) or `realtime`.
    #[arg(long, value_enum, default_value = "lockstep")]
    pub mode: Mode,

    /// Shorthand for `--mode realtime`.
    #[arg(long, conflicts_with_all = ["mode", "lockstep"])]
    pub realtime: bool,

    /// Shorthand for `--mode lockstep`.
    #[arg(long, conflicts_with = "mode")]
    pub lockstep: bool,

    /// Number of vehicles, system ids 1..=N, each its own core instance.
    #[arg(long, default_value_t = 1, value_parser = clap::value_parser!(u8).range(1..=254))]
    pub vehicles: u8,

    /// Base seed: vehicle k starts with seed + k − 1.
    #[arg(long, default_value_t = 0)]
    pub seed: u64,

    /// Parameter file (flat TOML of parameters by name: the model's and the task's, or with
    /// --px4 / --ardupilot the vehicle's quadrotor and sensor parameters).
    #[arg(long)]
    pub config: Option<PathBuf>,

    /// Log level on stderr: error, warn, info, debug (every skipped input) or trace.
    #[arg(long, default_value = "info")]
    pub log_level: tracing::Level,

    /// Home position `LAT,LON,ALT` (degrees, degrees, metres above MSL).
    #[arg(long, value_parser = parse_home, default_value = "47.397742,8.545594,488")]
    pub home: Home,

    /// Leave HIL_STATE_QUATERNION out of lockstep replies (peers can still turn it on with
    /// SET_MESSAGE_INTERVAL).
    #[arg(long)]
    pub no_state_reply: bool,

    /// Real time: seconds without a command after which the motors go off.
    #[arg(long, default_value_t = 0.5, value_parser = parse_seconds)]
    pub failsafe_timeout: f64,

    /// Real time: HIL_STATE_QUATERNION stream rate to controller peers, Hz.
    #[arg(long, default_value_t = 50.0, value_parser = parse_rate)]
    pub state_rate: f64,

    /// PX4 mode: be PX4's simulator (TCP, HIL_SENSOR / HIL_GPS out, HIL_ACTUATOR_CONTROLS in,
    /// lockstep); quadrotor only, the Iris preset unless `--config` names another file.
    #[arg(long)]
    pub px4: bool,

    /// PX4 mode: TCP address PX4 connects to (PX4 instance k uses port 4560 + k).
    #[arg(long, default_value = "127.0.0.1:4560")]
    pub px4_listen: SocketAddr,

    /// PX4 mode: physics step per HIL_ACTUATOR_CONTROLS, s.
    #[arg(long, default_value_t = 0.004, value_parser = parse_step)]
    pub px4_step: f64,

    /// ArduPilot mode: be ArduPilot's JSON physics backend (UDP: servo packets in, one JSON
    /// state line out per frame, lockstep); quadrotor only, the Iris preset unless `--config`
    /// names another file. ArduPilot runs with `--model JSON`.
    #[arg(long, conflicts_with = "px4")]
    pub ardupilot: bool,

    /// ArduPilot mode: UDP address ArduPilot sends its servo packets to (ArduPilot instance k
    /// sends to port 9002 + 10k; port 0 picks a free port, see the first stdout line).
    #[arg(long, default_value = "127.0.0.1:9002")]
    pub ardupilot_listen: SocketAddr,

    /// PX4 and ArduPilot modes: control link, a MAVLink UDP address that takes
    /// MAV_CMD_INJECT_FAILURE for the vehicle (system id 1) and answers COMMAND_ACK +
    /// STATUSTEXT (port 0 picks a free port: see `control=` in the first stdout line). The
    /// lockstep task mode takes the command on its `--listen` link.
    #[arg(long)]
    pub control: Option<SocketAddr>,

    /// PX4 and ArduPilot modes: simulation seconds per wall-clock second (0 = as fast as the
    /// autopilot answers). Start PX4 with the same PX4_SIM_SPEED_FACTOR, ArduPilot with a
    /// `--speedup` at least as high.
    #[arg(long, default_value_t = 1.0, value_parser = parse_speed)]
    pub speed_factor: f64,

    /// PX4, ArduPilot and fleet modes: write the ground-truth track (CSV, by default 50 Hz
    /// of simulation time; in fleet mode a row per vehicle, docs/fleet.md) to this file.
    #[arg(long)]
    pub track: Option<PathBuf>,

    /// PX4 and ArduPilot modes: send the ground truth (HIL_STATE_QUATERNION at 50 Hz of
    /// simulation time) to a live view listening at this UDP address (docs/view.md); in
    /// fleet mode every vehicle's, with its motor commands, collisions and notices.
    #[arg(long)]
    pub view: Option<SocketAddr>,

    /// Record every step of every vehicle (motor command, ground truth, wind; the task frame
    /// in lockstep and real time; PX4 and ArduPilot mode: the sensor samples sent and the
    /// autopilot's outputs; fleet mode: every world step of every vehicle, collisions and
    /// notices) to this MAVLink telemetry log (.tlog; docs/view.md).
    #[arg(long)]
    pub record: Option<PathBuf>,

    /// PX4, ArduPilot and fleet modes: simulation time between two rows of the track, µs
    /// (4000 = every PX4 step).
    #[arg(long, default_value_t = crate::track::TRACK_INTERVAL_US, value_parser = clap::value_parser!(u64).range(1..))]
    pub track_interval_us: u64,

    /// Fleet mode: a fleet file (TOML: `[world]`, one `[[vehicle]]` per autopilot) of PX4
    /// and ArduPilot vehicles sharing one world (docs/fleet.md). `--px4 --vehicles N` and
    /// `--ardupilot --vehicles N` make a row of N without a file.
    #[arg(long, conflicts_with_all = ["px4", "ardupilot"])]
    pub fleet: Option<PathBuf>,

    /// Fleet mode (`--vehicles N`): metres between neighbours of the row, going east.
    #[arg(long, default_value_t = 3.0, value_parser = parse_spacing)]
    pub spacing: f64,

    /// Fleet mode: wall seconds an autopilot may keep the world waiting before its
    /// vehicle's motors stop and the others go on (it takes its vehicle back when it
    /// answers again or restarts).
    #[arg(long, default_value_t = 3.0, value_parser = parse_seconds)]
    pub autopilot_timeout: f64,

    /// Print the task's parameters and exit: `table` (MAVLink ids, names, ranges, defaults;
    /// the default) or `toml` (a starter file for --config, with --config's values if given).
    #[arg(long, value_enum, num_args = 0..=1, default_missing_value = "table")]
    pub list_params: Option<ListFormat>,

    /// Print the task frame layout (DEBUG_FLOAT_ARRAY indices) and exit.
    #[arg(long)]
    pub describe_frame: bool,

    /// Print the autopilot parameters that match the vehicle's frame (the Iris preset or
    /// --config's `[frame]`) and exit: `px4` (`NAME VALUE` lines, for PX4_PARAM_NAME=VALUE)
    /// or `ardupilot` (a .parm file).
    #[arg(long, value_enum)]
    pub print_autopilot_params: Option<crate::autopilot_params::Autopilot>,
}

fn parse_spacing(s: &str) -> Result<f64, String> {
    match s.parse::<f64>() {
        Ok(x) if x.is_finite() && (0.5..=1000.0).contains(&x) => Ok(x),
        _ => Err(format!("`{s}`: the spacing must be 0.5 to 1000 m")),
    }
}

/// `--model`'s values: the core's model names.
fn model_parser() -> impl TypedValueParser<Value = ModelKind> {
    PossibleValuesParser::new(ModelKind::ALL.map(ModelKind::name))
        .try_map(|name| ModelKind::from_name(&name).ok_or("unknown model"))
}

/// A `--task`: a single-vehicle task (one per vehicle) or a multi-agent world.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TaskArg {
    Single(TaskKind),
    World(Scenario),
}

impl TaskArg {
    fn model(self) -> ModelKind {
        match self {
            TaskArg::Single(t) => t.model(),
            TaskArg::World(_) => ModelKind::Quadrotor,
        }
    }
}

/// `--task`'s values: the core's task names, then the multi-agent tasks'.
fn task_parser() -> impl TypedValueParser<Value = TaskArg> {
    let worlds = [Scenario::MultiHover, Scenario::Swap].map(Scenario::name);
    PossibleValuesParser::new(
        TaskKind::ALL
            .map(TaskKind::frame_name)
            .into_iter()
            .chain(worlds),
    )
    .try_map(|name| {
        TaskKind::from_name(&name)
            .map(TaskArg::Single)
            .or(Scenario::from_name(&name).map(TaskArg::World))
            .ok_or("unknown task")
    })
}

/// How `--list-params` prints.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum ListFormat {
    /// A Markdown table: MAVLink id, core name, set, type, unit, default, range.
    Table,
    /// A starter parameter file for `--config`.
    Toml,
}

/// Where ground-station telemetry goes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum GcsTarget {
    Off,
    At(SocketAddr),
}

fn parse_gcs(s: &str) -> Result<GcsTarget, String> {
    if s.eq_ignore_ascii_case("off") {
        return Ok(GcsTarget::Off);
    }
    s.parse()
        .map(GcsTarget::At)
        .map_err(|e| format!("`{s}` is neither `off` nor an address like 127.0.0.1:14550 ({e})"))
}

fn parse_home(s: &str) -> Result<Home, String> {
    let parts: Vec<&str> = s.split(',').map(str::trim).collect();
    let numbers: Vec<f64> = parts.iter().filter_map(|p| p.parse().ok()).collect();
    match numbers[..] {
        [lat, lon, alt]
            if parts.len() == 3
                && (-90.0..=90.0).contains(&lat)
                && (-180.0..=180.0).contains(&lon)
                && alt.is_finite() =>
        {
            Ok(Home {
                latitude_deg: lat,
                longitude_deg: lon,
                altitude_m: alt,
            })
        }
        _ => Err(format!(
            "`{s}` is not LAT,LON,ALT with latitude in [-90, 90] and longitude in [-180, 180]"
        )),
    }
}

fn parse_seconds(s: &str) -> Result<f64, String> {
    match s.parse::<f64>() {
        Ok(v) if v > 0.0 && v <= 3600.0 => Ok(v),
        _ => Err(format!("`{s}` is not a number of seconds in (0, 3600]")),
    }
}

fn parse_step(s: &str) -> Result<f64, String> {
    match s.parse::<f64>() {
        Ok(v) if (1e-4..=0.1).contains(&v) => Ok(v),
        _ => Err(format!("`{s}` is not a step in [0.0001, 0.1] s")),
    }
}

fn parse_speed(s: &str) -> Result<f64, String> {
    match s.parse::<f64>() {
        Ok(v) if (0.0..=1000.0).contains(&v) => Ok(v),
        _ => Err(format!(
            "`{s}` is not a speed factor in [0, 1000] (0 = as fast as possible)"
        )),
    }
}

fn parse_rate(s: &str) -> Result<f64, String> {
    match s.parse::<f64>() {
        Ok(v) if v > 0.0 && v <= 10_000.0 => Ok(v),
        _ => Err(format!("`{s}` is not a rate in (0, 10000] Hz")),
    }
}

impl Args {
    /// The model, from `--model` or the task's model.
    pub fn model(&self) -> ModelKind {
        self.model
            .or(self.task.map(TaskArg::model))
            .unwrap_or(ModelKind::Quadrotor)
    }

    /// The task, from `--task` or the model's default.
    pub fn task(&self) -> Result<TaskKind, String> {
        let model = self.model();
        let task = match self.task {
            Some(TaskArg::World(s)) => {
                return Err(format!(
                    "task `{}` is a multi-agent world, not one vehicle's task",
                    s.name()
                ));
            }
            Some(TaskArg::Single(t)) => t,
            None => TaskKind::default_for(model),
        };
        if task.model() != model {
            return Err(format!(
                "task `{}` does not run on model `{}`: quadrotor flies hover or waypoints, lander2d flies landing",
                task.frame_name(),
                model.name()
            ));
        }
        Ok(task)
    }

    /// The multi-agent task `--task` names, if it names one.
    pub fn world_task(&self) -> Option<Scenario> {
        match self.task {
            Some(TaskArg::World(s)) => Some(s),
            _ => None,
        }
    }

    /// The first option set that a multi-agent world does not take (it runs in lockstep and
    /// writes nothing beside the flight), if any: refused at start-up rather than ignored.
    pub fn not_for_a_world(&self) -> Option<&'static str> {
        [
            (self.mode() != Mode::Lockstep, "--realtime"),
            (self.record.is_some(), "--record"),
            (self.track.is_some(), "--track"),
            (self.view.is_some(), "--view"),
            (self.list_params.is_some(), "--list-params"),
            (self.describe_frame, "--describe-frame"),
            (self.model() != ModelKind::Quadrotor, "--model lander2d"),
        ]
        .into_iter()
        .find_map(|(set, option)| set.then_some(option))
    }

    pub fn mode(&self) -> Mode {
        if self.realtime {
            Mode::Realtime
        } else if self.lockstep {
            Mode::Lockstep
        } else {
            self.mode
        }
    }

    pub fn failsafe_timeout(&self) -> Duration {
        Duration::from_secs_f64(self.failsafe_timeout)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(args: &[&str]) -> Result<Args, clap::Error> {
        Args::try_parse_from(std::iter::once("flyloop-sitl").chain(args.iter().copied()))
    }

    #[test]
    fn defaults_are_a_lockstep_quadrotor_hovering() {
        let a = parse(&[]).unwrap();
        assert_eq!(
            (a.model(), a.task().unwrap(), a.mode()),
            (ModelKind::Quadrotor, TaskKind::Hover, Mode::Lockstep)
        );
        assert_eq!(a.gcs, GcsTarget::At("127.0.0.1:14550".parse().unwrap()));
        assert_eq!(a.listen.port(), 14560);
        let a = parse(&[
            "--model",
            "lander2d",
            "--realtime",
            "--gcs",
            "off",
            "--vehicles",
            "16",
        ])
        .unwrap();
        assert_eq!(
            (a.task().unwrap(), a.mode(), a.gcs, a.vehicles),
            (TaskKind::Landing, Mode::Realtime, GcsTarget::Off, 16)
        );
    }

    #[test]
    fn a_multi_agent_task_is_a_world_of_quadrotors() {
        let a = parse(&["--task", "swap", "--vehicles", "4"]).unwrap();
        assert_eq!(a.world_task(), Some(Scenario::Swap));
        assert_eq!(a.model(), ModelKind::Quadrotor);
        assert!(a.task().unwrap_err().contains("multi-agent world"));
        let a = parse(&["--task", "multi_hover"]).unwrap();
        assert_eq!(a.world_task(), Some(Scenario::MultiHover));
        assert_eq!(parse(&["--task", "hover"]).unwrap().world_task(), None);
    }

    #[test]
    fn a_world_refuses_the_options_it_would_ignore() {
        let world = ["--task", "swap", "--vehicles", "2"];
        assert_eq!(parse(&world).unwrap().not_for_a_world(), None);
        for (extra, named) in [
            (&["--realtime"][..], "--realtime"),
            (&["--record", "w.tlog"], "--record"),
            (&["--track", "w.csv"], "--track"),
            (&["--view", "127.0.0.1:14570"], "--view"),
            (&["--list-params"], "--list-params"),
            (&["--describe-frame"], "--describe-frame"),
            (&["--model", "lander2d"], "--model lander2d"),
        ] {
            let a = parse(&[&world[..], extra].concat()).unwrap();
            assert_eq!(a.not_for_a_world(), Some(named), "{extra:?}");
        }
    }

    #[test]
    fn bad_options_are_refused() {
        assert!(parse(&["--vehicles", "0"]).is_err());
        assert!(parse(&["--vehicles", "255"]).is_err());
        assert!(parse(&["--home", "91,0,0"]).is_err());
        assert!(parse(&["--failsafe-timeout", "-1"]).is_err());
        assert!(parse(&["--realtime", "--lockstep"]).is_err());
        let a = parse(&["--model", "lander2d", "--task", "hover"]).unwrap();
        assert!(a.task().unwrap_err().contains("does not run on model"));
        assert_eq!(
            parse(&["--task", "landing"]).unwrap().model(),
            ModelKind::Lander2d
        );
        assert!(parse(&["--px4-step", "0"]).is_err());
        assert!(parse(&["--speed-factor", "-1"]).is_err());
        let a = parse(&[
            "--px4",
            "--px4-listen",
            "127.0.0.1:4561",
            "--speed-factor",
            "0",
        ])
        .unwrap();
        assert_eq!(
            (a.px4, a.px4_listen.port(), a.speed_factor, a.px4_step),
            (true, 4561, 0.0, 0.004)
        );
        let a = parse(&["--ardupilot", "--ardupilot-listen", "127.0.0.1:0"]).unwrap();
        assert!(a.ardupilot && !a.px4 && a.ardupilot_listen.port() == 0);
        assert_eq!(parse(&[]).unwrap().ardupilot_listen.port(), 9002);
        assert!(parse(&["--ardupilot", "--px4"]).is_err());
        let h = parse(&["--home", "10.5, -20.25, 3"]).unwrap().home;
        assert_eq!(
            (h.latitude_deg, h.longitude_deg, h.altitude_m),
            (10.5, -20.25, 3.0)
        );
    }
}
