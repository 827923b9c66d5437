//! The error budget of ingest on a tiny stage capture whose walk cycles repeat: every
//! component is scored, the budget's own ingest is `frf ingest`'s, every component taken
//! from the truth at once is the oracle field of `frf stage field`, the fields are
//! reused when asked for again with the same settings, and bad requests are refused by
//! name.

#![allow(clippy::unwrap_used)] // tests: a failed unwrap is a failed test

use std::path::{Path, PathBuf};

use frf_core::env::EnvMap;
use frf_core::progress::Silent;
use frf_eval::ingest_budget::fields::{MADE_FILE, write_fields};
use frf_eval::ingest_budget::{BudgetScoring, Component, evaluate_fields};
use frf_eval::oracle::{OracleOptions, write_oracle_field};
use frf_flow::Preset;
use frf_ingest::pipeline::{IngestOptions, ingest};
use frf_ingest::shadows::ShadowOptions;
use frf_reflectance::project::FloorModel;
use frf_render::resident::Lighting;
use frf_stage::{Preset as StagePreset, SetFlowTruth, Stage, StageConfig, write_capture};

fn options() -> IngestOptions {
    IngestOptions {
        poses: vec![0],
        flow_preset: Preset::Fast,
        ..IngestOptions::default()
    }
}

/// Scores `fields` beside `given` under the built-in sky, on the CPU reference.
fn scored(
    stage: &Stage,
    fields: &[(Component, PathBuf)],
    given: &Path,
) -> (Vec<frf_eval::ingest_budget::ComponentScore>, (f64, f64)) {
    let env = EnvMap::sky();
    let lights = env.median_cut(64);
    let lighting = Lighting::Environment {
        env,
        floor: FloorModel::Environment,
    };
    let scoring = BudgetScoring {
        stage,
        pose: 0,
        lighting: &lighting,
        lights: &lights,
        cameras: 2,
        cpu: true,
        images: None,
    };
    let (rows, given, _) = evaluate_fields(fields, Some(given), &scoring, &Silent).unwrap();
    let g = given.unwrap();
    (rows, (g.captured_psnr, g.quad_centres_psnr))
}

#[test]
fn every_component_is_scored_and_all_of_them_true_is_the_oracle_field() {
    let dir = tempfile::tempdir().unwrap();
    let (cap, fields_dir) = (dir.path().join("cap"), dir.path().join("fields"));
    let mut config = StageConfig::preset(StagePreset::Tiny);
    config.poses = vec![0];
    config.perturbation = 0.0;
    config.set_flow_truth = SetFlowTruth::None;
    let stage = Stage::new(config).unwrap();
    write_capture(&stage, &cap, &|_, _| {}).unwrap();

    let fields = write_fields(&stage, &cap, 0, &options(), &fields_dir, &Silent).unwrap();
    assert_eq!(
        fields.iter().map(|f| f.0).collect::<Vec<_>>(),
        Component::ALL.to_vec()
    );
    // The oracle field as `frf stage field` writes it, and the field as `frf ingest`
    // writes it, scored beside the budget's own.
    let oracle = dir.path().join("oracle.frf");
    let oracle_options = OracleOptions {
        poses: vec![0],
        jpeg_quality: 95,
        predict_flow: true,
        shadows: Some(ShadowOptions::default()),
        pose_flows: false,
    };
    write_oracle_field(&stage, &oracle, &oracle_options, &|_, _| {}).unwrap();
    let ingested = dir.path().join("ingested.frf");
    ingest(
        &cap,
        &ingested,
        &options(),
        None,
        &frf_ingest::pipeline::Silent,
    )
    .unwrap();

    let (rows, oracle_psnr) = scored(&stage, &fields, &oracle);
    let (_, ingested_psnr) = scored(&stage, &fields, &ingested);
    for r in &rows {
        eprintln!(
            "{:<18} captured {:6.2} dB ({:+.2}, {:5.1} %), quad centres {:6.2} dB ({:+.2}, {:5.1} %)",
            r.component.name(),
            r.captured.psnr_subject,
            r.captured.gain_db,
            100.0 * r.captured.share_of_squared_error,
            r.quad_centres.psnr_subject,
            r.quad_centres.gain_db,
            100.0 * r.quad_centres.share_of_squared_error,
        );
        for p in [&r.captured, &r.quad_centres] {
            assert!(
                p.psnr_subject.is_finite() && p.frames_psnr.len() == 2,
                "{r:?}"
            );
        }
    }
    eprintln!("oracle field {oracle_psnr:?}, ingested field {ingested_psnr:?}");
    let row = |c: Component| rows.iter().find(|r| r.component == c).unwrap();
    let close = |a: f64, b: f64| (a - b).abs() < 0.1;
    // Every component true is the oracle field; none is `frf ingest`'s field.
    let (o, i) = (row(Component::Oracle), row(Component::Ingested));
    assert!(
        close(o.captured.psnr_subject, oracle_psnr.0)
            && close(o.quad_centres.psnr_subject, oracle_psnr.1),
        "{o:?} vs {oracle_psnr:?}"
    );
    assert!(
        close(i.captured.psnr_subject, ingested_psnr.0)
            && close(i.quad_centres.psnr_subject, ingested_psnr.1),
        "{i:?} vs {ingested_psnr:?}"
    );
    // Each row's gain is its mean PSNR's difference from the ingested field's, and its
    // share (worked by hand in the unit test of `share_removed`) has the gain's sign
    // when every frame moves one way.
    for r in &rows {
        for (p, base) in [
            (&r.captured, &i.captured),
            (&r.quad_centres, &i.quad_centres),
        ] {
            let gain = p.psnr_subject - base.psnr_subject;
            assert!((p.gain_db - gain).abs() < 1e-9, "{r:?}");
            assert!(p.share_of_squared_error <= 1.0, "{r:?}");
            let frames = p.frames_psnr.iter().zip(&base.frames_psnr);
            if frames.clone().all(|(a, b)| a >= b) {
                assert!(p.share_of_squared_error >= 0.0, "{r:?}");
            }
            if frames.clone().all(|(a, b)| a <= b) {
                assert!(p.share_of_squared_error <= 0.0, "{r:?}");
            }
        }
    }
    // Ingest costs something at both places, and the oracle field removes a good part of
    // it (on this tiny capture, when written: 55 % at the captured views, 16 % at quad
    // centres, where the renderer's own error at 32x45 pixels dominates).
    assert!(o.quad_centres.gain_db > 0.0, "{o:?}");
    assert!(o.captured.share_of_squared_error > 0.3, "{o:?}");
    assert!(o.quad_centres.share_of_squared_error > 0.05, "{o:?}");
    // The flows cost nothing at the captured views: no interpolation happens there.
    for c in [Component::HorizontalFlows, Component::VerticalFlows] {
        assert!(row(c).captured.gain_db.abs() < 0.02, "{:?}", row(c));
    }

    // Asked again with the same settings, the fields are reused (not rewritten); with
    // other settings they are made anew.
    let stamp = |p: &Path| std::fs::metadata(p).unwrap().modified().unwrap();
    let before = stamp(&fields_dir.join(MADE_FILE));
    let again = write_fields(&stage, &cap, 0, &options(), &fields_dir, &Silent).unwrap();
    assert_eq!(again, fields);
    assert_eq!(stamp(&fields_dir.join(MADE_FILE)), before);
    let other = IngestOptions {
        jpeg_quality: 90,
        ..options()
    };
    write_fields(&stage, &cap, 0, &other, &fields_dir, &Silent).unwrap();
    assert_ne!(stamp(&fields_dir.join(MADE_FILE)), before);
}

#[test]
fn the_budget_refuses_what_it_cannot_build() {
    let dir = tempfile::tempdir().unwrap();
    let cap = dir.path().join("cap");
    let mut config = StageConfig::preset(StagePreset::Tiny);
    config.poses = vec![0];
    config.cycles = 4;
    config.perturbation = 0.0;
    config.set_flow_truth = SetFlowTruth::None;
    let stage = Stage::new(config).unwrap();
    write_capture(&stage, &cap, &|_, _| {}).unwrap();
    let e = write_fields(&stage, &cap, 3, &options(), &dir.path().join("f"), &Silent)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("pose 3 is not in the capture (it holds 0)"),
        "{e}"
    );
    let e = write_fields(
        &stage,
        &dir.path().join("nowhere"),
        0,
        &options(),
        &dir.path().join("g"),
        &Silent,
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("nowhere"), "{e}");
    let bad = IngestOptions {
        flow_settings: vec![("lambda".into(), "-1".into())],
        ..options()
    };
    let e = write_fields(&stage, &cap, 0, &bad, &dir.path().join("h"), &Silent)
        .unwrap_err()
        .to_string();
    assert!(e.contains("lambda"), "{e}");
    // Nothing was made for a refused request.
    assert!(!dir.path().join("h").join(MADE_FILE).exists());
}
