//! What the PX4 and ArduPilot sessions share of the faults: the vehicle's fault plan on the
//! session's clock (the core's [`VehicleFaults`]: actuator path, air, sensor path), the
//! control link that injects faults at run time, and the report of every fault that fires
//! (the log, a STATUSTEXT on the control link). Without a plan and without a control link
//! nothing here runs: the session steps and samples exactly as before.

use crate::control_link::ControlLink;
use flyloop_core::ParamError;
use flyloop_core::faults::px4::unit;
use flyloop_core::faults::{
    Delivered, FaultEvent, FaultKind, FaultPlan, LinkCondition, SensorId, VehicleFaults,
};
use flyloop_core::sensors::{GpsFix, SensorParams, SensorReading};
use flyloop_core::vehicle::Vehicle;
use mavlink::dialects::common::MavSeverity;

/// Simulation time between two looks at the control link, µs.
const CONTROL_POLL_US: u64 = 10_000;

/// A session's faults and control link.
#[derive(Debug)]
pub struct SessionFaults {
    faults: Option<VehicleFaults>,
    control: Option<ControlLink>,
    rotors: usize,
    mass: f64,
    seed: u64,
    next_poll_us: u64,
    /// Only the IMU is sent (ArduPilot): faults of other sensors are refused.
    imu_only: bool,
    /// Events reported since the session last took them (for the track).
    reported: Vec<FaultEvent>,
    /// The lines of faults that fired or cleared, until [`Self::take_lines`] (the recording's).
    lines: Vec<String>,
}

/// Why ArduPilot mode refuses a fault of a sensor other than the IMU.
const IMU_ONLY: &str = "ArduPilot mode sends ArduPilot only the IMU (gyro, accel): it \
    simulates its mag, baro and GPS itself from the JSON position (fail them with its own \
    SIM_ parameters over MAVLink, e.g. SIM_GPS_DISABLE = 1 in ArduCopter 4.6)";

/// Whether a fault of `kind` on `sensor` reaches a sensor other than the IMU.
fn beyond_imu(kind: FaultKind, sensor: Option<SensorId>) -> bool {
    matches!(kind, FaultKind::GpsJump | FaultKind::GpsDegraded)
        || sensor.is_some_and(|s| !matches!(s, SensorId::Gyro | SensorId::Accel))
}

/// Refuses the faults of `plan` that act on a sensor other than the IMU, naming it.
pub fn refuse_beyond_imu(plan: &FaultPlan) -> Result<(), ParamError> {
    let refuse = |what: String| Err(ParamError::Parse(format!("fault {what}: {IMU_ONLY}")));
    for f in &plan.faults {
        if beyond_imu(f.kind, f.sensor) {
            return refuse(format!("`{}`", f.label()));
        }
    }
    for d in &plan.draws {
        let sensors = if d.sensors.is_empty() {
            SensorId::ALL.to_vec()
        } else {
            d.sensors.clone()
        };
        for &kind in &d.kinds {
            let sensor_kind = kind.spec().target == flyloop_core::faults::catalogue::Target::Sensor;
            let reaches = if sensor_kind {
                sensors.iter().any(|&s| beyond_imu(kind, Some(s)))
            } else {
                beyond_imu(kind, None)
            };
            if reaches {
                return refuse(format!("randomization kind `{}`", kind.name()));
            }
        }
    }
    Ok(())
}

impl SessionFaults {
    /// The faults of `plan` (none: nothing runs until one is injected) for a vehicle of
    /// `rotors` rotors and `mass` kg; `seed` draws the plan's random faults.
    pub fn new(plan: FaultPlan, rotors: usize, mass: f64, seed: u64) -> Result<Self, ParamError> {
        let faults = if plan.is_empty() {
            None
        } else {
            Some(VehicleFaults::new(plan, rotors, mass, seed)?)
        };
        Ok(SessionFaults {
            faults,
            control: None,
            rotors,
            mass,
            seed,
            next_poll_us: 0,
            imu_only: false,
            reported: Vec::new(),
            lines: Vec::new(),
        })
    }

    /// The faults of ArduPilot mode, which sends only the IMU: other sensors' faults are
    /// refused (in `plan` and at run time).
    pub fn imu_only(
        plan: FaultPlan,
        rotors: usize,
        mass: f64,
        seed: u64,
    ) -> Result<Self, ParamError> {
        refuse_beyond_imu(&plan)?;
        let mut faults = Self::new(plan, rotors, mass, seed)?;
        faults.imu_only = true;
        Ok(faults)
    }

    /// Takes faults at run time on `control` from now on.
    pub fn set_control(&mut self, control: ControlLink) {
        self.control = Some(control);
    }

    /// A new autopilot connection: the plan's faults start again (nothing fired).
    pub fn restart(&mut self) {
        if let Some(f) = &mut self.faults {
            f.restart(self.seed);
        }
        self.next_poll_us = 0;
    }

    /// Advances `vehicle` by `dt` s from `time_us`: the control link read when due, the faults
    /// due fired, the actuator path and the air applied, what fired reported.
    pub fn advance(&mut self, vehicle: &mut dyn Vehicle, time_us: u64, dt: f64) {
        self.poll(time_us);
        let Some(faults) = &mut self.faults else {
            vehicle.advance(dt);
            return;
        };
        faults.begin_step(time_us as f64 * 1e-6, vehicle);
        faults.advance(vehicle, dt);
        self.report();
    }

    /// The sensor path on `r` (taken at `time_us`, `dt` s after the last sample).
    pub fn reading(
        &mut self,
        r: &mut SensorReading,
        time_us: u64,
        dt: f64,
        p: &SensorParams,
        motors: &[f64],
    ) -> Delivered {
        match &mut self.faults {
            Some(f) => f.reading(r, time_us as f64 * 1e-6, dt, p, motors),
            None => Delivered::ALL,
        }
    }

    /// The sensor path on a GPS fix delivered at `time_us`.
    pub fn gps(&mut self, fix: GpsFix, time_us: u64, p: &SensorParams) -> Option<GpsFix> {
        match &mut self.faults {
            Some(f) => f.gps(fix, time_us as f64 * 1e-6, p),
            None => Some(fix),
        }
    }

    /// What the link faults in effect do to the autopilot's link now (a clear link without
    /// faults).
    pub fn link(&self) -> LinkCondition {
        (self.faults.as_ref()).map_or_else(LinkCondition::default, |f| f.state().link())
    }

    /// [`SessionFaults::link`] for a message arriving at `time_us`: the faults due by then
    /// fired first (the step that starts now fires them again as a no-op), so a link lost
    /// from time t drops what arrives for the step starting at t.
    pub fn link_at(&mut self, vehicle: &mut dyn Vehicle, time_us: u64) -> LinkCondition {
        match &mut self.faults {
            Some(f) => {
                f.begin_step(time_us as f64 * 1e-6, vehicle);
                f.state().link()
            }
            None => LinkCondition::default(),
        }
    }

    /// The faults that fired or cleared since the last call (for the track).
    pub fn take_events(&mut self) -> Vec<FaultEvent> {
        std::mem::take(&mut self.reported)
    }

    /// Whether a sensor fault path runs (faults set or injected).
    pub fn is_active(&self) -> bool {
        self.faults.is_some()
    }

    /// Reads the control link when due (every [`CONTROL_POLL_US`] of simulation time).
    fn poll(&mut self, time_us: u64) {
        let Some(control) = &mut self.control else {
            return;
        };
        if time_us < self.next_poll_us {
            return;
        }
        self.next_poll_us = time_us + CONTROL_POLL_US;
        let (faults, rotors, mass, seed) = (&mut self.faults, self.rotors, self.mass, self.seed);
        let imu_only = self.imu_only;
        control.poll(|unit, failure, instance| {
            if imu_only
                && matches!(
                    unit,
                    unit::SENSOR_MAG | unit::SENSOR_BARO | unit::SENSOR_GPS
                )
            {
                return Err(ParamError::Relation {
                    name: "failure_unit",
                    requirement: format!("{unit} is not the IMU's: {IMU_ONLY}"),
                });
            }
            let f = match faults {
                Some(f) => f,
                None => faults.insert(VehicleFaults::new(
                    FaultPlan::default(),
                    rotors,
                    mass,
                    seed,
                )?),
            };
            f.inject_px4(unit, failure, instance, rotors, time_us as f64 * 1e-6)
        });
        // The control link already answered with its own STATUSTEXT: only the log.
        if let Some(f) = &mut self.faults {
            for e in f.new_events() {
                tracing::warn!(time_s = e.time, fault = %e.label, fired = e.fired, "fault injected on the control link");
                self.reported.push(e.clone());
                self.lines.push(event_line(e));
            }
        }
    }

    /// Every fault that fired or cleared since the last report: logged, and a STATUSTEXT on
    /// the control link.
    fn report(&mut self) {
        let Some(f) = &mut self.faults else {
            return;
        };
        for e in f.new_events() {
            let text = event_line(e);
            tracing::warn!("{text}");
            self.reported.push(e.clone());
            if let Some(control) = &mut self.control {
                control.announce(MavSeverity::MAV_SEVERITY_WARNING, &text);
            }
            self.lines.push(text);
        }
    }

    /// The lines of the faults that fired or cleared since the last call.
    pub fn take_lines(&mut self) -> Vec<String> {
        std::mem::take(&mut self.lines)
    }
}

/// What is said of a fault that fired or cleared.
fn event_line(e: &FaultEvent) -> String {
    let what = if e.fired { "fired" } else { "cleared" };
    format!("fault {what}: {} at {:.3} s", e.label, e.time)
}
