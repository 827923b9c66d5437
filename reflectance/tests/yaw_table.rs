//! The yaw table against the projection it replaces: at its samples it is the direct
//! projection of the map turned there, for maps with and without suns, the whole map and
//! the map less its suns; between samples it stays between its neighbours' values; its
//! suns are the suns found in the turned map; a light of several maps is the sum of
//! theirs.

#![allow(clippy::unwrap_used)] // tests: a failed unwrap is a failed test

mod common;

use std::f32::consts::TAU;
use std::sync::Arc;

use frf_core::env::EnvMap;
use frf_core::image::{Image, Rgb};
use frf_core::sun::Sun;
use frf_reflectance::FieldHeader;
use frf_reflectance::field::ConditionRecord;
use frf_reflectance::flowcodec::quant::LogQuantizer;
use frf_reflectance::project::{FloorModel, Projector};
use frf_reflectance::sun_light::MAX_SUNS;
use frf_reflectance::yaw_light::{YawLight, YawTerm};
use frf_reflectance::yaw_table::{Part, SAMPLES_PER_TURN, YawTable};
use glam::Vec3;

fn conditions() -> Vec<ConditionRecord> {
    let capture = common::tiny_capture(36, 64, 90);
    FieldHeader::from_capture(&capture, &[0], LogQuantizer::new(0.2, 4.0).unwrap(), 90)
        .unwrap()
        .conditions
}

/// A soft sky (no sun: its brightest texel is far under 100 times its mean).
fn soft_sky() -> EnvMap {
    let probe = EnvMap::uniform([0.0; 3], 64);
    EnvMap::from_image(Image::from_fn(128, 64, |x, y| {
        let d = probe.direction_of(x as f32, y as f32);
        if d.y >= 0.0 {
            [0.5 + 0.3 * d.x, 0.6 + 0.1 * d.z, 0.9 + 0.2 * d.y]
        } else {
            [0.2 + 0.02 * (x % 7) as f32, 0.15, 0.1]
        }
    }))
    .unwrap()
}

/// The soft sky with two suns painted in.
fn two_suns() -> EnvMap {
    let a = Sun::new(Vec3::new(0.4, 0.7, -0.5), 1.0, [900.0, 800.0, 700.0]).unwrap();
    let b = Sun::new(Vec3::new(-0.6, 0.3, 0.5), 2.0, [300.0, 300.0, 350.0]).unwrap();
    b.lit(&a.lit(&soft_sky()).unwrap()).unwrap()
}

/// The largest difference between `a` and `b` relative to the largest value of `b`.
fn relative(a: &[Rgb], b: &[Rgb]) -> f32 {
    let scale = b
        .iter()
        .flatten()
        .fold(0.0f32, |m, v| m.max(v.abs()))
        .max(1e-12);
    a.iter()
        .zip(b)
        .flat_map(|(x, y)| (0..3).map(move |c| (x[c] - y[c]).abs()))
        .fold(0.0, f32::max)
        / scale
}

/// What relighting computed before the table, for the map turned by `yaw`: the direct
/// projection at each turntable angle; with `suns`, the upper conditions' of the map less
/// its suns (found one after the other, as many as [`MAX_SUNS`]).
fn direct(
    projector: &Projector,
    env: &EnvMap,
    yaw: f32,
    angles: &[f32],
    suns: bool,
) -> Vec<Vec<Rgb>> {
    let turned = env.rotated(yaw);
    let mut all = projector.project_many(&turned, angles, FloorModel::Environment);
    if suns {
        let mut rest: Option<EnvMap> = None;
        for _ in 0..MAX_SUNS {
            match Sun::extract(rest.as_ref().unwrap_or(&turned)).unwrap() {
                Some((_, less)) => rest = Some(less),
                None => break,
            }
        }
        if let Some(rest) = rest {
            let less = projector.project_many(&rest, angles, FloorModel::Environment);
            for (c, l) in all.iter_mut().zip(less) {
                for k in 0..c.len() {
                    if !projector.is_floor(k) {
                        c[k] = l[k];
                    }
                }
            }
        }
    }
    all
}

#[test]
fn the_yaw_table_at_its_samples_is_the_projection_of_the_turned_map() {
    let projector = Arc::new(Projector::new(&conditions()).unwrap());
    let step = TAU / SAMPLES_PER_TURN as f32;
    // The stage's turntable angles, and others on the table's samples.
    let angles: Vec<f32> = (0..36)
        .map(|u| (u as f32 * 10.0).to_radians())
        .chain([7.0 * step, 1201.0 * step])
        .collect();
    for (name, env) in [
        ("sky", EnvMap::sky()),
        ("soft", soft_sky()),
        ("two suns", two_suns()),
    ] {
        let table = YawTable::new(projector.clone(), &env, FloorModel::Environment);
        for yaw in [0.0, 90.0 * step, -333.0 * step] {
            for (part, suns) in [(Part::Whole, false), (Part::LessSuns, true)] {
                let got = table.coefficients(part, yaw, &angles).unwrap();
                let want = direct(&projector, &env, yaw, &angles, suns);
                for (k, (g, w)) in got.iter().zip(&want).enumerate() {
                    // Float rounding: a texel whose centre lies on a cell's edge may fall
                    // on its other side (a texel of the sky carries 5e-5 of the largest
                    // coefficient, the sun's).
                    let e = relative(g, w);
                    assert!(
                        e < 1e-4,
                        "{name}, yaw {yaw}, {part:?}, angle {}: {e:.2e} of the largest",
                        angles[k]
                    );
                }
            }
        }
        // Samples are made as needed, never the whole table for a few views.
        assert!(table.samples_made() < SAMPLES_PER_TURN / 4, "{name}");
    }
}

/// Off its samples (turns a fraction of a sample on, and angles no sample lies on), the
/// table against the projection it replaced, for the whole map (it was compared with the
/// projection only at its samples; the GPU-vs-CPU tests both read the table). The
/// projection takes each texel into the condition cell its centre falls in, so off a sample
/// it jumps as texels cross cells (up to 3.7 % of the largest coefficient within a quarter
/// of a degree on a smooth sky), where the table moves linearly between its samples:
/// within 4 % of the largest coefficient (measured: sky 2.5e-4, smooth sky 3.0e-2, two
/// suns 1e-5).
#[test]
fn off_its_samples_the_table_is_near_the_projection() {
    let projector = Arc::new(Projector::new(&conditions()).unwrap());
    let step = TAU / SAMPLES_PER_TURN as f32;
    let angles: Vec<f32> = [0.37f32, 0.5, 0.91]
        .iter()
        .map(|f| (40.0 + f) * step)
        .chain([0.123, 2.5, -1.0])
        .collect();
    for (name, env, bound) in [
        ("sky", EnvMap::sky(), 1e-3),
        ("soft", soft_sky(), 4e-2),
        ("two suns", two_suns(), 1e-3),
    ] {
        let table = YawTable::new(projector.clone(), &env, FloorModel::Environment);
        let got = table.coefficients(Part::Whole, 0.0, &angles).unwrap();
        let want = direct(&projector, &env, 0.0, &angles, false);
        let mut most = 0.0f32;
        for (k, &angle) in angles.iter().enumerate() {
            let e = relative(&got[k], &want[k]);
            most = most.max(e);
            assert!(e < bound, "{name}, angle {angle}: {e:.2e} of the largest");
        }
        eprintln!("{name}: the table off its samples within {most:.1e} of the largest");
    }
}

#[test]
fn between_samples_the_table_stays_between_its_neighbours() {
    let projector = Arc::new(Projector::new(&conditions()).unwrap());
    let env = two_suns();
    let table = YawTable::new(projector, &env, FloorModel::Environment);
    let step = TAU / SAMPLES_PER_TURN as f32;
    for i in [3usize, 400, 1439] {
        let at = |f: f32| {
            table
                .coefficients(Part::Whole, 0.0, &[(i as f32 + f) * step])
                .unwrap()
                .remove(0)
        };
        let (a, b, mid) = (at(0.0), at(1.0), at(0.37));
        for k in 0..a.len() {
            for c in 0..3 {
                let (lo, hi) = (a[k][c].min(b[k][c]), a[k][c].max(b[k][c]));
                let tol = 1e-6 * hi.abs().max(1.0);
                assert!(
                    mid[k][c] >= lo - tol && mid[k][c] <= hi + tol,
                    "sample {i}, condition {k}: {} outside [{lo}, {hi}]",
                    mid[k][c]
                );
                let want = a[k][c] + 0.37 * (b[k][c] - a[k][c]);
                assert!((mid[k][c] - want).abs() <= 1e-3 * hi.abs().max(1e-6));
            }
        }
    }
}

#[test]
fn a_turned_light_turns_its_suns_and_finds_them_once() {
    let projector = Arc::new(Projector::new(&conditions()).unwrap());
    let env = two_suns();
    let light = YawLight::of_env(projector, &env, FloorModel::Environment);
    for yaw in [0.0f32, 0.7, -2.9] {
        let turned = light.turned(yaw);
        let lit = turned.lighting(&[0.0], true).unwrap();
        // The suns found in the map turned there, one after the other.
        let mut found = Vec::new();
        let mut rest = env.rotated(yaw);
        while let Some((sun, less)) = Sun::extract(&rest).unwrap() {
            found.push(sun);
            rest = less;
        }
        assert_eq!(lit.suns.len(), found.len().min(MAX_SUNS), "yaw {yaw}");
        for (a, b) in lit.suns.iter().zip(&found) {
            assert!(
                a.direction().angle_between(b.direction()) < 1e-4,
                "yaw {yaw}"
            );
            for c in 0..3 {
                let (x, y) = (a.illuminance()[c], b.illuminance()[c]);
                assert!((x - y).abs() <= 1e-5 * y, "yaw {yaw}: {x} vs {y}");
            }
        }
    }
    // Without suns asked for, none, and the whole map's coefficients.
    let whole = light.lighting(&[0.0], false).unwrap();
    assert!(whole.suns.is_empty());
    assert_eq!(whole.coefficients[0], whole.ground);
}

#[test]
fn a_light_of_several_maps_is_the_weighted_sum_of_theirs() {
    let projector = Arc::new(Projector::new(&conditions()).unwrap());
    let table = |env: &EnvMap| {
        Arc::new(YawTable::new(
            projector.clone(),
            env,
            FloorModel::Environment,
        ))
    };
    let (a, b) = (table(&soft_sky()), table(&EnvMap::sky()));
    let light = YawLight::new(vec![
        YawTerm {
            table: a.clone(),
            weight: 0.25,
            yaw: 0.4,
        },
        YawTerm {
            table: b.clone(),
            weight: 2.0,
            yaw: -1.1,
        },
    ]);
    let angles = [0.0, 0.5, 2.0];
    let sum = light.lighting(&angles, false).unwrap();
    let ca = a.coefficients(Part::Whole, 0.4, &angles).unwrap();
    let cb = b.coefficients(Part::Whole, -1.1, &angles).unwrap();
    for v in 0..angles.len() {
        let want: Vec<Rgb> = ca[v]
            .iter()
            .zip(&cb[v])
            .map(|(x, y)| [0, 1, 2].map(|c| 0.25 * x[c] + 2.0 * y[c]))
            .collect();
        assert!(relative(&sum.coefficients[v], &want) < 1e-6);
    }
    // With suns: the sky's is taken out of its map and weighted by it.
    let lit = light.lighting(&angles, true).unwrap();
    assert_eq!(lit.suns.len(), 1);
    let sky_sun = b.suns().unwrap()[0];
    let e = lit.suns[0].illuminance()[0];
    assert!((e - 2.0 * sky_sun.illuminance()[0]).abs() <= 1e-5 * e);
}
