//! Every resident pose's pre-lit views in a few shared pages ([`super::arena`]), so that
//! the frame pass draws the renders of every relit copy of one pose's views (walkers under
//! their own lights and headings) in one dispatch (docs/design.md section 4.9): a pose's
//! range holds its views' scales (f32 bits, one a view, rounded up to 16 bytes), then per
//! pre-lit layer its texels, each packed RGBA8 (the sRGB codes of colour / the view's
//! scale, and the alpha code: the bytes a `Rgba8Uint` texel held). The relighting pass
//! writes both (`shaders/relight.wgsl`); the frame pass finds them at the words its
//! record names (`prelit` of `Frame`, `shaders/common.wgsl`).

use super::Gpu;
use super::arena::ArenaRange;
use crate::error::Result;

/// Bytes of a page of pre-lit views (a pose larger than a page opens its own; the
/// device's largest storage binding caps it: 128 MiB on lavapipe, 4 GiB on NVIDIA).
pub(super) const PRELIT_PAGE_BYTES: u64 = 1 << 30;

/// Words of a range's head: a scale a view, rounded up to 16 bytes.
pub(super) fn head_words(views: usize) -> u32 {
    (views.max(1) as u32).next_multiple_of(4)
}

/// Texels of every layer, packed RGBA8.
pub(super) type Layers = Vec<Vec<[u8; 4]>>;

/// A pose's pre-lit views: its range of the shared pages (see the module docs).
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

    /// What names its page (the frame pass binds a page once for every pose in it).
    pub(super) fn page_key(&self) -> usize {
        self.range.key().0
    }

    /// The range as a binding (the relighting pass writes it alone).
    pub(super) fn binding(&self) -> wgpu::BindingResource<'_> {
        self.range.binding()
    }

    /// Where its scales and its first layer's codes start, in words from the page's
    /// start (`prelit` of the frame pass's record).
    pub(super) fn words(&self) -> [u32; 4] {
        let at = (self.range.offset() / 4) as u32;
        [at, at + head_words(self.views), 0, 0]
    }

    /// Bytes of its codes, every layer.
    fn code_bytes(&self) -> u64 {
        (self.layers.max(1) * self.texels * 4) as u64
    }

    /// Bytes of its head.
    fn head_bytes(&self) -> u64 {
        u64::from(head_words(self.views)) * 4
    }
}

impl Gpu {
    /// A range for `views` views' scales and `layers` layers of `texels` texels: every
    /// scale 1 (a view the relighting pass does not write keeps it) and every texel
    /// zero (transparent) once the pending work is sent, whoever held the range before.
    pub(super) fn take_prelit(&self, views: usize, layers: usize, texels: usize) -> PrelitRange {
        let bytes = u64::from(head_words(views)) * 4 + (layers.max(1) * texels * 4) as u64;
        let range = PrelitRange {
            range: self.prelit.take(&self.device, bytes),
            views,
            layers,
            texels,
        };
        let ones = vec![1.0f32; head_words(views) as usize];
        self.upload(
            range.page(),
            range.range.offset(),
            bytemuck::cast_slice(&ones),
        );
        let codes_at = range.range.offset() + range.head_bytes();
        let size = range.code_bytes();
        self.with_pending(|encoder| encoder.clear_buffer(range.page(), codes_at, Some(size)));
        range
    }

    /// A range holding `scales` (one a view) and `codes` (every layer's texels, packed
    /// RGBA8 bytes, layer after layer), written in full.
    pub(super) fn prelit_with(&self, scales: &[f32], layers: usize, codes: &[u8]) -> PrelitRange {
        let texels = codes.len() / 4 / layers.max(1);
        let bytes = u64::from(head_words(scales.len())) * 4 + codes.len() as u64;
        let range = PrelitRange {
            range: self.prelit.take(&self.device, bytes),
            views: scales.len(),
            layers,
            texels,
        };
        let mut head = scales.to_vec();
        head.resize(head_words(scales.len()) as usize, 1.0);
        let mut all: Vec<u8> = bytemuck::cast_slice(&head).to_vec();
        all.extend_from_slice(codes);
        all.resize(range.range.size() as usize, 0);
        self.queue
            .write_buffer(range.page(), range.range.offset(), &all);
        range
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
        let scales: &[f32] = bytemuck::cast_slice(head);
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
        Ok((scales[..range.views].to_vec(), layers))
    }
}
