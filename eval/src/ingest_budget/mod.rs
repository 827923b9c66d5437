//! The error budget of ingest (`frf eval FIELD --capture C --env E --ingest-budget`): how
//! much of what a field loses against its oracle field comes from which step of ingest,
//! measured against the virtual stage's truth, so that a change to ingest is judged term
//! by term.
//!
//! **Fields.** One pose of the capture is ingested as `frf ingest` does, and again with
//! one [`Component`] at a time taken from the stage's truth ([`fields`]): the mattes, the
//! registration of the basis frames, what the sensor does to them (noise, quantization,
//! clipping), the registered basis images as a whole, the horizontal flows, the vertical
//! flows, and the image codec (JPEG at its best quality). With every component true the field is the oracle field
//! (`frf stage field`): true basis images and alpha, true flows.
//!
//! **Where.** Each field is rendered by the four-way morph at the captured views (no
//! interpolation: the error of the images and alpha alone) and at the centres of grid
//! quads ([`crate::views`]: the same cameras as `frf eval --cameras N`), and scored
//! against the stage's true image of the unperturbed walker under the environment. The
//! captures it is meant for repeat every walk cycle exactly (`frf stage --perturbation
//! 0`), so that the oracle field sits at the renderer's own floor.
//!
//! **What**, per component and place: the subject's PSNR and SSIM, the gain in dB over
//! the field as ingested, and the component's **share of the squared error**: the part
//! of the ingested field's squared error that making it true removes, `(E_ingested −
//! E_component) / E_ingested`, with `E` the frames' mean squared error on the subject
//! relative to each truth's peak (what PSNR measures). The oracle's share is what ingest
//! costs as a whole; the components' shares need not add up to it (they interact: a
//! better matte changes what registration moves).

pub mod fields;
pub mod plot;
pub mod variants;

use std::path::{Path, PathBuf};

use frf_core::image::{Image, Rgba};
use frf_core::io::write_png8_srgba;
use frf_core::light::DirLight;
use frf_core::progress::Progress;
use frf_reflectance::FieldFile;
use frf_render::morph::Variant;
use frf_render::renderer::Renderer;
use frf_render::resident::{Lighting, PoseSource};
use frf_stage::Stage;
use serde::{Deserialize, Serialize};

use crate::error::{EvalError, Result};
use crate::views::{
    EvalCamera, VariantScore, between_view_cameras, evaluate, grid_view_cameras, truth_frames,
};

/// A component of ingest that the budget takes from the truth, one at a time.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Component {
    /// Nothing: the field as ingested.
    Ingested,
    /// The set's alpha (the true coverage at the reference instant), and the basis
    /// frames matted with it.
    Mattes,
    /// The warp of each basis frame onto the reference instant: the true motion of the
    /// walker between them.
    Registration,
    /// The sensor: the basis frames and their clean plates as the lens forms them,
    /// without the sensor's noise, 12-bit quantization and clipping at full scale.
    Sensor,
    /// The sensor, the registration and the mattes together: the captured frames as
    /// the lens formed them, registered by the true motion and matted with the true
    /// alpha. What still separates them from the true basis images is the capture's own:
    /// each condition was lit at its own instant of the set, and shading changes as the
    /// walker moves.
    Steps,
    /// The registered basis images as a whole: the true images at the reference instant
    /// (registration, noise and the frames' matting together), with the estimated alpha.
    BasisImages,
    /// The flows between horizontal neighbours (consecutive cycles).
    HorizontalFlows,
    /// The flows between vertical neighbours (cameras).
    VerticalFlows,
    /// The image codec: the basis mosaics at JPEG quality 100.
    Codecs,
    /// Every component: the oracle field.
    Oracle,
}

impl Component {
    /// Every component, in the order of the budget's rows.
    pub const ALL: [Component; 10] = [
        Component::Ingested,
        Component::Mattes,
        Component::Registration,
        Component::Sensor,
        Component::Steps,
        Component::BasisImages,
        Component::HorizontalFlows,
        Component::VerticalFlows,
        Component::Codecs,
        Component::Oracle,
    ];

    /// Its name in reports and file names.
    pub fn name(self) -> &'static str {
        match self {
            Component::Ingested => "ingested",
            Component::Mattes => "mattes",
            Component::Registration => "registration",
            Component::Sensor => "sensor",
            Component::Steps => "sensor+reg+mattes",
            Component::BasisImages => "basis-images",
            Component::HorizontalFlows => "horizontal-flows",
            Component::VerticalFlows => "vertical-flows",
            Component::Codecs => "codecs",
            Component::Oracle => "oracle",
        }
    }

    /// What its field takes from the truth, in words.
    pub fn what(self) -> &'static str {
        match self {
            Component::Ingested => "nothing (the field as ingested)",
            Component::Mattes => "the alpha, and the frames matted with it",
            Component::Registration => "the motion each basis frame is registered by",
            Component::Sensor => {
                "basis frames and clean plates without noise, quantization or clipping"
            }
            Component::Steps => {
                "sensor, registration and mattes together (each frame still at its own instant)"
            }
            Component::BasisImages => "the registered basis images (estimated alpha)",
            Component::HorizontalFlows => "the flows between horizontal neighbours",
            Component::VerticalFlows => "the flows between vertical neighbours",
            Component::Codecs => "JPEG quality 100 for the basis mosaics",
            Component::Oracle => "everything (the oracle field)",
        }
    }
}

/// One place's scores of one component's field.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct PlaceScore {
    /// Mean subject PSNR over the place's cameras, dB.
    pub psnr_subject: f64,
    /// Mean subject SSIM.
    pub ssim_subject: f64,
    /// Mean alpha error over the frame.
    pub alpha_mae: f64,
    /// PSNR gained over the field as ingested, dB.
    pub gain_db: f64,
    /// Share of the ingested field's squared error that this component removes (see the
    /// module docs); negative when the field is worse.
    pub share_of_squared_error: f64,
    /// Each camera's subject PSNR, dB.
    pub frames_psnr: Vec<f64>,
}

/// One row of the budget: a component's field at the captured views and at quad
/// centres.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct ComponentScore {
    /// The component taken from the truth.
    pub component: Component,
    /// What that means.
    pub what: String,
    /// At the captured views.
    pub captured: PlaceScore,
    /// At the centres of grid quads.
    pub quad_centres: PlaceScore,
}

/// The field the user gave, scored beside the budget's own ingest of the capture (they
/// agree when it was ingested with the same settings).
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct GivenField {
    /// Its path.
    pub field: String,
    /// Mean subject PSNR at the captured views, dB.
    pub captured_psnr: f64,
    /// Mean subject PSNR at quad centres, dB.
    pub quad_centres_psnr: f64,
}

/// The whole budget (what `frf eval --ingest-budget --json` prints).
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct IngestBudgetReport {
    /// The capture whose stage gave the truth.
    pub capture: String,
    /// The environment.
    pub env: String,
    /// The pose.
    pub pose: u32,
    /// The renderer's device.
    pub device: String,
    /// Median-cut lights of the truth.
    pub truth_lights: usize,
    /// Cameras per place.
    pub cameras: usize,
    /// The ingest settings of the budget's fields.
    pub settings: String,
    /// The field given on the command line, if any.
    pub given: Option<GivenField>,
    /// Per component.
    pub rows: Vec<ComponentScore>,
}

impl IngestBudgetReport {
    /// The row of `component`.
    pub fn row(&self, component: Component) -> Option<&ComponentScore> {
        self.rows.iter().find(|r| r.component == component)
    }
}

/// What the budget's evaluation needs besides the fields.
pub struct BudgetScoring<'a> {
    /// The stage of the capture.
    pub stage: &'a Stage,
    /// The pose.
    pub pose: u32,
    /// How the fields are lit.
    pub lighting: &'a Lighting,
    /// The environment's lights (subject frame), for the truth.
    pub lights: &'a [DirLight],
    /// Cameras per place.
    pub cameras: usize,
    /// Render with the CPU reference.
    pub cpu: bool,
    /// Write every field's frame at the first camera of each place here.
    pub images: Option<&'a Path>,
}

/// The part of the summed squared error of frames of PSNR `base` that frames of PSNR
/// `row` (the same frames) remove: `1 − Σ row's / Σ base's` (0 where the base has none).
fn share_removed(base: &[f64], row: &[f64]) -> f64 {
    let sum = |p: &[f64]| -> f64 { p.iter().map(|&x| squared_error(x)).sum() };
    let e0 = sum(base);
    if e0 > 0.0 { (e0 - sum(row)) / e0 } else { 0.0 }
}

/// Normalised squared error of a frame from its PSNR (`10^(−PSNR/10)`: MSE over the
/// truth's peak squared).
fn squared_error(psnr: f64) -> f64 {
    if psnr.is_finite() {
        10f64.powf(-psnr / 10.0)
    } else if psnr > 0.0 {
        0.0
    } else {
        f64::INFINITY
    }
}

/// Renders a field at both places; returns its scores there and the renderer's device.
fn score_field(
    path: &Path,
    scoring: &BudgetScoring,
    cameras: &(Vec<EvalCamera>, Vec<EvalCamera>),
    truths: &(Vec<Image<Rgba>>, Vec<Image<Rgba>>),
    name: &str,
) -> Result<(VariantScore, VariantScore, String)> {
    let field = FieldFile::open(path)?;
    let source = PoseSource::load(&field, scoring.pose, scoring.lighting)?;
    let renderer = Renderer::open(&source, scoring.cpu)?;
    let keep = |place: &'static str| {
        move |i: usize, _: Variant, img: &Image<Rgba>| -> Result<()> {
            if let Some(dir) = scoring.images.filter(|_| i == 0) {
                write_png8_srgba(&dir.join(format!("{place}_{name}.png")), img, 1.0)?;
            }
            Ok(())
        }
    };
    let captured = evaluate(
        &renderer,
        &cameras.0,
        &truths.0,
        &[Variant::FourWay],
        &mut keep("captured"),
    )?
    .remove(0);
    let centres = evaluate(
        &renderer,
        &cameras.1,
        &truths.1,
        &[Variant::FourWay],
        &mut keep("quad_centre"),
    )?
    .remove(0);
    Ok((captured, centres, renderer.device()))
}

/// Scores every component's field (from [`fields::write_fields`]) and the field the user
/// gave, if any, at the captured views and at quad centres.
pub fn evaluate_fields(
    fields: &[(Component, PathBuf)],
    given: Option<&Path>,
    scoring: &BudgetScoring,
    progress: &dyn Progress,
) -> Result<(Vec<ComponentScore>, Option<GivenField>, String)> {
    let Some((_, first)) = fields.first() else {
        return Err(EvalError::Misuse(
            "the ingest budget has no fields to score".into(),
        ));
    };
    let geometry = {
        let field = FieldFile::open(first)?;
        PoseSource::load(&field, scoring.pose, &Lighting::Unlit)?.geometry
    };
    let cameras = (
        grid_view_cameras(&geometry, scoring.cameras)?,
        between_view_cameras(&geometry, scoring.cameras)?,
    );
    let all: Vec<_> = cameras
        .0
        .iter()
        .chain(&cameras.1)
        .map(|c| c.camera)
        .collect();
    progress.phase("ingest budget: truth frames", all.len());
    let (mut truth, _) = truth_frames(scoring.stage, scoring.pose, &all, scoring.lights, progress)?;
    progress.finish();
    let centres = truth.split_off(cameras.0.len());
    let truths = (truth, centres);
    if let Some(dir) = scoring.images {
        std::fs::create_dir_all(dir).map_err(|e| frf_core::CoreError::io(dir, e))?;
        write_png8_srgba(&dir.join("captured_truth.png"), &truths.0[0], 1.0)?;
        write_png8_srgba(&dir.join("quad_centre_truth.png"), &truths.1[0], 1.0)?;
    }
    progress.phase(
        "ingest budget: fields rendered",
        fields.len() + usize::from(given.is_some()),
    );
    let mut device = String::new();
    let mut scored = Vec::new();
    for (component, path) in fields {
        let (captured, centres, d) =
            score_field(path, scoring, &cameras, &truths, component.name())?;
        device = d;
        scored.push((*component, captured, centres));
        progress.step();
    }
    let given = match given {
        Some(path) => {
            let (captured, centres, _) = score_field(path, scoring, &cameras, &truths, "given")?;
            progress.step();
            Some(GivenField {
                field: path.display().to_string(),
                captured_psnr: captured.psnr_subject,
                quad_centres_psnr: centres.psnr_subject,
            })
        }
        None => None,
    };
    progress.finish();
    let base = scored
        .iter()
        .find(|s| s.0 == Component::Ingested)
        .ok_or_else(|| EvalError::Misuse("the ingest budget lacks its ingested field".into()))?
        .clone();
    let place = |s: &VariantScore, ingested: &VariantScore| {
        let psnr =
            |v: &VariantScore| -> Vec<f64> { v.frames.iter().map(|f| f.psnr_subject).collect() };
        PlaceScore {
            psnr_subject: s.psnr_subject,
            ssim_subject: s.ssim_subject,
            alpha_mae: s.alpha_mae,
            gain_db: s.psnr_subject - ingested.psnr_subject,
            share_of_squared_error: share_removed(&psnr(ingested), &psnr(s)),
            frames_psnr: psnr(s),
        }
    };
    let rows = scored
        .iter()
        .map(|(component, captured, centres)| ComponentScore {
            component: *component,
            what: component.what().to_string(),
            captured: place(captured, &base.1),
            quad_centres: place(centres, &base.2),
        })
        .collect();
    Ok((rows, given, device))
}

/// A row's figures: PSNR, gain and share (percent) at the captured views, then at quad
/// centres.
fn figures(r: &ComponentScore) -> [f64; 6] {
    let p = |s: &PlaceScore| [s.psnr_subject, s.gain_db, 100.0 * s.share_of_squared_error];
    let (a, b) = (p(&r.captured), p(&r.quad_centres));
    [a[0], a[1], a[2], b[0], b[1], b[2]]
}

/// The budget as a text table.
pub fn table(report: &IngestBudgetReport) -> String {
    let mut out = format!(
        "{:<17} {:>26}   {:>26}\n{:<17} {:>8} {:>8} {:>8}   {:>8} {:>8} {:>8}\n",
        "taken from truth",
        "at the captured views",
        "at quad centres",
        "",
        "PSNR dB",
        "gain dB",
        "share",
        "PSNR dB",
        "gain dB",
        "share"
    );
    for r in &report.rows {
        let f = figures(r);
        out += &format!(
            "{:<17} {:>8.2} {:>+8.2} {:>7.1}%   {:>8.2} {:>+8.2} {:>7.1}%\n",
            r.component.name(),
            f[0],
            f[1],
            f[2],
            f[3],
            f[4],
            f[5]
        );
    }
    if let Some(g) = &report.given {
        out += &format!(
            "{:<17} {:>8.2} {:>8} {:>8}   {:>8.2}\n",
            "(the field given)", g.captured_psnr, "", "", g.quad_centres_psnr
        );
    }
    out
}

/// The budget as a Markdown table, for docs/results.
pub fn markdown(report: &IngestBudgetReport) -> String {
    let mut out = String::from(
        "| taken from the truth | captured views: PSNR (dB) | gain (dB) | share of squared error | quad centres: PSNR (dB) | gain (dB) | share of squared error |\n|---|---|---|---|---|---|---|\n",
    );
    for r in &report.rows {
        let f = figures(r);
        out += &format!(
            "| {} | {:.2} | {:+.2} | {:.1} % | {:.2} | {:+.2} | {:.1} % |\n",
            r.component.name(),
            f[0],
            f[1],
            f[2],
            f[3],
            f[4],
            f[5]
        );
    }
    out
}
impl IngestBudgetReport {
    /// What the budget measured, in a line above its table.
    pub fn header(&self) -> String {
        format!(
            "ingest budget of {} pose {} under {}: subject PSNR of the four-way morph at {} \
             captured views and {} quad centres, each field with one component taken from the \
             truth (renders on {}; truth: {} median-cut lights)",
            self.capture,
            self.pose,
            self.env,
            self.cameras,
            self.cameras,
            self.device,
            self.truth_lights
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Known answers, worked by hand: frames at 30 and 40 dB hold squared errors 1e-3 and
    /// 1e-4 (1.1e-3 in all); at 40 and 40 dB, 2e-4: 9/11 of it removed. A row as bad as
    /// the base removes none; one twice as bad (3 dB lower: 10^-0.3 ≈ 0.501) removes
    /// about −0.995 of it; a perfect frame removes its own.
    #[test]
    fn the_share_removed_is_the_part_of_the_summed_squared_error_gone() {
        let close = |a: f64, b: f64| (a - b).abs() < 1e-9;
        assert!(close(
            share_removed(&[30.0, 40.0], &[40.0, 40.0]),
            9.0 / 11.0
        ));
        assert!(close(share_removed(&[30.0, 40.0], &[30.0, 40.0]), 0.0));
        let worse = share_removed(&[30.0], &[30.0 - 3.0]);
        assert!((worse + 0.995).abs() < 1e-3, "{worse}");
        assert!(close(
            share_removed(&[30.0, 30.0], &[f64::INFINITY, 30.0]),
            0.5
        ));
        assert!(close(share_removed(&[f64::INFINITY], &[30.0]), 0.0));
    }
}
