//! One pose of a field made ready to render: every view's pre-lit image (its basis images
//! relit by the environment, docs/design.md section 4.1), alpha and flows, in the compact form
//! the GPU holds them in, so that the GPU and the CPU reference read identical data.
//! Everything is cropped to the pose's crop ([`crate::geometry`]).
//!
//! - **Pre-lit images**: RGBA8, colour as sRGB-encoded `linear / scale` with one scale per
//!   view (its brightest value, so nothing clips), alpha linear. A GPU samples them through
//!   an sRGB view, which decodes before it filters; the CPU decodes each texel the same way.
//! - **Flows** stay as their 8-bit logarithmic codes, two per pixel, decoded when sampled,
//!   extended beyond the subject ([`crate::extend`]; a flow that knows no texel reads
//!   as zero displacement).
//!
//! Relighting skips conditions whose coefficient is zero for every view (none of its
//! light reaches the subject, e.g. the floor conditions under a black lower
//! hemisphere); [`LightingPlan`] says which and what that saved.

use std::sync::Arc;

use frf_core::camera::Camera;
use frf_core::env::EnvMap;
use frf_core::grid::Neighbour;
use frf_core::image::{GrayImage, Rgb};
use frf_core::io::{linear_to_srgb, srgb_to_linear};
use frf_reflectance::FieldFile;
use frf_reflectance::container::{ChunkKey, ChunkKind, ReadAt};
use frf_reflectance::floor_light::{floor_ratio, floor_shares, ground_weight};
use frf_reflectance::flowcodec::quant::{LogQuantizer, UNKNOWN_CODE};
use frf_reflectance::hull::VoxelHull;
use frf_reflectance::imagecodec::{BasisCodes, gamma_lut};
use frf_reflectance::light_fit::condition_light_shares;
use frf_reflectance::normalcodec::normal_of;
use frf_reflectance::project::FloorModel;
use frf_reflectance::sun_light::{SunLight, TexelCache, suns_texel};
use frf_reflectance::yaw_light::YawLight;
use glam::Vec2;
use rayon::prelude::*;

use crate::detail::{
    reduce_alpha, reduce_basis, reduce_flow, reduce_normals, reduced_camera, reduced_image,
};
use crate::error::{RenderError, Result};
use crate::extend::extend_flow;
use crate::footprint::SubjectBounds;
use crate::geometry::{Crop, PoseGeometry};
use crate::pose_plan::PosePlan;
use crate::proxy::Proxy;
use crate::reduced_views::{ReducedImage, ReducedViews};

/// How the field is lit.
#[derive(Debug, Clone)]
pub enum Lighting {
    /// An HDR environment (subject frame), with the floor conditions' model.
    Environment {
        /// The environment.
        env: EnvMap,
        /// Where the floor conditions' light comes from.
        floor: FloorModel,
    },
    /// A light of turned, weighted maps read through their yaw tables (what a shot
    /// relights its walkers with: a turning light and every heading share the tables).
    Tabled(YawLight),
    /// Every condition at coefficient 1 (for fields of photographs: no relighting).
    Unlit,
}

impl Lighting {
    /// The lighting of a field of `conditions` basis conditions by `env` (turned by `yaw`
    /// radians; unlit without one), and that environment for truth renders. A field of
    /// photographs (one condition) cannot be relit.
    pub fn of(
        env: Option<EnvMap>,
        yaw: f32,
        floor: FloorModel,
        conditions: usize,
    ) -> Result<(Self, Option<EnvMap>)> {
        let Some(env) = env else {
            return Ok((Lighting::Unlit, None));
        };
        if conditions <= 1 {
            return Err(RenderError::NotRelightable { conditions });
        }
        let env = env.rotated(yaw);
        let lighting = Lighting::Environment {
            env: env.clone(),
            floor,
        };
        Ok((lighting, Some(env)))
    }
}

/// One view's codes as read from the field: basis tiles, 8-bit alpha, the log-coded
/// flow to each of its four neighbours (absent at the grid's edges), and its fitted
/// normals' codes (none where the field holds none).
type ViewCodes = (BasisCodes, Vec<u8>, [Option<Vec<[i8; 2]>>; 4], Vec<[u8; 2]>);

/// What relighting left out.
#[derive(Debug, Clone, PartialEq)]
pub struct LightingPlan {
    /// Conditions whose coefficient is zero in every view: not relit at all.
    pub skipped_conditions: Vec<String>,
    /// Basis images decoded and combined.
    pub images_combined: usize,
    /// Basis images a plan without skipping would have combined.
    pub images_total: usize,
}

/// One pose's flows as stored: 8-bit log codes `(u, v)` per pixel, cropped, per view and
/// neighbour ([`Neighbour::ALL`] order; absent at the grid's edges), with the pose's
/// quantizer and the table both renderers decode them with ([`flow_lut`]).
#[derive(Debug, Clone)]
pub struct PoseFlows {
    /// Per view and neighbour: the codes.
    pub codes: Vec<[Option<Vec<[i8; 2]>>; 4]>,
    /// The pose's flow quantizer.
    pub quantizer: LogQuantizer,
    /// Code (offset by 128) to displacement.
    pub table: [f32; 256],
}

/// One pose's geometry, flows and basis images as loaded from a field file, before
/// relighting (what [`ResidentPose::relight_cpu`] and the GPU relighting pass start from).
#[derive(Debug, Clone)]
pub struct PoseSource {
    /// Grid, crop, cameras, cylinder.
    pub geometry: Arc<PoseGeometry>,
    /// The flows.
    pub flows: Arc<PoseFlows>,
    /// Per view: the basis mosaic's codes and scales, cropped (no tiles for a view not
    /// read); shared by the pose relit under other lights ([`PoseSource::relit`]).
    pub basis: Arc<Vec<BasisCodes>>,
    /// Per view: alpha codes (`round(255 α)`), cropped (none for a view not read).
    pub alpha: Arc<Vec<Vec<u8>>>,
    /// Per view: its fitted normals' octahedral codes, cropped (none where the field
    /// holds none, or for a view not read).
    pub normals: Arc<Vec<Vec<[u8; 2]>>>,
    /// Per view: where each texel's camera ray (cropped) meets the pose's visual hull, as
    /// `t` along the ray's unit direction, `-1` where it misses; the suns' shadows are
    /// judged from these points. Found once, at load ([`hull_surfaces`]); none for a view
    /// without normals, or a pose without a hull.
    pub surfaces: Arc<Vec<Vec<f32>>>,
    /// Per condition: its lights' directions (dome frame) and shares of its light
    /// ([`condition_light_shares`]), which shade the normals under a sun.
    pub condition_lights: Arc<Vec<Vec<(glam::Vec3, f32)>>>,
    /// Per view and condition: relighting coefficients (RGB), of the environment less
    /// the suns `suns` holds.
    pub coefficients: Vec<Vec<Rgb>>,
    /// The environment's suns, relit by the views' normals rather than by the basis
    /// (none: no sun, or views without normals), brightest first.
    pub suns: Arc<[SunLight]>,
    /// Per view and condition: what the suns add to `coefficients` when the basis
    /// relights them, where the normals' sun is not trusted ([`SunLight::trust`]; empty
    /// without suns).
    pub sun_coefficients: Vec<Vec<Rgb>>,
    /// Per view and condition: a floor condition's lights' shares reweighted by the
    /// light's ground ([`floor_shares`]), which relight its image by the normals; empty
    /// where the basis relights it alone (no normals, a modelled ground, not the floor).
    pub floor_shares: Vec<Vec<Vec<f32>>>,
    /// Per condition: whether it is a floor condition (those `floor_shares` may relight;
    /// the GPU keeps room for them whatever the light, so that a new light fits).
    pub floor_conditions: Arc<Vec<bool>>,
    /// Per condition: the coefficients of the ground's frame (turntable angle 0), which
    /// relight the shadow maps; `None` without an environment.
    pub ground_coefficients: Option<Vec<Rgb>>,
    /// What relighting leaves out.
    pub plan: LightingPlan,
}

impl PoseSource {
    /// Whether view `i` holds nothing (a view the plan did not read): no alpha and no
    /// codes, and no pre-lit layer once resident (it samples as transparent).
    pub fn is_blank(&self, i: usize) -> bool {
        self.alpha[i].is_empty()
    }

    /// The same views under `lighting`: new coefficients (the conditions `plan` leaves
    /// out at zero), everything else shared with `self`. What a new light costs the host
    /// before the GPU relights the views.
    pub fn relit<R: ReadAt>(
        &self,
        field: &FieldFile<R>,
        lighting: &Lighting,
        plan: Option<&PosePlan>,
    ) -> Result<Self> {
        let read: Vec<bool> = (0..self.basis.len()).map(|i| !self.is_blank(i)).collect();
        let relit = relighting(
            field,
            self.geometry.pose,
            lighting,
            plan,
            (&read, self.holds_normals()),
            (self.geometry.proxy.hull_shared(), self.geometry.level),
        )?;
        // The views, flows and geometry are shared; only the light's parts are new (a
        // clone of the whole would copy the old light's, to throw them away).
        Ok(Self {
            geometry: self.geometry.clone(),
            flows: self.flows.clone(),
            basis: self.basis.clone(),
            alpha: self.alpha.clone(),
            normals: self.normals.clone(),
            surfaces: self.surfaces.clone(),
            condition_lights: self.condition_lights.clone(),
            floor_conditions: self.floor_conditions.clone(),
            coefficients: relit.coefficients,
            ground_coefficients: relit.ground,
            plan: relit.plan,
            suns: relit.suns,
            sun_coefficients: relit.sun_coefficients,
            floor_shares: relit.floor_shares,
        })
    }

    /// Whether every view read holds its fitted normals (what relights a sun by them).
    pub fn holds_normals(&self) -> bool {
        let mut read = (0..self.basis.len())
            .filter(|&i| !self.is_blank(i))
            .peekable();
        read.peek().is_some() && read.all(|i| !self.normals[i].is_empty())
    }

    /// Bytes its basis and alpha codes hold.
    pub fn basis_bytes(&self) -> u64 {
        let basis: usize = self
            .basis
            .iter()
            .map(|b| b.tiles.iter().map(|t| t.len() * 3).sum::<usize>())
            .sum();
        let alpha: usize = self.alpha.iter().map(Vec::len).sum();
        (basis + alpha) as u64
    }

    /// Loads pose `pose` of a field and the relighting coefficients of `lighting`.
    pub fn load<R: ReadAt>(field: &FieldFile<R>, pose: u32, lighting: &Lighting) -> Result<Self> {
        Self::load_planned(field, pose, lighting, None)
    }

    /// Loads what `plan` (if any) says pose `pose` needs: the views, flows and conditions
    /// it leaves out are not read, decoded or relit (their views stay transparent, their
    /// flows absent, their coefficients zero); the crop covers the views read.
    pub fn load_planned<R: ReadAt>(
        field: &FieldFile<R>,
        pose: u32,
        lighting: &Lighting,
        plan: Option<&PosePlan>,
    ) -> Result<Self> {
        Self::load_at(field, pose, lighting, plan, 0, None)
    }

    /// [`PoseSource::load_planned`] at level of detail `level` ([`crate::detail`]): above
    /// 0, the views and flows read are reduced (taken from `kept` when it holds them, and
    /// kept there), and the crop is the whole reduced image.
    pub fn load_at<R: ReadAt>(
        field: &FieldFile<R>,
        pose: u32,
        lighting: &Lighting,
        plan: Option<&PosePlan>,
        level: u8,
        kept: Option<&ReducedViews>,
    ) -> Result<Self> {
        check_renderable(field)?;
        let h = field.header();
        let record = h.pose(pose)?;
        let (columns, rows) = (h.columns, h.rows);
        let read = views_read(field, pose, plan)?;
        let cameras = record
            .views
            .iter()
            .map(|v| v.camera.to_camera().map_err(RenderError::BadCamera))
            .collect::<Result<Vec<_>>>()?;
        // The hull is the renderer's proxy for rays beyond the grid's rows.
        let hull = if plan.is_none_or(|p| p.hull) {
            field.hull_shared(pose)?
        } else {
            None
        };
        let bounds = SubjectBounds::of_pose(record, hull.as_ref().and_then(|h| h.bounds()))?;
        let table = flow_lut(&record.flow_quantizer);
        let reading = Reading {
            field,
            pose,
            rows,
            read: &read,
            plan,
        };
        let (size, crop, cameras, per_view) = if level == 0 {
            let size = (h.width, h.height);
            let (crop, per_view) = reading.full_detail(size)?;
            (size, crop, cameras, per_view)
        } else {
            let none = ReducedViews::default();
            let (size, crop, per_view) = reading.reduced(level, kept.unwrap_or(&none), &table)?;
            let cameras = cameras.iter().map(|c| reduced_camera(c, level)).collect();
            (size, crop, cameras, per_view)
        };
        let mut basis = Vec::with_capacity(per_view.len());
        let mut alpha = Vec::with_capacity(per_view.len());
        let mut flows = Vec::with_capacity(per_view.len());
        let mut normals = Vec::with_capacity(per_view.len());
        for (b, a, f, n) in per_view {
            basis.push(b);
            alpha.push(a);
            flows.push(f);
            normals.push(n);
        }
        let held = (0..read.len()).any(|i| read[i])
            && (0..read.len()).all(|i| !read[i] || !normals[i].is_empty());
        let geometry =
            PoseGeometry::new(pose, columns, rows, h.wraps, size, crop, cameras, |i, n| {
                flows[i][n.index()].is_some()
            })
            .with_bounds(bounds)
            .with_proxy(Proxy::shared(hull))
            .with_held(|i| read[i])
            .at_level(level);
        let relit = relighting(
            field,
            pose,
            lighting,
            plan,
            (&read, held),
            (geometry.proxy.hull_shared(), level),
        )?;
        let surfaces = hull_surfaces(&geometry, &normals);
        Ok(Self {
            surfaces: Arc::new(surfaces),
            geometry: Arc::new(geometry),
            flows: Arc::new(PoseFlows {
                codes: flows,
                quantizer: record.flow_quantizer,
                table,
            }),
            basis: Arc::new(basis),
            alpha: Arc::new(alpha),
            normals: Arc::new(normals),
            condition_lights: Arc::new(condition_light_shares(&h.conditions)),
            floor_conditions: Arc::new(h.conditions.iter().map(|c| c.floor).collect()),
            coefficients: relit.coefficients,
            ground_coefficients: relit.ground,
            suns: relit.suns,
            sun_coefficients: relit.sun_coefficients,
            floor_shares: relit.floor_shares,
            plan: relit.plan,
        })
    }
}

/// Per view of pose `pose`, whether it is read: the plan wants it (or there is no plan)
/// and the field holds it (a field ingested for one scene holds only that scene's views).
/// A plan that does not fit the pose, or wants a view the field lacks, is refused.
fn views_read<R: ReadAt>(
    field: &FieldFile<R>,
    pose: u32,
    plan: Option<&PosePlan>,
) -> Result<Vec<bool>> {
    let h = field.header();
    let rows = h.rows;
    let views = h.columns * rows;
    if let Some(p) = plan
        && (p.pose != pose || p.views.len() != views || p.conditions.len() != h.conditions.len())
    {
        return Err(RenderError::Misuse(format!(
            "the plan of pose {} does not fit pose {pose} of this field",
            p.pose
        )));
    }
    let held = |i: usize| {
        field.has(&ChunkKey {
            pose,
            u: (i / rows) as u32,
            v: (i % rows) as u32,
            kind: ChunkKind::Alpha,
        })
    };
    if let Some(p) = plan
        && let Some(i) = (0..views).find(|&i| p.views[i] && !held(i))
    {
        return Err(RenderError::ViewNotHeld {
            field: field.path().to_path_buf(),
            pose,
            u: i / rows,
            v: i % rows,
        });
    }
    Ok((0..views)
        .map(|i| plan.is_none_or(|p| p.views[i]) && held(i))
        .collect())
}

/// Per view of `geometry` holding `normals`: where each cropped texel's camera ray meets
/// the pose's hull (`t` along the ray's unit direction, `-1` where it misses); nothing for
/// a view without normals, or without a hull (see [`PoseSource::surfaces`]).
fn hull_surfaces(geometry: &PoseGeometry, normals: &[Vec<[u8; 2]>]) -> Vec<Vec<f32>> {
    let Some(hull) = geometry.proxy.hull() else {
        return vec![Vec::new(); normals.len()];
    };
    let crop = geometry.crop;
    (0..normals.len())
        .into_par_iter()
        .map(|i| {
            if normals[i].is_empty() {
                return Vec::new();
            }
            let camera = &geometry.cameras[i];
            (0..crop.texels())
                .map(|p| {
                    let (o, d) = (camera.centre(), camera.ray_direction(texel_pixel(crop, p)));
                    hull.first_hit(o, d).unwrap_or(-1.0)
                })
                .collect()
        })
        .collect()
}

/// The pixel of cropped texel `p` of `crop`, as a point.
fn texel_pixel(crop: Crop, p: usize) -> glam::Vec2 {
    let (x, y) = crop.pixel(p);
    glam::Vec2::new(x as f32, y as f32)
}

/// A pose's relighting: per view the coefficients of every condition, the subject
/// frame's own (for the ground), the suns relit apart, and what relighting leaves out.
struct Relighting {
    coefficients: Vec<Vec<Rgb>>,
    ground: Option<Vec<Rgb>>,
    suns: Arc<[SunLight]>,
    sun_coefficients: Vec<Vec<Rgb>>,
    floor_shares: Vec<Vec<Vec<f32>>>,
    plan: LightingPlan,
}

/// Refuses, naming it, a field the renderer cannot draw: one of a single column of views
/// (`frf ingest-olat` writes one view: a one-light-at-a-time set's photographs as a
/// basis, for `frf eval-olat`), where a camera's ray has no views to interpolate between.
pub fn check_renderable<R: ReadAt>(field: &FieldFile<R>) -> Result<()> {
    let h = field.header();
    if h.columns >= 2 {
        return Ok(());
    }
    let what = if h.columns * h.rows == 1 {
        format!(
            "a field of one view ({} lighting conditions; frf ingest-olat writes such a field \
             of a one-light-at-a-time set, which frf eval-olat scores): rendering \
             interpolates between the views around the subject, and this field has one",
            h.conditions.len()
        )
    } else {
        format!(
            "a field of one column of {} views: rendering interpolates between columns of \
             views around the subject",
            h.rows
        )
    };
    Err(RenderError::NotRenderable {
        field: field.path().to_path_buf(),
        what,
    })
}

/// Per view of pose `pose` (those `read`), the relighting coefficients of `lighting`,
/// with the conditions `plan` leaves out at zero; the subject frame's own (for the
/// ground), and what relighting leaves out. Where the views hold their fitted normals
/// (`normals`) and the environment suns (up to [`MAX_SUNS`], each found in what the last
/// left), they are taken out of the views' coefficients and relit by the normals
/// ([`SunLight`]); the floor conditions keep the whole environment's (the ground the suns
/// light), and so does the ground.
fn relighting<R: ReadAt>(
    field: &FieldFile<R>,
    pose: u32,
    lighting: &Lighting,
    plan: Option<&PosePlan>,
    (read, normals): (&[bool], bool),
    (hull, level): (Option<&Arc<VoxelHull>>, u8),
) -> Result<Relighting> {
    let h = field.header();
    let record = h.pose(pose)?;
    let views = read.len();
    let mut suns = Vec::new();
    // Views not read keep angle 0 (their coefficients are never used).
    let mut angles = record.turntables();
    for (a, _) in angles.iter_mut().zip(read).filter(|(_, r)| !**r) {
        *a = 0.0;
    }
    // The views' coefficients and the ground's under a light read from its yaw tables;
    // where the views hold their normals, its suns apart, relit by them.
    let mut floor = Vec::new();
    let mut by_table =
        |light: &YawLight, angles: &[f32], normals: bool, suns: &mut Vec<SunLight>| {
            let lit = light.lighting(angles, normals)?;
            // The ground's own shape, where the views hold normals to relight it by.
            if let Some(radiance) = light.ground_radiance().filter(|_| normals) {
                let is_floor: Vec<bool> = h.conditions.iter().map(|c| c.floor).collect();
                let lights = condition_light_shares(&h.conditions);
                let weight = ground_weight(light.ground_share());
                floor = floor_shares(&lights, &is_floor, (angles, weight), radiance);
            }
            suns.extend(lit.suns.iter().map(|s| {
                SunLight::new(s, &h.conditions, angles, hull, level)
                    .with_occluders(light.occluders())
            }));
            Ok::<_, RenderError>((lit.coefficients, Some(lit.ground), lit.sun_coefficients))
        };
    let (mut coefficients, ground, mut sun_coefficients) = match lighting {
        Lighting::Unlit => (
            vec![vec![[1.0; 3]; h.conditions.len()]; views],
            None,
            Vec::new(),
        ),
        Lighting::Environment { env, floor } => {
            let light = YawLight::of_env(field.projector_shared()?.clone(), env, *floor);
            by_table(&light, &angles, normals, &mut suns)?
        }
        Lighting::Tabled(light) => by_table(light, &angles, normals, &mut suns)?,
    };
    if let Some(p) = plan {
        // Conditions the plan leaves out have zero weight at every frame.
        for c in coefficients.iter_mut().chain(&mut sun_coefficients) {
            for (k, used) in p.conditions.iter().enumerate() {
                if !used {
                    c[k] = [0.0; 3];
                }
            }
        }
    }
    let used: Vec<bool> = (0..h.conditions.len())
        .map(|k| {
            (coefficients.iter().chain(&sun_coefficients)).any(|c| c[k].iter().any(|&x| x != 0.0))
        })
        .collect();
    let plan = LightingPlan {
        skipped_conditions: h
            .conditions
            .iter()
            .zip(&used)
            .filter(|(_, u)| !**u)
            .map(|(c, _)| c.name.clone())
            .collect(),
        images_combined: views * used.iter().filter(|&&u| u).count(),
        images_total: views * h.conditions.len(),
    };
    Ok(Relighting {
        coefficients,
        ground,
        suns: suns.into(),
        sun_coefficients,
        floor_shares: floor,
        plan,
    })
}

/// What a load reads of a pose: the views `read`, and the flows `plan` wants.
struct Reading<'a, R: ReadAt> {
    field: &'a FieldFile<R>,
    pose: u32,
    rows: usize,
    read: &'a [bool],
    plan: Option<&'a PosePlan>,
}

impl<R: ReadAt> Reading<'_, R> {
    /// Whether the flow of view `i` toward `n` is read.
    fn flow_used(&self, i: usize, n: Neighbour) -> bool {
        self.plan.is_none_or(|p| p.flows[i][n.index()])
    }

    /// The views read at full detail (images of `size`), cropped to their mattes.
    fn full_detail(&self, size: (u32, u32)) -> Result<(Crop, Vec<ViewCodes>)> {
        let (field, pose, rows) = (self.field, self.pose, self.rows);
        let views = self.read.len();
        let alphas: Vec<GrayImage> = (0..views)
            .into_par_iter()
            .map(|i| {
                if self.read[i] {
                    Ok(field.alpha(pose, i / rows, i % rows)?)
                } else {
                    // Covers nothing: no pixels to allocate or scan.
                    Ok(GrayImage::new(0, 0, 0.0))
                }
            })
            .collect::<Result<_>>()?;
        let crop = Crop::of_mattes(&alphas, size);
        let full_w = size.0 as usize;
        let per_view: Vec<ViewCodes> = (0..views)
            .into_par_iter()
            .map(|i| {
                let (u, v) = (i / rows, i % rows);
                if !self.read[i] {
                    return Ok(not_read(crop));
                }
                let normals = field
                    .normal_codes(pose, u, v)?
                    .map_or_else(Vec::new, |n| crop.rows_of(&n, full_w));
                // Shared with every other read of the view (kept decoded, when the
                // caller set a budget for it), cropped here.
                let whole = field.basis_codes_shared(pose, u, v)?;
                let b = cropped(&whole, crop, full_w);
                let a = alpha_codes(&alphas[i]);
                let mut flows: [Option<Vec<[i8; 2]>>; 4] = Default::default();
                for n in Neighbour::ALL {
                    if !self.flow_used(i, n) {
                        continue;
                    }
                    if let Some(codes) = field.flow_codes(pose, u, v, n)? {
                        let mut cropped = crop.rows_of(&flow_pairs(&codes), full_w);
                        extend_flow(&mut cropped, crop.width as usize, crop.height as usize);
                        flows[n.index()] = Some(cropped);
                    }
                }
                Ok((b, crop.rows_of(&a, full_w), flows, normals))
            })
            .collect::<Result<_>>()?;
        Ok((crop, per_view))
    }

    /// The views read at level of detail `level` (taken from `kept` when it holds them,
    /// and kept there), cropped to their reduced mattes; the reduced image size.
    fn reduced(
        &self,
        level: u8,
        kept: &ReducedViews,
        table: &[f32; 256],
    ) -> Result<((u32, u32), Crop, Vec<ViewCodes>)> {
        let (field, pose, rows) = (self.field, self.pose, self.rows);
        let h = field.header();
        let (size, to) = reduced_image((h.width, h.height), level);
        let full = Crop {
            x0: 0,
            y0: 0,
            width: h.width,
            height: h.height,
        };
        // Per view read: its reduced image and flows (of the whole reduced image).
        type Reduced = (Arc<ReducedImage>, [Option<Arc<Vec<[i8; 2]>>>; 4]);
        let reduced: Vec<Option<Reduced>> = (0..self.read.len())
            .into_par_iter()
            .map(|i| {
                let (u, v) = (i / rows, i % rows);
                if !self.read[i] {
                    return Ok(None);
                }
                let image = kept.image((pose, i, level), || {
                    let alpha = alpha_codes(&field.alpha(pose, u, v)?);
                    let basis = field.basis_codes_shared(pose, u, v)?;
                    let alpha = reduce_alpha(&alpha, full, to, level);
                    let normals = field
                        .normal_codes(pose, u, v)?
                        .map_or_else(Vec::new, |n| reduce_normals(&n, full, to, level, &alpha));
                    Ok(ReducedImage {
                        basis: reduce_basis(&basis, full, to, level, &alpha),
                        alpha,
                        normals,
                    })
                })?;
                let mut flows: [Option<Arc<Vec<[i8; 2]>>>; 4] = Default::default();
                for n in Neighbour::ALL {
                    if !self.flow_used(i, n) {
                        continue;
                    }
                    // An absent flow (at the grid's edge) is kept as no codes.
                    let flow = kept.flow((pose, i, n.index(), level), || {
                        let Some(codes) = field.flow_codes(pose, u, v, n)? else {
                            return Ok(Vec::new());
                        };
                        let mut reduced = reduce_flow(&flow_pairs(&codes), table, full, to, level);
                        extend_flow(&mut reduced, to.width as usize, to.height as usize);
                        Ok(reduced)
                    })?;
                    flows[n.index()] = (!flow.is_empty()).then_some(flow);
                }
                Ok(Some((image, flows)))
            })
            .collect::<Result<_>>()?;
        // Cropped to the views' mattes, as at full detail.
        let alphas: Vec<&[u8]> = reduced
            .iter()
            .map(|r| r.as_ref().map_or(&[][..], |(i, _)| &i.alpha[..]))
            .collect();
        let crop = Crop::of_alpha_codes(&alphas, size);
        let w = size.0 as usize;
        let per_view: Vec<ViewCodes> = reduced
            .iter()
            .map(|r| {
                let Some((image, flows)) = r else {
                    return not_read(crop);
                };
                let basis = cropped(&image.basis, crop, w);
                let flows = flows
                    .each_ref()
                    .map(|f| f.as_ref().map(|f| crop.rows_of(f, w)));
                let normals = if image.normals.is_empty() {
                    Vec::new()
                } else {
                    crop.rows_of(&image.normals, w)
                };
                (basis, crop.rows_of(&image.alpha, w), flows, normals)
            })
            .collect();
        Ok((size, crop, per_view))
    }
}

/// What a view not read holds: no basis images, alpha or flows.
fn not_read(crop: Crop) -> ViewCodes {
    let blank = BasisCodes {
        width: crop.width as usize,
        height: crop.height as usize,
        tiles: Vec::new(),
        scales: Vec::new(),
    };
    (blank, Vec::new(), Default::default(), Vec::new())
}

/// Basis codes `b` (images `width` texels a row) cropped to `crop`.
fn cropped(b: &BasisCodes, crop: Crop, width: usize) -> BasisCodes {
    BasisCodes {
        width: crop.width as usize,
        height: crop.height as usize,
        tiles: b.tiles.iter().map(|t| crop.rows_of(t, width)).collect(),
        scales: b.scales.clone(),
    }
}

/// A stored flow's codes (the x plane, then the y plane) as per-texel pairs.
fn flow_pairs(codes: &[i8]) -> Vec<[i8; 2]> {
    let plane = codes.len() / 2;
    (0..plane).map(|k| [codes[k], codes[plane + k]]).collect()
}

/// A matte's alpha codes, `round(255 α)`.
fn alpha_codes(matte: &GrayImage) -> Vec<u8> {
    matte
        .pixels()
        .iter()
        .map(|&x| (x.clamp(0.0, 1.0) * 255.0).round() as u8)
        .collect()
}

/// A pose ready to render: pre-lit views, alpha and flow codes (see the module docs).
#[derive(Debug, Clone)]
pub struct ResidentPose {
    /// Grid, crop, cameras, cylinder.
    pub geometry: Arc<PoseGeometry>,
    /// The flows.
    pub flows: Arc<PoseFlows>,
    /// Per view: colour scale.
    pub scales: Vec<f32>,
    /// Per view: RGBA8 texels (sRGB colour / scale, linear alpha), cropped; none for a
    /// view not held.
    pub prelit: Vec<Vec<[u8; 4]>>,
    /// Decoding table of the pre-lit texels ([`srgb_lut`]).
    pub srgb_table: [f32; 256],
    /// What relighting left out.
    pub plan: LightingPlan,
}

/// 8-bit sRGB code to linear: the table both the CPU and the GPU decode texels with, so
/// that they read identical values.
pub fn srgb_lut() -> [f32; 256] {
    std::array::from_fn(|c| srgb_to_linear(c as f32 / 255.0))
}

/// Flow code (offset by 128) to displacement, unknown (−128) to zero: the table both the
/// CPU and the GPU decode flow texels with.
pub fn flow_lut(q: &LogQuantizer) -> [f32; 256] {
    std::array::from_fn(|i| {
        let code = (i as i32 - 128) as i8;
        if code == UNKNOWN_CODE {
            0.0
        } else {
            q.decode(code)
        }
    })
}

/// The pre-lit colour of one pixel from a view's basis codes and coefficients.
#[inline]
pub fn relit_pixel(basis: &BasisCodes, coefficients: &[Rgb], lut: &[f32; 256], i: usize) -> Rgb {
    let mut out = [0.0f32; 3];
    for ((tile, scale), c) in basis.tiles.iter().zip(&basis.scales).zip(coefficients) {
        if c.iter().all(|&x| x == 0.0) {
            continue;
        }
        let p = tile[i];
        for k in 0..3 {
            out[k] += c[k] * scale * lut[p[k] as usize];
        }
    }
    out
}

/// [`relit_pixel`] of two sets of coefficients (the light's, and its suns': what the
/// basis adds for them), each image decoded once for both, as `shaders/relight.wgsl`
/// does.
#[inline]
pub fn relit_pixel_pair(
    basis: &BasisCodes,
    (coefficients, suns): (&[Rgb], &[Rgb]),
    lut: &[f32; 256],
    i: usize,
) -> [Rgb; 2] {
    let mut out = [[0.0f32; 3]; 2];
    let images = basis.tiles.iter().zip(&basis.scales);
    for ((tile, scale), (c, d)) in images.zip(coefficients.iter().zip(suns)) {
        if c.iter().chain(d).all(|&x| x == 0.0) {
            continue;
        }
        let p = tile[i];
        for ch in 0..3 {
            let v = scale * lut[p[ch] as usize];
            out[0][ch] += c[ch] * v;
            out[1][ch] += d[ch] * v;
        }
    }
    out
}

/// Basis image `k`'s linear value at pixel `i` of a view's codes.
#[inline]
pub fn basis_value(basis: &BasisCodes, lut: &[f32; 256], k: usize, i: usize) -> Rgb {
    let (p, s) = (basis.tiles[k][i], basis.scales[k]);
    [p[0], p[1], p[2]].map(|c| s * lut[c as usize])
}

/// Views already lit, for [`ResidentPose::from_views`]: per view its camera, its RGBA8
/// texels (sRGB colour over its scale, linear alpha) and its scale, and per view and
/// neighbour ([`Neighbour::ALL`] order) its flow codes, all of the full image.
#[derive(Debug, Clone)]
pub struct LitViews {
    /// Columns and rows of the grid (`u`-major views), and whether the columns wrap.
    pub grid: (usize, usize, bool),
    /// Image size.
    pub size: (u32, u32),
    /// Per view: its camera (subject frame).
    pub cameras: Vec<Camera>,
    /// Per view: its texels.
    pub prelit: Vec<Vec<[u8; 4]>>,
    /// Per view: its colour scale.
    pub scales: Vec<f32>,
    /// Per view and neighbour: flow codes, absent where none is stored.
    pub codes: Vec<[Option<Vec<[i8; 2]>>; 4]>,
    /// The flows' quantizer.
    pub quantizer: LogQuantizer,
}

impl ResidentPose {
    /// A pose of views already lit, uncropped (synthetic poses and tests), its flows
    /// extended beyond the subject as a loaded pose's are.
    pub fn from_views(views: LitViews) -> Self {
        let (columns, rows, wraps) = views.grid;
        let (w, h) = views.size;
        let crop = Crop {
            x0: 0,
            y0: 0,
            width: w,
            height: h,
        };
        let mut codes = views.codes;
        for flow in codes.iter_mut().flatten().flatten() {
            extend_flow(flow, w as usize, h as usize);
        }
        let geometry = PoseGeometry::new(
            0,
            columns,
            rows,
            wraps,
            (w, h),
            crop,
            views.cameras,
            |i, n| codes[i][n.index()].is_some(),
        );
        Self {
            geometry: Arc::new(geometry),
            flows: Arc::new(PoseFlows {
                codes,
                quantizer: views.quantizer,
                table: flow_lut(&views.quantizer),
            }),
            scales: views.scales,
            prelit: views.prelit,
            srgb_table: srgb_lut(),
            plan: LightingPlan {
                skipped_conditions: Vec::new(),
                images_combined: 0,
                images_total: 0,
            },
        }
    }

    /// Relights every view on the CPU and encodes it (the GPU's relighting pass computes
    /// the same).
    pub fn relight_cpu(source: &PoseSource) -> Self {
        let lut = gamma_lut();
        let views: Vec<(f32, Vec<[u8; 4]>)> = (0..source.basis.len())
            .into_par_iter()
            .map(|i| {
                if source.is_blank(i) {
                    return (1.0, Vec::new());
                }
                let b = &source.basis[i];
                let n = b.width * b.height;
                // A transparent texel holds no light (the colour is premultiplied): it
                // is not relit.
                let alpha = &source.alpha[i];
                let normals = &source.normals[i];
                let suns = &source.suns;
                let sun_coefficients = source.sun_coefficients.get(i);
                let floor_shares = source.floor_shares.get(i).filter(|_| !normals.is_empty());
                let (camera, crop) = (&source.geometry.cameras[i], source.geometry.crop);
                // The texel's point on the visual hull (`None`: its ray misses it, or
                // there is none), which the suns' shadows are judged from.
                let surfaces = &source.surfaces[i];
                let surface = |p: usize| {
                    let t = *surfaces.get(p)?;
                    let (o, d) = (camera.centre(), camera.ray_direction(texel_pixel(crop, p)));
                    (t >= 0.0).then(|| o + d * t)
                };
                let mut cache = TexelCache::default();
                let relit: Vec<Rgb> = (0..n)
                    .map(|p| {
                        if alpha[p] == 0 {
                            return [0.0; 3];
                        }
                        let suns_basis = sun_coefficients.filter(|_| !suns.is_empty());
                        let [mut c, basis] = match suns_basis {
                            Some(d) => relit_pixel_pair(b, (&source.coefficients[i], d), &lut, p),
                            None => [relit_pixel(b, &source.coefficients[i], &lut, p), [0.0; 3]],
                        };
                        let normal = normals.get(p).and_then(|&n| normal_of(n));
                        // The floor conditions' images relit by the ground's shape.
                        if let Some(shares) = floor_shares {
                            for (k, e) in shares.iter().enumerate().filter(|(_, e)| !e.is_empty()) {
                                let r = floor_ratio(normal, &source.condition_lights[k], e);
                                let (v, w) =
                                    (basis_value(b, &lut, k, p), source.coefficients[i][k]);
                                for ch in 0..3 {
                                    c[ch] += w[ch] * v[ch] * (r - 1.0);
                                }
                            }
                        }
                        if suns_basis.is_none() {
                            return c;
                        }
                        // Found once, and only where a sun would light.
                        let mut at = None;
                        let s = suns_texel(
                            suns,
                            (i, normal),
                            (|k| basis_value(b, &lut, k, p), &mut cache),
                            basis,
                            |sun| {
                                (*at.get_or_insert_with(|| surface(p)))
                                    .is_none_or(|x| sun.sunlit(x))
                            },
                        );
                        for k in 0..3 {
                            c[k] += s[k];
                        }
                        c
                    })
                    .collect();
                let peak = relit.iter().flatten().copied().fold(0.0f32, f32::max);
                let scale = if peak > 0.0 { peak } else { 1.0 };
                let texels = relit
                    .iter()
                    .zip(&source.alpha[i])
                    .map(|(c, &a)| {
                        let e = |x: f32| (linear_to_srgb(x / scale) * 255.0).round() as u8;
                        [e(c[0]), e(c[1]), e(c[2]), a]
                    })
                    .collect();
                (scale, texels)
            })
            .collect();
        let (scales, prelit) = views.into_iter().unzip();
        Self::with_views(source, scales, prelit)
    }

    /// The pose of `source`'s geometry, flows and lighting plan with the pre-lit views
    /// `prelit` of `scales` (its relit colour, or what else its views carry:
    /// [`crate::motion::pose_motion`]).
    pub fn with_views(source: &PoseSource, scales: Vec<f32>, prelit: Vec<Vec<[u8; 4]>>) -> Self {
        Self {
            geometry: source.geometry.clone(),
            flows: source.flows.clone(),
            scales,
            prelit,
            srgb_table: srgb_lut(),
            plan: source.plan.clone(),
        }
    }

    /// Bytes the pose holds ([`PoseGeometry::resident_bytes`]).
    pub fn resident_bytes(&self) -> u64 {
        self.geometry.resident_bytes()
    }

    /// Bilinear sample (premultiplied RGBA, linear) of view `view` at full-image pixel
    /// coordinates `s`; the edge repeats beyond the crop (it is transparent there).
    pub fn sample_prelit(&self, view: usize, s: Vec2) -> [f32; 4] {
        let crop = &self.geometry.crop;
        let (w, h) = (crop.width as i64, crop.height as i64);
        let x = s.x - crop.x0 as f32;
        let y = s.y - crop.y0 as f32;
        if !(x.is_finite() && y.is_finite()) {
            return [0.0; 4];
        }
        let (x, y) = (x.clamp(-1.0, w as f32), y.clamp(-1.0, h as f32));
        let (x0, y0) = (x.floor(), y.floor());
        let (fx, fy) = (x - x0, y - y0);
        let texels = &self.prelit[view];
        if texels.is_empty() {
            // A view not held: transparent.
            return [0.0; 4];
        }
        let scale = self.scales[view];
        let lut = &self.srgb_table;
        let mut out = [0.0f32; 4];
        for (dy, wy) in [(0i64, 1.0 - fy), (1, fy)] {
            for (dx, wx) in [(0i64, 1.0 - fx), (1, fx)] {
                let xi = (x0 as i64 + dx).clamp(0, w - 1);
                let yi = (y0 as i64 + dy).clamp(0, h - 1);
                let t = texels[(yi * w + xi) as usize];
                let wt = wx * wy;
                for k in 0..3 {
                    out[k] += wt * (scale * lut[t[k] as usize]);
                }
                out[3] += wt * t[3] as f32 / 255.0;
            }
        }
        out
    }

    /// Bilinear sample of the flow from view `view` toward `n` at full-image pixel
    /// coordinates `s` (each texel decoded first; unknown or absent flow is zero).
    pub fn sample_flow(&self, view: usize, n: Neighbour, s: Vec2) -> Vec2 {
        let Some(codes) = &self.flows.codes[view][n.index()] else {
            return Vec2::ZERO;
        };
        let crop = &self.geometry.crop;
        let (w, h) = (crop.width as i64, crop.height as i64);
        let x = s.x - crop.x0 as f32;
        let y = s.y - crop.y0 as f32;
        if !(x.is_finite() && y.is_finite()) {
            return Vec2::ZERO;
        }
        let (x, y) = (x.clamp(-1.0, w as f32), y.clamp(-1.0, h as f32));
        let (x0, y0) = (x.floor(), y.floor());
        let (fx, fy) = (x - x0, y - y0);
        let lut = &self.flows.table;
        let mut out = Vec2::ZERO;
        for (dy, wy) in [(0i64, 1.0 - fy), (1, fy)] {
            for (dx, wx) in [(0i64, 1.0 - fx), (1, fx)] {
                let xi = (x0 as i64 + dx).clamp(0, w - 1);
                let yi = (y0 as i64 + dy).clamp(0, h - 1);
                let c = codes[(yi * w + xi) as usize];
                let known = c[0] != i8::MIN && c[1] != i8::MIN;
                if known {
                    let d = Vec2::new(
                        lut[(c[0] as i32 + 128) as usize],
                        lut[(c[1] as i32 + 128) as usize],
                    );
                    out += d * (wx * wy);
                }
            }
        }
        out
    }
}

/// One flow texel's displacement; unknown is zero.
#[inline]
pub fn decode_flow(c: [i8; 2], q: &LogQuantizer) -> Vec2 {
    if c[0] == UNKNOWN_CODE || c[1] == UNKNOWN_CODE {
        return Vec2::ZERO;
    }
    Vec2::new(q.decode(c[0]), q.decode(c[1]))
}
