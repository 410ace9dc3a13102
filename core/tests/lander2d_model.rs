//! Lander2D model behaviour: inertia, hover, touch-downs, platform motion, wind, battery,
//! determinism and exact save/restore.

// The helpers below are test code too: a failed setup is a failed test.

use flyloop_core::lander2d::{DroneState, Lander2d, Lander2dParams, SnapshotError};
use flyloop_core::rng::SimRng;

/// No thrust noise, no wind: the deterministic vehicle of the physics checks.
fn quiet() -> Lander2dParams {
    Lander2dParams {
        thrust_noise_std: 0.0,
        wind_enabled: false,
        ..Default::default()
    }
}

fn at(x: f64, y: f64) -> DroneState {
    DroneState {
        x,
        y,
        ..Default::default()
    }
}

fn lander(p: Lander2dParams, start: DroneState) -> Lander2d {
    Lander2d::new(p, start, SimRng::new(7)).unwrap()
}

/// Holds the drone level and descending at `descent` m/s: collective thrust on the vertical
/// speed error, differential thrust on angle and angular velocity.
fn descend(l: &mut Lander2d, descent: f64) {
    let p = l.params().clone();
    let d = l.drone();
    let collective = p.hover_thrust() + p.drone_mass / 2.0 * 4.0 * (-descent - d.vy);
    let differential = -2.0 * d.angle - 0.5 * d.angular_velocity;
    let left = p
        .command_for_thrust((collective - differential).clamp(0.0, p.max_thrust))
        .unwrap();
    let right = p
        .command_for_thrust((collective + differential).clamp(0.0, p.max_thrust))
        .unwrap();
    l.set_command([left, right]).unwrap();
    l.step();
}

/// Every number of the state, as bits, for bit-identity checks.
fn fingerprint(l: &Lander2d) -> Vec<u64> {
    let d = l.drone();
    let c = l.contact();
    [
        d.x,
        d.y,
        d.angle,
        d.vx,
        d.vy,
        d.angular_velocity,
        l.battery(),
        l.platform_x(),
        l.platform_vx(),
    ]
    .into_iter()
    .chain(l.thrust())
    .chain(l.acceleration())
    .chain([c.touchdown_speed, c.touchdown_angle])
    .map(f64::to_bits)
    .chain([
        u64::from(l.landed()),
        u64::from(l.crashed()),
        u64::from(c.on_platform),
        l.steps(),
    ])
    .collect()
}

#[test]
fn composite_inertia_is_0_21625_from_the_collider_mass_properties() {
    let l = lander(Lander2dParams::default(), at(25.0, 40.0));
    assert!((l.inertia() - 0.21625).abs() < 1e-12, "{}", l.inertia());
}

#[test]
fn hover_thrust_m_g_over_2_per_motor_holds_altitude_with_noise_off() {
    let p = quiet();
    let hover = p.command_for_thrust(p.hover_thrust()).unwrap();
    let mut l = lander(p.clone(), at(25.0, 40.0));
    l.set_command([hover, hover]).unwrap();
    for _ in 0..1000 {
        l.step();
    }
    let d = l.drone();
    assert_eq!(l.thrust(), [p.hover_thrust(); 2]);
    // 20 s of hover: the forces balance to rounding (vy ≈ 1e-13 m/s), so the drift stays
    // below a nanometre.
    assert!(
        (d.y - 40.0).abs() < 1e-9 && (d.x - 25.0).abs() < 1e-9,
        "{d:?}"
    );
    assert!(d.angle.abs() < 1e-12 && d.vy.abs() < 1e-11, "{d:?}");
    // Battery: 2 · 7.3575 N · 0.1 · 0.02 s per step for 1000 steps = 29.43.
    assert!(
        (l.battery() - (100.0 - 29.43)).abs() < 1e-9,
        "{}",
        l.battery()
    );
}

#[test]
fn gentle_descent_onto_the_platform_lands() {
    let mut l = lander(quiet(), at(25.0, 13.0));
    for _ in 0..500 {
        descend(&mut l, 0.5);
        if l.landed() || l.crashed() {
            break;
        }
    }
    assert!(l.landed(), "{l:?}");
    assert!(!l.crashed(), "{l:?}");
    let c = l.contact();
    assert!((c.touchdown_speed - 0.5).abs() < 0.05, "{c:?}");
    // The drone's bottom (motor half side 0.1) rests on the pad's top at 10.5 (prediction
    // distance 2 cm of slack).
    assert!((l.drone().y - 10.6).abs() < 0.03, "{:?}", l.drone());
}

#[test]
fn pad_landing_does_not_also_count_as_ground_contact() {
    let mut l = lander(quiet(), at(25.0, 13.0));
    for _ in 0..300 {
        descend(&mut l, 0.5);
    }
    // Then motors off: it sits on the pad for 4 s.
    l.set_command([-1.0, -1.0]).unwrap();
    for _ in 0..200 {
        l.step();
        assert!(!l.contact().on_ground && !l.contact().touched_ground);
    }
    assert!(l.landed() && !l.crashed(), "{l:?}");
    assert!(l.contact().on_platform);
}

#[test]
fn a_fall_onto_the_platform_crashes() {
    let mut l = lander(quiet(), at(25.0, 20.0));
    for _ in 0..200 {
        l.step();
        if l.crashed() {
            break;
        }
    }
    assert!(l.crashed() && !l.landed(), "{l:?}");
    // Free fall from 20 to 10.6: v = √(2 · 9.81 · 9.4) = 13.58 m/s (the explicit-Euler
    // integration and the 20 ms sampling add up to one step's Δv, 0.2 m/s).
    let v = l.contact().touchdown_speed;
    assert!((v - 13.58).abs() < 0.25, "{v}");
}

#[test]
fn a_tilted_touchdown_on_the_platform_crashes() {
    let start = DroneState {
        x: 25.0,
        y: 10.9,
        angle: 0.3,
        ..Default::default()
    };
    let mut l = lander(quiet(), start);
    for _ in 0..50 {
        l.step();
    }
    assert!(l.crashed() && !l.landed(), "{l:?}");
    assert!(
        (l.contact().touchdown_angle - 0.3).abs() < 0.05,
        "{:?}",
        l.contact()
    );
}

#[test]
fn touching_bare_ground_crashes_even_gently() {
    let mut l = lander(quiet(), at(8.0, 12.0));
    for _ in 0..500 {
        descend(&mut l, 0.3);
        if l.crashed() {
            break;
        }
    }
    assert!(l.crashed() && !l.landed(), "{l:?}");
    assert!(l.contact().on_ground);
}

#[test]
fn moving_platform_reverses_at_its_bounds() {
    let p = Lander2dParams {
        moving_platform: true,
        ..quiet()
    };
    let hover = p.command_for_thrust(p.hover_thrust()).unwrap();
    let mut l = lander(p.clone(), at(25.0, 40.0));
    l.set_command([hover, hover]).unwrap();
    let step = p.platform_speed * p.dt;
    let (mut min_x, mut max_x) = (f64::MAX, f64::MIN);
    let mut reversals = Vec::new();
    let mut last_vx = l.platform_vx();
    assert_eq!(last_vx.abs(), 1.5);
    // 50 m of travel at 1.5 m/s is 1,500 steps one way: 4,000 steps see both ends.
    for _ in 0..4000 {
        l.step();
        let x = l.platform_x();
        min_x = min_x.min(x);
        max_x = max_x.max(x);
        assert_eq!(l.platform_vx().abs(), 1.5);
        if l.platform_vx() != last_vx {
            reversals.push(x);
            last_vx = l.platform_vx();
        }
        assert_eq!(
            l.platform_target().1,
            10.5,
            "the platform moves along x only"
        );
    }
    assert!(reversals.len() >= 2, "{reversals:?}");
    // Each reversal happens the step the centre reaches 2.5 or 47.5: at most one step past.
    for x in &reversals {
        let at_low = (2.5 - step - 1e-9..=2.5).contains(x);
        let at_high = (47.5..=47.5 + step + 1e-9).contains(x);
        assert!(at_low || at_high, "reversal at {x}");
    }
    assert!(
        min_x >= 2.5 - step - 1e-9 && max_x <= 47.5 + step + 1e-9,
        "{min_x} {max_x}"
    );
}

#[test]
fn platform_start_direction_is_random_per_seed() {
    let p = Lander2dParams {
        moving_platform: true,
        platform_random_start_x: true,
        ..quiet()
    };
    let mut directions = std::collections::BTreeSet::new();
    for seed in 0..32 {
        let l = Lander2d::new(p.clone(), at(25.0, 40.0), SimRng::new(seed)).unwrap();
        directions.insert(l.platform_vx().to_bits());
        assert!((2.5..=47.5).contains(&l.platform_x()), "{}", l.platform_x());
    }
    assert_eq!(directions.len(), 2);
}

#[test]
fn wind_off_does_not_crash() {
    // The reference raised with wind switched off; here it is a zero force.
    let p = Lander2dParams {
        wind_enabled: false,
        ..Default::default()
    };
    let mut l = lander(p.clone(), at(25.0, 40.0));
    assert_eq!(l.wind_force(), [0.0, 0.0]);
    let hover = p.command_for_thrust(p.hover_thrust()).unwrap();
    l.set_command([hover, hover]).unwrap();
    for _ in 0..200 {
        l.step();
    }
    assert!(l.drone().x.is_finite() && !l.crashed());
}

#[test]
fn wind_pushes_with_speed_times_coefficient_times_width() {
    let p = Lander2dParams {
        thrust_noise_std: 0.0,
        wind_direction_random: false,
        wind_direction: 0.0,
        ..Default::default()
    };
    let hover = p.command_for_thrust(p.hover_thrust()).unwrap();
    let mut l = lander(p, at(25.0, 40.0));
    assert_eq!(l.wind_force(), [2.5, 0.0]);
    l.set_command([hover, hover]).unwrap();
    l.step();
    // 2.5 N / 1.5 kg along +x.
    assert!(
        (l.acceleration()[0] - 2.5 / 1.5).abs() < 1e-9,
        "{:?}",
        l.acceleration()
    );
    assert!(l.acceleration()[1].abs() < 1e-9, "{:?}", l.acceleration());
    l.set_external_wind_force([-2.5, 0.0]).unwrap();
    let v = l.drone().vx;
    l.step();
    assert!(
        (l.drone().vx - v).abs() < 1e-12,
        "input wind cancels the episode wind"
    );
}

#[test]
fn random_wind_direction_has_the_right_magnitude_per_seed() {
    let mut angles = Vec::new();
    for seed in 0..16 {
        let l =
            Lander2d::new(Lander2dParams::default(), at(25.0, 40.0), SimRng::new(seed)).unwrap();
        let [fx, fy] = l.wind_force();
        assert!((fx.hypot(fy) - 2.5).abs() < 1e-12);
        angles.push(fy.atan2(fx));
    }
    angles.sort_by(f64::total_cmp);
    angles.dedup();
    assert_eq!(angles.len(), 16);
}

#[test]
fn huge_drain_empties_the_battery_and_cuts_thrust() {
    let p = Lander2dParams {
        battery_consumption_rate: 1e9,
        ..quiet()
    };
    let mut l = lander(p, at(25.0, 40.0));
    l.set_command([1.0, 1.0]).unwrap();
    l.step();
    // The first period still flies on the charge it started with.
    assert_eq!(l.thrust(), [15.0, 15.0]);
    assert_eq!(l.battery(), 0.0);
    l.step();
    assert_eq!(l.thrust(), [0.0, 0.0]);
    // Empty: free fall.
    assert!(
        (l.acceleration()[1] + 9.81).abs() < 1e-9,
        "{:?}",
        l.acceleration()
    );
    assert_eq!(l.battery(), 0.0);
}

#[test]
fn command_maps_minus_one_to_zero_and_one_to_max_thrust_and_noise_is_clipped() {
    let mut l = lander(quiet(), at(25.0, 40.0));
    l.set_command([-1.0, 1.0]).unwrap();
    l.step();
    assert_eq!(l.thrust(), [0.0, 15.0]);
    assert!(l.set_command([f64::NAN, 0.0]).is_err());
    l.set_command([-5.0, 5.0]).unwrap();
    assert_eq!(l.command(), [-1.0, 1.0]);

    let p = Lander2dParams {
        initial_battery: 1e9,
        ..Default::default()
    };
    let mut l = lander(p, at(25.0, 40.0));
    l.set_command([0.0, 0.9]).unwrap();
    let n = 3000;
    let (mut sum, mut sum2) = (0.0, 0.0);
    for _ in 0..n {
        l.step();
        let [left, right] = l.thrust();
        assert!((0.0..=15.0).contains(&left) && (0.0..=15.0).contains(&right));
        sum += left;
        sum2 += left * left;
    }
    let mean = sum / n as f64;
    let std = (sum2 / n as f64 - mean * mean).sqrt();
    // Noise scales with the level: σ = 1.5 N · 7.5/15 = 0.75 N around 7.5 N (clipping is 10σ
    // away): standard errors 0.014 and 0.01.
    assert!((mean - 7.5).abs() < 0.05, "{mean}");
    assert!((std - 0.75).abs() < 0.04, "{std}");
}

/// The independent check's finding: at command −1 (zero thrust by the documented mapping) the
/// reference's additive noise still gave ≈ 0.6 N mean and up to ~4 N per motor, and drained
/// the battery. A stopped motor now gives exactly zero, with the default noise on.
#[test]
fn stopped_motors_give_zero_thrust_and_drain_nothing_with_noise_on() {
    let mut l = lander(Lander2dParams::default(), at(25.0, 40.0));
    l.set_command([-1.0, -1.0]).unwrap();
    for _ in 0..500 {
        l.step();
        assert_eq!(l.thrust(), [0.0, 0.0]);
    }
    assert_eq!(l.battery(), 100.0);
    // Free fall from rest for 500 · 0.02 s would be far below the ground: it fell (no lift).
    assert!(l.crashed() || l.drone().y < 39.0);

    // One motor off, one on: only the running one drains, σ-scaled noise included.
    let mut l = lander(Lander2dParams::default(), at(25.0, 40.0));
    l.set_command([-1.0, 0.0]).unwrap();
    let mut drained = 0.0;
    for _ in 0..10 {
        l.step();
        assert_eq!(l.thrust()[0], 0.0);
        drained += l.thrust()[1] * 0.1 * 0.02;
    }
    assert!((100.0 - l.battery() - drained).abs() < 1e-9);
}

#[test]
fn same_seed_gives_a_bit_identical_trajectory() {
    let run = |seed| {
        let mut l =
            Lander2d::new(Lander2dParams::default(), at(25.0, 30.0), SimRng::new(seed)).unwrap();
        let mut trace = Vec::new();
        for i in 0..400 {
            let a = (i as f64 * 0.05).sin() * 0.3;
            l.set_command([a, -a]).unwrap();
            l.step();
            trace.extend(fingerprint(&l));
        }
        trace
    };
    assert_eq!(run(11), run(11));
    assert_ne!(run(11), run(12));
}

#[test]
fn save_restore_continue_equals_an_uninterrupted_run() {
    // Thrust noise on (the RNG is part of the state); wind off so the drone stays over the pad.
    let p = Lander2dParams {
        moving_platform: true,
        platform_speed: 0.5,
        wind_enabled: false,
        ..Default::default()
    };
    let mut a = Lander2d::new(p, at(25.0, 11.0), SimRng::new(5)).unwrap();
    let mut snapshots = Vec::new();
    // Snapshots in the air, at touch-down and riding on the moving pad (warm-started
    // contacts in the narrow phase).
    for i in 0..400 {
        descend(&mut a, 0.5);
        if i % 40 == 0 || i == 30 {
            snapshots.push((i, a.save().unwrap(), fingerprint(&a)));
        }
    }
    assert!(
        a.contact().on_platform && a.landed(),
        "the run must end on the pad: {a:?}"
    );
    for (i, bytes, print) in snapshots {
        let mut b = Lander2d::restore(&bytes).unwrap();
        assert_eq!(fingerprint(&b), print, "restore at step {i}");
        let mut c = Lander2d::restore(&bytes).unwrap();
        for _ in i..399 {
            descend(&mut b, 0.5);
            descend(&mut c, 0.5);
        }
        assert_eq!(fingerprint(&b), fingerprint(&a), "continued from step {i}");
        assert_eq!(
            b.save().unwrap(),
            a.save().unwrap(),
            "continued from step {i}"
        );
    }
}

#[test]
fn garbage_restore_bytes_are_an_error() {
    let l = lander(Lander2dParams::default(), at(25.0, 40.0));
    let bytes = l.save().unwrap();
    assert!(matches!(
        Lander2d::restore(&[]),
        Err(SnapshotError::WrongFormat { .. })
    ));
    assert!(matches!(
        Lander2d::restore(b"{\"x\": 1}"),
        Err(SnapshotError::WrongFormat { .. })
    ));
    let mut rng = SimRng::new(1);
    for len in [1, 15, 16, 24, 100, 5000] {
        let noise: Vec<u8> = (0..len).map(|_| rng.next_u64() as u8).collect();
        assert!(Lander2d::restore(&noise).is_err());
        // Noise behind a valid tag and length.
        let mut forged = bytes[..8].to_vec();
        forged.extend_from_slice(&(len as u64).to_le_bytes());
        forged.extend_from_slice(&noise);
        forged.extend_from_slice(&[0; 8]);
        assert!(Lander2d::restore(&forged).is_err());
    }
    for cut in [bytes.len() - 1, bytes.len() / 2, 17] {
        assert!(matches!(
            Lander2d::restore(&bytes[..cut]),
            Err(SnapshotError::WrongLength { .. })
        ));
    }
    for position in [16, bytes.len() / 2, bytes.len() - 9] {
        let mut damaged = bytes.clone();
        damaged[position] ^= 0x40;
        assert_eq!(
            Lander2d::restore(&damaged).unwrap_err(),
            SnapshotError::Checksum
        );
    }
    assert!(Lander2d::restore(&bytes).is_ok());
}

#[test]
fn a_finer_physics_step_refines_the_same_flight() {
    let run = |physics_step| {
        let p = Lander2dParams {
            physics_step,
            ..quiet()
        };
        let mut l = lander(p, at(25.0, 30.0));
        l.set_command([0.2, 0.1]).unwrap();
        for _ in 0..50 {
            l.step();
        }
        l.drone()
    };
    let (one, four) = (run(0.02), run(0.005));
    // One second of a gentle turn: the two integrations agree to a few centimetres.
    assert!(
        (one.x - four.x).abs() < 0.05 && (one.y - four.y).abs() < 0.05,
        "{one:?} {four:?}"
    );
    assert_ne!(one, four);
}

#[test]
fn the_air_velocity_is_the_drone_velocity_since_the_wind_is_a_force() {
    let p = Lander2dParams::default();
    let hover = p.command_for_thrust(p.hover_thrust()).unwrap();
    let mut l = lander(p, at(25.0, 40.0));
    l.set_external_wind_force([3.0, 0.0]).unwrap();
    l.set_command([hover, hover]).unwrap();
    for _ in 0..50 {
        l.step();
    }
    let d = l.drone();
    assert!(d.vx > 0.0, "the wind pushes it east: {d:?}");
    assert_eq!(l.air_velocity(), [d.vx, d.vy]);
}

#[test]
fn the_rapier_world_exists_only_near_the_pad_and_the_ground() {
    // A gentle descent from 10 m above the pad: the world appears within reach of the pad, is
    // there at the touch-down, and goes once the drone climbs away again.
    let mut l = lander(quiet(), at(25.0, 20.5));
    assert!(!l.in_contact_world());
    let (mut free_steps, mut world_steps) = (0, 0);
    for _ in 0..3000 {
        descend(&mut l, 0.5);
        if l.in_contact_world() {
            world_steps += 1;
            // Never built early: the drone's outline (reach 0.51 m) is within 1 m of the pad.
            assert!(l.drone().y - 10.5 < 0.51 + 1.0, "{:?}", l.drone());
        } else {
            free_steps += 1;
        }
        if l.landed() {
            break;
        }
    }
    assert!(l.landed() && l.in_contact_world(), "{l:?}");
    assert!(
        free_steps > 5 * world_steps,
        "{free_steps} free, {world_steps} in the world"
    );
    // Full thrust: it climbs out and the world is dropped again.
    l.set_command([1.0, 1.0]).unwrap();
    for _ in 0..100 {
        l.step();
    }
    assert!(
        l.drone().y > 14.0 && !l.in_contact_world(),
        "{:?}",
        l.drone()
    );
}
