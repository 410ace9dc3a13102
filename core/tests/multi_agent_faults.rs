//! Faults in the multi-agent tasks (issue 35): tables for every agent or one (`agent`), drawn
//! per agent from the episode's seed, the actuator path inside the shared world, one info
//! layout for every agent, and bad input named.

use flyloop_core::quadrotor::model::hover_motor_state;
use flyloop_core::rng::SimRng;
use flyloop_core::tasks::InfoRef;
use flyloop_core::tasks::multi::{AgentFaults, MultiConfig, MultiFlight, Scenario};

fn task(agents: u32, faults: &str) -> MultiFlight {
    let config = MultiConfig::from_values([("num_agents", f64::from(agents))], Vec::new())
        .unwrap()
        .with_faults(AgentFaults::from_toml_str(faults).unwrap())
        .unwrap();
    MultiFlight::new(Scenario::MultiHover, config).unwrap()
}

fn config_error(agents: u32, faults: &str) -> String {
    let config = MultiConfig::from_values([("num_agents", f64::from(agents))], Vec::new()).unwrap();
    match AgentFaults::from_toml_str(faults) {
        Err(e) => e.to_string(),
        Ok(f) => config.with_faults(f).unwrap_err().to_string(),
    }
}

/// Agent `i`'s info vector `name`.
fn slots(t: &MultiFlight, i: usize, name: &str) -> Vec<f64> {
    let mut found = Vec::new();
    t.visit_info(i, &mut |n, v| {
        if let (true, InfoRef::Vector(x)) = (n == name, v) {
            found = x.to_vec();
        }
    });
    found
}

fn info_len(t: &MultiFlight, i: usize) -> usize {
    let mut n = 0;
    t.visit_info(i, &mut |_, v| {
        n += match v {
            InfoRef::Vector(x) => x.len(),
            _ => 1,
        }
    });
    n
}

/// The hover motor state of the nominal vehicle.
fn hover(t: &MultiFlight) -> f64 {
    let q = t.world().vehicle(0);
    hover_motor_state(q.params(), q.frame()).unwrap()
}

#[test]
fn a_weak_motor_of_one_agent_gives_that_agent_its_share_of_thrust() {
    // Agent 1's motor 1 at effectiveness 0.5 from t = 0; agent 0 healthy.
    let mut t = task(
        2,
        "[[faults]]\nkind = \"motor_effectiveness\"\nmotor = 1\neffectiveness = 0.5\nagent = 1\n",
    );
    t.reset(7).unwrap();
    let h = hover(&t);
    // The events the front ends report: agent 1's fault fired at 0, agent 0 has none.
    t.step(&[h; 8]).unwrap();
    let events = t.fault_events(1);
    assert_eq!(events.len(), 1);
    assert!(events[0].fired && events[0].time == 0.0, "{events:?}");
    assert_eq!(events[0].label, "motor_effectiveness:1");
    assert!(t.fault_events(0).is_empty());
    t.reset(7).unwrap();
    // Same command for both: the weak rotor settles to √0.5 of the state (τ = 0.08 s).
    for _ in 0..50 {
        t.step(&[h; 8]).unwrap();
    }
    let ratio = t.world().vehicle(1).thrust() / t.world().vehicle(0).thrust();
    let tau = t.world().vehicle(0).params().motor_time_constant;
    let weak = h * (0.5f64.sqrt() + (1.0 - 0.5f64.sqrt()) * (-0.5 / tau).exp());
    let expected = (3.0 * h * h + weak * weak) / (4.0 * h * h);
    assert!(
        (ratio - expected).abs() < 1e-3,
        "thrust ratio {ratio}, analytic {expected}"
    );
    assert!(ratio < 0.88, "{ratio}");
    // Commanding the weak motor h/√0.5 gives it the healthy thrust again.
    t.reset(7).unwrap();
    let mut actions = [h; 8];
    actions[4] = h / 0.5f64.sqrt();
    for _ in 0..50 {
        t.step(&actions).unwrap();
    }
    let ratio = t.world().vehicle(1).thrust() / t.world().vehicle(0).thrust();
    assert!(
        (ratio - 1.0).abs() < 1e-12,
        "compensated thrust ratio {ratio}"
    );
    // The slots: agent 1 has the fault (motor_effectiveness = kind 0, motor 1, fired at 0).
    assert_eq!(slots(&t, 1, "fault_kind"), [0.0]);
    assert_eq!(slots(&t, 1, "fault_target"), [1.0]);
    assert_eq!(slots(&t, 1, "fault_time"), [0.0]);
    assert_eq!(slots(&t, 1, "fault_active"), [1.0]);
    // Agent 0 reports the same slot, empty.
    assert_eq!(slots(&t, 0, "fault_kind"), [-1.0]);
    assert_eq!(slots(&t, 0, "fault_time"), [-1.0]);
    assert_eq!(slots(&t, 0, "fault_active"), [0.0]);
    assert_eq!(info_len(&t, 0), info_len(&t, 1));
}

const DRAW: &str = "[[fault_randomization]]\nkinds = [\"motor_effectiveness\"]\nat = [0.0, 0.5]\neffectiveness = [0.5, 1.0]\n";

/// Every agent's slots and observations over `steps` steps of random actions, as bits.
fn trace(t: &mut MultiFlight, seed: u64, steps: usize) -> Vec<u64> {
    t.reset(seed).unwrap();
    let n = t.num_agents();
    let mut rng = SimRng::new(5);
    let mut obs = vec![0.0f32; n * t.observation_size()];
    let mut out = Vec::new();
    for _ in 0..steps {
        let actions: Vec<f64> = (0..n * 4).map(|_| rng.uniform(0.45, 0.55)).collect();
        t.step(&actions).unwrap();
        t.write_observations(&mut obs);
        out.extend(obs.iter().map(|v| u64::from(v.to_bits())));
        for i in 0..n {
            for name in ["fault_kind", "fault_target", "fault_time", "fault_active"] {
                out.extend(slots(t, i, name).iter().map(|v| v.to_bits()));
            }
        }
    }
    out
}

#[test]
fn draws_are_per_agent_from_the_episode_seed_bit_for_bit() {
    let mut a = task(4, DRAW);
    let mut b = task(4, DRAW);
    assert_eq!(trace(&mut a, 11, 60), trace(&mut b, 11, 60));
    assert_ne!(trace(&mut a, 11, 60), trace(&mut a, 12, 60));
    // Each agent draws its own fault: over a few seeds the agents' motors and times differ.
    let mut distinct = 0;
    for seed in 0..5 {
        a.reset(seed).unwrap();
        for _ in 0..30 {
            a.step(&[0.5; 16]).unwrap();
        }
        let drawn: Vec<(Vec<f64>, Vec<f64>)> = (0..4)
            .map(|i| (slots(&a, i, "fault_target"), slots(&a, i, "fault_time")))
            .collect();
        distinct += usize::from(drawn.iter().any(|d| *d != drawn[0]));
        for i in 0..4 {
            assert_eq!(slots(&a, i, "fault_kind"), [0.0], "seed {seed} agent {i}");
            let m = slots(&a, i, "fault_target")[0];
            assert!((1.0..=4.0).contains(&m), "motor {m}");
        }
    }
    assert_eq!(distinct, 5);
}

#[test]
fn without_faults_the_task_flies_as_before_and_has_no_fault_info() {
    let config = MultiConfig::from_values([("num_agents", 3.0)], Vec::new()).unwrap();
    let mut plain = MultiFlight::new(Scenario::Swap, config.clone()).unwrap();
    let empty = config.with_faults(AgentFaults::default()).unwrap();
    let mut with_empty = MultiFlight::new(Scenario::Swap, empty).unwrap();
    assert_eq!(trace(&mut plain, 3, 40), trace(&mut with_empty, 3, 40));
    assert!(slots(&plain, 0, "fault_kind").is_empty());
    // A fault that never fires within the episode leaves the flight's bits alone too.
    let late = "[[faults]]\nkind = \"motor_off\"\nmotor = 2\nat = 9.0\n";
    let mut t = MultiFlight::new(
        Scenario::Swap,
        MultiConfig::from_values([("num_agents", 3.0)], Vec::new())
            .unwrap()
            .with_faults(AgentFaults::from_toml_str(late).unwrap())
            .unwrap(),
    )
    .unwrap();
    t.reset(3).unwrap();
    plain.reset(3).unwrap();
    for _ in 0..40 {
        t.step(&[0.5; 12]).unwrap();
        plain.step(&[0.5; 12]).unwrap();
    }
    for i in 0..3 {
        assert_eq!(t.world().vehicle(i).body(), plain.world().vehicle(i).body());
    }
}

#[test]
fn bad_faults_are_refused_naming_the_field() {
    let motor_off = "[[faults]]\nkind = \"motor_off\"\nmotor = 1\n";
    let e = config_error(4, &format!("{motor_off}agent = 4\n"));
    assert!(e.contains("`agent` = 4") && e.contains("[0, 3]"), "{e}");
    let e = config_error(4, &format!("{motor_off}agent = -1\n"));
    assert!(e.contains("`agent`"), "{e}");
    let e = config_error(4, &format!("{motor_off}agent = \"drone_1\"\n"));
    assert!(e.contains("`agent`"), "{e}");
    let e = config_error(4, "[[faults]]\nkind = \"gust\"\n");
    assert!(e.contains("`gust`") && e.contains("multi-agent"), "{e}");
    let e = config_error(4, "[[faults]]\nkind = \"link_loss\"\nduration = 1\n");
    assert!(
        e.contains("`link_loss`") && e.contains("multi-agent"),
        "{e}"
    );
    let e = config_error(
        4,
        "[[fault_randomization]]\nkinds = [\"motor_off\", \"wind_shear\"]\n",
    );
    assert!(e.contains("`wind_shear`"), "{e}");
    let e = config_error(4, "[[faults]]\nkind = \"motor_off\"\nmotor = 5\n");
    assert!(e.contains("`motor`") && e.contains("[0, 4]"), "{e}");
    let e = config_error(
        4,
        "[[faults]]\nkind = \"motor_effectiveness\"\neffectiveness = 1.5\nagent = 0\n",
    );
    assert!(e.contains("`effectiveness`") && e.contains("[0, 1]"), "{e}");
    let e = config_error(4, "[[faults]]\nkind = \"motor_off\"\nat_waypoint = 1\n");
    assert!(e.contains("at_waypoint"), "{e}");
    let e = config_error(4, "[[faults]]\nkind = \"motor_off\"\nat = 100.0\n");
    assert!(e.contains("`at`"), "{e}");
    let e = config_error(4, "[[fault]]\nkind = \"motor_off\"\n");
    assert!(e.contains("fault"), "{e}");
}
