//! Toward relighting fields under a sun by the per-texel light fit
//! ([`frf_reflectance::light_fit`]): at a pose's captured views, under an environment
//! holding a sun, the basis's relighting (which integrates the sun over its condition's
//! cell) against the environment less its sun ([`Sun::extract`]) relit by the basis plus
//! the sun relit by each view's light fit, both scored against the stage's truth. The fit
//! is made from the view's basis images, each condition a light at its lights'
//! irradiance-weighted direction, turned into the subject frame by the view's turntable
//! angle. A CPU experiment: fields do not relight this way yet.

use frf_core::env::EnvMap;
use frf_core::image::{Image, Rgb, RgbImage, luminance};
use frf_core::io::rgba_from;
use frf_core::sun::Sun;
use frf_reflectance::FieldFile;
use frf_reflectance::container::ReadAt;
use frf_reflectance::light_fit::LightFit;
use frf_reflectance::project::FloorModel;
use frf_reflectance::relight::relight;
use frf_stage::Stage;
use glam::{Mat3, Vec3};
use serde::Serialize;

use crate::error::{EvalError, Result};
use crate::metrics::{psnr, ssim, subject_mask};
use crate::views::truth_frame;

/// One captured view's scores.
#[derive(Debug, Clone, Serialize)]
pub struct SunFitScore {
    /// Column and row.
    pub view: (usize, usize),
    /// The basis alone: subject PSNR dB and SSIM.
    pub basis_psnr: f64,
    /// SSIM.
    pub basis_ssim: f64,
    /// The environment less its sun by the basis, plus the sun by the light fit.
    pub fit_psnr: f64,
    /// SSIM.
    pub fit_ssim: f64,
}

/// Scores `views` of `pose` under `env` (see the module text), the truth lit by
/// `lights` (the environment's median cut).
pub fn score_sun_fit<R: ReadAt>(
    field: &FieldFile<R>,
    stage: &Stage,
    pose: u32,
    (env, floor): (&EnvMap, FloorModel),
    views: &[((usize, usize), frf_core::camera::Camera)],
    lights: &[frf_core::light::DirLight],
) -> Result<Vec<SunFitScore>> {
    let Some((sun, rest)) = Sun::extract(env)? else {
        return Err(EvalError::Argument(frf_core::BadArgument::new(
            "--sun-fit",
            "the environment",
            "an environment with a sun (--sun, or a map with one)",
        )));
    };
    let h = field.header();
    let record = h.poses.iter().find(|p| p.pose == pose).ok_or_else(|| {
        EvalError::Argument(frf_core::BadArgument::new(
            "--pose",
            pose,
            "a pose of the field",
        ))
    })?;
    let projector = field.projector()?;
    // Each condition as one light: its lights' direction weighted by their irradiance,
    // and their irradiance summed.
    let conditions: Vec<(Vec3, Rgb)> = h
        .conditions
        .iter()
        .map(|c| {
            let (mut d, mut e) = (Vec3::ZERO, [0.0f32; 3]);
            for l in &c.lights {
                d += Vec3::from(l.direction).normalize() * luminance(l.intensity);
                for (sum, i) in e.iter_mut().zip(l.intensity) {
                    *sum += i;
                }
            }
            (d.normalize_or_zero(), e)
        })
        .collect();
    let mut scores = Vec::with_capacity(views.len());
    for &((u, v), camera) in views {
        let theta = record.views[u * h.rows + v].turntable_deg.to_radians();
        let to_subject = Mat3::from_rotation_y(-theta);
        let dirs: Vec<Vec3> = conditions.iter().map(|(d, _)| to_subject * *d).collect();
        let basis = field.basis(pose, u, v)?;
        let alpha = field.alpha(pose, u, v)?;
        // Each basis image per unit irradiance of its condition.
        let unit: Vec<RgbImage> = basis
            .iter()
            .zip(&conditions)
            .map(|(b, (_, e))| {
                b.map(|p| std::array::from_fn(|c| if e[c] > 0.0 { p[c] / e[c] } else { 0.0 }))
            })
            .collect();
        let refs: Vec<&RgbImage> = unit.iter().collect();
        let mask: Vec<bool> = alpha.pixels().iter().map(|&a| a > 0.5).collect();
        let fit = LightFit::fit(&refs, &dirs, &mask);
        let by_basis = relight(&basis, &projector.project(env, theta, floor))?;
        let smooth = relight(&basis, &projector.project(&rest, theta, floor))?;
        let e = sun.illuminance();
        let by_sun = fit.relight(&refs, &dirs, sun.direction(), 3);
        let by_fit = Image::from_fn(smooth.width(), smooth.height(), |x, y| {
            let (a, b) = (smooth.get(x, y), by_sun.get(x, y));
            std::array::from_fn(|c| a[c] + e[c] * b[c])
        });
        let truth = truth_frame(stage, pose, &camera, lights)?;
        let score = |img: &RgbImage| -> Result<(f64, f64)> {
            let test = rgba_from(img, &alpha)?;
            let m = subject_mask(&truth, &test);
            Ok((psnr(&truth, &test, Some(&m)), ssim(&truth, &test, Some(&m))))
        };
        let (basis_psnr, basis_ssim) = score(&by_basis)?;
        let (fit_psnr, fit_ssim) = score(&by_fit)?;
        scores.push(SunFitScore {
            view: (u, v),
            basis_psnr,
            basis_ssim,
            fit_psnr,
            fit_ssim,
        });
    }
    Ok(scores)
}
