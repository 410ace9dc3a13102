//! The fleet thread sleeps until every PX4 the world waits for has answered (one io_uring
//! wait, `fleet/uring.rs`, where the kernel allows it; epoll where not) and writes a step's
//! sensors to all PX4s at once. Pinned here over real TCP with plain clients in the PX4s'
//! place: a step needs every answer, all get the next sensors, and a PX4 that hangs up
//! while the world waits for it frees the others at once (its pending wait taken back),
//! not after the autopilot timeout; a PX4 that comes back on the port flies again. Each
//! twice: with io_uring, and with it off (`FLYLOOP_IO_URING=off`, the fleet as where the
//! kernel refuses io_uring).

use crate::fleet_paced_start::start_fleet_with;
use flyloop_sitl::fleet::uring::OFF;
use flyloop_sitl::wire::{Encoder, StreamDecoder};
use mavlink::dialects::common::{HIL_ACTUATOR_CONTROLS_DATA, HilActuatorControlsFlags, MavMessage};
use std::io::{ErrorKind, Read, Write};
use std::net::TcpStream;
use std::time::{Duration, Instant};

/// A plain TCP client in a PX4's place.
struct FakePx4 {
    stream: TcpStream,
    decoder: StreamDecoder,
    encoder: Encoder,
    /// Time of the newest HIL_SENSOR read.
    last_sensor_us: Option<u64>,
}

impl FakePx4 {
    fn connect(port: u16) -> FakePx4 {
        let stream = TcpStream::connect(("127.0.0.1", port)).unwrap();
        stream.set_nodelay(true).unwrap();
        FakePx4 {
            stream,
            decoder: StreamDecoder::default(),
            encoder: Encoder::default(),
            last_sensor_us: None,
        }
    }

    /// HIL_SENSORs read within `within` (stops at the first quiet 50 ms after one came).
    fn sensors_within(&mut self, within: Duration) -> usize {
        let end = Instant::now() + within;
        let mut count = 0;
        let mut buf = [0u8; 4096];
        loop {
            let now = Instant::now();
            if now >= end {
                return count;
            }
            let wait = if count > 0 {
                Duration::from_millis(50)
            } else {
                end - now
            };
            self.stream.set_read_timeout(Some(wait)).unwrap();
            match self.stream.read(&mut buf) {
                Ok(0) => return count,
                Ok(n) => self.decoder.push(&buf[..n]),
                Err(e) if matches!(e.kind(), ErrorKind::WouldBlock | ErrorKind::TimedOut) => {
                    if count > 0 {
                        return count;
                    }
                }
                Err(e) => panic!("read: {e}"),
            }
            while let Some(frame) = self.decoder.next_frame() {
                if let Ok(incoming) = frame {
                    if let MavMessage::HIL_SENSOR(s) = incoming.message {
                        self.last_sensor_us = Some(s.time_usec);
                        count += 1;
                    }
                }
            }
        }
    }

    /// Lockstep controls answering the newest HIL_SENSOR.
    fn answer(&mut self) {
        let controls = MavMessage::HIL_ACTUATOR_CONTROLS(HIL_ACTUATOR_CONTROLS_DATA {
            time_usec: self.last_sensor_us.expect("no sensors to answer"),
            flags: HilActuatorControlsFlags::HIL_ACTUATOR_CONTROLS_FLAGS_LOCKSTEP,
            ..Default::default()
        });
        let mut out = Vec::new();
        self.encoder.push(&mut out, 1, &controls);
        self.stream.write_all(&out).unwrap();
    }

    /// One lockstep step: answer, then the next sensors within `within`.
    fn step(&mut self, within: Duration) -> usize {
        self.answer();
        self.sensors_within(within)
    }
}

/// Two fake PX4s on ports 0 and 1 of a fleet, answered into lockstep.
fn both_in_lockstep(ports: &[u16]) -> (FakePx4, FakePx4) {
    let mut a = FakePx4::connect(ports[0]);
    let mut b = FakePx4::connect(ports[1]);
    // Free clock until both answer: both get sensors without answering.
    assert!(a.sensors_within(Duration::from_secs(3)) > 0);
    assert!(b.sensors_within(Duration::from_secs(3)) > 0);
    in_step(&mut a, &mut b, "start");
    (a, b)
}

/// Both answer the newest sensors they have until one step's sensors come only after both
/// answered (answers to older sensors are stale, not steps).
fn in_step(a: &mut FakePx4, b: &mut FakePx4, when: &str) {
    let start = Instant::now();
    loop {
        assert!(
            start.elapsed() < Duration::from_secs(10),
            "{when}: never in step"
        );
        a.answer();
        b.answer();
        let (na, nb) = (
            a.sensors_within(Duration::from_secs(2)),
            b.sensors_within(Duration::from_secs(2)),
        );
        if (na, nb) == (1, 1) {
            return;
        }
    }
}

/// With io_uring where the kernel has it, and as without it.
const MODES: [&[(&str, &str)]; 2] = [&[], &[OFF]];

#[test]
fn a_step_waits_for_every_px4_and_a_px4_that_hangs_up_frees_the_others_at_once() {
    for env in MODES {
        step_waits_for_every_px4(env);
    }
}

fn step_waits_for_every_px4(env: &[(&str, &str)]) {
    // A timeout far longer than any wait below: a wait that long would be the timeout's.
    let fleet = start_fleet_with("2", "0", &["--autopilot-timeout", "30"], env);
    let (mut a, mut b) = both_in_lockstep(&fleet.ports);
    for step in 0..8 {
        // A alone: the world waits for B.
        a.answer();
        let early = a.sensors_within(Duration::from_millis(300));
        assert_eq!(early, 0, "step {step}: a step without B's answer");
        // B too: both get the next step's sensors (one HIL_SENSOR each).
        let before = a.last_sensor_us;
        assert_eq!(b.step(Duration::from_secs(2)), 1, "step {step}: B");
        assert_eq!(
            a.sensors_within(Duration::from_secs(2)),
            1,
            "step {step}: A"
        );
        assert!(
            a.last_sensor_us > before,
            "step {step}: time did not advance"
        );
        assert_eq!(a.last_sensor_us, b.last_sensor_us, "step {step}");
    }
    // A answers, and B hangs up while the world waits for it.
    a.answer();
    let hung_up = Instant::now();
    drop(b);
    assert_eq!(
        a.sensors_within(Duration::from_secs(5)),
        1,
        "the world still waited for the PX4 that hung up"
    );
    assert!(hung_up.elapsed() < Duration::from_secs(5));
    // A flies on alone, and a PX4 that comes back on B's port gets sensors again.
    for step in 0..5 {
        assert_eq!(a.step(Duration::from_secs(2)), 1, "A alone, step {step}");
    }
    let mut back = FakePx4::connect(fleet.ports[1]);
    a.answer();
    assert!(
        back.sensors_within(Duration::from_secs(3)) > 0,
        "the PX4 that came back got no sensors"
    );
}

#[test]
fn a_px4_silenced_while_the_world_waited_for_it_rejoins_with_its_late_answer() {
    for env in MODES {
        silenced_px4_rejoins(env);
    }
}

fn silenced_px4_rejoins(env: &[(&str, &str)]) {
    let fleet = start_fleet_with("2", "0", &["--autopilot-timeout", "0.3"], env);
    let (mut a, mut b) = both_in_lockstep(&fleet.ports);
    for round in 0..3 {
        // B keeps the world waiting past the timeout: silenced, A flies on without it.
        a.answer();
        std::thread::sleep(Duration::from_millis(600));
        assert!(
            a.sensors_within(Duration::from_secs(2)) >= 1,
            "round {round}: A stopped"
        );
        for _ in 0..3 {
            assert_eq!(a.step(Duration::from_secs(2)), 1, "round {round}: A alone");
        }
        // B's late answer is read: B is back in lockstep and gets sensors again.
        b.answer();
        assert!(
            b.sensors_within(Duration::from_secs(3)) >= 1,
            "round {round}: B's late answer was not heard"
        );
        a.answer();
        a.sensors_within(Duration::from_millis(300));
        in_step(&mut a, &mut b, &format!("round {round}"));
    }
}

#[test]
fn a_silenced_px4_is_sent_sensors_again_until_it_answers() {
    // Regression: a silenced PX4 was sent nothing until it answered, and a PX4 silenced under
    // load that was itself waiting for sensors never answered ("poll timeout" for good).
    for env in MODES {
        silenced_px4_is_reminded(env);
    }
}

fn silenced_px4_is_reminded(env: &[(&str, &str)]) {
    let fleet = start_fleet_with("2", "0", &["--autopilot-timeout", "0.3"], env);
    let (mut a, mut b) = both_in_lockstep(&fleet.ports);
    // B has read its sensors and does not answer: silenced; A flies on without it.
    let unanswered = b.last_sensor_us;
    a.answer();
    std::thread::sleep(Duration::from_millis(600));
    assert!(a.sensors_within(Duration::from_secs(2)) >= 1, "A stopped");
    for _ in 0..20 {
        assert_eq!(a.step(Duration::from_secs(2)), 1, "A alone");
    }
    // B gets sensors again, at the world's time (A's steps), though it never answered.
    assert!(
        b.sensors_within(Duration::from_secs(2)) >= 1,
        "a silent PX4 was sent nothing"
    );
    assert!(
        b.last_sensor_us > unanswered,
        "the reminder is not at the world's time"
    );
    // Its answer to them puts it back in lockstep.
    b.answer();
    a.answer();
    in_step(&mut a, &mut b, "after the reminder");
}
