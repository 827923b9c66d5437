//! The error budget of view interpolation (`frf eval FIELD --capture C --env E
//! --budget`): how much of the subject's error at a camera between the grid's views
//! comes from where, measured against the virtual stage's truth, so that a change to the
//! renderer is judged term by term.
//!
//! **Where.** Cameras on the cylinder of camera centres at offsets `(β, γ)` of a grid
//! quad: along a row (`γ = 0`, `β` = ¼, ½, ¾), along a column (`β = 0`), and toward the
//! quad's centre (`β = γ`), each at the same [`crate::views`] spread of quads (over the
//! columns, alternating between the row gaps), plus the captured views themselves
//! (`β = γ = 0`). Each camera is centred at the bilinear blend of the quad's centres,
//! with orientation and intrinsics interpolated as the renderer does
//! ([`frf_render::cylinder::interpolate_camera`]).
//!
//! **What**, per offset, PSNR and SSIM of the subject (where either alpha is ≥ ½) against
//! the stage's true image of the unperturbed walker under the same environment:
//! - every interpolation variant the renderer offers;
//! - at the captured views (offset 0): the error of relighting through the basis and of
//!   storage, under everything else;
//! - the **flow floor** ([`floor`]): the field's views carried by the *true*
//!   correspondences with the true visibility, what any flow-based morph of this field
//!   would still get wrong (resampling, view-dependent shading, points no view sees);
//! - the **geometry baselines** ([`ulr`]): unstructured lumigraph rendering of the same
//!   views on the pose's visual hull, and on the stage's true surface (the upper bound
//!   of any proxy).
//!
//! The captures it is meant for repeat every walk cycle exactly (`frf stage
//! --perturbation 0`): then the truth is what interpolation should reach, and the budget
//! isolates the renderer from the cycle-to-cycle differences.

pub mod floor;
pub mod plot;
pub mod ulr;

use std::time::Instant;

use frf_core::camera::Camera;
use frf_core::image::{Image, Rgba};
use frf_core::light::DirLight;
use frf_render::cylinder::{bilinear_weights, interpolate_camera};
use frf_render::geometry::PoseGeometry;
use frf_render::morph::Variant;
use frf_render::renderer::Renderer;
use frf_render::resident::ResidentPose;
use frf_stage::Stage;
use frf_stage::geometry::Ray;
use glam::Vec3;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use crate::error::Result;
use crate::metrics::{psnr, ssim, subject_mask};
use crate::views::{quad_corners, truth_frame};
use frf_core::progress::Progress;

/// Which way from the quad's first corner the cameras are moved.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Direction {
    /// At the captured views.
    Captured,
    /// Along the row toward the next column (`γ = 0`).
    Row,
    /// Along the column toward the next row (`β = 0`).
    Column,
    /// Toward the quad's centre (`β = γ`).
    Centre,
}

impl Direction {
    /// Name in reports.
    pub fn name(self) -> &'static str {
        match self {
            Direction::Captured => "captured",
            Direction::Row => "row",
            Direction::Column => "column",
            Direction::Centre => "centre",
        }
    }
}

/// Fractions of the way to the next view that the budget measures at (besides 0).
pub const FRACTIONS: [f32; 3] = [0.25, 0.5, 0.75];

/// Name of the flow floor in reports.
pub const FLOOR: &str = "floor: true correspondences";
/// Name of ULR on the visual hull.
pub const ULR_HULL: &str = "ulr: visual hull";
/// Name of ULR on the true surface.
pub const ULR_TRUE: &str = "ulr: true surface";

/// Voxels by which a view's ray may enter the hull before the point it looks at and
/// still count as seeing it: the point lies on the hull's surface facing the camera, and
/// another view's ray may graze a voxel or two of that surface on its way.
const HULL_VISIBILITY_VOXELS: f32 = 2.5;
/// Metres by which a view's ray may meet the true surface before the point and still
/// see it (as the stage's true flows, `frf_stage::truth`).
const TRUE_VISIBILITY_M: f32 = 0.002;

/// One offset of the budget.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Offset {
    /// Which way.
    pub direction: Direction,
    /// Toward the next column.
    pub beta: f32,
    /// Toward the next row.
    pub gamma: f32,
}

/// The offsets the budget measures at: the captured views, then [`FRACTIONS`] along
/// rows, along columns and toward quad centres.
pub fn offsets() -> Vec<Offset> {
    let mut out = vec![Offset {
        direction: Direction::Captured,
        beta: 0.0,
        gamma: 0.0,
    }];
    for (direction, along) in [
        (Direction::Row, (1.0, 0.0)),
        (Direction::Column, (0.0, 1.0)),
        (Direction::Centre, (1.0, 1.0)),
    ] {
        out.extend(FRACTIONS.iter().map(|&f| Offset {
            direction,
            beta: f * along.0,
            gamma: f * along.1,
        }));
    }
    out
}

/// One camera of the budget: where it is in which quad.
#[derive(Debug, Clone)]
pub struct BudgetCamera {
    /// The camera (subject frame).
    pub camera: Camera,
    /// The quad's views `[A, B, C, D]`.
    pub views: [usize; 4],
    /// Their bilinear weights at the camera's offset.
    pub weights: [f32; 4],
}

/// The cameras at `offset` of `quads` quads of a pose (see the module docs).
pub fn cameras_at(
    geometry: &PoseGeometry,
    quads: usize,
    offset: Offset,
) -> Result<Vec<BudgetCamera>> {
    Ok(quad_corners(geometry, quads)?
        .into_iter()
        .map(|(u, v)| {
            let views = [
                geometry.view(u, v),
                geometry.view(u + 1, v),
                geometry.view(u, v + 1),
                geometry.view(u + 1, v + 1),
            ];
            let cams = views.map(|i| &geometry.cameras[i]);
            let weights = bilinear_weights(offset.beta, offset.gamma);
            let centre: Vec3 = (0..4).map(|k| cams[k].centre() * weights[k]).sum();
            BudgetCamera {
                camera: interpolate_camera(cams, offset.beta, offset.gamma, centre),
                views,
                weights,
            }
        })
        .collect())
}

/// One method scored at one offset: means over the offset's cameras.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct MethodScore {
    /// A variant's name, or [`FLOOR`], [`ULR_HULL`], [`ULR_TRUE`].
    pub name: String,
    /// PSNR of the subject, dB.
    pub psnr_subject: f64,
    /// SSIM of the subject's luminance.
    pub ssim_subject: f64,
    /// Seconds per frame (variants on the renderer's device; baselines on the CPU, not
    /// optimised: for orientation only).
    pub seconds_per_frame: f64,
}

/// The budget at one offset.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct BudgetRow {
    /// Which way.
    pub direction: Direction,
    /// Toward the next column.
    pub beta: f32,
    /// Toward the next row.
    pub gamma: f32,
    /// Each method.
    pub methods: Vec<MethodScore>,
}

impl BudgetRow {
    /// The score of the method named `name`.
    pub fn method(&self, name: &str) -> Option<&MethodScore> {
        self.methods.iter().find(|m| m.name == name)
    }
}

/// A whole budget (what `frf eval --budget --json` prints).
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct BudgetReport {
    /// The field.
    pub field: String,
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
    /// Quads (cameras) per offset.
    pub quads: usize,
    /// Per offset.
    pub rows: Vec<BudgetRow>,
}

/// What the budget needs: the renderer, the same pose resident on the CPU (for the
/// baselines), the stage and the environment's lights (subject frame).
pub struct BudgetInputs<'a> {
    /// Renders the variants.
    pub renderer: &'a Renderer,
    /// The pose relit on the CPU ([`ResidentPose::relight_cpu`]).
    pub resident: &'a ResidentPose,
    /// The stage of the capture.
    pub stage: &'a Stage,
    /// The pose.
    pub pose: u32,
    /// The environment's lights.
    pub lights: &'a [DirLight],
    /// Called with the first camera's frames at each offset (its truth named `truth`),
    /// to keep them.
    pub keep: Option<&'a Keep<'a>>,
}

/// What [`BudgetInputs::keep`] is called with: the offset, the method's name (or
/// `truth`), the frame.
pub type Keep<'a> = dyn Fn(&Offset, &str, &Image<Rgba>) -> Result<()> + Sync + 'a;

/// Frames the budget computes (for a progress bar): per offset and camera, the truth,
/// each variant and the three baselines.
pub fn frames(quads: usize, variants: usize) -> usize {
    offsets().len() * quads * (1 + variants + 3)
}

fn score(name: &str, truths: &[Image<Rgba>], frames: &[Image<Rgba>], seconds: f64) -> MethodScore {
    let n = truths.len().max(1) as f64;
    let (mut p, mut s) = (0.0, 0.0);
    for (t, f) in truths.iter().zip(frames) {
        let mask = subject_mask(t, f);
        p += psnr(t, f, Some(&mask));
        s += ssim(t, f, Some(&mask));
    }
    MethodScore {
        name: name.to_string(),
        psnr_subject: p / n,
        ssim_subject: s / n,
        seconds_per_frame: seconds / n,
    }
}

/// Runs the budget at every offset with `quads` cameras each, in one progress phase of
/// [`frames`] steps.
pub fn run(
    inputs: &BudgetInputs,
    quads: usize,
    variants: &[Variant],
    progress: &dyn Progress,
) -> Result<Vec<BudgetRow>> {
    progress.phase("budget frames", frames(quads, variants.len()));
    let step = || progress.step();
    let rows = run_offsets(inputs, quads, variants, &step);
    progress.finish();
    rows
}

fn run_offsets(
    inputs: &BudgetInputs,
    quads: usize,
    variants: &[Variant],
    step: &(dyn Fn() + Sync),
) -> Result<Vec<BudgetRow>> {
    let geometry = &inputs.resident.geometry;
    let hull = geometry.proxy.hull();
    let actor = inputs
        .stage
        .actor(None, inputs.stage.pose_time_s(inputs.pose));
    offsets()
        .into_iter()
        .map(|offset| {
            let cameras = cameras_at(geometry, quads, offset)?;
            let truths = cameras
                .par_iter()
                .map(|c| {
                    let t = truth_frame(inputs.stage, inputs.pose, &c.camera, inputs.lights);
                    step();
                    t
                })
                .collect::<Result<Vec<_>>>()?;
            let keep = |name: &str, frame: &Image<Rgba>| match inputs.keep {
                Some(keep) => keep(&offset, name, frame),
                None => Ok(()),
            };
            if let Some(t) = truths.first() {
                keep("truth", t)?;
            }
            let mut methods = Vec::new();
            for &variant in variants {
                let start = Instant::now();
                let frames = cameras
                    .iter()
                    .map(|c| {
                        let f = inputs.renderer.render(&c.camera, variant).map(|r| r.0);
                        step();
                        f
                    })
                    .collect::<std::result::Result<Vec<_>, _>>()?;
                methods.push(score(
                    variant.name(),
                    &truths,
                    &frames,
                    start.elapsed().as_secs_f64(),
                ));
                if let Some(f) = frames.first() {
                    keep(variant.name(), f)?;
                }
            }
            let baseline = |name: &str, f: &(dyn Fn(&BudgetCamera) -> Image<Rgba> + Sync)| {
                let start = Instant::now();
                let frames: Vec<Image<Rgba>> = cameras
                    .iter()
                    .map(|c| {
                        let frame = f(c);
                        step();
                        frame
                    })
                    .collect();
                let seconds = start.elapsed().as_secs_f64();
                if let Some(f) = frames.first() {
                    keep(name, f)?;
                }
                Ok::<_, crate::EvalError>(score(name, &truths, &frames, seconds))
            };
            methods.push(baseline(FLOOR, &|c| {
                floor::correspondence_floor(
                    inputs.stage,
                    inputs.pose,
                    inputs.resident,
                    &c.camera,
                    c.views,
                    c.weights,
                )
            })?);
            if let Some(hull) = hull {
                let slack = HULL_VISIBILITY_VOXELS * hull.grid().voxel_m;
                methods.push(baseline(ULR_HULL, &|c| {
                    let depths = ulr::depths(&c.camera, |o, d| hull.first_hit(o, d));
                    ulr::render(inputs.resident, &c.camera, &depths, |k, p| {
                        let centre = geometry.cameras[k].centre();
                        let to = p - centre;
                        hull.first_hit(centre, to.normalize())
                            .is_none_or(|t| t >= to.length() - slack)
                    })
                })?);
            }
            methods.push(baseline(ULR_TRUE, &|c| {
                let depths = ulr::depths(&c.camera, |o, d| {
                    actor
                        .intersect(&Ray { origin: o, dir: d }, 0.0, f32::INFINITY)
                        .map(|h| h.t)
                });
                ulr::render(inputs.resident, &c.camera, &depths, |k, p| {
                    let centre = geometry.cameras[k].centre();
                    let to = p - centre;
                    let dist = to.length();
                    actor
                        .intersect(
                            &Ray {
                                origin: centre,
                                dir: to / dist,
                            },
                            0.0,
                            dist + 1.0,
                        )
                        .is_none_or(|h| h.t >= dist - TRUE_VISIBILITY_M)
                })
            })?);
            Ok(BudgetRow {
                direction: offset.direction,
                beta: offset.beta,
                gamma: offset.gamma,
                methods,
            })
        })
        .collect()
}

/// The budget as a text table: one line per offset, PSNR / SSIM of each method.
pub fn table(rows: &[BudgetRow]) -> String {
    let Some(first) = rows.first() else {
        return String::new();
    };
    let mut out = format!("{:<9} {:>5} {:>5}", "offset", "β", "γ");
    for m in &first.methods {
        out += &format!("  {:>16}", short(&m.name));
    }
    out.push('\n');
    for r in rows {
        out += &format!("{:<9} {:>5.2} {:>5.2}", r.direction.name(), r.beta, r.gamma);
        for m in &r.methods {
            out += &format!("  {:>8.2} / {:.3}", m.psnr_subject, m.ssim_subject);
        }
        out.push('\n');
    }
    out
}

/// A method's name shortened for a column header.
fn short(name: &str) -> &str {
    match name {
        FLOOR => "flow floor",
        ULR_HULL => "ulr hull",
        ULR_TRUE => "ulr true",
        n => n,
    }
}

/// The budget as a Markdown table (PSNR dB / SSIM per method), for docs/results.
pub fn markdown(rows: &[BudgetRow]) -> String {
    let Some(first) = rows.first() else {
        return String::new();
    };
    let mut out = String::from("| offset | β | γ |");
    for m in &first.methods {
        out += &format!(" {} |", short(&m.name));
    }
    out += "\n|---|---|---|";
    out += &"---|".repeat(first.methods.len());
    out.push('\n');
    for r in rows {
        out += &format!("| {} | {} | {} |", r.direction.name(), r.beta, r.gamma);
        for m in &r.methods {
            out += &format!(" {:.2} / {:.3} |", m.psnr_subject, m.ssim_subject);
        }
        out.push('\n');
    }
    out
}
