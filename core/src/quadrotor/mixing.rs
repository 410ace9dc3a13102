//! The rotor sums of a frame, grouped once so the dynamics evaluate them cheaply and in a
//! fixed order.
//!
//! Each axis (thrust, roll, pitch, yaw torque) is Σᵢ cᵢ·mᵢ² over the rotors. Rotors whose
//! |cᵢ| is the same number share one term c·(Σ₊ mᵢ² − Σ₋ mᵢ²), the rotors pushing the positive
//! way on one side; a rotor with cᵢ = 0 (on the axis's line) is in no term. Within a side the
//! squares are added in pairs in motor order, then the pairs one after another: for the quad
//! X this is exactly the sums the dynamics wrote out by hand before frames existed
//! (((m₀² + m₁²) + (m₂² + m₃²)) for thrust, k·L/√2·((m₁² + m₂²) − (m₀² + m₃²)) for roll, …),
//! so its bits did not move. A term's coefficient comes from one member (all members have
//! the same), computed from the vehicle's parameters each step (`dynamics::Coefficients`).

use super::frame::{MAX_ROTORS, Rotor, Spin};
use nalgebra::DMatrix;

/// Motor indices of one side of a term, in motor order.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub(crate) struct Side {
    at: [u8; MAX_ROTORS],
    len: u8,
}

impl Side {
    fn members(&self) -> &[u8] {
        &self.at[..self.len as usize]
    }

    fn push(&mut self, i: usize) {
        self.at[self.len as usize] = i as u8;
        self.len += 1;
    }

    /// Σ squares[i] over the side: pairs in order, each pair added to the running sum.
    #[inline(always)]
    fn sum(&self, squares: &[f64; MAX_ROTORS]) -> f64 {
        let at = &self.at[..self.len as usize];
        let pair = |j: usize| match at.get(j + 1) {
            Some(&b) => squares[at[j] as usize] + squares[b as usize],
            None => squares[at[j] as usize],
        };
        let mut total = pair(0);
        let mut j = 2;
        while j < at.len() {
            total += pair(j);
            j += 2;
        }
        total
    }
}

/// c·(Σ₊ − Σ₋) for the rotors of one coefficient magnitude.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub(crate) struct Term {
    /// A member whose coefficients give the term's (every member has the same).
    pub(crate) representative: u8,
    plus: Side,
    minus: Side,
}

impl Term {
    /// Number of rotors in the term.
    pub(crate) fn len(&self) -> usize {
        usize::from(self.plus.len + self.minus.len)
    }

    #[inline(always)]
    fn signed_sum(&self, squares: &[f64; MAX_ROTORS]) -> f64 {
        match (self.plus.len, self.minus.len) {
            (_, 0) => self.plus.sum(squares),
            (0, _) => -self.minus.sum(squares),
            _ => self.plus.sum(squares) - self.minus.sum(squares),
        }
    }
}

/// The terms of one axis.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub(crate) struct Axis {
    terms: [Term; MAX_ROTORS],
    len: u8,
}

impl Axis {
    /// Groups the rotors by `key` (None: not on this axis; Some((magnitude key, positive))).
    fn group(rotors: &[Rotor], key: impl Fn(&Rotor) -> Option<([u64; 3], bool)>) -> Self {
        let mut axis = Axis::default();
        let mut keys = [[0u64; 3]; MAX_ROTORS];
        for (i, r) in rotors.iter().enumerate() {
            let Some((k, positive)) = key(r) else {
                continue;
            };
            let n = axis.len as usize;
            let t = match keys[..n].iter().position(|&other| other == k) {
                Some(t) => t,
                None => {
                    keys[n] = k;
                    axis.terms[n].representative = i as u8;
                    axis.len += 1;
                    n
                }
            };
            let term = &mut axis.terms[t];
            if positive {
                term.plus.push(i);
            } else {
                term.minus.push(i);
            }
        }
        axis
    }

    /// The terms, in order of their first member.
    pub(crate) fn terms(&self) -> &[Term] {
        &self.terms[..self.len as usize]
    }

    /// Σ coefficients[t]·(Σ₊ − Σ₋) over the terms, in order (0 when the axis has none).
    #[inline(always)]
    pub(crate) fn sum(&self, coefficients: &[f64; MAX_ROTORS], squares: &[f64; MAX_ROTORS]) -> f64 {
        let terms = self.terms();
        let Some(first) = terms.first() else {
            return 0.0;
        };
        let mut total = coefficients[0] * first.signed_sum(squares);
        for (t, term) in terms.iter().enumerate().skip(1) {
            total += coefficients[t] * term.signed_sum(squares);
        }
        total
    }
}

/// The four axes of a frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Mixing {
    /// Σ kᵢ/m · mᵢ²: acceleration along body z.
    pub(crate) thrust: Axis,
    /// Σ kᵢ·L·yᵢ · mᵢ²: torque about body x (r × F).
    pub(crate) roll: Axis,
    /// Σ −kᵢ·L·xᵢ · mᵢ²: torque about body y.
    pub(crate) pitch: Axis,
    /// Σ spinᵢ·kᵢ·cᵢ · mᵢ²: the rotors' reaction torque about body z.
    pub(crate) yaw: Axis,
    /// Whether the terms are the quad X's (four rotors, one term per axis with its sides):
    /// the dynamics then add the four squares with the same operations written out, which
    /// the compiler keeps in registers (a test checks both give the same bits).
    pub(crate) quad_x_terms: bool,
}

/// The bits of an optional coefficient (None and every value distinct).
fn bits(v: Option<f64>) -> u64 {
    v.map_or(u64::MAX, f64::to_bits)
}

impl Mixing {
    /// The grouped sums of `rotors`, or the first axis (roll, pitch, yaw) the rotors cannot
    /// steer independently of thrust and the axes before it.
    pub(crate) fn new(rotors: &[Rotor]) -> Result<Self, &'static str> {
        check_rank(rotors)?;
        let lever =
            |v: f64, positive: bool| (v != 0.0).then_some(([0, v.abs().to_bits(), 0], positive));
        let with_k = |r: &Rotor, (mut key, positive): ([u64; 3], bool)| {
            key[0] = bits(r.thrust_coefficient);
            (key, positive)
        };
        let mut mixing = Mixing {
            thrust: Axis::group(rotors, |r| Some(with_k(r, ([0; 3], true)))),
            roll: Axis::group(rotors, |r| lever(r.y, r.y > 0.0).map(|k| with_k(r, k))),
            pitch: Axis::group(rotors, |r| lever(r.x, r.x < 0.0).map(|k| with_k(r, k))),
            yaw: Axis::group(rotors, |r| {
                Some(with_k(
                    r,
                    ([0, 0, bits(r.torque_coefficient)], r.spin == Spin::Cw),
                ))
            }),
            quad_x_terms: false,
        };
        mixing.quad_x_terms = mixing.has_quad_x_terms();
        Ok(mixing)
    }

    fn has_quad_x_terms(&self) -> bool {
        let one = |axis: &Axis, plus: &[u8], minus: &[u8]| {
            let [t] = axis.terms() else { return false };
            t.plus.members() == plus && t.minus.members() == minus
        };
        one(&self.thrust, &[0, 1, 2, 3], &[])
            && one(&self.roll, &[1, 2], &[0, 3])
            && one(&self.pitch, &[1, 3], &[0, 2])
            && one(&self.yaw, &[2, 3], &[0, 1])
    }
}

/// The effectiveness rows thrust, roll, pitch, yaw (unit coefficients, the rotor's own where
/// it has them) must have rank 4; the first row that adds nothing names the axis.
fn check_rank(rotors: &[Rotor]) -> Result<(), &'static str> {
    let n = rotors.len();
    let row = |axis: usize, r: &Rotor| {
        let k = r.thrust_coefficient.unwrap_or(1.0);
        k * match axis {
            0 => 1.0,
            1 => r.y,
            2 => -r.x,
            _ => r.spin.sign() * r.torque_coefficient.unwrap_or(1.0),
        }
    };
    for (axis, name) in [(1, "roll"), (2, "pitch"), (3, "yaw")] {
        let m = DMatrix::from_fn(axis + 1, n, |a, i| row(a, &rotors[i]));
        if m.rank(1e-9) < axis + 1 {
            return Err(name);
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::quadrotor::frame::Frame;

    fn members(side: &Side) -> Vec<u8> {
        side.members().to_vec()
    }

    #[test]
    fn the_quad_x_groups_are_the_sums_written_out_before_frames() {
        let f = Frame::quad_x();
        let m = f.mixing();
        let one = |axis: &Axis| {
            assert_eq!(axis.terms().len(), 1);
            let t = axis.terms()[0];
            (members(&t.plus), members(&t.minus))
        };
        assert_eq!(one(&m.thrust), (vec![0, 1, 2, 3], vec![]));
        assert_eq!(one(&m.roll), (vec![1, 2], vec![0, 3]));
        assert_eq!(one(&m.pitch), (vec![1, 3], vec![0, 2]));
        assert_eq!(one(&m.yaw), (vec![2, 3], vec![0, 1]));
        assert!(m.quad_x_terms);
        assert!(!Frame::named("quad_plus").unwrap().mixing().quad_x_terms);
    }

    #[test]
    fn a_hexa_has_two_roll_terms_and_its_side_rotors_no_pitch_arm() {
        let f = Frame::named("hexa_x").unwrap();
        let m = f.mixing();
        assert_eq!(m.roll.terms().len(), 2);
        assert_eq!(m.pitch.terms().len(), 1);
        let pitch = m.pitch.terms()[0];
        assert_eq!(
            (members(&pitch.plus), members(&pitch.minus)),
            (vec![3, 5], vec![2, 4])
        );
        // Sums: squares 1..6 → thrust pairs (1+4)+(9+16)+(25+36).
        let squares: [f64; MAX_ROTORS] = std::array::from_fn(|i| ((i + 1) * (i + 1)) as f64);
        let unit = [1.0; MAX_ROTORS];
        assert_eq!(m.thrust.sum(&unit, &squares), 91.0);
        // Yaw: CW 0, 2, 5 minus CCW 1, 3, 4.
        assert_eq!(
            m.yaw.sum(&unit, &squares),
            (1.0 + 9.0 + 36.0) - (4.0 + 16.0 + 25.0)
        );
    }
}
