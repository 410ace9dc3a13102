//! The sensor models against hand-computed values, their noise against their parameters,
//! and their determinism.

use super::*;
use crate::quadrotor::contact::rest_height;
use crate::quadrotor::{BodyState, Frame, QuadrotorParams, multirotor_at};
use crate::vehicle::AirVehicle;
use std::f64::consts::FRAC_PI_2;

const DT: f64 = 0.004;

/// Parameters without any noise or bias: readings are the ideal values.
fn ideal() -> SensorParams {
    SensorParams {
        mag_noise: 0.0,
        gyro_noise_density: 0.0,
        gyro_bias_random_walk: 0.0,
        accel_noise_density: 0.0,
        accel_bias_random_walk: 0.0,
        baro_noise: 0.0,
        gps_horizontal_noise: 0.0,
        gps_vertical_noise: 0.0,
        gps_velocity_noise: 0.0,
        ..SensorParams::default()
    }
}

fn still_air() -> QuadrotorParams {
    QuadrotorParams {
        wind_enabled: false,
        ..QuadrotorParams::default()
    }
}

fn quad_at(position: Vector3<f64>, yaw: f64) -> Box<dyn AirVehicle> {
    let body = BodyState::at_rest(position, 0.0, 0.0, yaw, 0.0);
    multirotor_at(still_air(), Frame::quad_x(), body, SimRng::new(1)).unwrap()
}

fn close(a: &Vector3<f64>, b: &Vector3<f64>, tol: f64) -> bool {
    (a - b).norm() < tol
}

#[test]
fn at_rest_on_the_ground_the_imu_reads_minus_g_and_no_rotation() {
    // Standing on its feet: the landing gear carries the weight.
    let mut quad = quad_at(Vector3::new(0.0, 0.0, rest_height(&still_air())), 0.7);
    quad.advance(DT);
    assert!(quad.is_grounded());
    let r = Sensors::new(ideal(), 0)
        .unwrap()
        .sample(&quad.kinematics(), DT);
    assert!(
        close(&r.imu.accel, &Vector3::new(0.0, 0.0, -9.81), 1e-12),
        "{}",
        r.imu.accel
    );
    assert_eq!(r.imu.gyro, Vector3::zeros());
}

#[test]
fn in_free_fall_the_accelerometer_reads_zero_and_the_gyro_reads_frd_rates() {
    let mut quad = quad_at(Vector3::new(0.0, 0.0, 50.0), 0.0);
    quad.body_mut().body_rates = Vector3::new(0.1, 0.2, 0.3); // FLU
    let r = Sensors::new(ideal(), 0)
        .unwrap()
        .sample(&quad.kinematics(), DT);
    assert!(
        close(&r.imu.accel, &Vector3::zeros(), 1e-12),
        "{}",
        r.imu.accel
    );
    assert!(close(&r.imu.gyro, &Vector3::new(0.1, -0.2, -0.3), 1e-15));
}

#[test]
fn a_tilted_vehicle_sees_gravity_on_its_tilted_axes() {
    // Rolled +30° about FLU x (left side up, right side down): the specific force points up,
    // which now leans toward the raised left side: in FRD (0, −g·sin 30°, −g·cos 30°).
    let body = BodyState::at_rest(Vector3::zeros(), 30f64.to_radians(), 0.0, 0.0, 0.0);
    let attitude = nalgebra::UnitQuaternion::new_unchecked(body.attitude);
    let f = imu::specific_force_frd(&attitude, &Vector3::zeros(), 9.81);
    assert!(
        close(
            &f,
            &Vector3::new(0.0, -4.905, -9.81 * 0.75f64.sqrt()),
            1e-12
        ),
        "{f}"
    );
}

#[test]
fn the_barometer_at_100_m_above_home_reads_the_isa() {
    let quad = quad_at(Vector3::new(0.0, 0.0, 100.0), 0.0);
    let b = Sensors::new(ideal(), 0)
        .unwrap()
        .sample(&quad.kinematics(), DT)
        .baro;
    // ISA at 588 m MSL: 101325·(1 − 0.0065·588/288.15)^5.255877 Pa (tables: ~944.6 hPa),
    // 15 − 0.0065·588 °C.
    assert!(
        (b.pressure_hpa - 944.577_974_466).abs() < 1e-6,
        "{}",
        b.pressure_hpa
    );
    assert!((b.temperature_c - 11.178).abs() < 1e-9);
    assert!((b.pressure_altitude - 588.0).abs() < 1e-6);
    assert_eq!(baro::isa_pressure(0.0), 101_325.0);
}

#[test]
fn the_magnetometer_at_home_reads_the_declared_field() {
    // F = 0.482 G, I = 63.15°, D = 3.27°: N = F cos I cos D, E = F cos I sin D, D = F sin I.
    let (n, e, d) = (0.217_343_883, 0.012_417_794, 0.430_036_551);
    // Facing north (ENU yaw 90°), level: FRD is NED.
    let north = Sensors::new(ideal(), 0)
        .unwrap()
        .sample(&quad_at(Vector3::zeros(), FRAC_PI_2).kinematics(), DT);
    assert!(
        close(&north.mag, &Vector3::new(n, e, d), 1e-9),
        "{}",
        north.mag
    );
    // Facing east: forward is east, right is south.
    let east = Sensors::new(ideal(), 0)
        .unwrap()
        .sample(&quad_at(Vector3::zeros(), 0.0).kinematics(), DT);
    assert!(
        close(&east.mag, &Vector3::new(e, -n, d), 1e-9),
        "{}",
        east.mag
    );
    assert!((east.mag.norm() - 0.482).abs() < 1e-12);
}

#[test]
fn gps_reports_the_state_around_home_at_its_rate_and_delay() {
    let mut quad = quad_at(Vector3::new(10.0, 20.0, 5.0), 0.0);
    quad.body_mut().velocity = Vector3::new(1.0, 2.0, -0.5);
    let mut s = Sensors::new(ideal(), 0).unwrap();
    let f = s
        .gps(&quad.kinematics(), 0.0)
        .expect("the first fix comes at once without delay");
    assert!((f.position.latitude_deg - 47.397_921_663_06).abs() < 1e-10);
    assert!((f.position.longitude_deg - 8.545_726_709_215).abs() < 1e-10);
    assert!((f.position.altitude_m - 493.0).abs() < 1e-12);
    assert_eq!(f.velocity_ned, Vector3::new(2.0, 1.0, 0.5));
    assert!((f.course_deg.unwrap() - 26.565_051_177).abs() < 1e-8);
    assert!((f.ground_speed - 5f64.sqrt()).abs() < 1e-12);
    assert_eq!((f.eph, f.epv, f.satellites), (0.3, 0.4, 12));
    // 10 Hz at 4 ms steps over one second: fixes at 0.0, 0.1, …, 0.9 (and 1.0 is the next).
    let fixes = (1..250)
        .filter(|k| s.gps(&quad.kinematics(), f64::from(*k) * DT).is_some())
        .count();
    assert_eq!(fixes, 9);
    // With 0.2 s delay the first fix, taken at 0, arrives at 0.2 s.
    let mut late = Sensors::new(
        SensorParams {
            gps_delay: 0.2,
            ..ideal()
        },
        0,
    )
    .unwrap();
    let first = (0..100)
        .find_map(|k| {
            late.gps(&quad.kinematics(), f64::from(k) * DT)
                .map(|f| (k, f))
        })
        .unwrap();
    assert_eq!(first.0, 50);
    assert_eq!(first.1.measured_at, 0.0);
    // At rest the course is unknown.
    quad.body_mut().velocity = Vector3::zeros();
    assert_eq!(
        Sensors::new(ideal(), 0)
            .unwrap()
            .gps(&quad.kinematics(), 0.0)
            .unwrap()
            .course_deg,
        None
    );
}

fn std_dev(values: &[f64]) -> f64 {
    let n = values.len() as f64;
    let mean = values.iter().sum::<f64>() / n;
    (values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1.0)).sqrt()
}

#[test]
fn white_noise_has_the_standard_deviation_of_its_parameters() {
    let params = SensorParams {
        gyro_bias_random_walk: 0.0,
        accel_bias_random_walk: 0.0,
        ..SensorParams::default()
    };
    let quad = quad_at(Vector3::new(0.0, 0.0, 10.0), 0.0);
    let mut s = Sensors::new(params.clone(), 7).unwrap();
    let n = 20_000;
    let (mut ax, mut gz, mut my, mut p, mut gps_n) = (vec![], vec![], vec![], vec![], vec![]);
    for k in 0..n {
        let r = s.sample(&quad.kinematics(), DT);
        ax.push(r.imu.accel.x);
        gz.push(r.imu.gyro.z);
        my.push(r.mag.y);
        p.push(r.baro.pressure_hpa * 100.0);
        if let Some(f) = s.gps(&quad.kinematics(), f64::from(k) * 0.1) {
            gps_n.push(f.position.latitude_deg.to_radians() * gps::EARTH_RADIUS);
        }
    }
    // The sample std of 20 000 normals is within 2 % of σ with overwhelming probability.
    let check = |name: &str, got: f64, want: f64| {
        assert!((got / want - 1.0).abs() < 0.02, "{name}: {got} vs {want}");
    };
    check(
        "accel",
        std_dev(&ax),
        params.accel_noise_density / DT.sqrt(),
    );
    check("gyro", std_dev(&gz), params.gyro_noise_density / DT.sqrt());
    check("mag", std_dev(&my), params.mag_noise);
    check("baro", std_dev(&p), params.baro_noise);
    check("gps", std_dev(&gps_n), params.gps_horizontal_noise);
}

#[test]
fn biases_wander_as_their_gauss_markov_process_says() {
    // From zero, after t the variance is rw²·τ/2·(1 − e^(−2t/τ)); over many seeds the spread
    // of the bias matches it.
    let params = SensorParams {
        gyro_noise_density: 0.0,
        accel_noise_density: 0.0,
        gyro_bias_correlation_time: 10.0,
        ..SensorParams::default()
    };
    let quad = quad_at(Vector3::new(0.0, 0.0, 10.0), 0.0);
    let steps = 500; // 2 s
    let mut biases = Vec::new();
    for seed in 0..2000 {
        let mut s = Sensors::new(params.clone(), seed).unwrap();
        for _ in 0..steps {
            s.sample(&quad.kinematics(), DT);
        }
        biases.push(s.biases().0.x);
    }
    let t = steps as f64 * DT;
    let want = params.gyro_bias_random_walk * (5.0 * (1.0 - (-2.0 * t / 10.0f64).exp())).sqrt();
    let got = std_dev(&biases);
    assert!((got / want - 1.0).abs() < 0.06, "{got} vs {want}");
}

fn stream(s: &mut Sensors, quad: &dyn AirVehicle, steps: u32) -> Vec<u64> {
    let mut bits = Vec::new();
    for k in 0..steps {
        let r = s.sample(&quad.kinematics(), DT);
        bits.extend(
            [r.imu.accel, r.imu.gyro, r.mag]
                .iter()
                .flat_map(|v| v.iter().map(|x| x.to_bits())),
        );
        bits.push(r.baro.pressure_hpa.to_bits());
        if let Some(f) = s.gps(&quad.kinematics(), f64::from(k) * DT) {
            bits.push(f.position.latitude_deg.to_bits());
            bits.push(f.velocity_ned.z.to_bits());
        }
    }
    bits
}

#[test]
fn same_seed_same_bits_and_a_restored_suite_continues_exactly() {
    let mut quad = quad_at(Vector3::new(1.0, 2.0, 3.0), 0.4);
    quad.body_mut().velocity = Vector3::new(0.3, -0.2, 0.1);
    let params = SensorParams {
        gps_delay: 0.15,
        ..SensorParams::default()
    };
    let mut a = Sensors::new(params.clone(), 42).unwrap();
    let mut b = Sensors::new(params.clone(), 42).unwrap();
    assert_eq!(
        stream(&mut a, quad.as_ref(), 300),
        stream(&mut b, quad.as_ref(), 300)
    );
    let mut other = Sensors::new(params.clone(), 43).unwrap();
    let mut again = Sensors::new(params, 42).unwrap();
    assert_ne!(
        stream(&mut other, quad.as_ref(), 10),
        stream(&mut again, quad.as_ref(), 10)
    );

    let bytes = a.save().unwrap();
    let mut restored = Sensors::restore(&bytes).unwrap();
    assert_eq!(restored, a);
    assert_eq!(
        stream(&mut restored, quad.as_ref(), 300),
        stream(&mut a, quad.as_ref(), 300)
    );
    assert!(Sensors::restore(&bytes[..bytes.len() - 1]).is_err());
    assert!(Sensors::restore(&quad.save().unwrap()).is_err());

    // reset(seed) is a fresh suite with that seed.
    let mut fresh = Sensors::new(a.params().clone(), 9).unwrap();
    a.reset(9);
    assert_eq!(
        stream(&mut a, quad.as_ref(), 100),
        stream(&mut fresh, quad.as_ref(), 100)
    );
}

#[test]
fn bad_parameters_are_refused_with_their_name() {
    let err = Sensors::new(
        SensorParams {
            mag_strength: -1.0,
            ..SensorParams::default()
        },
        0,
    )
    .unwrap_err()
    .to_string();
    assert!(err.contains("`mag_strength`"), "{err}");
}
