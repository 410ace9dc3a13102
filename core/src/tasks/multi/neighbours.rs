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
use nalgebra::Vector3;

/// Below this many vehicles every agent scans all the others: the grid does not pay.
const GRID_FROM: usize = 48;
/// A slot of [`all_nearest`]'s lists with no neighbour.
pub const ABSENT: u32 = u32::MAX;

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
    let positions: Vec<Vector3<f64>> = vehicles.iter().map(|v| v.body().position).collect();
    let mut best = Best::new(k);
    for j in 0..positions.len() {
        best.offer(&positions, i, j);
    }
    std::array::from_fn(|s| best.get(s).map(|j| j as usize))
}

/// Every agent's `k` nearest neighbours at once, as [`nearest`] finds them (the same lists,
/// bit for bit): agent i's are `lists[i*k..(i+1)*k]`, [`ABSENT`] past the number of others.
/// From [`GRID_FROM`] vehicles on, each agent searches a grid of columns ring by ring from
/// its own, O(N·k) for vehicles spread over the plane instead of O(N²).
pub fn all_nearest(vehicles: &[Box<dyn AirVehicle>], k: usize) -> Vec<u32> {
    let positions: Vec<Vector3<f64>> = vehicles.iter().map(|v| v.body().position).collect();
    let n = positions.len();
    let mut lists = Vec::with_capacity(n * k);
    let grid = (n >= GRID_FROM && k > 0)
        .then(|| Grid::new(&positions))
        .flatten();
    for i in 0..n {
        let mut best = Best::new(k);
        match &grid {
            Some(grid) => grid.search(&positions, i, &mut best),
            None => (0..n).for_each(|j| best.offer(&positions, i, j)),
        }
        lists.extend((0..k).map(|s| best.get(s).unwrap_or(ABSENT)));
    }
    lists
}

/// The `k` best (squared distance, index) pairs offered so far, sorted; the order is total
/// on finite distances, so any order of offers gives the same list.
struct Best {
    found: [(f64, u32); MAX_NEIGHBOURS as usize],
    count: usize,
    k: usize,
}

impl Best {
    fn new(k: usize) -> Self {
        Best {
            found: [(f64::INFINITY, ABSENT); MAX_NEIGHBOURS as usize],
            count: 0,
            k: k.min(MAX_NEIGHBOURS as usize),
        }
    }

    /// Offers vehicle `j` as a neighbour of `i`.
    fn offer(&mut self, positions: &[Vector3<f64>], i: usize, j: usize) {
        let k = self.k;
        if j == i || k == 0 {
            return;
        }
        let d = (positions[j] - positions[i]).norm_squared();
        let j = j as u32;
        // Insert (d, j) into the sorted first `count` entries if it beats the last.
        if self.count == k && (d, j) >= self.found[k - 1] {
            return;
        }
        let mut at = self.count.min(k - 1);
        while at > 0 && (d, j) < self.found[at - 1] {
            self.found[at] = self.found[at - 1];
            at -= 1;
        }
        self.found[at] = (d, j);
        self.count = (self.count + 1).min(k);
    }

    fn get(&self, slot: usize) -> Option<u32> {
        (slot < self.count).then_some(self.found[slot].1)
    }

    /// Whether nothing at a squared distance above `d2` can enter the list any more.
    fn full_within(&self, d2: f64) -> bool {
        self.count == self.k && self.found[self.k - 1].0 <= d2
    }
}

/// Square columns of side `side` over the vehicles' horizontal extent, about one vehicle
/// each, their members listed column by column (a counting sort: O(N)).
struct Grid {
    min: [f64; 2],
    side: f64,
    width: usize,
    height: usize,
    /// Column c's members are `members[start[c]..start[c + 1]]`, in index order.
    start: Vec<u32>,
    members: Vec<u32>,
}

impl Grid {
    /// `None` when the positions are not finite or all on one vertical line (scan instead).
    fn new(positions: &[Vector3<f64>]) -> Option<Self> {
        let n = positions.len();
        let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
        for p in positions {
            for a in 0..2 {
                lo[a] = lo[a].min(p[a]);
                hi[a] = hi[a].max(p[a]);
            }
        }
        let extent = [hi[0] - lo[0], hi[1] - lo[1]];
        if !(extent[0].is_finite() && extent[1].is_finite())
            || positions.iter().any(|p| !p.z.is_finite())
        {
            return None;
        }
        // About one vehicle per column; no more than ~3N columns however thin the extent.
        let longest = extent[0].max(extent[1]);
        let side = (extent[0] * extent[1] / n as f64)
            .sqrt()
            .max(longest / n as f64);
        if side <= 0.0 || !side.is_finite() {
            return None;
        }
        let cells = |e: f64| (e / side).floor() as usize + 1;
        let (width, height) = (cells(extent[0]), cells(extent[1]));
        let mut grid = Grid {
            min: lo,
            side,
            width,
            height,
            start: vec![0; width * height + 1],
            members: vec![0; n],
        };
        let column: Vec<usize> = positions.iter().map(|p| grid.column_of(p)).collect();
        for &c in &column {
            grid.start[c + 1] += 1;
        }
        for c in 0..width * height {
            grid.start[c + 1] += grid.start[c];
        }
        let mut next = grid.start.clone();
        for (j, &c) in column.iter().enumerate() {
            grid.members[next[c] as usize] = j as u32;
            next[c] += 1;
        }
        Some(grid)
    }

    fn cell(&self, p: &Vector3<f64>) -> (usize, usize) {
        let at = |a: usize, size: usize| {
            (((p[a] - self.min[a]) / self.side).floor().max(0.0) as usize).min(size - 1)
        };
        (at(0, self.width), at(1, self.height))
    }

    fn column_of(&self, p: &Vector3<f64>) -> usize {
        let (x, y) = self.cell(p);
        y * self.width + x
    }

    fn offer_column(&self, positions: &[Vector3<f64>], i: usize, column: usize, best: &mut Best) {
        let (from, to) = (self.start[column] as usize, self.start[column + 1] as usize);
        for &j in &self.members[from..to] {
            best.offer(positions, i, j as usize);
        }
    }

    /// Offers agent `i` the members of the columns ring by ring (ring r: the columns r away
    /// in x or y) until no farther column can hold a nearer vehicle: a vehicle r + 1 columns
    /// away is more than r·side away horizontally. The bound is taken a millionth of a side
    /// short, for positions that rounding put in the next column.
    fn search(&self, positions: &[Vector3<f64>], i: usize, best: &mut Best) {
        let (cx, cy) = self.cell(&positions[i]);
        let last_ring = (cx.max(self.width - 1 - cx)).max(cy.max(self.height - 1 - cy));
        for r in 0..=last_ring {
            let (x0, x1) = (cx.saturating_sub(r), (cx + r).min(self.width - 1));
            let (y0, y1) = (cy.saturating_sub(r), (cy + r).min(self.height - 1));
            for y in y0..=y1 {
                if y.abs_diff(cy) == r {
                    (x0..=x1)
                        .for_each(|x| self.offer_column(positions, i, y * self.width + x, best));
                } else {
                    // Between the ring's top and bottom rows only its two side columns.
                    if cx >= r {
                        self.offer_column(positions, i, y * self.width + cx - r, best);
                    }
                    if cx + r < self.width {
                        self.offer_column(positions, i, y * self.width + cx + r, best);
                    }
                }
            }
            let safe = (r as f64 - 1e-6) * self.side;
            if r >= 1 && best.full_within(safe * safe) {
                return;
            }
        }
    }
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

/// Writes agent `i`'s neighbour slots (`nearest`: its list from [`all_nearest`]) into `out`
/// (length 7k), clipped into `lo..=hi`.
pub fn write(
    link: &FlightLink,
    vehicles: &[Box<dyn AirVehicle>],
    i: usize,
    nearest: &[u32],
    lo: &[f32],
    hi: &[f32],
    out: &mut [f32],
) {
    let own = vehicles[i].as_ref();
    for (s, &j) in nearest.iter().enumerate() {
        let at = s * NEIGHBOUR_VALUES;
        if j == ABSENT {
            out[at..at + NEIGHBOUR_VALUES].fill(0.0);
            continue;
        }
        let other = vehicles[j as usize].body();
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

    fn at_xyz(p: [f64; 3]) -> Box<dyn AirVehicle> {
        let mut v = at(0.0);
        let mut body = *v.body();
        body.position = Vector3::from(p);
        v.restart(body, SimRng::new(0));
        v
    }

    /// The grid must find exactly the lists the scan finds, ties and all.
    fn assert_grid_equals_scan(points: &[[f64; 3]], k: usize) {
        let v: Vec<Box<dyn AirVehicle>> = points.iter().copied().map(at_xyz).collect();
        let lists = all_nearest(&v, k);
        for i in 0..v.len() {
            let scan = nearest(&v, i, k);
            let want: Vec<u32> = scan[..k]
                .iter()
                .map(|s| s.map_or(ABSENT, |j| j as u32))
                .collect();
            assert_eq!(
                &lists[i * k..(i + 1) * k],
                &want[..],
                "agent {i} of {}, k {k}",
                v.len()
            );
        }
    }

    #[test]
    fn the_grid_finds_the_same_neighbours_as_the_scan() {
        let mut rng = SimRng::new(7);
        for &n in &[1, 2, 47, 48, 49, 100, 300] {
            for &k in &[0, 1, 3, 8, 64] {
                // Spread, clustered (a tight knot plus a far outlier), and a lattice of ties.
                let spread: Vec<[f64; 3]> = (0..n)
                    .map(|_| {
                        [
                            rng.uniform(-20.0, 20.0),
                            rng.uniform(-5.0, 5.0),
                            rng.uniform(0.5, 3.0),
                        ]
                    })
                    .collect();
                assert_grid_equals_scan(&spread, k);
                let mut knot: Vec<[f64; 3]> = (0..n)
                    .map(|_| [rng.uniform(0.0, 0.1), rng.uniform(0.0, 0.1), 1.0])
                    .collect();
                knot[0] = [500.0, -300.0, 1.0];
                assert_grid_equals_scan(&knot, k);
                let lattice: Vec<[f64; 3]> = (0..n)
                    .map(|j| [(j % 7) as f64, (j / 7) as f64, 1.0])
                    .collect();
                assert_grid_equals_scan(&lattice, k);
                let column: Vec<[f64; 3]> = (0..n).map(|j| [0.0, 0.0, j as f64 * 0.5]).collect();
                assert_grid_equals_scan(&column, k);
                let row: Vec<[f64; 3]> = (0..n).map(|j| [j as f64 * 0.3, -2.0, 1.0]).collect();
                assert_grid_equals_scan(&row, k);
            }
        }
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
