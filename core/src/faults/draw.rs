//! Faults drawn per episode: which fault (from a list of kinds), when (a time range), on
//! which motor or sensor, how strong (a range per parameter) and whether at all (a
//! probability) — from a generator seeded by the episode's seed, like domain randomisation,
//! so the same seed gives the same faults in every front end.

use super::catalogue::{FaultKind, SensorId, Target};
use super::spec::{FaultSpec, MAX_MOTOR};
use super::trigger::{Reach, Trigger};
use crate::error::{ParamError, Role};
use crate::rng::SimRng;
use serde::{Deserialize, Serialize};

/// One drawn fault slot (`[[fault_randomization]]`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FaultDraw {
    /// The kinds one is drawn from, uniformly.
    pub kinds: Vec<FaultKind>,
    /// Chance that an episode has the fault, in [0, 1]. Default 1.
    pub probability: f64,
    /// Range of the firing time, s. Default [0, 0].
    pub at: (f64, f64),
    /// Range of the motor instance (PX4's numbering, inclusive); `None`: every single
    /// motor of the frame (1..=rotors).
    pub motor: Option<(u8, u8)>,
    /// Sensors one is drawn from (sensor kinds); default all.
    pub sensors: Vec<SensorId>,
    /// Ranges of the kinds' parameters, by name: (name, low, high).
    pub ranges: Vec<(String, f64, f64)>,
    /// How long the fault lasts, s (`None`: to the end).
    pub duration: Option<f64>,
}

fn pair(key: &str, value: &toml::Value) -> Result<(f64, f64), ParamError> {
    let nums: Option<Vec<f64>> = value.as_array().filter(|a| a.len() == 2).map(|a| {
        a.iter()
            .filter_map(|v| v.as_float().or(v.as_integer().map(|i| i as f64)))
            .collect()
    });
    match nums.as_deref() {
        Some(&[lo, hi]) if lo <= hi => Ok((lo, hi)),
        _ => Err(ParamError::Parse(format!(
            "fault_randomization: `{key}` must be a pair of numbers [low, high] with low <= high"
        ))),
    }
}

impl FaultDraw {
    /// A draw from its TOML table: `kinds` (a list of fault kinds), `probability`, `at`,
    /// `motor`, `sensors`, `duration`, and `[low, high]` ranges of the kinds' parameters.
    pub fn from_toml(table: &toml::Table) -> Result<FaultDraw, ParamError> {
        let mut d = FaultDraw {
            kinds: Vec::new(),
            probability: 1.0,
            at: (0.0, 0.0),
            motor: None,
            sensors: SensorId::ALL.to_vec(),
            ranges: Vec::new(),
            duration: None,
        };
        let names = |v: &toml::Value, key: &str| -> Result<Vec<String>, ParamError> {
            let list = v
                .as_array()
                .map(|a| a.iter().map(|s| s.as_str().map(String::from)).collect());
            match list {
                Some(Some(l)) => Ok(l),
                _ => Err(ParamError::Parse(format!(
                    "fault_randomization: `{key}` must be a list of names"
                ))),
            }
        };
        for (key, value) in table {
            match key.as_str() {
                "kinds" => {
                    d.kinds = names(value, key)?
                        .iter()
                        .map(|n| FaultKind::from_name(n))
                        .collect::<Result<_, _>>()?;
                }
                "sensors" => {
                    d.sensors = names(value, key)?
                        .iter()
                        .map(|n| SensorId::from_name(n))
                        .collect::<Result<_, _>>()?;
                }
                "probability" => {
                    let p = value.as_float().or(value.as_integer().map(|i| i as f64));
                    d.probability = match p {
                        Some(p) if (0.0..=1.0).contains(&p) => p,
                        _ => {
                            return Err(ParamError::OutOfRange {
                                role: Role::Parameter,
                                name: "probability",
                                value: p.unwrap_or(f64::NAN),
                                min: 0.0,
                                max: 1.0,
                                unit: "",
                            });
                        }
                    }
                }
                "at" => d.at = pair(key, value)?,
                "motor" => {
                    let (lo, hi) = pair(key, value)?;
                    let ok = |m: f64| m.fract() == 0.0 && (1.0..=f64::from(MAX_MOTOR)).contains(&m);
                    if !(ok(lo) && ok(hi)) {
                        return Err(ParamError::Parse(format!(
                            "fault_randomization: `motor` = [{lo}, {hi}] must be whole motor numbers in [1, {MAX_MOTOR}]"
                        )));
                    }
                    d.motor = Some((lo as u8, hi as u8));
                }
                "duration" => {
                    let v = value.as_float().or(value.as_integer().map(|i| i as f64));
                    d.duration = match v {
                        Some(v) if v.is_finite() && v > 0.0 => Some(v),
                        _ => {
                            return Err(ParamError::Parse(
                                "fault_randomization: `duration` must be a number > 0 (s)".into(),
                            ));
                        }
                    }
                }
                name => {
                    let (lo, hi) = pair(name, value)?;
                    d.ranges.push((name.to_string(), lo, hi));
                }
            }
        }
        if d.kinds.is_empty() {
            return Err(ParamError::Parse(
                "fault_randomization needs `kinds`: the fault kinds to draw from".into(),
            ));
        }
        if let Some(k) = d.kinds.iter().find(|k| k.spec().target == Target::Link) {
            return Err(ParamError::Parse(format!(
                "fault_randomization: `{}` cannot be drawn yet; write it as a [[faults]] entry with its time and duration",
                k.name()
            )));
        }
        if d.sensors.is_empty() {
            return Err(ParamError::Parse(
                "fault_randomization: `sensors` must name at least one sensor".into(),
            ));
        }
        // Every range must name a parameter of a kind and lie in its bounds.
        for (name, lo, hi) in &d.ranges {
            let mut known = false;
            for k in &d.kinds {
                if let Some(f) = k.spec().fields.iter().find(|f| f.name == name) {
                    known = true;
                    f.check(*lo)?;
                    f.check(*hi)?;
                }
            }
            if !known {
                let fields: Vec<&str> = (d.kinds.iter())
                    .flat_map(|k| k.spec().fields.iter().map(|f| f.name))
                    .collect();
                return Err(ParamError::UnknownName(format!(
                    "{name}` in fault_randomization: not a parameter of its kinds; parameters: `{}",
                    fields.join("`, `")
                )));
            }
        }
        Trigger::parse("at", d.at.0)?;
        Ok(d)
    }

    /// Refuses a draw the flight cannot have (a motor range past the frame, times past the
    /// episode's end).
    pub fn check(&self, reach: &Reach) -> Result<(), ParamError> {
        if let Some((_, hi)) = self.motor {
            if usize::from(hi) > reach.rotors {
                return Err(ParamError::OutOfRange {
                    role: Role::Parameter,
                    name: "motor",
                    value: f64::from(hi),
                    min: 1.0,
                    max: reach.rotors as f64,
                    unit: "",
                });
            }
        }
        Trigger::At(self.at.1).check_reachable(reach)
    }

    /// The episode's fault from `rng` (`None`: this episode has none). The draws come in a
    /// fixed order: the chance, the kind, the time, the motor, the sensor, the parameters in
    /// the kind's order.
    pub fn draw(&self, rng: &mut SimRng, rotors: usize) -> Option<FaultSpec> {
        let happens = rng.unit() < self.probability;
        let kind = self.kinds[pick(rng, self.kinds.len())];
        let at = rng.uniform(self.at.0, self.at.1);
        let (lo, hi) = self
            .motor
            .unwrap_or((1, rotors.clamp(1, usize::from(MAX_MOTOR)) as u8));
        let motor = lo + pick(rng, usize::from(hi - lo) + 1) as u8;
        let sensor = self.sensors[pick(rng, self.sensors.len())];
        let mut fault = FaultSpec::new(kind);
        fault.trigger = Trigger::At(at);
        fault.duration = self.duration;
        match kind.spec().target {
            Target::Motor => fault.motor = motor,
            Target::Sensor => fault.sensor = Some(sensor),
            Target::Vehicle | Target::Link => {}
        }
        for (i, f) in kind.spec().fields.iter().enumerate() {
            if let Some((_, lo, hi)) = self.ranges.iter().find(|(n, _, _)| n == f.name) {
                fault.values[i] = rng.uniform(*lo, *hi);
            }
        }
        happens.then_some(fault)
    }
}

/// An index in 0..n, uniform.
fn pick(rng: &mut SimRng, n: usize) -> usize {
    ((rng.unit() * n as f64) as usize).min(n.saturating_sub(1))
}
