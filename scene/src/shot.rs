//! Rendering a scene's frames ([`Shot`]): each walker's pose made resident when a frame
//! first needs it (read from the field as the plan says: only its views, flows and
//! conditions), relit for the walker's heading and the frame's lighting, kept while the
//! resident poses fit in a stated memory budget (the least recently used leaves first),
//! and relit again only when the lighting it was relit with changes.
//!
//! A shot is also what a viewer draws ([`Shot::live`]): frames at any time and camera,
//! drawn into kept targets without a readback ([`Shot::draw_at`]), the scene edited
//! between frames ([`Shot::edit`]; what an edit changes is made again, nothing else).
//!
//! The lighting of a frame is the scene's at its time: a mix of at most two maps (a
//! cross-fade), turned by the yaw and scaled by the intensity, in the scene frame. A
//! walker turned by heading `h` sees it turned by `−h`. The environment backdrop is the
//! same lighting, seen from the scene frame.

use std::borrow::Cow;
use std::collections::HashMap;
use std::sync::Arc;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::Instant;

use frf_core::env::{EnvMap, EnvSource};
use frf_core::image::RgbImage;
use frf_core::io::read_photo;
use frf_reflectance::FieldFile;
use frf_reflectance::container::ReadAt;
use frf_reflectance::hull::VoxelHull;
use frf_reflectance::sun_depth::Occluder;
use frf_reflectance::yaw_light::{YawLight, YawTerm};
use frf_reflectance::yaw_table::YawTable;

use super::plan::{FramePlan, Plan, PosePlan, ShotFrame};
use super::{BackdropSpec, LightingAt, Placement, Scene, ShadowSpec, TimeInterpolation};
use crate::error::{Result, SceneError};
use frf_core::BadArgument;
use frf_core::camera::{Camera, Rigid};
use frf_core::grid::PoseStep;
use frf_render::composite::Backdrop;
use frf_render::footprint::PixelBox;
use frf_render::gpu::composite::DrawnFrame;
use frf_render::motion::pose_motion;
use frf_render::reduced_views::ReducedViews;
use frf_render::renderer::{
    Device, DeviceBackdrop, Frame, FrameInFlight, Resident, SceneShadow, Walker,
};
use frf_render::resident::{Lighting, PoseSource};
use frf_render::shadow::{ShadowMaps, traced_shadow};

/// The share of the memory budget, `1 / DECODED_SHARE`, that keeps views' basis images
/// decoded between reads ([`FieldFile::keep_decoded`]), besides the resident poses'.
pub const DECODED_SHARE: u64 = 4;

/// How a shot is rendered.
#[derive(Debug, Clone, Copy)]
pub struct ShotOptions {
    /// Most bytes the resident poses may hold together (and a quarter of it again for
    /// views kept decoded, [`DECODED_SHARE`]).
    pub memory_budget: u64,
    /// Read, relight and draw only what the plan says (else every view, flow and
    /// condition of the poses drawn).
    pub planned: bool,
    /// Median-cut lights of a traced shadow.
    pub traced_lights: usize,
    /// Every walker at this level of detail ([`frf_render::detail`]); `None`: the plan's
    /// choice per walker (full detail without a plan).
    pub detail: Option<u8>,
    /// How far a walker's own light may move from the one its poses were relit for
    /// before they are relit again ([`LightTolerance`]).
    pub light_tolerance: LightTolerance,
    /// Whether walkers standing between another and a sun shade it
    /// ([`frf_reflectance::sun_depth::Occluder`]); `false` is the ablation.
    pub walker_shadows: bool,
}

/// How far a walker's own light (its heading, the probes' weights where it stands) may
/// move from the one its resident poses were relit for before they are relit: a walker
/// that turns or walks between probes is then relit every few frames rather than every
/// frame. A light that turns (its lighting keys' yaw) turns every walker's light alike, by
/// the same turn relative to it as the walker's own turn the other way: the tolerance on
/// heading holds for the two together (with probes, whose maps the keys do not turn, for
/// the maps and the scene's sun each). Zero relights at every change (exact).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct LightTolerance {
    /// Radians of heading, the walker's relative to the light's maps and to its sun as
    /// the lighting keys turn them.
    pub heading: f32,
    /// Of any probe's weight.
    pub weight: f32,
}

impl LightTolerance {
    /// Exact: every change relights.
    pub const EXACT: Self = Self {
        heading: 0.0,
        weight: 0.0,
    };

    /// What shots use unless told otherwise: 2° of heading, 2 % of a probe's weight.
    /// Chosen on `scenes/bend.toml` (the small oracle field of every third pose, 12 fps,
    /// the heading turning 1.3° a frame): against relighting every change, the walker's
    /// layer over all 69 frames at 50.6 dB with 1°, 41.3 with 2°, 38.9 with 3° and 4°;
    /// against the stage's truth 24.55 dB exact, 24.59 with 2°, 24.60 with 8° (the
    /// render's own error dominates); poses relit 114, 68, 52, 49 times. Reported on
    /// `scenes/crossing.toml` in docs/results/scene.md.
    pub const DEFAULT: Self = Self {
        heading: 2.0 * std::f32::consts::PI / 180.0,
        weight: 0.02,
    };

    /// Whether poses relit for `lit` still serve a walker whose light is `now` (the
    /// walkers in the way of its suns where they were, [`OCCLUDER_STEP_M`]).
    fn holds(&self, lit: &WalkerLight, now: &WalkerLight) -> bool {
        if lit.key == now.key && lit.yaw == now.yaw {
            return true;
        }
        if lit.occluder_key != now.occluder_key {
            return false;
        }
        // How far the light's maps and its sun have turned relative to the walker since
        // it was relit, the farther of the two.
        let wrap = |a: f32| {
            (a + std::f32::consts::PI).rem_euclid(std::f32::consts::TAU) - std::f32::consts::PI
        };
        let turned = |k: usize| wrap((now.yaw[k] - now.heading) - (lit.yaw[k] - lit.heading)).abs();
        let turn = turned(0).max(turned(1));
        let weight =
            |w: &[(usize, f32)], k: usize| w.iter().find(|p| p.0 == k).map_or(0.0, |p| p.1);
        let moved = (lit.weights.iter().chain(&now.weights))
            .map(|&(k, _)| (weight(&lit.weights, k) - weight(&now.weights, k)).abs())
            .fold(0.0f32, f32::max);
        // A light turning by the tolerance a frame holds every other frame, however the
        // angles round: a ten-thousandth of the tolerance's slack (none when exact).
        turn <= self.heading * (1.0 + 1e-4) && moved <= self.weight
    }

    /// The light of those `ahead` (the frames after `now`'s, in order) a walker lit now
    /// is relit for: the last of those up to the first that does not hold `now` (when
    /// `shared`, that has not `now`'s key: walkers of one key share its resident), or
    /// `now`. A light turning steadily then holds for twice as many frames as one relit
    /// for `now`, within the same tolerance (the frame is lit for the middle of its run).
    fn farthest<'a>(
        &self,
        now: &'a WalkerLight,
        ahead: impl IntoIterator<Item = &'a WalkerLight>,
        shared: bool,
    ) -> &'a WalkerLight {
        let mut chosen = now;
        for light in ahead {
            if !self.holds(light, now) || (shared && light.key != now.key) {
                break;
            }
            chosen = light;
        }
        chosen
    }
}

/// Whether a resident made from `have` serves a walker that needs `want` (`None`:
/// everything).
fn covers(have: &Option<PosePlan>, want: Option<&PosePlan>) -> bool {
    let within = |w: &[bool], h: &[bool]| w.iter().zip(h).all(|(&w, &h)| !w || h);
    match (have, want) {
        (None, _) => true,
        (Some(_), None) => false,
        (Some(h), Some(w)) => {
            within(&w.views, &h.views)
                && w.flows.iter().zip(&h.flows).all(|(w, h)| within(w, h))
                && within(&w.pose_flows, &h.pose_flows)
                && within(&w.conditions, &h.conditions)
                && (!w.shadow_maps || h.shadow_maps)
                && (!w.hull || h.hull)
                && w.level == h.level
        }
    }
}

/// Bytes the cache's residents hold: each its own, and what they share (basis codes,
/// motion) once for those that share it.
fn cache_bytes(cache: &[Cached]) -> u64 {
    let mut seen: Vec<usize> = Vec::new();
    let mut total = 0;
    for c in cache {
        total += c.bytes;
        for &(id, bytes) in &c.shared {
            if !seen.contains(&id) {
                seen.push(id);
                total += bytes;
            }
        }
    }
    total
}

/// Shadow maps by pose and level of detail (`None`: the field holds none for the pose).
type KeptMaps = HashMap<(u32, u8), Option<Arc<ShadowMaps>>>;

/// A walker's cache slot in a frame, and between two poses the later pose's slot and the
/// fraction of the way to it.
type Slot = (usize, Option<(usize, f32)>);

/// A lighting, as a key that tells two apart.
#[derive(Debug, Clone, PartialEq)]
struct LightingKey {
    maps: Vec<(String, u32)>,
    yaw: u32,
    intensity: u32,
    /// The sun's direction, radius and illuminance, as bits.
    sun: Option<[u32; 7]>,
}

impl LightingKey {
    /// Whether `other` is this lighting turned (only its yaw, and so its sun's direction,
    /// differ): what a walker's light tolerance may hold ([`LightTolerance`]).
    fn turned_alike(&self, other: &Self) -> bool {
        self.maps == other.maps
            && self.intensity == other.intensity
            && self.sun.is_some() == other.sun.is_some()
    }

    fn of(l: &LightingAt) -> Self {
        Self {
            maps: l
                .maps
                .iter()
                .map(|(e, w)| (e.to_string(), w.to_bits()))
                .collect(),
            yaw: l.yaw.to_bits(),
            intensity: l.intensity.to_bits(),
            sun: l.sun.map(|s| {
                let (d, e) = (s.direction(), s.illuminance());
                [d.x, d.y, d.z, s.radius(), e[0], e[1], e[2]].map(f32::to_bits)
            }),
        }
    }
}

/// A frame's lighting in the scene frame: the map it composes (what the backdrop and
/// traced shadows show) and the same light as its maps' yaw tables read it (what relights
/// the walkers).
struct World {
    env: EnvMap,
    light: YawLight,
    /// Toward each sun of the light (scene frame, unit): the maps' suns as their terms
    /// turn them, and the scene's sun.
    sun_directions: Vec<glam::Vec3>,
    /// With probes: each probe's map (turned and scaled) and its term, and the sun's term,
    /// which light the walkers where they stand instead of `light`.
    probes: Option<ProbeLights>,
}

/// The scene's probes under a frame's lighting (see [`World`]).
struct ProbeLights {
    maps: Vec<EnvMap>,
    terms: Vec<YawTerm>,
    sun: Option<YawTerm>,
    /// The scene's sun, as turned and scaled at the frame.
    sun_light: Option<frf_core::sun::Sun>,
}

/// A walker's own light at a frame: its heading and the probes' weights where it stands,
/// and that as bits, which tell two apart (see [`Cached::lit`]).
#[derive(Debug, Clone)]
struct WalkerLight {
    heading: f32,
    /// How far the lighting's keys have turned its maps and its sun at the frame
    /// (radians): the walker is lit by each turned by that less its heading. Probes' maps
    /// do not turn with the keys (0), the scene's sun does.
    yaw: [f32; 2],
    weights: Vec<(usize, f32)>,
    /// How much farther the keys have turned the light than the frame's own lighting it
    /// is relit under (radians): nonzero for a light looked ahead to
    /// ([`LOOK_AHEAD_FRAMES`]).
    ahead: f32,
    key: Vec<u32>,
    /// The other walkers in the way of its suns, in its frame ([`Occluder`]), and where
    /// they stand relative to it, to [`OCCLUDER_STEP_M`] and [`OCCLUDER_STEP_RAD`]
    /// (with their poses): poses are relit when that changes.
    occluders: Vec<Occluder>,
    occluder_key: Vec<i64>,
}

/// How far another walker in the way of a walker's sun moves (metres), or turns
/// (radians), relative to it before the walker is relit: its cast shadow moves as far,
/// under a sharp sun at most a few pixels of a captured view.
pub const OCCLUDER_STEP_M: f32 = 0.02;
/// (See [`OCCLUDER_STEP_M`].)
pub const OCCLUDER_STEP_RAD: f32 = 2.0 * std::f32::consts::PI / 180.0;

/// Frames ahead whose light a walker may be relit for, where it holds the light of the
/// frame relit ([`LightTolerance::farthest`]): a light turning a quarter of the tolerance
/// a frame or faster is relit half as often.
pub const LOOK_AHEAD_FRAMES: usize = 4;

impl WalkerLight {
    fn new(heading: f32, yaw: [f32; 2], weights: Vec<(usize, f32)>) -> Self {
        let mut key = vec![heading.to_bits()];
        for &(k, w) in &weights {
            key.extend([k as u32, w.to_bits()]);
        }
        Self {
            heading,
            yaw,
            weights,
            ahead: 0.0,
            key,
            occluders: Vec::new(),
            occluder_key: Vec::new(),
        }
    }

    /// With walker `j`, whose hull is that of pose `pose`, in the way at
    /// `here_from_there` (its frame into this walker's).
    fn with_occluder(
        &mut self,
        j: usize,
        (pose, hull): (u32, Arc<VoxelHull>),
        here_from_there: Rigid,
    ) {
        let step = |v: f32, s: f32| (v / s).round() as i64;
        let t = here_from_there.translation;
        let turn = here_from_there.rotation.x_axis;
        self.occluder_key.extend([
            j as i64,
            i64::from(pose),
            step(t.x, OCCLUDER_STEP_M),
            step(t.z, OCCLUDER_STEP_M),
            step(turn.z.atan2(turn.x), OCCLUDER_STEP_RAD),
        ]);
        self.key.extend(
            self.occluder_key[self.occluder_key.len() - 5..]
                .iter()
                .map(|&v| v as u32),
        );
        self.occluders.push(Occluder {
            hull,
            here_from_there,
        });
    }
}

/// Two bodies' radii, and a margin for the hulls' extent: how near the line toward a
/// sun another walker stands to shade one ([`may_shade`]).
const SHADE_WIDTH_M: f32 = 1.0;

/// A sun as [`may_shade`] reads it: worked out once a frame, not once a pair.
#[derive(Debug, Clone, Copy)]
enum SunReach {
    /// Below the horizon: no one shades anyone.
    Below,
    /// Straight overhead: a walker shades only what it stands over.
    Overhead,
    /// Toward `toward` (unit, on the ground), a person's shadow `reach` metres long
    /// ([`frf_render::shadow_reach`]).
    Toward { toward: glam::Vec2, reach: f32 },
}

impl SunReach {
    /// The sun toward `d` (unit, scene frame).
    fn of(d: glam::Vec3) -> Self {
        use frf_render::shadow_reach::{NOMINAL_SUBJECT, shadow_reach};
        let horizontal = glam::Vec2::new(d.x, d.z);
        if d.y <= 0.0 {
            SunReach::Below
        } else if horizontal.length() < 1e-6 {
            SunReach::Overhead
        } else {
            SunReach::Toward {
                toward: horizontal.normalize(),
                reach: shadow_reach(d.y.asin(), NOMINAL_SUBJECT),
            }
        }
    }
}

/// Whether a walker standing at `there` may shade one at `here` under `suns`: it stands
/// toward one of them, within a body's width of the line from `here` toward it, and no
/// farther than the shadow of a person reaches under it.
fn may_shade(here: glam::Vec3, there: glam::Vec3, suns: &[SunReach]) -> bool {
    let rel = glam::Vec2::new(there.x - here.x, there.z - here.z);
    suns.iter().any(|sun| match *sun {
        SunReach::Below => false,
        SunReach::Overhead => rel.length() < SHADE_WIDTH_M,
        SunReach::Toward { toward, reach } => {
            let along = rel.dot(toward);
            let across = (rel - toward * along).length();
            along > -SHADE_WIDTH_M && along < reach + SHADE_WIDTH_M && across < SHADE_WIDTH_M
        }
    })
}

/// A frame's light as its walkers see it: the frame, where each walker stands, its suns,
/// the turn of the keys' light (maps, sun) and how much farther that is than the light
/// walkers are relit under ([`WalkerLight::ahead`]).
struct FrameLight {
    fp: FramePlan,
    placements: Vec<Placement>,
    suns: Vec<SunReach>,
    yaw: [f32; 2],
    ahead: f32,
}

/// The map that lights a walker under `world` (scene frame): the scene's, or with probes
/// theirs mixed by `weights` with the scene's sun in it.
fn walker_map(world: &World, weights: &[(usize, f32)]) -> Result<EnvMap> {
    let Some(p) = &world.probes else {
        return Ok(world.env.clone());
    };
    let mixed: Vec<(&EnvMap, f32)> = weights.iter().map(|&(k, w)| (&p.maps[k], w)).collect();
    let mixed = EnvMap::mix(&mixed)?;
    Ok(match &p.sun_light {
        Some(s) => s.lit(&mixed)?,
        None => mixed,
    })
}

struct Cached {
    pose: u32,
    /// The walker's light it is relit for (its heading, and the probes' weights where it
    /// stood).
    lit: WalkerLight,
    /// The walker it serves alone, when that walker turns (a walker on a path: relit in
    /// place as it turns); `None`: any walker of its heading.
    owner: Option<usize>,
    /// What it was made from (`None`: every view, flow and condition).
    plan: Option<PosePlan>,
    lighting: LightingKey,
    resident: Resident,
    /// The resident's own bytes, and what it shares with residents of the same views
    /// (identities and bytes, [`Resident::shared`]), measured when made or relit.
    bytes: u64,
    shared: Vec<(usize, u64)>,
    last_frame: usize,
}

/// What happened while rendering the shot so far.
#[derive(Debug, Clone, Default, PartialEq, serde::Serialize)]
pub struct ShotCounters {
    /// Poses made resident (read and relit), counting relights for a new lighting.
    pub poses_made_resident: usize,
    /// Of those, relights of a pose already resident under another lighting.
    pub relights: usize,
    /// Poses dropped to stay within the budget.
    pub evictions: usize,
    /// Most bytes resident at once.
    pub peak_resident_bytes: u64,
    /// Seconds reading and relighting poses.
    pub residency_seconds: f64,
    /// Views' basis images read from those kept decoded, and decoded, for the field so
    /// far ([`DECODED_SHARE`]).
    pub basis_views_reused: u64,
    /// (See `basis_views_reused`.)
    pub basis_views_decoded: u64,
    /// Reduced views and flows (level of detail) taken from those kept between
    /// residencies, and reduced, so far ([`frf_render::reduced_views`]).
    pub reduced_reused: u64,
    /// (See `reduced_reused`.)
    pub reduced_made: u64,
    /// Yaw tables made (one a map, and one for the scene's sun, whatever the turns).
    pub yaw_tables: usize,
    /// Poses' motion toward a neighbouring pose made ([`pose_motion`]); a walker whose
    /// views another walker's copy holds shares that copy's instead.
    pub motions_made: usize,
    /// Times a pose's shadow maps were read from the field (once a pose and level of
    /// detail: every walker of it shares the copy read).
    pub shadow_maps_read: usize,
}

/// One rendered frame of a shot.
#[derive(Debug, Clone)]
pub struct ShotResult {
    /// The frame.
    pub frame: Frame,
    /// Per walker: the pose drawn (the earlier, between two).
    pub poses: Vec<u32>,
    /// Per walker, between two poses: the later and the fraction of the way to it.
    pub between: Vec<Option<(u32, f32)>>,
    /// Poses made resident (read and relit) for this frame.
    pub made_resident: Vec<u32>,
}

/// A frame of a shot drawn and submitted, not yet read back ([`Shot::submit`]).
/// It carries [`ShotResult`]'s fields but the frame.
pub struct ShotInFlight {
    frame: FrameInFlight,
    poses: Vec<u32>,
    between: Vec<Option<(u32, f32)>>,
    made_resident: Vec<u32>,
}

/// How far a shot's shadow reaches ([`Shot::shadow_reach`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ShadowReach {
    /// Elevation of the lowest light that makes the shadow, degrees.
    pub elevation_deg: f32,
    /// How far from the subject's axis its shadow reaches, metres.
    pub reach_m: f32,
    /// Side of the field's patch of maps, metres.
    pub patch_side_m: f32,
}

impl ShadowReach {
    /// Whether the shadow reaches past where the maps begin to fade.
    pub fn cut(&self) -> bool {
        self.reach_m > 0.5 * self.patch_side_m * frf_render::shadow::EDGE_FADE_FROM
    }

    /// The patch side that would hold the shadow whole, metres.
    pub fn side_needed_m(&self) -> f32 {
        frf_render::shadow_reach::patch_side_holding(self.reach_m)
    }
}

/// A scene being rendered on a field (see the module docs).
pub struct Shot<'a, R: ReadAt> {
    scene: Cow<'a, Scene>,
    field: &'a FieldFile<R>,
    device: Device,
    plan: Plan,
    options: ShotOptions,
    envs: HashMap<String, EnvMap>,
    /// The yaw tables of the maps lit so far (and of a scene's sun in a map of its own),
    /// by map: every walker and every turn of the light reads them.
    tables: HashMap<String, Arc<YawTable>>,
    world: Option<(LightingKey, Option<Arc<World>>)>,
    backdrop: Option<(LightingKey, DeviceBackdrop)>,
    plate: Option<RgbImage>,
    cache: Vec<Cached>,
    /// Views reduced to a level of detail, kept between residencies (the same share of
    /// the budget as the decoded views).
    reduced: ReducedViews,
    counters: ShotCounters,
    /// Frames drawn at a time and camera of the caller's ([`Shot::draw_at`]).
    live_frames: usize,
    /// Per walker, the cache slots its poses took last frame: looked at first, so that
    /// a frame's search of the cache grows with its walkers, not with their square.
    last_slots: Vec<Vec<usize>>,
    /// Whether every frame of the planned shot has one lighting and every walker one
    /// heading: its poses then let go of their basis codes once lit
    /// ([`Device::release_basis`]), and hold what a pre-lit pose holds.
    held_light: bool,
    /// Per walker: whether its own light changes during the shot (it turns, or moves
    /// between probes, [`Scene::walker_light_changes`]): its residents are its own, relit
    /// in place.
    own_light: Vec<bool>,
    /// The visual hulls read so far (the walkers in the way of another's suns), by pose.
    hulls: HashMap<u32, Option<Arc<VoxelHull>>>,
    /// The shadow maps read so far, by pose and level of detail: every walker of a pose
    /// shares one copy.
    shadow_maps: std::sync::Mutex<KeptMaps>,
    /// How many times shadow maps were read from the field.
    maps_read: AtomicUsize,
}

impl<'a, R: ReadAt> Shot<'a, R> {
    /// A shot of `frames` of `scene` on `field`, rendered on `device`.
    pub fn new(
        scene: &'a Scene,
        field: &'a FieldFile<R>,
        device: Device,
        frames: &[ShotFrame],
        options: ShotOptions,
    ) -> Result<Self> {
        Self::with_scene(Cow::Borrowed(scene), field, device, frames, options)
    }

    /// A shot of `scene` on `field` drawn at any time and camera ([`Shot::draw_at`],
    /// [`Shot::render_at`]): every view, flow and condition of the poses drawn is read
    /// (nothing is planned), and the scene may change between frames ([`Shot::edit`]).
    pub fn live(
        scene: Scene,
        field: &'a FieldFile<R>,
        device: Device,
        options: ShotOptions,
    ) -> Result<Self> {
        let size = scene
            .size
            .unwrap_or((field.header().width, field.header().height));
        let frames = scene.shot_frames(0..1, size)?;
        let options = ShotOptions {
            planned: false,
            ..options
        };
        Self::with_scene(Cow::Owned(scene), field, device, &frames, options)
    }

    fn with_scene(
        mut scene: Cow<'a, Scene>,
        field: &'a FieldFile<R>,
        device: Device,
        frames: &[ShotFrame],
        options: ShotOptions,
    ) -> Result<Self> {
        // Walkers on paths turn on their planted foot where the hulls tell the feet.
        if scene.instances.iter().any(|i| i.moves())
            && let Some(track) = frf_reflectance::gait_speed::FootTrack::of(field)?
        {
            let gait = crate::Gait::of_field(field)?;
            let stance = |t| {
                track
                    .stance(t)
                    .map(|(point, both)| crate::walk::Stance { point, both })
            };
            for instance in &mut scene.to_mut().instances {
                instance.plant(&gait, &stance);
            }
        }
        if let Some(most) = device.max_walkers()
            && scene.instances.len() > most
        {
            return Err(BadArgument::new(
                "[[instance]]",
                format!("{} walkers", scene.instances.len()),
                format!("at most {most} walkers a frame on {}", device.name()),
            )
            .into());
        }
        let plan = Plan::new(&scene, field, frames)?;
        let keys: Vec<LightingKey> = frames
            .iter()
            .map(|f| LightingKey::of(&scene.lighting_at(f.time)))
            .collect();
        let own_light: Vec<bool> = (0..scene.instances.len())
            .map(|i| scene.walker_light_changes(i, options.walker_shadows))
            .collect();
        let held_light = options.planned
            && keys.windows(2).all(|w| w[0] == w[1])
            && !own_light.iter().any(|&t| t);
        // Views read again (by another walker's heading, or a new light) are not decoded
        // again: a quarter of the budget keeps them decoded.
        field.keep_decoded(options.memory_budget / DECODED_SHARE);
        let plate = match &scene.backdrop {
            BackdropSpec::Plate(p) => Some(read_photo(p)?),
            _ => None,
        };
        Ok(Self {
            scene,
            field,
            device,
            plan,
            options,
            envs: HashMap::new(),
            tables: HashMap::new(),
            world: None,
            backdrop: None,
            plate,
            cache: Vec::new(),
            reduced: ReducedViews::with_budget(options.memory_budget / DECODED_SHARE),
            counters: ShotCounters::default(),
            live_frames: 0,
            last_slots: Vec::new(),
            held_light,
            own_light,
            hulls: HashMap::new(),
            shadow_maps: Default::default(),
            maps_read: AtomicUsize::new(0),
        })
    }

    /// The plan.
    pub fn plan(&self) -> &Plan {
        &self.plan
    }

    /// How far the shot's shadow reaches against the field's patch of maps
    /// ([`frf_render::shadow_reach`]), under the lowest of its lighting keys' shadow-making
    /// lights, for the hull of the first pose drawn (a nominal person without one);
    /// `None` when no map is drawn or nothing lights the ground from above.
    pub fn shadow_reach(&mut self) -> Result<Option<ShadowReach>> {
        use frf_render::shadow_reach::{
            NOMINAL_SUBJECT, lowest_shadow_light_elevation, shadow_reach,
        };
        let Some(spec) = &self.field.header().shadows else {
            return Ok(None);
        };
        let patch_side_m = spec.ground.extent_m;
        if self.scene.shadow != super::ShadowSpec::Maps || !self.plan.ground_seen {
            return Ok(None);
        }
        // Each map once, however many keys name it (a light's elevations do not turn with
        // its yaw): 2000 keys of one map reduced it 2000 times.
        let mut sources: Vec<EnvSource> = Vec::new();
        for k in &self.scene.lighting {
            if !sources.contains(&k.env) {
                sources.push(k.env.clone());
            }
        }
        let mut envs = Vec::new();
        for source in &sources {
            envs.extend(self.env(source)?);
        }
        let Some(elevation) = lowest_shadow_light_elevation(&envs) else {
            return Ok(None);
        };
        let hull = match self.plan.poses.first() {
            Some(p) => self.field.hull_shared(p.pose)?,
            None => None,
        };
        let subject = hull
            .and_then(|h| h.bounds())
            .map_or(NOMINAL_SUBJECT, |(lo, hi)| {
                let radius = [lo.x, hi.x]
                    .iter()
                    .flat_map(|&x| [lo.z, hi.z].map(|z| x.hypot(z)))
                    .fold(0.0f32, f32::max);
                (hi.y, radius)
            });
        Ok(Some(ShadowReach {
            elevation_deg: elevation.to_degrees(),
            reach_m: shadow_reach(elevation, subject),
            patch_side_m,
        }))
    }

    /// What happened so far.
    pub fn counters(&self) -> &ShotCounters {
        &self.counters
    }

    /// Whether only what the plan says is read, relit and drawn.
    pub fn planned(&self) -> bool {
        self.options.planned
    }

    /// The device, in words.
    pub fn device(&self) -> String {
        self.device.name()
    }

    /// The GPU adapter and why it was taken; `None` on the CPU.
    pub fn adapter(&self) -> Option<&frf_render::gpu::adapter::AdapterReport> {
        self.device.adapter_report()
    }

    /// The environment of `source`, loaded once.
    fn env(&mut self, source: &EnvSource) -> Result<Option<EnvMap>> {
        let key = source.to_string();
        if let Some(e) = self.envs.get(&key) {
            return Ok(Some(e.clone()));
        }
        let Some(e) = source.load()? else {
            return Ok(None);
        };
        self.envs.insert(key, e.clone());
        Ok(Some(e))
    }

    /// The map of `probe`: its environment, or that less its suns ([`frf_core::sun::Sun::extract`], as
    /// many as a relighting takes out) when it stands in shade; made once.
    fn probe_map(&mut self, probe: &crate::Probe) -> Result<EnvMap> {
        let e = self.env(&probe.env)?.ok_or(SceneError::Misuse(
            "a probe without a map (refused when the scene is read)",
        ))?;
        if probe.suns {
            return Ok(e);
        }
        let key = format!("{} (shade)", probe.env);
        if let Some(shade) = self.envs.get(&key) {
            return Ok(shade.clone());
        }
        let most = frf_reflectance::sun_light::MAX_SUNS;
        let shade = frf_core::sun::Sun::extract_all(&e, most)?.1.unwrap_or(e);
        self.envs.insert(key, shade.clone());
        Ok(shade)
    }

    /// The yaw table of the map `key` (made by `map` the first time).
    fn table(
        &mut self,
        key: String,
        map: impl FnOnce() -> Result<EnvMap>,
    ) -> Result<Arc<YawTable>> {
        if let Some(t) = self.tables.get(&key) {
            return Ok(t.clone());
        }
        let projector = self.field.projector_shared()?.clone();
        let table = Arc::new(YawTable::new(projector, &map()?, self.scene.floor));
        self.tables.insert(key, table.clone());
        self.counters.yaw_tables += 1;
        Ok(table)
    }

    /// The lighting of the scene frame at `l`: `None` without an environment.
    fn world_lighting(&mut self, l: &LightingAt) -> Result<Option<Arc<World>>> {
        let key = LightingKey::of(l);
        if let Some((k, world)) = &self.world
            && *k == key
        {
            return Ok(world.clone());
        }
        let mut maps = Vec::new();
        let mut terms = Vec::new();
        for (source, weight) in &l.maps {
            match (self.env(source)?, l.sun) {
                (Some(e), _) => {
                    let table = self.table(source.to_string(), || Ok(e.clone()))?;
                    terms.push(YawTerm {
                        table,
                        weight: weight * l.intensity,
                        yaw: l.yaw,
                    });
                    maps.push((e.rotated(l.yaw).scaled(l.intensity), *weight));
                }
                // A sun alone: a black sky of the built-in sky's texels holds it.
                (None, Some(_)) => maps.push((EnvMap::uniform([0.0; 3], 128), *weight)),
                (None, None) => {
                    self.world = Some((key, None));
                    return Ok(None);
                }
            }
        }
        let mut env = if maps.len() == 1 && maps[0].1 == 1.0 {
            maps.remove(0).0
        } else {
            EnvMap::mix(&maps.iter().map(|(e, w)| (e, *w)).collect::<Vec<_>>())?
        };
        let mut sun_term = None;
        if let (Some(sun), Some(base)) = (&l.sun, self.scene.sun) {
            // The scene's sun in a map of its own, black but for it, of the world map's
            // texels: one table for the shot, turned and weighted as the lighting keys turn
            // and scale it (`Scene::lighting_at`), so that a turning light reads one table
            // (on the device, one held) instead of making one at each turn.
            let (w, h) = env.image().size();
            let table = self.table(format!("sun {base:?} {w}x{h}"), || {
                let black = EnvMap::from_image(RgbImage::new(w, h, [0.0; 3]))?;
                Ok(base.lit(&black)?)
            })?;
            let term = YawTerm {
                table,
                weight: l.intensity,
                yaw: l.yaw,
            };
            terms.push(term.clone());
            sun_term = Some(term);
            env = sun.lit(&env)?;
        }
        let probes = match self.scene.probes.clone() {
            None => None,
            Some(p) => {
                let (mut maps, mut terms) = (Vec::new(), Vec::new());
                for (k, probe) in p.probes.iter().enumerate() {
                    let used = self.plan.probes_used.get(k).copied().unwrap_or(true);
                    if self.options.planned && !used {
                        // No walker stands where it weighs: a black map of the scene's
                        // texels holds its place, never read with a weight.
                        let (w, h) = env.image().size();
                        let black = EnvMap::from_image(RgbImage::new(w, h, [0.0; 3]))?;
                        let table = self.table(format!("unused {w}x{h}"), || Ok(black.clone()))?;
                        maps.push(black);
                        terms.push(YawTerm {
                            table,
                            weight: 0.0,
                            yaw: 0.0,
                        });
                        continue;
                    }
                    let e = self.probe_map(probe)?;
                    let shade = if probe.suns { "" } else { " (shade)" };
                    let table = self.table(format!("{}{shade}", probe.env), || Ok(e.clone()))?;
                    let weight = probe.intensity * l.intensity;
                    maps.push(e.rotated(probe.yaw).scaled(weight));
                    terms.push(YawTerm {
                        table,
                        weight,
                        yaw: probe.yaw,
                    });
                }
                Some(ProbeLights {
                    maps,
                    terms,
                    sun: sun_term,
                    sun_light: l.sun,
                })
            }
        };
        let light = YawLight::new(terms);
        let mut sun_directions = Vec::new();
        let all_terms = light
            .terms()
            .iter()
            .chain(probes.iter().flat_map(|p| &p.terms));
        for t in all_terms {
            for s in t.table.suns()? {
                sun_directions.push(glam::Mat3::from_rotation_y(t.yaw) * s.direction());
            }
        }
        let world = Arc::new(World {
            env,
            light,
            sun_directions,
            probes,
        });
        self.world = Some((key, Some(world.clone())));
        Ok(Some(world))
    }

    /// The scene shot.
    pub fn scene(&self) -> &Scene {
        &self.scene
    }

    /// The field drawn.
    pub fn field(&self) -> &'a FieldFile<R> {
        self.field
    }

    /// The device frames are drawn on.
    pub fn render_device(&self) -> &Device {
        &self.device
    }

    /// Bytes the resident poses hold now.
    pub fn resident_bytes(&self) -> u64 {
        cache_bytes(&self.cache)
    }

    /// Changes the scene by `f`; what the change makes stale is made again when a frame
    /// next needs it (poses relit and shadowed anew when the floor or the shadow changes,
    /// the backdrop when it changes; a new lighting is told by its key anyway).
    pub fn edit(&mut self, f: impl FnOnce(&mut Scene)) -> Result<()> {
        let before = (
            self.scene.floor,
            self.scene.shadow,
            self.scene.backdrop.clone(),
        );
        f(self.scene.to_mut());
        self.own_light = (0..self.scene.instances.len())
            .map(|i| {
                self.scene
                    .walker_light_changes(i, self.options.walker_shadows)
            })
            .collect();
        let scene = &self.scene;
        if (scene.floor, scene.shadow) != (before.0, before.1) {
            self.cache.clear();
        }
        if scene.floor != before.0 {
            // The tables light the floor conditions by the floor.
            self.tables.clear();
            self.world = None;
        }
        if scene.backdrop != before.2 {
            self.backdrop = None;
            self.plate = match &scene.backdrop {
                BackdropSpec::Plate(p) => Some(read_photo(p)?),
                _ => None,
            };
        }
        Ok(())
    }

    /// The pose each walker shows at `time`: the walk's pose at that time, or the nearest
    /// one the field holds; between two poses when the shot morphs in time, the earlier.
    pub fn poses_at(&self, time: f64) -> Vec<u32> {
        self.frame_at(0, time).poses
    }

    /// The plan of a frame at `time` drawn as frame `index`: per walker, its pose (or the
    /// two it is between) as the shot's plan would give it.
    fn frame_at(&self, index: usize, time: f64) -> FramePlan {
        let h = self.field.header();
        let mut held: Vec<u32> = h.poses.iter().map(|p| p.pose).collect();
        held.sort_unstable();
        FramePlan::at(
            &self.scene,
            h,
            &held,
            (self.plan.interpolate, &self.plan.gait),
            (index, time),
        )
    }

    /// Draws the frame of `camera` at `time` into the kept targets of its size (on the
    /// GPU; nothing is read back): what a window shows. Poses are made resident and
    /// relit as [`Shot::render`] does; the first pass writes `timestamps` when given.
    pub fn draw_at(
        &mut self,
        encoder: &mut wgpu::CommandEncoder,
        time: f64,
        camera: &frf_core::camera::Camera,
        timestamps: frf_render::gpu::timing::Timestamps,
    ) -> Result<DrawnFrame> {
        let Device::Gpu(_) = &self.device else {
            return Err(SceneError::Misuse(
                "a frame drawn without a readback needs the GPU",
            ));
        };
        self.live_frames += 1;
        let fp = self.frame_at(self.live_frames, time);
        let slots = self.prepare(&fp)?.0;
        if let Device::Gpu(gpu) = &self.device {
            // Relights recorded for this frame go ahead of the caller's encoder.
            gpu.flush();
        }
        let walkers = self.walkers(&slots, camera, fp.time);
        let backdrop = &self.backdrop.as_ref().expect("made by prepare").1;
        let Device::Gpu(gpu) = &self.device else {
            unreachable!("checked above")
        };
        let instances = walkers
            .iter()
            .map(Walker::gpu_instance)
            .collect::<frf_render::Result<Vec<_>>>()?;
        let b = backdrop
            .gpu()
            .ok_or_else(|| SceneError::Misuse("a backdrop made resident on the CPU"))?;
        backdrop.check(camera)?;
        Ok(gpu.encode_composite(
            encoder,
            &instances,
            b,
            camera,
            self.scene.variant,
            timestamps,
        )?)
    }

    /// Renders the frame of `camera` at `time` and reads it back, as [`Shot::draw_at`]
    /// draws it (a viewer's screenshot; on the CPU too).
    pub fn render_at(
        &mut self,
        time: f64,
        camera: &frf_core::camera::Camera,
        layers: bool,
    ) -> Result<ShotResult> {
        self.live_frames += 1;
        let fp = self.frame_at(self.live_frames, time);
        self.render_plan(&fp, camera, layers)
    }

    /// The environment that lights walker `walker` at `t` seconds (scene frame): the
    /// scene's ([`Shot::lighting_at`]), or with probes theirs mixed where it stands with
    /// the scene's sun; `None` when the scene shows the field unlit. What its truth is lit
    /// by.
    pub fn walker_environment(&mut self, walker: usize, t: f64) -> Result<Option<EnvMap>> {
        let l = self.scene.lighting_at(t);
        let Some(world) = self.world_lighting(&l)? else {
            return Ok(None);
        };
        let weights = self.scene.probe_weights(walker, t);
        Ok(Some(walker_map(&world, &weights)?))
    }

    /// The environment lighting the scene (scene frame) at `t` seconds: `None` when the
    /// scene shows the field unlit.
    pub fn lighting_at(&mut self, t: f64) -> Result<Option<EnvMap>> {
        let l = self.scene.lighting_at(t);
        Ok(self.world_lighting(&l)?.map(|w| w.env.clone()))
    }

    /// The backdrop of the scene under `world` (the lighting of a frame).
    pub fn backdrop_of(&self, world: Option<&EnvMap>) -> Result<Backdrop> {
        Ok(match (&self.scene.backdrop, world) {
            (BackdropSpec::None, _) => Backdrop::None,
            (BackdropSpec::Environment(ground), Some(env)) => {
                Backdrop::environment(env.clone(), *ground)
            }
            (BackdropSpec::Environment(_), None) => {
                return Err(SceneError::Misuse(
                    "an environment backdrop without an environment",
                ));
            }
            (BackdropSpec::Plate(_), _) => Backdrop::Plate(
                self.plate
                    .clone()
                    .ok_or(SceneError::Misuse("no plate loaded"))?,
            ),
        })
    }

    /// Renders frame `frame` (one of the frames the shot was planned for).
    pub fn render(&mut self, frame: &ShotFrame, layers: bool) -> Result<ShotResult> {
        let drawn = self.submit(frame, layers)?;
        self.finish(drawn)
    }

    /// Draws frame `frame` as [`Shot::render`] does and submits it without waiting for
    /// it ([`Device::submit_frame`]): a sequence submits the next frame before it
    /// [`Shot::finish`]es this one, so that the GPU draws one while the other is read back.
    pub fn submit(&mut self, frame: &ShotFrame, layers: bool) -> Result<ShotInFlight> {
        let fp = self.frame_plan(frame)?;
        self.submit_plan(&fp, &frame.camera, layers)
    }

    /// The plan of `frame` (one of the frames the shot was planned for).
    fn frame_plan(&self, frame: &ShotFrame) -> Result<FramePlan> {
        (self.plan.frames.iter())
            .find(|f| f.index == frame.index)
            .cloned()
            .ok_or_else(|| SceneError::Internal(format!("frame {} was not planned", frame.index)))
    }

    /// Draws frame `frame` as [`Shot::render`] does and waits until the device has drawn
    /// it, reading nothing back ([`Device::draw_frame_unread`]); the poses made resident
    /// for it.
    pub fn draw_unread(&mut self, frame: &ShotFrame) -> Result<Vec<u32>> {
        let fp = self.frame_plan(frame)?;
        let (slots, made_resident) = self.prepare(&fp)?;
        let walkers = self.walkers(&slots, &frame.camera, fp.time);
        let backdrop = &self.backdrop.as_ref().expect("made by prepare").1;
        self.device
            .draw_frame_unread(&walkers, backdrop, &frame.camera, self.scene.variant)?;
        Ok(made_resident)
    }

    /// Reads back a frame [`Shot::submit`] drew.
    pub fn finish(&mut self, drawn: ShotInFlight) -> Result<ShotResult> {
        Ok(ShotResult {
            frame: self.device.finish_frame(drawn.frame)?,
            poses: drawn.poses,
            between: drawn.between,
            made_resident: drawn.made_resident,
        })
    }

    /// Renders the frame `fp` plans, seen by `camera`.
    fn render_plan(
        &mut self,
        fp: &FramePlan,
        camera: &frf_core::camera::Camera,
        layers: bool,
    ) -> Result<ShotResult> {
        let drawn = self.submit_plan(fp, camera, layers)?;
        self.finish(drawn)
    }

    /// Draws and submits the frame `fp` plans, seen by `camera`.
    fn submit_plan(
        &mut self,
        fp: &FramePlan,
        camera: &frf_core::camera::Camera,
        layers: bool,
    ) -> Result<ShotInFlight> {
        let (slots, made_resident) = self.prepare(fp)?;
        let walkers = self.walkers(&slots, camera, fp.time);
        let backdrop = &self.backdrop.as_ref().expect("made by prepare").1;
        let frame =
            self.device
                .submit_frame(&walkers, backdrop, camera, self.scene.variant, layers)?;
        Ok(ShotInFlight {
            frame,
            poses: fp.poses.clone(),
            between: fp.between.clone(),
            made_resident,
        })
    }

    /// The walkers of a frame of `camera` at `time` whose poses are the cache's `slots`
    /// (each where it stands then); a planned
    /// shot shades each within the pixels where its pose (both, between two) may show
    /// ([`frf_render::footprint::SubjectBounds::pixel_box`]).
    fn walkers(&self, slots: &[Slot], camera: &Camera, time: f64) -> Vec<Walker<'_>> {
        slots
            .iter()
            .enumerate()
            .map(|(i, &(k, between))| {
                let world_from_subject = self.scene.placement(i, time).world_from_subject();
                let resident = &self.cache[k].resident;
                let within = self.options.planned.then(|| {
                    let mut bounds = resident.bounds();
                    if let Some((after, _)) = between {
                        bounds = bounds.union(self.cache[after].resident.bounds());
                    }
                    bounds
                        .pixel_box(&camera.transformed(&world_from_subject.inverse()))
                        .unwrap_or(PixelBox::EMPTY)
                });
                Walker {
                    resident,
                    world_from_subject,
                    between: between.map(|(after, s)| (&self.cache[after].resident, s)),
                    within,
                }
            })
            .collect()
    }

    /// Makes every pose of `fp` resident and relit for the frame's lighting, and the
    /// backdrop of that lighting: the cache slots of the walkers' poses, and the poses made
    /// resident for it.
    fn prepare(&mut self, fp: &FramePlan) -> Result<(Vec<Slot>, Vec<u32>)> {
        let lighting = self.scene.lighting_at(fp.time);
        let key = LightingKey::of(&lighting);
        let world = self.world_lighting(&lighting)?;
        let world = world.as_deref();

        // Every walker's pose (both, between two), resident and relit for this lighting.
        let mut made_resident = Vec::new();
        let mut slots = Vec::with_capacity(fp.poses.len());
        let drawn = fp.poses.iter().enumerate().flat_map(|(i, &pose)| {
            [(i, pose)]
                .into_iter()
                .chain(fp.between[i].map(|(after, _)| (i, after)))
        });
        let suns = world.map_or(&[][..], |w| &w.sun_directions[..]);
        let frame = self.frame_light(fp.clone(), (suns, lighting.yaw, 0.0));
        let lights = (0..fp.poses.len())
            .map(|i| self.walker_light(&frame, i))
            .collect::<Result<Vec<_>>>()?;
        // The lights of the frames ahead, worked out when a walker is first relit.
        let mut ahead = None;
        for (i, pose) in drawn {
            let light = &lights[i];
            // A walker whose own light changes (it turns, or moves between probes) has
            // residents of its own, relit in place as its light changes.
            let owner = self.own_light[i].then_some(i);
            // The walker's own needs of the pose: a resident that covers them serves it
            // (walkers of one light seeing the same quads share one); the one it had
            // last frame, when it still does.
            let wanted = self.walker_plan(i, pose);
            let serves = |c: &Cached| {
                c.pose == pose
                    && c.owner == owner
                    && (owner.is_some() || c.lit.key == light.key)
                    && covers(&c.plan, wanted)
            };
            let found = self
                .last_slots
                .get(i)
                .and_then(|last| {
                    last.iter()
                        .copied()
                        .find(|&k| self.cache.get(k).is_some_and(serves))
                })
                .or_else(|| self.cache.iter().position(serves));
            let slot = match found {
                Some(k)
                    if self.cache[k].lighting.turned_alike(&key)
                        && self
                            .options
                            .light_tolerance
                            .holds(&self.cache[k].lit, light) =>
                {
                    k
                }
                Some(k) => {
                    // The same views under a new light, turned or moved: relit where they
                    // are, for the light ahead that holds this frame's.
                    let light =
                        &self.light_ahead(fp, (&lighting, world), &mut ahead, (i, light))?;
                    self.cache[k].lit = light.clone();
                    let t = Instant::now();
                    self.relight_cached(k, world, light)?;
                    self.counters.residency_seconds += t.elapsed().as_secs_f64();
                    self.counters.poses_made_resident += 1;
                    self.counters.relights += 1;
                    made_resident.push(pose);
                    let c = &mut self.cache[k];
                    c.lighting = key.clone();
                    // Codes let go of are uploaded again to relight.
                    (c.bytes, c.shared) = (c.resident.bytes(), c.resident.shared());
                    k
                }
                None => {
                    let wanted = wanted.cloned();
                    let light =
                        &self.light_ahead(fp, (&lighting, world), &mut ahead, (i, light))?;
                    let t = Instant::now();
                    // Another walker's copy of views that cover these lends them, basis
                    // codes and all (the first made, so that copies share one).
                    let like = self
                        .cache
                        .iter()
                        .position(|c| c.pose == pose && covers(&c.plan, wanted.as_ref()));
                    let (resident, motions) =
                        self.make_resident(pose, light, world, wanted.as_ref(), like)?;
                    self.counters.motions_made += motions;
                    self.counters.shadow_maps_read = self.maps_read.load(Ordering::Relaxed);
                    self.counters.residency_seconds += t.elapsed().as_secs_f64();
                    (
                        self.counters.basis_views_reused,
                        self.counters.basis_views_decoded,
                    ) = self.field.decoded_counts();
                    (self.counters.reduced_reused, self.counters.reduced_made) =
                        self.reduced.counts();
                    self.counters.poses_made_resident += 1;
                    made_resident.push(pose);
                    self.cache.push(Cached {
                        pose,
                        lit: light.clone(),
                        owner,
                        plan: wanted,
                        lighting: key.clone(),
                        bytes: resident.bytes(),
                        shared: resident.shared(),
                        resident,
                        last_frame: fp.index,
                    });
                    self.cache.len() - 1
                }
            };
            self.cache[slot].last_frame = fp.index;
            slots.push(slot);
        }
        self.keep_within_budget(fp.index, &mut slots)?;
        let mut flat = slots.into_iter();
        let slots: Vec<Slot> = fp
            .between
            .iter()
            .map(|b| {
                let k = flat.next().expect("a slot per pose drawn");
                (
                    k,
                    b.map(|(_, s)| (flat.next().expect("a slot per pose drawn"), s)),
                )
            })
            .collect();
        self.last_slots = slots
            .iter()
            .map(|&(k, after)| {
                [Some(k), after.map(|a| a.0)]
                    .into_iter()
                    .flatten()
                    .collect()
            })
            .collect();

        // The backdrop of this lighting.
        let stale = self.backdrop.as_ref().is_none_or(|(k, _)| *k != key);
        if stale {
            let backdrop = self.backdrop_of(world.map(|w| &w.env))?;
            self.backdrop = Some((key, self.device.backdrop(backdrop)?));
        }
        Ok((slots, made_resident))
    }

    /// The light walker `i`, whose own light at frame `fp` (under `lighting`, `world`) is
    /// `now`, is relit for ([`LightTolerance::farthest`]): that of the farthest frame of
    /// the next [`LOOK_AHEAD_FRAMES`] (at the scene's rate) whose light holds `now`, so
    /// that the frames after it hold too. A resident shared by walkers of one light is
    /// relit for one that keeps their key. `ahead`: the frames' lights, worked out the
    /// first time one is asked for.
    fn light_ahead(
        &mut self,
        fp: &FramePlan,
        (lighting, world): (&LightingAt, Option<&World>),
        ahead: &mut Option<Vec<FrameLight>>,
        (i, now): (usize, &WalkerLight),
    ) -> Result<WalkerLight> {
        let frames = match ahead {
            Some(frames) => frames,
            None => ahead.insert(self.lights_ahead(fp, lighting, world)),
        };
        // The walker's own light at each frame ahead, up to the first that does not
        // hold its light now ([`LightTolerance::farthest`]).
        let mut lights = Vec::new();
        for frame in frames.iter() {
            let light = self.walker_light(frame, i)?;
            let holds = self.options.light_tolerance.holds(&light, now);
            lights.push(light);
            if !holds {
                break;
            }
        }
        let shared = !self.own_light[i];
        Ok((self.options.light_tolerance)
            .farthest(now, &lights, shared)
            .clone())
    }

    /// The light of each of the [`LOOK_AHEAD_FRAMES`] frames after `fp` (under
    /// `lighting`, `world`), at the scene's rate, up to the first whose lighting is not
    /// the frame's turned (or, with probes, whose maps the keys do not turn, turned at
    /// all): each as the frame's lighting turned by how far the keys turn it by then
    /// ([`WalkerLight::ahead`]). None when the tolerance is exact.
    fn lights_ahead(
        &self,
        fp: &FramePlan,
        lighting: &LightingAt,
        world: Option<&World>,
    ) -> Vec<FrameLight> {
        let step = 1.0 / self.scene.fps;
        let tolerance = self.options.light_tolerance;
        let mut out = Vec::new();
        if tolerance == LightTolerance::EXACT || !(step.is_finite() && step > 0.0) {
            return out;
        }
        let key = LightingKey::of(lighting);
        for k in 1..=LOOK_AHEAD_FRAMES {
            let t = fp.time + k as f64 * step;
            let l = self.scene.lighting_at(t);
            let turn = l.yaw - lighting.yaw;
            let turned = turn != 0.0;
            if !LightingKey::of(&l).turned_alike(&key) || (turned && self.scene.probes.is_some()) {
                break;
            }
            let spin = glam::Mat3::from_rotation_y(turn);
            let suns: Vec<glam::Vec3> = world
                .map_or(&[][..], |w| &w.sun_directions[..])
                .iter()
                .map(|&d| spin * d)
                .collect();
            let frame = self.frame_at(fp.index + k, t);
            out.push(self.frame_light(frame, (&suns, l.yaw, turn)));
        }
        out
    }

    /// Frame `fp`'s light under suns toward `suns` (scene frame, unit), the lighting keys
    /// turning the light by `keys` (radians), `ahead` farther than the light walkers are
    /// relit under.
    fn frame_light(
        &self,
        fp: FramePlan,
        (suns, keys, ahead): (&[glam::Vec3], f32, f32),
    ) -> FrameLight {
        let n = self.scene.instances.len();
        let placements = (0..n).map(|i| self.scene.placement(i, fp.time)).collect();
        let maps = if self.scene.probes.is_some() {
            0.0
        } else {
            keys
        };
        FrameLight {
            placements,
            suns: suns.iter().map(|&d| SunReach::of(d)).collect(),
            yaw: [maps, keys],
            ahead,
            fp,
        }
    }

    /// Walker `i`'s own light in `frame`: its heading, the probes' weights where it
    /// stands, and the other walkers in the way of its suns ([`may_shade`]).
    fn walker_light(&mut self, frame: &FrameLight, i: usize) -> Result<WalkerLight> {
        let here = &frame.placements[i];
        let weights = self.scene.probe_weights(i, frame.fp.time);
        let mut light = WalkerLight::new(here.heading, frame.yaw, weights);
        light.ahead = frame.ahead;
        let subject_from_world = here.world_from_subject().inverse();
        for (j, there) in frame.placements.iter().enumerate() {
            let shades = self.options.walker_shadows && j != i;
            if !shades || !may_shade(here.position, there.position, &frame.suns) {
                continue;
            }
            // The nearer of the two poses it is drawn between casts the shadow.
            let pose = match frame.fp.between[j] {
                Some((after, s)) if s >= 0.5 => after,
                _ => frame.fp.poses[j],
            };
            let Some(hull) = self.hull(pose)? else {
                continue;
            };
            let here_from_there = subject_from_world.compose(&there.world_from_subject());
            light.with_occluder(j, (pose, hull), here_from_there);
        }
        Ok(light)
    }

    /// The visual hull of pose `pose`, read once.
    fn hull(&mut self, pose: u32) -> Result<Option<Arc<VoxelHull>>> {
        if let Some(h) = self.hulls.get(&pose) {
            return Ok(h.clone());
        }
        let h = self.field.hull_shared(pose)?;
        self.hulls.insert(pose, h.clone());
        Ok(h)
    }

    /// The shadow maps of pose `pose` reduced to `level`, read once.
    fn shadow_maps(&self, pose: u32, level: u8) -> Result<Option<Arc<ShadowMaps>>> {
        let mut kept = self.shadow_maps.lock().unwrap_or_else(|e| e.into_inner());
        if let Some(maps) = kept.get(&(pose, level)) {
            return Ok(maps.clone());
        }
        self.maps_read.fetch_add(1, Ordering::Relaxed);
        let maps = ShadowMaps::load(self.field, pose)?.map(|m| Arc::new(m.reduced(level)));
        kept.insert((pose, level), maps.clone());
        Ok(maps)
    }

    /// What walker `walker` needs of pose `pose` when the shot is planned (`None`:
    /// everything).
    fn walker_plan(&self, walker: usize, pose: u32) -> Option<&PosePlan> {
        if self.options.planned {
            self.plan.walker_pose(walker, pose)
        } else {
            None
        }
    }

    /// The lighting of a walker whose own light is `light` under the scene frame's
    /// lighting `world`: the scene's light, or with probes theirs weighted where it
    /// stands and the sun, turned by minus its heading.
    fn walker_lighting(&self, light: &WalkerLight, world: Option<&World>) -> Lighting {
        let Some(w) = world else {
            return Lighting::Unlit;
        };
        let scene_frame = match &w.probes {
            None => w.light.clone(),
            Some(p) => YawLight::new(
                light
                    .weights
                    .iter()
                    .map(|&(k, weight)| YawTerm {
                        weight: weight * p.terms[k].weight,
                        ..p.terms[k].clone()
                    })
                    .chain(p.sun.clone())
                    .collect(),
            ),
        };
        let occluders = light.occluders.clone();
        Lighting::Tabled(
            scene_frame
                .turned(light.ahead - light.heading)
                .with_occluders(occluders),
        )
    }

    /// Relights cache entry `k` for its walker's light `light` under `world`: its views'
    /// new coefficients, relit where they are resident, with its shadow.
    fn relight_cached(
        &mut self,
        k: usize,
        world: Option<&World>,
        light: &WalkerLight,
    ) -> Result<()> {
        let lighting = self.walker_lighting(light, world);
        let entry = &self.cache[k];
        let traced = match self.scene.shadow {
            ShadowSpec::Traced if entry.resident.has_shadow() => {
                self.traced_shadow(entry.pose, world, light)?
            }
            _ => None,
        };
        let entry = &mut self.cache[k];
        let resident = &mut entry.resident;
        match &lighting {
            // Looked up from the light's tables on the device, where there is one.
            Lighting::Tabled(l) => {
                (self.device).relight_tabled(resident, self.field, l, entry.plan.as_ref())?
            }
            _ => {
                let source =
                    (resident.source()).relit(self.field, &lighting, entry.plan.as_ref())?;
                self.device.relight(resident, &source)?;
            }
        }
        if let Some(shadow) = traced {
            self.device
                .set_shadow(resident, SceneShadow::Relit(shadow))?;
        }
        Ok(())
    }

    /// The shadow of pose `pose`'s hull under `world` seen by a walker whose own light
    /// is `light` (traced), when it has a hull and there is an environment: the scene's
    /// map, or with probes theirs mixed where it stands.
    fn traced_shadow(
        &self,
        pose: u32,
        world: Option<&World>,
        light: &WalkerLight,
    ) -> Result<Option<frf_render::shadow::RelitShadow>> {
        let (Some(hull), Some(world)) = (self.field.hull_shared(pose)?, world) else {
            return Ok(None);
        };
        let env = walker_map(world, &light.weights)?.rotated(light.ahead - light.heading);
        let ground = self
            .field
            .header()
            .shadows
            .as_ref()
            .map_or(frf_core::volume::GroundGrid::ORIGINAL, |s| s.ground);
        let lights = env.median_cut(self.options.traced_lights);
        Ok(Some(traced_shadow(&hull, &lights, ground)))
    }

    /// Reads pose `pose` as `plan` says (everything when `None`), relights it for a walker
    /// of `heading` under the scene frame's lighting `world`, and sets its shadow. With
    /// `like` (a cache entry of the same pose whose plan covers `plan`), its views are
    /// taken from there, basis codes and motion shared, instead of being read again. The
    /// resident, and how many motions toward a neighbouring pose were made for it.
    fn make_resident(
        &self,
        pose: u32,
        light: &WalkerLight,
        world: Option<&World>,
        plan: Option<&PosePlan>,
        like: Option<usize>,
    ) -> Result<(Resident, usize)> {
        let lighting = self.walker_lighting(light, world);
        let level = self
            .options
            .detail
            .unwrap_or_else(|| plan.map_or(0, |p| p.level));
        let like = like.map(|k| &self.cache[k].resident);
        let source = match like {
            Some(r) => r.source().relit(self.field, &lighting, plan)?,
            None => PoseSource::load_at(
                self.field,
                pose,
                &lighting,
                plan,
                level,
                Some(&self.reduced),
            )?,
        };
        let mut resident = self.device.make_resident_sharing(&source, like)?;
        if self.held_light {
            self.device.release_basis(&mut resident);
        }
        let mut made = 0;
        if self.plan.interpolate == TimeInterpolation::Flow {
            // The motion of views another walker's copy holds is shared, not made again.
            let held = like.map_or([false; 2], |l| resident.share_motion(l));
            let motion = PoseStep::ALL.map(|step| {
                let wanted = match plan {
                    Some(p) => p.pose_flows[step.index()],
                    None => true,
                };
                (wanted && !held[step.index()]).then(|| pose_motion(self.field, &source, step))
            });
            let [next, prev] = motion;
            let motion = [next.transpose()?.flatten(), prev.transpose()?.flatten()];
            made = motion.iter().flatten().count();
            self.device.set_motion(&mut resident, motion)?;
        }
        let wants = |planned: bool| if self.options.planned { planned } else { true };
        match self.scene.shadow {
            ShadowSpec::Maps if wants(plan.is_some_and(|p| p.shadow_maps)) => {
                let level = self
                    .options
                    .detail
                    .unwrap_or_else(|| plan.map_or(0, |p| p.shadow_level));
                if let Some(maps) = self.shadow_maps(pose, level)? {
                    self.device
                        .set_shadow(&mut resident, SceneShadow::Maps(maps))?;
                }
            }
            ShadowSpec::Traced if wants(plan.is_some_and(|p| p.hull)) => {
                if let Some(shadow) = self.traced_shadow(pose, world, light)? {
                    self.device
                        .set_shadow(&mut resident, SceneShadow::Relit(shadow))?;
                }
            }
            _ => {}
        }
        Ok((resident, made))
    }

    /// Drops the least recently used poses the current frame does not draw until the
    /// resident poses fit the budget; `slots` (indices into the cache of this frame's
    /// poses) are kept valid.
    fn keep_within_budget(&mut self, frame: usize, slots: &mut [usize]) -> Result<()> {
        let total = cache_bytes;
        while total(&self.cache) > self.options.memory_budget {
            let victim = self
                .cache
                .iter()
                .enumerate()
                .filter(|(_, c)| c.last_frame != frame)
                .min_by_key(|(_, c)| c.last_frame)
                .map(|(k, _)| k);
            let Some(k) = victim else {
                return Err(SceneError::MemoryBudget {
                    frame,
                    needed_mb: total(&self.cache) as f64 / 1e6,
                    budget_mb: self.options.memory_budget as f64 / 1e6,
                });
            };
            self.cache.remove(k);
            self.counters.evictions += 1;
            for s in slots.iter_mut() {
                if *s > k {
                    *s -= 1;
                }
            }
        }
        self.counters.peak_resident_bytes =
            self.counters.peak_resident_bytes.max(total(&self.cache));
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The light tolerance holds a walker's heading relative to the light the keys turn:
    /// a light turning within it, or turning with the walker, keeps its poses; with
    /// probes, whose maps the keys do not turn, a walker turning with the keys has turned
    /// against the maps and is relit.
    #[test]
    fn the_tolerance_holds_the_heading_relative_to_what_the_keys_turn() {
        let tolerance = LightTolerance::DEFAULT;
        let deg = |d: f32| d.to_radians();
        let light = |heading: f32, yaw: [f32; 2]| WalkerLight::new(deg(heading), yaw, Vec::new());
        let keys = |d: f32| [deg(d), deg(d)];
        let lit = light(30.0, keys(0.0));
        assert!(tolerance.holds(&lit, &light(30.0, keys(1.5))));
        assert!(!tolerance.holds(&lit, &light(30.0, keys(3.0))));
        assert!(!tolerance.holds(&lit, &light(33.0, keys(0.0))));
        // Walker and light turned alike: the same light relative to the walker.
        assert!(tolerance.holds(&lit, &light(40.0, keys(10.0))));
        // With probes: the maps stay, the sun turns with the keys.
        let probes = |d: f32| [0.0, deg(d)];
        let lit = light(30.0, probes(0.0));
        assert!(tolerance.holds(&lit, &light(30.0, probes(1.5))));
        assert!(!tolerance.holds(&lit, &light(40.0, probes(10.0))));
        assert!(!tolerance.holds(&lit, &light(30.0, probes(3.0))));
        // A light turning by the tolerance holds, at any yaw the rounding meets.
        for k in 0..180 {
            let lit = light(37.3, keys(2.0 * k as f32));
            let now = light(37.3, keys(2.0 * (k + 1) as f32));
            assert!(tolerance.holds(&lit, &now), "turned to {}°", 2 * (k + 1));
        }
        // Exact: any turn relights.
        assert!(!LightTolerance::EXACT.holds(&light(30.0, keys(0.0)), &light(30.0, keys(0.1))));
        assert!(LightTolerance::EXACT.holds(&light(30.0, keys(0.1)), &light(30.0, keys(0.1))));
    }

    /// A walker relit is lit for the farthest light ahead that holds its own: under the 2°
    /// tolerance, a light turning 1° a frame is lit for two frames ahead, which holds the
    /// four frames after (relit every fifth frame instead of every third); one turning 3°
    /// a frame for its own; a resident shared by walkers of one light keeps their key.
    #[test]
    fn a_relight_is_lit_for_the_farthest_light_ahead_that_holds() {
        let tolerance = LightTolerance::DEFAULT;
        let light = |heading: f32, keys: f32| {
            WalkerLight::new(heading.to_radians(), [keys.to_radians(); 2], Vec::new())
        };
        let ahead = |rate: f32| -> Vec<WalkerLight> {
            (1..=LOOK_AHEAD_FRAMES)
                .map(|k| light(30.0, rate * k as f32))
                .collect()
        };
        let now = light(30.0, 0.0);
        let slow = ahead(1.0);
        let lit = tolerance.farthest(&now, &slow, false);
        assert_eq!(lit.yaw, slow[1].yaw);
        for k in 0..=4 {
            assert!(tolerance.holds(lit, &light(30.0, k as f32)), "frame {k}");
        }
        assert!(!tolerance.holds(lit, &light(30.0, 5.0)));
        // Turning faster than the tolerance: lit for its own frame.
        let fast = ahead(3.0);
        assert_eq!(tolerance.farthest(&now, &fast, false).yaw, now.yaw);
        // A walker turning: its own resident is lit ahead; a shared one (all of whose
        // walkers have one key) is not.
        let turning: Vec<WalkerLight> = (1..=4).map(|k| light(30.0 + k as f32, 0.0)).collect();
        assert_eq!(
            tolerance.farthest(&now, &turning, false).heading,
            turning[1].heading
        );
        assert_eq!(
            tolerance.farthest(&now, &turning, true).heading,
            now.heading
        );
        // Exact: its own.
        assert_eq!(
            LightTolerance::EXACT.farthest(&now, &slow, false).yaw,
            now.yaw
        );
    }
}
