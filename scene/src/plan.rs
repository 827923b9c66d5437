//! What a scene needs from a field, computed from the scene and the field's index alone,
//! before anything is read or drawn; the renderer then reads, relits and draws only that.
//!
//! - **Poses**: the poses the walkers show at the frames rendered (the nearest pose the
//!   field holds stands in for one it lacks, and the plan says so).
//! - **Views and flows**, per walker: the quads of the grid reached by the camera's rays
//!   that may see the walker (that pass through its pose's bounds,
//!   [`SubjectBounds::of_pose`]: a ray that misses them shows nothing of it), traced
//!   through the cylinder of the pose's camera centres over the box where the camera
//!   sees those bounds: at every pixel of a small box (the frame pass traces pixel
//!   centres alone, so their quads are all it reads, with the quad across a side a hit
//!   lies near), and every [`RAY_STEP_PX`] pixels of a larger one, each quad hit grown by
//!   its neighbours so that a ray between two samples is covered ([`EXACT_PIXELS`]). A
//!   quad needs its four views and the eight flows between them. Each walker is made
//!   resident with its own needs; the field must provide every walker's together.
//! - **Conditions**: a basis condition whose coefficient is zero at every frame is not
//!   relit. Turned by any yaw, heading or turntable angle, a condition's region of the
//!   sphere stays in its band of elevations; so it is left out when every environment of
//!   the scene is black over that band (e.g. the floor conditions under a black lower
//!   hemisphere), or when the scene's intensity is zero throughout.
//! - **Probes**: a light probe no walker stands near at any frame (weight 0 wherever they
//!   are, [`crate::probes`]) is not loaded; the others are.
//! - **Shadows**: the maps only when the scene asks for a shadow and some ray meets the
//!   ground patch. The visual hull (a few kilobytes) is always read when the field holds
//!   it: it is the renderer's proxy for rays beyond the grid's rows, and traced shadows'.
//!
//! The plan is conservative: no frame may need something it left out (a test renders
//! scenes with and without the plan and compares the frames).

use std::collections::btree_map::Entry;
use std::collections::{BTreeMap, BTreeSet};

use frf_core::BadArgument;
use frf_core::camera::Camera;
use frf_core::env::EnvMap;
use frf_core::grid::{Neighbour, PoseStep};
use frf_core::manifest::FilmedSpec;
use frf_reflectance::container::{ChunkKind, ReadAt};
use frf_reflectance::project::{FloorModel, Projector};
use frf_reflectance::{FieldFile, FieldHeader, ReflectanceError};
use glam::{Vec2, Vec3};
use serde::Serialize;

pub use frf_render::pose_plan::PosePlan;

use super::{Gait, Scene, ShadowSpec, TimeInterpolation};
use crate::error::{Result, SceneError};
use frf_render::cylinder::Cylinder;
use frf_render::detail::detail_level;
pub use frf_render::footprint::{SUBJECT_HEIGHTS_M, SUBJECT_RADIUS_M};
use frf_render::footprint::{SubjectBounds, captured_ppm, pixels_per_metre};
use frf_render::shadow::ground_hit;

/// Spacing of the rays traced to find the quads a frame reaches, pixels, over a box of
/// more than [`EXACT_PIXELS`].
pub const RAY_STEP_PX: u32 = 4;

/// A box of at most this many pixels is traced at every pixel: the frame pass traces
/// pixel centres alone, so the quads those rays hit are all it reads (with the neighbour
/// across a side a hit lies within [`EDGE`] of, where the GPU's arithmetic may round the
/// other way); a larger box is sampled every [`RAY_STEP_PX`] and every hit grown by its
/// eight neighbours.
pub const EXACT_PIXELS: usize = 128 * 128;

/// Fraction of a quad's side within which a hit also needs the quad across it
/// ([`EXACT_PIXELS`]).
pub const EDGE: f32 = 0.02;

/// One frame: its time and the pose each walker shows.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FramePlan {
    /// Index in the scene's frames.
    pub index: usize,
    /// Seconds.
    pub time: f64,
    /// Per instance: the pose drawn (the earlier of two between poses).
    pub poses: Vec<u32>,
    /// Per instance, between two poses: the later pose and the fraction of the way to it
    /// ([`frf_render::motion`]).
    pub between: Vec<Option<(u32, f32)>>,
}

impl FramePlan {
    /// Frame `index` at `time` of `scene` on a field of header `h` holding `field_poses`
    /// (sorted) whose walk is `gait`: each walker's pose, the nearest held, or, morphing
    /// in time, the held poses around its instant ([`poses_around`]).
    pub fn at(
        scene: &Scene,
        h: &FieldHeader,
        field_poses: &[u32],
        (interpolate, gait): (TimeInterpolation, &Gait),
        (index, time): (usize, f64),
    ) -> Self {
        let (poses, between) = (0..scene.instances.len())
            .map(|i| match interpolate {
                TimeInterpolation::Nearest => {
                    let wanted = scene.pose_at(i, time, gait, h.poses_per_cycle);
                    (nearest_pose(wanted, field_poses, h.poses_per_cycle), None)
                }
                TimeInterpolation::Flow => {
                    let at = scene.phase_at(i, time, gait) * h.poses_per_cycle.max(1) as f64;
                    poses_around(at, field_poses, h.poses_per_cycle)
                }
            })
            .unzip();
        Self {
            index,
            time,
            poses,
            between,
        }
    }
}

/// The counts a person reads (and `frf render --plan --json` prints).
#[derive(Debug, Clone, Default, PartialEq, Eq, Serialize)]
pub struct PlanCounts {
    /// Poses the frames draw.
    pub poses_used: usize,
    /// Poses the field holds.
    pub poses_total: usize,
    /// Views read, over the poses used.
    pub views_used: usize,
    /// Views the poses used hold.
    pub views_total: usize,
    /// Flow maps read.
    pub flows_used: usize,
    /// Flow maps the poses used hold.
    pub flows_total: usize,
    /// Pose-to-pose flow maps read (for frames between poses).
    pub pose_flows_used: usize,
    /// Basis conditions relit.
    pub conditions_used: usize,
    /// Basis conditions of the field.
    pub conditions_total: usize,
    /// Bytes of the chunks read.
    pub bytes_read: u64,
    /// Bytes of every chunk of the field.
    pub bytes_total: u64,
}

/// What one walker draws: the poses, and of them the views and flows its own rays reach
/// (summed over its poses).
#[derive(Debug, Clone, Default, PartialEq, Eq, Serialize)]
pub struct WalkerCounts {
    /// Poses it draws.
    pub poses: Vec<u32>,
    /// Views made resident for it, over its poses.
    pub views: usize,
    /// Flow maps made resident for it, over its poses.
    pub flows: usize,
    /// Per pose: its level of detail ([`frf_render::detail`]).
    pub levels: Vec<u8>,
    /// Per pose: the level its shadow maps are relit at.
    pub shadow_levels: Vec<u8>,
}

impl WalkerCounts {
    fn of(plans: &[PosePlan]) -> Self {
        Self {
            poses: plans.iter().map(|p| p.pose).collect(),
            views: plans
                .iter()
                .map(|p| p.views.iter().filter(|&&v| v).count())
                .sum(),
            flows: plans
                .iter()
                .map(|p| p.flows.iter().flatten().filter(|&&f| f).count())
                .sum(),
            levels: plans.iter().map(|p| p.level).collect(),
            shadow_levels: plans.iter().map(|p| p.shadow_level).collect(),
        }
    }
}

/// The plan of a scene on a field (see the module docs).
#[derive(Debug, Clone, Serialize)]
pub struct Plan {
    /// The counts.
    #[serde(flatten)]
    pub counts: PlanCounts,
    /// Per frame rendered.
    pub frames: Vec<FramePlan>,
    /// Per pose used: what the field must provide (every walker's needs together).
    pub poses: Vec<PosePlan>,
    /// Per walker, per pose it draws: what its own rays reach, which is all its poses
    /// are made resident with.
    #[serde(skip)]
    pub walkers: Vec<Vec<PosePlan>>,
    /// Per walker: what it reads and draws.
    pub walker_counts: Vec<WalkerCounts>,
    /// Poses the scene asks for that the field lacks, and the pose drawn instead.
    pub poses_substituted: Vec<(u32, u32)>,
    /// Conditions left out, by name.
    pub conditions_left_out: Vec<String>,
    /// Floor conditions among them.
    pub floor_conditions_left_out: usize,
    /// Whether some frame sees the ground patch (a shadow is drawn).
    pub ground_seen: bool,
    /// Per light probe of the scene: whether some walker is lit by it at some frame
    /// (the others are not loaded).
    pub probes_used: Vec<bool>,
    /// What frames between captured poses show.
    pub interpolate: TimeInterpolation,
    /// The field's walk: how walkers on paths advance their phase.
    pub gait: Gait,
}

/// The plan of `pose` in `plans`, added (needing nothing yet) when absent.
fn entry<'p>(
    plans: &'p mut Vec<PosePlan>,
    pose: u32,
    views: usize,
    lit: &[bool],
) -> &'p mut PosePlan {
    match plans.iter().position(|p| p.pose == pose) {
        Some(k) => &mut plans[k],
        None => {
            plans.push(PosePlan {
                pose,
                views: vec![false; views],
                flows: vec![[false; 4]; views],
                conditions: lit.to_vec(),
                shadow_maps: false,
                hull: false,
                pose_flows: [false; 2],
                level: u8::MAX,
                shadow_level: u8::MAX,
                bounds: SubjectBounds::DESIGN,
            });
            plans.last_mut().expect("just pushed")
        }
    }
}

/// Fractions of a pose's step this close to a pose draw that pose alone.
const AT_POSE: f64 = 1e-3;

/// The pose `field_poses` (sorted) holds at or before the continuous pose `at` (a phase
/// of the cycle times its `n` poses), going round the cycle, and, unless `at` falls on
/// it, the next pose held with the fraction of the way to it.
pub(crate) fn poses_around(at: f64, field_poses: &[u32], n: u32) -> (u32, Option<(u32, f32)>) {
    let n = n.max(1) as f64;
    let before = field_poses
        .iter()
        .rev()
        .find(|&&p| p as f64 <= at)
        .or(field_poses.last())
        .copied()
        .expect("a field holds at least one pose");
    let after = field_poses
        .iter()
        .find(|&&p| p > before)
        .or(field_poses.first())
        .copied()
        .expect("a field holds at least one pose");
    let gap = (after as f64 - before as f64).rem_euclid(n);
    if field_poses.len() < 2 || gap == 0.0 {
        return (before, None);
    }
    let s = (at - before as f64).rem_euclid(n) / gap;
    if s < AT_POSE {
        (before, None)
    } else if s > 1.0 - AT_POSE {
        (after, None)
    } else {
        (before, Some((after, s as f32)))
    }
}

/// The nearest pose `field_poses` holds to `wanted`, going round the cycle of `n` poses.
pub(crate) fn nearest_pose(wanted: u32, field_poses: &[u32], n: u32) -> u32 {
    *field_poses
        .iter()
        .min_by_key(|&&p| {
            let d = p.abs_diff(wanted);
            d.min(n.max(1) - d.min(n.max(1)))
        })
        .expect("a field holds at least one pose")
}

/// Every `step`-th of `lo..=hi`, and `hi`.
fn samples(lo: u32, hi: u32, step: u32) -> Vec<u32> {
    let mut v: Vec<u32> = (lo..=hi).step_by(step.max(1) as usize).collect();
    if v.last() != Some(&hi) {
        v.push(hi);
    }
    v
}

/// The quads `(u, v)` of `cylinder` (neighbours' columns taken round its spans) that
/// the rays of `camera` that may see the subject (that pass through its `bounds`) reach,
/// traced over the box where the camera sees the bounds: at every pixel of a box of at
/// most [`EXACT_PIXELS`], each hit with the quad across a side it lies within [`EDGE`]
/// of; else every [`RAY_STEP_PX`] pixels (finer for a thin box) and along its border,
/// each hit grown by its eight neighbours, so that a ray between two
/// samples, which meets the cylinder between their quads, is covered. Rays clamped above
/// or below the grid keep the top or bottom row's quads. And whether a ray of the whole
/// frame (sampled every [`RAY_STEP_PX`]) meets the ground within `ground_half` metres of
/// the subject's axis (in the same frame).
fn reached(
    cylinder: &Cylinder,
    camera: &Camera,
    bounds: &SubjectBounds,
    ground_half: f32,
) -> (BTreeSet<(usize, usize)>, bool) {
    let (w, h) = (camera.width, camera.height);
    let spans = cylinder.spans().max(1);
    let quad_rows = cylinder.rows().saturating_sub(1).max(1);
    let mut quads = BTreeSet::new();
    if let Some(b) = bounds.pixel_box(camera) {
        let (x0, y0, x1, y1) = (b.x0, b.y0, b.x1 - 1, b.y1 - 1);
        let exact = b.pixels() <= EXACT_PIXELS;
        let step = if exact {
            1
        } else {
            ((x1 - x0).min(y1 - y0) / 8).clamp(1, RAY_STEP_PX)
        };
        const ALL: &[isize] = &[-1, 0, 1];
        // The offsets to the quads across the sides `f` (a fraction of the quad) is near.
        let near = |f: f32| -> &'static [isize] {
            if f < EDGE {
                &[-1, 0]
            } else if f > 1.0 - EDGE {
                &[0, 1]
            } else {
                &[0]
            }
        };
        for &y in &samples(y0, y1, step) {
            for &x in &samples(x0, x1, step) {
                let dir = camera.ray_direction(Vec2::new(x as f32, y as f32));
                if !bounds.may_see(camera.centre(), dir) {
                    continue;
                }
                let Some(hit) = cylinder.intersect(camera.centre(), dir) else {
                    continue;
                };
                let v = hit.v.min(quad_rows - 1);
                let (dus, dvs) = if exact {
                    (near(hit.beta), near(hit.gamma))
                } else {
                    (ALL, ALL)
                };
                for &du in dus {
                    let u = (hit.u as isize + du).rem_euclid(spans as isize) as usize;
                    for &dv in dvs {
                        let v = (v as isize + dv).clamp(0, quad_rows as isize - 1) as usize;
                        quads.insert((u, v));
                    }
                }
            }
        }
    }
    let mut ground = false;
    for &y in &samples(0, h - 1, RAY_STEP_PX) {
        for &x in &samples(0, w - 1, RAY_STEP_PX) {
            let dir = camera.ray_direction(Vec2::new(x as f32, y as f32));
            if let Some(p) = ground_hit(camera.centre(), dir) {
                ground |= p.x.abs() <= ground_half && p.z.abs() <= ground_half;
            }
        }
    }
    (quads, ground)
}

/// Per probe of `scene`, whether some walker stands where it weighs at one of `frames`.
fn probes_used(scene: &Scene, frames: &[ShotFrame]) -> Vec<bool> {
    let Some(p) = &scene.probes else {
        return Vec::new();
    };
    let mut used = vec![false; p.probes.len()];
    for f in frames {
        for i in 0..scene.instances.len() {
            for (k, w) in scene.probe_weights(i, f.time) {
                used[k] |= w > 0.0;
            }
        }
    }
    used
}

/// Which conditions the scene can light (see the module docs).
fn lit_conditions(
    scene: &Scene,
    projector: &Projector,
    conditions: &[frf_reflectance::field::ConditionRecord],
) -> Result<Vec<bool>> {
    if scene.lighting.iter().all(|k| k.intensity == 0.0) {
        return Ok(vec![false; conditions.len()]);
    }
    let mut lit = vec![false; conditions.len()];
    let bands = projector.elevation_bands();
    for source in scene.environments() {
        let Some(env) = source.load()? else {
            // No relighting: every condition shows at weight 1.
            return Ok(vec![true; conditions.len()]);
        };
        let rows = nonzero_rows(&env);
        let upper_lit = rows
            .iter()
            .any(|&(lo, hi)| hi > 0.0 && lo < std::f32::consts::FRAC_PI_2);
        for (k, c) in conditions.iter().enumerate() {
            lit[k] |= if c.floor && matches!(scene.floor, FloorModel::LambertianGround { .. }) {
                upper_lit
            } else {
                let (lo, hi) = bands[k];
                rows.iter().any(|&(a, b)| a < hi && b > lo)
            };
        }
    }
    Ok(lit)
}

/// The elevation bands (radians) of the environment's rows holding any light.
fn nonzero_rows(env: &EnvMap) -> Vec<(f32, f32)> {
    let img = env.image();
    let h = img.height() as f32;
    (0..img.height())
        .filter(|&y| img.row(y).iter().any(|p| p.iter().any(|&c| c > 0.0)))
        .map(|y| {
            let top = std::f32::consts::FRAC_PI_2 - y as f32 / h * std::f32::consts::PI;
            let bottom = std::f32::consts::FRAC_PI_2 - (y + 1) as f32 / h * std::f32::consts::PI;
            (bottom, top)
        })
        .collect()
}

/// The flows a quad with corners `A = (u, v)`, `B = (u+1, v)`, `C = (u, v+1)`,
/// `D = (u+1, v+1)` reads: `(view, neighbour)` pairs (the rows clamped to the grid).
fn quad_flows(u: usize, v: usize, columns: usize, rows: usize) -> Vec<((usize, usize), Neighbour)> {
    let (u1, v1) = ((u + 1) % columns, (v + 1).min(rows - 1));
    let mut out = vec![((u, v), Neighbour::Right), ((u1, v), Neighbour::Left)];
    if v1 != v {
        out.extend([
            ((u, v), Neighbour::Up),
            ((u, v1), Neighbour::Down),
            ((u1, v), Neighbour::Up),
            ((u1, v1), Neighbour::Down),
            ((u, v1), Neighbour::Right),
            ((u1, v1), Neighbour::Left),
        ]);
    }
    out
}

/// One frame to render: its index in the shot, its time (seconds) and its camera
/// (scene frame).
#[derive(Debug, Clone, Copy)]
pub struct ShotFrame {
    /// Index in the shot.
    pub index: usize,
    /// Seconds.
    pub time: f64,
    /// The camera.
    pub camera: Camera,
}

/// The frames `spec` names of a shot of `total` (`--frames`): `N` (frames 0 to N − 1)
/// or `A..B`; all of them when absent.
pub fn frame_range(spec: Option<&str>, total: usize) -> Result<std::ops::Range<usize>> {
    let Some(s) = spec else {
        return Ok(0..total);
    };
    let bad = || {
        let allowed = format!("N or A..B within the shot's {total} frames");
        SceneError::from(BadArgument::new("--frames", format!("{s:?}"), allowed))
    };
    let range = match s.split_once("..") {
        Some((a, b)) => {
            let a: usize = a.trim().parse().map_err(|_| bad())?;
            let b: usize = b.trim().parse().map_err(|_| bad())?;
            a..b
        }
        None => 0..s.trim().parse::<usize>().map_err(|_| bad())?,
    };
    if range.start >= range.end || range.end > total {
        return Err(bad());
    }
    Ok(range)
}

/// The largest patch of shadow maps sized for a scene's lighting, metres: a sun a few
/// degrees high would ask for tens of metres.
pub const MAX_SCENE_PATCH_M: f32 = 12.0;

impl Scene {
    /// The side of the patch of shadow maps (metres, at most [`MAX_SCENE_PATCH_M`])
    /// that holds the shadow of a standing person under the lowest shadow-making light of
    /// the scene's lighting keys, and that light's elevation (degrees); `None` when
    /// nothing lights the ground from above.
    pub fn shadow_patch(&self) -> Result<Option<(f32, f32)>> {
        use frf_render::shadow_reach::{
            NOMINAL_SUBJECT, lowest_shadow_light_elevation, patch_side_holding, shadow_reach,
        };
        let mut envs = Vec::new();
        for env in self.environments() {
            envs.extend(env.load()?);
        }
        Ok(lowest_shadow_light_elevation(&envs).map(|e| {
            let side = patch_side_holding(shadow_reach(e, NOMINAL_SUBJECT));
            (side.min(MAX_SCENE_PATCH_M), e.to_degrees())
        }))
    }

    /// The frames `range` of the scene (indices into [`Scene::frame_times`]), of `size`.
    pub fn shot_frames(
        &self,
        range: std::ops::Range<usize>,
        size: (u32, u32),
    ) -> Result<Vec<ShotFrame>> {
        let times = self.frame_times();
        if range.start >= range.end || range.end > times.len() {
            return Err(BadArgument::new(
                "--frames",
                format!("{}..{}", range.start, range.end),
                format!("frames within 0..{} of this scene", times.len()),
            )
            .into());
        }
        range
            .map(|index| {
                Ok(ShotFrame {
                    index,
                    time: times[index],
                    camera: self.camera_at(times[index], size)?,
                })
            })
            .collect()
    }
}

/// Every [`HULL_RING_STEP`]-th column of the middle row is filmed and ingested for a
/// scene that draws a shadow, whether its camera sees them or not: the visual hull the
/// shadow maps are traced from needs silhouettes from all around. Measured on the demo
/// scene (small preset, 10 poses), hull IoU against the true body: 0.57 from the 29
/// views per pose a wider camera move reached alone, 0.79 with a ring every 40 degrees
/// (0.84 from all 108 views).
pub const HULL_RING_STEP: usize = 6;

impl Plan {
    /// What filming or ingesting a capture for `scene` must keep (`frf stage --for`,
    /// `frf ingest --for`): the plan of every frame of the shot, at the scene's size or
    /// `image_size`, on the field `header` the capture would make, with the hull's ring of
    /// views ([`HULL_RING_STEP`]) when the scene draws a shadow the camera sees.
    pub fn for_capture(
        scene: &Scene,
        header: &FieldHeader,
        image_size: (u32, u32),
    ) -> Result<Self> {
        let size = scene.size.unwrap_or(image_size);
        let frames = scene.shot_frames(0..scene.frame_times().len(), size)?;
        let interpolate = scene.interpolate.unwrap_or(TimeInterpolation::Nearest);
        // No hull yet: the design's bounds.
        let gait = Gait::new(header.cycle_seconds, header.gait_speed_mps);
        let projector = Projector::new(&header.conditions)?;
        let mut plan = Self::from_header(
            scene,
            (header, &projector),
            &frames,
            (interpolate, gait),
            &mut |_| Ok(None),
        )?;
        if plan.ground_seen && scene.shadow != ShadowSpec::None {
            let (columns, rows) = (header.columns, header.rows);
            for p in &mut plan.poses {
                for u in (0..columns).step_by(HULL_RING_STEP) {
                    p.views[u * rows + rows / 2] = true;
                }
            }
            plan.counts.views_used = plan
                .poses
                .iter()
                .map(|p| p.views.iter().filter(|&&v| v).count())
                .sum();
        }
        Ok(plan)
    }

    /// The views the plan keeps, per pose, as a capture manifest lists what was filmed
    /// (`rows` cameras per column).
    pub fn filmed(&self, rows: usize) -> Vec<FilmedSpec> {
        self.poses
            .iter()
            .map(|p| FilmedSpec {
                pose: p.pose,
                views: p
                    .views
                    .iter()
                    .enumerate()
                    .filter(|(_, v)| **v)
                    .map(|(i, _)| [(i / rows) as u32, (i % rows) as u32])
                    .collect(),
            })
            .collect()
    }

    /// A line for people: what the plan keeps.
    pub fn summary(&self) -> String {
        let c = &self.counts;
        let between = match self.interpolate {
            TimeInterpolation::Flow
                if self
                    .frames
                    .iter()
                    .any(|f| f.between.iter().any(Option::is_some)) =>
            {
                format!(
                    ", {} pose-to-pose flows (frames between poses morphed in time)",
                    c.pose_flows_used
                )
            }
            _ => String::new(),
        };
        format!(
            "for the scene: {} of {} poses ({:?}), {} of {} views, {} flows{between}",
            c.poses_used,
            c.poses_total,
            self.poses.iter().map(|p| p.pose).collect::<Vec<_>>(),
            c.views_used,
            c.views_total,
            c.flows_used
        )
    }

    /// The plan of `scene` on `field` for `frames`, with the bytes it reads.
    pub fn new<R: ReadAt>(
        scene: &Scene,
        field: &FieldFile<R>,
        frames: &[ShotFrame],
    ) -> Result<Self> {
        let holds_pose_flows = field
            .chunks()
            .any(|c| matches!(c.key.kind, ChunkKind::PoseFlow(_)));
        let interpolate = match scene.interpolate {
            Some(TimeInterpolation::Flow) if !holds_pose_flows => {
                return Err(SceneError::FieldLacks {
                    field: field.path().to_path_buf(),
                    problem: "the scene morphs between poses (time.interpolate = \"flow\") and \
                              the field holds no pose-to-pose flow: ingest with --pose-flow, or \
                              set interpolate = \"nearest\""
                        .into(),
                });
            }
            Some(i) => i,
            None if holds_pose_flows => TimeInterpolation::Flow,
            None => TimeInterpolation::Nearest,
        };
        let mut hull_box = |pose| {
            Ok(match field.header().hulls {
                Some(_) => field.hull_shared(pose)?.and_then(|h| h.bounds()),
                None => None,
            })
        };
        if interpolate == TimeInterpolation::Flow {
            field
                .header()
                .check_pose_flows()
                .map_err(|(_, problem)| SceneError::FieldLacks {
                    field: field.path().to_path_buf(),
                    problem: format!(
                        "{problem}; or draw the nearest pose (time.interpolate = \"nearest\")"
                    ),
                })?;
        }
        let gait = Gait::of_field(field)?;
        let mut plan = Self::from_header(
            scene,
            (field.header(), field.projector()?),
            frames,
            (interpolate, gait),
            &mut hull_box,
        )?;
        let rows = field.header().rows;
        let counts = &mut plan.counts;
        (counts.views_used, counts.views_total, counts.flows_used) = (0, 0, 0);
        counts.pose_flows_used = 0;
        let mut held = BTreeSet::new();
        for c in field.chunks() {
            if c.key.kind == ChunkKind::Basis {
                held.insert((c.key.pose, c.key.u as usize, c.key.v as usize));
            }
            counts.bytes_total += c.length;
            let Some(p) = plan.poses.iter().find(|p| p.pose == c.key.pose) else {
                continue;
            };
            let view = c.key.u as usize * rows + c.key.v as usize;
            let used = match c.key.kind {
                ChunkKind::Basis => {
                    counts.views_total += 1;
                    let used = p.views.get(view).copied().unwrap_or(false);
                    counts.views_used += used as usize;
                    used
                }
                ChunkKind::Alpha | ChunkKind::Normals => {
                    p.views.get(view).copied().unwrap_or(false)
                }
                ChunkKind::Flow(n) => {
                    counts.flows_total += 1;
                    let used = p.flows.get(view).is_some_and(|f| f[n.index()]);
                    counts.flows_used += used as usize;
                    used
                }
                ChunkKind::PoseFlow(step) => {
                    let used =
                        p.pose_flows[step.index()] && p.views.get(view).copied().unwrap_or(false);
                    counts.pose_flows_used += used as usize;
                    used
                }
                ChunkKind::Shadows => p.shadow_maps,
                ChunkKind::Hull => p.hull,
            };
            if used {
                counts.bytes_read += c.length;
            }
        }
        plan.check_views_held(field.path(), rows, &held)?;
        plan.check_pose_flows_held(field)?;
        Ok(plan)
    }

    /// An error naming the first pose whose motion toward the next or previous pose the
    /// frames between poses need and the field lacks altogether (its part merged without
    /// `--pose-flow`, before merge refused that), before anything is rendered.
    fn check_pose_flows_held<R: ReadAt>(&self, field: &FieldFile<R>) -> Result<()> {
        for p in &self.poses {
            for step in PoseStep::ALL {
                let holds = field
                    .chunks()
                    .any(|c| c.key.pose == p.pose && c.key.kind == ChunkKind::PoseFlow(step));
                if p.pose_flows[step.index()] && !holds {
                    return Err(SceneError::FieldLacks {
                        field: field.path().to_path_buf(),
                        problem: format!(
                            "frames between poses need pose {}'s motion {}, and the field holds \
                         none for it (was its part ingested without --pose-flow?): ingest pose {} \
                         with --pose-flow and merge again, or draw the nearest pose \
                         (time.interpolate = \"nearest\")",
                            p.pose,
                            step.name(),
                            p.pose
                        ),
                    });
                }
            }
        }
        Ok(())
    }

    /// An error naming the views the frames need that the field lacks (a field made for
    /// another scene, `frf ingest --for`), before anything is rendered or written.
    fn check_views_held(
        &self,
        field: &std::path::Path,
        rows: usize,
        held: &BTreeSet<(u32, usize, usize)>,
    ) -> Result<()> {
        let (mut missing, mut needed) = (Vec::new(), 0);
        for p in &self.poses {
            for (i, _) in p.views.iter().enumerate().filter(|(_, needed)| **needed) {
                needed += 1;
                let (u, v) = (i / rows, i % rows);
                if !held.contains(&(p.pose, u, v)) {
                    missing.push((p.pose, u, v));
                }
            }
        }
        if missing.is_empty() {
            return Ok(());
        }
        let listed: Vec<String> = missing
            .iter()
            .take(8)
            .map(|(p, u, v)| format!("pose {p} view ({u}, {v})"))
            .collect();
        Err(SceneError::FieldLacks {
            field: field.to_path_buf(),
            problem: format!(
                "lacks {} of the {} views the frames need ({}{}): it was made for another \
             scene or camera (frf ingest --for); film and ingest these views (frf stage --for, \
             frf ingest --for this scene) or render from a field that holds them",
                missing.len(),
                needed,
                listed.join(", "),
                if missing.len() > listed.len() {
                    ", ..."
                } else {
                    ""
                }
            ),
        })
    }

    /// The plan of `scene` on a field (or a capture) with `h`'s grid, cameras, basis and
    /// poses (and `projector`, its basis's) and the walk `gait`, for `frames`, frames between poses drawn as
    /// `interpolate` says, each pose's
    /// subject within the bounds of the hull box `hull_box` gives
    /// ([`SubjectBounds::of_pose`]); the counts of views and flows are those the plan asks
    /// for (no chunk is known, so no byte either).
    pub fn from_header(
        scene: &Scene,
        (h, projector): (&FieldHeader, &Projector),
        frames: &[ShotFrame],
        (interpolate, gait): (TimeInterpolation, Gait),
        hull_box: &mut dyn FnMut(u32) -> Result<Option<(Vec3, Vec3)>>,
    ) -> Result<Self> {
        if frames.is_empty() {
            return Err(SceneError::Misuse("a shot of no frame"));
        }
        let (frame_plans, substituted) = frame_plans(scene, h, frames, (interpolate, &gait));
        let views = h.columns * h.rows;
        let lit = lit_conditions(scene, projector, &h.conditions)?;
        let traced = Traced {
            scene,
            h,
            lit: &lit,
        };
        let (mut walkers, ground_seen) = traced.walkers(&frame_plans, frames, hull_box)?;
        // Every walker's plans together: what the field must provide for the shot.
        let mut poses = union_of(&walkers, views, &lit);
        let wants_shadow = ground_seen && scene.shadow != ShadowSpec::None;
        for p in poses.iter_mut().chain(walkers.iter_mut().flatten()) {
            p.shadow_maps = wants_shadow && scene.shadow == ShadowSpec::Maps && h.shadows.is_some();
            // The hull is the proxy of rays beyond the grid's rows, and traced shadows'.
            p.hull = h.hulls.is_some();
        }
        poses.sort_by_key(|p| p.pose);
        for w in &mut walkers {
            w.sort_by_key(|p| p.pose);
        }
        let counts = PlanCounts::of(&poses, h, &lit);
        let left_out: Vec<usize> = (0..lit.len()).filter(|&k| !lit[k]).collect();
        Ok(Self {
            counts,
            frames: frame_plans,
            poses,
            walker_counts: walkers.iter().map(|w| WalkerCounts::of(w)).collect(),
            walkers,
            poses_substituted: substituted.into_iter().collect(),
            conditions_left_out: left_out
                .iter()
                .map(|&k| h.conditions[k].name.clone())
                .collect(),
            floor_conditions_left_out: left_out.iter().filter(|&&k| h.conditions[k].floor).count(),
            ground_seen,
            probes_used: probes_used(scene, frames),
            interpolate,
            gait,
        })
    }

    /// The plan of pose `pose`.
    pub fn pose(&self, pose: u32) -> Option<&PosePlan> {
        self.poses.iter().find(|p| p.pose == pose)
    }

    /// The plan of pose `pose` as walker `walker` draws it (its own rays' needs).
    pub fn walker_pose(&self, walker: usize, pose: u32) -> Option<&PosePlan> {
        self.walkers.get(walker)?.iter().find(|p| p.pose == pose)
    }
}

/// Per frame, the pose each walker shows; and the poses substituted (`(wanted, held)`)
/// for ones the field lacks.
fn frame_plans(
    scene: &Scene,
    h: &FieldHeader,
    frames: &[ShotFrame],
    (interpolate, gait): (TimeInterpolation, &Gait),
) -> (Vec<FramePlan>, BTreeSet<(u32, u32)>) {
    let mut field_poses: Vec<u32> = h.poses.iter().map(|p| p.pose).collect();
    field_poses.sort_unstable();
    let mut substituted = BTreeSet::new();
    let frame_plans: Vec<FramePlan> = frames
        .iter()
        .map(|f| {
            let (index, time) = (f.index, f.time);
            let fp = FramePlan::at(scene, h, &field_poses, (interpolate, gait), (index, time));
            for (i, &held) in fp.poses.iter().enumerate() {
                let wanted = scene.pose_at(i, time, gait, h.poses_per_cycle);
                // Morphing in time, a frame stands a pose in only where it has no
                // other to morph toward (a one-pose field): said as nearest's are.
                let morphed = interpolate == TimeInterpolation::Flow && fp.between[i].is_some();
                if !morphed && held != wanted {
                    substituted.insert((wanted, held));
                }
            }
            fp
        })
        .collect();
    (frame_plans, substituted)
}

/// What the walkers' rays are traced against: the scene, the field's header and which
/// conditions are lit.
struct Traced<'a> {
    scene: &'a Scene,
    h: &'a FieldHeader,
    lit: &'a [bool],
}

impl Traced<'_> {
    /// Per walker, the poses it draws and what its own rays reach of them over
    /// `frames` (planned as `frame_plans`); and whether any ray meets the ground patch.
    fn walkers(
        &self,
        frame_plans: &[FramePlan],
        frames: &[ShotFrame],
        hull_box: &mut dyn FnMut(u32) -> Result<Option<(Vec3, Vec3)>>,
    ) -> Result<(Vec<Vec<PosePlan>>, bool)> {
        let mut ground_seen = false;
        // Per pose drawn, where its subject can show.
        let mut bounds = BTreeMap::new();
        let mut walkers: Vec<Vec<PosePlan>> = vec![Vec::new(); self.scene.instances.len()];
        for (fp, frame) in frame_plans.iter().zip(frames) {
            let drawn = fp.poses.iter().enumerate().flat_map(|(i, &pose)| {
                let between = fp.between[i];
                // Pose k, with its motion on to k'; and k', with its motion back to k.
                [(i, pose, between.map(|_| PoseStep::Next))]
                    .into_iter()
                    .chain(between.map(|(after, _)| (i, after, Some(PoseStep::Prev))))
            });
            for (i, pose, motion) in drawn {
                let record = self.h.pose(pose)?;
                let b = match bounds.entry(pose) {
                    Entry::Occupied(b) => *b.get(),
                    Entry::Vacant(b) => *b.insert(SubjectBounds::of_pose(record, hull_box(pose)?)?),
                };
                let subject_camera = self
                    .scene
                    .placement(i, frame.time)
                    .camera_in_subject_frame(&frame.camera);
                let plan = entry(
                    &mut walkers[i],
                    pose,
                    self.h.columns * self.h.rows,
                    self.lit,
                );
                ground_seen |= self.trace(record, &subject_camera, b, motion, plan)?;
            }
        }
        Ok((walkers, ground_seen))
    }

    /// Marks in `plan` what `camera` (in the subject's frame) reaches of the pose of
    /// `record` whose subject shows within `bounds`, drawn with its motion toward
    /// `motion`; whether a ray meets the ground patch.
    fn trace(
        &self,
        record: &frf_reflectance::field::PoseRecord,
        camera: &Camera,
        bounds: SubjectBounds,
        motion: Option<PoseStep>,
        plan: &mut PosePlan,
    ) -> Result<bool> {
        let h = self.h;
        let (columns, rows) = (h.columns, h.rows);
        let half = h.shadows.as_ref().map_or(0.0, |s| 0.5 * s.ground.extent_m);
        let centres: Vec<Vec3> = record
            .views
            .iter()
            .map(|v| {
                v.camera
                    .to_camera()
                    .map(|c| c.centre())
                    .map_err(|e| ReflectanceError::Corrupt(format!("a camera: {e}")).into())
            })
            .collect::<Result<_>>()?;
        let cylinder = Cylinder::new(&centres, columns, rows, h.wraps);
        let (quads, ground) = reached(&cylinder, camera, &bounds, half);
        let level = detail_level(captured_ppm(record)?, pixels_per_metre(camera));
        let shadow_level = h.shadows.as_ref().map_or(0, |s| {
            let ground = s.ground.texels as f32 / s.ground.extent_m;
            detail_level(ground, pixels_per_metre(camera))
        });
        plan.bounds = bounds;
        plan.level = plan.level.min(level);
        plan.shadow_level = plan.shadow_level.min(shadow_level);
        if let Some(step) = motion {
            plan.pose_flows[step.index()] = true;
        }
        for &(u, v) in &quads {
            let (u1, v1) = ((u + 1) % columns, (v + 1).min(rows - 1));
            for (a, b) in [(u, v), (u1, v), (u, v1), (u1, v1)] {
                plan.views[a * rows + b] = true;
            }
            for ((a, b), n) in quad_flows(u, v, columns, rows) {
                plan.flows[a * rows + b][n.index()] = true;
            }
        }
        Ok(ground)
    }
}

/// Every walker's plans of a pose together, per pose (poses of `views` views, `lit`
/// conditions).
fn union_of(walkers: &[Vec<PosePlan>], views: usize, lit: &[bool]) -> Vec<PosePlan> {
    let mut poses: Vec<PosePlan> = Vec::new();
    for w in walkers {
        for p in w {
            let union = entry(&mut poses, p.pose, views, lit);
            union
                .views
                .iter_mut()
                .zip(&p.views)
                .for_each(|(u, &v)| *u |= v);
            for (u, f) in union.flows.iter_mut().zip(&p.flows) {
                for k in 0..4 {
                    u[k] |= f[k];
                }
            }
            for k in 0..2 {
                union.pose_flows[k] |= p.pose_flows[k];
            }
            union.bounds = p.bounds;
            union.level = union.level.min(p.level);
            union.shadow_level = union.shadow_level.min(p.shadow_level);
        }
    }
    poses
}

impl PlanCounts {
    /// The counts of `poses` planned on the field of `h` with `lit` conditions (the
    /// bytes are counted once the field's index is at hand, [`Plan::new`]).
    fn of(poses: &[PosePlan], h: &FieldHeader, lit: &[bool]) -> Self {
        let views = h.columns * h.rows;
        PlanCounts {
            poses_used: poses.len(),
            poses_total: h.poses.len(),
            views_used: poses
                .iter()
                .map(|p| p.views.iter().filter(|&&v| v).count())
                .sum(),
            views_total: poses.len() * views,
            flows_used: poses
                .iter()
                .map(|p| p.flows.iter().flatten().filter(|&&f| f).count())
                .sum(),
            flows_total: 0,
            pose_flows_used: poses
                .iter()
                .map(|p| {
                    let views = p.views.iter().filter(|&&v| v).count();
                    p.pose_flows.iter().filter(|&&f| f).count() * views
                })
                .sum(),
            conditions_used: lit.iter().filter(|&&l| l).count(),
            conditions_total: h.conditions.len(),
            bytes_read: 0,
            bytes_total: 0,
        }
    }
}
