//! The ground-station link's message streams: which messages go out how often (wall clock),
//! changed by SET_MESSAGE_INTERVAL.

use crate::pacer::Cadence;
use crate::telemetry::id;
use mavlink::dialects::common::MavResult;
use std::time::{Duration, Instant};

/// (message id, default interval) of every stream; HOME_POSITION and AUTOPILOT_VERSION are
/// also sent on request.
pub const DEFAULT_STREAMS: &[(u32, Duration)] = &[
    (id::HEARTBEAT, Duration::from_secs(1)),
    (id::SYS_STATUS, Duration::from_secs(1)),
    (id::ATTITUDE, Duration::from_millis(100)),
    (id::GLOBAL_POSITION_INT, Duration::from_millis(200)),
    (id::LOCAL_POSITION_NED, Duration::from_millis(200)),
    (id::VFR_HUD, Duration::from_millis(250)),
    (id::HOME_POSITION, Duration::from_secs(5)),
];

/// Messages that may be streamed on request but are off by default (a live view asks for
/// the truth, the motor commands, the wind and the task frame: docs/view.md).
const OPTIONAL_STREAMS: &[u32] = &[
    id::HIL_STATE_QUATERNION,
    id::AUTOPILOT_VERSION,
    id::SERVO_OUTPUT_RAW,
    id::WIND_COV,
    id::DEBUG_FLOAT_ARRAY,
];

/// Shortest interval accepted (50 Hz).
const MIN_INTERVAL: Duration = Duration::from_millis(20);

#[derive(Debug, Clone, Copy)]
struct Stream {
    message_id: u32,
    interval: Option<Duration>,
    cadence: Cadence,
}

/// The streams of the ground-station link.
#[derive(Debug, Clone)]
pub struct GcsStreams {
    streams: Vec<Stream>,
}

fn default_interval(message_id: u32) -> Option<Duration> {
    DEFAULT_STREAMS
        .iter()
        .find(|(m, _)| *m == message_id)
        .map(|(_, d)| *d)
}

impl GcsStreams {
    pub fn new(now: Instant) -> Self {
        let streams = DEFAULT_STREAMS
            .iter()
            .map(|&(message_id, interval)| (message_id, Some(interval)))
            .chain(OPTIONAL_STREAMS.iter().map(|&m| (m, None)))
            .map(|(message_id, interval)| Stream {
                message_id,
                interval,
                cadence: Cadence::starting(now),
            })
            .collect();
        GcsStreams { streams }
    }

    /// SET_MESSAGE_INTERVAL: interval µs > 0 sets it (at most 50 Hz), 0 restores the
    /// default, −1 stops the stream.
    pub fn set_interval(&mut self, message_id: u32, interval_us: f32) -> MavResult {
        let Some(stream) = self.streams.iter_mut().find(|s| s.message_id == message_id) else {
            return MavResult::MAV_RESULT_UNSUPPORTED;
        };
        stream.interval = if interval_us == -1.0 {
            None
        } else if interval_us == 0.0 {
            default_interval(message_id)
        } else if interval_us > 0.0 {
            Some(Duration::from_micros(interval_us as u64).max(MIN_INTERVAL))
        } else {
            return MavResult::MAV_RESULT_DENIED;
        };
        MavResult::MAV_RESULT_ACCEPTED
    }

    /// The messages due at `now` (their next time moves on by one interval).
    pub fn due(&mut self, now: Instant) -> Vec<u32> {
        let mut out = Vec::new();
        for s in &mut self.streams {
            if let Some(interval) = s.interval {
                if s.cadence.take(now, interval) {
                    out.push(s.message_id);
                    s.cadence.skip_if_behind(now, interval);
                }
            }
        }
        out
    }

    /// When the next message is due (in a second if nothing streams).
    pub fn next_due(&self) -> Instant {
        self.streams
            .iter()
            .filter(|s| s.interval.is_some())
            .map(|s| s.cadence.next())
            .min()
            .unwrap_or_else(|| Instant::now() + Duration::from_secs(1))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn streams_fire_at_their_intervals_and_can_be_changed() {
        let t0 = Instant::now();
        let mut s = GcsStreams::new(t0);
        let first = s.due(t0);
        assert!(first.contains(&id::HEARTBEAT) && first.contains(&id::ATTITUDE));
        assert!(!first.contains(&id::HIL_STATE_QUATERNION));
        assert_eq!(s.due(t0 + Duration::from_millis(100)), vec![id::ATTITUDE]);
        assert_eq!(
            s.set_interval(id::ATTITUDE, -1.0),
            MavResult::MAV_RESULT_ACCEPTED
        );
        assert!(
            s.due(t0 + Duration::from_millis(300))
                .iter()
                .all(|&m| m != id::ATTITUDE)
        );
        assert_eq!(
            s.set_interval(id::HIL_STATE_QUATERNION, 1000.0),
            MavResult::MAV_RESULT_ACCEPTED
        );
        assert!(
            s.due(t0 + Duration::from_millis(400))
                .contains(&id::HIL_STATE_QUATERNION)
        );
        assert_eq!(
            s.set_interval(9999, 1000.0),
            MavResult::MAV_RESULT_UNSUPPORTED
        );
        assert_eq!(
            s.set_interval(id::ATTITUDE, -5.0),
            MavResult::MAV_RESULT_DENIED
        );
    }
}
