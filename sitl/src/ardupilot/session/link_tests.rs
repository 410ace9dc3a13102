//! Issue 35: link faults on ArduPilot's JSON link. ArduPilot's clock follows the JSON
//! timestamps and it blocks until a frame comes, so every servo frame is still answered:
//! on a lost link with the last JSON frame that got through (its clock stands still, its
//! servo frames are dropped), on a delayed one with the frame of `delay` ago.

use super::tests::{addr, field, servo};
use super::*;

fn faulty_session(faults: &str) -> Session {
    let text = format!("{}\n{faults}", crate::config::IRIS_PRESET);
    Session::new(&SessionOptions {
        vehicle: AutopilotVehicle::parse(&text).unwrap(),
        seed: 1,
    })
    .unwrap()
}

/// The reply to each frame `counts` at `pwm`.
fn fly(s: &mut Session, counts: std::ops::Range<u32>, pwm: u16) -> Vec<Vec<u8>> {
    let ap = addr(40000);
    counts
        .map(|k| {
            assert_eq!(s.receive(&servo(k, pwm), ap), Outcome::Stepped);
            s.reply().to_vec()
        })
        .collect()
}

#[test]
fn a_link_loss_answers_with_the_last_frame_and_drops_the_servo_frames() {
    let mut s = faulty_session("[[faults]]\nkind = \"link_loss\"\nat = 0.5\nduration = 0.25");
    // Frame k steps from k·833 µs: frame 601 (from 0.500633 s) is the first lost, and the
    // loss ends 0.25 s after it fired: frame 902 (from 0.751366 s) is the first through.
    let before = fly(&mut s, 0..601, 1500);
    assert_eq!(field(&before[600], "timestamp"), vec![0.500633]);
    let lost = fly(&mut s, 601..902, 1900);
    assert!(
        lost.iter().all(|r| *r == before[600]),
        "the last frame again"
    );
    let held = vec![packet::motor_command(1500); 4];
    assert_eq!(
        s.vehicle().actuators(),
        held,
        "the 1900 µs frames never arrived"
    );
    assert_eq!(s.time_us(), 902 * 833, "the world went on");
    assert_eq!(s.stats.link_dropped, 301);
    let after = fly(&mut s, 902..903, 1900);
    assert_eq!(field(&after[0], "timestamp"), vec![0.752199]);
    assert_eq!(
        s.vehicle().actuators(),
        vec![packet::motor_command(1900); 4]
    );
}

#[test]
fn a_link_delay_answers_with_the_frame_of_delay_ago() {
    let mut delayed =
        faulty_session("[[faults]]\nkind = \"link_delay\"\ndelay = 0.05\nat = 0.5\nduration = 1");
    let mut healthy = faulty_session("");
    let a = fly(&mut delayed, 0..1500, 1550);
    let b = fly(&mut healthy, 0..1500, 1550);
    assert_eq!(a[..601], b[..601]);
    // The delay fires with frame 601 (at 0.500633 s): from then on the frame made at least
    // 0.05 s ago (60.02 frames of 833 µs: 61 frames), and until one is that old frame 600's again. It
    // clears 1 s after it fired, past these frames.
    for (k, reply) in a.iter().enumerate().skip(601) {
        let source = if k < 662 { 600 } else { k - 61 };
        assert_eq!(*reply, b[source], "frame {k}");
    }
}
