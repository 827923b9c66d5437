//! A synthetic pose of the original system's shape, for benchmarks that must run without
//! a field: 36 x 3 views of 320 x 448 pixels on a ring of radius 4.5 m (rows at 0°, 17°
//! and 34° of elevation about a point 0.9 m up, columns 10° apart), cropped to 170 x 400
//! as an ingested walker is, every neighbour flow stored. The content is procedural (an
//! elliptical silhouette with a striped texture, a smooth flow field of a few pixels): it
//! has the sizes, layout and memory traffic of a real pose, not its looks. Nothing here
//! comes from the virtual light stage.

use std::sync::Arc;

use frf_core::camera::Camera;
use frf_core::grid::Neighbour;
use frf_core::light::direction_from_azimuth_elevation;
use frf_reflectance::flowcodec::quant::LogQuantizer;
use frf_reflectance::imagecodec::BasisCodes;
use glam::Vec3;

use crate::error::{RenderError, Result};
use crate::geometry::{Crop, PoseGeometry};
use crate::resident::{LightingPlan, PoseFlows, PoseSource, flow_lut};

/// Columns of the synthetic grid.
pub const COLUMNS: usize = 36;
/// Rows of the synthetic grid.
pub const ROWS: usize = 3;
/// Image size of a view.
pub const IMAGE: (u32, u32) = (320, 448);
/// The crop of every view.
pub const CROP: Crop = Crop {
    x0: 75,
    y0: 24,
    width: 170,
    height: 400,
};
/// Radius of the ring of cameras, metres.
pub const RADIUS_M: f32 = 4.5;
/// The point the cameras look at.
pub const TARGET: Vec3 = Vec3::new(0.0, 0.9, 0.0);
/// Vertical field of view of the cameras, radians.
const FOV: f32 = 0.48;

/// The camera of view `(u, v)`.
fn camera(u: usize, v: usize) -> Result<Camera> {
    let elevation = [0.0f32, 17.0, 34.0][v].to_radians();
    let azimuth = -(u as f32 * 10.0).to_radians();
    let eye = TARGET + direction_from_azimuth_elevation(azimuth, elevation) * RADIUS_M;
    Camera::look_at(eye, TARGET, Vec3::Y, FOV, IMAGE.0, IMAGE.1)
        .map_err(|e| RenderError::Misuse(e.to_string()))
}

/// The synthetic pose (see the module docs), lit by one white condition.
pub fn synthetic_pose() -> Result<PoseSource> {
    let views = COLUMNS * ROWS;
    let cameras = (0..COLUMNS)
        .flat_map(|u| (0..ROWS).map(move |v| (u, v)))
        .map(|(u, v)| camera(u, v))
        .collect::<Result<Vec<_>>>()?;
    let has_flow = |i: usize, n: Neighbour| {
        let v = i % ROWS;
        match n {
            Neighbour::Right | Neighbour::Left => true,
            Neighbour::Up => v + 1 < ROWS,
            Neighbour::Down => v > 0,
        }
    };
    let geometry = PoseGeometry::new(0, COLUMNS, ROWS, true, IMAGE, CROP, cameras, has_flow);
    let (w, h) = (CROP.width as usize, CROP.height as usize);
    // An elliptical silhouette filling the crop, soft over two pixels.
    let alpha_at = |x: usize, y: usize| {
        let dx = (x as f32 + 0.5) / w as f32 * 2.0 - 1.0;
        let dy = (y as f32 + 0.5) / h as f32 * 2.0 - 1.0;
        let r = (dx * dx + dy * dy).sqrt();
        let edge = 2.0 / w as f32;
        ((1.0 - r) / edge).clamp(0.0, 1.0)
    };
    let alpha: Vec<u8> = (0..w * h)
        .map(|i| (alpha_at(i % w, i / w) * 255.0).round() as u8)
        .collect();
    let quantizer = LogQuantizer::new(0.5, 64.0).map_err(|e| RenderError::Misuse(e.to_string()))?;
    let mut basis = Vec::with_capacity(views);
    let mut codes = Vec::with_capacity(views);
    for i in 0..views {
        let texels = (0..w * h)
            .map(|p| {
                let (x, y) = (p % w, p / w);
                let stripe = ((y / 6 + i) % 3) as u8;
                [60 + 50 * stripe, (80 + x / 2) as u8, (200 - y / 3) as u8]
            })
            .collect();
        basis.push(BasisCodes {
            width: w,
            height: h,
            tiles: vec![texels],
            scales: vec![1.0],
        });
        // A smooth flow of a few pixels toward each neighbour (sign by direction).
        let flow = |n: Neighbour| -> Vec<[i8; 2]> {
            let (sx, sy) = match n {
                Neighbour::Right => (1.0, 0.0),
                Neighbour::Left => (-1.0, 0.0),
                Neighbour::Up => (0.0, 1.0),
                Neighbour::Down => (0.0, -1.0),
            };
            (0..w * h)
                .map(|p| {
                    let (x, y) = ((p % w) as f32 / w as f32, (p / w) as f32 / h as f32);
                    let mag = 6.0 + 4.0 * (x * 6.0 + y * 3.0).sin();
                    [
                        quantizer.encode(sx * mag + 0.5 * sy),
                        quantizer.encode(sy * mag * 0.8 + 0.3 * sx),
                    ]
                })
                .collect()
        };
        codes.push(Neighbour::ALL.map(|n| has_flow(i, n).then(|| flow(n))));
    }
    Ok(PoseSource {
        geometry: Arc::new(geometry),
        flows: Arc::new(PoseFlows {
            codes,
            table: flow_lut(&quantizer),
            quantizer,
        }),
        basis: Arc::new(basis),
        alpha: Arc::new(vec![alpha; views]),
        normals: Arc::new(vec![Vec::new(); views]),
        surfaces: Arc::new(vec![Vec::new(); views]),
        condition_lights: Arc::new(Vec::new()),
        coefficients: vec![vec![[1.0, 1.0, 1.0]]; views],
        suns: Arc::from([]),
        sun_coefficients: Vec::new(),
        floor_shares: Vec::new(),
        floor_conditions: Arc::new(Vec::new()),
        ground_coefficients: None,
        plan: LightingPlan {
            skipped_conditions: Vec::new(),
            images_combined: views,
            images_total: views,
        },
    })
}

/// A camera between the synthetic grid's views (a quarter of the way to the next column
/// and a third of the way to the next row, 4.5 m out), looking at the subject, of
/// `size`: the bench's frame.
pub fn bench_camera(size: (u32, u32)) -> Result<Camera> {
    let elevation = (17.0f32 / 3.0).to_radians();
    let azimuth = -(2.5f32 * 10.0).to_radians();
    let eye = TARGET + direction_from_azimuth_elevation(azimuth, elevation) * RADIUS_M;
    Camera::look_at(eye, TARGET, Vec3::Y, FOV, size.0, size.1)
        .map_err(|e| RenderError::Misuse(e.to_string()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_synthetic_pose_has_the_original_layout() {
        let p = synthetic_pose().unwrap();
        assert_eq!(p.geometry.views(), 108);
        // 36 x 3 x 2 horizontal flows, 36 x 2 x 2 vertical.
        assert_eq!(p.geometry.flow_layer_count, 216 + 144);
        // Its resident size is the paper pose's (78.4 MB ingested).
        let mb = p.geometry.resident_bytes() as f64 / 1e6;
        assert!((mb - 78.4).abs() < 2.0, "{mb} MB");
        // The bench camera sees the subject through the grid's interior.
        let cam = bench_camera((64, 64)).unwrap();
        let hit = p
            .geometry
            .cylinder
            .intersect(cam.centre(), (TARGET - cam.centre()).normalize())
            .unwrap();
        assert_eq!(hit.clamped, crate::cylinder::Clamp::None);
        assert!(hit.beta > 0.1 && hit.beta < 0.9 && hit.gamma > 0.1 && hit.gamma < 0.9);
    }
}
