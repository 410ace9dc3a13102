//! Table-driven parameters: one [`ParamSpec`] row per field gives its name, unit, bounds and
//! description. Validation, name-based get/set (the SITL's parameter protocol), the FMU's
//! modelDescription and the parameter reference (docs/parameters.md) all read the same rows.

use crate::error::{ParamError, Role};
use serde::Serialize;
use serde::de::DeserializeOwned;

/// The value type of a parameter or variable, as FMI 2.0 knows them.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ValueKind {
    Real,
    Integer,
    Boolean,
}

/// One row of a parameter table. All bounds are inclusive; values travel as `f64`
/// (integers and booleans are exact in an `f64`).
pub struct ParamSpec<P> {
    pub name: &'static str,
    pub unit: &'static str,
    pub kind: ValueKind,
    pub min: f64,
    pub max: f64,
    pub description: &'static str,
    pub get: fn(&P) -> f64,
    pub set: fn(&mut P, f64),
}

impl<P> std::fmt::Debug for ParamSpec<P> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("ParamSpec")
            .field("name", &self.name)
            .field("unit", &self.unit)
            .field("kind", &self.kind)
            .field("min", &self.min)
            .field("max", &self.max)
            .finish()
    }
}

impl<P> ParamSpec<P> {
    /// Checks one value against this row's kind and bounds.
    pub fn check(&self, value: f64) -> Result<(), ParamError> {
        if !(value >= self.min && value <= self.max) {
            return Err(ParamError::OutOfRange {
                role: Role::Parameter,
                name: self.name,
                value,
                min: self.min,
                max: self.max,
                unit: self.unit,
            });
        }
        let expected = match self.kind {
            ValueKind::Real => return Ok(()),
            ValueKind::Integer => "an integer",
            ValueKind::Boolean => "a boolean (0 or 1)",
        };
        if value.fract() != 0.0 {
            return Err(ParamError::WrongKind {
                name: self.name,
                value,
                expected,
            });
        }
        Ok(())
    }
}

fn not_a_number(name: &'static str) -> ParamError {
    ParamError::Parse(format!("parameter `{name}` must be a number or a boolean"))
}

/// A parameter struct described by a table of [`ParamSpec`] rows.
///
/// `Default` gives the documented defaults. Files are read through the table, not through
/// serde, so every error names its parameter; serde is for saving whole states.
pub trait Parameters: Sized + Clone + Default + Serialize + DeserializeOwned + 'static {
    /// The table, one row per field.
    fn specs() -> &'static [ParamSpec<Self>];

    /// Relations between fields that single-row bounds cannot express.
    fn check_relations(&self) -> Result<(), ParamError> {
        Ok(())
    }

    /// Every field within its bounds and every relation holding.
    fn validate(&self) -> Result<(), ParamError> {
        for spec in Self::specs() {
            spec.check((spec.get)(self))?;
        }
        self.check_relations()
    }

    /// The row of parameter `name`.
    fn spec(name: &str) -> Result<&'static ParamSpec<Self>, ParamError> {
        Self::specs()
            .iter()
            .find(|s| s.name == name)
            .ok_or_else(|| ParamError::UnknownName(name.to_string()))
    }

    /// Value of parameter `name`.
    fn get(&self, name: &str) -> Result<f64, ParamError> {
        Ok((Self::spec(name)?.get)(self))
    }

    /// Sets parameter `name` if the result is valid; on error `self` is unchanged.
    fn set(&mut self, name: &str, value: f64) -> Result<(), ParamError> {
        let spec = Self::spec(name)?;
        spec.check(value)?;
        let mut candidate = self.clone();
        (spec.set)(&mut candidate, value);
        candidate.check_relations()?;
        *self = candidate;
        Ok(())
    }

    /// Starts from the defaults and applies `(name, value)` pairs, each checked against its
    /// row; relations are checked once all are applied. Unknown names are an error.
    fn from_values<'a>(
        values: impl IntoIterator<Item = (&'a str, f64)>,
    ) -> Result<Self, ParamError> {
        let mut params = Self::default();
        for (name, value) in values {
            let spec = Self::spec(name)?;
            spec.check(value)?;
            (spec.set)(&mut params, value);
        }
        params.check_relations()?;
        Ok(params)
    }

    /// Parses and validates a flat TOML table (missing keys keep their defaults).
    fn from_toml_str(text: &str) -> Result<Self, ParamError> {
        let table: toml::Table = toml::from_str(text)?;
        let mut values = Vec::with_capacity(table.len());
        for (name, value) in &table {
            let number = match value {
                toml::Value::Integer(i) => *i as f64,
                toml::Value::Float(x) => *x,
                toml::Value::Boolean(b) => f64::from(u8::from(*b)),
                _ => return Err(not_a_number(Self::spec(name)?.name)),
            };
            values.push((name.as_str(), number));
        }
        Self::from_values(values)
    }

    /// Parses and validates a flat JSON object (missing keys keep their defaults).
    fn from_json_str(text: &str) -> Result<Self, ParamError> {
        let object: serde_json::Map<String, serde_json::Value> = serde_json::from_str(text)?;
        let mut values = Vec::with_capacity(object.len());
        for (name, value) in &object {
            let number = match value {
                serde_json::Value::Number(n) => n.as_f64(),
                serde_json::Value::Bool(b) => Some(f64::from(u8::from(*b))),
                _ => None,
            };
            let number = number.ok_or_else(|| match Self::spec(name) {
                Ok(spec) => not_a_number(spec.name),
                Err(e) => e,
            })?;
            values.push((name.as_str(), number));
        }
        Self::from_values(values)
    }

    /// The table as a flat TOML document with every value (a starting point for a config file).
    fn to_toml_string(&self) -> String {
        let mut out = String::new();
        for s in Self::specs() {
            let v = (s.get)(self);
            let text = match s.kind {
                ValueKind::Boolean => (v != 0.0).to_string(),
                ValueKind::Integer => format!("{}", v as i64),
                ValueKind::Real => format!("{v:?}"),
            };
            out.push_str(&format!("{} = {}\n", s.name, text));
        }
        out
    }

    /// The table as Markdown (name, unit, default, range, description), for docs/parameters.md.
    fn markdown_table() -> String {
        let defaults = Self::default();
        let mut out = String::from(
            "| name | unit | default | range | description |\n|---|---|---|---|---|\n",
        );
        for s in Self::specs() {
            let range = match s.kind {
                ValueKind::Boolean => "0 / 1".to_string(),
                _ => format!("[{}, {}]", s.min, s.max),
            };
            out.push_str(&format!(
                "| `{}` | {} | {} | {} | {} |\n",
                s.name,
                s.unit,
                (s.get)(&defaults),
                range,
                // A bare | would end the table cell.
                s.description.replace('|', "\\|")
            ));
        }
        out
    }
}

/// Builds a [`ParamSpec`] row for a field.
///
/// `param!(real field, "unit", min, max, "description")`, likewise `integer` (any integer
/// field type) and `boolean` (a `bool` field, 0/1 as `f64`).
#[macro_export]
macro_rules! param {
    (real $field:ident, $unit:expr, $min:expr, $max:expr, $doc:expr) => {
        $crate::params::ParamSpec {
            name: stringify!($field),
            unit: $unit,
            kind: $crate::params::ValueKind::Real,
            min: $min,
            max: $max,
            description: $doc,
            get: |p| p.$field,
            set: |p, v| p.$field = v,
        }
    };
    (integer $field:ident, $unit:expr, $min:expr, $max:expr, $doc:expr) => {
        $crate::params::ParamSpec {
            name: stringify!($field),
            unit: $unit,
            kind: $crate::params::ValueKind::Integer,
            min: $min as f64,
            max: $max as f64,
            description: $doc,
            get: |p| p.$field as f64,
            set: |p, v| p.$field = v as _,
        }
    };
    (boolean $field:ident, $doc:expr) => {
        $crate::params::ParamSpec {
            name: stringify!($field),
            unit: "",
            kind: $crate::params::ValueKind::Boolean,
            min: 0.0,
            max: 1.0,
            description: $doc,
            get: |p| if p.$field { 1.0 } else { 0.0 },
            set: |p, v| p.$field = v != 0.0,
        }
    };
}

/// Shared checks every parameter table must pass; called from each model's tests.
#[cfg(test)]
pub(crate) fn assert_table_is_consistent<P: Parameters + std::fmt::Debug>() {
    let defaults = P::default();
    defaults.validate().expect("defaults must validate");
    let mut names = std::collections::HashSet::new();
    for spec in P::specs() {
        assert!(names.insert(spec.name), "duplicate parameter {}", spec.name);
        assert!(spec.min <= spec.max, "{}: min > max", spec.name);
        assert!(
            !spec.description.is_empty(),
            "{}: no description",
            spec.name
        );
        // Every row reads and writes its own field.
        let mut p = defaults.clone();
        let probe = if spec.kind == ValueKind::Boolean {
            1.0 - (spec.get)(&p)
        } else if spec.max > (spec.get)(&p) {
            spec.max
        } else {
            spec.min
        };
        (spec.set)(&mut p, probe);
        assert_eq!((spec.get)(&p), probe, "{} does not round-trip", spec.name);
    }
    // serde and the table agree on the field set: a TOML round trip keeps every value.
    let text = defaults.to_toml_string();
    let back = P::from_toml_str(&text).expect("parse own output");
    for spec in P::specs() {
        assert_eq!((spec.get)(&back), (spec.get)(&defaults), "{}", spec.name);
    }
}

/// Asserts that each parameter's bounds are enforced with an error naming it.
#[cfg(test)]
pub(crate) fn assert_every_bound_is_enforced<P: Parameters>() {
    for spec in P::specs() {
        let mut bad_values = vec![f64::NAN];
        if spec.min > f64::MIN {
            bad_values.push(spec.min - spec.min.abs().max(1.0));
        }
        if spec.max < f64::MAX {
            bad_values.push(spec.max + spec.max.abs().max(1.0));
        }
        for bad in bad_values {
            let mut p = P::default();
            let err = p.set(spec.name, bad).expect_err(spec.name);
            assert!(
                err.to_string().contains(spec.name),
                "error for {} does not name it: {err}",
                spec.name
            );
            // The same through a file: refused, naming the parameter.
            if bad.is_finite() {
                let mut doc = serde_json::to_value(P::default()).expect("to json");
                doc[spec.name] = serde_json::json!(bad);
                let text = doc.to_string();
                if let Err(e) = P::from_json_str(&text) {
                    assert!(
                        e.to_string().contains(spec.name),
                        "file error for {} does not name it: {e}",
                        spec.name
                    );
                } else {
                    panic!("{} = {bad} accepted from a file", spec.name);
                }
            }
        }
    }
}
