//! The export itself: what is taken from the field, in which order, into the GLB.

use std::collections::BTreeMap;
use std::path::Path;
use std::time::Instant;

use frf_core::grid::{Neighbour, PoseStep};
use frf_core::image::{GrayImage, Rgb};
use frf_core::sh::{Convention, SH_COUNT};
use frf_reflectance::FieldFile;
use frf_reflectance::chunk::{ChunkKey, ChunkKind};
use frf_reflectance::field::CameraRecord;
use frf_reflectance::light_fit::LightFit;
use frf_reflectance::sh_transfer::{sh_weights, texel_transfer};
use glam::{Mat3, Vec3};
use rayon::prelude::*;
use serde_json::{Value, json};

use crate::error::{ExportError, Result};
use crate::format::{BASIS_COLUMNS, EXTENSION, VERSION};
use crate::glb::Glb;
use crate::hull_mesh::hull_mesh;
use crate::model::{
    Basis, BasisImages, Extension, Grid, GroundShadow, MotionImage, PoseRecord, ScaledImage,
    TierName, Transfer, ViewRecord, Walk,
};
use crate::view_maps::{
    AtlasFormat, CodeError, alpha_png, flow_png, motion_png, normals_png, scaled_rgb_png,
    tile_atlas, transfer_atlas,
};

/// Which views of each pose are exported.
#[derive(Debug, Clone, PartialEq)]
pub enum ViewSelection {
    /// Every view of the grid.
    All,
    /// One row of cameras (`v`), all the way round.
    Ring(usize),
    /// These `(u, v)`.
    List(Vec<(usize, usize)>),
}

/// How much of the transfer is kept.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Tier {
    /// Nine RGB coefficients per texel (three grey atlases).
    Full,
    /// Nine grey coefficients (the transfer's luminance, one atlas) and one colour per
    /// texel (its band-0 transfer over its luminance): `T_i ≈ colour · t_i`. A third of
    /// the transfer's bytes; exact where a texel's colour does not change with the
    /// light's direction.
    Compact,
}

/// `full` or `compact` (`frf export --tier`).
impl std::str::FromStr for Tier {
    type Err = String;

    fn from_str(s: &str) -> std::result::Result<Self, String> {
        match s {
            "full" => Ok(Tier::Full),
            "compact" => Ok(Tier::Compact),
            other => Err(format!("{other:?}: expected full or compact")),
        }
    }
}

/// How the transfer's (and the basis') atlases are stored (`frf export --textures`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Textures {
    /// Grey JPEGs, one a channel: the smallest files, decoded to texels by a player.
    Jpeg,
    /// One GPU-compressed KTX2 image of UASTC blocks (zstd) a view: a player transcodes
    /// it to its GPU's block format and keeps it compressed there (8 bits a texel for the
    /// three channels, against 24 decoded).
    Ktx2,
}

/// `jpeg` or `ktx2` (`frf export --textures`).
impl std::str::FromStr for Textures {
    type Err = String;

    fn from_str(s: &str) -> std::result::Result<Self, String> {
        match s {
            "jpeg" => Ok(Textures::Jpeg),
            "ktx2" => Ok(Textures::Ktx2),
            other => Err(format!("{other:?}: expected jpeg or ktx2")),
        }
    }
}

/// `all`, `ring:V` (a row of cameras) or `U,V;U,V;...`, each view once (`frf export
/// --views`).
impl std::str::FromStr for ViewSelection {
    type Err = String;

    fn from_str(s: &str) -> std::result::Result<Self, String> {
        if s == "all" {
            return Ok(ViewSelection::All);
        }
        if let Some(v) = s.strip_prefix("ring:") {
            return v
                .parse()
                .map(ViewSelection::Ring)
                .map_err(|_| format!("ring:{v}: expected a camera row number"));
        }
        let views = s
            .split(';')
            .map(|p| {
                let (u, v) = p
                    .split_once(',')
                    .ok_or_else(|| format!("{p:?}: expected U,V"))?;
                Ok((
                    u.trim()
                        .parse()
                        .map_err(|_| format!("{p:?}: expected U,V"))?,
                    v.trim()
                        .parse()
                        .map_err(|_| format!("{p:?}: expected U,V"))?,
                ))
            })
            .collect::<std::result::Result<Vec<(usize, usize)>, String>>()?;
        if let Some((k, (u, v))) = frf_core::argument::given_twice(&views) {
            return Err(format!(
                "{s:?}: view {u},{v} is given twice (the second time at place {k})"
            ));
        }
        Ok(ViewSelection::List(views))
    }
}

/// What to export.
#[derive(Debug, Clone)]
pub struct ExportOptions {
    /// The transfer's tier.
    pub tier: Tier,
    /// Poses (default: every pose of the field).
    pub poses: Option<Vec<u32>>,
    /// Views.
    pub views: ViewSelection,
    /// Voxel side of the hull meshes, metres (never finer than the hull's own).
    pub mesh_voxel_m: f32,
    /// How the transfer atlases are stored.
    pub textures: Textures,
    /// How the basis atlases are stored (with [`ExportOptions::basis`]).
    pub basis_textures: Textures,
    /// JPEG quality of the transfer atlases (and the basis'), [`Textures::Jpeg`].
    pub jpeg_quality: u8,
    /// Whether the views' basis images go too (what frf relights a sun by).
    pub basis: bool,
}

impl ExportOptions {
    /// How atlases stored as `textures` are encoded.
    fn atlas_format(&self, textures: Textures) -> AtlasFormat {
        match textures {
            Textures::Jpeg => AtlasFormat::Jpeg(self.jpeg_quality),
            Textures::Ktx2 => AtlasFormat::Ktx2,
        }
    }

    /// Whether the export holds KTX2 images.
    fn writes_ktx2(&self) -> bool {
        self.textures == Textures::Ktx2 || (self.basis && self.basis_textures == Textures::Ktx2)
    }
}

impl Default for ExportOptions {
    fn default() -> Self {
        Self {
            tier: Tier::Full,
            poses: None,
            views: ViewSelection::All,
            mesh_voxel_m: 0.02,
            textures: Textures::Jpeg,
            basis_textures: Textures::Jpeg,
            jpeg_quality: 95,
            basis: false,
        }
    }
}

/// What an export wrote.
#[derive(Debug, Clone, serde::Serialize)]
pub struct ExportReport {
    /// The file's bytes.
    pub bytes: u64,
    /// Poses exported.
    pub poses: usize,
    /// Views exported, all poses together.
    pub views: usize,
    /// Triangles of all hull meshes.
    pub triangles: usize,
    /// Bytes of the transfer atlases, alpha, normals, albedo, flows, meshes, motion,
    /// ground shadows and basis images.
    pub section_bytes: [(String, u64); SECTIONS],
    /// Wall seconds.
    pub seconds: f64,
    /// The atlases' codes as a reader decodes them against those encoded, by atlas
    /// (`transfer`, `basis`), all views pooled.
    pub atlas_error: Vec<AtlasError>,
    /// What the export lacks that a player may expect (a field without normals).
    pub notes: Vec<String>,
}

/// The error of one kind of atlas, all views pooled ([`crate::view_maps::CodeError`]).
#[derive(Debug, Clone, serde::Serialize)]
pub struct AtlasError {
    /// `transfer` or `basis`.
    pub atlas: &'static str,
    /// The images' media type.
    pub mime: &'static str,
    /// Root mean square error, codes (a 255th of a tile's range).
    pub rms_codes: f64,
    /// Peak signal to noise ratio over the 255 codes, dB.
    pub psnr_db: f64,
    /// The largest error, codes.
    pub largest_codes: u8,
    /// The worst view's PSNR, dB.
    pub worst_view_psnr_db: f64,
}

impl AtlasError {
    fn of(atlas: &'static str, mime: &'static str, errors: &[CodeError]) -> Self {
        let mut all = CodeError::default();
        errors.iter().for_each(|e| all.add(e));
        let worst = errors
            .iter()
            .map(CodeError::psnr_db)
            .fold(f64::INFINITY, f64::min);
        Self {
            atlas,
            mime,
            rms_codes: all.rms(),
            psnr_db: all.psnr_db(),
            largest_codes: all.largest,
            worst_view_psnr_db: worst,
        }
    }
}

/// The sections of an export's bytes ([`ExportReport::section_bytes`]).
const SECTIONS: usize = 9;

/// One view's maps, encoded.
struct ViewOut {
    u: usize,
    v: usize,
    turntable_deg: f32,
    camera: CameraRecord,
    atlas: crate::view_maps::Atlas,
    colour: Option<(Vec<u8>, Rgb)>,
    alpha: Vec<u8>,
    normals: Option<Vec<u8>>,
    albedo: (Vec<u8>, Rgb),
    flows: Vec<(Neighbour, Vec<u8>)>,
    /// The largest flow component of `flows`, pixels.
    max_flow_px: f32,
    motion: Vec<(PoseStep, Vec<u8>, f32)>,
    basis: Option<crate::view_maps::Atlas>,
}

/// Exports `field` to `out` (written to a temporary file and renamed).
pub fn export(field_path: &Path, out: &Path, options: &ExportOptions) -> Result<ExportReport> {
    let started = Instant::now();
    frf_core::atomic::refuse_overwriting_inputs(out, &[field_path])?;
    let field = FieldFile::open(field_path)?;
    check_exportable(&field)?;
    let header = field.header().clone();
    let (poses, wanted) = selection(&field, options)?;
    let projector = field.projector()?;
    let mut glb = Glb::default();
    let mut sizes = [0u64; SECTIONS];
    let mut nodes = vec![json!({"name": "walker", "children": []})];
    let mut meshes = Vec::new();
    let mut pose_records = Vec::new();
    let mut triangles = 0;
    let mut exported_views = 0;
    let (mut transfer_errors, mut basis_errors) = (Vec::new(), Vec::new());
    for &pose in &poses {
        let record = header.pose(pose)?.clone();
        let hull = field.hull(pose)?.ok_or_else(|| {
            ExportError::Field(format!(
                "pose {pose} has no visual hull (ingest it without --no-shadows)"
            ))
        })?;
        let mesh = hull_mesh(&hull, options.mesh_voxel_m, pose)?;
        triangles += mesh.indices.len() / 3;
        let node = add_hull(&mut glb, &mut sizes, (&mut nodes, &mut meshes), &mesh, pose);

        let ground_shadow = match field.shadows(pose)? {
            Some(maps) => {
                let before = glb.binary_bytes();
                let png = crate::view_maps::stacked_maps_png(&maps)?;
                let image = glb.image(&png, "image/png", format!("pose {pose} ground shadow"));
                sizes[7] += (glb.binary_bytes() - before) as u64;
                Some(image)
            }
            None => None,
        };
        // A field ingested for a scene holds some views of a pose: `all` takes those.
        let held = |&(u, v): &(usize, usize)| {
            field.has(&ChunkKey {
                pose,
                u: u as u32,
                v: v as u32,
                kind: ChunkKind::Basis,
            })
        };
        let views: Vec<(usize, usize)> = wanted.iter().copied().filter(held).collect();
        if options.views != ViewSelection::All && views.len() < wanted.len() {
            let missing = wanted.iter().find(|w| !held(w)).expect("one is missing");
            return Err(ExportError::Option(format!(
                "--views: view {},{} of pose {pose} is not in the field",
                missing.0, missing.1
            )));
        }
        if views.is_empty() {
            return Err(ExportError::Field(format!("pose {pose} holds no view")));
        }
        exported_views += views.len();
        let turntables: Vec<f32> = views
            .iter()
            .map(|&(u, v)| {
                record.views[header.view_index(u, v)]
                    .turntable_deg
                    .to_radians()
            })
            .collect();
        let weights = sh_weights(projector, &turntables)?;
        let encoded: Vec<ViewOut> = views
            .par_iter()
            .zip(&weights)
            .map(|(&(u, v), w)| {
                let rec = &record.views[header.view_index(u, v)];
                encode_view(&field, pose, (u, v), rec, w, options)
            })
            .collect::<Result<_>>()?;
        let max_flow_px = encoded.iter().map(|e| e.max_flow_px).fold(0.0f32, f32::max);
        transfer_errors.extend(encoded.iter().map(|e| e.atlas.error));
        basis_errors.extend(encoded.iter().filter_map(|e| Some(e.basis.as_ref()?.error)));
        let views: Vec<ViewRecord> = encoded
            .into_iter()
            .map(|e| add_view(&mut glb, &mut sizes, pose, e))
            .collect();
        // Every camera of the grid (u-major), the held views' and the others': a player
        // re-bins rays through the cylinder of all their centres.
        let cameras: Vec<CameraRecord> = (0..header.columns)
            .flat_map(|u| (0..header.rows).map(move |v| (u, v)))
            .map(|(u, v)| record.views[header.view_index(u, v)].camera.clone())
            .collect();
        // Where frf starts a sun's shadow ray from the hull (a player's sun does the same).
        let offset = frf_reflectance::sun_light::shadow_offset_m(&hull);
        pose_records.push(PoseRecord {
            pose,
            time_s: record.time_s,
            node,
            cameras,
            sun_shadow_offset_m: offset,
            ground_shadow,
            motion_to: motion_to(&record),
            max_flow_px: Some(max_flow_px),
            views,
        });
    }
    let nodes_of: Vec<usize> = pose_records.iter().map(|p| p.node).collect();
    let animation = pose_animation(&mut glb, &poses, &header, &nodes_of);
    let extension = extension_of(&field, field_path, options, pose_records)?;
    let document = document_of(options, (nodes, meshes), animation, extension);
    let bytes = glb.finish(document);
    frf_core::atomic::write_bytes_atomic(out, &bytes)?;
    let names = [
        "transfer", "alpha", "normals", "albedo", "flows", "meshes", "motion", "shadow", "basis",
    ];
    let mut notes = Vec::new();
    if sizes[2] == 0 {
        notes.push(format!(
            "{} holds no fitted normals (written before them, or of too few conditions): \
             the export's views have none, and a player cannot add a sun by them",
            field_path.display()
        ));
    }
    Ok(ExportReport {
        bytes: bytes.len() as u64,
        poses: poses.len(),
        views: exported_views,
        triangles,
        section_bytes: std::array::from_fn(|i| (names[i].to_string(), sizes[i])),
        seconds: started.elapsed().as_secs_f64(),
        atlas_error: [
            ("transfer", options.textures, transfer_errors),
            ("basis", options.basis_textures, basis_errors),
        ]
        .into_iter()
        .filter(|(_, _, e)| !e.is_empty())
        .map(|(atlas, t, e)| AtlasError::of(atlas, options.atlas_format(t).mime(), &e))
        .collect(),
        notes,
    })
}

/// The glTF document of the walker: its nodes and hull meshes, the poses' animation and
/// the extension.
fn document_of(
    options: &ExportOptions,
    (nodes, meshes): (Vec<Value>, Vec<Value>),
    animation: Value,
    extension: Value,
) -> Value {
    // KTX2 images are glTF's by KHR_texture_basisu (which lists image/ktx2 among the
    // media types).
    let extensions_used = match options.writes_ktx2() {
        true => vec![EXTENSION, "KHR_texture_basisu"],
        false => vec![EXTENSION],
    };
    json!({
        "asset": {"version": "2.0", "generator": format!("frf {}", env!("CARGO_PKG_VERSION"))},
        "extensionsUsed": extensions_used,
        "scene": 0,
        "scenes": [{"nodes": [0]}],
        "nodes": nodes,
        "meshes": meshes,
        "materials": [{"name": "hull", "pbrMetallicRoughness": {"baseColorFactor": [0.6, 0.6, 0.6, 1.0], "metallicFactor": 0.0, "roughnessFactor": 0.9}}],
        "animations": [animation],
        "extensions": {EXTENSION: extension},
    })
}

/// Adds pose `pose`'s hull mesh to `glb` (its bytes counted in `sizes`), as a mesh and a
/// node under the walker's: the node's index.
fn add_hull(
    glb: &mut Glb,
    sizes: &mut [u64; SECTIONS],
    (nodes, meshes): (&mut Vec<Value>, &mut Vec<Value>),
    mesh: &crate::hull_mesh::Mesh,
    pose: u32,
) -> usize {
    let before = glb.binary_bytes();
    let positions = glb.vec3(&mesh.positions);
    let indices = glb.indices(&mesh.indices);
    sizes[5] += (glb.binary_bytes() - before) as u64;
    meshes.push(json!({
        "name": format!("hull of pose {pose}"),
        "primitives": [{"attributes": {"POSITION": positions}, "indices": indices, "material": 0}]
    }));
    nodes.push(json!({"name": format!("pose {pose}"), "mesh": meshes.len() - 1}));
    let node = nodes.len() - 1;
    nodes[0]["children"]
        .as_array_mut()
        .expect("an array")
        .push(json!(node));
    node
}

/// The ground-shadow basis' patch and each map's SH weights (frf's ground coefficients
/// at turntable angle 0, `render/src/shadow.rs`), where the field holds shadow maps.
fn ground_shadow(field: &FieldFile) -> Result<Option<GroundShadow>> {
    let h = field.header();
    let Some(spec) = &h.shadows else {
        return Ok(None);
    };
    let w = sh_weights(field.projector()?, &[0.0])?.remove(0);
    let weights = spec
        .conditions
        .iter()
        .map(|&k| {
            let e = frf_reflectance::shadow::ground_irradiance(&h.conditions[k]);
            w[k].map(|wi| [0, 1, 2].map(|c| wi[c] * e[c]))
        })
        .collect();
    Ok(Some(GroundShadow {
        extent_m: spec.ground.extent_m,
        texels: spec.ground.texels,
        edge_fade_from: frf_reflectance::shadow::EDGE_FADE_FROM,
        weights,
    }))
}

/// Where a pose's motion leads (`next`, `prev`): the poses its pose-to-pose flows reach.
fn motion_to(record: &frf_reflectance::field::PoseRecord) -> BTreeMap<String, u32> {
    let Some(to) = record.pose_flows_to else {
        return BTreeMap::new();
    };
    PoseStep::ALL
        .into_iter()
        .zip(to)
        .filter_map(|(step, to)| to.map(|p| (step_name(step).to_string(), p)))
        .collect()
}

/// The extension's object ([`crate::model`]) of `field` (read from `field_path`) holding
/// `poses`, as JSON.
fn extension_of(
    field: &FieldFile,
    field_path: &Path,
    options: &ExportOptions,
    poses: Vec<PoseRecord>,
) -> Result<Value> {
    let header = field.header();
    // The walk's speed as the field records it or its hulls tell it: what an engine moves
    // the walker by so that its feet stay planted (docs/export.md, "Root motion").
    let walk = frf_reflectance::gait_speed::gait_speed_mps(field)?.map(|speed| Walk {
        speed_mps: speed,
        stride_m: speed * header.cycle_seconds,
        forward: [1.0, 0.0, 0.0],
        measured: header.gait_speed_mps.is_none(),
    });
    let extension = Extension {
        version: VERSION,
        tier: match options.tier {
            Tier::Full => TierName::Full,
            Tier::Compact => TierName::Compact,
        },
        sh: Convention::frf(),
        grid: Grid {
            columns: header.columns,
            rows: header.rows,
            wraps: header.wraps,
            width: header.width,
            height: header.height,
        },
        cycle_seconds: header.cycle_seconds,
        poses_per_cycle: header.poses_per_cycle,
        walk,
        source: field_path
            .file_name()
            .map(|n| n.to_string_lossy().into_owned()),
        ground_shadow: ground_shadow(field)?,
        basis: options.basis.then(|| Basis {
            columns: BASIS_COLUMNS,
            conditions: header.conditions.clone(),
        }),
        poses,
    };
    serde_json::to_value(&extension)
        .map_err(|e| ExportError::Field(format!("the extension's JSON: {e}")))
}

/// Poses, and views `(u, v)`.
type Selection = (Vec<u32>, Vec<(usize, usize)>);

/// The poses and views `options` ask for, checked against `field`, and the options
/// checked.
fn selection(field: &FieldFile, options: &ExportOptions) -> Result<Selection> {
    let header = field.header();
    let poses = match &options.poses {
        Some(p) => p
            .iter()
            .map(|&p| field.pose_or_first(Some(p)))
            .collect::<std::result::Result<Vec<_>, _>>()?,
        None => header.pose_list(),
    };
    let wanted: Vec<(usize, usize)> = match &options.views {
        ViewSelection::All => (0..header.columns)
            .flat_map(|u| (0..header.rows).map(move |v| (u, v)))
            .collect(),
        ViewSelection::Ring(v) if *v < header.rows => {
            (0..header.columns).map(|u| (u, *v)).collect()
        }
        ViewSelection::Ring(v) => {
            return Err(ExportError::Option(format!(
                "--views ring {v}: the field has camera rows 0..{}",
                header.rows
            )));
        }
        ViewSelection::List(l) => {
            if let Some(bad) = l
                .iter()
                .find(|(u, v)| *u >= header.columns || *v >= header.rows)
            {
                return Err(ExportError::Option(format!(
                    "--views {},{}: outside the field's {}x{} grid",
                    bad.0, bad.1, header.columns, header.rows
                )));
            }
            l.clone()
        }
    };
    if !(1..=100).contains(&options.jpeg_quality) {
        return Err(ExportError::Option(format!(
            "--jpeg-quality {}: expected 1 to 100",
            options.jpeg_quality
        )));
    }
    if !(options.mesh_voxel_m.is_finite()
        && options.mesh_voxel_m > 0.0
        && options.mesh_voxel_m <= 0.5)
    {
        return Err(ExportError::Option(format!(
            "--mesh-voxel {}: expected a side in metres, above 0 and at most 0.5",
            options.mesh_voxel_m
        )));
    }
    Ok((poses, wanted))
}

/// Adds view `e` of `pose`'s images to `glb` (their bytes counted in `sizes`, by
/// section) and returns its record in the extension.
fn add_view(glb: &mut Glb, sizes: &mut [u64; SECTIONS], pose: u32, e: ViewOut) -> ViewRecord {
    let name = |what: &str| format!("pose {pose} view {},{} {what}", e.u, e.v);
    let before = glb.binary_bytes();
    let rgb = ["red", "green", "blue"];
    // One grey JPEG a channel, or one KTX2 image of them all.
    let channel_names = |what: &str, mime: &str, count: usize| -> Vec<String> {
        match mime {
            "image/jpeg" => (rgb.iter().take(count))
                .map(|c| format!("{what} {c}"))
                .collect(),
            _ => vec![what.to_string()],
        }
    };
    let atlas: Vec<usize> = (e.atlas.images.iter())
        .zip(channel_names(
            "transfer",
            e.atlas.mime,
            e.atlas.images.len(),
        ))
        .map(|(bytes, what)| glb.image(bytes, e.atlas.mime, name(&what)))
        .collect();
    let colour = e.colour.as_ref().map(|(png, scale)| ScaledImage {
        image: glb.image(png, "image/png", name("transfer colour")),
        scale: *scale,
    });
    sizes[0] += (glb.binary_bytes() - before) as u64;
    let before = glb.binary_bytes();
    let alpha = glb.image(&e.alpha, "image/png", name("alpha"));
    sizes[1] += (glb.binary_bytes() - before) as u64;
    let before = glb.binary_bytes();
    let normals = e
        .normals
        .as_ref()
        .map(|n| glb.image(n, "image/png", name("normals")));
    sizes[2] += (glb.binary_bytes() - before) as u64;
    let before = glb.binary_bytes();
    let albedo = glb.image(&e.albedo.0, "image/png", name("albedo"));
    sizes[3] += (glb.binary_bytes() - before) as u64;
    let before = glb.binary_bytes();
    let mut flows = BTreeMap::new();
    for (n, bytes) in &e.flows {
        let image = glb.image(bytes, "image/png", name(&format!("flow {}", n.name())));
        flows.insert(n.name().to_string(), image);
    }
    sizes[4] += (glb.binary_bytes() - before) as u64;
    let before = glb.binary_bytes();
    let mut motion = BTreeMap::new();
    for (step, bytes, step_m) in &e.motion {
        let name = name(&format!("motion {}", step_name(*step)));
        let image = glb.image(bytes, "image/png", name);
        motion.insert(
            step_name(*step).to_string(),
            MotionImage {
                image,
                step_m: *step_m,
            },
        );
    }
    sizes[6] += (glb.binary_bytes() - before) as u64;
    let before = glb.binary_bytes();
    let basis = e.basis.map(|b| BasisImages {
        images: (b.images.iter())
            .zip(channel_names("basis", b.mime, b.images.len()))
            .map(|(bytes, what)| glb.image(bytes, b.mime, name(&what)))
            .collect(),
        scale: b.scale,
        offset: b.offset,
    });
    sizes[8] += (glb.binary_bytes() - before) as u64;
    ViewRecord {
        u: e.u,
        v: e.v,
        turntable_deg: e.turntable_deg,
        camera: e.camera,
        alpha,
        transfer: Transfer {
            images: atlas,
            scale: nine(&e.atlas.scale),
            offset: nine(&e.atlas.offset),
            colour,
        },
        normals,
        albedo: ScaledImage {
            image: albedo,
            scale: e.albedo.1,
        },
        flows,
        motion,
        basis,
    }
}

/// A transfer atlas' nine tiles' values (the atlas holds [`SH_COUNT`] by construction).
fn nine(values: &[Rgb]) -> [Rgb; SH_COUNT] {
    std::array::from_fn(|i| values[i])
}

/// A pose step's key in the extension.
fn step_name(step: PoseStep) -> &'static str {
    match step {
        PoseStep::Next => "next",
        PoseStep::Prev => "prev",
    }
}

/// A field of one view (an OLAT set) or one condition (a ring of photographs) has
/// nothing to relight or morph between.
fn check_exportable(field: &FieldFile) -> Result<()> {
    let h = field.header();
    if h.columns * h.rows < 2 || h.conditions.len() < 2 {
        return Err(ExportError::Field(format!(
            "{}: {} view(s) of {} condition(s); an export needs a grid of views under a basis of lights",
            field.path().display(),
            h.columns * h.rows,
            h.conditions.len()
        )));
    }
    Ok(())
}

/// Encodes view `(u, v)` of `pose`.
fn encode_view(
    field: &FieldFile,
    pose: u32,
    (u, v): (usize, usize),
    rec: &frf_reflectance::field::ViewRecord,
    weights: &frf_reflectance::sh_transfer::ShWeights,
    options: &ExportOptions,
) -> Result<ViewOut> {
    let basis = field.basis(pose, u, v)?;
    let alpha: GrayImage = field.alpha(pose, u, v)?;
    let (w, h) = alpha.size();
    let transfer: Vec<[Rgb; SH_COUNT]> = (0..w * h)
        .map(|i| {
            if alpha.pixels()[i] > 0.0 {
                texel_transfer(weights, basis.iter().map(|b| b.pixels()[i]))
            } else {
                [[0.0; 3]; SH_COUNT]
            }
        })
        .collect();
    let format = options.atlas_format(options.textures);
    let (atlas, colour) = match options.tier {
        Tier::Full => (transfer_atlas(&transfer, &alpha, format, 3)?, None),
        Tier::Compact => {
            let lum = |c: Rgb| frf_core::image::luminance(c);
            let grey: Vec<[Rgb; SH_COUNT]> = transfer
                .iter()
                .map(|t| t.map(|c| [lum(c), 0.0, 0.0]))
                .collect();
            let colour: Vec<Rgb> = transfer
                .iter()
                .map(|t| {
                    let l = lum(t[0]);
                    if l > 0.0 {
                        t[0].map(|c| (c / l).max(0.0))
                    } else {
                        [1.0; 3]
                    }
                })
                .collect();
            (
                transfer_atlas(&grey, &alpha, format, 1)?,
                Some(scaled_rgb_png(&colour, w, h)?),
            )
        }
    };
    let to_subject = Mat3::from_rotation_y(-rec.turntable_deg.to_radians());
    let normals = field
        .normals(pose, u, v)?
        .map(|n| {
            let n: Vec<Option<Vec3>> = n.iter().map(|n| n.map(|n| to_subject * n)).collect();
            normals_png(&n, w, h)
        })
        .transpose()?;
    let fit = LightFit::of_basis(&basis, &field.header().conditions, &alpha);
    let albedo: Vec<Rgb> = fit.albedo();
    let albedo = scaled_rgb_png(&albedo, w, h)?;
    let mut flows = Vec::new();
    let mut max_flow_px = 0.0f32;
    for n in Neighbour::ALL {
        if let Some(mut f) = field.flow(pose, u, v, n)? {
            // Beyond the subject as frf reads it when it loads a pose: each unknown texel
            // takes its nearest known one's flow (docs/design.md section 4.2).
            let (fw, fh) = f.size();
            frf_core::filter::extend_nearest(f.pixels_mut(), fw, fh, |p| {
                p[0].abs() < frf_core::flo::UNKNOWN_THRESHOLD
                    && p[1].abs() < frf_core::flo::UNKNOWN_THRESHOLD
            });
            let (png, largest) = flow_png(&f)?;
            max_flow_px = max_flow_px.max(largest);
            flows.push((n, png));
        }
    }
    let motion = view_motion(field, pose, (u, v), (w, h))?;
    // What frf relights a sun by: each condition's image, zero where nothing is seen.
    let basis = options
        .basis
        .then(|| {
            let tile = |p: usize, k: usize| match alpha.pixels()[p] > 0.0 {
                true => basis[k].pixels()[p],
                false => [0.0; 3],
            };
            let format = options.atlas_format(options.basis_textures);
            tile_atlas(tile, (basis.len(), BASIS_COLUMNS), &alpha, format, 3)
        })
        .transpose()?;
    Ok(ViewOut {
        u,
        v,
        turntable_deg: rec.turntable_deg,
        camera: rec.camera.clone(),
        atlas,
        colour,
        alpha: alpha_png(&alpha)?,
        normals,
        albedo,
        flows,
        max_flow_px,
        motion,
        basis,
    })
}

/// View `(u, v)` of `pose`'s motion toward the poses its pose-to-pose flows lead to, in
/// metres across the axis and up it (as frf's morph in time reads them,
/// [`frf_core::subject_motion`]), beyond the subject its nearest known texel's.
fn view_motion(
    field: &FieldFile,
    pose: u32,
    (u, v): (usize, usize),
    (w, h): (usize, usize),
) -> Result<Vec<(PoseStep, Vec<u8>, f32)>> {
    let header = field.header();
    let poses = header.pose_list();
    let camera = |pose: u32, u: usize| -> Result<frf_core::camera::Camera> {
        header.pose(pose)?.views[header.view_index(u, v)]
            .camera
            .to_camera()
            .map_err(|e| ExportError::Field(format!("pose {pose} view {u},{v}'s camera: {e}")))
    };
    let mut out = Vec::new();
    for step in PoseStep::ALL {
        let Some(flow) = field.pose_flow(pose, u, v, step)? else {
            continue;
        };
        let Some((to_pose, to_u)) = step.of(pose, u, &poses, header.columns, header.wraps) else {
            continue;
        };
        let (from, later) = (camera(pose, u)?, camera(to_pose, to_u)?);
        let Some(metres) =
            frf_core::subject_motion::view_motion_m(&from, &later, &flow, (w, h), |k| {
                (k % w, k / w)
            })
        else {
            continue;
        };
        let (png, step_m) = motion_png(&metres, w, h)?;
        out.push((step, png, step_m));
    }
    Ok(out)
}

/// The walk: each pose's node at scale 1 from its time to the next pose's, 0 otherwise,
/// over one cycle.
fn pose_animation(
    glb: &mut Glb,
    poses: &[u32],
    header: &frf_reflectance::FieldHeader,
    nodes_of: &[usize],
) -> Value {
    let period = header.cycle_seconds as f32 / header.poses_per_cycle.max(1) as f32;
    // A last key at the cycle's end shows the first pose again: the walk loops.
    let times: Vec<f32> = (0..=poses.len()).map(|i| i as f32 * period).collect();
    let input = glb.scalars(&times);
    let mut samplers = Vec::new();
    let mut channels = Vec::new();
    for (i, node) in nodes_of.iter().enumerate() {
        let scales: Vec<[f32; 3]> = (0..=poses.len())
            .map(|k| {
                if k % poses.len() == i {
                    [1.0; 3]
                } else {
                    [0.0; 3]
                }
            })
            .collect();
        let output = glb.vec3_values(&scales);
        samplers.push(json!({"input": input, "output": output, "interpolation": "STEP"}));
        channels.push(
            json!({"sampler": samplers.len() - 1, "target": {"node": node, "path": "scale"}}),
        );
    }
    json!({"name": "walk", "samplers": samplers, "channels": channels})
}
