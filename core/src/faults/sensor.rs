//! The sensor path: what an active sensor fault does to a sample after the sensor model made
//! it. Order: the delay picks an older sample, a stuck sensor repeats the one it had when it
//! stuck, the bias (and its drift) is added, the extra noise, and an off sensor gives nothing.

use super::catalogue::{FaultKind, SensorId};
use super::spec::FaultSpec;
use crate::rng::SimRng;
use nalgebra::Vector3;
use serde::{Deserialize, Serialize};
use std::collections::VecDeque;

/// Samples kept until they are old enough to deliver.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct DelayLine<T> {
    samples: VecDeque<(f64, T)>,
}

impl<T> Default for DelayLine<T> {
    fn default() -> Self {
        DelayLine {
            samples: VecDeque::new(),
        }
    }
}

impl<T: Clone> DelayLine<T> {
    /// Stores `sample` taken at `time` and returns the newest one at least `delay` old (none
    /// yet: nothing).
    pub fn push(&mut self, time: f64, sample: T, delay: f64) -> Option<T> {
        self.samples.push_back((time, sample));
        let due = time - delay + 1e-9;
        let mut out = None;
        while let Some((t, _)) = self.samples.front() {
            if *t > due {
                break;
            }
            out = self.samples.pop_front().map(|(_, s)| s);
        }
        if let Some(s) = &out {
            // Keep the delivered sample as the oldest, so the next call can repeat it.
            self.samples.push_front((f64::NEG_INFINITY, s.clone()));
        }
        out
    }
}

/// A sensor fault in effect: its spec and when it fired.
#[derive(Debug, Clone, Copy)]
pub struct ActiveFault<'f> {
    pub spec: &'f FaultSpec,
    pub fired: f64,
}

/// One sensor's fault state: its delay line and its stuck sample.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct SensorChannel {
    delay: DelayLine<Vector3<f64>>,
    stuck: Option<Vector3<f64>>,
}

impl SensorChannel {
    /// `value` (sampled at `time`, the sensor's own noise of standard deviation `sigma`)
    /// through the active faults of `sensor`; `None` when the sensor gives nothing.
    pub fn apply(
        &mut self,
        sensor: SensorId,
        faults: &[ActiveFault<'_>],
        value: Vector3<f64>,
        time: f64,
        sigma: f64,
        rng: &mut SimRng,
    ) -> Option<Vector3<f64>> {
        let mine = || faults.iter().filter(move |f| f.spec.sensor == Some(sensor));
        let mut out = value;
        let mut off = false;
        let mut stuck = false;
        for f in mine() {
            if f.spec.kind == FaultKind::SensorDelay {
                let delay = f.spec.values[0];
                out = self.delay.push(time, value, delay)?;
            }
        }
        for f in mine() {
            let s = f.spec;
            match s.kind {
                FaultKind::SensorStuck => {
                    stuck = true;
                    out = *self.stuck.get_or_insert(out);
                }
                FaultKind::SensorBias => {
                    let b = s.values[0] + s.values[1] * (time - f.fired);
                    out += Vector3::repeat(b);
                }
                FaultKind::SensorNoise => {
                    let extra = sigma * (s.values[0] * s.values[0] - 1.0).sqrt();
                    if extra > 0.0 {
                        out += Vector3::new(rng.normal(), rng.normal(), rng.normal()) * extra;
                    }
                }
                FaultKind::SensorOff => off = true,
                _ => {}
            }
        }
        if !stuck {
            self.stuck = None;
        }
        (!off).then_some(out)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::faults::catalogue::FaultKind;

    fn fault(kind: FaultKind, values: &[(&str, f64)]) -> FaultSpec {
        let mut f = FaultSpec::new(kind);
        f.sensor = Some(SensorId::Baro);
        for (k, v) in values {
            f.set(k, *v).unwrap();
        }
        f
    }

    #[test]
    fn off_stuck_bias_drift_noise_and_delay_change_the_sample_as_specified() {
        let mut rng = SimRng::new(1);
        let v = |x: f64| Vector3::new(x, 0.0, 0.0);
        let run = |faults: &[ActiveFault<'_>], rng: &mut SimRng| {
            let mut ch = SensorChannel::default();
            (0..5)
                .map(|i| {
                    ch.apply(
                        SensorId::Baro,
                        faults,
                        v(i as f64),
                        i as f64 * 0.1,
                        0.5,
                        rng,
                    )
                })
                .collect::<Vec<_>>()
        };
        let off = fault(FaultKind::SensorOff, &[]);
        assert!(
            run(
                &[ActiveFault {
                    spec: &off,
                    fired: 0.0
                }],
                &mut rng
            )
            .iter()
            .all(Option::is_none)
        );
        let stuck = fault(FaultKind::SensorStuck, &[]);
        let out = run(
            &[ActiveFault {
                spec: &stuck,
                fired: 0.0,
            }],
            &mut rng,
        );
        assert!(out.iter().all(|o| *o == Some(v(0.0))));
        let bias = fault(FaultKind::SensorBias, &[("bias", 2.0), ("drift", 10.0)]);
        let out = run(
            &[ActiveFault {
                spec: &bias,
                fired: 0.0,
            }],
            &mut rng,
        );
        // Sample i at t = 0.1 i: i + 2 + 10 · 0.1 i = 2 + 2 i.
        for (i, o) in out.iter().enumerate() {
            assert!((o.unwrap().x - (2.0 + 2.0 * i as f64)).abs() < 1e-12);
        }
        let delay = fault(FaultKind::SensorDelay, &[("delay", 0.2)]);
        let out = run(
            &[ActiveFault {
                spec: &delay,
                fired: 0.0,
            }],
            &mut rng,
        );
        assert_eq!(out[..2], [None, None]);
        assert_eq!(out[2..], [Some(v(0.0)), Some(v(1.0)), Some(v(2.0))]);
        // Noise × 3 on σ = 0.5: the added noise has σ·√8 ≈ 1.414.
        let noise = fault(FaultKind::SensorNoise, &[("factor", 3.0)]);
        let mut ch = SensorChannel::default();
        let n = 20_000;
        let sq: f64 = (0..n)
            .map(|_| {
                let o = ch.apply(
                    SensorId::Baro,
                    &[ActiveFault {
                        spec: &noise,
                        fired: 0.0,
                    }],
                    v(0.0),
                    0.0,
                    0.5,
                    &mut rng,
                );
                o.unwrap().x.powi(2)
            })
            .sum();
        let std = (sq / n as f64).sqrt();
        assert!((std - 0.5 * 8f64.sqrt()).abs() < 0.03, "{std}");
        // Another sensor's fault leaves this one alone.
        let mut gyro_off = off.clone();
        gyro_off.sensor = Some(SensorId::Gyro);
        let out = run(
            &[ActiveFault {
                spec: &gyro_off,
                fired: 0.0,
            }],
            &mut rng,
        );
        assert_eq!(out[3], Some(v(3.0)));
    }
}
