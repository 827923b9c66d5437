//! The treadmill gait's feet: a foot on the belt is level on it and moves with it at the
//! belt's speed exactly (no sliding), no part of the body goes through the belt, a walk
//! always has a foot down and a run's feet are both up only in its flight phases.

#![allow(clippy::unwrap_used)] // tests: a failed unwrap is a failed test

use frf_stage::actor::Part;
use frf_stage::body::SOLE_POINT;
use frf_stage::{Gait, Preset, Stage, StageConfig};

fn stage(gait: Gait) -> Stage {
    let mut c = StageConfig::preset(Preset::Tiny);
    c.gait = gait;
    Stage::new(c).unwrap()
}

/// Samples per cycle: 1 ms apart walking, 0.7 ms running.
const SAMPLES: usize = 1000;

#[test]
fn planted_feet_move_with_the_belt_and_rest_on_it() {
    for gait in [Gait::Walk, Gait::Run] {
        let stage = stage(gait);
        let (cycle, v) = (gait.cycle_seconds(), gait.speed_mps());
        let mut worst_slide = 0.0f64;
        let mut worst_height = 0.0f64;
        let mut stances = 0;
        for foot in 0..2 {
            // Where the foot is in the belt's frame (moving at -v): constant in a stance.
            let mut stance: Vec<f64> = Vec::new();
            for k in 0..=2 * SAMPLES {
                let t = cycle * k as f64 / SAMPLES as f64;
                let c = stage.feet_at(t)[foot];
                if c.down {
                    stance.push(c.point.x as f64 + v * t);
                    worst_height = worst_height.max((c.point.y as f64).abs());
                } else if !stance.is_empty() {
                    let (lo, hi) = stance
                        .iter()
                        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &x| {
                            (lo.min(x), hi.max(x))
                        });
                    assert!(
                        stance.len() > 100,
                        "{gait:?}: a stance of {} samples",
                        stance.len()
                    );
                    worst_slide = worst_slide.max(hi - lo);
                    stances += 1;
                    stance.clear();
                }
            }
        }
        assert!(stances >= 3, "{gait:?}: {stances} stances");
        // Within 0.1 mm; measured 0.3 µm walking, 0.5 µm running (f32 rounding).
        assert!(
            worst_slide < 1e-4,
            "{gait:?}: a planted foot slides {worst_slide} m"
        );
        assert!(
            worst_height < 1e-4,
            "{gait:?}: a planted sole at {worst_height} m"
        );
    }
}

#[test]
fn the_feet_are_those_of_the_posed_walker() {
    for gait in [Gait::Walk, Gait::Run] {
        let stage = stage(gait);
        for k in 0..20 {
            let t = gait.cycle_seconds() * k as f64 / 20.0;
            let actor = stage.true_actor_at(t);
            let feet = stage.feet_at(t);
            for (foot, part) in feet.iter().zip([Part::FootLeft, Part::FootRight]) {
                let posed = actor.point(part, SOLE_POINT);
                assert!((posed - foot.point).length() < 1e-5, "{gait:?} {t}");
            }
            // The left foot is on the -z side.
            assert!(feet[0].point.z < 0.0 && feet[1].point.z > 0.0);
        }
    }
}

#[test]
fn no_part_of_the_body_goes_through_the_belt() {
    for gait in [Gait::Walk, Gait::Run] {
        let stage = stage(gait);
        let mut lowest = f32::INFINITY;
        for k in 0..SAMPLES {
            let t = gait.cycle_seconds() * k as f64 / SAMPLES as f64;
            lowest = lowest.min(stage.true_actor_at(t).lowest_y());
        }
        assert!(lowest > -1e-3, "{gait:?}: lowest point {lowest} m");
        assert!(
            lowest < 1e-4,
            "{gait:?}: never touches the belt ({lowest} m)"
        );
    }
}

#[test]
fn a_walk_always_has_a_foot_down_and_a_run_flies_between_stances() {
    for gait in [Gait::Walk, Gait::Run] {
        let stage = stage(gait);
        let (mut both_down, mut both_up) = (0, 0);
        for k in 0..SAMPLES {
            let t = gait.cycle_seconds() * k as f64 / SAMPLES as f64;
            let [l, r] = stage.feet_at(t);
            both_down += usize::from(l.down && r.down);
            both_up += usize::from(!l.down && !r.down);
        }
        let fraction = |n: usize| n as f64 / SAMPLES as f64;
        let duty = f64::from(gait.duty_factor());
        match gait {
            Gait::Walk => {
                assert_eq!(both_up, 0, "the walker leaves the belt");
                // Double support: twice per cycle, 2 (duty - 1/2) of it in all.
                assert!((fraction(both_down) - 2.0 * (duty - 0.5)).abs() < 0.005);
            }
            Gait::Run => {
                assert_eq!(both_down, 0, "the runner has both feet down");
                // Flight: twice per cycle, 1 - 2 duty of it in all.
                assert!((fraction(both_up) - (1.0 - 2.0 * duty)).abs() < 0.005);
            }
        }
    }
}
