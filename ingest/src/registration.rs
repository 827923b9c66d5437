//! Lighting-basis registration (docs/design.md section 2.2; Wenger et al., SIGGRAPH 2005): the
//! actor moves during the 1/30 s of a lighting set, so every frame of the set is warped
//! onto the reference track frame T1 before the frames are combined.
//!
//! Flow is measured only between track frames (evenly lit, so that brightness constancy
//! holds): from T1 to each other track frame. For a frame at time `t` the flow is
//! interpolated linearly in time between the track frames around it (flow to T1 itself is
//! zero), and extrapolated from the nearest segment outside them (no frame is more than
//! 1/60 s from T1). The frame is then warped onto T1 by reverse lookup,
//! `I'(s) = I(s + f_t(s))`, bilinear.

use frf_core::image::{Border, FlowImage, Image, Pixel};

use crate::error::{IngestError, Result};

/// Flow from the reference frame (at time 0) to each track frame at its time offset.
#[derive(Debug, Clone)]
pub struct TrackFlows {
    /// `(time offset in seconds, flow from the reference to that frame)`, the reference
    /// itself included with zero flow, sorted by time.
    knots: Vec<(f64, FlowImage)>,
}

impl TrackFlows {
    /// Knots from the flows to the other track frames; the reference (time 0, zero flow)
    /// is added. Times must be distinct, finite and non-zero, flows of one size.
    pub fn new(mut to_tracks: Vec<(f64, FlowImage)>) -> Result<Self> {
        let Some((_, first)) = to_tracks.first() else {
            return Err(IngestError::Degenerate(
                "registration needs at least one other track frame".into(),
            ));
        };
        let (w, h) = first.size();
        for (i, (t, f)) in to_tracks.iter().enumerate() {
            if !t.is_finite() || *t == 0.0 {
                let allowed = "a finite, non-zero time in seconds (0 is the reference frame)";
                return Err(frf_core::BadArgument::new(
                    format!("track flow {i}'s time"),
                    t,
                    allowed,
                )
                .into());
            }
            if f.size() != (w, h) {
                return Err(IngestError::sizes(
                    &format!("track flow {i}"),
                    (w, h),
                    f.size(),
                ));
            }
        }
        to_tracks.push((0.0, Image::new(w, h, [0.0; 2])));
        to_tracks.sort_by(|a, b| a.0.total_cmp(&b.0));
        if to_tracks.windows(2).any(|k| k[0].0 == k[1].0) {
            return Err(IngestError::Degenerate(
                "two track frames share a time".into(),
            ));
        }
        Ok(Self { knots: to_tracks })
    }

    /// The flow from the reference to a frame at time offset `t`: piecewise linear in
    /// time through the knots, extended linearly beyond the first and last.
    pub fn at(&self, t: f64) -> FlowImage {
        let k = &self.knots;
        // The segment [i, i + 1] containing t, or the nearest one.
        let i = k
            .windows(2)
            .position(|s| t <= s[1].0)
            .unwrap_or(k.len().saturating_sub(2))
            .min(k.len().saturating_sub(2));
        let (t0, f0) = (&k[i].0, &k[i].1);
        let (t1, f1) = (&k[i + 1].0, &k[i + 1].1);
        let a = ((t - t0) / (t1 - t0)) as f32;
        let pixels = f0
            .pixels()
            .iter()
            .zip(f1.pixels())
            .map(|(p, q)| [p[0] + a * (q[0] - p[0]), p[1] + a * (q[1] - p[1])])
            .collect();
        Image::from_vec(f0.width(), f0.height(), pixels).expect("same size as the knots")
    }
}

/// Warps `frame` onto the reference by reverse lookup, `I'(s) = I(s + F(s))`, bilinear,
/// repeating the edge outside the image.
pub fn warp_to_reference<P: Pixel>(frame: &Image<P>, flow: &FlowImage) -> Result<Image<P>> {
    if !frame.same_size(flow) {
        return Err(IngestError::sizes("the flow", frame.size(), flow.size()));
    }
    let w = frame.width();
    let pixels = flow
        .pixels()
        .iter()
        .enumerate()
        .map(|(i, f)| {
            let (x, y) = ((i % w) as f32, (i / w) as f32);
            frame.sample_bilinear(x + f[0], y + f[1], Border::Clamp)
        })
        .collect();
    Ok(Image::from_vec(w, frame.height(), pixels)?)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn constant(v: [f32; 2]) -> FlowImage {
        Image::new(3, 2, v)
    }

    #[test]
    fn flow_is_linear_in_time_and_extrapolates() {
        let t = TrackFlows::new(vec![
            (-8.0, constant([-2.0, 4.0])),
            (8.0, constant([3.0, 1.0])),
        ])
        .unwrap();
        assert_eq!(t.at(0.0).get(0, 0), [0.0, 0.0]);
        assert_eq!(t.at(-8.0).get(1, 1), [-2.0, 4.0]);
        assert_eq!(t.at(4.0).get(2, 0), [1.5, 0.5]);
        assert_eq!(t.at(-4.0).get(2, 0), [-1.0, 2.0]);
        // Beyond the last track frame the last segment continues.
        assert_eq!(t.at(16.0).get(0, 0), [6.0, 2.0]);
        assert_eq!(t.at(-12.0).get(0, 0), [-3.0, 6.0]);
        let e = TrackFlows::new(vec![]).unwrap_err().to_string();
        assert!(e.contains("at least one other track frame"), "{e}");
        let e = TrackFlows::new(vec![(0.0, constant([0.0; 2]))])
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("track flow 0's time 0: expected a finite, non-zero time"),
            "{e}"
        );
        let e = TrackFlows::new(vec![(1.0, constant([0.0; 2])), (1.0, constant([1.0; 2]))])
            .unwrap_err()
            .to_string();
        assert!(e.contains("share a time"), "{e}");
    }

    #[test]
    fn warping_undoes_a_translation() {
        let img = Image::from_fn(10, 8, |x, y| [x as f32, y as f32, 1.0]);
        // The frame shows the reference moved right by 1.5 px: I(s + 1.5) = R(s).
        let moved = Image::from_fn(10, 8, |x, y| [x as f32 - 1.5, y as f32, 1.0]);
        let back = warp_to_reference(&moved, &Image::new(10, 8, [1.5, 0.0])).unwrap();
        for y in 0..8 {
            for x in 0..7 {
                assert!((back.get(x, y)[0] - img.get(x, y)[0]).abs() < 1e-5);
            }
        }
    }
}
