//! The oracle field: the flowed reflectance field that a perfect ingest would produce
//! from a virtual-stage capture, built from the stage's ground truth instead of being
//! estimated: noise-free basis images of each view at its reference instant (perfectly
//! registered and matted onto black), the true alpha, and the true flows to every grid
//! neighbour. It measures the storage on stage data before any estimation error, and
//! lets the renderer be judged apart from ingest.

use frf_core::camera::Camera;
use frf_core::capture::Capture;
use frf_core::grid::{Neighbour, PoseStep};
use frf_core::image::{FlowImage, GrayImage};
use frf_ingest::shadows::{ShadowOptions, pose_shadows};
use frf_reflectance::flowcodec::quant::LogQuantizer;
use frf_reflectance::stats::FieldStats;
use frf_reflectance::store::{EncodedView, encode_pose_flows, encode_view};
use frf_reflectance::{FieldFile, FieldHeader, FieldWriter, ViewData};
use frf_stage::Stage;
use frf_stage::render::{Scene, render};
use frf_stage::studio::Illumination;
use rayon::prelude::*;

use crate::error::Result;

/// The true flows of view `(u, v)` of `pose` to each neighbour ([`Neighbour::ALL`] order).
pub fn true_flows(stage: &Stage, pose: u32, u: usize, v: usize) -> Result<[Option<FlowImage>; 4]> {
    let (surface, _) = stage.reference_surface(pose, u, v)?;
    let mut flows: [Option<FlowImage>; 4] = Default::default();
    for n in Neighbour::ALL {
        if let Some((u2, v2)) = n.of(u, v, stage.cycles(), stage.cameras().len(), true) {
            let to = stage.view_setup(pose, u2, v2, 0.0)?;
            flows[n.index()] = Some(frf_stage::truth::flow_between(&surface, &to).flow);
        }
    }
    Ok(flows)
}

/// The true flows of view `(u, v)` of `pose` to the same camera's image at the next and
/// the previous of `poses` (sorted; [`PoseStep::ALL`] order, [`PoseStep::of`]): how the
/// walker moves between them, in true pixels of both images, as ingest stores them.
pub fn true_pose_flows(
    stage: &Stage,
    poses: &[u32],
    pose: u32,
    u: usize,
    v: usize,
) -> Result<[Option<FlowImage>; 2]> {
    let (surface, _) = stage.reference_surface(pose, u, v)?;
    let mut flows: [Option<FlowImage>; 2] = Default::default();
    for step in PoseStep::ALL {
        if let Some((to_pose, to_u)) = step.of(pose, u, poses, stage.cycles(), true) {
            let to = stage.view_setup(to_pose, to_u, v, 0.0)?;
            flows[step.index()] = Some(frf_stage::truth::flow_between(&surface, &to).flow);
        }
    }
    Ok(flows)
}

/// The oracle data of one view: true basis images, alpha and flows.
pub fn oracle_view(stage: &Stage, pose: u32, u: usize, v: usize) -> Result<ViewData> {
    let setup = stage.view_setup(pose, u, v, 0.0)?;
    let basis = (0..stage.basis().len())
        .map(|c| {
            let illumination = Illumination::Lights(stage.condition_lights(c)?);
            let scene = Scene {
                actor: Some(&setup.actor),
                studio: false,
                illumination: &illumination,
            };
            Ok(render(&setup.camera, &scene, stage.config().samples_per_axis).color)
        })
        .collect::<Result<Vec<_>>>()?;
    let (_, alpha) = stage.reference_surface(pose, u, v)?;
    Ok(ViewData {
        basis,
        alpha,
        flows: true_flows(stage, pose, u, v)?,
    })
}

/// Options of [`write_oracle_field`].
#[derive(Debug, Clone)]
pub struct OracleOptions {
    /// Poses to include (each must be in the stage's configuration).
    pub poses: Vec<u32>,
    /// JPEG quality of the basis mosaics.
    pub jpeg_quality: u8,
    /// Left-predict flow codes before Huffman coding.
    pub predict_flow: bool,
    /// Visual hulls and shadow maps, carved from the true mattes (`None`: neither).
    pub shadows: Option<ShadowOptions>,
    /// The true flows between consecutive poses of the field, as `frf ingest
    /// --pose-flow` stores estimated ones.
    pub pose_flows: bool,
}

/// What writing an oracle field made.
#[derive(Debug, Clone)]
pub struct OracleWritten {
    /// The field's statistics.
    pub stats: FieldStats,
    /// Wall seconds spent carving the visual hulls and computing the shadow maps.
    pub shadow_seconds: f64,
}

impl OracleWritten {
    /// The field written to `out` for a person, `seconds` after it was started: the
    /// time, the hulls' and shadow maps' (on a line `frf report` reads) and the sizes.
    pub fn describe(&self, out: &std::path::Path, seconds: f64) -> Result<String> {
        let stats = &self.stats;
        let bytes = std::fs::metadata(out)
            .map_err(|e| frf_core::CoreError::io(out, e))?
            .len();
        Ok([
            format!(
                "oracle field written to {} in {seconds:.1} s (wall)",
                out.display()
            ),
            format!("{SHADOW_TIME_LINE}{:.3} s", self.shadow_seconds),
            format!(
                "flow: {:.1} % of 8-bit quantized size; basis images: {:.1}:1 against 16-bit linear; total {:.2} MB",
                100.0 * stats.flow_ratio_vs_8bit,
                stats.image_ratio_vs_16bit,
                bytes as f64 / 1e6
            ),
        ]
        .join("\n"))
    }
}

/// How `frf stage field` starts the line giving the seconds of its hulls and shadow maps
/// ([`OracleWritten::shadow_seconds`]), which `frf report` reads.
pub const SHADOW_TIME_LINE: &str = "visual hulls and shadow maps: ";

/// Writes the oracle field of `stage` to `path`; `progress(done, total)` counts views.
pub fn write_oracle_field(
    stage: &Stage,
    path: &std::path::Path,
    options: &OracleOptions,
    progress: &(dyn Fn(usize, usize) + Sync),
) -> Result<OracleWritten> {
    if let Some(p) = options
        .poses
        .iter()
        .find(|p| !stage.config().poses.contains(p))
    {
        return Err(frf_reflectance::ReflectanceError::NoSuchPose {
            file: Some(path.to_path_buf()),
            within: "capture",
            pose: *p,
            held: frf_reflectance::field::listed(&stage.config().poses),
        }
        .into());
    }
    let capture = Capture::from_manifest(path.parent().unwrap_or(path), stage.manifest())?;
    let (columns, rows) = (stage.cycles(), stage.cameras().len());
    let views: Vec<(u32, usize, usize)> = options
        .poses
        .iter()
        .flat_map(|&p| (0..columns).flat_map(move |u| (0..rows).map(move |v| (p, u, v))))
        .collect();
    let total = 2 * views.len();
    let done = std::sync::atomic::AtomicUsize::new(0);
    let tick = || {
        progress(
            done.fetch_add(1, std::sync::atomic::Ordering::Relaxed) + 1,
            total,
        )
    };
    let mut sorted = options.poses.clone();
    sorted.sort_unstable();
    let pose_flows = |p, u, v| -> Result<[Option<FlowImage>; 2]> {
        if options.pose_flows {
            true_pose_flows(stage, &sorted, p, u, v)
        } else {
            Ok(Default::default())
        }
    };
    // Pass 1: every true flow, to fit the quantizer to the whole field.
    let magnitudes: Vec<Vec<f32>> = views
        .par_iter()
        .map(|&(p, u, v)| {
            let flows = true_flows(stage, p, u, v)?;
            let between = pose_flows(p, u, v)?;
            tick();
            Ok(flows
                .iter()
                .chain(&between)
                .flatten()
                .flat_map(|f| f.pixels().iter().flatten().copied())
                .collect())
        })
        .collect::<Result<_>>()?;
    let quantizer = LogQuantizer::fit(magnitudes.into_iter().flatten());
    let mut header =
        FieldHeader::from_capture(&capture, &options.poses, quantizer, options.jpeg_quality)?;
    header.flow_predicted = options.predict_flow;
    header.shadows = options.shadows.map(|s| s.spec(&header.conditions));
    header.hulls = options.shadows.map(|s| s.hull(capture.cameras()));
    header.description = format!("oracle field (stage ground truth): {}", header.description);
    if options.pose_flows {
        for &p in &options.poses {
            header.record_pose_flows(p, &sorted)?;
        }
    }
    // Pass 2: render and encode views in parallel, write them in order, keeping the true
    // mattes for the hulls.
    let mut writer = FieldWriter::create(path, header.clone())?;
    let mut alphas = Vec::with_capacity(views.len());
    for chunk in views.chunks(rayon::current_num_threads().max(1) * 4) {
        let encoded: Vec<(EncodedView, GrayImage)> = chunk
            .par_iter()
            .map(|&(p, u, v)| {
                let view = oracle_view(stage, p, u, v)?;
                let mut e = encode_view(&header, p, &view)?;
                if options.pose_flows {
                    e.extend(encode_pose_flows(&header, p, &pose_flows(p, u, v)?)?);
                }
                tick();
                Ok((e, view.alpha))
            })
            .collect::<Result<_>>()?;
        for (&(p, u, v), (e, alpha)) in chunk.iter().zip(encoded) {
            writer.add_view(p, u, v, &e)?;
            alphas.push(alpha);
        }
    }
    let shadows_start = std::time::Instant::now();
    if let Some(s) = &options.shadows {
        let per_pose = columns * rows;
        for (i, &pose) in options.poses.iter().enumerate() {
            let cameras: Vec<Camera> = (0..per_pose)
                .map(|j| stage.subject_camera(pose, j / rows, j % rows))
                .collect::<std::result::Result<_, _>>()?;
            let mattes: Vec<&GrayImage> = alphas[i * per_pose..(i + 1) * per_pose].iter().collect();
            let r = pose_shadows(
                &cameras,
                &mattes,
                &header.conditions,
                s.hull(capture.cameras()),
                s,
            )?;
            writer.add_hull(pose, &r.hull)?;
            writer.add_shadows(pose, &r.maps)?;
        }
    }
    let shadow_seconds = shadows_start.elapsed().as_secs_f64();
    writer.finish()?;
    Ok(OracleWritten {
        stats: FieldFile::open(path)?.stats(),
        shadow_seconds,
    })
}
