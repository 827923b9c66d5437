//! One view of one pose, from captured frames to registered basis images: load the set's
//! frames, matte every track frame against the matte frame after it ([`crate::matte`]),
//! measure flow from the matted reference track frame to the other track frames, warp
//! every basis frame onto the reference ([`crate::registration`]), and matte it onto
//! black with the reference's alpha and the clean plate of its own condition, keeping
//! backdrop light out of the edge pixels as [`EdgeMethod`] says ([`crate::edges`]). The sum of
//! the registered basis images (the subject under the whole dome: evenly lit, and with
//! a fifth of a single frame's relative noise) is the image inter-view flow is measured on.

use std::time::Instant;

use frf_core::capture::{Capture, SlotKind};
use frf_core::image::{FlowImage, GrayImage, RgbImage};
use frf_flow::FlowParams;

use crate::edges::{EdgeMethod, extend_interior, soft_alpha};
use crate::error::Result;
use crate::matte::{MatteInput, MatteRule, alpha as matte_alpha, premultiply};
use crate::registration::{TrackFlows, warp_to_reference};

/// Thread-seconds spent in each step of [`process_view`].
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct ViewSeconds {
    /// Reading and decoding frame files.
    pub load: f64,
    /// Mattes of the track frames.
    pub matte: f64,
    /// Flow between track frames.
    pub registration_flow: f64,
    /// Warping and matting the basis frames.
    pub registration_warp: f64,
}

impl std::ops::AddAssign for ViewSeconds {
    fn add_assign(&mut self, o: Self) {
        self.load += o.load;
        self.matte += o.matte;
        self.registration_flow += o.registration_flow;
        self.registration_warp += o.registration_warp;
    }
}

/// What a view keeps beside its basis images when asked (to measure what registration
/// and edge decontamination gain).
#[derive(Debug, Clone)]
pub struct KeptFrames {
    /// The basis frames matted without registration, with the same edge treatment.
    pub unregistered: Vec<RgbImage>,
    /// The registered basis frames matted with the blurred binary matte, before edge
    /// decontamination ([`EdgeMethod::None`]).
    pub raw_basis: Vec<RgbImage>,
    /// That blurred binary matte.
    pub raw_alpha: GrayImage,
}

/// A registered view.
#[derive(Debug, Clone)]
pub struct RegisteredView {
    /// Alpha of the reference track frame, shared by the whole set (after edge
    /// decontamination when the method changes it).
    pub alpha: GrayImage,
    /// The matted reference track frame.
    pub track: RgbImage,
    /// The sum of the registered basis images matted with the blurred binary matte (the
    /// image inter-view flow is measured on, the same whatever the edge method).
    pub summed: RgbImage,
    /// Registered basis images, matted onto black, in condition order.
    pub basis: Vec<RgbImage>,
    /// Frames kept only when asked ([`ViewSettings::keep_unregistered`]).
    pub kept: Option<KeptFrames>,
    /// Flow from the reference to each other track frame: `(time offset, flow)`.
    pub track_flows: Vec<(f64, FlowImage)>,
    /// Time spent per step.
    pub seconds: ViewSeconds,
}

/// How a view is processed.
#[derive(Debug, Clone)]
pub struct ViewSettings {
    /// Flow parameters of the registration.
    pub flow: FlowParams,
    /// Which pixels are foreground.
    pub matte_rule: MatteRule,
    /// Keep the unregistered and the undecontaminated frames too ([`KeptFrames`]).
    pub keep_unregistered: bool,
    /// What to do about backdrop light at the subject's edges.
    pub edge: EdgeMethod,
}

/// Processes view `(u, v)` of `pose`; `clean` holds camera `v`'s clean plates by slot.
pub fn process_view(
    capture: &Capture,
    pose: u32,
    u: usize,
    v: usize,
    clean: &[RgbImage],
    settings: &ViewSettings,
) -> Result<RegisteredView> {
    let (flow, keep_unregistered) = (&settings.flow, settings.keep_unregistered);
    let mut seconds = ViewSeconds::default();
    let mut clock = Instant::now();
    let mut lap = |into: &mut f64| {
        *into += clock.elapsed().as_secs_f64();
        clock = Instant::now();
    };
    let frames = (0..capture.slots().len())
        .map(|slot| capture.load_frame(pose, u, v, slot))
        .collect::<frf_core::Result<Vec<_>>>()?;
    lap(&mut seconds.load);

    let reference = capture.reference_track();
    let mut matted_tracks = Vec::new();
    let mut reference_alpha = None;
    for t in capture.tracks() {
        let input = MatteInput {
            track: &frames[t.track_slot],
            matte: &frames[t.matte_slot],
            matte_clean: &clean[t.matte_slot],
        };
        let a = matte_alpha(&input, settings.matte_rule)?;
        let matted = premultiply(&frames[t.track_slot], &a, &clean[t.track_slot])?;
        if t.index == reference.index {
            reference_alpha = Some((a, t.matte_slot));
        }
        matted_tracks.push((t, matted));
    }
    let (raw_alpha, matte_slot) = reference_alpha.expect("the reference track is among the tracks");
    // The set's alpha, which the basis frames are matted with. The track frames keep the
    // blurred binary matte, so that registration flow does not depend on the edge method.
    let alpha = match settings.edge {
        EdgeMethod::Solve => soft_alpha(&raw_alpha, &frames[matte_slot], &clean[matte_slot])?,
        EdgeMethod::None | EdgeMethod::Extend => raw_alpha.clone(),
    };
    let track = matted_tracks
        .iter()
        .find(|(t, _)| t.index == reference.index)
        .map(|(_, m)| m.clone())
        .expect("the reference track is among the tracks");
    lap(&mut seconds.matte);

    let track_flows = matted_tracks
        .iter()
        .filter(|(t, _)| t.index != reference.index)
        .map(|(t, m)| {
            let offset = capture.slots()[t.track_slot].time_offset_s
                - capture.slots()[reference.track_slot].time_offset_s;
            Ok((offset, frf_flow::estimate_flow(&track, m, flow)?))
        })
        .collect::<Result<Vec<_>>>()?;
    lap(&mut seconds.registration_flow);

    let interpolate = TrackFlows::new(track_flows.clone())?;
    let reference_time = capture.slots()[reference.track_slot].time_offset_s;
    let matte = |frame: &RgbImage, clean: &RgbImage| -> Result<RgbImage> {
        let f = premultiply(frame, &alpha, clean)?;
        match settings.edge {
            EdgeMethod::Extend => extend_interior(&f, &alpha),
            EdgeMethod::None | EdgeMethod::Solve => Ok(f),
        }
    };
    let conditions = capture.conditions().len();
    let mut basis = vec![None; conditions];
    let mut unregistered = keep_unregistered.then(|| vec![None; conditions]);
    // Matted with the blurred binary matte, before edge decontamination.
    let mut raw_basis = vec![None; conditions];
    for (slot, s) in capture.slots().iter().enumerate() {
        let SlotKind::Basis(c) = s.kind else { continue };
        let f = interpolate.at(s.time_offset_s - reference_time);
        let warped = warp_to_reference(&frames[slot], &f)?;
        let raw = premultiply(&warped, &raw_alpha, &clean[slot])?;
        basis[c] = Some(match settings.edge {
            EdgeMethod::None => raw.clone(),
            EdgeMethod::Extend | EdgeMethod::Solve => matte(&warped, &clean[slot])?,
        });
        raw_basis[c] = Some(raw);
        if let Some(u) = unregistered.as_mut() {
            u[c] = Some(matte(&frames[slot], &clean[slot])?);
        }
    }
    let all = |v: Vec<Option<RgbImage>>| -> Vec<RgbImage> {
        v.into_iter()
            .map(|b| b.expect("every condition has a slot"))
            .collect()
    };
    let (basis, raw_basis) = (all(basis), all(raw_basis));
    // The image inter-view flow is measured on sums the frames matted with the blurred
    // binary matte whatever the edge method, so that flow does not depend on it either
    // (on the edges of `solve` it measured 0.599 px instead of 0.590 px, small preset).
    let mut summed = raw_basis[0].clone();
    for b in &raw_basis[1..] {
        for (s, p) in summed.pixels_mut().iter_mut().zip(b.pixels()) {
            for k in 0..3 {
                s[k] += p[k];
            }
        }
    }
    lap(&mut seconds.registration_warp);
    Ok(RegisteredView {
        alpha,
        track,
        summed,
        basis,
        kept: unregistered.map(|u| KeptFrames {
            unregistered: all(u),
            raw_basis,
            raw_alpha,
        }),
        track_flows,
        seconds,
    })
}
