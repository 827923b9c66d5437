//! Every resident pose copy's own part in a few shared pages ([`super::arena`]), so that
//! the frame pass draws the renders of every copy of one pose's views (walkers under their
//! own lights and headings, read by plans of their own) in one dispatch (docs/design.md
//! section 4.9). What a copy holds of its own:
//!
//! - its views' heads, 8 words a view ([`HEAD_WORDS`]): its pre-lit scale (f32 bits), its
//!   pre-lit layer (-1: not held), two unused, its flow layers toward right, left, up,
//!   down (-1: none stored), as its plan chose them;
//! - then per pre-lit layer its texels, each packed RGBA8 (the sRGB codes of colour / the
//!   view's scale, and the alpha code: the bytes a `Rgba8Uint` texel held);
//! - its flows' codes ([`FlowRange`], shared by the copies made from the same flows): per
//!   stored flow its texels, two bytes each (x code, y code), two texels a word.
//!
//! The relighting pass writes a copy's scales and codes (`shaders/relight.wgsl`); the frame
//! pass finds them at the words its record names (`prelit` of `Frame`,
//! `shaders/common.wgsl`).

use std::sync::{Arc, Mutex, Weak};

use super::Gpu;
use super::arena::ArenaRange;
use crate::error::Result;
use crate::geometry::PoseGeometry;
use crate::resident::PoseFlows;

/// Bytes of a page (a copy larger than a page opens its own; the device's largest
/// storage binding caps it: 128 MiB on lavapipe, 4 GiB on NVIDIA).
pub(super) const PRELIT_PAGE_BYTES: u64 = 1 << 30;

/// Words of a view's head (see the module docs).
pub(super) const HEAD_WORDS: u32 = 8;

/// Words of the heads of `views` views.
pub(super) fn head_words(views: usize) -> u32 {
    views.max(1) as u32 * HEAD_WORDS
}

/// Texels of every layer, packed RGBA8.
pub(super) type Layers = Vec<Vec<[u8; 4]>>;

/// A pose copy's heads and pre-lit views: its range of the shared pages (see the module
/// docs).
pub(super) struct PrelitRange {
    range: ArenaRange,
    views: usize,
    layers: usize,
    texels: usize,
}

impl PrelitRange {
    /// The page's buffer, every range of the page shares it.
    pub(super) fn page(&self) -> &wgpu::Buffer {
        self.range.buffer()
    }

    /// What names its page (the frame pass binds a page once for every copy in it).
    pub(super) fn page_key(&self) -> usize {
        self.range.key().0
    }

    /// Where its heads and its first layer's codes start, in words from the page's
    /// start (`prelit.xy` of the frame pass's record).
    pub(super) fn words(&self) -> [u32; 2] {
        let at = (self.range.offset() / 4) as u32;
        [at, at + head_words(self.views)]
    }

    /// Bytes of its codes, every layer.
    fn code_bytes(&self) -> u64 {
        (self.layers * self.texels * 4) as u64
    }

    /// Bytes of its heads.
    fn head_bytes(&self) -> u64 {
        u64::from(head_words(self.views)) * 4
    }
}

/// A pose's flows' codes: a range of the shared pages, shared by the copies made from
/// the same flows (see the module docs).
pub(super) struct FlowRange {
    range: ArenaRange,
    /// What they were made from (what names them while they live).
    flows: Arc<PoseFlows>,
}

impl FlowRange {
    /// The page's buffer.
    pub(super) fn page(&self) -> &wgpu::Buffer {
        self.range.buffer()
    }

    /// What names its page.
    pub(super) fn page_key(&self) -> usize {
        self.range.key().0
    }

    /// Where its codes start, in words from the page's start (`prelit.z` of the frame
    /// pass's record).
    pub(super) fn word(&self) -> u32 {
        (self.range.offset() / 4) as u32
    }
}

/// The flows' ranges resident, found again by the flows they hold while a copy holds
/// them.
#[derive(Default)]
pub(super) struct FlowsKept(Mutex<Vec<Weak<FlowRange>>>);

/// The heads of `geometry`'s views with `scales` (one a view; 1 where absent).
fn heads(geometry: &PoseGeometry, scales: &[f32]) -> Vec<u32> {
    let mut out = Vec::with_capacity(head_words(geometry.views()) as usize);
    for i in 0..geometry.views() {
        let scale = scales.get(i).copied().unwrap_or(1.0);
        let layer = geometry.prelit_layers.get(i).copied().unwrap_or(-1);
        out.extend([scale.to_bits(), layer as u32, 0, 0]);
        let flows = geometry.flow_layers.get(i).copied().unwrap_or([-1; 4]);
        out.extend(flows.map(|l| l as u32));
    }
    out.resize(head_words(geometry.views()) as usize, 0);
    out
}

impl Gpu {
    /// A range for a copy of `geometry`'s views, for the relighting pass to write: its
    /// heads (every scale 1: a view the pass does not write keeps it) and its pre-lit
    /// layers, every texel zero (transparent) once the pending work is sent, whoever held
    /// the range before.
    pub(super) fn take_prelit(&self, geometry: &PoseGeometry) -> PrelitRange {
        let layers = geometry.prelit_layer_count;
        let texels = geometry.crop.texels();
        let bytes = u64::from(head_words(geometry.views())) * 4 + (layers * texels * 4) as u64;
        let range = PrelitRange {
            range: self.prelit.take(&self.device, bytes),
            views: geometry.views(),
            layers,
            texels,
        };
        let heads = heads(geometry, &[]);
        self.upload(
            range.page(),
            range.range.offset(),
            bytemuck::cast_slice(&heads),
        );
        let codes_at = range.range.offset() + range.head_bytes();
        let size = range.code_bytes();
        if size > 0 {
            self.with_pending(|encoder| encoder.clear_buffer(range.page(), codes_at, Some(size)));
        }
        range
    }

    /// A range holding `geometry`'s heads with `scales` (one a view) and `codes` (every
    /// layer's texels, packed RGBA8 bytes, layer after layer; none when a texture holds
    /// them), written in full.
    pub(super) fn prelit_with(
        &self,
        geometry: &PoseGeometry,
        scales: &[f32],
        codes: &[u8],
    ) -> PrelitRange {
        let texels = geometry.crop.texels();
        let layers = codes.len() / 4 / texels.max(1);
        let heads = heads(geometry, scales);
        let bytes = (heads.len() * 4 + codes.len()) as u64;
        let range = PrelitRange {
            range: self.prelit.take(&self.device, bytes),
            views: geometry.views(),
            layers,
            texels,
        };
        let mut all: Vec<u8> = bytemuck::cast_slice(&heads).to_vec();
        all.extend_from_slice(codes);
        all.resize(range.range.size() as usize, 0);
        self.queue
            .write_buffer(range.page(), range.range.offset(), &all);
        range
    }

    /// The codes of `flows` (of `geometry`'s crop) in the shared pages: those a resident
    /// copy made from the same flows holds, else written now.
    pub(super) fn flow_range(
        &self,
        geometry: &PoseGeometry,
        flows: &Arc<PoseFlows>,
    ) -> Arc<FlowRange> {
        let mut kept = self.flow_ranges.0.lock().unwrap_or_else(|e| e.into_inner());
        kept.retain(|r| r.strong_count() > 0);
        let found = kept
            .iter()
            .filter_map(Weak::upgrade)
            .find(|r| Arc::ptr_eq(&r.flows, flows));
        if let Some(r) = found {
            return r;
        }
        // One layer per stored flow, in the order of the geometry's flow layers.
        let mut bytes: Vec<u8> = flows
            .codes
            .iter()
            .flat_map(|f| f.iter().flatten())
            .flat_map(|c| c.iter().flat_map(|c| [c[0] as u8, c[1] as u8]))
            .collect();
        debug_assert_eq!(
            bytes.len(),
            geometry.flow_layer_count * geometry.crop.texels() * 2
        );
        bytes.resize(bytes.len().next_multiple_of(4).max(4), 0);
        let range = self.prelit.take(&self.device, bytes.len() as u64);
        bytes.resize(range.size() as usize, 0);
        self.queue
            .write_buffer(range.buffer(), range.offset(), &bytes);
        let made = Arc::new(FlowRange {
            range,
            flows: flows.clone(),
        });
        kept.push(Arc::downgrade(&made));
        made
    }

    /// The range's scales (one a view) and codes (per layer, its texels), as the GPU
    /// holds them.
    pub(super) fn read_prelit_range(&self, range: &PrelitRange) -> Result<(Vec<f32>, Layers)> {
        let at = (
            range.range.offset(),
            range.head_bytes() + range.code_bytes(),
        );
        let bytes = self.read_back_range(range.page(), at, "pre-lit readback")?;
        let (head, codes) = bytes.split_at(range.head_bytes() as usize);
        let words: &[u32] = bytemuck::cast_slice(head);
        let scales = (0..range.views)
            .map(|i| f32::from_bits(words[i * HEAD_WORDS as usize]))
            .collect();
        let layers = codes
            .chunks_exact(range.texels.max(1) * 4)
            .take(range.layers)
            .map(|layer| {
                layer
                    .chunks_exact(4)
                    .map(|c| [c[0], c[1], c[2], c[3]])
                    .collect()
            })
            .collect();
        Ok((scales, layers))
    }
}
