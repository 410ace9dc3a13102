//! A flight's faults at run time: the episode's schedule, which have fired and when (the
//! event list front ends read), and the state the fault paths keep (added lags, rotor phases,
//! the battery, the sensors' delay lines and stuck samples).

use super::actuator::{LagState, acts_on, motor_commands};
use super::air::{gust, shear};
use super::battery::{Battery, BatteryParams};
use super::catalogue::{FaultKind, SensorId, Target};
use super::plan::FaultPlan;
use super::sensor::{ActiveFault, DelayLine, SensorChannel};
use super::spec::FaultSpec;
use super::trigger::Conditions;
use crate::quadrotor::frame::MAX_ROTORS;
use crate::rng::SimRng;
use crate::sensors::GpsFix;
use nalgebra::Vector3;
use serde::{Deserialize, Serialize};
use std::f64::consts::TAU;

/// Salt of the sensor faults' noise generator.
const NOISE_STREAM: u64 = 0x0fa1_7500_5e50_0004;

/// A fault firing or clearing, with its simulation time.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FaultEvent {
    /// Simulation time, s.
    pub time: f64,
    /// Slot of the schedule.
    pub slot: usize,
    /// `motor_effectiveness:2`, `sensor_off:gps`, …
    pub label: String,
    /// Fired (true) or cleared (false).
    pub fired: bool,
}

/// What the link faults in effect do to the link now.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct LinkCondition {
    /// A `link_loss` is in effect: nothing new gets through.
    pub lost: bool,
    /// Age of what the link delivers, s (the largest `link_delay` in effect; 0: none).
    pub delay: f64,
}

impl LinkCondition {
    /// Whether the link is healthy.
    pub fn is_clear(&self) -> bool {
        !self.lost && self.delay == 0.0
    }
}

/// The faults of one vehicle over an episode.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FaultState {
    plan: FaultPlan,
    rotors: usize,
    schedule: Vec<Option<FaultSpec>>,
    fired: Vec<Option<f64>>,
    cleared: Vec<bool>,
    events: Vec<FaultEvent>,
    takeoff: Option<f64>,
    lag: LagState,
    /// Angle of each rotor, rad (for the imbalance of a damaged propeller).
    phase: [f64; MAX_ROTORS],
    battery: Option<Battery>,
    channels: [SensorChannel; 5],
    gps_line: DelayLine<GpsFix>,
    gps_stuck: Option<GpsFix>,
    rng: SimRng,
}

impl FaultState {
    /// The faults of `plan` on a frame of `rotors` rotors; [`FaultState::reset`] draws an
    /// episode's schedule.
    pub fn new(plan: FaultPlan, rotors: usize) -> Self {
        let mut s = FaultState {
            plan,
            rotors,
            schedule: Vec::new(),
            fired: Vec::new(),
            cleared: Vec::new(),
            events: Vec::new(),
            takeoff: None,
            lag: LagState::default(),
            phase: [0.0; MAX_ROTORS],
            battery: None,
            channels: Default::default(),
            gps_line: DelayLine::default(),
            gps_stuck: None,
            rng: SimRng::new(NOISE_STREAM),
        };
        s.reset(0);
        s
    }

    pub fn plan(&self) -> &FaultPlan {
        &self.plan
    }

    /// The episode with `seed`: its schedule drawn, nothing fired, the paths' state cleared.
    pub fn reset(&mut self, seed: u64) {
        self.schedule = self.plan.schedule(seed, self.rotors);
        let n = self.schedule.len();
        self.fired = vec![None; n];
        self.cleared = vec![false; n];
        self.events.clear();
        self.takeoff = None;
        self.lag = LagState::default();
        self.phase = [0.0; MAX_ROTORS];
        self.battery = None;
        self.channels = Default::default();
        self.gps_line = DelayLine::default();
        self.gps_stuck = None;
        self.rng = SimRng::new(seed ^ NOISE_STREAM);
    }

    /// The episode's faults, one per slot (`None`: a draw that gave none this episode).
    pub fn schedule(&self) -> &[Option<FaultSpec>] {
        &self.schedule
    }

    /// When each slot's fault fired (`None`: not yet).
    pub fn fired(&self) -> &[Option<f64>] {
        &self.fired
    }

    /// Every firing and clearing so far, in time order.
    pub fn events(&self) -> &[FaultEvent] {
        &self.events
    }

    /// The battery, once a `battery` or `low_battery` fault has fired.
    pub fn battery(&self) -> Option<&Battery> {
        self.battery.as_ref()
    }

    /// Whether slot `i`'s fault is in effect.
    pub fn is_active(&self, i: usize) -> bool {
        self.fired[i].is_some() && !self.cleared[i]
    }

    /// Fires the faults whose trigger holds under `c` and clears those whose duration ran
    /// out; records each as an event.
    pub fn update(&mut self, c: &Conditions) {
        let mut c = *c;
        // The first time the vehicle left the ground counts (the caller says "airborne now"
        // with the current time every step): keep it once known.
        if self.takeoff.is_some() {
            c.takeoff = self.takeoff;
        }
        self.takeoff = c.takeoff;
        for i in 0..self.schedule.len() {
            let Some(spec) = &self.schedule[i] else {
                continue;
            };
            match self.fired[i] {
                None if spec.trigger.holds(&c) => {
                    self.fired[i] = Some(c.time);
                    let spec = spec.clone();
                    self.on_fire(&spec);
                    self.record(c.time, i, true);
                }
                Some(t0)
                    if !self.cleared[i]
                        && spec.duration.is_some_and(|d| c.time >= t0 + d - 1e-9) =>
                {
                    self.cleared[i] = true;
                    self.record(c.time, i, false);
                }
                _ => {}
            }
        }
    }

    /// Fires `spec` now (a run-time injection, e.g. MAV_CMD_INJECT_FAILURE), in a new slot.
    pub fn inject(&mut self, spec: FaultSpec, time: f64) {
        self.on_fire(&spec);
        self.schedule.push(Some(spec));
        self.fired.push(Some(time));
        self.cleared.push(false);
        self.record(time, self.schedule.len() - 1, true);
    }

    /// Clears every active fault of `motor` (0 = all motors' faults) or of `sensor`.
    pub fn clear(&mut self, motor: u8, sensor: Option<SensorId>, time: f64) {
        for i in 0..self.schedule.len() {
            let hit = self.schedule[i].as_ref().is_some_and(|s| match sensor {
                Some(sensor) => s.sensor == Some(sensor),
                None => s.kind.spec().target == Target::Motor && (motor == 0 || s.motor == motor),
            });
            if hit && self.is_active(i) {
                self.cleared[i] = true;
                self.record(time, i, false);
            }
        }
    }

    fn on_fire(&mut self, spec: &FaultSpec) {
        match spec.kind {
            FaultKind::Battery => {
                let v = &spec.values;
                let params = BatteryParams {
                    capacity: v[0],
                    cells: v[1],
                    internal_resistance: v[2],
                    max_current: v[3],
                    idle_current: v[4],
                };
                self.battery = Some(Battery::new(params, v[5]));
            }
            FaultKind::LowBattery => {
                let b = self
                    .battery
                    .get_or_insert_with(|| Battery::new(BatteryParams::default(), 1.0));
                b.charge = spec.values[0];
            }
            _ => {}
        }
    }

    fn record(&mut self, time: f64, slot: usize, fired: bool) {
        let label = (self.schedule[slot].as_ref()).map_or_else(String::new, FaultSpec::label);
        self.events.push(FaultEvent {
            time,
            slot,
            label,
            fired,
        });
    }

    /// The faults in effect that `wanted` accepts.
    fn active(&self, wanted: impl Fn(&FaultSpec) -> bool) -> Vec<ActiveFault<'_>> {
        active_in(&self.schedule, &self.fired, &self.cleared, wanted)
    }

    /// Whether the actuator path changes anything now (a motor or propeller fault in
    /// effect, or a battery).
    pub fn acts_on_motors(&self) -> bool {
        self.battery.is_some() || !self.active(|s| is_actuator(s.kind)).is_empty()
    }

    /// Whether a fault of `sensor` is in effect.
    pub fn acts_on_sensor(&self, sensor: SensorId) -> bool {
        !self.active(|s| s.sensor == Some(sensor)).is_empty()
    }

    /// What the link faults in effect do to the link (a healthy link without them).
    pub fn link(&self) -> LinkCondition {
        let mut c = LinkCondition::default();
        for f in self.active(|s| s.kind.spec().target == Target::Link) {
            match f.spec.kind {
                FaultKind::LinkLoss => c.lost = true,
                FaultKind::LinkDelay => c.delay = c.delay.max(f.spec.values[0]),
                _ => {}
            }
        }
        c
    }

    /// Whether an air fault is in effect.
    pub fn acts_on_air(&self) -> bool {
        !self.active(|s| is_air(s.kind)).is_empty()
    }

    /// The actuator path: writes into `out` what the motors get for `commanded` over the
    /// next `dt` seconds, with the motors now at `motors` (the battery's load); advances the
    /// lags, the battery's charge and the rotors' phases by `dt`.
    pub fn motor_commands(&mut self, commanded: &[f64], motors: &[f64], dt: f64, out: &mut [f64]) {
        let active = active_in(&self.schedule, &self.fired, &self.cleared, |s| {
            is_actuator(s.kind)
        });
        motor_commands(&active, commanded, &mut self.lag, dt, out);
        if let Some(b) = &mut self.battery {
            let scale = b.draw(motors, dt);
            for o in out.iter_mut() {
                *o *= scale;
            }
        }
        for f in active
            .iter()
            .filter(|f| f.spec.kind == FaultKind::PropellerDamage)
        {
            let max_speed = f.spec.values[2];
            for (i, m) in motors.iter().enumerate() {
                if acts_on(f.spec.motor, i) {
                    self.phase[i] = (self.phase[i] + m * max_speed * dt) % TAU;
                }
            }
        }
    }

    /// The wind the air faults add at simulation time `time` and height `height` m, world
    /// ENU, m/s.
    pub fn wind(&self, time: f64, height: f64) -> Vector3<f64> {
        let mut w = Vector3::zeros();
        for f in self.active(|s| is_air(s.kind)) {
            let v = &f.spec.values;
            match f.spec.kind {
                FaultKind::Gust => {
                    w += gust(&Vector3::new(v[0], v[1], v[2]), v[3], v[4], time - f.fired);
                }
                FaultKind::WindShear => w += shear(v[0], v[1], v[2], v[3], height),
                _ => {}
            }
        }
        w
    }

    /// The acceleration the damaged propellers' imbalance shakes the body with now, body
    /// FRD, m/s² (the accelerometer adds it): imbalance·Ω² / mass, turning with each rotor.
    pub fn imu_vibration(&self, motors: &[f64], mass: f64) -> Vector3<f64> {
        let mut a = Vector3::zeros();
        for f in self.active(|s| s.kind == FaultKind::PropellerDamage) {
            let (imbalance, max_speed) = (f.spec.values[1], f.spec.values[2]);
            for (i, m) in motors.iter().enumerate() {
                if acts_on(f.spec.motor, i) {
                    let omega = m * max_speed;
                    let force = imbalance * omega * omega;
                    let (s, c) = self.phase[i].sin_cos();
                    a += Vector3::new(c, s, 0.0) * (force / mass);
                }
            }
        }
        a
    }

    /// The sensor path for a vector sensor (gyro, accel, mag; the baro's altitude in x):
    /// `value` sampled at `time` with the sensor's own noise `sigma`; `None`: no sample.
    pub fn sensor(
        &mut self,
        sensor: SensorId,
        value: Vector3<f64>,
        time: f64,
        sigma: f64,
    ) -> Option<Vector3<f64>> {
        let active = active_in(&self.schedule, &self.fired, &self.cleared, |s| {
            s.sensor == Some(sensor)
        });
        if active.is_empty() {
            self.channels[sensor as usize] = SensorChannel::default();
            return Some(value);
        }
        let ch = &mut self.channels[sensor as usize];
        ch.apply(sensor, &active, value, time, sigma, &mut self.rng)
    }

    /// The sensor path for a GPS fix (taken at `time`, horizontal noise `sigma` m, the
    /// vertical `sigma_v`): the sensor faults of `gps`, then a jump and a degradation.
    pub fn gps(&mut self, fix: GpsFix, time: f64, sigma: f64, sigma_v: f64) -> Option<GpsFix> {
        let faults: Vec<FaultSpec> = self
            .active(|s| matches!(s.kind, FaultKind::GpsJump | FaultKind::GpsDegraded))
            .into_iter()
            .map(|f| f.spec.clone())
            .chain(
                self.active(|s| s.sensor == Some(SensorId::Gps))
                    .into_iter()
                    .map(|f| f.spec.clone()),
            )
            .collect();
        if faults.is_empty() {
            self.gps_line = DelayLine::default();
            self.gps_stuck = None;
            return Some(fix);
        }
        let mut out = fix;
        if let Some(f) = faults.iter().find(|f| f.kind == FaultKind::SensorDelay) {
            out = self.gps_line.push(time, fix, f.values[0])?;
        }
        if faults.iter().any(|f| f.kind == FaultKind::SensorStuck) {
            out = *self.gps_stuck.get_or_insert(out);
        } else {
            self.gps_stuck = None;
        }
        let mut offset = Vector3::zeros();
        for f in &faults {
            let v = &f.values;
            match f.kind {
                FaultKind::GpsJump => offset += Vector3::new(v[0], v[1], v[2]),
                FaultKind::SensorBias => {
                    let fired = self.fired_time_of(f).unwrap_or(time);
                    offset += Vector3::repeat(v[0] + v[1] * (time - fired));
                }
                FaultKind::SensorNoise => {
                    let k = (v[0] * v[0] - 1.0).sqrt();
                    let r = &mut self.rng;
                    offset +=
                        Vector3::new(sigma * r.normal(), sigma * r.normal(), sigma_v * r.normal())
                            * k;
                }
                FaultKind::GpsDegraded => {
                    out.satellites = v[0] as u8;
                    let (kh, kv) = (v[1] / out.eph.max(1e-9), v[2] / out.epv.max(1e-9));
                    let r = &mut self.rng;
                    let extra = |k: f64| (k * k - 1.0).max(0.0).sqrt();
                    offset += Vector3::new(
                        sigma * extra(kh) * r.normal(),
                        sigma * extra(kh) * r.normal(),
                        sigma_v * extra(kv) * r.normal(),
                    );
                    out.eph = v[1];
                    out.epv = v[2];
                }
                _ => {}
            }
        }
        out.position = out.position.offset(&offset);
        if faults.iter().any(|f| f.kind == FaultKind::SensorOff) {
            return None;
        }
        Some(out)
    }

    fn fired_time_of(&self, spec: &FaultSpec) -> Option<f64> {
        (self.schedule.iter().zip(&self.fired))
            .find(|(s, _)| s.as_ref() == Some(spec))
            .and_then(|(_, f)| *f)
    }
}

/// The faults of `schedule` in effect (fired, not cleared) that `wanted` accepts.
fn active_in<'f>(
    schedule: &'f [Option<FaultSpec>],
    fired: &[Option<f64>],
    cleared: &[bool],
    wanted: impl Fn(&FaultSpec) -> bool,
) -> Vec<ActiveFault<'f>> {
    (schedule.iter().zip(fired).zip(cleared))
        .filter_map(|((s, f), c)| match (s, f) {
            (Some(spec), Some(fired)) if !c && wanted(spec) => Some(ActiveFault {
                spec,
                fired: *fired,
            }),
            _ => None,
        })
        .collect()
}

fn is_actuator(kind: FaultKind) -> bool {
    kind.spec().target == Target::Motor
}

fn is_air(kind: FaultKind) -> bool {
    matches!(kind, FaultKind::Gust | FaultKind::WindShear)
}
