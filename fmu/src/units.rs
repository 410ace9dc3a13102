//! SI base-unit exponents of every unit string the core's tables use, for the
//! modelDescription's UnitDefinitions (an importer converts units through them).

/// Exponents of kg, m, s, A, K, mol, cd, rad.
pub type Exponents = [i32; 8];

/// Attribute names of `Exponents`, in order (fmi2ModelDescription BaseUnit).
pub const BASE_UNITS: [&str; 8] = ["kg", "m", "s", "A", "K", "mol", "cd", "rad"];

/// Known units. `None`: no integer-exponent base unit (m/s/s0.5), so no BaseUnit element.
static UNITS: &[(&str, Option<Exponents>)] = &[
    ("1", Some([0, 0, 0, 0, 0, 0, 0, 0])),
    ("m", Some([0, 1, 0, 0, 0, 0, 0, 0])),
    ("1/m", Some([0, -1, 0, 0, 0, 0, 0, 0])),
    ("s/m", Some([0, -1, 1, 0, 0, 0, 0, 0])),
    ("m2", Some([0, 2, 0, 0, 0, 0, 0, 0])),
    ("s", Some([0, 0, 1, 0, 0, 0, 0, 0])),
    ("1/s", Some([0, 0, -1, 0, 0, 0, 0, 0])),
    ("Hz", Some([0, 0, -1, 0, 0, 0, 0, 0])),
    ("m/s", Some([0, 1, -1, 0, 0, 0, 0, 0])),
    ("1/s2", Some([0, 0, -2, 0, 0, 0, 0, 0])),
    ("m/s2", Some([0, 1, -2, 0, 0, 0, 0, 0])),
    ("kg", Some([1, 0, 0, 0, 0, 0, 0, 0])),
    ("kg/m3", Some([1, -3, 0, 0, 0, 0, 0, 0])),
    ("kg.m2", Some([1, 2, 0, 0, 0, 0, 0, 0])),
    ("N", Some([1, 1, -2, 0, 0, 0, 0, 0])),
    ("N/m", Some([1, 0, -2, 0, 0, 0, 0, 0])),
    ("N.s/m", Some([1, 0, -1, 0, 0, 0, 0, 0])),
    ("N.s/m2", Some([1, -1, -1, 0, 0, 0, 0, 0])),
    ("1/(N.s)", Some([-1, -1, 1, 0, 0, 0, 0, 0])),
    ("rad", Some([0, 0, 0, 0, 0, 0, 0, 1])),
    ("rad/s", Some([0, 0, -1, 0, 0, 0, 0, 1])),
    ("deg/s", Some([0, 0, -1, 0, 0, 0, 0, 1])),
    ("rad/s2", Some([0, 0, -2, 0, 0, 0, 0, 1])),
    ("N.m.s/rad", Some([1, 2, -1, 0, 0, 0, 0, -1])),
    ("N.m.s2/rad2", Some([1, 2, 0, 0, 0, 0, 0, -2])),
    ("m/s/s0.5", None),
];

/// Factor from a unit to its base units where it is not 1 (PX4's deg/s rate bounds).
pub fn factor(unit: &str) -> Option<f64> {
    (unit == "deg/s").then_some(std::f64::consts::PI / 180.0)
}

/// The base-unit exponents of `unit`: `None` if the unit is unknown, `Some(None)` if it
/// has no integer-exponent form.
pub fn exponents(unit: &str) -> Option<Option<Exponents>> {
    UNITS.iter().find(|(u, _)| *u == unit).map(|(_, e)| *e)
}
