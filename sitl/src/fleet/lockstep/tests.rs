use super::*;

/// A step taken: the time after it, who was due, the commands set.
type Taken = (u64, Vec<usize>, Vec<(usize, Vec<f64>)>);

/// Runs the barrier for `steps` steps, answering in `script`'s order whenever it waits.
fn drive(l: &mut Lockstep, script: &[usize], steps: usize) -> Vec<Taken> {
    let mut taken = Vec::new();
    let mut next = script.iter().cycle();
    let mut k = 0.0;
    while taken.len() < steps {
        match l.advance(false) {
            Ok(a) => taken.push((l.now_us(), a.due, a.commands)),
            Err(Hold::Waiting(_)) => {
                // Answer in the script's order, but only those the barrier awaits.
                let i = *next.next().unwrap();
                if l.is_awaited(i) {
                    k += 1.0;
                    l.answer(i, vec![k]);
                }
            }
            Err(Hold::Idle) => panic!("idle with autopilots in lockstep"),
        }
    }
    taken
}

#[test]
fn px4_and_ardupilot_steps_meet_on_the_union_of_their_grids() {
    let mut l = Lockstep::new(&[4000, 833]);
    l.connect(0, true);
    l.connect(1, true);
    assert_eq!(
        l.advance(false),
        Err(Hold::Waiting(0)),
        "nobody answered yet"
    );
    l.answer(0, vec![0.5]);
    assert_eq!(
        l.advance(false),
        Err(Hold::Waiting(1)),
        "the ArduPilot is awaited"
    );
    l.answer(1, vec![0.6]);
    let a = l.advance(false).unwrap();
    assert_eq!((a.dt_us, a.due.as_slice()), (833, &[1][..]));
    assert_eq!(a.commands, vec![(0, vec![0.5]), (1, vec![0.6])]);
    // The PX4 is mid-step: only the ArduPilot is awaited; four ArduPilot steps fit before
    // 4000 µs, then the PX4 is due at 4000 and the ArduPilot at 4165.
    let mut times = vec![l.now_us()];
    for _ in 0..4 {
        assert_eq!(l.advance(false), Err(Hold::Waiting(1)));
        l.answer(1, vec![0.6]);
        let a = l.advance(false).unwrap();
        times.push(l.now_us());
        if l.now_us() == 4000 {
            assert_eq!(a.due, vec![0]);
        }
    }
    assert_eq!(times, vec![833, 1666, 2499, 3332, 4000]);
    assert_eq!(
        l.advance(false),
        Err(Hold::Waiting(0)),
        "the PX4 is due its answer"
    );
}

#[test]
fn the_order_answers_arrive_in_changes_no_step() {
    let run = |script: &[usize]| {
        let mut l = Lockstep::new(&[4000, 4000, 833, 2500]);
        for i in 0..4 {
            l.connect(i, true);
        }
        drive(&mut l, script, 500)
    };
    let a = run(&[0, 1, 2, 3]);
    let b = run(&[3, 2, 1, 0]);
    let c = run(&[2, 0, 3, 1, 1, 2]);
    let times = |r: &Vec<Taken>| r.iter().map(|s| (s.0, s.1.clone())).collect::<Vec<_>>();
    assert_eq!(times(&a), times(&b));
    assert_eq!(times(&a), times(&c));
    // Every grid time of every autopilot is a world time.
    let worlds: Vec<u64> = a.iter().map(|s| s.0).collect();
    for step in [4000, 833, 2500] {
        for k in 1..=10 {
            assert!(worlds.contains(&(k * step)), "{} missing", k * step);
        }
    }
}

#[test]
fn a_silent_autopilot_is_left_out_and_rejoins_when_it_answers() {
    let mut l = Lockstep::new(&[4000, 4000]);
    l.connect(0, true);
    l.connect(1, true);
    l.answer(0, vec![1.0]);
    l.answer(1, vec![1.0]);
    l.advance(false).unwrap();
    l.answer(0, vec![1.0]);
    assert_eq!(l.advance(false), Err(Hold::Waiting(1)));
    l.silence(1);
    for _ in 0..10 {
        l.advance(false).unwrap();
        l.answer(0, vec![1.0]);
    }
    assert_eq!(l.now_us(), 44_000);
    assert_eq!(l.slot(1).phase, Phase::Silent);
    // It answers again: set at once, back in the barrier from now.
    assert_eq!(l.answer(1, vec![0.3]), Some(vec![0.3]));
    assert_eq!(l.slot(1).next_us, Some(48_000));
    let a = l.advance(false).unwrap();
    assert_eq!((l.now_us(), a.due), (48_000, vec![0, 1]));
}

#[test]
fn free_autopilots_hold_nothing_back_and_absent_ones_get_nothing() {
    let mut l = Lockstep::new(&[4000, 4000, 4000]);
    assert_eq!(l.advance(true), Err(Hold::Idle), "nobody connected");
    l.connect(0, false);
    assert_eq!(
        l.advance(false),
        Err(Hold::Idle),
        "free steps only when asked"
    );
    let a = l.advance(true).unwrap();
    assert_eq!((a.dt_us, a.due), (4000, vec![0]));
    l.connect(1, true);
    l.answer(1, vec![0.2]);
    // In lockstep now: free autopilot 0 is carried along, absent 2 gets nothing.
    let a = l.advance(false).unwrap();
    assert_eq!((l.now_us(), a.due), (8000, vec![0, 1]));
    assert_eq!(l.advance(false), Err(Hold::Waiting(1)));
    // Its first answer puts autopilot 0 in lockstep for the step under way.
    assert_eq!(l.answer(0, vec![0.4]), Some(vec![0.4]));
    l.answer(1, vec![0.2]);
    let a = l.advance(false).unwrap();
    assert_eq!((l.now_us(), a.due), (12_000, vec![0, 1]));
    assert_eq!(l.advance(false), Err(Hold::Waiting(0)));
    l.disconnect(0);
    assert_eq!(l.advance(false), Err(Hold::Waiting(1)));
}
