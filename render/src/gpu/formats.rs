//! How a resident pose's pre-lit views and flows are stored on the GPU, and how the frame
//! pass filters them: each choice is a texture format and a WGSL snippet of
//! `shaders/sample/` defining `sample_prelit` or `sample_flow_layer`, composed into the
//! frame pass ([`PoseFormats::rebin_source`]). `frf bench interp` measures every
//! combination; [`PoseFormats::DEFAULT`] is the renderer's.
//!
//! | choice | texture | filtered by | bytes a texel | against the CPU reference |
//! |---|---|---|---|---|
//! | image `codes` | packed RGBA8 in the shared pages ([`super::prelit`]) | the shader, texel by texel through the sRGB table | 4 | exact |
//! | image `srgb8` | `Rgba8UnormSrgb` (the same bytes) | the sampler (sRGB decoded before filtering) | 4 | the hardware's filter precision |
//! | flow `codes8` | the stored log codes, two bytes a texel in the shared pages | the shader, texel by texel through the code table | 2 | exact |
//! | flow `f16` | `Rg16Float`, decoded at upload | the sampler | 4 | half precision |
//! | flow `f32` | `Rg32Float`, decoded at upload | the shader (unfilterable) | 8 | exact |

use super::shaders;

/// Where the frame pass's pose group binds sRGB8 pre-lit texels
/// (`shaders/sample/prelit_srgb.wgsl`).
pub const PRELIT_TEXELS_BINDING: u32 = 10;

/// How the pre-lit views are stored and filtered.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum ImageFormat {
    /// Integer codes, decoded and filtered in the shader.
    Codes,
    /// sRGB8 texels filtered by the sampler.
    Srgb8,
}

/// How the flows are stored and filtered.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum FlowFormat {
    /// The stored 8-bit log codes, decoded in the shader.
    Codes8,
    /// Half floats filtered by the sampler.
    F16,
    /// Floats filtered in the shader.
    F32,
}

impl ImageFormat {
    /// Every choice.
    pub const ALL: [ImageFormat; 2] = [ImageFormat::Codes, ImageFormat::Srgb8];

    /// Its name in reports.
    pub fn name(self) -> &'static str {
        match self {
            ImageFormat::Codes => "codes",
            ImageFormat::Srgb8 => "srgb8",
        }
    }

    /// The texture format of sRGB8 pre-lit views (the codes' bytes are those of a
    /// `Rgba8Uint` texel, though they lie in the shared pages).
    pub fn texture(self) -> wgpu::TextureFormat {
        match self {
            ImageFormat::Codes => wgpu::TextureFormat::Rgba8Uint,
            ImageFormat::Srgb8 => wgpu::TextureFormat::Rgba8UnormSrgb,
        }
    }

    /// Whether the texels lie in a texture of the pose's own (bound at
    /// [`PRELIT_TEXELS_BINDING`]) rather than in the shared pages.
    pub fn in_texture(self) -> bool {
        self == ImageFormat::Srgb8
    }

    fn snippet(self) -> &'static str {
        match self {
            ImageFormat::Codes => shaders::PRELIT_CODES,
            ImageFormat::Srgb8 => shaders::PRELIT_SRGB,
        }
    }
}

impl FlowFormat {
    /// Every choice.
    pub const ALL: [FlowFormat; 3] = [FlowFormat::Codes8, FlowFormat::F16, FlowFormat::F32];

    /// Its name in reports.
    pub fn name(self) -> &'static str {
        match self {
            FlowFormat::Codes8 => "codes8",
            FlowFormat::F16 => "f16",
            FlowFormat::F32 => "f32",
        }
    }

    /// The texture format of the flows.
    pub fn texture(self) -> wgpu::TextureFormat {
        match self {
            FlowFormat::Codes8 => wgpu::TextureFormat::Rg8Sint,
            FlowFormat::F16 => wgpu::TextureFormat::Rg16Float,
            FlowFormat::F32 => wgpu::TextureFormat::Rg32Float,
        }
    }

    /// How the frame pass binds it, at `binding`: the codes in the shared pages
    /// ([`super::prelit`]) as a storage buffer, decoded flows as a texture array.
    pub fn layout_entry(self, binding: u32) -> wgpu::BindGroupLayoutEntry {
        let float = |filterable| wgpu::TextureSampleType::Float { filterable };
        match self {
            FlowFormat::Codes8 => super::bind::storage::<u32>(
                binding,
                true,
                wgpu::ShaderStages::FRAGMENT | wgpu::ShaderStages::COMPUTE,
            ),
            FlowFormat::F16 => super::bind::texture_array(binding, float(true)),
            FlowFormat::F32 => super::bind::texture_array(binding, float(false)),
        }
    }

    /// Whether the flows lie in a texture of the pose's own rather than in the shared
    /// pages.
    pub fn in_texture(self) -> bool {
        self != FlowFormat::Codes8
    }

    /// Bytes a flow texel takes.
    pub fn texel_bytes(self) -> u64 {
        match self {
            FlowFormat::Codes8 => 2,
            FlowFormat::F16 => 4,
            FlowFormat::F32 => 8,
        }
    }

    /// The texels of decoded flows `(u, v)` (unknown as zero) in this format's bytes;
    /// `None` for the codes, which upload as stored.
    pub fn encode(self, flows: &[[f32; 2]]) -> Option<Vec<u8>> {
        match self {
            FlowFormat::Codes8 => None,
            FlowFormat::F16 => Some(
                flows
                    .iter()
                    .flat_map(|f| f.map(|x| half::f16::from_f32(x).to_bits()))
                    .flat_map(u16::to_le_bytes)
                    .collect(),
            ),
            FlowFormat::F32 => Some(bytemuck::cast_slice(flows).to_vec()),
        }
    }

    fn snippet(self) -> &'static str {
        match self {
            FlowFormat::Codes8 => shaders::FLOW_CODES,
            FlowFormat::F16 => shaders::FLOW_F16,
            FlowFormat::F32 => shaders::FLOW_F32,
        }
    }
}

/// The storage of a resident pose.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct PoseFormats {
    /// Pre-lit views.
    pub image: ImageFormat,
    /// Flows.
    pub flow: FlowFormat,
}

impl PoseFormats {
    /// The renderer's: exact twins of the CPU reference, 6 bytes a texel per view.
    pub const DEFAULT: PoseFormats = PoseFormats {
        image: ImageFormat::Codes,
        flow: FlowFormat::Codes8,
    };

    /// `image/flow`, e.g. `codes/codes8`.
    pub fn name(self) -> String {
        format!("{}/{}", self.image.name(), self.flow.name())
    }

    /// The frame pass's source with these formats' sampling, for the morph `(kind, flags)`
    /// ([`crate::morph::Variant::index`], [`crate::morph::Variant::flags`]).
    pub fn rebin_source(self, morph: (u32, u32)) -> String {
        shaders::frame_pass(self.image.snippet(), self.flow.snippet(), morph)
    }
}
