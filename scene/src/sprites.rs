//! A relit sprite sheet for engines that play flipbooks (2D games, particle systems):
//! the walk cycle's poses rendered by frf from cameras around the walker, one row per
//! heading and one column per pose, into one 8-bit sRGB PNG with straight alpha (the
//! ground shadow a black layer of alpha `1 − S`, as `frf render --backdrop none` writes
//! it), and a JSON of each frame's rectangle, pose, time and camera beside it.

use std::path::{Path, PathBuf};
use std::time::Instant;

use frf_core::camera::Camera;
use frf_core::env::EnvSource;
use frf_core::image::{Image, Rgba};
use frf_reflectance::FieldFile;
use frf_reflectance::project::FloorModel;
use frf_render::renderer::Device;

use crate::path::{Orbit, Trajectory};
use crate::shot::{Shot, ShotOptions};
use crate::{BackdropSpec, FieldLook, Scene, ShadowSpec};
use glam::Vec3;
use serde_json::json;

use crate::error::{Result, SceneError};

/// The sheet's JSON format name and version.
pub const SPRITES_FORMAT: &str = "frf-sprites";
/// See [`SPRITES_FORMAT`].
pub const SPRITES_VERSION: u32 = 1;

/// What a sheet holds and how it is lit.
#[derive(Debug, Clone)]
pub struct SpriteOptions {
    /// The light (an environment, the built-in sky, or an L2 file of `frf env-sh`).
    pub env: EnvSource,
    /// A sun added to it.
    pub sun: Option<frf_core::sun::Sun>,
    /// Camera azimuths about the walker, degrees (0 on `+z`, increasing toward `+x`;
    /// the stage's walker walks toward `+x`: 0 sees its right side, 90 its front): the
    /// sheet's rows.
    pub headings_deg: Vec<f32>,
    /// Poses (default: all the field's): the sheet's columns.
    pub poses: Option<Vec<u32>>,
    /// A frame's size, pixels.
    pub frame_size: (u32, u32),
    /// The cameras' horizontal distance from the walker's axis and height, metres.
    pub radius_m: f32,
    /// See `radius_m`.
    pub height_m: f32,
    /// The point looked at, and the vertical field of view, degrees.
    pub look_at: Vec3,
    /// See `look_at`.
    pub fov_deg: f32,
    /// Exposure of the PNG, stops.
    pub exposure_stops: f32,
    /// Render on the CPU reference instead of the GPU.
    pub cpu: bool,
}

/// What a sheet took.
#[derive(Debug, Clone, serde::Serialize)]
pub struct SpriteReport {
    /// The PNG and the JSON written.
    pub image: PathBuf,
    /// See `image`.
    pub json: PathBuf,
    /// Rows (headings) and columns (poses).
    pub rows: usize,
    /// See `rows`.
    pub columns: usize,
    /// The sheet's size, pixels.
    pub width: u32,
    /// See `width`.
    pub height: u32,
    /// Wall seconds.
    pub seconds: f64,
}

/// The JSON written beside `png`: its stem with `.json`.
pub fn sheet_json_path(png: &Path) -> PathBuf {
    png.with_extension("json")
}

/// The largest side of a sprite frame, pixels.
pub const MOST_FRAME_SIDE: u32 = 2048;

/// The most pixels a side of a sheet: the largest texture engines take (and a sheet that
/// size is 4 GiB while it is rendered, four floats a pixel).
pub const MOST_SHEET_SIDE: usize = 16384;

/// Why a sprite frame of `(w, h)` pixels is refused, if it is.
pub fn frame_size_problem((w, h): (u32, u32)) -> Option<String> {
    let side = 1..=MOST_FRAME_SIDE;
    (!side.contains(&w) || !side.contains(&h))
        .then(|| format!("--sprite-size {w}x{h}: 1 to {MOST_FRAME_SIDE} pixels a side"))
}

fn check(options: &SpriteOptions) -> Result<()> {
    let bad = |m: String| Err(SceneError::Sprites(m));
    if let Some(problem) = frame_size_problem(options.frame_size) {
        return bad(problem);
    }
    if !(-30.0..=30.0).contains(&options.exposure_stops) {
        return bad(format!(
            "--exposure {}: -30 to 30 stops",
            options.exposure_stops
        ));
    }
    let n = options.headings_deg.len();
    if n == 0 || n > 64 || options.headings_deg.iter().any(|a| !a.is_finite()) {
        return bad(format!("--headings: {n} headings; 1 to 64 finite angles"));
    }
    let orbit = Orbit {
        radius: options.radius_m,
        height: options.height_m,
        start_deg: 0.0,
        sweep_deg: 360.0,
        look_at: options.look_at,
        fov_deg: options.fov_deg,
    };
    orbit
        .validate()
        .map_err(|e| SceneError::Sprites(format!("--sprite-orbit/--fov: {e}")))
}

/// Renders `field`'s sheet into `png` and its JSON beside it (each written to a
/// temporary file and renamed), and says what it took.
pub fn sprite_sheet(
    field_path: &Path,
    png: &Path,
    options: &SpriteOptions,
) -> Result<SpriteReport> {
    let started = Instant::now();
    check(options)?;
    // Neither output may be an input, nor the two outputs one file.
    let json_path = sheet_json_path(png);
    let light = match &options.env {
        EnvSource::File(p) => Some(p.as_path()),
        _ => None,
    };
    let inputs: Vec<&Path> = std::iter::once(field_path).chain(light).collect();
    for out in [png, json_path.as_path()] {
        frf_core::atomic::refuse_overwriting_inputs(out, &inputs)?;
    }
    if json_path == png {
        return Err(frf_core::CoreError::BadOutput {
            path: png.to_path_buf(),
            problem: "the sheet's JSON is written beside the image with the extension .json: \
                      the image needs another extension (.png)"
                .into(),
        }
        .into());
    }
    let field = FieldFile::open(field_path)?;
    frf_render::resident::check_renderable(&field)?;
    let header = field.header().clone();
    let poses: Vec<u32> = match &options.poses {
        Some(p) => p
            .iter()
            .map(|&p| field.pose_or_first(Some(p)))
            .collect::<std::result::Result<_, _>>()?,
        None => header.pose_list(),
    };
    let (fw, fh) = options.frame_size;
    let (columns, rows) = (poses.len(), options.headings_deg.len());
    let (sw, sh) = (fw as usize * columns, fh as usize * rows);
    if sw > MOST_SHEET_SIDE || sh > MOST_SHEET_SIDE {
        return Err(SceneError::Sprites(format!(
            "a sheet of {sw}x{sh} pixels ({columns} pose(s) x {rows} heading(s) of {fw}x{fh}) \
             is beyond {MOST_SHEET_SIDE} pixels a side, the largest texture engines take ({:.0} \
             GiB to hold while rendering): fewer --headings or --poses, or a smaller \
             --sprite-size",
            (sw * sh * 16) as f64 / f64::from(1u32 << 30)
        )));
    }
    let first = poses[0];
    let look = FieldLook {
        env: options.env.clone(),
        yaw_deg: 0.0,
        sun: options.sun,
        floor: FloorModel::Environment,
        camera: Trajectory::Orbit(Orbit {
            radius: options.radius_m,
            height: options.height_m,
            start_deg: options.headings_deg[0],
            sweep_deg: 360.0,
            look_at: options.look_at,
            fov_deg: options.fov_deg,
        }),
        backdrop: BackdropSpec::None,
        shadow: ShadowSpec::Maps,
    };
    // The still of the first pose; every frame asks for the walk's time of its pose.
    let mut scene = Scene::of_field(field_path, &header, first, look);
    scene.size = Some(options.frame_size);
    let first_time = header.pose(first)?.time_s;
    let device = Device::open(options.cpu)?;
    let shot_options = ShotOptions {
        memory_budget: 4 << 30,
        planned: false,
        traced_lights: 256,
        detail: Some(0),
        light_tolerance: crate::shot::LightTolerance::DEFAULT,
        walker_shadows: true,
    };
    let mut shot = Shot::live(scene, &field, device, shot_options)?;
    let mut sheet = Image::new(fw as usize * columns, fh as usize * rows, [0.0f32; 4]);
    let mut frames = Vec::new();
    let progress = frf_core::bars::bar("sprites");
    progress.set_length((rows * columns) as u64);
    for (row, &heading) in options.headings_deg.iter().enumerate() {
        let camera = heading_camera(options, heading)?;
        // Where the walker's foot point (the origin) lands: the sprite's pivot.
        let pivot = camera.project(Vec3::ZERO).map(|p| [p.x, p.y]);
        for (column, &pose) in poses.iter().enumerate() {
            let pose_time = header.pose(pose)?.time_s;
            let time = pose_time - first_time;
            let frame = shot.render_at(time, &camera, false)?;
            let (x0, y0) = (column * fw as usize, row * fh as usize);
            paste(&mut sheet, &frame.frame.composite, x0, y0);
            progress.inc(1);
            frames.push(json!({
                "x": x0, "y": y0, "w": fw, "h": fh,
                "row": row, "column": column, "heading_deg": heading,
                "pose": pose, "time_s": pose_time, "pivot": pivot,
            }));
        }
    }
    progress.finish_and_clear();
    frf_core::io::write_png8_srgba(png, &sheet, options.exposure_stops.exp2())?;
    let period = header.cycle_seconds / f64::from(header.poses_per_cycle.max(1));
    let document = json!({
        "format": SPRITES_FORMAT,
        "version": SPRITES_VERSION,
        "image": png.file_name().map(|n| n.to_string_lossy().into_owned()),
        "encoding": "8-bit sRGB, straight alpha; the ground shadow a black layer of alpha 1 - S",
        "frame_width": fw, "frame_height": fh,
        "columns": columns, "rows": rows,
        "frame_seconds": period,
        "cycle_seconds": header.cycle_seconds,
        "loops": poses.len() == header.poses_per_cycle as usize,
        "light": options.env.to_string(),
        "exposure_stops": options.exposure_stops,
        "sun": options.sun.map(|s| json!({"direction": s.direction().to_array(), "illuminance": s.illuminance()})),
        "camera": {"radius_m": options.radius_m, "height_m": options.height_m,
                   "look_at": options.look_at.to_array(), "fov_deg": options.fov_deg,
                   "heading": "azimuth of the camera about the walker, degrees: 0 on +z, increasing toward +x (the stage's walker walks toward +x: 0 sees its right side, 90 its front)"},
        "pivot": "pixel (x right, y down, within the frame) where the walker's foot point on the ground lands",
        "source": field_path.file_name().map(|n| n.to_string_lossy().into_owned()),
        "frames": frames,
    });
    let text = serde_json::to_string_pretty(&document)
        .map_err(|e| SceneError::Internal(format!("the sheet's JSON: {e}")))?;
    frf_core::atomic::write_bytes_atomic(&json_path, text.as_bytes())?;
    Ok(SpriteReport {
        image: png.to_path_buf(),
        json: json_path,
        rows,
        columns,
        width: fw * columns as u32,
        height: fh * rows as u32,
        seconds: started.elapsed().as_secs_f64(),
    })
}

/// The camera of a row: on the orbit at azimuth `heading` degrees.
fn heading_camera(o: &SpriteOptions, heading: f32) -> Result<Camera> {
    let a = heading.to_radians();
    let eye = Vec3::new(o.radius_m * a.sin(), o.height_m, o.radius_m * a.cos());
    Camera::look_at(
        eye,
        o.look_at,
        Vec3::Y,
        o.fov_deg.to_radians(),
        o.frame_size.0,
        o.frame_size.1,
    )
    .map_err(SceneError::Core)
}

/// Copies `frame` into `sheet` with its top-left corner at `(x0, y0)`.
fn paste(sheet: &mut Image<Rgba>, frame: &Image<Rgba>, x0: usize, y0: usize) {
    let (w, h) = frame.size();
    let sw = sheet.size().0;
    let dst = sheet.pixels_mut();
    for (y, row) in frame.pixels().chunks_exact(w).enumerate().take(h) {
        let at = (y0 + y) * sw + x0;
        dst[at..at + w].copy_from_slice(row);
    }
}
