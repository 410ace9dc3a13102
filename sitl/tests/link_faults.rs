//! Issue 35: link faults on the lockstep task link, the real binary over loopback on port 0.
//! The lockstep tick is the client's command, so a link fault never stalls the world: every
//! command is answered — while the link is lost with the last reply that got through (its
//! time stands still, the command is dropped and the world steps on the one in effect),
//! while it is delayed with the reply of `delay` ago. Same seed and schedule, same bytes.

use crate::lockstep_over_udp::{Client, Sitl, controls};
use mavlink::dialects::common::MavMessage;
use std::io::Write;

const FAULTS: &str = "[[faults]]\nkind = \"link_loss\"\nat = 0.5\nduration = 0.2\n\
                      [[faults]]\nkind = \"link_delay\"\ndelay = 0.05\nat = 1.0\nduration = 0.3\n";

/// The replies' HIL_STATE_QUATERNION times to 200 commands of a SITL flying `FAULTS`.
fn fly() -> (Vec<u64>, Vec<Vec<(u8, MavMessage)>>) {
    let dir = std::env::temp_dir().join(format!("flyloop-link-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("faults.toml");
    std::fs::File::create(&path)
        .unwrap()
        .write_all(FAULTS.as_bytes())
        .unwrap();
    let mut sitl = Sitl::start(&["--seed", "7", "--config", path.to_str().unwrap()]);
    let mut client = Client::new(&sitl);
    let mut replies = Vec::new();
    for k in 0..200 {
        let x = if (40..80).contains(&k) { 0.9 } else { 0.55 };
        replies.push(client.exchange(1, &[controls([x; 4])]));
    }
    sitl.stop();
    let times = (replies.iter())
        .map(|r| {
            r.iter()
                .find_map(|(_, m)| match m {
                    MavMessage::HIL_STATE_QUATERNION(s) => Some(s.time_usec),
                    _ => None,
                })
                .unwrap()
        })
        .collect();
    (times, replies)
}

#[test]
fn a_lost_or_delayed_lockstep_link_answers_every_command_with_old_replies() {
    let (times, replies) = fly();
    // Step k (from 0) ends at 0.01·(k + 1) s. The task fires the loss in the step that
    // starts at 0.5 s (k = 50); the SITL sees it from that step's reply on.
    let clock = |k: usize| 10_000 * (k as u64 + 1);
    assert!((0..50).all(|k| times[k] == clock(k)), "{:?}", &times[..51]);
    assert!(
        (50..70).all(|k| times[k] == clock(49)),
        "lost: the reply of 0.5 s again: {:?}",
        &times[49..72]
    );
    // Clear from the step starting at 0.7 s: the fresh reply, the time jumped 0.2 s.
    assert!(
        (70..100).all(|k| times[k] == clock(k)),
        "{:?}",
        &times[68..72]
    );
    // Delayed from the step starting at 1.0 s (k = 100) to 1.3 s: the reply of 0.05 s ago,
    // the last one before the delay until one is that old.
    for (k, &time) in times.iter().enumerate().take(130).skip(100) {
        let expected = if k < 105 { clock(99) } else { clock(k - 5) };
        assert_eq!(time, expected, "step {k}");
    }
    assert!((130..200).all(|k| times[k] == clock(k)));
    // Same seed and schedule: the same bytes.
    let (_, again) = fly();
    assert_eq!(replies, again);
}
