//! A synthetic one-light-at-a-time set: a sphere of the stage's own reflectance
//! (Lambert plus Torrance–Sparrow, [`crate::brdf`]) seen by an orthographic camera
//! looking down its `−z`, under distant lights spread over the hemisphere facing it,
//! written in the layout real sets share (`NNN.png` 16-bit linear, `light_directions.txt`,
//! `mask.png`). Its truth is exact (no cast shadows on a convex body, no noise), so a
//! relighting's error on it is the model's own: the development set of the light fit's
//! glossy lobe (real glossy photographs are kept for reporting).

use std::path::Path;

use frf_core::image::{GrayImage, Image, RgbImage};
use frf_core::io::{write_png16_gray, write_png16_rgb};
use glam::Vec3;

use crate::brdf::reflect;
use crate::error::Result;
use crate::material::Surface;

/// Lights of a set of `count`: a Fibonacci spiral over the cap of directions whose
/// angle to the camera (`+z`) is at most 70°, camera frame.
pub fn sphere_lights(count: usize) -> Vec<Vec3> {
    let floor = 70f32.to_radians().cos();
    (0..count)
        .map(|k| {
            let z = 1.0 - (1.0 - floor) * (k as f32 + 0.5) / count as f32;
            let r = (1.0 - z * z).max(0.0).sqrt();
            let a = k as f32 * 2.399_963;
            Vec3::new(r * a.cos(), r * a.sin(), z)
        })
        .collect()
}

/// The sphere of `surface` seen `side` pixels square (radius 0.45 of it) under a unit
/// light from each of `lights`: per light its image (linear radiance), and the mask.
pub fn sphere_images(
    side: usize,
    lights: &[Vec3],
    surface: &Surface,
) -> (Vec<RgbImage>, Vec<bool>) {
    sphere_images_by(side, lights, |n, l, v| reflect(surface, n, l, v))
}

/// [`sphere_images`] of another reflectance: `reflect(n, l, v)`, the radiance a unit
/// light from `l` sends toward `v` off a surface of normal `n` (data the stage's own
/// model did not make, for judging a fit of that model).
pub fn sphere_images_by(
    side: usize,
    lights: &[Vec3],
    reflect: impl Fn(Vec3, Vec3, Vec3) -> frf_core::image::Rgb,
) -> (Vec<RgbImage>, Vec<bool>) {
    let normal = |x: usize, y: usize| {
        let c = side as f32 / 2.0;
        let (u, v) = (
            (x as f32 + 0.5 - c) / (0.45 * side as f32),
            (c - y as f32 - 0.5) / (0.45 * side as f32),
        );
        let r2 = u * u + v * v;
        (r2 < 1.0).then(|| Vec3::new(u, v, (1.0 - r2).sqrt()))
    };
    let images = lights
        .iter()
        .map(|&l| {
            Image::from_fn(side, side, |x, y| {
                normal(x, y).map_or([0.0; 3], |n| reflect(n, l, Vec3::Z))
            })
        })
        .collect();
    let mask = (0..side * side)
        .map(|i| normal(i % side, i / side).is_some())
        .collect();
    (images, mask)
}

/// Writes [`sphere_images`] as a set into `dir` (created where missing), each file
/// atomically; images are scaled by `exposure` (kept below 1, a 16-bit PNG's white).
pub fn write_sphere_set(
    dir: &Path,
    (side, lights): (usize, &[Vec3]),
    surface: &Surface,
    exposure: f32,
) -> Result<()> {
    std::fs::create_dir_all(dir).map_err(|e| frf_core::CoreError::io(dir, e))?;
    let (images, mask) = sphere_images(side, lights, surface);
    for (k, img) in images.iter().enumerate() {
        write_png16_rgb(
            &dir.join(format!("{:03}.png", k + 1)),
            &img.map(|p| p.map(|c| c * exposure)),
        )?;
    }
    let mask = GrayImage::from_vec(
        side,
        side,
        mask.iter().map(|&m| f32::from(u8::from(m))).collect(),
    )
    .expect("sized by the images");
    write_png16_gray(&dir.join("mask.png"), &mask)?;
    let rows: String = lights
        .iter()
        .map(|l| format!("{:.6} {:.6} {:.6}\n", l.x, l.y, l.z))
        .collect();
    frf_core::atomic::write_bytes_atomic(&dir.join("light_directions.txt"), rows.as_bytes())?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_sphere_is_lit_where_it_faces_the_light_and_glints_at_the_mirror_point() {
        let surface = Surface {
            albedo: [0.4; 3],
            f0: 0.04,
            roughness: 0.15,
        };
        let l = Vec3::new(0.5, 0.0, 1.0).normalize();
        let (images, mask) = sphere_images(64, &[l], &surface);
        let img = &images[0];
        // The brightest texel's normal is halfway between the light and the view.
        let (best, _) = (0..64 * 64)
            .filter(|&i| mask[i])
            .map(|i| (i, img.pixels()[i][0]))
            .fold((0, 0.0f32), |a, b| if b.1 > a.1 { b } else { a });
        let h = (l + Vec3::Z).normalize();
        let (x, y) = (
            (best % 64) as f32 + 0.5 - 32.0,
            32.0 - (best / 64) as f32 - 0.5,
        );
        let (u, v) = (x / (0.45 * 64.0), y / (0.45 * 64.0));
        assert!((u - h.x).abs() < 0.06 && v.abs() < 0.06, "{u} {v} vs {h}");
        assert_eq!(img.pixels()[0], [0.0; 3]);
        assert_eq!(sphere_lights(12).len(), 12);
        assert!(
            sphere_lights(12)
                .iter()
                .all(|d| (d.length() - 1.0).abs() < 1e-5 && d.z > 0.3)
        );
    }
}
