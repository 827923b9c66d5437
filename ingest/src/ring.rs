//! A real-data adapter: a calibrated ring of photographs in the Middlebury multi-view
//! layout (Seitz et al., CVPR 2006; see `docs/data.md`) ingested as a one-row field
//! with its own cameras and no relighting (one basis condition: the photograph), so that
//! the renderer can be checked against real photographs.
//!
//! - **Calibration**: `*_par.txt` holds, per image, `K` and `[R | t]` with
//!   `x = K [R | t] X` (world to pixels, origin top-left); the camera centre is `−Rᵀt`.
//! - **Frame**: the field's subject frame puts the ring's axis on `+y` (the normal of
//!   the plane of the camera centres, oriented so that most images are upright) through
//!   the point all cameras look at (least-squares meeting point of their optical axes),
//!   and the first view at azimuth 0 (of an open arc: the view at its end). Views are ordered by azimuth about the axis; the
//!   grid closes when no gap between azimuths (the one closing the circle included)
//!   exceeds 2.5 times the median gap; otherwise the ring is an open arc, ordered from
//!   the view after its widest gap (a 130° arc of a ring is open, however its views are
//!   listed).
//! - **Images**: 8-bit sRGB, linearized. **Alpha**: the recipe of the data set's README
//!   (object brighter than 0.19 against the black background), closed by 3 pixels to fill
//!   dark shadows on the object, the largest central component kept, blurred by 1 pixel.
//! - **Flow**: between ring neighbours, rectified like vertical pairs of a capture
//!   ([`crate::interview`]), averaged with the reverse flow.

use std::path::{Path, PathBuf};
use std::time::Instant;

use frf_core::camera::{Camera, Intrinsics, Rigid};
use frf_core::filter::gaussian_blur;
use frf_core::image::{GrayImage, Image, RgbImage};
use frf_flow::FlowParams;
use frf_reflectance::field::{CameraRecord, ConditionRecord, LightRecord, PoseRecord, ViewRecord};
use frf_reflectance::flowcodec::quant::LogQuantizer;
use frf_reflectance::store::{encode_flows, encode_images};
use frf_reflectance::{FieldFile, FieldHeader, FieldWriter};
use glam::{Mat3, Vec3};
use rayon::prelude::*;

use crate::error::{IngestError, Result};
use crate::interview::{GridViews, grid_flows};
use crate::matte::{MATTE_BLUR_SIGMA_PX, largest_central_component};

/// The data set README's background threshold, on 0–1 encoded values.
const BACKGROUND_THRESHOLD: f32 = 0.19;
/// Closing radius that fills the dark shadows on the object, pixels (the README closes
/// by dilating 10 and eroding 7 for a conservative hull; a matte wants a tight one).
const CLOSE_RADIUS_PX: usize = 3;

/// One calibrated photograph.
#[derive(Debug, Clone)]
pub struct RingView {
    /// Image file.
    pub path: PathBuf,
    /// Camera, world frame of the calibration.
    pub camera: Camera,
}

fn bad(path: &Path, problem: impl Into<String>) -> IngestError {
    IngestError::Core(frf_core::CoreError::bad_file(path, problem))
}

/// Reads a Middlebury `*_par.txt` file; image sizes are read from the images' headers.
pub fn read_par(path: &Path) -> Result<Vec<RingView>> {
    let text = std::fs::read_to_string(path).map_err(|e| frf_core::CoreError::io(path, e))?;
    let mut lines = text.lines().filter(|l| !l.trim().is_empty());
    let count: usize = lines
        .next()
        .and_then(|l| l.trim().parse().ok())
        .ok_or_else(|| bad(path, "first line must be the number of images"))?;
    let dir = path.parent().unwrap_or(Path::new("."));
    let views = lines
        .enumerate()
        .map(|(i, line)| {
            let fields: Vec<&str> = line.split_whitespace().collect();
            if fields.len() != 22 {
                return Err(bad(
                    path,
                    format!("line {}: {} fields, expected 22", i + 2, fields.len()),
                ));
            }
            let v: Vec<f32> = fields[1..]
                .iter()
                .map(|f| f.parse::<f32>())
                .collect::<std::result::Result<_, _>>()
                .map_err(|_| bad(path, format!("line {}: a number does not parse", i + 2)))?;
            if v.iter().any(|x| !x.is_finite()) {
                return Err(bad(path, format!("line {}: NaN or infinity", i + 2)));
            }
            // Rows of K, then rows of R (camera from world), then t.
            let r = Mat3::from_cols(
                Vec3::new(v[9], v[12], v[15]),
                Vec3::new(v[10], v[13], v[16]),
                Vec3::new(v[11], v[14], v[17]),
            );
            let t = Vec3::new(v[18], v[19], v[20]);
            let camera_from_world = Rigid {
                rotation: r,
                translation: t,
            };
            camera_from_world
                .validate(1e-3)
                .map_err(|p| bad(path, format!("line {}: {p}", i + 2)))?;
            let image = dir.join(fields[0]);
            let (width, height) = frf_core::io::image_dimensions(&image)?;
            Ok(RingView {
                camera: Camera {
                    width: width as u32,
                    height: height as u32,
                    intrinsics: Intrinsics {
                        fx: v[0],
                        fy: v[4],
                        cx: v[2],
                        cy: v[5],
                    },
                    world_from_camera: camera_from_world.inverse(),
                },
                path: image,
            })
        })
        .collect::<Result<Vec<_>>>()?;
    if views.len() != count || views.len() < 3 {
        return Err(bad(
            path,
            format!(
                "{} images listed, header says {count} (need at least 3)",
                views.len()
            ),
        ));
    }
    Ok(views)
}

/// The point nearest to all cameras' optical axes (least squares).
fn meeting_point(cameras: &[Camera]) -> Vec3 {
    let (mut a, mut b) = (Mat3::ZERO, Vec3::ZERO);
    for c in cameras {
        let d = c.forward();
        let p = Mat3::IDENTITY - Mat3::from_cols(d * d.x, d * d.y, d * d.z);
        a += p;
        b += p * c.centre();
    }
    a.inverse() * b
}

/// Centre of the circle through points lying in the plane through `mean` normal to
/// `axis`: the algebraic least-squares fit (Kåsa, 1976), `x² + y² = 2ax + 2by + c`,
/// which the views need not cover evenly.
fn circle_centre(points: &[Vec3], mean: Vec3, axis: Vec3) -> Vec3 {
    let e1 = axis.any_orthonormal_vector();
    let e2 = axis.cross(e1);
    // Normal equations of the 3-parameter linear fit, in f64.
    let (mut m, mut r) = ([[0.0f64; 3]; 3], [0.0f64; 3]);
    for p in points {
        let (x, y) = ((*p - mean).dot(e1) as f64, (*p - mean).dot(e2) as f64);
        let row = [2.0 * x, 2.0 * y, 1.0];
        let rhs = x * x + y * y;
        for i in 0..3 {
            for j in 0..3 {
                m[i][j] += row[i] * row[j];
            }
            r[i] += row[i] * rhs;
        }
    }
    let det = |a: &[[f64; 3]; 3]| {
        a[0][0] * (a[1][1] * a[2][2] - a[1][2] * a[2][1])
            - a[0][1] * (a[1][0] * a[2][2] - a[1][2] * a[2][0])
            + a[0][2] * (a[1][0] * a[2][1] - a[1][1] * a[2][0])
    };
    let d = det(&m);
    if d.abs() < 1e-18 {
        return mean;
    }
    // Cramer's rule for the two centre coordinates.
    let solve = |k: usize| {
        let mut a = m;
        for (row, value) in a.iter_mut().zip(r) {
            row[k] = value;
        }
        det(&a) / d
    };
    mean + e1 * solve(0) as f32 + e2 * solve(1) as f32
}

/// The subject frame of a ring: `(subject_from_world, views sorted by azimuth, wraps)`.
pub fn ring_frame(views: &[RingView]) -> Result<(Rigid, Vec<usize>, bool)> {
    let centres: Vec<Vec3> = views.iter().map(|v| v.camera.centre()).collect();
    let mean = centres.iter().copied().sum::<Vec3>() / centres.len() as f32;
    // Normal of the ring's plane: the sum of cross products of successive radii is
    // robust to their order as long as the ring is roughly convex.
    let mut normal = Vec3::ZERO;
    let by_index: Vec<Vec3> = centres.iter().map(|c| *c - mean).collect();
    for (i, r) in by_index.iter().enumerate() {
        let s = by_index[(i + 1) % by_index.len()];
        let n = r.cross(s);
        normal += if n.dot(normal) < 0.0 { -n } else { n };
    }
    let mut axis = normal.normalize_or_zero();
    if axis == Vec3::ZERO {
        return Err(IngestError::Degenerate(
            "the cameras do not form a ring".into(),
        ));
    }
    // Upright: most cameras' image "up" (−y of the camera) along +axis.
    let up: f32 = views
        .iter()
        .map(|v| (-v.camera.world_from_camera.rotation.y_axis).dot(axis))
        .sum();
    if up < 0.0 {
        axis = -axis;
    }
    let look = meeting_point(&views.iter().map(|v| v.camera).collect::<Vec<_>>());
    let origin = circle_centre(&centres, mean, axis) + axis * (look - mean).dot(axis);
    // x and z: view `first`'s direction from the axis is +z.
    let frame = |first: usize| {
        let radial = (centres[first] - origin) - axis * (centres[first] - origin).dot(axis);
        let z = radial.normalize_or_zero();
        let x = axis.cross(z);
        let world_to_subject = Mat3::from_cols(x, axis, z).transpose();
        Rigid {
            rotation: world_to_subject,
            translation: -(world_to_subject * origin),
        }
    };
    let sorted = |f: &Rigid| {
        let mut azimuths: Vec<(f32, usize)> = centres
            .iter()
            .enumerate()
            .map(|(i, c)| {
                let p = f.transform_point(*c);
                (p.x.atan2(p.z).rem_euclid(std::f32::consts::TAU), i)
            })
            .collect();
        azimuths.sort_by(|a, b| a.0.total_cmp(&b.0));
        azimuths
    };
    let azimuths = sorted(&frame(0));
    let n = azimuths.len();
    // The gaps between successive azimuths, the last one closing the circle: the ring
    // is open where one gap exceeds 2.5 times the median gap, and starts after it.
    let gaps: Vec<f32> = (0..n)
        .map(|i| (azimuths[(i + 1) % n].0 - azimuths[i].0).rem_euclid(std::f32::consts::TAU))
        .collect();
    let mut by_size = gaps.clone();
    by_size.sort_by(f32::total_cmp);
    let median = by_size[n / 2];
    let (widest, &gap) = gaps
        .iter()
        .enumerate()
        .max_by(|a, b| a.1.total_cmp(b.1))
        .ok_or_else(|| IngestError::Degenerate("a ring without views".into()))?;
    let wraps = gap < 2.5 * median;
    let start = if wraps { 0 } else { (widest + 1) % n };
    let order: Vec<usize> = (0..n).map(|k| azimuths[(start + k) % n].1).collect();
    // A closed ring keeps the first listed view at azimuth 0 (fields ingested before
    // open arcs were recognised depend on it); an open arc puts its first view there.
    let first = if wraps { 0 } else { order[0] };
    Ok((frame(first), order, wraps))
}

/// A photograph: linear RGB (sRGB decoded) and its alpha.
pub fn photo_and_alpha(path: &Path) -> Result<(RgbImage, GrayImage)> {
    let encoded = frf_core::io::read_rgb(path)?;
    let (w, h) = encoded.size();
    let raw: Vec<bool> = encoded
        .pixels()
        .iter()
        .map(|p| p.iter().copied().fold(0.0, f32::max) > BACKGROUND_THRESHOLD)
        .collect();
    let r = CLOSE_RADIUS_PX as i64;
    let dilate = |m: &[bool], value: bool| -> Vec<bool> {
        (0..w * h)
            .map(|i| {
                let (x, y) = ((i % w) as i64, (i / w) as i64);
                let hit = (-r..=r).any(|dy| {
                    (-r..=r).any(|dx| {
                        let (xx, yy) = (x + dx, y + dy);
                        xx >= 0
                            && yy >= 0
                            && xx < w as i64
                            && yy < h as i64
                            && m[yy as usize * w + xx as usize] == value
                    })
                });
                if hit { value } else { !value }
            })
            .collect()
    };
    let closed = dilate(&dilate(&raw, true), false);
    let fg = largest_central_component(&Image::from_vec(w, h, closed)?)?;
    let alpha = gaussian_blur(&fg.map(|b| if b { 1.0 } else { 0.0 }), MATTE_BLUR_SIGMA_PX);
    let photo = Image::from_fn(w, h, |x, y| {
        if alpha.get(x, y) > 0.0 {
            encoded.get(x, y).map(frf_core::io::srgb_to_linear)
        } else {
            [0.0; 3]
        }
    });
    Ok((photo, alpha))
}

/// What [`ingest_ring`] did.
#[derive(Debug, Clone, serde::Serialize)]
pub struct RingReport {
    /// Views in the ring.
    pub views: usize,
    /// Whether the ring closes.
    pub wraps: bool,
    /// Mean alpha over the images (fraction of the frame covered).
    pub coverage: f64,
    /// Wall-clock seconds.
    pub seconds: f64,
}

impl RingReport {
    /// The ring written to `out`, for a person.
    pub fn describe(&self, out: &Path) -> String {
        format!(
            "ring of {} photographs ({}) written to {} in {:.1} s (wall); mean matte coverage {:.1} % of the frame",
            self.views,
            if self.wraps { "closed" } else { "open" },
            out.display(),
            self.seconds,
            100.0 * self.coverage
        )
    }
}

/// The ring described by `par` in its subject frame: the views sorted by azimuth, their
/// cameras (subject frame) and whether the ring closes.
pub fn ring_views(par: &Path) -> Result<(Vec<RingView>, Vec<Camera>, bool)> {
    let all = read_par(par)?;
    let (subject_from_world, order, wraps) = ring_frame(&all)?;
    let views: Vec<RingView> = order.iter().map(|&i| all[i].clone()).collect();
    let (w, h) = (views[0].camera.width, views[0].camera.height);
    if let Some(v) = views
        .iter()
        .find(|v| (v.camera.width, v.camera.height) != (w, h))
    {
        return Err(bad(
            &v.path,
            format!(
                "{}x{}, the others are {w}x{h}",
                v.camera.width, v.camera.height
            ),
        ));
    }
    let cameras = views
        .iter()
        .map(|v| v.camera.transformed(&subject_from_world))
        .collect();
    Ok((views, cameras, wraps))
}

/// Ingests the ring described by `par` into the field file `out`, keeping every
/// `stride`-th view in azimuth order from the first (1: all; 2, 3, 4, ...: the views
/// between them are held out for evaluation, in the subject frame of the whole ring).
pub fn ingest_ring(
    par: &Path,
    out: &Path,
    params: &FlowParams,
    jpeg_quality: u8,
    stride: usize,
) -> Result<RingReport> {
    let start = Instant::now();
    let (all_views, all_cameras, all_wrap) = ring_views(par)?;
    if stride == 0 || all_views.len() / stride.max(1) < 3 {
        return Err(bad(
            par,
            format!(
                "stride {stride} leaves fewer than 3 of the ring's {} views",
                all_views.len()
            ),
        ));
    }
    // The kept views close into a ring when the whole ring does (the gap from the last
    // kept view to the first is then at most `stride` views).
    let wraps = all_wrap;
    let views: Vec<&RingView> = all_views.iter().step_by(stride).collect();
    let cameras: Vec<Camera> = all_cameras.iter().step_by(stride).copied().collect();
    let (w, h) = (cameras[0].width, cameras[0].height);
    let images: Vec<(RgbImage, GrayImage)> = views
        .par_iter()
        .map(|v| photo_and_alpha(&v.path))
        .collect::<Result<_>>()?;
    let columns = views.len();
    let flows = grid_flows(
        &GridViews {
            columns,
            rows: 1,
            wraps,
            images: &images.iter().map(|i| Some(&i.0)).collect::<Vec<_>>(),
            alphas: &images.iter().map(|i| Some(&i.1)).collect::<Vec<_>>(),
            cameras: &cameras,
            wanted: None,
            // The hull's search region is the stage's, not a ring's: matched on images.
            hull: None,
        },
        params,
        &|| Ok(()),
    )?
    .flows;
    let header = FieldHeader {
        description: format!("calibrated ring of photographs {}", par.display()),
        columns,
        rows: 1,
        wraps,
        width: w,
        height: h,
        cycle_seconds: 1.0,
        poses_per_cycle: 1,
        conditions: vec![ConditionRecord {
            name: "photograph".into(),
            floor: false,
            // No relighting: one condition standing for the whole sphere.
            lights: vec![LightRecord {
                direction: [0.0, 1.0, 0.0],
                intensity: [1.0; 3],
                solid_angle_sr: 4.0 * std::f32::consts::PI,
            }],
        }],
        poses: vec![PoseRecord {
            pose: 0,
            time_s: 0.0,
            views: cameras
                .iter()
                .map(|c| ViewRecord {
                    camera: CameraRecord::from_camera(c),
                    turntable_deg: 0.0,
                })
                .collect(),
            flow_quantizer: LogQuantizer::fit(
                flows
                    .iter()
                    .flatten()
                    .flatten()
                    .flat_map(|f| f.pixels().iter().flatten().copied()),
            ),
            pose_flows_to: None,
        }],
        flow_predicted: true,
        jpeg_quality,
        shadows: None,
        hulls: None,
        gait_speed_mps: None,
    };
    let mut writer = FieldWriter::create(out, header.clone())?;
    for u in 0..columns {
        writer.add_view(
            0,
            u,
            0,
            &encode_images(&header, std::slice::from_ref(&images[u].0), &images[u].1)?,
        )?;
        writer.add_view(0, u, 0, &encode_flows(&header, 0, &flows[u])?)?;
    }
    writer.finish()?;
    FieldFile::open(out)?;
    let coverage = images
        .iter()
        .map(|i| i.1.pixels().iter().map(|&a| a as f64).sum::<f64>() / (w * h) as f64)
        .sum::<f64>()
        / columns as f64;
    Ok(RingReport {
        views: columns,
        wraps,
        coverage,
        seconds: start.elapsed().as_secs_f64(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Views on a circle of radius 2 about the vertical axis through `(0, 1, 0)`, from
    /// azimuth 0 over `arc_deg` degrees, looking at its centre, listed out of order.
    fn arc(count: usize, arc_deg: f32, closed: bool) -> Vec<RingView> {
        let step = if closed {
            arc_deg / count as f32
        } else {
            arc_deg / (count - 1) as f32
        };
        let mut views: Vec<RingView> = (0..count)
            .map(|i| {
                let a = (i as f32 * step).to_radians();
                let eye = Vec3::new(2.0 * a.sin(), 1.3, 2.0 * a.cos());
                RingView {
                    path: PathBuf::from(format!("view{i}.png")),
                    camera: Camera::look_at(eye, Vec3::new(0.0, 1.0, 0.0), Vec3::Y, 0.6, 64, 48)
                        .unwrap(),
                }
            })
            .collect();
        views.swap(1, count - 2);
        // Listed from the middle of the arc.
        views.rotate_left(count / 2);
        views
    }

    #[test]
    fn the_calibration_says_whether_a_ring_closes() {
        let (_, order, wraps) = ring_frame(&arc(48, 360.0, true)).unwrap();
        assert!(wraps, "a whole ring closes");
        assert_eq!(order.len(), 48);
        // A 130-degree arc of a ring is open, however its views are listed; its views
        // come out in azimuth order from one end.
        let views = arc(16, 130.0, false);
        let (frame, order, wraps) = ring_frame(&views).unwrap();
        assert!(!wraps, "a 130-degree arc is open");
        let azimuth = |i: usize| {
            let p = frame.transform_point(views[order[i]].camera.centre());
            p.x.atan2(p.z).rem_euclid(std::f32::consts::TAU)
        };
        assert!((1..16).all(|i| azimuth(i) > azimuth(i - 1)));
        assert!(azimuth(15) - azimuth(0) < 131f32.to_radians());
    }
}
