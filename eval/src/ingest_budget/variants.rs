//! One view of the ingest budget: its set ingested by ingest's own steps
//! ([`frf_ingest::views`]), and again with one input taken from the stage's truth (the
//! true alpha, the true motion of each basis frame, the frames as the lens forms them,
//! before the sensor's noise, quantization and clipping; the three together), beside
//! the oracle view ([`crate::oracle::oracle_view`]: the true basis images, alpha and
//! flows). Every variant's images are encoded at once, so that a view holds only
//! compressed images once done.

use frf_core::capture::{Capture, SlotKind};
use frf_core::filter::extend_nearest;
use frf_core::image::{FlowImage, GrayImage, RgbImage};
use frf_flow::FlowParams;
use frf_ingest::edges::EdgeMethod;
use frf_ingest::pipeline::IngestOptions;
use frf_ingest::views::{
    SetFrames, SetMotion, SetRegistration, load_set, register_basis, register_set,
};
use frf_reflectance::FieldHeader;
use frf_reflectance::store::{EncodedView, encode_images};
use frf_stage::Stage;
use frf_stage::truth::flow_between;

use crate::error::Result;
use crate::oracle::oracle_view;

/// Which images a budget field holds.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Images {
    /// As ingested.
    Ingested,
    /// As ingested, encoded at the codec's best quality.
    IngestedLossless,
    /// Registered and matted with the true alpha (and the true alpha stored).
    TrueMattes,
    /// Registered by the true motion of each frame.
    TrueMotion,
    /// Registered from frames as the lens forms them (no sensor).
    NoSensor,
    /// Registered by the true motion from frames as the lens forms them, matted with the
    /// true alpha (and the true alpha stored).
    TrueSteps,
    /// The true basis images, with the estimated alpha.
    TrueBasis,
    /// The true basis images and alpha (the oracle's).
    Oracle,
}

impl Images {
    /// Every variant, in the order of [`ViewVariants::encoded`].
    pub const ALL: [Images; 8] = [
        Images::Ingested,
        Images::IngestedLossless,
        Images::TrueMattes,
        Images::TrueMotion,
        Images::NoSensor,
        Images::TrueSteps,
        Images::TrueBasis,
        Images::Oracle,
    ];

    /// Its index in [`Images::ALL`].
    pub fn index(self) -> usize {
        Self::ALL
            .iter()
            .position(|&i| i == self)
            .expect("every variant is listed")
    }

    /// Whether its alpha is the true one.
    pub fn true_alpha(self) -> bool {
        matches!(
            self,
            Images::TrueMattes | Images::TrueSteps | Images::Oracle
        )
    }
}

/// What the budget knows of the capture before its views: the capture and its stage, the
/// pose, the ingest settings, and each camera's clean plates (as filmed, and as the lens
/// forms them for the basis slots).
pub struct BudgetCapture<'a> {
    /// The capture.
    pub capture: &'a Capture,
    /// The stage that filmed it.
    pub stage: &'a Stage,
    /// The pose.
    pub pose: u32,
    /// How it is ingested.
    pub options: &'a IngestOptions,
    /// The flow parameters of its registration.
    pub params: FlowParams,
    /// Per camera and slot: the clean plate as filmed.
    pub clean: Vec<Vec<RgbImage>>,
    /// Per camera and slot: the clean plate as the lens forms it (basis slots; the others
    /// as filmed).
    pub lens_clean: Vec<Vec<RgbImage>>,
}

impl<'a> BudgetCapture<'a> {
    /// Reads the clean plates of `capture` and renders their lens-formed twins.
    pub fn new(
        capture: &'a Capture,
        stage: &'a Stage,
        pose: u32,
        options: &'a IngestOptions,
    ) -> Result<Self> {
        let slots = capture.slots().len();
        let rows = capture.cameras().len();
        let clean: Vec<Vec<RgbImage>> = (0..rows)
            .map(|v| {
                (0..slots)
                    .map(|s| Ok(capture.load_clean_plate(v, s)?))
                    .collect::<Result<_>>()
            })
            .collect::<Result<_>>()?;
        let lens_clean = (0..rows)
            .map(|v| {
                (0..slots)
                    .map(|s| match capture.slots()[s].kind {
                        SlotKind::Basis(_) => Ok(stage.render_clean_plate(v, s)?),
                        _ => Ok(clean[v][s].clone()),
                    })
                    .collect::<Result<_>>()
            })
            .collect::<Result<_>>()?;
        Ok(Self {
            capture,
            stage,
            pose,
            options,
            params: options.flow_params()?,
            clean,
            lens_clean,
        })
    }
}

/// One view's variants: the encoded images of each, and what the grid's steps need.
pub struct ViewVariants {
    /// Per [`Images`] variant, in [`Images::ALL`] order: the basis mosaic and alpha.
    pub encoded: Vec<EncodedView>,
    /// The sum of the ingested basis images (inter-view flow is measured on it).
    pub summed: RgbImage,
    /// The estimated alpha.
    pub alpha: GrayImage,
    /// The true alpha.
    pub true_alpha: GrayImage,
    /// The true flows to the grid neighbours.
    pub true_flows: [Option<FlowImage>; 4],
}

/// View `(u, v)` ingested, and with each input taken from the truth; `headers` are the
/// field headers to encode with, at the ingest's JPEG quality and at the codec's best.
pub fn view_variants(
    at: &BudgetCapture,
    (u, v): (usize, usize),
    headers: (&FieldHeader, &FieldHeader),
) -> Result<ViewVariants> {
    let (capture, stage, pose, options) = (at.capture, at.stage, at.pose, at.options);
    let frames = load_set(capture, pose, u, v)?;
    let set = SetFrames {
        capture,
        frames: &frames,
        clean: &at.clean[v],
    };
    let SetRegistration { mattes, motion, .. } =
        register_set(&set, options.matte_rule, options.edge, &at.params)?;
    let estimated = |slot: usize| Ok(motion.at(set.offset_s(slot)));
    let (surface, true_alpha) = stage.reference_surface(pose, u, v)?;
    // The true motion of every basis frame: where each point of the reference frame is
    // at the frame's instant.
    let true_motion: Vec<Option<FlowImage>> = (0..frames.len())
        .map(|s| match capture.slots()[s].kind {
            SlotKind::Basis(_) => {
                let offset = frf_stage::rig::slot_time_offset_s(s);
                let to = stage.view_setup(pose, u, v, offset)?;
                Ok(Some(filled(flow_between(&surface, &to).flow)))
            }
            _ => Ok(None),
        })
        .collect::<Result<_>>()?;
    let true_motion = |slot: usize| Ok(true_motion[slot].clone().expect("a basis slot's motion"));
    let lens_frames: Vec<RgbImage> = (0..frames.len())
        .map(|s| match capture.slots()[s].kind {
            SlotKind::Basis(_) => Ok(stage.render_frame(pose, u, v, s)?.color),
            _ => Ok(frames[s].clone()),
        })
        .collect::<Result<_>>()?;
    let lens_set = SetFrames {
        capture,
        frames: &lens_frames,
        clean: &at.lens_clean[v],
    };
    let estimated_alpha = (&mattes.alpha, &mattes.raw_alpha, options.edge);
    let true_alpha_as_is = (&true_alpha, &true_alpha, EdgeMethod::None);
    let register = |set: &SetFrames,
                    (alpha, raw, edge): (&GrayImage, &GrayImage, EdgeMethod),
                    motion: &SetMotion| {
        Ok::<_, crate::EvalError>(register_basis(set, alpha, raw, edge, motion, false)?.basis)
    };
    let ingested = register_basis(
        &set,
        &mattes.alpha,
        &mattes.raw_alpha,
        options.edge,
        &estimated,
        false,
    )?;
    let oracle = oracle_view(stage, pose, u, v)?;
    let (header, lossless) = headers;
    let encoded = Images::ALL
        .iter()
        .map(|&k| {
            let basis = match k {
                Images::Ingested | Images::IngestedLossless => ingested.basis.clone(),
                Images::TrueMattes => register(&set, true_alpha_as_is, &estimated)?,
                Images::TrueMotion => register(&set, estimated_alpha, &true_motion)?,
                Images::NoSensor => register(&lens_set, estimated_alpha, &estimated)?,
                Images::TrueSteps => register(&lens_set, true_alpha_as_is, &true_motion)?,
                Images::TrueBasis | Images::Oracle => oracle.basis.clone(),
            };
            let alpha = match k {
                Images::Oracle => &oracle.alpha,
                k if k.true_alpha() => &true_alpha,
                _ => &mattes.alpha,
            };
            let h = if k == Images::IngestedLossless {
                lossless
            } else {
                header
            };
            Ok(encode_images(h, &basis, alpha)?)
        })
        .collect::<Result<Vec<_>>>()?;
    Ok(ViewVariants {
        encoded,
        summed: ingested.summed,
        alpha: mattes.alpha,
        true_alpha,
        true_flows: oracle.flows,
    })
}

/// A true motion field with its unknown pixels (where the reference pixel sees no part
/// of the walker) given the nearest known motion, so that a silhouette pixel whose
/// centre misses the walker moves with the limb it partly covers; with nothing known,
/// no motion.
fn filled(mut flow: FlowImage) -> FlowImage {
    let (w, h) = flow.size();
    let pixels = flow.pixels_mut();
    extend_nearest(pixels, w, h, |f| frf_core::flo::is_known(*f));
    for p in pixels.iter_mut() {
        if !frf_core::flo::is_known(*p) {
            *p = [0.0; 2];
        }
    }
    flow
}
