//! Environment projection and relighting: an environment equal to one basis condition
//! relights to that condition's image, both steps are linear, a full turn is the
//! identity, projection conserves light, and the two floor models agree where they must.

#![allow(clippy::unwrap_used)] // tests: a failed unwrap is a failed test

mod common;

use std::f32::consts::{PI, TAU};

use frf_core::env::EnvMap;
use frf_core::image::{Image, Rgb, RgbImage};
use frf_reflectance::FieldHeader;
use frf_reflectance::field::ConditionRecord;
use frf_reflectance::flowcodec::quant::LogQuantizer;
use frf_reflectance::project::{FloorModel, Projector};
use frf_reflectance::relight::relight;
use glam::Mat3;

fn conditions() -> Vec<ConditionRecord> {
    let capture = common::tiny_capture(36, 64, 90);
    FieldHeader::from_capture(&capture, &[0], LogQuantizer::new(0.2, 4.0).unwrap(), 90)
        .unwrap()
        .conditions
}

fn delivered(c: &ConditionRecord) -> Rgb {
    c.lights
        .iter()
        .fold([0.0; 3], |a, l| [0, 1, 2].map(|i| a[i] + l.intensity[i]))
}

/// A textured environment: a sky gradient, a warm sun, a darker ground.
fn textured_env(w: usize) -> EnvMap {
    let probe = EnvMap::uniform([0.0; 3], w / 2);
    let img = Image::from_fn(w, w / 2, |x, y| {
        let d = probe.direction_of(x as f32, y as f32);
        let sun = d
            .dot(glam::Vec3::new(0.5, 0.6, -0.62).normalize())
            .max(0.0)
            .powi(200)
            * 500.0;
        if d.y >= 0.0 {
            [
                0.4 + d.x * 0.2 + sun,
                0.5 + sun * 0.9,
                0.9 - d.z * 0.3 + sun * 0.7,
            ]
        } else {
            [0.2 + 0.05 * (x % 9) as f32, 0.15, 0.1]
        }
    });
    EnvMap::from_image(img).unwrap()
}

fn basis_images(n: usize) -> Vec<RgbImage> {
    (0..n)
        .map(|k| {
            Image::from_fn(8, 6, |x, y| {
                [(x + k) as f32 * 0.1, (y * k) as f32 * 0.01, 0.5]
            })
        })
        .collect()
}

fn close(a: &[Rgb], b: &[Rgb], tol: f32) {
    let scale = a
        .iter()
        .flatten()
        .fold(0.0f32, |m, v| m.max(v.abs()))
        .max(1e-6);
    for (x, y) in a.iter().zip(b) {
        for c in 0..3 {
            assert!((x[c] - y[c]).abs() <= tol * scale, "{x:?} vs {y:?}");
        }
    }
}

#[test]
fn an_environment_equal_to_one_condition_relights_to_its_image() {
    let conds = conditions();
    let projector = Projector::new(&conds).unwrap();
    let turntable = 0.7;
    let probe = EnvMap::uniform([0.0; 3], 256);
    for k in [0, 9, 20, 24] {
        // Radiance such that the region's light equals what the condition delivers.
        let rot = Mat3::from_rotation_y(turntable);
        let in_region = |x: usize, y: usize| {
            projector.condition_of(rot * probe.direction_of(x as f32, y as f32)) == k
        };
        let omega: f32 = (0..256)
            .flat_map(|y| (0..512).map(move |x| (x, y)))
            .filter(|&(x, y)| in_region(x, y))
            .map(|(_, y)| probe.texel_solid_angle(y))
            .sum();
        let radiance = delivered(&conds[k]).map(|d| d / omega);
        let env = EnvMap::from_image(Image::from_fn(512, 256, |x, y| {
            if in_region(x, y) { radiance } else { [0.0; 3] }
        }))
        .unwrap();
        let coefficients = projector.project(&env, turntable, FloorModel::Environment);
        for (j, c) in coefficients.iter().enumerate() {
            let expected = if j == k { 1.0 } else { 0.0 };
            for v in c {
                assert!(
                    (v - expected).abs() < 1e-4,
                    "condition {k}: coefficient {j} = {c:?}"
                );
            }
        }
        let basis = basis_images(conds.len());
        let lit = relight(&basis, &coefficients).unwrap();
        close(lit.pixels(), basis[k].pixels(), 1e-4);
    }
}

/// The projection checked against a computation of its own: an environment lit in one
/// texel puts `L · Δω / Σ E` into the condition of the light nearest the texel's direction
/// (turned by the turntable), found by brute force over every light, with the texel's
/// solid angle from the equirectangular band formula; every other coefficient is zero.
/// Nothing here uses the projector's lookup grid or its sums.
#[test]
fn a_lit_texel_projects_onto_the_condition_of_its_nearest_light() {
    let conds = conditions();
    let projector = Projector::new(&conds).unwrap();
    let lights: Vec<(usize, glam::Vec3)> = conds
        .iter()
        .enumerate()
        .flat_map(|(k, c)| {
            c.lights
                .iter()
                .map(move |l| (k, glam::Vec3::from(l.direction)))
        })
        .collect();
    let (w, h) = (256usize, 128usize);
    let probe = EnvMap::uniform([0.0; 3], h);
    let radiance = [3.0f32, 2.0, 1.0];
    let mut checked = 0;
    for (i, turntable) in [0.0f32, 0.7, 2.5].into_iter().enumerate() {
        for t in 0..40usize {
            let (x, y) = ((t * 53 + i * 17) % w, (t * 29 + i * 11) % h);
            let d = Mat3::from_rotation_y(turntable) * probe.direction_of(x as f32, y as f32);
            let mut near: Vec<(f32, usize)> = lights.iter().map(|&(k, l)| (l.dot(d), k)).collect();
            near.sort_by(|a, b| b.0.total_cmp(&a.0));
            // Away from region boundaries: the projector's lookup grid is 0.5 degrees.
            let (best, second) = (near[0], near.iter().find(|n| n.1 != near[0].1).unwrap());
            if best.0.clamp(-1.0, 1.0).acos() + 2f32.to_radians() > second.0.clamp(-1.0, 1.0).acos()
            {
                continue;
            }
            let band = (2.0 * PI / w as f32)
                * ((y as f32 * PI / h as f32).cos() - ((y + 1) as f32 * PI / h as f32).cos());
            let env = EnvMap::from_image(Image::from_fn(w, h, |px, py| {
                if (px, py) == (x, y) {
                    radiance
                } else {
                    [0.0; 3]
                }
            }))
            .unwrap();
            let k = projector.project(&env, turntable, FloorModel::Environment);
            let e = delivered(&conds[best.1]);
            for (j, c) in k.iter().enumerate() {
                for ch in 0..3 {
                    let expected = if j == best.1 {
                        radiance[ch] * band / e[ch]
                    } else {
                        0.0
                    };
                    assert!(
                        (c[ch] - expected).abs() <= 1e-4 * expected.abs().max(1e-6),
                        "texel ({x}, {y}) at turntable {turntable}: condition {j} = {c:?}, expected {expected} in channel {ch} of condition {}",
                        best.1
                    );
                }
            }
            checked += 1;
        }
    }
    assert!(
        checked >= 60,
        "only {checked} texels away from region boundaries"
    );
}

#[test]
fn projection_and_relighting_are_linear() {
    let projector = Projector::new(&conditions()).unwrap();
    let a = textured_env(256);
    let b = EnvMap::sky();
    let b = EnvMap::from_image(Image::from_fn(256, 128, |x, y| b.image().get(x, y))).unwrap();
    let mix = EnvMap::from_image(Image::from_fn(256, 128, |x, y| {
        let (p, q) = (a.image().get(x, y), b.image().get(x, y));
        [0, 1, 2].map(|c| 2.0 * p[c] + 0.5 * q[c])
    }))
    .unwrap();
    let pa = projector.project(&a, 0.3, FloorModel::Environment);
    let pb = projector.project(&b, 0.3, FloorModel::Environment);
    let pm = projector.project(&mix, 0.3, FloorModel::Environment);
    let expected: Vec<Rgb> = pa
        .iter()
        .zip(&pb)
        .map(|(x, y)| [0, 1, 2].map(|c| 2.0 * x[c] + 0.5 * y[c]))
        .collect();
    close(&pm, &expected, 1e-4);
    let basis = basis_images(pa.len());
    let lm = relight(&basis, &pm).unwrap();
    let (la, lb) = (relight(&basis, &pa).unwrap(), relight(&basis, &pb).unwrap());
    let sum: Vec<Rgb> = la
        .pixels()
        .iter()
        .zip(lb.pixels())
        .map(|(x, y)| [0, 1, 2].map(|c| 2.0 * x[c] + 0.5 * y[c]))
        .collect();
    close(lm.pixels(), &sum, 1e-4);
}

#[test]
fn a_full_turn_is_the_identity_and_turns_compose() {
    let projector = Projector::new(&conditions()).unwrap();
    let env = textured_env(512);
    let base = projector.project(&env, 0.4, FloorModel::Environment);
    close(
        &projector.project(&env, 0.4 + TAU, FloorModel::Environment),
        &base,
        1e-3,
    );
    close(
        &projector.project(&env.rotated(TAU), 0.4, FloorModel::Environment),
        &base,
        1e-3,
    );
    // Turning the map by φ is turning the subject by φ.
    close(
        &projector.project(&env.rotated(0.4), 0.0, FloorModel::Environment),
        &base,
        1e-3,
    );
    // And a quarter turn does change things (the sun moves to another region).
    let quarter = projector.project(&env, 0.4 + PI / 2.0, FloorModel::Environment);
    let diff: f32 = quarter
        .iter()
        .zip(&base)
        .map(|(a, b)| (a[0] - b[0]).abs())
        .sum();
    assert!(diff > 0.1, "{diff}");
}

#[test]
fn projection_conserves_light() {
    let conds = conditions();
    let projector = Projector::new(&conds).unwrap();
    let env = textured_env(512);
    let regions = projector.region_light(&env, 1.1, FloorModel::Environment);
    let total = env.total_light();
    for c in 0..3 {
        let sum: f32 = regions.iter().map(|r| r[c]).sum();
        assert!(
            (sum - total[c]).abs() < 1e-4 * total[c],
            "{sum} vs {}",
            total[c]
        );
    }
    // Coefficients times what each condition delivers give the regions' light back.
    let coefficients = projector.project(&env, 1.1, FloorModel::Environment);
    for ((k, r), cond) in coefficients.iter().zip(&regions).zip(&conds) {
        let d = delivered(cond);
        for c in 0..3 {
            assert!((k[c] * d[c] - r[c]).abs() <= 1e-4 * r[c].abs().max(1e-3));
        }
    }
}

#[test]
fn lambertian_ground_of_albedo_one_under_a_uniform_sky_is_the_sky() {
    // Uniform radiance 1 over the upper hemisphere gives ground irradiance π, hence a
    // white ground's radiance 1: the same light from below as a uniform sphere.
    let projector = Projector::new(&conditions()).unwrap();
    let sphere = EnvMap::uniform([1.0; 3], 128);
    let sky_only = EnvMap::from_image(Image::from_fn(256, 128, |_, y| {
        if y < 64 { [1.0; 3] } else { [0.0; 3] }
    }))
    .unwrap();
    let reference = projector.project(&sphere, 0.0, FloorModel::Environment);
    let modelled = projector.project(
        &sky_only,
        0.0,
        FloorModel::LambertianGround { albedo: [1.0; 3] },
    );
    close(&modelled, &reference, 2e-3);
    // With the environment's own (black) lower hemisphere the floor gets nothing.
    let dark = projector.project(&sky_only, 0.0, FloorModel::Environment);
    for (k, c) in dark.iter().enumerate() {
        if projector.is_floor(k) {
            assert!(c[0].abs() < 1e-3, "floor condition {k}: {c:?}");
        }
    }
}

#[test]
fn bad_relighting_input_is_refused() {
    let basis = basis_images(3);
    let refused = |basis: &[RgbImage], c: &[[f32; 3]]| relight(basis, c).unwrap_err().to_string();
    let e = refused(&basis, &[[1.0; 3]; 2]);
    assert!(
        e.contains("relighting coefficients: expected 3, got 2"),
        "{e}"
    );
    let e = refused(&basis, &[[1.0; 3], [f32::NAN, 0.0, 0.0], [0.0; 3]]);
    assert!(
        e.contains("coefficient [NaN, 0.0, 0.0] is not finite"),
        "{e}"
    );
    let e = refused(&[], &[]);
    assert!(e.contains("no basis images to relight"), "{e}");
    let mut odd = basis.clone();
    odd[1] = Image::new(3, 3, [0.0; 3]);
    let e = refused(&odd, &[[1.0; 3]; 3]);
    assert!(e.contains("basis image size: expected 8x6, got 3x3"), "{e}");
}

/// The projection sums each condition's run of grid cells over a row's prefix sums
/// (issue 37); it equals the texel-by-texel sum of each texel into the condition of its
/// turned direction, for a turned map, any turntable angle and both floor models.
#[test]
fn the_run_length_projection_equals_the_sum_texel_by_texel() {
    let conds = conditions();
    let projector = Projector::new(&conds).unwrap();
    let env = textured_env(256).rotated(0.37);
    let floors = [
        FloorModel::Environment,
        FloorModel::LambertianGround {
            albedo: [0.3, 0.25, 0.2],
        },
    ];
    let turntables = [0.0f32, 0.7, -2.3, 5.9, 10f32.to_radians()];
    for floor in floors {
        let fast = projector.region_light_many(&env, &turntables, floor);
        let ground = match floor {
            FloorModel::Environment => None,
            FloorModel::LambertianGround { albedo } => Some(env.lambertian_ground(albedo)),
        };
        for (t, fast) in turntables.iter().zip(&fast) {
            let rot = Mat3::from_rotation_y(*t);
            let mut slow = vec![[0.0f64; 3]; conds.len()];
            let (w, h) = env.image().size();
            for y in 0..h {
                let omega = env.texel_solid_angle(y) as f64;
                for x in 0..w {
                    let d = env.direction_of(x as f32, y as f32);
                    let l = match ground {
                        Some(g) if d.y < 0.0 => g,
                        _ => env.image().get(x, y),
                    };
                    let k = projector.condition_of(rot * d);
                    for c in 0..3 {
                        slow[k][c] += l[c] as f64 * omega;
                    }
                }
            }
            let slow: Vec<Rgb> = slow.iter().map(|s| s.map(|v| v as f32)).collect();
            close(&slow, fast, 1e-5);
        }
    }
}
