//! A multirotor's frame: its rotor table, the one place its geometry is written.
//!
//! A frame is a list of rotors (like ArduPilot's SIM_Frame motor tables and PX4's
//! `CA_ROTORn_*` parameters): each rotor's position, its spin and, where it differs from the
//! vehicle's, its own thrust coefficient, torque coefficient and motor time constant; a
//! rotor that gives none takes the vehicle's (`QuadrotorParams::thrust_coefficient`,
//! `yaw_torque_coefficient`, `motor_time_constant`), so the parameters stay one table and
//! randomising them moves every rotor. Positions are body FLU (x forward, y left) in units of
//! `arm_length`, so the vehicle's size stays one parameter; a frame in metres is the same
//! table with `arm_length = 1`. Every rotor pushes along body +z.
//!
//! The shipped frames list their rotors in PX4's motor order for the matching airframe
//! (`CA_ROTORn`, mirrored from PX4's FRD to FLU), so PX4 output n drives rotor n:
//! `quad_x` (PX4's 10016 Iris order: front-right, rear-left, front-left, rear-right),
//! `quad_plus` (5001), `hexa_x` (6001) and `octo_x` (8001).

use super::mixing::Mixing;
pub use super::rotor::{MAX_ROTORS, Rotor, Spin};
use serde::{Deserialize, Serialize};
use std::fmt;
use std::sync::Arc;

/// A frame as written: a name and its rotors, in motor order. This is what a config file
/// holds (`[frame]` with `name` and one `[[frame.rotor]]` per rotor).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FrameTable {
    pub name: String,
    #[serde(rename = "rotor")]
    pub rotors: Vec<Rotor>,
}

/// Why a frame table was refused: each names the rotor and the field, and the bound.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum FrameError {
    #[error("frame `{frame}` has {count} rotors: a frame needs 4 to {MAX_ROTORS}")]
    RotorCount { frame: String, count: usize },
    #[error("frame `{frame}`, rotor {rotor}: `{field}` = {value} is not a finite number")]
    NotFinite {
        frame: String,
        rotor: usize,
        field: &'static str,
        value: f64,
    },
    #[error(
        "frame `{frame}`, rotor {rotor}: `{field}` = {value} is out of range: it must be in [{min}, {max}]{unit}"
    )]
    OutOfRange {
        frame: String,
        rotor: usize,
        field: &'static str,
        value: f64,
        min: f64,
        max: f64,
        unit: &'static str,
    },
    #[error(
        "frame `{frame}`, rotor {rotor}: at the centre (x = 0, y = 0) it has no torque arm; move it out along `x` or `y`"
    )]
    AtCentre { frame: String, rotor: usize },
    #[error(
        "frame `{frame}` cannot control {axis}: its rotors' {axis} torques do not balance and steer independently of the other axes"
    )]
    Uncontrollable { frame: String, axis: &'static str },
    #[error("unknown frame `{0}`: the shipped frames are quad_x, quad_plus, hexa_x, octo_x")]
    Unknown(String),
    #[error("invalid frame file: {0}")]
    Parse(String),
}

/// A checked frame: its table and the sums the dynamics evaluate (derived from it once).
#[derive(Clone, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "FrameTable", into = "FrameTable")]
pub struct Frame {
    // Shared between clones: a frame is ~1.3 kB and every env holds several copies (the
    // vehicle's, the nominal parameters', ...), which put 100,000 envs past 1 GB.
    shared: Arc<FrameParts>,
}

/// What a frame holds, never changed once checked.
#[derive(PartialEq)]
struct FrameParts {
    table: FrameTable,
    mixing: Mixing,
}

impl fmt::Debug for Frame {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        self.shared.table.fmt(f)
    }
}

impl Default for Frame {
    /// `quad_x`, the Iris the project flew before frames existed.
    fn default() -> Self {
        Frame::quad_x()
    }
}

impl TryFrom<FrameTable> for Frame {
    type Error = FrameError;

    fn try_from(table: FrameTable) -> Result<Self, FrameError> {
        Frame::new(table)
    }
}

impl From<Frame> for FrameTable {
    fn from(frame: Frame) -> Self {
        frame.shared.table.clone()
    }
}

const FRAC_1_SQRT_2: f64 = std::f64::consts::FRAC_1_SQRT_2;
/// √3/2 and ½: a hexa's rotors at 30° from an axis.
const SIN_60: f64 = 0.866_025_403_784_438_6;
/// cos and sin of 22.5°: an octo's rotors.
const COS_22_5: f64 = 0.923_879_532_511_286_7;
const SIN_22_5: f64 = 0.382_683_432_365_089_8;

/// The shipped frames: (name, rotors in PX4's motor order).
const SHIPPED: [(&str, &[Rotor]); 4] = [
    (
        "quad_x",
        &[
            Rotor::at(FRAC_1_SQRT_2, -FRAC_1_SQRT_2, Spin::Ccw),
            Rotor::at(-FRAC_1_SQRT_2, FRAC_1_SQRT_2, Spin::Ccw),
            Rotor::at(FRAC_1_SQRT_2, FRAC_1_SQRT_2, Spin::Cw),
            Rotor::at(-FRAC_1_SQRT_2, -FRAC_1_SQRT_2, Spin::Cw),
        ],
    ),
    (
        "quad_plus",
        &[
            Rotor::at(0.0, -1.0, Spin::Ccw),
            Rotor::at(0.0, 1.0, Spin::Ccw),
            Rotor::at(1.0, 0.0, Spin::Cw),
            Rotor::at(-1.0, 0.0, Spin::Cw),
        ],
    ),
    (
        "hexa_x",
        &[
            Rotor::at(0.0, -1.0, Spin::Cw),
            Rotor::at(0.0, 1.0, Spin::Ccw),
            Rotor::at(SIN_60, 0.5, Spin::Cw),
            Rotor::at(-SIN_60, -0.5, Spin::Ccw),
            Rotor::at(SIN_60, -0.5, Spin::Ccw),
            Rotor::at(-SIN_60, 0.5, Spin::Cw),
        ],
    ),
    (
        "octo_x",
        &[
            Rotor::at(COS_22_5, -SIN_22_5, Spin::Cw),
            Rotor::at(-COS_22_5, SIN_22_5, Spin::Cw),
            Rotor::at(SIN_22_5, -COS_22_5, Spin::Ccw),
            Rotor::at(-COS_22_5, -SIN_22_5, Spin::Ccw),
            Rotor::at(COS_22_5, SIN_22_5, Spin::Ccw),
            Rotor::at(-SIN_22_5, COS_22_5, Spin::Ccw),
            Rotor::at(SIN_22_5, COS_22_5, Spin::Cw),
            Rotor::at(-SIN_22_5, -COS_22_5, Spin::Cw),
        ],
    ),
];

/// Names of the shipped frames, in order.
pub fn shipped_names() -> impl Iterator<Item = &'static str> {
    SHIPPED.iter().map(|(name, _)| *name)
}

impl Frame {
    /// A frame from its table, checked: 4 to [`MAX_ROTORS`] rotors, finite positions within
    /// 100 arm lengths, none at the centre, coefficients inside the vehicle parameters'
    /// bounds, and rotors that steer roll, pitch, yaw and thrust independently.
    pub fn new(table: FrameTable) -> Result<Self, FrameError> {
        check_table(&table)?;
        let mixing = Mixing::new(&table.rotors).map_err(|axis| FrameError::Uncontrollable {
            frame: table.name.clone(),
            axis,
        })?;
        Ok(Frame {
            shared: Arc::new(FrameParts { table, mixing }),
        })
    }

    /// A shipped frame by name: `quad_x`, `quad_plus`, `hexa_x`, `octo_x`.
    pub fn named(name: &str) -> Result<Self, FrameError> {
        let (name, rotors) = SHIPPED
            .iter()
            .find(|(n, _)| *n == name)
            .ok_or_else(|| FrameError::Unknown(name.to_string()))?;
        Frame::new(FrameTable {
            name: name.to_string(),
            rotors: rotors.to_vec(),
        })
    }

    /// The quad X (PX4's motor order; the frame of `QuadrotorParams::default()`).
    pub fn quad_x() -> Self {
        // A shipped frame always passes its own checks (a test builds each).
        Frame::named("quad_x").unwrap_or_else(|_| unreachable!("quad_x is shipped"))
    }

    /// A frame from TOML: either `name = "hexa_x"` (a shipped frame) or a whole table
    /// (`name` and one `[[rotor]]` per rotor).
    pub fn from_toml_str(text: &str) -> Result<Self, FrameError> {
        let value: toml::Table =
            toml::from_str(text).map_err(|e| FrameError::Parse(e.to_string()))?;
        Frame::from_toml_table(value)
    }

    /// [`Frame::from_toml_str`] for an already parsed table (a config file's `[frame]`).
    pub fn from_toml_table(value: toml::Table) -> Result<Self, FrameError> {
        if value.len() == 1
            && let Some(toml::Value::String(name)) = value.get("name")
        {
            return Frame::named(name);
        }
        let table: FrameTable =
            FrameTable::deserialize(value).map_err(|e| FrameError::Parse(e.to_string()))?;
        Frame::new(table)
    }

    pub fn name(&self) -> &str {
        &self.shared.table.name
    }

    /// The rotors, in motor order.
    pub fn rotors(&self) -> &[Rotor] {
        &self.shared.table.rotors
    }

    pub fn rotor_count(&self) -> usize {
        self.shared.table.rotors.len()
    }

    pub fn table(&self) -> &FrameTable {
        &self.shared.table
    }

    pub(crate) fn mixing(&self) -> &Mixing {
        &self.shared.mixing
    }

    /// Whether this is the quad X the project flew before frames existed (same table).
    pub fn is_quad_x(&self) -> bool {
        self.shared.table.rotors == SHIPPED[0].1
    }
}

/// Bounds of a rotor's own coefficients: the vehicle parameters' bounds (params.rs).
const COEFFICIENT_BOUNDS: [(&str, f64, f64, &str); 3] = [
    ("thrust_coefficient", 0.0, 1e6, " N"),
    ("torque_coefficient", 0.0, 10.0, " m"),
    ("time_constant", 1e-4, 10.0, " s"),
];

fn check_table(table: &FrameTable) -> Result<(), FrameError> {
    let count = table.rotors.len();
    if !(4..=MAX_ROTORS).contains(&count) {
        return Err(FrameError::RotorCount {
            frame: table.name.clone(),
            count,
        });
    }
    for (rotor, r) in table.rotors.iter().enumerate() {
        // One value of rotor `rotor`: finite, then inside [min, max].
        let check = |field, value: f64, min, max, unit| {
            let frame = table.name.clone();
            if !value.is_finite() {
                Err(FrameError::NotFinite {
                    frame,
                    rotor,
                    field,
                    value,
                })
            } else if !(min..=max).contains(&value) {
                Err(FrameError::OutOfRange {
                    frame,
                    rotor,
                    field,
                    value,
                    min,
                    max,
                    unit,
                })
            } else {
                Ok(())
            }
        };
        check("x", r.x, -100.0, 100.0, " arm lengths")?;
        check("y", r.y, -100.0, 100.0, " arm lengths")?;
        if r.x == 0.0 && r.y == 0.0 {
            return Err(FrameError::AtCentre {
                frame: table.name.clone(),
                rotor,
            });
        }
        let own = [r.thrust_coefficient, r.torque_coefficient, r.time_constant];
        for ((field, min, max, unit), value) in COEFFICIENT_BOUNDS.into_iter().zip(own) {
            if let Some(value) = value {
                check(field, value, min, max, unit)?;
            }
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_shipped_frame_builds_and_balances_its_spins() {
        for name in shipped_names() {
            let f = Frame::named(name).unwrap();
            let spin: f64 = f.rotors().iter().map(|r| r.spin.sign()).sum();
            assert_eq!(spin, 0.0, "{name}");
            let (x, y): (f64, f64) = f
                .rotors()
                .iter()
                .fold((0.0, 0.0), |(x, y), r| (x + r.x, y + r.y));
            assert!(x.abs() < 1e-12 && y.abs() < 1e-12, "{name}: {x} {y}");
        }
        assert_eq!(Frame::named("hexa_x").unwrap().rotor_count(), 6);
        assert_eq!(Frame::named("octo_x").unwrap().rotor_count(), 8);
        assert!(Frame::default().is_quad_x());
    }

    #[test]
    fn bad_tables_are_refused_naming_the_rotor_and_the_field() {
        let quad = || Frame::quad_x().table().clone();
        let refused = |edit: &dyn Fn(&mut FrameTable)| {
            let mut t = quad();
            edit(&mut t);
            Frame::new(t).unwrap_err().to_string()
        };
        let e = refused(&|t| t.rotors.clear());
        assert_eq!(e, "frame `quad_x` has 0 rotors: a frame needs 4 to 12");
        let e = refused(&|t| t.rotors[2].y = f64::NAN);
        assert_eq!(
            e,
            "frame `quad_x`, rotor 2: `y` = NaN is not a finite number"
        );
        let e = refused(&|t| (t.rotors[1].x, t.rotors[1].y) = (0.0, 0.0));
        assert!(
            e.starts_with("frame `quad_x`, rotor 1: at the centre"),
            "{e}"
        );
        let e = refused(&|t| t.rotors[3].thrust_coefficient = Some(f64::INFINITY));
        assert!(e.contains("rotor 3: `thrust_coefficient` = inf"), "{e}");
        let e = refused(&|t| t.rotors[0].time_constant = Some(0.0));
        assert!(
            e.contains(
                "rotor 0: `time_constant` = 0 is out of range: it must be in [0.0001, 10] s"
            ),
            "{e}"
        );
        // Every rotor turning the same way: nothing balances yaw.
        let e = refused(&|t| t.rotors.iter_mut().for_each(|r| r.spin = Spin::Cw));
        assert_eq!(
            e,
            "frame `quad_x` cannot control yaw: its rotors' yaw torques do not balance and steer independently of the other axes"
        );
        // Four rotors on one line: no roll authority.
        let e = refused(&|t| t.rotors.iter_mut().for_each(|r| r.y = 0.0));
        assert!(e.contains("cannot control roll"), "{e}");
        assert!(matches!(Frame::named("tri"), Err(FrameError::Unknown(_))));
    }

    #[test]
    fn frames_load_from_toml_by_name_or_in_full() {
        let f = Frame::from_toml_str("name = \"octo_x\"").unwrap();
        assert_eq!(f.rotor_count(), 8);
        let text = r#"
            name = "wide_quad"
            [[rotor]]
            x = 0.5
            y = -1.0
            spin = "ccw"
            thrust_coefficient = 11.0
            [[rotor]]
            x = -0.5
            y = 1.0
            spin = "ccw"
            [[rotor]]
            x = 0.5
            y = 1.0
            spin = "cw"
            [[rotor]]
            x = -0.5
            y = -1.0
            spin = "cw"
            time_constant = 0.05
        "#;
        let f = Frame::from_toml_str(text).unwrap();
        assert_eq!(f.name(), "wide_quad");
        assert_eq!(f.rotors()[0].thrust_coefficient, Some(11.0));
        assert_eq!(f.rotors()[3].time_constant, Some(0.05));
        let e = Frame::from_toml_str("name = \"x\"\n[[rotor]]\nx = 1\ny = 0\nspin = \"up\"")
            .unwrap_err();
        assert!(e.to_string().starts_with("invalid frame file"), "{e}");
        let e = Frame::from_toml_str("name = \"x\"\n[[rotor]]\nx = 1\ny = 0\nspin = \"cw\"\nk = 1")
            .unwrap_err();
        assert!(e.to_string().contains("unknown field `k`"), "{e}");
    }

    #[test]
    fn a_frame_round_trips_through_serde_and_is_checked_on_the_way_in() {
        let f = Frame::named("hexa_x").unwrap();
        let json = serde_json::to_string(&f).unwrap();
        let back: Frame = serde_json::from_str(&json).unwrap();
        assert_eq!(back, f);
        let broken = json.replacen("\"x\":0.0", "\"x\":1e300", 1);
        assert!(serde_json::from_str::<Frame>(&broken).is_err());
    }
}
