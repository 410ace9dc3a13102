//! What an agent observes of the others: its k nearest neighbours (by distance, ties to the
//! lower index), nearest first, each as 7 values — position relative to the agent's observed
//! position (3, m), velocity relative to its observed velocity (3, m/s), both in the agent's
//! observation frame (world ENU on the motor interface, the heading frame on the rates
//! interface), then 1 (present). A slot with no neighbour (fewer than k others) is **absent**:
//! all 7 values 0 — the flag tells it from a neighbour at the agent's own position.

use super::params::MAX_NEIGHBOURS;
use crate::tasks::clip_f32;
use crate::tasks::flight_link::FlightLink;
use crate::vehicle::AirVehicle;

/// Values per neighbour slot.
pub const NEIGHBOUR_VALUES: usize = 7;
/// Bound of a neighbour's relative velocity, m/s (two vehicles at the velocity bound, 40).
const RELATIVE_VELOCITY_BOUND: f64 = 80.0;

/// The `k` (≤ [`MAX_NEIGHBOURS`]) vehicles nearest to vehicle `i`, nearest first, ties to
/// the lower index; `None` past the number of others.
pub fn nearest(
    vehicles: &[Box<dyn AirVehicle>],
    i: usize,
    k: usize,
) -> [Option<usize>; MAX_NEIGHBOURS as usize] {
    let mut found: [(f64, usize); MAX_NEIGHBOURS as usize] =
        [(f64::INFINITY, usize::MAX); MAX_NEIGHBOURS as usize];
    let mut count = 0;
    let own = &vehicles[i].body().position;
    for (j, v) in vehicles.iter().enumerate() {
        if j == i || k == 0 {
            continue;
        }
        let d = (v.body().position - own).norm_squared();
        // Insert (d, j) into the sorted first `count` entries if it beats the last.
        if count == k && (d, j) >= found[k - 1] {
            continue;
        }
        let mut at = count.min(k - 1);
        while at > 0 && (d, j) < found[at - 1] {
            found[at] = found[at - 1];
            at -= 1;
        }
        found[at] = (d, j);
        count = (count + 1).min(k);
    }
    std::array::from_fn(|s| (s < count).then_some(found[s].1))
}

/// Bounds of the `k` neighbour slots: relative position ±`position_bound`, relative velocity
/// ±80 m/s, present in [0, 1].
pub fn bounds(k: usize, position_bound: f64) -> (Vec<f32>, Vec<f32>) {
    let p = position_bound as f32;
    let v = RELATIVE_VELOCITY_BOUND as f32;
    let lo = [-p, -p, -p, -v, -v, -v, 0.0];
    let hi = [p, p, p, v, v, v, 1.0];
    (lo.repeat(k), hi.repeat(k))
}

/// Writes agent `i`'s `k` neighbour slots into `out` (length 7k), clipped into `lo..=hi`.
pub fn write(
    link: &FlightLink,
    vehicles: &[Box<dyn AirVehicle>],
    i: usize,
    k: usize,
    lo: &[f32],
    hi: &[f32],
    out: &mut [f32],
) {
    let own = vehicles[i].as_ref();
    for (s, slot) in nearest(vehicles, i, k).iter().take(k).enumerate() {
        let at = s * NEIGHBOUR_VALUES;
        let Some(j) = slot else {
            out[at..at + NEIGHBOUR_VALUES].fill(0.0);
            continue;
        };
        let other = vehicles[*j].body();
        let position = link.observed_offset(own, &other.position);
        let velocity = link.observed_relative_velocity(own, &other.velocity);
        let values = position.iter().chain(velocity.iter()).chain(&[1.0]);
        for (m, &v) in values.enumerate() {
            out[at + m] = clip_f32(v, lo[at + m], hi[at + m]);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::quadrotor::{BodyState, QuadrotorParams};
    use crate::rng::SimRng;
    use nalgebra::Vector3;

    fn at(x: f64) -> Box<dyn AirVehicle> {
        let body = BodyState::at_rest(Vector3::new(x, 0.0, 1.0), 0.0, 0.0, 0.0, 0.0);
        crate::quadrotor::multirotor_at(
            QuadrotorParams::default(),
            crate::quadrotor::Frame::quad_x(),
            body,
            SimRng::new(0),
        )
        .unwrap()
    }

    #[test]
    fn nearest_first_ties_to_the_lower_index_and_absent_past_the_others() {
        let v: Vec<Box<dyn AirVehicle>> = [0.0, 3.0, -1.0, 1.0, 2.0].into_iter().map(at).collect();
        let n = nearest(&v, 0, 3);
        // 2 and 3 are both 1 m away: the lower index first.
        assert_eq!(&n[..4], &[Some(2), Some(3), Some(4), None]);
        let n = nearest(&v, 1, 6);
        assert_eq!(&n[..6], &[Some(4), Some(3), Some(0), Some(2), None, None]);
        assert_eq!(nearest(&v, 1, 0)[0], None);
    }
}
