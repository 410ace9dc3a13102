//! Which vehicles are near enough to interact: a sorted grid of vertical columns.
//!
//! Every vehicle falls into the column (⌊x/h⌋, ⌊y/h⌋) of side h = the interaction reach;
//! the (cell, index) list is sorted, and each vehicle looks up its own and the eight
//! neighbouring columns by binary search. Every pair closer than h horizontally is found in
//! O(N log N + pairs), with no hash map, so the candidate list is the same on every machine;
//! it comes out sorted by (i, j), the order the forces are summed in.

/// Candidate pairs (i < j) of the points `xy` within `reach` horizontally (and possibly a
/// few farther: the caller applies its exact tests), sorted by (i, j).
pub fn candidate_pairs(xy: &[[f64; 2]], reach: f64) -> Vec<(u32, u32)> {
    let cell = |v: f64| (v / reach).floor() as i64;
    let mut cells: Vec<((i64, i64), u32)> = (xy.iter().enumerate())
        .map(|(i, p)| ((cell(p[0]), cell(p[1])), i as u32))
        .collect();
    cells.sort_unstable();
    let mut pairs = Vec::new();
    for &((cx, cy), i) in &cells {
        for dx in -1..=1 {
            for dy in -1..=1 {
                let key = (cx.saturating_add(dx), cy.saturating_add(dy));
                let start = cells.partition_point(|(c, _)| *c < key);
                let members = cells[start..].iter().take_while(|(c, _)| *c == key);
                pairs.extend(members.filter(|(_, j)| *j > i).map(|&(_, j)| (i, j)));
            }
        }
    }
    pairs.sort_unstable();
    pairs.dedup();
    pairs
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::SimRng;

    /// Against all pairs checked one by one: every pair within the reach is a candidate.
    #[test]
    fn every_pair_within_reach_is_found() {
        let mut rng = SimRng::new(11);
        let xy: Vec<[f64; 2]> = (0..600)
            .map(|_| [rng.uniform(-20.0, 20.0), rng.uniform(-20.0, 20.0)])
            .collect();
        let reach = 1.5;
        let pairs = candidate_pairs(&xy, reach);
        let mut near = 0;
        for i in 0..xy.len() {
            for j in i + 1..xy.len() {
                let d = ((xy[i][0] - xy[j][0]).powi(2) + (xy[i][1] - xy[j][1]).powi(2)).sqrt();
                if d <= reach {
                    near += 1;
                    assert!(
                        pairs.binary_search(&(i as u32, j as u32)).is_ok(),
                        "{i} {j}"
                    );
                }
            }
        }
        assert!(near > 100, "{near}");
        // Candidates are a few times the true pairs, not all N²/2.
        assert!(pairs.len() < 6 * near, "{} candidates", pairs.len());
        assert!(pairs.windows(2).all(|w| w[0] < w[1]));
    }

    #[test]
    fn far_apart_points_make_no_pairs_and_odd_values_do_not_panic() {
        assert!(candidate_pairs(&[[0.0, 0.0], [10.0, 0.0]], 1.0).is_empty());
        let odd = [[f64::NAN, 0.0], [f64::INFINITY, 1e300], [-1e300, 0.0]];
        let _ = candidate_pairs(&odd, 1.0);
    }
}
