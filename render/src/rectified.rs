//! The rectified frame of a quad of the grid (docs/design.md section 4.2): one image
//! plane shared by the quad's four cameras, parallel to the plane of their centres, in
//! which moving the camera is a pure translation of the image by `f Δc / Z`.
//!
//! The four views of a quad look at the subject from centres that lie (on the stage
//! exactly, on a real rig nearly) in one plane, each turned toward the subject. Turning
//! each view about its own centre onto the common orientation `R_q` (optical axis along
//! the plane's inward normal `n`) and the common intrinsics `K_q` is a homography of its
//! pixels, `H_X = K_q R_qᵀ R_X K_X⁻¹`. In that frame a point `P` at depth `Z = n·(P − c)`
//! (the same for every centre `c` in the plane) is seen at
//!
//! ```text
//! x_r(c) = f (P − c)_xy / Z + principal point,
//! ```
//!
//! linear in the camera centre: a camera anywhere in the plane sees the point displaced
//! from view `X`'s image by `f (c − c_X)_xy / Z`, and the flows between the quad's views
//! measure exactly these displacements. This is view morphing's rectification (Seitz &
//! Dyer 1996) for a grid: without it, interpolating the flows of cameras that converge on
//! the subject foreshortens the image (a 17° gap between rows scales it by about 1 %,
//! which misplaces detail by a pixel at the subject's head and feet).

use bytemuck::Zeroable;
use frf_core::camera::{Camera, Intrinsics};
use glam::{Mat3, Vec2, Vec3};

use frf_shaders::types::GpuQuadFrame;

/// The rectified frame of one quad (see the module docs).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct QuadFrame {
    /// `world_from_rectified`: columns `x` (image right), `y` (image down), `n` (inward
    /// normal of the plane of the centres).
    pub rotation: Mat3,
    /// The common intrinsics: the mean of the four views'.
    pub intrinsics: Intrinsics,
    /// Per vertex `[A, B, C, D]`: pixel of the view to rectified pixel (`H_X`).
    pub to_rectified: [Mat3; 4],
    /// Per vertex: rectified pixel to pixel of the view (`H_X⁻¹`).
    pub from_rectified: [Mat3; 4],
    /// Per vertex: its centre in the plane's coordinates (`R_qᵀ c`, `x` and `y`), metres.
    pub centres: [Vec2; 4],
    /// The depth, along `n`, of the point the four views look at most nearly: the
    /// morph's starting depth where no proxy says better.
    pub fixation_depth: f32,
}

/// Applies a homography to a pixel; `None` where the point maps to infinity.
#[inline]
pub fn apply(h: &Mat3, p: Vec2) -> Vec2 {
    let q = *h * p.extend(1.0);
    // Grid homographies turn views by a few degrees: `q.z` stays near 1 for any pixel
    // of the image; guard the division all the same.
    let z = if q.z.abs() < 1e-6 { 1e-6 } else { q.z };
    Vec2::new(q.x / z, q.y / z)
}

fn k_matrix(k: &Intrinsics) -> Mat3 {
    Mat3::from_cols(
        Vec3::new(k.fx, 0.0, 0.0),
        Vec3::new(0.0, k.fy, 0.0),
        Vec3::new(k.cx, k.cy, 1.0),
    )
}

fn k_inverse(k: &Intrinsics) -> Mat3 {
    Mat3::from_cols(
        Vec3::new(1.0 / k.fx, 0.0, 0.0),
        Vec3::new(0.0, 1.0 / k.fy, 0.0),
        Vec3::new(-k.cx / k.fx, -k.cy / k.fy, 1.0),
    )
}

/// The point nearest, in the least-squares sense, to the optical axes of `cams`.
fn fixation(cams: &[&Camera; 4]) -> Option<Vec3> {
    // Σ (I − d dᵀ) p = Σ (I − d dᵀ) c.
    let mut a = Mat3::ZERO;
    let mut b = Vec3::ZERO;
    for c in cams {
        let d = c.forward();
        let m = Mat3::IDENTITY - Mat3::from_cols(d * d.x, d * d.y, d * d.z);
        a += m;
        b += m * c.centre();
    }
    (a.determinant().abs() > 1e-9).then(|| a.inverse() * b)
}

impl QuadFrame {
    /// The frame of the quad of views `cams = [A, B, C, D]` (`C = A`, `D = B` on a grid
    /// of one row). `None` when the centres do not span a plane the views look into.
    pub fn new(cams: [&Camera; 4]) -> Option<Self> {
        let c = cams.map(|c| c.centre());
        let forward: Vec3 = cams.iter().map(|c| c.forward()).sum();
        // The plane: its diagonals' normal, or for one row (or a degenerate quad) the
        // vertical plane through the row's edge.
        let diagonal = (c[3] - c[0]).cross(c[2] - c[1]);
        let mut n = if diagonal.length() > 1e-6 * (c[3] - c[0]).length_squared().max(1e-12) {
            diagonal.normalize()
        } else {
            (c[1] - c[0]).cross(Vec3::Y).normalize_or_zero()
        };
        if n.dot(forward) < 0.0 {
            n = -n;
        }
        if n == Vec3::ZERO || n.dot(forward.normalize_or_zero()) < 0.2 {
            return None;
        }
        let right: Vec3 = cams
            .iter()
            .map(|c| c.world_from_camera.rotation.x_axis)
            .sum();
        let x = (right - n * right.dot(n)).normalize_or_zero();
        if x == Vec3::ZERO {
            return None;
        }
        let rotation = Mat3::from_cols(x, n.cross(x), n);
        let mean =
            |f: fn(&Intrinsics) -> f32| cams.iter().map(|c| f(&c.intrinsics)).sum::<f32>() / 4.0;
        let intrinsics = Intrinsics {
            fx: mean(|k| k.fx),
            fy: mean(|k| k.fy),
            cx: mean(|k| k.cx),
            cy: mean(|k| k.cy),
        };
        let kq = k_matrix(&intrinsics);
        let to_rectified = cams.map(|cam| {
            kq * rotation.transpose() * cam.world_from_camera.rotation * k_inverse(&cam.intrinsics)
        });
        let from_rectified = to_rectified.map(|h| h.inverse());
        if from_rectified.iter().any(|h| !h.is_finite()) {
            return None;
        }
        let centres = c.map(|p| (rotation.transpose() * p).truncate());
        let mean_centre = c.iter().sum::<Vec3>() / 4.0;
        let fixation_depth = fixation(&cams)
            .map(|p| n.dot(p - mean_centre))
            .filter(|z| z.is_finite() && *z > 1e-3)
            .unwrap_or(1.0);
        Some(Self {
            rotation,
            intrinsics,
            to_rectified,
            from_rectified,
            centres,
            fixation_depth,
        })
    }

    /// The rectified pixel of a world direction (seen from any centre in the plane);
    /// `None` for directions that do not point into the plane's inner side.
    pub fn project_direction(&self, dir: Vec3) -> Option<Vec2> {
        let d = self.rotation.transpose() * dir;
        if d.z <= 1e-6 * dir.length() {
            return None;
        }
        let k = &self.intrinsics;
        Some(Vec2::new(k.fx * d.x / d.z + k.cx, k.fy * d.y / d.z + k.cy))
    }

    /// A world point in the plane's coordinates: `x`, `y` in the plane, `z` along `n`.
    pub fn to_plane(&self, p: Vec3) -> Vec3 {
        self.rotation.transpose() * p
    }

    /// The rectified displacement, pixels per unit inverse depth, of the view at
    /// in-plane position `from` seen from in-plane position `to`: `f (to − from)`,
    /// per axis.
    pub fn parallax(&self, from: Vec2, to: Vec2) -> Vec2 {
        (to - from) * Vec2::new(self.intrinsics.fx, self.intrinsics.fy)
    }
}

/// A frame as the GPU reads it (`QuadFrame` of `shaders/morph/solved.wgsl`); a quad
/// without one is marked invalid.
pub fn gpu_frame(frame: Option<&QuadFrame>) -> GpuQuadFrame {
    let Some(f) = frame else {
        return GpuQuadFrame::zeroed();
    };
    let columns = |m: &Mat3| [m.x_axis, m.y_axis, m.z_axis].map(|c| [c.x, c.y, c.z, 0.0]);
    let k = &f.intrinsics;
    let c = &f.centres;
    GpuQuadFrame {
        axis_x: f.rotation.x_axis.extend(0.0).to_array(),
        axis_y: f.rotation.y_axis.extend(0.0).to_array(),
        axis_n: f.rotation.z_axis.extend(0.0).to_array(),
        intrinsics: [k.fx, k.fy, k.cx, k.cy],
        to_rectified: f.to_rectified.each_ref().map(columns),
        from_rectified: f.from_rectified.each_ref().map(columns),
        centres: [
            [c[0].x, c[0].y, c[1].x, c[1].y],
            [c[2].x, c[2].y, c[3].x, c[3].y],
        ],
        fixation_depth: f.fixation_depth,
        valid: 1,
        pad: [0.0; 2],
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn quad() -> [Camera; 4] {
        let target = Vec3::new(0.0, 0.9, 0.0);
        let cam = |az: f32, el: f32| {
            let d =
                frf_core::light::direction_from_azimuth_elevation(az.to_radians(), el.to_radians());
            Camera::look_at(target + d * 4.5, target, Vec3::Y, 0.6, 160, 224).unwrap()
        };
        [
            cam(0.0, 17.0),
            cam(-10.0, 17.0),
            cam(0.0, 34.0),
            cam(-10.0, 34.0),
        ]
    }

    #[test]
    fn a_point_moves_in_the_rectified_frame_by_f_times_the_baseline_over_its_depth() {
        let cams = quad();
        let f = QuadFrame::new([&cams[0], &cams[1], &cams[2], &cams[3]]).unwrap();
        for p in [Vec3::new(0.1, 1.3, 0.2), Vec3::new(-0.3, 0.2, -0.25)] {
            let rect: Vec<Vec2> = (0..4)
                .map(|k| apply(&f.to_rectified[k], cams[k].project(p).unwrap()))
                .collect();
            let z = f.to_plane(p).z - f.to_plane(cams[0].centre()).z;
            for k in 1..4 {
                let expected = -f.parallax(f.centres[0], f.centres[k]) / z;
                let got = rect[k] - rect[0];
                assert!((got - expected).length() < 2e-3, "{k}: {got} vs {expected}");
            }
            // Back to the view's pixels.
            for k in 0..4 {
                let back = apply(&f.from_rectified[k], rect[k]);
                assert!((back - cams[k].project(p).unwrap()).length() < 1e-3);
            }
        }
        assert!((f.fixation_depth - 4.5).abs() < 0.1, "{}", f.fixation_depth);
    }
}
