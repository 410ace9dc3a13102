//! The task frame: what a gym step returns (reward, terminated, truncated, observation, info)
//! as float32 values in DEBUG_FLOAT_ARRAY messages. The layout is defined here and in
//! docs/protocol.md, nowhere else:
//!
//! | index | value |
//! |---|---|
//! | 0 | reward |
//! | 1 | terminated (0 or 1) |
//! | 2 | truncated (0 or 1) |
//! | 3 | episode step (0 after a reset) |
//! | 4 | n_obs, the number of observation values |
//! | 5 | n_info, the number of info values |
//! | 6 .. 6+n_obs | observation |
//! | 6+n_obs .. 6+n_obs+n_info | info values, flattened in the task's info order |
//!
//! The values are concatenated over DEBUG_FLOAT_ARRAY messages with array_id 1, 2, … (58
//! values each); `name` is the task's name, `time_usec` the vehicle's simulation time.

use flyloop_core::tasks::registry::{TaskInstance, push_info, push_infos};
use mavlink::dialects::common::{DEBUG_FLOAT_ARRAY_DATA, MavMessage};

/// Values per DEBUG_FLOAT_ARRAY.
pub const ARRAY_LEN: usize = 58;
/// Values before the observation.
pub const HEADER_LEN: usize = 6;

/// The outcome part of a frame.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct FrameHeader {
    pub reward: f64,
    pub terminated: bool,
    pub truncated: bool,
    pub step: u64,
}

fn flag(b: bool) -> f32 {
    if b { 1.0 } else { 0.0 }
}

/// The frame values of `task` after a step (or a reset) with outcome `header`.
pub fn values(task: &TaskInstance, header: &FrameHeader, out: &mut Vec<f32>) {
    out.clear();
    let n_obs = task.observation_size();
    out.extend_from_slice(&[
        header.reward as f32,
        flag(header.terminated),
        flag(header.truncated),
        header.step as f32,
        n_obs as f32,
        0.0,
    ]);
    out.resize(HEADER_LEN + n_obs, 0.0);
    task.write_observation(&mut out[HEADER_LEN..]);
    push_infos(task, out);
    out[5] = (out.len() - HEADER_LEN - n_obs) as f32;
}

/// The info layout of `task`: (name, first index in the frame, count), for the docs and
/// `--describe`.
pub fn info_layout(task: &TaskInstance) -> Vec<(&'static str, usize, usize)> {
    let mut at = HEADER_LEN + task.observation_size();
    task.info()
        .into_iter()
        .map(|(name, value)| {
            let mut tmp = Vec::new();
            push_info(&mut tmp, value.as_ref());
            let entry = (name, at, tmp.len());
            at += tmp.len();
            entry
        })
        .collect()
}

/// The DEBUG_FLOAT_ARRAY messages carrying `values`.
pub fn messages(name: &str, time_usec: u64, values: &[f32]) -> impl Iterator<Item = MavMessage> {
    let name = mavlink::types::CharArray::<10>::from(name);
    values
        .chunks(ARRAY_LEN)
        .zip(1u16..)
        .map(move |(chunk, array_id)| {
            let mut data = [0.0f32; ARRAY_LEN];
            data[..chunk.len()].copy_from_slice(chunk);
            MavMessage::DEBUG_FLOAT_ARRAY(DEBUG_FLOAT_ARRAY_DATA {
                time_usec,
                array_id,
                name,
                data,
            })
        })
}

#[cfg(test)]
mod tests {
    use super::*;
    use flyloop_core::tasks::registry::{TaskConfig, TaskKind};

    #[test]
    fn the_layout_holds_header_observation_and_info() {
        let mut task = TaskInstance::build(TaskKind::Hover, &TaskConfig::default()).unwrap();
        task.reset(5);
        let outcome = task.step(&[0.5; 4]).unwrap();
        let header = FrameHeader {
            reward: outcome.reward,
            terminated: outcome.terminated,
            truncated: outcome.truncated,
            step: 1,
        };
        let mut v = Vec::new();
        values(&task, &header, &mut v);
        assert_eq!(v[0], outcome.reward as f32);
        assert_eq!(&v[3..6], &[1.0, 33.0, 12.0]);
        assert_eq!(&v[6..39], task.observation().as_slice());
        let layout = info_layout(&task);
        assert_eq!(layout[0], ("distance_to_target", 39, 1));
        assert_eq!(layout[1], ("position", 40, 3));
        assert_eq!(v.len(), 51);
        let TaskInstance::Hover(h) = &task else {
            unreachable!()
        };
        assert_eq!(v[40], h.air_vehicle().body().position.x as f32);
        assert_eq!(messages("hover", 10_000, &v).count(), 1);
    }

    #[test]
    fn waypoints_spill_into_a_second_array() {
        let task = TaskInstance::build(TaskKind::Waypoints, &TaskConfig::default()).unwrap();
        let mut v = Vec::new();
        values(&task, &FrameHeader::default(), &mut v);
        assert_eq!(v.len(), HEADER_LEN + 37 + 20);
        let arrays: Vec<MavMessage> = messages("waypoints", 0, &v).collect();
        assert_eq!(arrays.len(), 2);
        let MavMessage::DEBUG_FLOAT_ARRAY(second) = &arrays[1] else {
            unreachable!()
        };
        assert_eq!(second.array_id, 2);
        assert_eq!(&second.data[..v.len() - ARRAY_LEN], &v[ARRAY_LEN..]);
    }

    #[test]
    fn landing_frames_fit_in_one_array() {
        let task = TaskInstance::build(TaskKind::Landing, &TaskConfig::default()).unwrap();
        let mut v = Vec::new();
        values(&task, &FrameHeader::default(), &mut v);
        assert_eq!(v.len(), HEADER_LEN + 11 + 23);
        assert_eq!(v[4], 11.0);
    }
}
