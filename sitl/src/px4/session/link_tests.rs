//! Issue 35: link faults on PX4's TCP link. A stream loses no single message, and PX4's
//! lockstep clock is the HIL_SENSOR it is sent (its rate loop, and so its next controls,
//! runs on a new gyro sample), so a loss keeps the tick and loses the data: every step
//! still gets a HIL_SENSOR stamped now, carrying the last IMU sample delivered again and no
//! mag or baro field, no HIL_GPS, and PX4's controls are dropped; a delay sends the values
//! sampled `delay` ago.

use super::faults_tests::faulty_session;
use super::tests::{controls, messages, session};
use super::*;
use mavlink::dialects::common::HIL_SENSOR_DATA;

/// `steps` lockstep steps at motor command `value`; the HIL_SENSORs and the HIL_GPS count.
fn fly(s: &mut Session, steps: usize, value: f32) -> (Vec<HIL_SENSOR_DATA>, usize) {
    let mut out = Vec::new();
    for _ in 0..steps {
        s.receive(&controls(value), &mut out);
    }
    let sent = messages(&out);
    let sensors = (sent.iter())
        .filter_map(|m| match m {
            MavMessage::HIL_SENSOR(h) => Some(h.clone()),
            _ => None,
        })
        .collect();
    let gps = (sent.iter())
        .filter(|m| matches!(m, MavMessage::HIL_GPS(_)))
        .count();
    (sensors, gps)
}

#[test]
fn a_link_loss_keeps_px4s_tick_but_sends_no_data_and_drops_its_controls() {
    let mut s = faulty_session("[[faults]]\nkind = \"link_loss\"\nat = 0.5\nduration = 0.4");
    let mut out = Vec::new();
    s.connect(1_000_000, &mut out);
    // 0.008 … 0.496 s at 0.3: the link is healthy.
    let (before, gps) = fly(&mut s, 123, 0.3);
    assert!(before.iter().all(|h| h.fields_updated.bits() > 0b11_1111) && gps > 0);
    // The controls of the step starting at 0.496 s get through; the loss fires at the step
    // starting at 0.5 s (its controls are dropped) and clears at 0.9 s.
    let (mut lost, _) = fly(&mut s, 1, 0.3);
    let (rest, gps) = fly(&mut s, 99, 0.9);
    lost.extend(rest);
    let times: Vec<u64> = lost.iter().map(|h| h.time_usec).collect();
    assert_eq!(
        times,
        (0..100).map(|k| 500_000 + 4000 * k).collect::<Vec<_>>(),
        "one HIL_SENSOR per step, stamped now: PX4's clock goes on"
    );
    // The IMU fields only, with the last sample delivered (the one of 0.5 s) again.
    assert!(
        lost[1..]
            .iter()
            .all(|h| h.fields_updated.bits() == 0b11_1111)
    );
    assert!(
        lost[1..]
            .iter()
            .all(|h| (h.xacc, h.zgyro) == (lost[0].xacc, lost[0].zgyro))
    );
    assert_eq!(gps, 0, "no HIL_GPS while the link is lost");
    assert_eq!(
        s.vehicle().actuators(),
        [0.3f32 as f64; 4],
        "PX4's 0.9 never arrived"
    );
    assert_eq!(s.stats.link_dropped, 99);
    // The controls answering 0.896 s are the last dropped; the samples from 0.904 s are whole.
    let (after, gps) = fly(&mut s, 50, 0.9);
    assert_eq!(s.stats.link_dropped, 100);
    assert!(
        after[1..]
            .iter()
            .all(|h| h.fields_updated.bits() > 0b11_1111)
            && gps > 0
    );
    assert_eq!(s.vehicle().actuators(), [0.9f32 as f64; 4]);
}

#[test]
fn a_link_delay_sends_px4_the_samples_of_delay_ago_stamped_now() {
    let mut delayed =
        faulty_session("[[faults]]\nkind = \"link_delay\"\ndelay = 0.1\nat = 0.5\nduration = 1");
    let mut healthy = session(5);
    let (mut oa, mut ob) = (Vec::new(), Vec::new());
    delayed.connect(1_000_000, &mut oa);
    healthy.connect(1_000_000, &mut ob);
    let (a, _) = fly(&mut delayed, 400, 0.6);
    let (b, _) = fly(&mut healthy, 400, 0.6);
    // a[k] is stamped 0.008 + 0.004·k s; the delay acts on the samples from 0.504 s (k =
    // 124) to 1.5 s: until one is 0.1 s (25 steps) old, the last one sent before the delay
    // is repeated, then each is 25 steps old; the stamp is always now.
    assert_eq!(a[..124], b[..124], "the same stream before the delay");
    assert_eq!(a[374..], b[374..], "and after it");
    for k in 124..374 {
        assert_eq!(a[k].time_usec, b[k].time_usec);
        let source = if k < 149 { 123 } else { k - 25 };
        assert_eq!(a[k].xacc, b[source].xacc, "step {k}");
        assert_eq!(a[k].abs_pressure, b[source].abs_pressure, "step {k}");
    }
}

#[test]
fn the_same_seed_and_link_faults_give_the_same_bytes() {
    let faults = "[[faults]]\nkind = \"link_loss\"\nat = 0.2\nduration = 0.1\n\
                  [[faults]]\nkind = \"link_delay\"\ndelay = 0.05\nat = 0.5\nduration = 0.3";
    let run = || {
        let mut s = faulty_session(faults);
        let mut out = Vec::new();
        s.connect(1_000_000, &mut out);
        for k in 0..300 {
            s.receive(&controls(0.5 + 0.001 * (k % 7) as f32), &mut out);
        }
        out
    };
    assert_eq!(run(), run());
}
