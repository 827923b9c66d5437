//! A scene's shot judged frame by frame against the virtual stage's truth: the frame the
//! renderer draws (walkers, shadows and backdrop) against the true composite of the same
//! camera, time and lighting.
//!
//! The truth of a frame: the stage's true walkers ([`frf_stage::crowd`]), each where the
//! scene places it at the frame (its position and heading on its path), at the frame's
//! instant of its walk ([`TruthAt::Instant`], the default: its phase as the scene
//! advances it, by time or by the distance walked; between two captured poses the walker
//! is in between, which a render of the nearest pose is not) or at the instant of the
//! pose the plan draws ([`TruthAt::Pose`]: the renderer's view error alone), each lit by
//! the light at it (the scene's environment, or its probes mixed where it stands, with
//! the sun) reduced to median-cut lights, with true occlusion between walkers and their
//! true shadows on each other; the ground's true relative irradiance among all of them
//! under the scene's lighting; both composited over the frame's own backdrop by the
//! product's compositing ([`frf_render::composite::compose`]), so that only the walkers
//! and their shadows differ.
//!
//! Per frame: PSNR of the frame and of the walkers' layer where either covers a pixel,
//! SSIM, and the walkers' alpha against the true coverage as a soft intersection over
//! union, `Σ min(a, â) / Σ max(a, â)`; the same per walker over the pixels where it is the
//! nearest true walker (grown by [`WALKER_MARGIN_PX`], so that a rendered edge beside the
//! true one counts). Over the shot, how far a stance foot slides on the ground
//! ([`foot_slide_cm`]).

use std::path::PathBuf;
use std::time::Instant;

use frf_core::light::DirLight;
use frf_reflectance::FieldFile;
use frf_reflectance::container::ReadAt;
use frf_render::composite::compose;
use frf_render::renderer::Device;
use frf_scene::Scene;
use frf_scene::plan::ShotFrame;
use frf_scene::shot::{Shot, ShotOptions};
use frf_stage::Stage;
use frf_stage::crowd::Walker as TrueWalker;
use frf_stage::ground::relative_irradiance_among;
use serde::{Deserialize, Serialize};

use crate::error::{EvalError, Result};
use crate::metrics::{psnr, ssim, subject_mask};
use frf_core::image::{GrayImage, Image, Rgba};
use frf_core::io::rgba_from;
use frf_core::progress::Progress;

/// Pixels a walker's own pixels are grown by for its scores (see the module docs).
pub const WALKER_MARGIN_PX: usize = 2;

/// A pixel belongs to the walker whose true coverage is at least this share of the
/// pixel's true alpha, where that alpha is at least [`crate::metrics::SUBJECT_ALPHA`].
const OWN_SHARE: f32 = 0.5;

/// Which instant of the walk a frame's truth shows.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
pub enum TruthAt {
    /// The frame's own instant (what a viewer expects to see).
    Instant,
    /// The instant of the captured pose the frame draws (the view's error alone).
    Pose,
}

/// One walker of one frame against its truth.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct WalkerFrameScore {
    /// The pose drawn (the earlier, between two).
    pub pose: u32,
    /// Between two poses: the later and the fraction of the way to it.
    pub between: Option<(u32, f32)>,
    /// The instant of its walk the truth shows, seconds into its cycle.
    pub truth_time_s: f64,
    /// Its pixels (where it is the nearest true walker, grown by [`WALKER_MARGIN_PX`]).
    pub pixels: usize,
    /// PSNR of the walkers' layer over its pixels, dB (`None` without pixels).
    pub psnr_subject: Option<f64>,
    /// Soft alpha IoU over its pixels (`None` without pixels).
    pub alpha_iou: Option<f64>,
}

/// One frame of a shot against its truth.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct ShotFrameScore {
    /// Index in the shot.
    pub index: usize,
    /// Seconds into the shot.
    pub time: f64,
    /// The pose the first walker draws (the earlier, between two).
    pub pose: u32,
    /// Between two poses: the later and the fraction of the way to it (first walker).
    pub between: Option<(u32, f32)>,
    /// The instant of the first walker's walk the truth shows, seconds into its cycle.
    pub truth_time_s: f64,
    /// How far that instant is from the drawn pose's, seconds (wrapped to the nearest
    /// cycle; 0 when the truth is at the pose).
    pub time_from_pose_s: f64,
    /// PSNR of the whole frame (walkers, shadows, backdrop) against the true composite, dB.
    pub psnr_frame: f64,
    /// PSNR of the walkers' layer where it or the truth covers the pixel, dB.
    pub psnr_subject: f64,
    /// SSIM of the walkers' layer over the same pixels.
    pub ssim_subject: f64,
    /// Soft intersection over union of the walkers' alpha with the true coverage.
    pub alpha_iou: f64,
    /// Whether two walkers' true pixels overlap in the frame (one hides part of another).
    pub walkers_overlap: bool,
    /// Where walkers cross: the pixels whose ray meets two true bodies, and the share of
    /// them where the renderer puts the truly nearest in front ([`Occlusion`]).
    pub occlusion: Option<Occlusion>,
    /// Per walker.
    pub walkers: Vec<WalkerFrameScore>,
    /// Seconds the renderer took for the frame (including making its poses resident).
    pub seconds_render: f64,
    /// Seconds the stage took for the true frame (CPU).
    pub seconds_truth: f64,
    /// With `--standing`: the PSNR of the same walker standing at the origin, seen and
    /// lit alike in its own frame ([`standing_twin`]), against the same truth, dB.
    pub psnr_subject_standing: Option<f64>,
}

/// How walkers that cross are ordered at the pixels where they do (see
/// [`ShotFrameScore::occlusion`]).
#[derive(Debug, Clone, Copy, Serialize, Deserialize)]
pub struct Occlusion {
    /// Pixels whose ray (through the pixel's centre) meets two or more true bodies.
    pub pixels: usize,
    /// Share of them where the walker the renderer puts in front (of those the ray
    /// meets, the nearest by its depth there, [`frf_render::proxy::Proxy::depth`]) is the
    /// truly nearest body.
    pub by_depth: f64,
    /// The same for whole walkers put over each other back to front by position (the
    /// order before depth).
    pub by_position: f64,
}

/// Where walkers cross in a frame of `camera` (scene frame): at every pixel whose ray
/// meets two or more of the true bodies `actors` (world frame), whether the renderer's
/// order (by each walker's depth: the nearer of its poses' proxies', `hulls` with its
/// placement) and the order by position put the truly nearest body in front. `None`
/// where no ray meets two.
fn occlusion(
    camera: &frf_core::camera::Camera,
    actors: &[frf_stage::actor::Actor],
    hulls: &[(Vec<frf_render::proxy::Proxy>, frf_scene::Placement)],
) -> Option<Occlusion> {
    let positions: Vec<glam::Vec3> = hulls.iter().map(|h| h.1.position).collect();
    let by_position = frf_render::composite::back_to_front(camera, &positions);
    let (mut pixels, mut depth_right, mut position_right) = (0usize, 0usize, 0usize);
    for y in 0..camera.height {
        for x in 0..camera.width {
            let dir = camera
                .ray_direction(glam::Vec2::new(x as f32, y as f32))
                .normalize();
            let ray = frf_stage::geometry::Ray {
                origin: camera.centre(),
                dir,
            };
            let bodies: Vec<(usize, f32)> = (actors.iter().enumerate())
                .filter_map(|(k, a)| a.intersect(&ray, 0.0, f32::INFINITY).map(|h| (k, h.t)))
                .collect();
            if bodies.len() < 2 {
                continue;
            }
            let nearest =
                |v: &[(usize, f32)]| v.iter().min_by(|a, b| a.1.total_cmp(&b.1)).map(|m| m.0);
            let truth = nearest(&bodies);
            // The renderer orders the walkers that show at the pixel by their depth there.
            let depths: Vec<(usize, f32)> = (bodies.iter())
                .map(|&(k, _)| {
                    let (proxies, placed) = &hulls[k];
                    let there = placed.world_from_subject().inverse();
                    let (o, d) = (there.transform_point(camera.centre()), there.rotation * dir);
                    let depth = proxies
                        .iter()
                        .map(|p| p.depth(o, d))
                        .fold(f32::INFINITY, f32::min);
                    (k, depth)
                })
                .collect();
            pixels += 1;
            depth_right += usize::from(nearest(&depths) == truth);
            // Back to front: the last of the walkers the ray meets goes in front.
            let front = by_position
                .iter()
                .rev()
                .find(|k| bodies.iter().any(|b| b.0 == **k));
            position_right += usize::from(front.copied() == truth);
        }
    }
    (pixels > 0).then(|| Occlusion {
        pixels,
        by_depth: depth_right as f64 / pixels as f64,
        by_position: position_right as f64 / pixels as f64,
    })
}

/// The rendered and the true walkers of a frame (premultiplied RGBA).
type Walkers = (Image<Rgba>, Image<Rgba>);

/// `Σ min / Σ max` of two alphas over the pixels `mask` keeps (all without one); 1 where
/// both are empty.
pub fn soft_iou(a: &[f32], b: &[f32], mask: Option<&[bool]>) -> f64 {
    let (mut inter, mut union) = (0.0f64, 0.0f64);
    for (i, (&x, &y)) in a.iter().zip(b).enumerate() {
        if mask.is_some_and(|m| !m[i]) {
            continue;
        }
        let (x, y) = (x.clamp(0.0, 1.0) as f64, y.clamp(0.0, 1.0) as f64);
        inter += x.min(y);
        union += x.max(y);
    }
    if union > 0.0 { inter / union } else { 1.0 }
}

/// The pixels where walker `k` is the nearest true walker (see the module docs), grown by
/// [`WALKER_MARGIN_PX`].
fn own_pixels(coverage: &[GrayImage], alpha: &GrayImage, k: usize) -> Vec<bool> {
    let (w, h) = alpha.size();
    let own: Vec<bool> = (0..w * h)
        .map(|i| {
            let a = alpha.pixels()[i];
            a >= crate::metrics::SUBJECT_ALPHA && coverage[k].pixels()[i] >= OWN_SHARE * a
        })
        .collect();
    let m = WALKER_MARGIN_PX as isize;
    (0..w * h)
        .map(|i| {
            let (x, y) = ((i % w) as isize, (i / w) as isize);
            (-m..=m).any(|dy| {
                (-m..=m).any(|dx| {
                    let (u, v) = (x + dx, y + dy);
                    u >= 0
                        && v >= 0
                        && (u as usize) < w
                        && (v as usize) < h
                        && own[v as usize * w + u as usize]
                })
            })
        })
        .collect()
}

/// Scores `frame` of `shot` against the truth of `stage` under `lights` median-cut
/// lights of each walker's environment (see the module docs), with the frame's rendered
/// and true walkers, and its rendered and true composites.
fn score_frame_walkers<R: ReadAt>(
    stage: &Stage,
    shot: &mut Shot<'_, R>,
    frame: &ShotFrame,
    lights: usize,
    truth_at: TruthAt,
) -> Result<(ShotFrameScore, Walkers, Walkers)> {
    let scene = shot.scene().clone();
    let gait = shot.plan().gait;
    let cycle = stage.config().gait.cycle_seconds();
    let world = shot.lighting_at(frame.time)?.ok_or_else(|| {
        EvalError::NoTruth("an unlit scene has no true lighting to compare with".into())
    })?;
    let backdrop = shot.backdrop_of(Some(&world))?;

    let t = Instant::now();
    let rendered = shot.render(frame, true)?;
    let seconds_render = t.elapsed().as_secs_f64();
    let layers = rendered
        .frame
        .layers
        .ok_or_else(|| EvalError::Misuse("the renderer returned no layers".into()))?;

    // The truth: every walker where the scene places it, at its instant, lit where it is.
    let t = Instant::now();
    let mut walkers = Vec::with_capacity(scene.instances.len());
    let mut times = Vec::with_capacity(scene.instances.len());
    for i in 0..scene.instances.len() {
        let placement = scene.placement(i, frame.time);
        let env = shot.walker_environment(i, frame.time)?.ok_or_else(|| {
            EvalError::NoTruth("an unlit scene has no true lighting to compare with".into())
        })?;
        let time_s = match truth_at {
            TruthAt::Pose => stage.pose_time_s(rendered.poses[i]),
            TruthAt::Instant => scene.phase_at(i, frame.time, &gait) * cycle,
        };
        times.push(time_s);
        walkers.push(TrueWalker {
            world_from_subject: placement.world_from_subject(),
            time_s,
            lights: env.median_cut(lights),
        });
    }
    let truth = stage.crowd_truth(&frame.camera, &walkers);
    let subject = rgba_from(&truth.color, &truth.alpha)?;
    let actors = stage.crowd_actors(&walkers);
    let ground_lights: Vec<DirLight> = world.median_cut(lights);
    let shadow = |p: glam::Vec3| relative_irradiance_among(&actors, &ground_lights, p);
    let (truth_frame, _) = compose(subject.clone(), &frame.camera, &backdrop, &shadow)?;
    let seconds_truth = t.elapsed().as_secs_f64();

    let mask = subject_mask(&subject, &layers.subject);
    let rendered_alpha: Vec<f32> = layers.subject.pixels().iter().map(|p| p[3]).collect();
    let true_alpha: Vec<f32> = subject.pixels().iter().map(|p| p[3]).collect();
    let own: Vec<Vec<bool>> = (0..walkers.len())
        .map(|k| own_pixels(&truth.coverage, &truth.alpha, k))
        .collect();
    let walkers_overlap = (0..walkers.len()).any(|a| {
        (a + 1..walkers.len()).any(|b| {
            truth.coverage[a]
                .pixels()
                .iter()
                .zip(truth.coverage[b].pixels())
                .any(|(x, y)| *x > 0.01 && *y > 0.01)
        })
    });
    // Where two or more walkers are drawn, each one's proxies (of the pose drawn, and of
    // the later between two) order them as the renderer does.
    let occlusion = if walkers.len() > 1 {
        let hulls = (0..walkers.len())
            .map(|i| {
                let proxy = |pose| {
                    Ok(frf_render::proxy::Proxy::shared(
                        shot.field().hull_shared(pose)?,
                    ))
                };
                let poses = [Some(rendered.poses[i]), rendered.between[i].map(|b| b.0)];
                let proxies = poses
                    .into_iter()
                    .flatten()
                    .map(proxy)
                    .collect::<Result<_>>()?;
                Ok((proxies, scene.placement(i, frame.time)))
            })
            .collect::<Result<Vec<_>>>()?;
        occlusion(&frame.camera, &actors, &hulls)
    } else {
        None
    };
    let per_walker = (0..walkers.len())
        .map(|k| {
            let pixels = own[k].iter().filter(|&&m| m).count();
            WalkerFrameScore {
                pose: rendered.poses[k],
                between: rendered.between[k],
                truth_time_s: times[k],
                pixels,
                psnr_subject: (pixels > 0).then(|| psnr(&subject, &layers.subject, Some(&own[k]))),
                alpha_iou: (pixels > 0)
                    .then(|| soft_iou(&rendered_alpha, &true_alpha, Some(&own[k]))),
            }
        })
        .collect();
    let pose_time = stage.pose_time_s(rendered.poses[0]);
    let time_from_pose_s = {
        let d = (times[0] - pose_time).rem_euclid(cycle);
        let d = if d > 0.5 * cycle { d - cycle } else { d };
        // Rounding at a pose's own instant is no time at all (not -0.0 ms).
        if d.abs() < 1e-9 { 0.0 } else { d }
    };
    let score = ShotFrameScore {
        index: frame.index,
        time: frame.time,
        pose: rendered.poses[0],
        between: rendered.between[0],
        truth_time_s: times[0],
        time_from_pose_s,
        psnr_frame: psnr(&truth_frame, &rendered.frame.composite, None),
        psnr_subject: psnr(&subject, &layers.subject, Some(&mask)),
        ssim_subject: ssim(&subject, &layers.subject, Some(&mask)),
        alpha_iou: soft_iou(&rendered_alpha, &true_alpha, None),
        walkers_overlap,
        occlusion,
        walkers: per_walker,
        seconds_render,
        seconds_truth,
        psnr_subject_standing: None,
    };
    Ok((
        score,
        (layers.subject, subject),
        (rendered.frame.composite, truth_frame),
    ))
}

/// The twin of `scene`'s one walker at `frame` standing still: at the origin facing `+x`,
/// at the same instant of its walk (its phase under `gait`), seen by the frame's camera
/// carried into the walker's frame, lit by the same light turned with it (the lighting
/// keys' yaw, the probes' places and turns), so that it sees the same relative views under
/// the same relative light; one frame at time 0.
pub fn standing_twin(
    scene: &Scene,
    frame: &ShotFrame,
    gait: &frf_scene::Gait,
    stage: &Stage,
) -> Result<(Scene, ShotFrame)> {
    let t = frame.time;
    let placement = scene.placement(0, t);
    let subject_from_world = placement.world_from_subject().inverse();
    let heading = placement.heading;
    let cycle = stage.config().gait.cycle_seconds();
    let mut twin = scene.clone();
    twin.start = 0.0;
    twin.end = 0.0;
    twin.instances = vec![frf_scene::Instance::standing(
        glam::Vec3::ZERO,
        0.0,
        scene.phase_at(0, t, gait) * cycle,
    )];
    // The lighting at t, turned against the heading: one key, or two cross-fading at t's
    // share.
    let l = scene.lighting_at(t);
    let key = |time: f64, env: &frf_core::env::EnvSource| frf_scene::LightKey {
        time,
        env: env.clone(),
        yaw_deg: f64::from(l.yaw - heading).to_degrees(),
        intensity: l.intensity,
    };
    twin.lighting = match l.maps.as_slice() {
        [(env, _)] => vec![key(f64::NEG_INFINITY, env)],
        [(a, _), (b, s)] => vec![
            key(f64::NEG_INFINITY, a),
            key(-f64::from(*s), a),
            key(1.0 - f64::from(*s), b),
        ],
        _ => return Err(EvalError::Misuse("a lighting of no map".into())),
    };
    if let Some(p) = &mut twin.probes {
        for probe in &mut p.probes {
            probe.position = subject_from_world.transform_point(probe.position);
            probe.yaw -= heading;
        }
        let points = p
            .probes
            .iter()
            .map(|q| glam::Vec2::new(q.position.x, q.position.z))
            .collect();
        p.layout = frf_scene::probes::ProbeLayout::new(points)
            .map_err(|(_, e)| EvalError::Misuse(format!("the twin's probes: {e}")))?;
    }
    let camera = placement.camera_in_subject_frame(&frame.camera);
    Ok((
        twin,
        ShotFrame {
            index: 0,
            time: 0.0,
            camera,
        },
    ))
}

/// The most a stance foot slides on the ground over the time range of `scene` (the
/// largest distance, in centimetres, that the stage's own sole point of a foot that is
/// down moves from where it touched down), sampled `rate_hz` times a second, for every
/// walker: each placed where the scene places it and at the instant of its walk the
/// scene's phase gives ([`Scene::phase_at`] with `gait`). A walker on the spot slides by
/// its treadmill's travel over a stance; on a path at the captured speed, by nothing.
pub fn foot_slide_cm(stage: &Stage, scene: &Scene, gait: &frf_scene::Gait, rate_hz: f64) -> f64 {
    let cycle = stage.config().gait.cycle_seconds();
    let steps = (((scene.end - scene.start) * rate_hz).ceil() as usize).max(1);
    let mut worst = 0.0f64;
    for i in 0..scene.instances.len() {
        // Per foot: where it touched down, while it is down.
        let mut planted: [Option<glam::Vec3>; 2] = [None, None];
        for k in 0..=steps {
            let t = scene.start + (scene.end - scene.start) * k as f64 / steps as f64;
            let place = scene.placement(i, t).world_from_subject();
            let feet = stage.feet_at(scene.phase_at(i, t, gait) * cycle);
            for (f, foot) in feet.iter().enumerate() {
                if !foot.down {
                    planted[f] = None;
                    continue;
                }
                let at = place.transform_point(foot.point);
                let first = *planted[f].get_or_insert(at);
                worst = worst.max(at.distance(first) as f64);
            }
        }
    }
    100.0 * worst
}

/// Samples a second of [`foot_slide_cm`] in reports: a 240 Hz clock resolves a foot's
/// slide to under half a centimetre at walking speeds.
pub const FOOT_SLIDE_RATE_HZ: f64 = 240.0;

/// How the walker changes from frame to frame, against how the true walker does: over
/// the pairs of consecutive frames scored, the mean absolute change of its premultiplied
/// RGBA per pixel. A shot that steps from pose to pose changes by nothing, then by a
/// whole pose's step: its largest change is about twice the truth's.
#[derive(Debug, Clone, Copy, Serialize, Deserialize)]
pub struct Steadiness {
    /// Pairs of consecutive frames compared.
    pub pairs: usize,
    /// The rendered walker's largest change between two consecutive frames.
    pub largest_change: f64,
    /// The true walker's largest change.
    pub truth_largest_change: f64,
    /// The first over the second (1: as steady as the truth).
    pub ratio: f64,
}

/// The mean absolute difference per pixel of two images (all channels summed).
fn change(a: &Image<Rgba>, b: &Image<Rgba>) -> f64 {
    let sum: f64 = a
        .pixels()
        .iter()
        .zip(b.pixels())
        .map(|(p, q)| {
            p.iter()
                .zip(q)
                .map(|(x, y)| (x - y).abs() as f64)
                .sum::<f64>()
        })
        .sum();
    sum / a.pixels().len().max(1) as f64
}

/// The steadiness of `frames` (scores and walkers, in shot order): `None` without two
/// consecutive frames.
fn steadiness(frames: &[(ShotFrameScore, Walkers)]) -> Option<Steadiness> {
    let (mut pairs, mut largest, mut truth_largest) = (0, 0.0f64, 0.0f64);
    for w in frames.windows(2) {
        let ((a, (ra, ta)), (b, (rb, tb))) = (&w[0], &w[1]);
        if b.index != a.index + 1 || ra.size() != rb.size() {
            continue;
        }
        pairs += 1;
        largest = largest.max(change(ra, rb));
        truth_largest = truth_largest.max(change(ta, tb));
    }
    (pairs > 0).then(|| Steadiness {
        pairs,
        largest_change: largest,
        truth_largest_change: truth_largest,
        ratio: largest / truth_largest.max(1e-12),
    })
}

/// One walker over the frames scored.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct WalkerSummary {
    /// Mean PSNR over its pixels, dB (`None`: never seen).
    pub psnr_subject_mean: Option<f64>,
    /// Mean soft alpha IoU over its pixels.
    pub alpha_iou_mean: Option<f64>,
    /// The same over the frames where walkers overlap (`None`: none do).
    pub psnr_subject_overlap: Option<f64>,
    /// (See `psnr_subject_overlap`.)
    pub alpha_iou_overlap: Option<f64>,
}

/// The mean of the values given, if any.
fn mean_some(v: impl Iterator<Item = Option<f64>>) -> Option<f64> {
    let v: Vec<f64> = v.flatten().collect();
    (!v.is_empty()).then(|| v.iter().sum::<f64>() / v.len() as f64)
}

/// Memory budget of the poses kept resident while scoring a shot, bytes (a few frames
/// only).
const BUDGET_BYTES: u64 = 4_000_000_000;

/// What `frf eval SCENE.toml --json` prints.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct ShotReport {
    /// The scene file.
    pub scene: PathBuf,
    /// The field rendered.
    pub field: PathBuf,
    /// The capture whose stage gave the truth.
    pub capture: PathBuf,
    /// The renderer's device.
    pub device: String,
    /// Median-cut lights of the truth.
    pub truth_lights: usize,
    /// Which instant the truth shows.
    pub truth_at: TruthAt,
    /// Frames of the shot.
    pub frames_total: usize,
    /// Each frame scored.
    pub frames: Vec<ShotFrameScore>,
    /// Mean PSNR of the whole frames, dB.
    pub psnr_frame_mean: f64,
    /// Mean PSNR of the walker, dB.
    pub psnr_subject_mean: f64,
    /// Mean SSIM of the walker.
    pub ssim_subject_mean: f64,
    /// Mean soft alpha IoU of the walkers against the true coverage.
    pub alpha_iou_mean: f64,
    /// Per walker: its mean PSNR and alpha IoU over its own pixels (frames where it has
    /// some), and over the frames where walkers overlap.
    pub walkers: Vec<WalkerSummary>,
    /// The most a stance foot slides on the ground over the shot, cm ([`foot_slide_cm`]).
    pub foot_slide_cm: f64,
    /// With `--standing`: the mean PSNR of the walker's standing twin ([`standing_twin`])
    /// over the same frames, dB.
    pub psnr_subject_standing_mean: Option<f64>,
    /// Over the frames where walkers cross, every crossing pixel counted once
    /// ([`Occlusion`]); `None` where none cross.
    pub occlusion: Option<Occlusion>,
    /// Mean seconds to render a frame.
    pub seconds_render_mean: f64,
    /// Mean seconds for a true frame.
    pub seconds_truth_mean: f64,
    /// How the walker changes from frame to frame against the truth (consecutive frames
    /// only).
    pub steadiness: Option<Steadiness>,
    /// Seconds in all.
    pub seconds: f64,
}

/// How a shot is scored ([`evaluate_shot`]).
#[derive(Debug, Clone, Copy)]
pub struct ShotEval {
    /// Frames scored, spread evenly over the shot.
    pub frames: usize,
    /// Median-cut lights of the truth.
    pub lights: usize,
    /// Which instant the truth shows.
    pub truth_at: TruthAt,
    /// How far a walker's own light may move before its poses are relit.
    pub light_tolerance: frf_scene::shot::LightTolerance,
    /// Also score, at each frame, the same walker standing at the origin seen by the same
    /// camera and lit by the same light in its own frame ([`standing_twin`]): what a
    /// walker on a path loses against one on the spot (one walker only).
    pub standing: bool,
    /// Render on the CPU reference.
    pub cpu: bool,
    /// Whether walkers shade one another under a sun (`false`: the ablation).
    pub walker_shadows: bool,
}

/// Where `evaluate_shot` writes each scored frame's render and truth, as PNGs
/// (`frame_NNNN.png`, `frame_NNNN_truth.png`), when given.
pub type ShotImages<'a> = Option<&'a std::path::Path>;

/// Scores frames of the shot of `scene` (rendered from `field`, which `paths.1` names)
/// against the truth of `stage` as `how` says; `paths` = (scene file, field, capture)
/// for the report.
pub fn evaluate_shot<R: ReadAt>(
    scene: &Scene,
    field: &FieldFile<R>,
    stage: &Stage,
    (how, images): (&ShotEval, ShotImages),
    paths: (PathBuf, PathBuf, PathBuf),
    progress: &dyn Progress,
) -> Result<ShotReport> {
    let (count, lights, truth_at) = (how.frames, how.lights, how.truth_at);
    if how.standing && scene.instances.len() != 1 {
        return Err(EvalError::Misuse(format!(
            "--standing compares one walker with itself standing, and the scene has {}",
            scene.instances.len()
        )));
    }
    let device = Device::open(how.cpu)?;
    let start = Instant::now();
    let h = field.header();
    let size = scene.size.unwrap_or((h.width, h.height));
    let total = scene.frame_times().len();
    let frames: Vec<ShotFrame> = spread_frames(total, count)
        .into_iter()
        .map(|i| Ok(scene.shot_frames(i..i + 1, size)?[0]))
        .collect::<Result<_>>()?;
    let options = ShotOptions {
        memory_budget: BUDGET_BYTES,
        planned: true,
        traced_lights: lights,
        detail: None,
        light_tolerance: how.light_tolerance,
        walker_shadows: how.walker_shadows,
    };
    let mut shot = Shot::new(scene, field, device, &frames, options)?;
    for f in &shot.plan().frames {
        if let Some(p) = f.poses.iter().find(|p| !stage.config().poses.contains(p)) {
            return Err(EvalError::NoTruth(format!(
                "{}: frame {} draws pose {p}, which the capture did not film",
                paths.2.display(),
                f.index
            )));
        }
    }
    progress.phase("frames scored", frames.len());
    let mut scored = Vec::new();
    for f in &frames {
        let (mut score, walkers, composites) =
            score_frame_walkers(stage, &mut shot, f, lights, truth_at)?;
        if let Some(dir) = images {
            let name = |suffix: &str| dir.join(format!("frame_{:04}{suffix}.png", f.index));
            frf_core::io::write_png8_srgba(&name(""), &composites.0, 1.0)?;
            frf_core::io::write_png8_srgba(&name("_truth"), &composites.1, 1.0)?;
        }
        if how.standing {
            let (twin, twin_frame) = standing_twin(shot.scene(), f, &shot.plan().gait, stage)?;
            let mut twin_shot =
                Shot::new(&twin, field, Device::open(how.cpu)?, &[twin_frame], options)?;
            let r = twin_shot.render(&twin_frame, true)?;
            let layer = r
                .frame
                .layers
                .ok_or_else(|| EvalError::Misuse("the renderer returned no layers".into()))?
                .subject;
            let mask = subject_mask(&walkers.1, &layer);
            score.psnr_subject_standing = Some(psnr(&walkers.1, &layer, Some(&mask)));
        }
        scored.push((score, walkers));
        progress.step();
    }
    progress.finish();
    let steadiness = steadiness(&scored);
    let scores: Vec<ShotFrameScore> = scored.into_iter().map(|(s, _)| s).collect();
    let mean =
        |g: fn(&ShotFrameScore) -> f64| scores.iter().map(g).sum::<f64>() / scores.len() as f64;
    let walkers = (0..scene.instances.len())
        .map(|k| {
            let of = |overlap: bool, g: fn(&WalkerFrameScore) -> Option<f64>| {
                mean_some(
                    (scores.iter())
                        .filter(|s| !overlap || s.walkers_overlap)
                        .map(|s| g(&s.walkers[k])),
                )
            };
            WalkerSummary {
                psnr_subject_mean: of(false, |w| w.psnr_subject),
                alpha_iou_mean: of(false, |w| w.alpha_iou),
                psnr_subject_overlap: of(true, |w| w.psnr_subject),
                alpha_iou_overlap: of(true, |w| w.alpha_iou),
            }
        })
        .collect();
    let foot_slide_cm = foot_slide_cm(stage, shot.scene(), &shot.plan().gait, FOOT_SLIDE_RATE_HZ);
    let (scene_path, field_path, capture) = paths;
    Ok(ShotReport {
        scene: scene_path,
        field: field_path,
        capture,
        device: shot.device(),
        truth_lights: lights,
        truth_at,
        frames_total: total,
        psnr_frame_mean: mean(|s| s.psnr_frame),
        psnr_subject_mean: mean(|s| s.psnr_subject),
        ssim_subject_mean: mean(|s| s.ssim_subject),
        alpha_iou_mean: mean(|s| s.alpha_iou),
        walkers,
        foot_slide_cm,
        psnr_subject_standing_mean: mean_some(scores.iter().map(|s| s.psnr_subject_standing)),
        occlusion: {
            let all: Vec<Occlusion> = scores.iter().filter_map(|s| s.occlusion).collect();
            let pixels: usize = all.iter().map(|o| o.pixels).sum();
            let share = |g: fn(&Occlusion) -> f64| {
                all.iter().map(|o| g(o) * o.pixels as f64).sum::<f64>() / pixels as f64
            };
            (pixels > 0).then(|| Occlusion {
                pixels,
                by_depth: share(|o| o.by_depth),
                by_position: share(|o| o.by_position),
            })
        },
        seconds_render_mean: mean(|s| s.seconds_render),
        seconds_truth_mean: mean(|s| s.seconds_truth),
        frames: scores,
        steadiness,
        seconds: start.elapsed().as_secs_f64(),
    })
}

/// `count` frame indices spread evenly over a shot of `total` frames (first and last
/// included).
pub fn spread_frames(total: usize, count: usize) -> Vec<usize> {
    let count = count.clamp(1, total.max(1));
    if count == 1 {
        return vec![0];
    }
    let mut out: Vec<usize> = (0..count)
        .map(|k| (k * (total - 1) + (count - 1) / 2) / (count - 1))
        .collect();
    out.dedup();
    out
}

impl ShotReport {
    /// The report for a person: a line per frame and their means (`lights`: the truth's
    /// median-cut lights).
    pub fn describe(&self, lights: usize) -> String {
        let mut lines = Vec::new();
        lines.push(format!(
            "{}: {} of {} frames against the stage's truth ({} median-cut lights, the walker at {}), {}",
            self.scene.display(),
            self.frames.len(),
            self.frames_total,
            lights,
            match self.truth_at {
                TruthAt::Instant => "each frame's instant",
                TruthAt::Pose => "the instant of the pose drawn",
            },
            self.device
        ));
        lines.push("frame   time  pose  from pose  PSNR frame  PSNR walker  SSIM walker  alpha IoU  render s  truth s".to_string());
        for s in &self.frames {
            // Between two poses: both, the earlier first.
            let pose = match s.between {
                Some((after, _)) => format!("{}-{after}", s.pose),
                None => s.pose.to_string(),
            };
            lines.push(format!(
                "{:>5} {:>6.2} {:>5} {:>7.1} ms {:>8.2} dB {:>9.2} dB {:>12.4} {:>10.4} {:>9.3} {:>8.2}",
                s.index,
                s.time,
                pose,
                1e3 * s.time_from_pose_s,
                s.psnr_frame,
                s.psnr_subject,
                s.ssim_subject,
                s.alpha_iou,
                s.seconds_render,
                s.seconds_truth
            ));
        }
        lines.push(format!(
            "mean: frame {:.2} dB, walker {:.2} dB (SSIM {:.4}); {:.3} s a frame rendered (first frames make their poses resident), {:.2} s a true frame",
            self.psnr_frame_mean,
            self.psnr_subject_mean,
            self.ssim_subject_mean,
            self.seconds_render_mean,
            self.seconds_truth_mean
        ));
        lines.push(format!(
            "alpha IoU of the walkers against the true coverage: {:.4} (mean); a stance foot slides \
             {:.2} cm at most on the ground",
            self.alpha_iou_mean, self.foot_slide_cm
        ));
        if let Some(o) = &self.occlusion {
            lines.push(format!(
                "where walkers cross ({} pixels): the nearer by depth is the true nearest at \
                 {:.2} %, the nearer by position at {:.2} %",
                o.pixels,
                100.0 * o.by_depth,
                100.0 * o.by_position
            ));
        }
        if let Some(standing) = self.psnr_subject_standing_mean {
            lines.push(format!(
                "the same walker standing, seen and lit alike in its own frame: {standing:.2} dB \
                 (walking {:.2} dB: {:+.2} dB)",
                self.psnr_subject_mean,
                self.psnr_subject_mean - standing
            ));
        }
        if self.walkers.len() > 1 {
            for (k, w) in self.walkers.iter().enumerate() {
                let db = |v: Option<f64>| v.map_or("-".to_string(), |v| format!("{v:.2} dB"));
                let iou = |v: Option<f64>| v.map_or("-".to_string(), |v| format!("{v:.4}"));
                lines.push(format!(
                    "walker {k}: {} (alpha IoU {}) over its pixels; where walkers overlap {} ({})",
                    db(w.psnr_subject_mean),
                    iou(w.alpha_iou_mean),
                    db(w.psnr_subject_overlap),
                    iou(w.alpha_iou_overlap)
                ));
            }
        }
        if let Some(m) = &self.steadiness {
            lines.push(format!(
                "motion: the walker's largest change between consecutive frames {:.5} (mean |ΔRGBA| a pixel), \
                 the truth's {:.5}: {:.2}x ({} pairs)",
                m.largest_change, m.truth_largest_change, m.ratio, m.pairs
            ));
        }
        lines.join("\n")
    }
}

#[cfg(test)]
mod tests {
    use super::spread_frames;

    #[test]
    fn spread_frames_cover_the_shot_without_repeats() {
        assert_eq!(spread_frames(20, 4), vec![0, 6, 13, 19]);
        assert_eq!(spread_frames(3, 10), vec![0, 1, 2]);
        assert_eq!(spread_frames(1, 3), vec![0]);
        assert_eq!(spread_frames(10, 1), vec![0]);
    }
}
