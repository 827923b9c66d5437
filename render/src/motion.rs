//! Time between captured poses (docs/design.md section 4.7): the subject's motion from
//! one captured pose to the next, carried into the novel view, and the morph in time of
//! the two poses' renders by it.
//!
//! A field's pose-to-pose flow of view `(u, v)` maps each pixel of pose `k`'s image to
//! where it lies in the next (or previous) pose's image of the same camera, in true
//! pixels of both, so it holds the turntable's turn between the two instants as well as
//! the walk. [`pose_motion`] takes the turn out and turns the pixels into metres in the
//! two directions every camera round the grid sees alike, across the subject's axis and
//! along it ([`frf_core::subject_motion`], which the export's player shares).
//!
//! Those two components are stored as the views of a pose (red and green: each plus an
//! offset that keeps it positive; blue: the offset; alpha 1 everywhere), so the renderer
//! morphs them into the novel view exactly as it morphs colour, with the same
//! inter-view flows, on the GPU and the CPU alike. Whatever the views' offsets and
//! weights, the novel view reads its motion as `((r − b) / a, (g − b) / a)`
//! ([`decode_motion`]).
//!
//! [`time_morph`]: the frame at fraction `s` of the way from pose `k` to `k'` samples the
//! render of `k` where the point was at `k` (back along `k'`'s motion toward `k`, a
//! fraction `s` of it) and the render of `k'` where it will be (along `k`'s motion, a
//! fraction `1 − s`), and mixes them `(1 − s, s)`: each motion is taken at the frame's
//! pixel rather than at the point's, which holds where motion varies slowly across a
//! fraction of a pose's step. `shaders/time_morph.wgsl` is its twin on the GPU.

use frf_core::camera::Camera;
use frf_core::grid::PoseStep;
use frf_core::image::{Border, Image, Rgba};
use frf_core::io::linear_to_srgb;
use frf_reflectance::FieldFile;
use frf_reflectance::container::ReadAt;
use glam::{Mat2, Vec2};
use rayon::prelude::*;

use crate::error::{RenderError, Result};
use crate::resident::{PoseSource, ResidentPose, srgb_lut};
use frf_core::subject_motion::view_motion_m;

/// The code of the offset texel (blue): its decoded value times the view's scale is the
/// offset exactly, so that `r − b` is the motion without a rounding bias.
const OFFSET_CODE: u8 = 188;

/// The motion of every view of `source`'s pose toward its `step` neighbour among the
/// field's poses, as a pose of motion views sharing `source`'s geometry and inter-view
/// flows (see the module docs); `None` when the field holds no such flow for any view
/// `source` read. Views not read (transparent in `source`) stay transparent; a view read
/// without a stored flow moves by nothing; a pixel whose flow is unknown (beyond the
/// subject) moves as the nearest pixel whose flow is known.
pub fn pose_motion<R: ReadAt>(
    field: &FieldFile<R>,
    source: &PoseSource,
    step: PoseStep,
) -> Result<Option<ResidentPose>> {
    let h = field.header();
    let g = &source.geometry;
    let (pose, rows, crop) = (g.pose, g.rows, g.crop);
    // Motion is in metres, the same at every level: a texel of a pose read at a level
    // of detail ([`crate::detail`]) takes its block's middle pixel's.
    let level = g.level;
    let mut poses: Vec<u32> = h.poses.iter().map(|p| p.pose).collect();
    poses.sort_unstable();
    let read: Vec<bool> = source
        .alpha
        .iter()
        .map(|a| a.iter().any(|&x| x > 0))
        .collect();
    let views: Vec<Option<(f32, Vec<[u8; 4]>)>> = (0..g.views())
        .into_par_iter()
        .map(|i| -> Result<Option<(f32, Vec<[u8; 4]>)>> {
            if !read[i] {
                return Ok(None);
            }
            let (u, v) = (i / rows, i % rows);
            let Some((to_pose, to_u)) = step.of(pose, u, &poses, g.columns, g.wraps) else {
                return Ok(None);
            };
            let Some(flow) = field.pose_flow(pose, u, v, step)? else {
                return Ok(None);
            };
            // The flow is in the captured image's pixels: read it through the captured
            // cameras, whatever the level the pose was read at.
            let captured = |pose: u32, i: usize| -> Result<Camera> {
                h.pose(pose)?.views[i]
                    .camera
                    .to_camera()
                    .map_err(RenderError::BadCamera)
            };
            let camera = captured(pose, i)?;
            let later = captured(to_pose, to_u * rows + v)?;
            let size = (flow.width(), flow.height());
            let pixel = |k| block_pixel(crop.pixel(k), level, size);
            let dims = (crop.width as usize, crop.height as usize);
            let Some(metres) = view_motion_m(&camera, &later, &flow, dims, pixel) else {
                return Ok(None);
            };
            Ok(Some(encode_view(&metres)))
        })
        .collect::<Result<_>>()?;
    if views.iter().all(Option::is_none) {
        return Ok(None);
    }
    let texels = crop.texels();
    let (scales, prelit) = views
        .into_iter()
        .zip(&read)
        .map(|(view, &read)| match view {
            Some(v) => v,
            // A view read without motion: still, and opaque, so it weighs in the mix.
            None if read => encode_view(&vec![Vec2::ZERO; texels]),
            None => (1.0, Vec::new()),
        })
        .unzip();
    Ok(Some(ResidentPose::with_views(source, scales, prelit)))
}

/// The captured image's pixel a texel `(x, y)` of the image reduced to `level` takes its
/// motion from: its block's middle one (the one right of and below the middle of an
/// even block), within the captured image of `size`.
fn block_pixel((x, y): (usize, usize), level: u8, size: (usize, usize)) -> (usize, usize) {
    let middle = (1usize << level) / 2;
    let at = |t: usize, n: usize| ((t << level) + middle).min(n.saturating_sub(1));
    (at(x, size.0), at(y, size.1))
}

/// One view's motion (metres) as pre-lit texels and their scale (see the module docs).
fn encode_view(metres: &[Vec2]) -> (f32, Vec<[u8; 4]>) {
    let reach = metres
        .iter()
        .map(|m| m.abs().max_element())
        .fold(0.0f32, f32::max)
        .max(1e-4);
    let lut = srgb_lut();
    let offset_fraction = lut[OFFSET_CODE as usize];
    // `reach + offset` must stay at or below the scale, `offset − reach` at or above zero.
    let scale = reach / (1.0 - offset_fraction);
    let offset = scale * offset_fraction;
    let e = |x: f32| (linear_to_srgb((x / scale).clamp(0.0, 1.0)) * 255.0).round() as u8;
    let texels = metres
        .iter()
        .map(|m| [e(m.x + offset), e(m.y + offset), OFFSET_CODE, 255])
        .collect();
    (scale, texels)
}

/// The motion (metres across and along the axis) a rendered motion pixel holds; none
/// where no view reached it.
#[inline]
pub fn decode_motion(p: Rgba) -> Vec2 {
    if p[3] < 1e-3 {
        return Vec2::ZERO;
    }
    Vec2::new(p[0] - p[2], p[1] - p[2]) / p[3]
}

/// The four renders of one frame between two poses (premultiplied RGBA, all of one size):
/// each pose's colour and its motion toward the other.
pub struct TimePair<'a> {
    /// Pose `k`'s colour.
    pub before: &'a Image<Rgba>,
    /// Pose `k'`'s colour.
    pub after: &'a Image<Rgba>,
    /// Pose `k`'s motion toward `k'`.
    pub before_motion: &'a Image<Rgba>,
    /// Pose `k'`'s motion toward `k`.
    pub after_motion: &'a Image<Rgba>,
}

/// The frame a fraction `s` of the way from pose `k` to `k'` (see the module docs);
/// `to_image` is the novel camera's [`motion_to_image`].
pub fn time_morph(pair: &TimePair, s: f32, to_image: Mat2) -> Result<Image<Rgba>> {
    let (w, h) = pair.before.size();
    if [pair.after, pair.before_motion, pair.after_motion]
        .iter()
        .any(|i| i.size() != (w, h))
    {
        return Err(RenderError::Misuse(
            "the renders of a frame between poses differ in size".into(),
        ));
    }
    let rows: Vec<Vec<Rgba>> = (0..h)
        .into_par_iter()
        .map(|y| {
            (0..w)
                .map(|x| {
                    let at = Vec2::new(x as f32, y as f32);
                    let back = to_image * decode_motion(pair.after_motion.get(x, y));
                    let on = to_image * decode_motion(pair.before_motion.get(x, y));
                    let a = at + s * back;
                    let b = at + (1.0 - s) * on;
                    let pa = pair.before.sample_bilinear(a.x, a.y, Border::Zero);
                    let pb = pair.after.sample_bilinear(b.x, b.y, Border::Zero);
                    std::array::from_fn(|c| (1.0 - s) * pa[c] + s * pb[c])
                })
                .collect()
        })
        .collect();
    Ok(Image::from_vec(w, h, rows.into_iter().flatten().collect()).expect("w*h pixels"))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Encoded and decoded through the sRGB table, a motion comes back to within the
    /// texels' precision, and any offset cancels.
    #[test]
    fn motion_survives_its_encoding() {
        let metres: Vec<Vec2> = (0..50)
            .map(|i| Vec2::new(0.06 * (i as f32 / 49.0 - 0.5), -0.02 + 0.001 * i as f32))
            .collect();
        let (scale, texels) = encode_view(&metres);
        let lut = srgb_lut();
        for (m, t) in metres.iter().zip(&texels) {
            let p = [
                scale * lut[t[0] as usize],
                scale * lut[t[1] as usize],
                scale * lut[t[2] as usize],
                1.0,
            ];
            let got = decode_motion(p);
            assert!((got - *m).length() < 0.0015, "{m} -> {got}");
        }
    }

    /// A disc moving right by 4 px: half-way, the morph puts it 2 px on, whole.
    #[test]
    fn half_way_the_morph_moves_a_disc_half_as_far() {
        let disc = |cx: f32| {
            Image::from_fn(32, 16, |x, y| {
                let r = ((x as f32 - cx).powi(2) + (y as f32 - 8.0).powi(2)).sqrt();
                let a = (4.0 - r).clamp(0.0, 1.0);
                [a, 0.5 * a, 0.0, a]
            })
        };
        let to_image = Mat2::from_diagonal(Vec2::splat(100.0));
        // 4 px right is 0.04 m across.
        let moving = |dx: f32| {
            let v = dx / 100.0;
            Image::from_fn(32, 16, move |_, _| {
                let o = 1.0;
                [v + o, o, o, 1.0]
            })
        };
        let (before, after) = (disc(12.0), disc(16.0));
        let (fwd, back) = (moving(4.0), moving(-4.0));
        let pair = TimePair {
            before: &before,
            after: &after,
            before_motion: &fwd,
            after_motion: &back,
        };
        let mid = time_morph(&pair, 0.5, to_image).unwrap();
        let truth = disc(14.0);
        let err = mid
            .pixels()
            .iter()
            .zip(truth.pixels())
            .map(|(a, b)| (a[3] - b[3]).abs())
            .fold(0.0f32, f32::max);
        assert!(err < 0.05, "{err}");
        // A cross-fade would leave two half discs.
        let fade = time_morph(&pair, 0.5, Mat2::ZERO).unwrap();
        let fade_err = fade
            .pixels()
            .iter()
            .zip(truth.pixels())
            .map(|(a, b)| (a[3] - b[3]).abs())
            .fold(0.0f32, f32::max);
        assert!(fade_err > 0.4, "{fade_err}");
    }
}
