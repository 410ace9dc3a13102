//! Regression: a paced fleet (`--speed-factor 1`) whose first PX4 is starting up (free
//! clock, no controls yet) stayed inside its free steps forever — the pacer's sleep ends at
//! the next free step's time or after it — and never heard a second PX4 connect, nor a
//! stop. The real binary, PX4 ports on port 0 (each member an ephemeral port of its own),
//! plain TCP clients in the PX4s' place.

use crate::lockstep_over_udp::spawn_ready;
use std::io::Read;
use std::net::TcpStream;
use std::process::{Child, Command};
use std::time::{Duration, Instant};

pub(crate) struct Fleet {
    pub(crate) child: Child,
    pub(crate) ports: Vec<u16>,
}

/// A failing test must not leave the SITL running.
impl Drop for Fleet {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

fn start_fleet(vehicles: &str, speed: &str) -> Fleet {
    start_fleet_with(vehicles, speed, &[], &[])
}

/// A PX4 fleet of `vehicles` on ephemeral ports, with more arguments and environment.
pub(crate) fn start_fleet_with(
    vehicles: &str,
    speed: &str,
    more: &[&str],
    env: &[(&str, &str)],
) -> Fleet {
    let mut command = Command::new(env!("CARGO_BIN_EXE_flyloop-sitl"));
    command.envs(env.iter().copied());
    command
        .args([
            "--px4",
            "--vehicles",
            vehicles,
            "--px4-listen",
            "127.0.0.1:0",
        ])
        .args([
            "--speed-factor",
            speed,
            "--gcs",
            "off",
            "--log-level",
            "warn",
        ])
        .args(more);
    let (child, line) = spawn_ready(&mut command);
    assert!(line.starts_with("flyloop-sitl ready mode=fleet"), "{line}");
    // members=px4-000:px4:PORT:SYSID,...
    let members = line.split("members=").nth(1).unwrap();
    let members = members.split_whitespace().next().unwrap();
    let ports = (members.split(','))
        .map(|m| m.split(':').nth(2).unwrap().parse().unwrap())
        .collect();
    Fleet { child, ports }
}

/// Bytes the fleet writes to `stream` within `within`.
fn bytes_within(stream: &mut TcpStream, within: Duration) -> usize {
    stream.set_read_timeout(Some(within)).unwrap();
    let mut buf = [0u8; 4096];
    stream.read(&mut buf).unwrap_or(0)
}

#[test]
fn fleet_members_on_port_zero_each_get_an_ephemeral_port_and_a_sysid() {
    let fleet = start_fleet("3", "0");
    assert_eq!(fleet.ports.len(), 3);
    assert!(fleet.ports.iter().all(|&p| p >= 1024), "{:?}", fleet.ports);
    let mut distinct = fleet.ports.clone();
    distinct.dedup();
    assert_eq!(distinct.len(), 3, "{:?}", fleet.ports);
}

#[test]
fn a_paced_fleet_hears_a_second_px4_and_a_stop_while_the_first_starts_up() {
    let mut fleet = start_fleet("2", "1");
    // Idle, the fleet thread looks at its clock every 100 ms; a connection more than one
    // free step (4 ms) after such a look is what started the endless free steps.
    std::thread::sleep(Duration::from_millis(250));
    let mut first = TcpStream::connect(("127.0.0.1", fleet.ports[0])).unwrap();
    // The free clock runs: the first PX4 gets its sensors without answering.
    assert!(bytes_within(&mut first, Duration::from_secs(2)) > 0);
    std::thread::sleep(Duration::from_millis(300));
    let mut second = TcpStream::connect(("127.0.0.1", fleet.ports[1])).unwrap();
    assert!(
        bytes_within(&mut second, Duration::from_secs(3)) > 0,
        "the second PX4 got no sensors: its connection was not heard"
    );
    let status = Command::new("kill")
        .args(["-TERM", &fleet.child.id().to_string()])
        .status()
        .unwrap();
    assert!(status.success());
    let asked = Instant::now();
    while fleet.child.try_wait().unwrap().is_none() {
        assert!(
            asked.elapsed() < Duration::from_secs(5),
            "SIGTERM not heard within 5 s"
        );
        std::thread::sleep(Duration::from_millis(20));
    }
    assert!(fleet.child.wait().unwrap().success());
}
