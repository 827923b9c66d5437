//! The light fit's glossy lobe on the stage's synthetic glossy sphere
//! (`frf_stage::olat_sphere`): half of 24 lights kept, each other light's image predicted
//! and compared with the exact one. The lobe places held-out highlights the diffuse fit
//! and the interpolation of photographs cannot; the set written to disk reads back as a
//! set and scores as in memory.

#![allow(clippy::unwrap_used)] // tests: a failed unwrap is a failed test

use frf_core::image::RgbImage;
use frf_eval::olat::evaluate_olat;
use frf_ingest::olat::OlatSet;
use frf_reflectance::light_fit::{LightFit, blend, farthest_lights, nearest_weights};
use frf_stage::material::Surface;
use frf_stage::olat_sphere::{sphere_images, sphere_lights, write_sphere_set};
use glam::Vec3;

const SIDE: usize = 96;

fn surface() -> Surface {
    Surface {
        albedo: [0.45, 0.35, 0.3],
        f0: 0.05,
        roughness: 0.2,
    }
}

/// PSNR over `texels` (peak: the truth's brightest there).
fn psnr(a: &RgbImage, truth: &RgbImage, texels: &[usize]) -> f64 {
    let peak = texels
        .iter()
        .flat_map(|&i| truth.pixels()[i])
        .fold(0.0f32, f32::max) as f64;
    let mse = texels
        .iter()
        .flat_map(|&i| (0..3).map(move |c| (a.pixels()[i][c] - truth.pixels()[i][c]) as f64))
        .map(|d| d * d)
        .sum::<f64>()
        / (3 * texels.len()) as f64;
    10.0 * (peak * peak / mse).log10()
}

#[test]
fn held_out_highlights_land_where_the_sphere_puts_them() {
    let lights = sphere_lights(24);
    let (images, mask) = sphere_images(SIDE, &lights, &surface());
    let kept = farthest_lights(&lights, 12, Vec3::Z);
    let dirs: Vec<Vec3> = kept.iter().map(|&k| lights[k]).collect();
    let refs: Vec<&RgbImage> = kept.iter().map(|&k| &images[k]).collect();
    let diffuse = LightFit::fit(&refs, &dirs, &mask);
    let glossy = LightFit::fit_glossy(&refs, &dirs, &mask, Vec3::Z);
    let gloss = glossy.gloss().expect("the sphere is glossy");
    // The roughness chosen is the sphere's, among the candidates.
    assert!((gloss.roughness - 0.2).abs() <= 0.05, "{}", gloss.roughness);
    let inside: Vec<usize> = (0..SIDE * SIDE).filter(|&i| mask[i]).collect();
    let (mut ours, mut plain, mut interpolated, mut highlights) = (0.0, 0.0, 0.0, 0.0);
    let (mut spot_plain, mut spot_interpolated) = (0.0, 0.0);
    let held: Vec<usize> = (0..lights.len()).filter(|k| !kept.contains(k)).collect();
    for &k in &held {
        let l = lights[k];
        let truth = &images[k];
        let g = glossy.relight(&refs, &dirs, l, 3);
        ours += psnr(&g, truth, &inside);
        plain += psnr(&diffuse.relight(&refs, &dirs, l, 3), truth, &inside);
        interpolated += psnr(&blend(&refs, &nearest_weights(&dirs, l, 3)), truth, &inside);
        // The held-out light's highlight: texels within 0.15 of its mirror normal.
        let h = (l + Vec3::Z).normalize();
        let spot: Vec<usize> = inside
            .iter()
            .copied()
            .filter(|&i| {
                let c = SIDE as f32 / 2.0;
                let u = ((i % SIDE) as f32 + 0.5 - c) / (0.45 * SIDE as f32);
                let v = (c - (i / SIDE) as f32 - 0.5) / (0.45 * SIDE as f32);
                (u - h.x).hypot(v - h.y) < 0.15
            })
            .collect();
        highlights += psnr(&g, truth, &spot);
        spot_plain += psnr(&diffuse.relight(&refs, &dirs, l, 3), truth, &spot);
        spot_interpolated += psnr(&blend(&refs, &nearest_weights(&dirs, l, 3)), truth, &spot);
    }
    let m = held.len() as f64;
    let (ours, plain, interpolated) = (ours / m, plain / m, interpolated / m);
    let (highlights, spot_plain, spot_interpolated) =
        (highlights / m, spot_plain / m, spot_interpolated / m);
    eprintln!(
        "glossy {ours:.2} dB, diffuse fit {plain:.2}, interpolation {interpolated:.2}; \
         highlights {highlights:.2} dB ({spot_plain:.2}, {spot_interpolated:.2}); roughness {}",
        gloss.roughness
    );
    assert!(ours >= interpolated + 3.0, "{ours} vs {interpolated}");
    assert!(ours >= plain + 2.0, "{ours} vs {plain}");
    // Inside the held-out highlights, the RMS error is at most 16 % of their peak
    // (measured 18.4 dB; the diffuse fit 13.8, the interpolation 11.6).
    assert!(highlights >= 16.0, "{highlights}");
    assert!(
        highlights >= spot_plain + 3.0,
        "{highlights} vs {spot_plain}"
    );
}

#[test]
fn the_sphere_written_as_a_set_reads_back_and_scores_as_in_memory() {
    let dir = tempfile::tempdir().unwrap();
    let lights = sphere_lights(12);
    write_sphere_set(dir.path(), (48, &lights), &surface(), 0.9).unwrap();
    let set = OlatSet::read(dir.path()).unwrap();
    assert_eq!(set.directions.len(), 12);
    assert!(
        set.directions
            .iter()
            .zip(&lights)
            .all(|(a, b)| a.distance(*b) < 1e-5)
    );
    let report = evaluate_olat(&set, 6, None, true).unwrap();
    assert!(report.gloss_roughness.is_some());
    assert!(
        report.mean_psnr >= report.baselines.interpolated.mean_psnr + 1.5,
        "{} vs {}",
        report.mean_psnr,
        report.baselines.interpolated.mean_psnr
    );
    // The same set kept in memory (the test's name promised this comparison and made
    // none): the images read back within 16-bit quantisation, and the scores agree.
    let (images, mask) = sphere_images(48, &lights, &surface());
    let scale = set.images[0]
        .pixels()
        .iter()
        .flatten()
        .fold(0.0f32, |m, &c| m.max(c))
        / images[0]
            .pixels()
            .iter()
            .flatten()
            .fold(0.0f32, |m, &c| m.max(c));
    let in_memory = OlatSet {
        dir: dir.path().to_path_buf(),
        images: images
            .iter()
            .map(|img| img.map(|p| p.map(|c| c * scale)))
            .collect(),
        directions: lights.clone(),
        mask,
    };
    assert_eq!(in_memory.mask, set.mask);
    for (a, b) in in_memory.images.iter().zip(&set.images) {
        for (p, q) in a.pixels().iter().zip(b.pixels()) {
            for c in 0..3 {
                assert!((p[c] - q[c]).abs() <= 1.0 / 65535.0 * scale.max(1.0) + 1e-6);
            }
        }
    }
    let memory = evaluate_olat(&in_memory, 6, None, true).unwrap();
    assert!(
        (memory.mean_psnr - report.mean_psnr).abs() < 0.05,
        "in memory {} dB, read back {} dB",
        memory.mean_psnr,
        report.mean_psnr
    );
}

/// A sphere of a reflectance the lobe does not model: GGX (Trowbridge-Reitz) microfacets
/// with Smith's masking, α = `alpha` (its tails far longer than Beckmann's), Schlick's
/// Fresnel, a Lambert base.
fn ggx(n: Vec3, l: Vec3, v: Vec3, alpha: f32) -> [f32; 3] {
    let (nl, nv) = (n.dot(l), n.dot(v));
    if nl <= 0.0 || nv <= 0.0 {
        return [0.0; 3];
    }
    let h = (l + v).normalize();
    let (nh, vh) = (n.dot(h).max(0.0), v.dot(h).max(1e-4));
    let a2 = alpha * alpha;
    let d = a2 / (std::f32::consts::PI * (nh * nh * (a2 - 1.0) + 1.0).powi(2));
    let g1 = |c: f32| 2.0 * c / (c + (a2 + (1.0 - a2) * c * c).sqrt());
    let f = 0.05 + 0.95 * (1.0 - vh).powi(5);
    let specular = f * d * g1(nl) * g1(nv) / (4.0 * nv);
    [0.45, 0.35, 0.3].map(|a| a * nl * std::f32::consts::FRAC_1_PI + specular)
}

/// The lobe (Beckmann, roughness chosen among [`frf_reflectance::gloss::ROUGHNESS`]) on
/// spheres it did not make: GGX at α 0.1 and 0.3 (neither on the grid). Held-out lights
/// gain over the diffuse fit and over the interpolation of the three nearest (measured:
/// α 0.1 31.86 dB against 26.68 and 26.02, roughness 0.12 chosen; α 0.3 36.07 against
/// 33.38 and 23.67, roughness 0.18).
#[test]
fn the_lobe_on_a_reflectance_it_does_not_model() {
    for alpha in [0.1f32, 0.3] {
        let lights = sphere_lights(24);
        let (images, mask) =
            frf_stage::olat_sphere::sphere_images_by(SIDE, &lights, |n, l, v| ggx(n, l, v, alpha));
        let kept = farthest_lights(&lights, 12, Vec3::Z);
        let dirs: Vec<Vec3> = kept.iter().map(|&k| lights[k]).collect();
        let refs: Vec<&RgbImage> = kept.iter().map(|&k| &images[k]).collect();
        let diffuse = LightFit::fit(&refs, &dirs, &mask);
        let glossy = LightFit::fit_glossy(&refs, &dirs, &mask, Vec3::Z);
        let inside: Vec<usize> = (0..SIDE * SIDE).filter(|&i| mask[i]).collect();
        let held: Vec<usize> = (0..lights.len()).filter(|k| !kept.contains(k)).collect();
        let (mut ours, mut plain, mut interpolated) = (0.0, 0.0, 0.0);
        for &k in &held {
            let (l, truth) = (lights[k], &images[k]);
            ours += psnr(&glossy.relight(&refs, &dirs, l, 3), truth, &inside);
            plain += psnr(&diffuse.relight(&refs, &dirs, l, 3), truth, &inside);
            interpolated += psnr(&blend(&refs, &nearest_weights(&dirs, l, 3)), truth, &inside);
        }
        let m = held.len() as f64;
        let (ours, plain, interpolated) = (ours / m, plain / m, interpolated / m);
        eprintln!(
            "GGX α {alpha}: glossy {ours:.2} dB (roughness {:?}), diffuse fit {plain:.2}, \
             interpolation {interpolated:.2}",
            glossy.gloss().map(|g| g.roughness),
        );
        assert!(ours >= plain + 1.5, "α {alpha}: {ours} vs {plain}");
        assert!(
            ours >= interpolated + 3.0,
            "α {alpha}: {ours} vs {interpolated}"
        );
    }
}
