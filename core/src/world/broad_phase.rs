//! Which vehicles are near enough to interact: a sorted grid of vertical columns.
//!
//! Every vehicle falls into the column (⌊x/h⌋, ⌊y/h⌋) of side h = the interaction reach; the
//! (column, index) list is sorted, so the three columns (c, r−1..r+1) of one grid line are
//! one contiguous run. Each occupied column pairs its members with each other and with the
//! columns ahead of it (the rest of its own line's neighbours and the next line's three):
//! every pair closer than h horizontally is found once, in O(N log N + pairs), with no hash
//! map. The list is a pure function of the positions and indices, so the forces are summed in
//! the same order on every machine; it is kept between calls only because vehicles move little
//! per step and an almost sorted list sorts fast.

/// The sorted columns, kept between calls to sort faster (not state: any content works).
#[derive(Debug, Clone, Default)]
pub struct Columns(Vec<((i64, i64), u32)>);

impl PartialEq for Columns {
    fn eq(&self, _: &Self) -> bool {
        true
    }
}

impl Columns {
    /// Candidate pairs (i < j or j < i: each unordered pair once) of the points `xy` within
    /// `reach` horizontally, and possibly a few farther: the caller applies its exact tests.
    pub fn candidate_pairs(&mut self, xy: &[[f64; 2]], reach: f64) -> Vec<(u32, u32)> {
        let cell = |v: f64| (v / reach).floor() as i64;
        let cells = &mut self.0;
        cells.clear();
        cells.extend((xy.iter().enumerate()).map(|(i, p)| ((cell(p[0]), cell(p[1])), i as u32)));
        cells.sort();
        let mut pairs = Vec::new();
        let mut start = 0;
        while start < cells.len() {
            let key = cells[start].0;
            let end = start + cells[start..].iter().take_while(|(c, _)| *c == key).count();
            let members = &cells[start..end];
            for (k, &(_, i)) in members.iter().enumerate() {
                pairs.extend(members[k + 1..].iter().map(|&(_, j)| (i, j)));
            }
            let (cx, cy) = key;
            // Ahead of this column: (cx, cy+1) and the next line's (cx+1, cy−1..=cy+1).
            let ahead = [
                ((cx, cy.saturating_add(1)), (cx, cy.saturating_add(1))),
                (
                    (cx.saturating_add(1), cy.saturating_sub(1)),
                    (cx.saturating_add(1), cy.saturating_add(1)),
                ),
            ];
            for (lo, hi) in ahead {
                if (lo, hi) == (key, key) {
                    continue; // saturated at the edge of i64: no neighbour there
                }
                let from = end + cells[end..].partition_point(|(c, _)| *c < lo);
                let others = cells[from..].iter().take_while(|(c, _)| *c <= hi);
                for &(_, i) in members {
                    pairs.extend(others.clone().map(|&(_, j)| (i, j)));
                }
            }
            start = end;
        }
        pairs
    }
}

/// [`Columns::candidate_pairs`] without a kept list.
pub fn candidate_pairs(xy: &[[f64; 2]], reach: f64) -> Vec<(u32, u32)> {
    Columns::default().candidate_pairs(xy, reach)
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
        let pairs: Vec<(u32, u32)> = {
            let mut p: Vec<(u32, u32)> = candidate_pairs(&xy, reach)
                .into_iter()
                .map(|(i, j)| (i.min(j), i.max(j)))
                .collect();
            p.sort_unstable();
            let before = p.len();
            p.dedup();
            assert_eq!(p.len(), before, "a pair was found twice");
            p
        };
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
