//! The per-texel light fit on a synthetic glossy sphere whose normals are known: the
//! normals it recovers, and a light between the captured ones relit against the analytic
//! image, beside interpolating the nearest photographs.

use frf_core::image::{Image, RgbImage};
use frf_reflectance::light_fit::{LightFit, blend, farthest_lights, nearest_weights};
use glam::Vec3;

const SIDE: usize = 96;

/// The sphere's unit normal at pixel `i` (camera looking down -z), when it covers it.
fn normal(i: usize) -> Option<Vec3> {
    let (x, y) = (i % SIDE, i / SIDE);
    let u = (x as f32 + 0.5) / SIDE as f32 * 2.0 - 1.0;
    let v = 1.0 - (y as f32 + 0.5) / SIDE as f32 * 2.0;
    let r2 = u * u + v * v;
    (r2 < 0.95).then(|| Vec3::new(u, v, (1.0 - r2).sqrt()))
}

/// The sphere (albedo varying with position, a Blinn-Phong highlight) under a unit light
/// from `l`, seen from +z.
fn photograph(l: Vec3) -> RgbImage {
    let pixels = (0..SIDE * SIDE)
        .map(|i| match normal(i) {
            None => [0.0; 3],
            Some(n) => {
                let albedo = [0.6 + 0.2 * n.x, 0.5, 0.4 - 0.2 * n.y];
                let diffuse = n.dot(l).max(0.0);
                let h = (l + Vec3::Z).normalize();
                let specular = if diffuse > 0.0 {
                    0.15 * n.dot(h).max(0.0).powf(40.0)
                } else {
                    0.0
                };
                albedo.map(|a| a * diffuse + specular)
            }
        })
        .collect();
    Image::from_vec(SIDE, SIDE, pixels).expect("sized")
}

/// Lights on rings of the hemisphere toward the camera.
fn lights() -> Vec<Vec3> {
    let mut out = Vec::new();
    for (ring, count) in [(15f32, 4), (40.0, 8), (65.0, 12)] {
        for k in 0..count {
            let az =
                (k as f32 + 0.5 * (ring / 25.0).floor()) / count as f32 * std::f32::consts::TAU;
            let polar = ring.to_radians();
            out.push(Vec3::new(
                polar.sin() * az.cos(),
                polar.sin() * az.sin(),
                polar.cos(),
            ));
        }
    }
    out
}

fn psnr(a: &RgbImage, b: &RgbImage, mask: &[bool]) -> f64 {
    let (mut se, mut n) = (0.0f64, 0usize);
    for ((p, q), &m) in a.pixels().iter().zip(b.pixels()).zip(mask) {
        if m {
            for c in 0..3 {
                se += ((p[c] - q[c]) as f64).powi(2);
            }
            n += 3;
        }
    }
    10.0 * (1.0 / (se / n as f64)).log10()
}

#[test]
fn the_fit_recovers_the_normals_of_a_glossy_sphere() {
    let dirs = lights();
    let images: Vec<RgbImage> = dirs.iter().map(|&l| photograph(l)).collect();
    let refs: Vec<&RgbImage> = images.iter().collect();
    let mask: Vec<bool> = (0..SIDE * SIDE).map(|i| normal(i).is_some()).collect();
    let fit = LightFit::fit(&refs, &dirs, &mask);
    let mut errors: Vec<f32> = (0..SIDE * SIDE)
        .filter_map(|i| {
            let (n, _) = fit.texel(i)?;
            Some(n.dot(normal(i)?).clamp(-1.0, 1.0).acos().to_degrees())
        })
        .collect();
    let fitted = errors.len() as f32 / mask.iter().filter(|&&m| m).count() as f32;
    errors.sort_by(f32::total_cmp);
    let median = errors[errors.len() / 2];
    let p90 = errors[errors.len() * 9 / 10];
    assert!(fitted > 0.95, "fitted {fitted}");
    assert!(
        median < 3.0 && p90 < 6.0,
        "normal error median {median}°, 90th {p90}°"
    );
}

#[test]
fn a_light_between_the_kept_ones_relights_near_the_truth_where_interpolation_fails() {
    let all = lights();
    let kept = farthest_lights(&all, all.len() / 2, Vec3::Z);
    let dirs: Vec<Vec3> = kept.iter().map(|&k| all[k]).collect();
    let images: Vec<RgbImage> = dirs.iter().map(|&l| photograph(l)).collect();
    let refs: Vec<&RgbImage> = images.iter().collect();
    let mask: Vec<bool> = (0..SIDE * SIDE).map(|i| normal(i).is_some()).collect();
    let fit = LightFit::fit(&refs, &dirs, &mask);
    let mut gains = Vec::new();
    for (k, &l) in all.iter().enumerate().filter(|(k, _)| !kept.contains(k)) {
        let truth = photograph(l);
        let ours = fit.relight(&refs, &dirs, l, 3);
        let interpolated = blend(&refs, &nearest_weights(&dirs, l, 3));
        let (a, b) = (
            psnr(&truth, &ours, &mask),
            psnr(&truth, &interpolated, &mask),
        );
        assert!(a > 30.0, "light {k}: {a:.1} dB");
        gains.push(a - b);
    }
    let mean = gains.iter().sum::<f64>() / gains.len() as f64;
    assert!(
        mean >= 5.0,
        "mean gain over interpolation {mean:.1} dB ({gains:?})"
    );
}
