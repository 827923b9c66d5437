//! The error budget of view interpolation on the tiny stage's oracle field (every walk
//! cycle repeats, so the truth between views is what interpolation should reach): every
//! offset and method is scored, the captured views reproduce themselves whichever way
//! they are rendered, and the solved morph stays near the floor of flow-based morphs
//! where E06's four-way morph does not.

#![allow(clippy::unwrap_used)] // tests: a failed unwrap is a failed test

use std::sync::Mutex;
use std::sync::atomic::{AtomicUsize, Ordering};

use frf_core::env::EnvMap;
use frf_core::progress::Progress;
use frf_eval::budget::{self, BudgetInputs, Direction, FLOOR, ULR_HULL, ULR_TRUE};
use frf_render::morph::Variant;
use frf_render::renderer::Renderer;
use frf_render::resident::ResidentPose;

/// Counts the phases announced and the steps done.
#[derive(Default)]
struct Steps {
    phases: Mutex<Vec<usize>>,
    done: AtomicUsize,
}

impl Progress for Steps {
    fn phase(&self, _what: &str, total: usize) {
        self.phases.lock().unwrap().push(total);
    }
    fn step(&self) {
        self.done.fetch_add(1, Ordering::Relaxed);
    }
}

#[test]
fn the_budget_scores_every_offset_and_the_solved_morph_sits_near_the_floor() {
    let tiny = frf_testkit::tiny_field();
    let env = EnvMap::sky();
    let source = tiny.source(&env);
    let renderer = Renderer::new(&source, None).unwrap();
    let resident = ResidentPose::relight_cpu(&source);
    let lights = env.median_cut(64);
    let inputs = BudgetInputs {
        renderer: &renderer,
        resident: &resident,
        stage: &tiny.stage,
        pose: 0,
        lights: &lights,
        keep: None,
    };
    let steps = Steps::default();
    let variants = [Variant::FourWayE06, Variant::FourWay];
    let rows = budget::run(&inputs, 2, &variants, &steps).unwrap();
    eprint!("{}", budget::table(&rows));
    assert_eq!(rows.len(), budget::offsets().len());
    // One phase, as many steps as it announced.
    assert_eq!(
        steps.phases.into_inner().unwrap(),
        vec![budget::frames(2, variants.len())]
    );
    assert_eq!(steps.done.into_inner(), budget::frames(2, variants.len()));
    let psnr = |row: &budget::BudgetRow, name: &str| row.method(name).unwrap().psnr_subject;
    for row in &rows {
        for name in ["fourway-e06", "fourway", FLOOR, ULR_HULL, ULR_TRUE] {
            let m = row.method(name).unwrap();
            assert!(
                m.psnr_subject.is_finite() && m.psnr_subject > 10.0,
                "{name}: {m:?}"
            );
            assert!((0.0..=1.0).contains(&m.ssim_subject), "{name}: {m:?}");
        }
    }
    // At the captured views every flow-based method returns the view itself.
    let captured = &rows[0];
    assert_eq!(captured.direction, Direction::Captured);
    for name in ["fourway-e06", FLOOR] {
        assert!(
            (psnr(captured, name) - psnr(captured, "fourway")).abs() < 0.05,
            "{name} at the captured views: {captured:?}"
        );
    }
    // Between views: the solved morph within 1.5 dB of the floor everywhere (measured:
    // within 0.4 dB), E06's four-way far below it at the quad's centre (measured: 4.9 dB
    // under the solved morph, 21.4 against 26.3 dB).
    for row in &rows[1..] {
        let (solved, floor) = (psnr(row, "fourway"), psnr(row, FLOOR));
        assert!(solved > floor - 1.5, "{row:?}");
        assert!(
            floor < psnr(captured, FLOOR) + 0.5,
            "the floor above the views: {row:?}"
        );
    }
    let centre = rows
        .iter()
        .find(|r| r.direction == Direction::Centre && r.beta == 0.5)
        .unwrap();
    assert!(
        psnr(centre, "fourway") > psnr(centre, "fourway-e06") + 3.0,
        "{centre:?}"
    );
}
