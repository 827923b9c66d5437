//! The SH transfer against the basis relighting it stands for: for a light that is
//! exactly L2 (as frf makes a map of it), relighting by the transfer and by the
//! projection of the map agree to float rounding, at any turntable angle, texel by texel.

#![allow(clippy::unwrap_used)] // tests: a failed unwrap is a failed test

mod common;

use frf_core::env::SH_MAP_HEIGHT;
use frf_core::sh::{SH_COUNT, ShLight};
use frf_reflectance::FieldHeader;
use frf_reflectance::flowcodec::quant::LogQuantizer;
use frf_reflectance::project::{FloorModel, Projector};
use frf_reflectance::sh_transfer::{coefficients_of, sh_weights, texel_transfer};

/// A positive L2 light with every coefficient in play.
fn light() -> ShLight {
    let mut c = [[0.0f32; 3]; SH_COUNT];
    for (i, ci) in c.iter_mut().enumerate() {
        let i = i as f32;
        *ci = [
            0.25 * (i * 1.3).cos(),
            0.2 - 0.04 * i,
            0.3 * (i * 0.7).sin(),
        ];
    }
    c[0] = [6.0, 5.0, 4.0];
    ShLight::from_coefficients(c)
}

#[test]
fn the_transfer_relights_an_l2_light_as_the_basis_does() {
    let capture = common::tiny_capture(36, 64, 90);
    let conditions =
        FieldHeader::from_capture(&capture, &[0], LogQuantizer::new(0.2, 4.0).unwrap(), 90)
            .unwrap()
            .conditions;
    let projector = Projector::new(&conditions).unwrap();
    let light = light();
    let env = frf_core::env::EnvMap::from_sh_clamped(&light, SH_MAP_HEIGHT).unwrap();
    assert_eq!(env.clamped_texels(), 0);
    let turntables = [0.0f32, 1.3, 4.0];
    let weights = sh_weights(&projector, &turntables).unwrap();
    let mut checked = 0;
    for (&t, w) in turntables.iter().zip(&weights) {
        let by_map = projector.project(&env, t, FloorModel::Environment);
        let by_sh = coefficients_of(w, &light);
        let scale = by_map.iter().flatten().fold(0.0f32, |m, v| m.max(v.abs()));
        assert!(scale > 0.0);
        for (a, b) in by_map.iter().zip(&by_sh) {
            for c in 0..3 {
                assert!(
                    (a[c] - b[c]).abs() <= 1e-5 * scale,
                    "turntable {t}: {a:?} {b:?}"
                );
                checked += 1;
            }
        }
        // A texel: Σ_k B_k a_k = Σ_i c_i T_i.
        let basis: Vec<[f32; 3]> = (0..conditions.len())
            .map(|k| {
                [
                    0.1 + 0.03 * k as f32,
                    0.5 / (1.0 + k as f32),
                    (k % 5) as f32 * 0.2,
                ]
            })
            .collect();
        let transfer = texel_transfer(w, basis.iter().copied());
        for c in 0..3 {
            let relit: f32 = basis.iter().zip(&by_map).map(|(b, a)| b[c] * a[c]).sum();
            let sh: f32 = transfer
                .iter()
                .zip(&light.coefficients)
                .map(|(t, l)| t[c] * l[c])
                .sum();
            assert!(
                (relit - sh).abs() <= 1e-5 * relit.abs().max(1.0),
                "{relit} {sh}"
            );
        }
    }
    assert_eq!(checked, 3 * 3 * conditions.len());
}
