//! The `flyloop-sitl` program: options, sockets, then the server loop until SIGINT / SIGTERM.
//! A library function so the binary and the Python wheel's `flyloop-sitl` command share it.

use crate::autopilot_params::{self, Autopilot};
use crate::cli::{Args, GcsTarget, ListFormat};
use crate::config::{self, AutopilotVehicle, ConfigError};
use crate::control_link::ControlLink;
use crate::px4::server::Pacing;
use crate::px4::session::{Session, SessionOptions};
use crate::server::{self, GcsLink};
use crate::sim::{Sim, SimOptions, WorldTask};
use crate::track::Track;
use crate::{ardupilot, px4};
use crate::{param_table, starter_config, task_frame};
use clap::Parser;
use flyloop_core::ParamError;
use flyloop_core::tasks::multi::{MultiError, Scenario};
use flyloop_core::tasks::registry::{ModelKind, TaskConfig, TaskInstance, TaskKind};
use std::io::IsTerminal;
use std::net::SocketAddr;
use std::time::Instant;

/// Why the SITL could not start (printed as one line, exit code 1).
#[derive(Debug, thiserror::Error)]
enum StartError {
    #[error("{0}")]
    Options(String),
    #[error(transparent)]
    Config(#[from] ConfigError),
    #[error("{0}")]
    Parameters(#[from] ParamError),
    #[error("cannot bind the {link} socket to {addr}: {source}")]
    Bind {
        link: &'static str,
        addr: SocketAddr,
        source: std::io::Error,
    },
    #[error("cannot write the track file {path}: {source}")]
    Track {
        path: std::path::PathBuf,
        source: std::io::Error,
    },
    #[error("cannot open a socket to send to the view at {target}: {source}")]
    View {
        target: SocketAddr,
        source: std::io::Error,
    },
    #[error("cannot write the recording {path}: {source}")]
    Record {
        path: std::path::PathBuf,
        source: std::io::Error,
    },
    #[error("fleet file {path}: {source}")]
    FleetFile {
        path: std::path::PathBuf,
        source: crate::fleet::file::FleetError,
    },
    #[error("{0}")]
    Fleet(#[from] crate::fleet::file::FleetError),
    #[error("{0}")]
    FleetStart(#[from] crate::fleet::FleetStartError),
    #[error("vehicle `{name}`: cannot bind its autopilot's port {addr}: {source}")]
    FleetBind {
        name: String,
        addr: SocketAddr,
        source: std::io::Error,
    },
    #[error("cannot start the runtime: {0}")]
    Runtime(#[from] std::io::Error),
}

/// Bytes asked for each socket's receive and send buffer.
const SOCKET_BUFFER: usize = 8 << 20;

fn bind(link: &'static str, addr: SocketAddr) -> Result<std::net::UdpSocket, StartError> {
    let socket = std::net::UdpSocket::bind(addr).map_err(|source| StartError::Bind {
        link,
        addr,
        source,
    })?;
    socket
        .set_nonblocking(true)
        .map_err(|source| StartError::Bind { link, addr, source })?;
    // Room for bursts (a flood beside a lockstep client, a vector env's large replies): the
    // kernel's default (~208 KiB) overflows in a few thousand datagrams. The kernel caps the
    // request at net.core.rmem_max / wmem_max; a smaller buffer is not an error.
    let sock = socket2::SockRef::from(&socket);
    for (what, r) in [
        ("receive", sock.set_recv_buffer_size(SOCKET_BUFFER)),
        ("send", sock.set_send_buffer_size(SOCKET_BUFFER)),
    ] {
        if let Err(e) = r {
            tracing::warn!(link, error = %e, "cannot size the {what} buffer");
        }
    }
    Ok(socket)
}

fn describe_frame(task: TaskKind, config: &TaskConfig) -> Result<String, ParamError> {
    let t = TaskInstance::build(task, config)?;
    let n = t.observation_size();
    let info = task_frame::info_layout(&t);
    let values = task_frame::HEADER_LEN + n + info.iter().map(|e| e.2).sum::<usize>();
    let mut out = format!(
        "task frame of `{name}` (DEBUG_FLOAT_ARRAY name \"{name}\", {values} values over {} array(s) of {})\n",
        values.div_ceil(task_frame::ARRAY_LEN),
        task_frame::ARRAY_LEN,
        name = task.frame_name(),
    );
    out.push_str("0 reward\n1 terminated\n2 truncated\n3 step\n4 n_obs\n5 n_info\n");
    out.push_str(&format!(
        "{}..{} observation ({n} values)\n",
        task_frame::HEADER_LEN,
        task_frame::HEADER_LEN + n
    ));
    for (name, at, count) in info {
        if count == 1 {
            out.push_str(&format!("{at} info.{name}\n"));
        } else {
            out.push_str(&format!(
                "{at}..{} info.{name} ({count} values)\n",
                at + count
            ));
        }
    }
    Ok(out)
}

/// PX4 mode: the vehicle and sensor parameters, the TCP listener, then PX4 connections until
/// a signal.
fn start_px4(args: Args) -> Result<(), StartError> {
    quadrotor_only(&args, "--px4")?;
    let mut vehicle = vehicle_config(&args)?;
    vehicle.sensors.home_latitude = args.home.latitude_deg;
    vehicle.sensors.home_longitude = args.home.longitude_deg;
    vehicle.sensors.home_altitude = args.home.altitude_m;
    let step_us = (args.px4_step * 1e6).round() as u64;
    let mut session = Session::new(&SessionOptions {
        vehicle,
        step_us,
        seed: args.seed,
    })?;
    session_outputs(
        &args,
        session.vehicle().actuator_count(),
        &mut session.track,
    )?;
    let listener =
        std::net::TcpListener::bind(args.px4_listen).map_err(|source| StartError::Bind {
            link: "PX4",
            addr: args.px4_listen,
            source,
        })?;
    listener.set_nonblocking(true)?;
    let listen = listener.local_addr()?;
    let speed = args.speed_factor;
    let control = control_link(&args)?;
    let ready = format!(
        "flyloop-sitl ready px4={listen} mode=px4 model=quadrotor step_us={step_us} speed_factor={speed} seed={}{}",
        args.seed,
        control_field(control.as_ref())?,
    );
    if let Some(control) = control {
        session.set_control(control);
    }
    let pacing = Pacing {
        speed_factor: speed,
    };
    serve_until_signal(
        |shutdown| {
            let listener = tokio::net::TcpListener::from_std(listener)?;
            Ok(async move {
                let s = px4::server::run(session, listener, pacing, shutdown).await?;
                Ok(format!("{} {}", s.speed.summary(), s.stats))
            })
        },
        || {
            println!("{ready}");
            tracing::info!(%listen, speed_factor = speed, "flyloop-sitl waiting for PX4");
        },
    )
}

/// Fleet mode: the fleet (file or row), its world, a socket per autopilot, then the
/// lockstep until a signal.
fn start_fleet(args: Args) -> Result<(), StartError> {
    use crate::fleet::{self, file};
    let mut spec = match &args.fleet {
        Some(path) => {
            let fleet_err = |source| StartError::FleetFile {
                path: path.clone(),
                source,
            };
            let text = std::fs::read_to_string(path)
                .map_err(|e| fleet_err(file::FleetError(format!("cannot read it: {e}"))))?;
            let dir = path.parent().unwrap_or(std::path::Path::new("."));
            file::parse(&text, dir).map_err(fleet_err)?
        }
        None => {
            let (autopilot, base) = if args.px4 {
                (file::Autopilot::Px4, args.px4_listen)
            } else {
                (file::Autopilot::Ardupilot, args.ardupilot_listen)
            };
            quadrotor_only(&args, if args.px4 { "--px4" } else { "--ardupilot" })?;
            let vehicle = vehicle_config(&args)?;
            file::row(
                autopilot,
                usize::from(args.vehicles),
                base,
                args.spacing,
                &vehicle,
            )?
        }
    };
    for v in &mut spec.vehicles {
        v.vehicle.sensors.home_latitude = args.home.latitude_deg;
        v.vehicle.sensors.home_longitude = args.home.longitude_deg;
        v.vehicle.sensors.home_altitude = args.home.altitude_m;
    }
    let step_us = (args.px4_step * 1e6).round() as u64;
    let mut fleet = fleet::Fleet::new(&spec, args.seed, step_us)?;
    fleet_view_record(&args, &mut fleet.view_record)?;
    let control = control_link(&args)?;
    let control_text = control_field(control.as_ref())?;
    if let Some(control) = control {
        fleet.set_control(control);
    }
    let sockets = fleet::server::bind(&fleet)
        .map_err(|(name, addr, source)| StartError::FleetBind { name, addr, source })?;
    let outputs = fleet_outputs(&args, &fleet)?;
    let ports: Vec<String> = (fleet.members().iter().zip(&sockets))
        .map(|(m, socket)| {
            format!(
                "{}:{}:{}:{}",
                m.name,
                m.autopilot.name(),
                socket.port().unwrap_or(m.listen.port()),
                m.sysid
            )
        })
        .collect();
    let gcs = match args.gcs {
        GcsTarget::Off => None,
        GcsTarget::At(target) => Some(target),
    };
    let speed = args.speed_factor;
    let ready = format!(
        "flyloop-sitl ready mode=fleet vehicles={} members={} speed_factor={speed} seed={}{control_text}",
        fleet.members().len(),
        ports.join(","),
        args.seed
    );
    let options = fleet::server::FleetOptions {
        pacing: Pacing {
            speed_factor: speed,
        },
        timeout: std::time::Duration::from_secs_f64(args.autopilot_timeout),
        gcs,
    };
    let n = fleet.members().len();
    serve_until_signal(
        |shutdown| {
            Ok(async move {
                let (_, summary) =
                    fleet::server::run(fleet, sockets, options, outputs, shutdown).await?;
                Ok(summary)
            })
        },
        || {
            println!("{ready}");
            tracing::info!(
                vehicles = n,
                speed_factor = speed,
                "flyloop-sitl waiting for the fleet's autopilots"
            );
        },
    )
}

/// Runs a mode's server on one thread until a signal. `server` makes its future from the
/// bound sockets inside the runtime; `announce` says the SITL is ready once the sockets and
/// the signal handlers are in place (so an early signal still stops it cleanly). The counters
/// the server returns are logged at the stop.
fn serve_until_signal<F, S>(
    server: impl FnOnce(server::Shutdown) -> std::io::Result<F>,
    announce: impl FnOnce(),
) -> Result<(), StartError>
where
    F: Future<Output = std::io::Result<S>>,
    S: std::fmt::Display,
{
    let runtime = single_thread_runtime()?;
    let stats = runtime.block_on(async move {
        let shutdown = server::Shutdown::install()?;
        let serving = server(shutdown)?;
        announce();
        serving.await
    })?;
    tracing::info!("stopped: {stats}");
    Ok(())
}

/// The tokio runtime every mode's sockets and signals run on.
fn single_thread_runtime() -> std::io::Result<tokio::runtime::Runtime> {
    tokio::runtime::Builder::new_current_thread()
        .enable_all()
        .build()
}

/// The autopilot modes fly the quadrotor only.
fn quadrotor_only(args: &Args, mode_flag: &str) -> Result<(), StartError> {
    if args.model() != ModelKind::Quadrotor {
        return Err(StartError::Options(format!(
            "{mode_flag} flies the quadrotor only"
        )));
    }
    Ok(())
}

/// The ground-truth CSV of the autopilot modes (`--track`), if asked for.
fn track(args: &Args, rotors: usize) -> Result<Option<Track>, StartError> {
    let Some(path) = &args.track else {
        return Ok(None);
    };
    let track = Track::create(path, args.track_interval_us, rotors).map_err(|source| {
        StartError::Track {
            path: path.clone(),
            source,
        }
    })?;
    Ok(Some(track))
}

/// What fleet mode writes beside the flight, as asked for: `--track`.
fn fleet_outputs(
    args: &Args,
    fleet: &crate::fleet::Fleet,
) -> Result<crate::fleet::outputs::Outputs, StartError> {
    let mut outputs = crate::fleet::outputs::Outputs::default();
    if let Some(path) = &args.track {
        let track = crate::fleet::track::FleetTrack::create(path, args.track_interval_us, fleet)
            .map_err(|source| StartError::Track {
                path: path.clone(),
                source,
            })?;
        outputs.track = Some(track);
    }
    Ok(outputs)
}

/// What an autopilot session writes beside the flight, as asked for: `--track`, `--view`,
/// `--record`.
fn session_outputs(
    args: &Args,
    rotors: usize,
    outputs: &mut crate::track::SessionTrack,
) -> Result<(), StartError> {
    if let Some(track) = track(args, rotors)? {
        outputs.set(track);
    }
    if let Some(view) = view_stream(args)? {
        outputs.set_view(view);
    }
    if let Some(recorder) = autopilot_recording(args)? {
        outputs.set_recording(recorder);
    }
    Ok(())
}

/// The fleet's live view stream and recording, as asked for: `--view`, `--record`.
fn fleet_view_record(
    args: &Args,
    outputs: &mut crate::fleet::view_record::ViewRecord,
) -> Result<(), StartError> {
    if let Some(view) = view_stream(args)? {
        outputs.set_view(view);
    }
    if let Some(recorder) = autopilot_recording(args)? {
        outputs.set_recording(recorder);
    }
    Ok(())
}

/// The recording of the autopilot modes and the fleet (`--record`), if asked for.
fn autopilot_recording(
    args: &Args,
) -> Result<Option<crate::autopilot_record::AutopilotRecorder>, StartError> {
    let Some(path) = &args.record else {
        return Ok(None);
    };
    let recorder =
        crate::autopilot_record::AutopilotRecorder::create(path, args.home).map_err(|source| {
            StartError::Record {
                path: path.clone(),
                source,
            }
        })?;
    Ok(Some(recorder))
}

/// The live view's stream of the autopilot modes (`--view`), if asked for.
fn view_stream(args: &Args) -> Result<Option<crate::view_stream::ViewStream>, StartError> {
    let Some(target) = args.view else {
        return Ok(None);
    };
    let stream = crate::view_stream::ViewStream::new(target, args.home)
        .map_err(|source| StartError::View { target, source })?;
    Ok(Some(stream))
}

/// The autopilot modes' control link (`--control`), if asked for.
fn control_link(args: &Args) -> Result<Option<ControlLink>, StartError> {
    let Some(addr) = args.control else {
        return Ok(None);
    };
    let socket = bind("control", addr)?;
    Ok(Some(ControlLink::new(socket)?))
}

/// ` control=HOST:PORT` for the ready line (empty without a control link).
fn control_field(control: Option<&ControlLink>) -> Result<String, StartError> {
    Ok(match control {
        Some(c) => format!(" control={}", c.local_addr()?),
        None => String::new(),
    })
}

/// The vehicle of the autopilot modes: `--config`, else the Iris preset.
fn vehicle_config(args: &Args) -> Result<AutopilotVehicle, StartError> {
    Ok(match &args.config {
        Some(path) => config::load_autopilot_vehicle(path)?,
        None => AutopilotVehicle::iris(),
    })
}

/// ArduPilot mode: the vehicle, the UDP socket, then ArduPilot's frames until a signal.
fn start_ardupilot(args: Args) -> Result<(), StartError> {
    quadrotor_only(&args, "--ardupilot")?;
    let vehicle = vehicle_config(&args)?;
    let mut session = ardupilot::session::Session::new(&ardupilot::session::SessionOptions {
        vehicle,
        seed: args.seed,
    })?;
    session_outputs(
        &args,
        session.vehicle().actuator_count(),
        &mut session.track,
    )?;
    let socket =
        std::net::UdpSocket::bind(args.ardupilot_listen).map_err(|source| StartError::Bind {
            link: "ArduPilot",
            addr: args.ardupilot_listen,
            source,
        })?;
    let listen = socket.local_addr()?;
    let speed = args.speed_factor;
    let control = control_link(&args)?;
    let ready = format!(
        "flyloop-sitl ready ardupilot={listen} mode=ardupilot model=quadrotor speed_factor={speed} seed={}{}",
        args.seed,
        control_field(control.as_ref())?,
    );
    if let Some(control) = control {
        session.set_control(control);
    }
    let pacing = Pacing {
        speed_factor: speed,
    };
    serve_until_signal(
        |shutdown| {
            let serving = ardupilot::server::run(session, socket, pacing, shutdown);
            Ok(async move {
                let s = serving.await?;
                Ok(format!("{} {}", s.speed.summary(), s.stats))
            })
        },
        || {
            println!("{ready}");
            tracing::info!(%listen, speed_factor = speed, "flyloop-sitl waiting for ArduPilot");
        },
    )
}

fn start(args: Args) -> Result<(), StartError> {
    let fleet = args.fleet.is_some() || ((args.px4 || args.ardupilot) && args.vehicles > 1);
    if let Some(autopilot) = args.print_autopilot_params {
        let vehicle = vehicle_config(&args)?;
        let text = match autopilot {
            Autopilot::Px4 => autopilot_params::px4(&vehicle.frame, &vehicle.quadrotor),
            Autopilot::Ardupilot => {
                autopilot_params::ardupilot(&vehicle.frame).map_err(StartError::Options)?
            }
        };
        print!("{text}");
        return Ok(());
    }
    if fleet {
        return start_fleet(args);
    }
    if args.px4 {
        return start_px4(args);
    }
    if args.ardupilot {
        return start_ardupilot(args);
    }
    if let Some(scenario) = args.world_task() {
        return start_world(args, scenario);
    }
    let task = args.task().map_err(StartError::Options)?;
    let config = match &args.config {
        Some(path) => config::load(task, path)?,
        None => TaskConfig::default(),
    };
    if let Some(text) = printout(&args, task, &config)? {
        print!("{text}");
        return Ok(());
    }
    start_mavlink(args, task, config, None)
}

/// What `--list-params` or `--describe-frame` prints instead of running, if asked for.
fn printout(
    args: &Args,
    task: TaskKind,
    config: &TaskConfig,
) -> Result<Option<String>, StartError> {
    Ok(match args.list_params {
        Some(ListFormat::Table) => Some(param_table::listing(task, config)),
        Some(ListFormat::Toml) => Some(starter_config::starter_toml(task, config)),
        None if args.describe_frame => Some(describe_frame(task, config)?),
        None => None,
    })
}

/// A multi-agent task as one world of `--vehicles` quadrotors on the lockstep MAVLink link
/// (docs/protocol.md section 14).
fn start_world(args: Args, scenario: Scenario) -> Result<(), StartError> {
    if let Some(option) = args.not_for_a_world() {
        return Err(StartError::Options(format!(
            "{option} is not available for the multi-agent task `{}` (a lockstep world; docs/protocol.md section 14)",
            scenario.name()
        )));
    }
    let config = config::load_world(args.config.as_deref(), args.vehicles)?;
    let world = WorldTask::new(scenario, config, args.seed).map_err(|e| match e {
        MultiError::Param(p) => StartError::Parameters(p),
        other => StartError::Options(other.to_string()),
    })?;
    start_mavlink(args, TaskKind::Hover, TaskConfig::default(), Some(world))
}

/// The MAVLink SITL (lockstep or real time): the vehicles (or the multi-agent `world`), the
/// sockets, then datagrams until a signal.
fn start_mavlink(
    args: Args,
    task: TaskKind,
    config: TaskConfig,
    world: Option<WorldTask>,
) -> Result<(), StartError> {
    if args.control.is_some() {
        return Err(StartError::Options(
            "--control is for the PX4 and ArduPilot modes: the MAVLink task mode takes MAV_CMD_INJECT_FAILURE on its --listen link (control= in the ready line)".to_string(),
        ));
    }
    let task_name = match &world {
        Some(w) => w.flight.scenario().name(),
        None => task.frame_name(),
    };
    let mut options = SimOptions::new(task);
    options.vehicles = args.vehicles;
    options.seed = args.seed;
    options.config = config;
    options.mode = args.mode();
    options.home = args.home;
    options.state_in_reply = !args.no_state_reply;
    options.failsafe_timeout = args.failsafe_timeout();
    options.state_rate_hz = args.state_rate;
    let mut sim = match world {
        Some(w) => Sim::new_world(options, w, Instant::now())?,
        None => Sim::new(options, Instant::now())?,
    };
    if let Some(path) = &args.record {
        let recorder =
            crate::record::Recorder::create(path).map_err(|source| StartError::Record {
                path: path.clone(),
                source,
            })?;
        sim.recorder = Some(recorder);
    }

    let controller = bind("controller", args.listen)?;
    let gcs = match args.gcs {
        GcsTarget::Off => None,
        GcsTarget::At(target) => Some((bind("ground-station", args.gcs_bind)?, target)),
    };
    let listen = controller.local_addr()?;
    let gcs_text = match &gcs {
        Some((socket, target)) => format!("{}->{}", socket.local_addr()?, target),
        None => "off".to_string(),
    };
    let ready = format!(
        "flyloop-sitl ready listen={listen} gcs={gcs_text} mode={} model={} task={} vehicles={} seed={} control={listen}",
        args.mode().name(),
        args.model().name(),
        task_name,
        args.vehicles,
        args.seed
    );

    serve_until_signal(
        |shutdown| {
            let controller = tokio::net::UdpSocket::from_std(controller)?;
            let gcs = match gcs {
                Some((socket, target)) => Some(GcsLink {
                    socket: tokio::net::UdpSocket::from_std(socket)?,
                    target,
                }),
                None => None,
            };
            Ok(server::run(sim, controller, gcs, shutdown))
        },
        || {
            println!("{ready}");
            tracing::info!(%listen, gcs = %gcs_text, "flyloop-sitl running");
        },
    )
}

/// Runs the SITL with command-line `args` (the program name first) until SIGINT / SIGTERM;
/// returns the process exit code (0, 1 on a start error, 2 on bad options).
pub fn main_with_args<I, T>(args: I) -> u8
where
    I: IntoIterator<Item = T>,
    T: Into<std::ffi::OsString> + Clone,
{
    let args = match Args::try_parse_from(args) {
        Ok(args) => args,
        Err(e) => {
            // --help and --version print and succeed; bad options print and exit 2.
            let _ = e.print();
            return u8::try_from(e.exit_code()).unwrap_or(2);
        }
    };
    // try_init: a host process (the Python extension) may have installed one already.
    let _ = tracing_subscriber::fmt()
        .with_writer(std::io::stderr)
        .with_max_level(args.log_level)
        .with_target(false)
        .with_ansi(std::io::stderr().is_terminal())
        .try_init();
    match start(args) {
        Ok(()) => 0,
        Err(e) => {
            eprintln!("flyloop-sitl: error: {e}");
            1
        }
    }
}
