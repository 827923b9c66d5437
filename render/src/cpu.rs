//! The CPU reference renderer (rayon): for every pixel of the virtual camera, the ray
//! through it is re-binned through the cylinder of camera centres ([`crate::cylinder`])
//! and the quad's images morphed where they show what the ray sees ([`crate::morph`]). The GPU renderer
//! computes the same in `shaders/rebin.wgsl` and is tested against this one.

use frf_core::camera::Camera;
use frf_core::image::{Image, Rgba};
use glam::Vec2;
use rayon::prelude::*;

use crate::cylinder::{Clamp, Cylinder, CylinderHit};
use crate::footprint::PixelBox;
use crate::morph::{Variant, shade};
use crate::resident::ResidentPose;

/// What happened to the pixels of a frame.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct FrameStats {
    /// Pixels whose ray crossed the cylinder inside the grid.
    pub inside: usize,
    /// Pixels clamped to the top row (rays above the grid).
    pub clamped_above: usize,
    /// Pixels clamped to the bottom row.
    pub clamped_below: usize,
    /// Pixels whose ray meets no view (looking away from, or along the axis of, the grid).
    pub missed: usize,
}

impl FrameStats {
    fn count(&mut self, hit: Option<&CylinderHit>) {
        match hit.map(|h| h.clamped) {
            Some(Clamp::None) => self.inside += 1,
            Some(Clamp::Above) => self.clamped_above += 1,
            Some(Clamp::Below) => self.clamped_below += 1,
            None => self.missed += 1,
        }
    }

    /// The counts of two frames (or two walkers of a frame) together.
    pub fn merge(mut self, o: Self) -> Self {
        self.inside += o.inside;
        self.clamped_above += o.clamped_above;
        self.clamped_below += o.clamped_below;
        self.missed += o.missed;
        self
    }
}

/// One pixel: premultiplied RGBA and how its ray was re-binned.
pub fn render_pixel(
    pose: &ResidentPose,
    cylinder: &Cylinder,
    camera: &Camera,
    pixel: Vec2,
    variant: Variant,
) -> (Rgba, Option<CylinderHit>) {
    let dir = camera.ray_direction(pixel);
    let Some(hit) = cylinder.intersect(camera.centre(), dir) else {
        return ([0.0; 4], None);
    };
    match shade(pose, &hit, camera.centre(), dir, variant) {
        Some(px) => (px, Some(hit)),
        None => ([0.0; 4], None),
    }
}

/// Renders a frame of `camera` (subject frame) with `variant`.
pub fn render_cpu(
    pose: &ResidentPose,
    camera: &Camera,
    variant: Variant,
) -> (Image<Rgba>, FrameStats) {
    render_cpu_within(pose, camera, variant, None)
}

/// [`render_cpu`] shading only the pixels `within` (the whole frame when `None`): the
/// others are transparent and counted as missed, as the GPU's frame pass leaves them.
pub fn render_cpu_within(
    pose: &ResidentPose,
    camera: &Camera,
    variant: Variant,
    within: Option<PixelBox>,
) -> (Image<Rgba>, FrameStats) {
    let cylinder = &pose.geometry.cylinder;
    let (w, h) = (camera.width as usize, camera.height as usize);
    let within = within.unwrap_or(PixelBox::whole(camera.width, camera.height));
    let rows: Vec<(Vec<Rgba>, FrameStats)> = (0..h)
        .into_par_iter()
        .map(|y| {
            let mut stats = FrameStats::default();
            let row = (0..w)
                .map(|x| {
                    if !within.contains(x as u32, y as u32) {
                        stats.count(None);
                        return [0.0; 4];
                    }
                    let (px, hit) = render_pixel(
                        pose,
                        cylinder,
                        camera,
                        Vec2::new(x as f32, y as f32),
                        variant,
                    );
                    stats.count(hit.as_ref());
                    px
                })
                .collect();
            (row, stats)
        })
        .collect();
    let mut stats = FrameStats::default();
    let mut pixels = Vec::with_capacity(w * h);
    for (row, s) in rows {
        pixels.extend(row);
        stats = stats.merge(s);
    }
    (
        Image::from_vec(w, h, pixels).expect("w*h pixels by construction"),
        stats,
    )
}

/// The depth of the subject of `pose` at each pixel of `camera` (subject frame) within
/// `within` ([`crate::proxy::Proxy::depth`]: metres along the pixel's ray); infinite
/// outside it. What orders overlapping walkers pixel by pixel
/// ([`crate::composite::stack_by_depth`]); twin of the frame pass's depth.
pub fn depth_cpu_within(
    pose: &ResidentPose,
    camera: &Camera,
    within: Option<PixelBox>,
) -> Image<f32> {
    let (w, h) = (camera.width as usize, camera.height as usize);
    let within = within.unwrap_or(PixelBox::whole(camera.width, camera.height));
    let proxy = &pose.geometry.proxy;
    let rows: Vec<Vec<f32>> = (0..h)
        .into_par_iter()
        .map(|y| {
            (0..w)
                .map(|x| {
                    if !within.contains(x as u32, y as u32) {
                        return f32::INFINITY;
                    }
                    let dir = camera.ray_direction(Vec2::new(x as f32, y as f32));
                    proxy.depth(camera.centre(), dir)
                })
                .collect()
        })
        .collect();
    Image::from_vec(w, h, rows.into_iter().flatten().collect()).expect("w*h pixels by construction")
}
