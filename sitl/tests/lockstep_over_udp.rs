//! The real binary on an ephemeral port, a Rust MAVLink client over loopback UDP: every
//! lockstep reply matches the core's Hover task stepped directly in this test, and SIGTERM
//! stops the SITL cleanly.
// Test code: a failed unwrap is a failed test.

use flyloop_core::quadrotor::QuadrotorParams;
use flyloop_core::tasks::flight::FlightParams;
use flyloop_core::tasks::hover::Hover;
use flyloop_core::tasks::{StepOutcome, Task};
use flyloop_sitl::commands::seed_params;
use flyloop_sitl::kinematics::{Home, attitude_ned};
use flyloop_sitl::wire::{Encoder, frames};
use mavlink::dialects::common::{
    COMMAND_LONG_DATA, HIL_ACTUATOR_CONTROLS_DATA, HilActuatorControlsFlags, MavCmd, MavMessage,
};
use nalgebra::Vector3;
use std::io::{BufRead, BufReader};
use std::net::{SocketAddr, UdpSocket};
use std::process::{Child, Command, Stdio};
use std::time::Duration;

pub(crate) struct Sitl {
    child: Child,
    addr: SocketAddr,
}

/// A failing test must not leave the SITL running.
impl Drop for Sitl {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

/// The SITL started by `command` (stdout piped) and its first stdout line, the ready line.
pub(crate) fn spawn_ready(command: &mut Command) -> (Child, String) {
    let mut child = command.stdout(Stdio::piped()).spawn().unwrap();
    let mut line = String::new();
    BufReader::new(child.stdout.take().unwrap())
        .read_line(&mut line)
        .unwrap();
    (child, line)
}

impl Sitl {
    pub(crate) fn start(args: &[&str]) -> Sitl {
        let mut command = Command::new(env!("CARGO_BIN_EXE_flyloop-sitl"));
        command
            .args([
                "--listen",
                "127.0.0.1:0",
                "--gcs",
                "off",
                "--log-level",
                "warn",
            ])
            .args(args);
        let (child, line) = spawn_ready(&mut command);
        assert!(line.starts_with("flyloop-sitl ready listen="), "{line}");
        let addr = line
            .split("listen=")
            .nth(1)
            .unwrap()
            .split_whitespace()
            .next()
            .unwrap();
        Sitl {
            child,
            addr: addr.parse().unwrap(),
        }
    }

    /// SIGTERM, then the exit status must be success.
    pub(crate) fn stop(&mut self) {
        let status = Command::new("kill")
            .args(["-TERM", &self.child.id().to_string()])
            .status()
            .unwrap();
        assert!(status.success());
        assert!(self.child.wait().unwrap().success());
    }
}

pub(crate) struct Client {
    socket: UdpSocket,
    encoder: Encoder,
}

impl Client {
    pub(crate) fn new(sitl: &Sitl) -> Client {
        let socket = UdpSocket::bind("127.0.0.1:0").unwrap();
        socket
            .set_read_timeout(Some(Duration::from_secs(5)))
            .unwrap();
        socket.connect(sitl.addr).unwrap();
        Client {
            socket,
            encoder: Encoder::default(),
        }
    }

    pub(crate) fn exchange(
        &mut self,
        from_system: u8,
        messages: &[MavMessage],
    ) -> Vec<(u8, MavMessage)> {
        let mut out = Vec::new();
        for m in messages {
            self.encoder.push(&mut out, from_system, m);
        }
        self.socket.send(&out).unwrap();
        let mut buf = vec![0u8; 65_536];
        let n = self.socket.recv(&mut buf).unwrap();
        frames(&buf[..n])
            .map(|f| {
                let f = f.unwrap();
                (f.header.system_id, f.message)
            })
            .collect()
    }
}

pub(crate) fn controls(action: [f32; 4]) -> MavMessage {
    let mut c = [0.0; 16];
    c[..4].copy_from_slice(&action);
    MavMessage::HIL_ACTUATOR_CONTROLS(HIL_ACTUATOR_CONTROLS_DATA {
        controls: c,
        flags: HilActuatorControlsFlags::HIL_ACTUATOR_CONTROLS_FLAGS_LOCKSTEP,
        ..Default::default()
    })
}

fn reset(seed: u64) -> MavMessage {
    let [p1, p2, p3, p4] = seed_params(seed);
    MavMessage::COMMAND_LONG(COMMAND_LONG_DATA {
        param1: p1,
        param2: p2,
        param3: p3,
        param4: p4,
        command: MavCmd::MAV_CMD_USER_1,
        target_system: 1,
        target_component: 1,
        ..Default::default()
    })
}

/// The frame header of a step: reward, terminated, truncated, step.
fn head(outcome: StepOutcome, step: u64) -> [f32; 4] {
    let flag = |b: bool| if b { 1.0 } else { 0.0 };
    [
        outcome.reward as f32,
        flag(outcome.terminated),
        flag(outcome.truncated),
        step as f32,
    ]
}

/// The expected reply for `hover` at simulation time `time_usec` (conversions spelled out here).
fn check_reply(reply: &[(u8, MavMessage)], hover: &Hover, time_usec: u64, head: [f32; 4]) {
    let [
        (1, MavMessage::HIL_STATE_QUATERNION(s)),
        (1, MavMessage::DEBUG_FLOAT_ARRAY(f)),
    ] = reply
    else {
        panic!("unexpected reply {reply:?}");
    };
    let quad = hover.air_vehicle();
    let b = quad.body();
    assert_eq!(s.time_usec, time_usec);
    let q = attitude_ned(&quad.attitude());
    assert_eq!(
        s.attitude_quaternion,
        [q.w as f32, q.i as f32, q.j as f32, q.k as f32]
    );
    assert_eq!(
        [s.rollspeed, s.pitchspeed, s.yawspeed],
        [
            b.body_rates.x as f32,
            -b.body_rates.y as f32,
            -b.body_rates.z as f32
        ]
    );
    let g = Home::default().global(&b.position);
    assert_eq!((s.lat, s.lon, s.alt), (g.lat, g.lon, g.alt_mm));
    let v = Vector3::new(b.velocity.y, b.velocity.x, -b.velocity.z) * 100.0;
    assert_eq!(
        (s.vx, s.vy, s.vz),
        (v.x.round() as i16, v.y.round() as i16, v.z.round() as i16)
    );

    assert_eq!(f.time_usec, time_usec);
    assert_eq!(f.array_id, 1);
    assert_eq!(f.name.to_str().unwrap(), "hover");
    assert_eq!(&f.data[..4], &head);
    assert_eq!(&f.data[4..6], &[33.0, 12.0]);
    assert_eq!(&f.data[6..39], hover.observation().as_slice());
    let p = b.position;
    assert_eq!(&f.data[40..43], &[p.x as f32, p.y as f32, p.z as f32]);
}

#[test]
fn lockstep_replies_match_the_core_stepped_directly_and_sigterm_stops_cleanly() {
    let mut sitl = Sitl::start(&["--seed", "99"]);
    let mut client = Client::new(&sitl);
    let mut hover = Hover::new(QuadrotorParams::default(), FlightParams::default()).unwrap();

    hover.reset(99);
    let reply = client.exchange(1, &[controls([0.5; 4])]);
    let outcome = hover.step(&[0.5; 4]).unwrap();
    check_reply(&reply, &hover, 10_000, head(outcome, 1));

    let reply = client.exchange(255, &[reset(123_456_789_012)]);
    assert!(matches!(reply[0], (1, MavMessage::COMMAND_ACK(_))));
    hover.reset(123_456_789_012);
    check_reply(&reply[1..], &hover, 10_000, [0.0; 4]);
    let mut terminated_at = None;
    for k in 1..=200u64 {
        let x = 0.02 * ((k as f32) / 9.0).sin();
        let action = [0.5 + x, 0.5 - x, 0.495, 0.505 + x / 2.0];
        let reply = client.exchange(1, &[controls(action)]);
        let outcome = hover.step(&action.map(f64::from)).unwrap();
        check_reply(&reply, &hover, 10_000 * (k + 1), head(outcome, k));
        if outcome.terminated && terminated_at.is_none() {
            terminated_at = Some(k);
        }
    }
    // The open-loop wobble ends the episode; stepping on continues it, as documented.
    assert!(terminated_at.is_some_and(|k| k < 200), "{terminated_at:?}");
    sitl.stop();
}
