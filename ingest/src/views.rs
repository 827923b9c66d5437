//! One view of one pose, from captured frames to registered basis images, in three steps
//! that [`process_view`] runs in order and that the error budget of ingest (`frf-eval`)
//! runs with one input at a time taken from a ground truth:
//!
//! 1. [`matte_set`]: matte every track frame against the matte frame after it
//!    ([`crate::matte`]); the reference track frame's matte, after the edge method
//!    ([`crate::edges`]), is the alpha of the whole set;
//! 2. [`measure_track_flows`]: flow from the matted reference track frame to the other
//!    track frames, the motion of the set ([`crate::registration`]);
//! 3. [`register_basis`]: warp every basis frame onto the reference by that motion and
//!    matte it onto black with the set's alpha and the clean plate of its own condition,
//!    keeping backdrop light out of the edge pixels as [`EdgeMethod`] says.
//!
//! The sum of the registered basis images (the subject under the whole dome: evenly lit,
//! and with a fifth of a single frame's relative noise) is the image inter-view flow is
//! measured on.

use std::time::Instant;

use frf_core::capture::{Capture, SlotKind, TrackPair};
use frf_core::image::{FlowImage, GrayImage, RgbImage};
use frf_flow::FlowParams;

use crate::edges::{EdgeMethod, extend_interior, soft_alpha};
use crate::error::{IngestError, Result};
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
    /// The subject's motion across the set: the flow from the reference to any instant
    /// of it, through the track frames.
    pub motion: TrackFlows,
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

/// One lighting set of one view as captured: its frames by slot, and the clean plates
/// of its camera by slot.
#[derive(Debug, Clone, Copy)]
pub struct SetFrames<'a> {
    /// The capture (its slots, tracks and conditions).
    pub capture: &'a Capture,
    /// The set's frames, by slot.
    pub frames: &'a [RgbImage],
    /// The camera's clean plates, by slot.
    pub clean: &'a [RgbImage],
}

impl SetFrames<'_> {
    fn check(&self) -> Result<()> {
        let slots = self.capture.slots().len();
        if self.frames.len() != slots || self.clean.len() != slots {
            return Err(IngestError::Mismatch {
                what: "the frames and clean plates of a lighting set".into(),
                expected: format!("{slots} of each (one per slot)"),
                got: format!("{} and {}", self.frames.len(), self.clean.len()),
            });
        }
        Ok(())
    }

    /// Seconds from the reference track frame to slot `slot`.
    pub fn offset_s(&self, slot: usize) -> f64 {
        let slots = self.capture.slots();
        slots[slot].time_offset_s - slots[self.capture.reference_track().track_slot].time_offset_s
    }
}

/// The mattes of a lighting set ([`matte_set`]).
#[derive(Debug, Clone)]
pub struct SetMattes {
    /// The set's alpha: the reference track frame's matte after the edge method.
    pub alpha: GrayImage,
    /// The reference track frame's blurred binary matte.
    pub raw_alpha: GrayImage,
    /// Every track frame matted with its own blurred binary matte, and its pair.
    pub tracks: Vec<(TrackPair, RgbImage)>,
    /// Index in `tracks` of the reference track frame.
    pub reference: usize,
    /// The slot of the matte frame the set's alpha was measured in.
    pub matte_slot: usize,
}

impl SetMattes {
    /// The matted reference track frame.
    pub fn reference_track(&self) -> &RgbImage {
        &self.tracks[self.reference].1
    }
}

/// Step 1: the mattes of a set. Every track frame is matted with its own blurred binary
/// matte (so that registration flow does not depend on the edge method); the set's alpha
/// is the reference's, after `edge`.
pub fn matte_set(set: &SetFrames, rule: MatteRule, edge: EdgeMethod) -> Result<SetMattes> {
    set.check()?;
    let (frames, clean) = (set.frames, set.clean);
    let reference = set.capture.reference_track();
    let mut tracks = Vec::new();
    let mut found = None;
    for t in set.capture.tracks() {
        let input = MatteInput {
            track: &frames[t.track_slot],
            matte: &frames[t.matte_slot],
            matte_clean: &clean[t.matte_slot],
        };
        let a = matte_alpha(&input, rule)?;
        let matted = premultiply(&frames[t.track_slot], &a, &clean[t.track_slot])?;
        if t.index == reference.index {
            found = Some((tracks.len(), a, t.matte_slot));
        }
        tracks.push((*t, matted));
    }
    let (reference, raw_alpha, matte_slot) =
        found.expect("a capture's reference track is among its tracks");
    let alpha = match edge {
        EdgeMethod::Solve => soft_alpha(&raw_alpha, &frames[matte_slot], &clean[matte_slot])?,
        EdgeMethod::None | EdgeMethod::Extend => raw_alpha.clone(),
    };
    Ok(SetMattes {
        alpha,
        raw_alpha,
        tracks,
        reference,
        matte_slot,
    })
}

/// Step 2: the flow from the matted reference track frame to each other track frame,
/// `(time offset from the reference, flow)`.
pub fn measure_track_flows(
    set: &SetFrames,
    mattes: &SetMattes,
    params: &FlowParams,
) -> Result<Vec<(f64, FlowImage)>> {
    let reference = mattes.reference_track();
    mattes
        .tracks
        .iter()
        .enumerate()
        .filter(|(k, _)| *k != mattes.reference)
        .map(|(_, (t, m))| {
            Ok((
                set.offset_s(t.track_slot),
                frf_flow::estimate_flow(reference, m, params)?,
            ))
        })
        .collect()
}

/// Steps 1 and 2 of a set: its mattes, and the motion of the subject across it.
#[derive(Debug, Clone)]
pub struct SetRegistration {
    /// The mattes, the set's alpha moved to the reference instant.
    pub mattes: SetMattes,
    /// Flow from the reference to each other track frame: `(time offset, flow)`.
    pub track_flows: Vec<(f64, FlowImage)>,
    /// The motion at any instant of the set, interpolated through the track flows.
    pub motion: TrackFlows,
    /// Thread-seconds of the mattes, and of the motion and the alpha's move.
    pub seconds: (f64, f64),
}

/// Mattes the set, measures its motion, and moves the set's alpha from the instant of
/// the matte frame it was measured in (one frame after the reference track frame) to
/// the reference instant, by the motion at the matte frame's instant. The matte rule and
/// the edge method read the matte frame alone, so the silhouette they find is the matte
/// frame's; a limb swinging at 3 m/s has moved 0.3 px in that frame's millisecond.
pub fn register_set(
    set: &SetFrames,
    rule: MatteRule,
    edge: EdgeMethod,
    params: &FlowParams,
) -> Result<SetRegistration> {
    let start = Instant::now();
    let mut mattes = matte_set(set, rule, edge)?;
    let matte_seconds = start.elapsed().as_secs_f64();
    let track_flows = measure_track_flows(set, &mattes, params)?;
    let motion = TrackFlows::new(track_flows.clone())?;
    let at_matte = motion.at(set.offset_s(mattes.matte_slot));
    mattes.alpha = warp_to_reference(&mattes.alpha, &at_matte)?;
    mattes.raw_alpha = warp_to_reference(&mattes.raw_alpha, &at_matte)?;
    Ok(SetRegistration {
        mattes,
        track_flows,
        motion,
        seconds: (matte_seconds, start.elapsed().as_secs_f64() - matte_seconds),
    })
}

/// The registered basis images of a set ([`register_basis`]).
#[derive(Debug, Clone)]
pub struct SetBasis {
    /// Registered and matted onto black with the set's alpha, in condition order.
    pub basis: Vec<RgbImage>,
    /// Registered and matted with the blurred binary matte (before the edge method).
    pub raw_basis: Vec<RgbImage>,
    /// Matted without registration, when asked for.
    pub unregistered: Option<Vec<RgbImage>>,
    /// The sum of `raw_basis`: the image inter-view flow is measured on.
    pub summed: RgbImage,
}

/// How the subject moved during a set: the flow from the reference track frame to the
/// frame in slot `slot` (its reverse lookup `I'(s) = I(s + F(s))` registers the frame).
pub type SetMotion<'a> = dyn Fn(usize) -> Result<FlowImage> + 'a;

/// Step 3: every basis frame warped onto the reference by `motion` and matted onto black
/// with `alpha` (and with the blurred binary matte `raw_alpha`, for the flow image and
/// for comparison) and the clean plate of its own slot.
pub fn register_basis(
    set: &SetFrames,
    alpha: &GrayImage,
    raw_alpha: &GrayImage,
    edge: EdgeMethod,
    motion: &SetMotion,
    keep_unregistered: bool,
) -> Result<SetBasis> {
    set.check()?;
    let (frames, clean) = (set.frames, set.clean);
    let matte = |frame: &RgbImage, clean: &RgbImage| -> Result<RgbImage> {
        let f = premultiply(frame, alpha, clean)?;
        match edge {
            EdgeMethod::Extend => extend_interior(&f, alpha),
            EdgeMethod::None | EdgeMethod::Solve => Ok(f),
        }
    };
    let conditions = set.capture.conditions().len();
    let mut basis = vec![None; conditions];
    let mut unregistered = keep_unregistered.then(|| vec![None; conditions]);
    let mut raw_basis = vec![None; conditions];
    for (slot, s) in set.capture.slots().iter().enumerate() {
        let SlotKind::Basis(c) = s.kind else { continue };
        let warped = warp_to_reference(&frames[slot], &motion(slot)?)?;
        let raw = premultiply(&warped, raw_alpha, &clean[slot])?;
        basis[c] = Some(match edge {
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
            .map(|b| b.expect("a capture has a slot for every condition"))
            .collect()
    };
    let (basis, raw_basis) = (all(basis), all(raw_basis));
    // Summed from the frames matted with the blurred binary matte whatever the edge
    // method, so that flow does not depend on it either (on the edges of `solve` it
    // measured 0.599 px instead of 0.590 px, small preset).
    let mut summed = raw_basis[0].clone();
    for b in &raw_basis[1..] {
        for (s, p) in summed.pixels_mut().iter_mut().zip(b.pixels()) {
            for k in 0..3 {
                s[k] += p[k];
            }
        }
    }
    Ok(SetBasis {
        basis,
        raw_basis,
        unregistered: unregistered.map(all),
        summed,
    })
}

/// The frames of view `(u, v)` of `pose`, by slot.
pub fn load_set(capture: &Capture, pose: u32, u: usize, v: usize) -> Result<Vec<RgbImage>> {
    Ok((0..capture.slots().len())
        .map(|slot| capture.load_frame(pose, u, v, slot))
        .collect::<frf_core::Result<Vec<_>>>()?)
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
    let mut seconds = ViewSeconds::default();
    let mut clock = Instant::now();
    let mut lap = |into: &mut f64| {
        *into += clock.elapsed().as_secs_f64();
        clock = Instant::now();
    };
    let frames = load_set(capture, pose, u, v)?;
    lap(&mut seconds.load);
    let set = SetFrames {
        capture,
        frames: &frames,
        clean,
    };
    let SetRegistration {
        mattes,
        motion,
        seconds: (matte_seconds, flow_seconds),
        ..
    } = register_set(&set, settings.matte_rule, settings.edge, &settings.flow)?;
    seconds.matte += matte_seconds;
    seconds.registration_flow += flow_seconds;
    // Restart the clock: `register_set` timed its own steps.
    lap(&mut 0.0);
    let r = register_basis(
        &set,
        &mattes.alpha,
        &mattes.raw_alpha,
        settings.edge,
        &|slot| Ok(motion.at(set.offset_s(slot))),
        settings.keep_unregistered,
    )?;
    lap(&mut seconds.registration_warp);
    let track = mattes.reference_track().clone();
    Ok(RegisteredView {
        track,
        summed: r.summed,
        basis: r.basis,
        kept: r.unregistered.map(|unregistered| KeptFrames {
            unregistered,
            raw_basis: r.raw_basis,
            raw_alpha: mattes.raw_alpha,
        }),
        alpha: mattes.alpha,
        motion,
        seconds,
    })
}
