//! The Lander2D's physics grid: rapier steps, thrust noise and battery drain on the fixed grid
//! k·physics_step from the start, whatever the control period `dt`. Every `dt` that is a
//! multiple of `physics_step` gives the same bits at the shared times — in the air, through
//! the impact and resting after it, with wind and thrust noise. A `dt` off the grid ends its
//! periods in shortened rapier steps, lands on its times exactly and stays close. The
//! snapshot keeps the grid phase.

// Test code: a failed unwrap is a failed test.

use flyloop_core::lander2d::{DroneState, Lander2d, Lander2dParams};
use flyloop_core::rng::SimRng;

/// The lander on a 5 ms physics grid with control period `dt`, wind on (2.5 N, direction
/// drawn from seed 11), thrust noise on, 20 m above the ground (y = 30) over the pad.
fn dropped(dt: f64) -> Lander2d {
    let params = Lander2dParams {
        dt,
        physics_step: 0.005,
        ..Default::default()
    };
    let start = DroneState {
        x: 25.0,
        y: 30.0,
        ..Default::default()
    };
    Lander2d::new(params, start, SimRng::new(11)).unwrap()
}

/// Every number of the state that does not name the control period (the mean acceleration
/// and the period count do), as bits.
fn bits(l: &Lander2d) -> Vec<u64> {
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
        c.touchdown_speed,
        c.touchdown_angle,
        l.time(),
    ]
    .into_iter()
    .chain(l.thrust())
    .map(f64::to_bits)
    .chain([l.landed(), l.crashed(), c.on_platform, c.on_ground].map(u64::from))
    .collect()
}

/// The state every 0.02 s over `seconds`, stepped at `dt`, the commands of `command` held
/// per 0.02 s.
fn every_20ms(dt: f64, seconds: f64, command: impl Fn(usize) -> [f64; 2]) -> Vec<Vec<u64>> {
    let mut l = dropped(dt);
    let per = (0.02 / dt).round() as usize;
    let mut out = vec![bits(&l)];
    for k in 0..(seconds / 0.02).round() as usize {
        l.set_command(command(k)).unwrap();
        for _ in 0..per {
            l.step();
        }
        assert_eq!(l.steps(), ((k + 1) * per) as u64);
        out.push(bits(&l));
    }
    out
}

fn same_at_every_shared_time(command: impl Fn(usize) -> [f64; 2] + Copy) -> Vec<Vec<u64>> {
    let reference = every_20ms(0.02, 4.0, command);
    assert_eq!(reference.len(), 201);
    for dt in [0.005, 0.01] {
        let run = every_20ms(dt, 4.0, command);
        for (k, (a, b)) in run.iter().zip(&reference).enumerate() {
            assert_eq!(a, b, "dt = {dt}: t = {:.2} s", 0.02 * k as f64);
        }
    }
    reference
}

fn y(bits: &[u64]) -> f64 {
    f64::from_bits(bits[1])
}

#[test]
fn a_windy_drop_with_the_motors_off_is_the_same_at_every_dt_on_the_grid() {
    let reference = same_at_every_shared_time(|_| [-1.0, -1.0]);
    // A real test: the wind (2.5 N along +x here) carried it 3.3 m sideways, past the pad's
    // edge (27.5 m, the drone's half width 0.5 m), and it fell the 20 m in 2 s onto the
    // ground, hit it at 19.9 m/s (a crash) and lies on it (ground 10 m, half height 0.1 m).
    let x = |b: &[u64]| f64::from_bits(b[0]);
    let vy = |b: &[u64]| f64::from_bits(b[4]);
    let flags = |b: &[u64]| b[b.len() - 4..].to_vec();
    let hit = reference.iter().position(|b| y(b) < 10.11).unwrap();
    assert_eq!(hit, 101, "on the ground at sample {hit}");
    assert!((vy(&reference[100]) + 19.87).abs() < 0.01);
    assert_eq!(flags(&reference[100]), [0, 0, 0, 0], "in the air before");
    let end = reference.last().unwrap();
    assert!((y(end) - 10.1).abs() < 1e-3, "{}", y(end));
    assert!((x(end) - 28.33).abs() < 0.01, "{}", x(end));
    // landed, crashed, on the pad, on the ground.
    assert_eq!(flags(end), [0, 1, 0, 1]);
}

#[test]
fn thrust_noise_and_battery_live_on_the_grid_not_on_the_control_period() {
    // A weave around hover, held per 0.02 s: the noise is drawn every 5 ms, so at dt = 0.005,
    // 0.01 and 0.02 the same draws meet the same commands.
    let weave = |k: usize| {
        let a = 0.3 * (k as f64 * 0.1).sin();
        [-0.02 + a, -0.02 - a]
    };
    let reference = same_at_every_shared_time(weave);
    let battery = f64::from_bits(reference.last().unwrap()[6]);
    // 4 s at ≈ 2 × 7.35 N: 100 − 4 × 14.7 × 0.1 ≈ 94.1, noise and weave included.
    assert!((battery - 94.1).abs() < 0.3, "{battery}");
    // It flew: thrust on, noisy (not exactly the commanded level).
    let thrust = f64::from_bits(reference[100][11]);
    assert!(thrust > 5.0 && thrust != 7.35, "{thrust}");
}

#[test]
fn a_dt_off_the_grid_cuts_the_grid_steps_ends_on_its_times_and_stays_close() {
    // 7 ms periods on the 5 ms grid: 0.14 s is a shared time (20 periods, 28 grid steps).
    let mut off = dropped(0.007);
    let mut on = dropped(0.005);
    let hover = off.params().command_for_thrust(7.0).unwrap();
    off.set_command([hover, hover]).unwrap();
    on.set_command([hover, hover]).unwrap();
    let mut gap: f64 = 0.0;
    for n in 1..=200 {
        off.step();
        assert!(
            (off.time() - n as f64 * 0.007).abs() < 1e-12,
            "period {n} ends at {}",
            off.time()
        );
        assert_eq!(off.steps(), n);
        assert!(off.at_period_boundary());
        if n % 20 == 0 {
            for _ in 0..28 {
                on.step();
            }
            let (a, b) = (off.drone(), on.drone());
            gap = gap.max((a.x - b.x).hypot(a.y - b.y));
        }
    }
    // The same grid steps' noise, pieces of 1–5 ms instead of 5 ms: the symplectic Euler
    // error of a slow descent, far below a millimetre after 1.4 s.
    assert!(gap > 0.0 && gap < 1e-3, "{gap}");
    // The battery drained the same grid steps (the drain is taken at each step's start).
    assert!((off.battery() - on.battery()).abs() < 1e-9);
}

#[test]
fn the_snapshot_keeps_the_grid_phase() {
    let mut a = dropped(0.007);
    a.set_command([0.0, 0.0]).unwrap();
    a.step(); // 2 ms into the second grid step
    let mut b = Lander2d::restore(&a.save().unwrap()).unwrap();
    for _ in 0..100 {
        a.step();
        b.step();
    }
    assert_eq!(bits(&a), bits(&b));
    assert_eq!(a.save().unwrap(), b.save().unwrap());
    // Bytes of the version before the grid are refused, not misread.
    let mut bytes = a.save().unwrap();
    assert_eq!(&bytes[..8], b"FLYL2D04");
    bytes[7] = b'2';
    assert!(Lander2d::restore(&bytes).is_err());
}

#[test]
fn the_clock_parameters_are_checked_and_fixed_once_running() {
    let mut l = dropped(0.02);
    let e = l.set_parameter("physics_step", 0.0).unwrap_err();
    assert_eq!(
        e.to_string(),
        "parameter `physics_step` = 0 s is out of range: it must be in [0.0001, 1] s"
    );
    l.set_parameter("physics_step", 0.01).unwrap();
    l.step();
    let e = l.set_parameter("physics_step", 0.005).unwrap_err();
    assert!(e.to_string().contains("`physics_step`"), "{e}");
    assert!(e.to_string().contains("only before the first step"), "{e}");
    assert!(l.set_parameter("dt", 0.01).is_err());
    // Other parameters still change on a running instance; the clock is untouched.
    l.set_parameter("max_thrust", 20.0).unwrap();
    assert_eq!((l.time(), l.params().physics_step), (0.02, 0.01));
}
