//! The physics grid: any step size that is a multiple of `max_substep` integrates the same
//! intervals, so the same bits come out at the shared times — in the air, through the impact
//! and on the ground, with wind. A step size off the grid ends in partial pieces and stays
//! close. The snapshot keeps the grid phase.

// Test code: a failed unwrap is a failed test.

use flyloop_core::quadrotor::{BodyState, Quadrotor, QuadrotorInitial, QuadrotorParams};

/// The case: dropped from 20 m, motors off, wind on (mean 2–4 m/s + turbulence),
/// seed 11; 4 s take it to the ground (~2 s) and through its bounces.
fn dropped() -> Quadrotor {
    let params = QuadrotorParams {
        wind_speed_min: 2.0,
        wind_speed_max: 4.0,
        ..Default::default()
    };
    let initial = QuadrotorInitial {
        seed: 11,
        initial_z: 20.0,
        initial_motor: 0.0,
        ..Default::default()
    };
    Quadrotor::from_initial(params, &initial).unwrap()
}

/// The body every 0.02 s over `seconds`, stepped at `h`.
fn every_20ms(h: f64, seconds: f64) -> Vec<BodyState> {
    let mut quad = dropped();
    let per = (0.02 / h).round() as usize;
    let mut out = vec![quad.body];
    for k in 1..=(seconds / h).round() as usize {
        quad.step(h);
        if k % per == 0 {
            out.push(quad.body);
        }
    }
    out
}

#[test]
fn a_windy_drop_gives_the_same_bits_at_every_shared_time_for_h_on_the_grid() {
    let reference = every_20ms(0.02, 4.0);
    assert_eq!(reference.len(), 201);
    for h in [0.005, 0.01] {
        let run = every_20ms(h, 4.0);
        assert_eq!(run.len(), reference.len());
        for (k, (a, b)) in run.iter().zip(&reference).enumerate() {
            assert_eq!(a, b, "h = {h}: t = {:.2} s", 0.02 * k as f64);
        }
    }
    // A real test: it fell to the ground, bounced, and the wind pushed it sideways.
    let z: Vec<f64> = reference.iter().map(|b| b.position.z).collect();
    let landed = z.iter().position(|&z| z < 0.2).unwrap();
    assert!(
        (80..120).contains(&landed),
        "reached the ground at sample {landed}"
    );
    // The gear springs it back up (a 20 m/s impact), lower than it fell, twice.
    let after = &z[landed..];
    let top = after.iter().copied().fold(f64::MIN, f64::max);
    let bottom = after.iter().copied().fold(f64::MAX, f64::min);
    assert!(top > 1.0 && top < 5.0 && bottom > -0.2, "{after:?}");
    let bounces = after
        .windows(3)
        .filter(|w| w[1] < w[0] && w[1] < w[2])
        .count();
    assert!(bounces >= 2, "{after:?}");
    let end = reference.last().unwrap();
    assert!(
        end.position.x.hypot(end.position.y) > 0.1,
        "{:?}",
        end.position
    );
    assert!(end.velocity.norm() < 10.0, "{:?}", end.velocity);
}

#[test]
fn a_step_off_the_grid_ends_in_a_partial_piece_and_stays_close() {
    // PX4's 4 ms step on the default 5 ms grid: 0.02 s is a shared time of both.
    let reference = every_20ms(0.02, 1.8);
    let run = every_20ms(0.004, 1.8);
    assert_eq!(run.len(), reference.len());
    let gap = run
        .iter()
        .zip(&reference)
        .map(|(a, b)| (a.position - b.position).norm())
        .fold(0.0, f64::max);
    // Integration error only (RK4, pieces of 1–5 ms): far below a millimetre in the air.
    assert!(gap > 0.0 && gap < 1e-6, "{gap}");
}

#[test]
fn the_snapshot_keeps_the_grid_phase() {
    let mut a = dropped();
    a.step(0.004); // 1 ms short of the grid point
    let mut b = Quadrotor::restore(&a.save().unwrap()).unwrap();
    assert_eq!(a, b);
    for _ in 0..100 {
        a.step(0.004);
        b.step(0.004);
    }
    assert_eq!(a.body, b.body);
    // Bytes of another version are refused, not misread.
    let mut bytes = a.save().unwrap();
    let at = bytes.windows(8).position(|w| w == b"FLYQUA05").unwrap();
    bytes[at + 7] = b'4';
    assert!(Quadrotor::restore(&bytes).is_err());
}
