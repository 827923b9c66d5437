//! Storage and relighting of stage data against its ground truth: the oracle field meets
//! the compression targets (flow at most 34 % of its 8-bit size, basis images at least
//! 16:1 against 16-bit linear with relit PSNR of at least 40 dB), decodes to what was
//! stored, and the basis-projection error of every environment is measured.

#![allow(clippy::unwrap_used)] // tests: a failed unwrap is a failed test

use frf_core::env::EnvMap;
use frf_core::flo::is_known;
use frf_core::grid::Neighbour;
use frf_eval::oracle::{oracle_view, true_flows};
use frf_eval::storage::{codec_curve, projection_error, stage_projector};
use frf_reflectance::FieldFile;
use frf_reflectance::project::FloorModel;
use frf_stage::{Preset, Stage, StageConfig};

fn stage(cycles: u32, lights_per_axis: u32) -> Stage {
    let mut c = StageConfig::preset(Preset::Tiny);
    c.cycles = cycles;
    c.poses = vec![1];
    c.lights_per_axis = lights_per_axis;
    Stage::new(c).unwrap()
}

#[test]
fn the_oracle_field_meets_the_storage_targets_and_decodes_faithfully() {
    let tiny = frf_testkit::tiny_field();
    let (stage, path) = (&tiny.stage, &tiny.field);
    let field = FieldFile::open(path).unwrap();
    let stats = field.stats();
    eprintln!(
        "flow {:.3} of 8-bit, images {:.1}:1",
        stats.flow_ratio_vs_8bit, stats.image_ratio_vs_16bit
    );
    // Measured on this field: 12.0 % and 25.5:1 (the original: 34 % and 16:1).
    assert!(
        stats.flow_ratio_vs_8bit <= 0.34,
        "flow at {}",
        stats.flow_ratio_vs_8bit
    );
    assert!(
        stats.image_ratio_vs_16bit >= 16.0,
        "images at {}:1",
        stats.image_ratio_vs_16bit
    );
    assert_eq!(stats.flow_maps, 36 * 10);

    let q = field.header().pose(0).unwrap().flow_quantizer;
    let (u, v) = (17, 1);
    let truth = true_flows(stage, 0, u, v).unwrap();
    for n in Neighbour::ALL {
        let stored = field.flow(0, u, v, n).unwrap().unwrap();
        let true_flow = truth[n.index()].as_ref().unwrap();
        for (s, t) in stored.pixels().iter().zip(true_flow.pixels()) {
            assert_eq!(is_known(*s), is_known(*t));
            if is_known(*t) {
                for c in 0..2 {
                    // Within the quantizer's stated bound (saturation cannot occur: M
                    // is the field's largest flow).
                    assert!((s[c] - t[c]).abs() <= q.error_bound(t[c]) * 1.001 + 1e-6);
                }
            }
        }
    }
    let view = oracle_view(stage, 0, u, v).unwrap();
    let alpha = field.alpha(0, u, v).unwrap();
    for (a, b) in view.alpha.pixels().iter().zip(alpha.pixels()) {
        assert!((a - b).abs() <= 0.5 / 65535.0 + 1e-7);
    }
}

#[test]
fn jpeg_quality_95_keeps_relit_psnr_near_40_db_at_16_to_1() {
    // At the small preset's size (160x224), under the built-in sky with its sun.
    let mut c = StageConfig::preset(Preset::Small);
    c.poses = vec![1];
    let stage = Stage::new(c).unwrap();
    let env = EnvMap::sky();
    let views = [(0, 0), (18, 2), (27, 1)];
    let curve = codec_curve(&stage, &env, 1, &views, &[70, 95]).unwrap();
    let (low, high) = (&curve[0], &curve[1]);
    eprintln!("{low:?}\n{high:?}");
    // Measured: quality 95 gives 45.7:1 with the worst view at 40.4 dB (the sky's sun
    // makes bright glints, the hardest case); 70 gives 87:1 at 31.9 dB. The bound keeps
    // 0.9 dB of headroom below the measured worst view (a JPEG encoder's rounding moves
    // it by tenths of a dB), and the ratio bound is the design's target (16:1).
    assert!(
        high.ratio_vs_16bit >= 16.0 && high.min_relit_psnr_db >= 39.5,
        "{high:?}"
    );
    assert!(
        low.ratio_vs_16bit > high.ratio_vs_16bit && low.min_relit_psnr_db < high.min_relit_psnr_db
    );
}

#[test]
fn basis_projection_error_per_environment() {
    let views = [(0, 1), (12, 0), (24, 2)];
    let coarse = stage(36, 1);
    let fine = stage(36, 3);
    let mut envs = vec![
        ("sky".to_string(), EnvMap::sky()),
        ("uniform".to_string(), EnvMap::uniform([1.0; 3], 64)),
    ];
    if let Some(dir) = frf_core::shared_data::shared_data("envmaps") {
        for name in ["grace", "pisa", "uffizi", "ennis", "wells"] {
            envs.push((
                name.to_string(),
                EnvMap::load(&dir.join(format!("{name}.hdr"))).unwrap(),
            ));
        }
    }
    let psnr = |stage: &Stage, env: &EnvMap| {
        let projector = stage_projector(stage).unwrap();
        let errors = projection_error(
            stage,
            &projector,
            env,
            256,
            FloorModel::Environment,
            1,
            &views,
        )
        .unwrap();
        errors.iter().map(|e| e.psnr_subject_db).sum::<f64>() / errors.len() as f64
    };
    for (name, env) in &envs {
        let (c, f) = (psnr(&coarse, env), psnr(&fine, env));
        eprintln!(
            "{name:<8} basis-projection PSNR: 1 light per condition {c:.1} dB, 9 lights {f:.1} dB"
        );
        // Neither is better everywhere: spreading a condition's light over its cell
        // softens shadows, which suits broad light and not a small sun (measured on the
        // built-in sky: 30.4 dB with 1 light, 28.5 dB with 9).
        assert!(c.is_finite() && f.is_finite());
        assert!(f > 20.0 && c > 20.0, "{name}: {c} dB / {f} dB");
        // Broad light is what many lights per condition reproduce better. Measured on
        // the uniform sphere: 35.2 dB with 9 lights, 24.3 dB with 1 (what remains is the
        // lights' discreteness: separate glints on shiny hair and shoes).
        if name == "uniform" {
            assert!(
                f > 33.0 && f > c + 5.0,
                "uniform: {f} dB with 9 lights, {c} dB with 1"
            );
        }
    }
}

#[test]
fn the_fitted_flow_quantizer_beats_scales_too_fine_or_too_coarse() {
    // A smooth true flow with unknown pixels, as a field stores it.
    let flow = frf_core::image::Image::from_fn(40, 30, |x, y| {
        if x < 3 {
            [frf_core::flo::UNKNOWN; 2]
        } else {
            [
                0.2 * x as f32 - 3.0,
                0.05 * y as f32 * (x as f32 * 0.3).sin(),
            ]
        }
    });
    let flows = [flow];
    // Codes are 8 bits whatever the scale: a tiny scale spends them near zero and leaves
    // wide steps at the range; a large one is nearly linear, wide steps everywhere.
    let fine = frf_eval::storage::flow_quantization(&flows, Some(0.0005)).unwrap();
    let coarse = frf_eval::storage::flow_quantization(&flows, Some(50.0)).unwrap();
    let fitted = frf_eval::storage::flow_quantization(&flows, None).unwrap();
    // The bound of the log quantizer (half a code step, relative) holds on average.
    for s in [fine, coarse, fitted] {
        assert!(s.epe.is_finite() && s.epe < 0.2, "{s:?}");
    }
    eprintln!("{fine:?}\n{coarse:?}\n{fitted:?}");
    assert!(
        fitted.epe < fine.epe && fitted.epe < coarse.epe,
        "{fitted:?}"
    );
    assert_eq!(fitted.range, fine.range);
    assert!(frf_eval::storage::flow_quantization(&[], None).is_err());
}
