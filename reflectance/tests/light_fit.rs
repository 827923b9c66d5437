//! The per-texel light fit on a synthetic glossy sphere whose normals are known: the
//! normals it recovers, and a light between the captured ones relit against the analytic
//! image, beside interpolating the nearest photographs; and, from a basis of grouped
//! lights as a stage's, a sun relit by the fitted normals beside the basis's relighting.

use frf_core::image::{Image, RgbImage};
use frf_core::sun::Sun;
use frf_reflectance::field::{ConditionRecord, LightRecord};
use frf_reflectance::light_fit::{LightFit, blend, farthest_lights, nearest_weights};
use frf_reflectance::project::Projector;
use frf_reflectance::sun_light::SunLight;
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

/// Basis conditions as a stage has them: each a 2 x 2 group of lights 12° apart about
/// one of `lights()`'s directions, of irradiance 2 in all.
fn grouped_conditions() -> Vec<ConditionRecord> {
    lights()
        .iter()
        .enumerate()
        .map(|(k, &d)| {
            let side = d.cross(Vec3::Y).normalize();
            let up = side.cross(d);
            let spread = 6f32.to_radians().tan();
            let lights = [(-1.0, -1.0), (1.0, -1.0), (-1.0, 1.0), (1.0, 1.0)]
                .map(|(a, b)| LightRecord {
                    direction: (d + spread * (a * side + b * up)).normalize().to_array(),
                    intensity: [0.5; 3],
                    solid_angle_sr: 0.05,
                })
                .to_vec();
            ConditionRecord {
                name: format!("c{k}"),
                floor: false,
                lights,
            }
        })
        .collect()
}

#[test]
fn a_field_basis_relights_a_sun_by_its_fitted_normals_near_the_analytic_image() {
    let conditions = grouped_conditions();
    // Each condition's image: its lights' photographs summed.
    let basis: Vec<RgbImage> = conditions
        .iter()
        .map(|c| {
            let parts: Vec<RgbImage> = c
                .lights
                .iter()
                .map(|l| photograph(Vec3::from(l.direction)).map(|p| p.map(|x| x * l.intensity[0])))
                .collect();
            Image::from_fn(SIDE, SIDE, |x, y| {
                let mut s = [0.0f32; 3];
                for p in &parts {
                    let v = p.get(x, y);
                    for c in 0..3 {
                        s[c] += v[c];
                    }
                }
                s
            })
        })
        .collect();
    let mask: Vec<bool> = (0..SIDE * SIDE).map(|i| normal(i).is_some()).collect();
    let alpha =
        Image::from_vec(SIDE, SIDE, mask.iter().map(|&m| m as u8 as f32).collect()).expect("sized");
    let fit = LightFit::of_basis(&basis, &conditions, &alpha);
    // The normals where the fit holds one, against the sphere's.
    let mut errors: Vec<f32> = (0..SIDE * SIDE)
        .filter_map(|i| Some(fit.texel(i)?.0.angle_between(normal(i)?).to_degrees()))
        .collect();
    errors.sort_by(f32::total_cmp);
    assert!(errors.len() > mask.iter().filter(|&&m| m).count() * 9 / 10);
    assert!(
        errors[errors.len() / 2] < 3.0,
        "median {}°",
        errors[errors.len() / 2]
    );
    // A sun between conditions, of illuminance 3.
    let direction = Vec3::new(0.45, 0.35, 0.82).normalize();
    let sun = Sun::new(direction, 0.53, [3.0; 3]).unwrap();
    let truth = photograph(direction).map(|p| p.map(|x| 3.0 * x));
    let light = SunLight::new(&sun, &conditions, &[0.0], None, 0);
    let normals = fit.normals();
    let ours = Image::from_fn(SIDE, SIDE, |x, y| {
        let i = y * SIDE + x;
        light.texel(0, normals[i], |k| basis[k].get(x, y))
    });
    // The basis: the sun's light given to the condition whose cell holds it.
    let k = Projector::new(&conditions).unwrap().condition_of(direction);
    let by_basis = basis[k].map(|p| p.map(|x| x * 3.0 / 2.0));
    let (a, b) = (psnr(&truth, &ours, &mask), psnr(&truth, &by_basis, &mask));
    assert!(a > 30.0 && a >= b + 5.0, "fit {a:.2} dB, basis {b:.2} dB");
}
