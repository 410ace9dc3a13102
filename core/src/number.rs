//! Numbers in messages: compact like C's `%g`, but exact.

use std::fmt;

/// Displays an `f64` as its shortest exact decimal (Rust's `{}`) when that is short, and in
/// exponent form outside [1e-4, 1e6): `1e300`, not a 301-digit integer; `2.5e-7`, not
/// `0.00000025`. NaN and infinities print as `NaN`, `inf`, `-inf`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Compact(pub f64);

impl fmt::Display for Compact {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let x = self.0;
        let magnitude = x.abs();
        if x.is_finite() && magnitude != 0.0 && !(1e-4..1e6).contains(&magnitude) {
            write!(f, "{x:e}")
        } else {
            write!(f, "{x}")
        }
    }
}

#[cfg(test)]
mod tests {
    use super::Compact;

    #[test]
    fn numbers_print_short_and_exact() {
        let cases = [
            (1e300, "1e300"),
            (-1e300, "-1e300"),
            (1e6, "1e6"),
            (999_999.5, "999999.5"),
            (0.001, "0.001"),
            (1e-4, "0.0001"),
            (2.5e-7, "2.5e-7"),
            (0.0, "0"),
            (-0.0, "-0"),
            (1.0, "1"),
            (0.1 + 0.2, "0.30000000000000004"),
            (f64::NAN, "NaN"),
            (f64::INFINITY, "inf"),
            (f64::NEG_INFINITY, "-inf"),
            (f64::MAX, "1.7976931348623157e308"),
            (f64::MIN_POSITIVE, "2.2250738585072014e-308"),
        ];
        for (x, text) in cases {
            assert_eq!(Compact(x).to_string(), text, "{x:?}");
            // Exact: the text reads back as the same number.
            if x.is_finite() {
                assert_eq!(text.parse::<f64>().ok(), Some(x), "{text}");
            }
        }
    }
}
