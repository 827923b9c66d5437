//! Small pieces every pass uses: bind-group layout entries (buffers with their least
//! size), texture creation and readback with rows padded to
//! `COPY_BYTES_PER_ROW_ALIGNMENT`, decoding tables as storage, and full-screen render and
//! compute pipelines.

/// A storage-buffer binding of at least `min_bytes` (checked once, when a bind group is
/// made, instead of at every dispatch).
pub fn storage_min(
    binding: u32,
    read_only: bool,
    visibility: wgpu::ShaderStages,
    min_bytes: u64,
) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility,
        ty: wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Storage { read_only },
            has_dynamic_offset: false,
            min_binding_size: wgpu::BufferSize::new(min_bytes),
        },
        count: None,
    }
}

/// A storage-buffer binding of `T`s (at least one).
pub fn storage<T>(
    binding: u32,
    read_only: bool,
    visibility: wgpu::ShaderStages,
) -> wgpu::BindGroupLayoutEntry {
    storage_min(binding, read_only, visibility, size_of::<T>() as u64)
}

/// A uniform-buffer binding of a `T`.
pub fn uniform<T>(binding: u32, visibility: wgpu::ShaderStages) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility,
        ty: wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Uniform,
            has_dynamic_offset: false,
            min_binding_size: wgpu::BufferSize::new(size_of::<T>() as u64),
        },
        count: None,
    }
}

/// A filtering sampler binding.
pub fn sampler(binding: u32, visibility: wgpu::ShaderStages) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility,
        ty: wgpu::BindingType::Sampler(wgpu::SamplerBindingType::Filtering),
        count: None,
    }
}

/// A 2D texture-array binding visible to the fragment and compute stages.
pub fn texture_array(
    binding: u32,
    sample_type: wgpu::TextureSampleType,
) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::FRAGMENT.union(wgpu::ShaderStages::COMPUTE),
        ty: wgpu::BindingType::Texture {
            sample_type,
            view_dimension: wgpu::TextureViewDimension::D2Array,
            multisampled: false,
        },
        count: None,
    }
}

/// Copies `size = (width, height, layers)` of `texture` into `buffer`, rows `row` bytes
/// apart.
pub fn copy_to_buffer(
    encoder: &mut wgpu::CommandEncoder,
    texture: &wgpu::Texture,
    buffer: &wgpu::Buffer,
    row: u32,
    size: (u32, u32, u32),
) {
    encoder.copy_texture_to_buffer(
        texture.as_image_copy(),
        wgpu::TexelCopyBufferInfo {
            buffer,
            layout: wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some(row),
                rows_per_image: Some(size.1),
            },
        },
        wgpu::Extent3d {
            width: size.0,
            height: size.1,
            depth_or_array_layers: size.2,
        },
    );
}

/// Pads `[f32; 256]` as `array<vec4<f32>, 64>`.
pub fn table_bytes(tables: &[[f32; 256]]) -> Vec<u8> {
    tables
        .iter()
        .flat_map(|t| bytemuck::cast_slice::<f32, u8>(t).to_vec())
        .collect()
}

/// A 2D texture binding visible to the fragment and compute stages, read with
/// `textureLoad`.
pub fn texture_2d(
    binding: u32,
    sample_type: wgpu::TextureSampleType,
) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::FRAGMENT.union(wgpu::ShaderStages::COMPUTE),
        ty: wgpu::BindingType::Texture {
            sample_type,
            view_dimension: wgpu::TextureViewDimension::D2,
            multisampled: false,
        },
        count: None,
    }
}

/// A bind group of `layout` whose bindings are `resources` in order (binding `i` the
/// `i`-th).
pub fn bind_group(
    device: &wgpu::Device,
    label: &str,
    layout: &wgpu::BindGroupLayout,
    resources: Vec<wgpu::BindingResource<'_>>,
) -> wgpu::BindGroup {
    let entries: Vec<wgpu::BindGroupEntry> = resources
        .into_iter()
        .enumerate()
        .map(|(i, resource)| wgpu::BindGroupEntry {
            binding: i as u32,
            resource,
        })
        .collect();
    device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some(label),
        layout,
        entries: &entries,
    })
}

/// A write-only storage texture binding of a compute pass.
pub fn storage_texture(binding: u32, format: wgpu::TextureFormat) -> wgpu::BindGroupLayoutEntry {
    storage_texture_of(binding, format, wgpu::TextureViewDimension::D2)
}

/// A write-only storage texture array binding of a compute pass.
pub fn storage_texture_array(
    binding: u32,
    format: wgpu::TextureFormat,
) -> wgpu::BindGroupLayoutEntry {
    storage_texture_of(binding, format, wgpu::TextureViewDimension::D2Array)
}

fn storage_texture_of(
    binding: u32,
    format: wgpu::TextureFormat,
    view_dimension: wgpu::TextureViewDimension,
) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::COMPUTE,
        ty: wgpu::BindingType::StorageTexture {
            access: wgpu::StorageTextureAccess::WriteOnly,
            format,
            view_dimension,
        },
        count: None,
    }
}

/// Unfilterable 32-bit float texels (read with `textureLoad`, filtered in the shader).
pub const FLOAT: wgpu::TextureSampleType = wgpu::TextureSampleType::Float { filterable: false };

/// A `width x height` RGBA32F texture with `usage`.
pub fn rgba32f(
    device: &wgpu::Device,
    label: &str,
    (width, height): (u32, u32),
    usage: wgpu::TextureUsages,
) -> wgpu::Texture {
    device.create_texture(&wgpu::TextureDescriptor {
        label: Some(label),
        size: wgpu::Extent3d {
            width,
            height,
            depth_or_array_layers: 1,
        },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format: wgpu::TextureFormat::Rgba32Float,
        usage,
        view_formats: &[],
    })
}

/// Bytes per row of a readback of rows `bytes` long.
pub fn padded_row(bytes: u32) -> u32 {
    bytes.div_ceil(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT) * wgpu::COPY_BYTES_PER_ROW_ALIGNMENT
}

/// A uniform buffer of `size` bytes, written with `Queue::write_buffer`.
pub fn uniform_buffer(device: &wgpu::Device, label: &str, size: usize) -> wgpu::Buffer {
    device.create_buffer(&wgpu::BufferDescriptor {
        label: Some(label),
        size: size as u64,
        usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    })
}

/// The stride of uniforms of `size` bytes packed into one buffer and bound at offsets:
/// `size` rounded up to the device's uniform offset alignment.
pub fn uniform_stride(device: &wgpu::Device, size: usize) -> usize {
    let align = device.limits().min_uniform_buffer_offset_alignment as usize;
    size.div_ceil(align) * align
}

/// A buffer of `usage` holding `contents`.
pub fn buffer_with(
    device: &wgpu::Device,
    label: &str,
    contents: &[u8],
    usage: wgpu::BufferUsages,
) -> wgpu::Buffer {
    use wgpu::util::DeviceExt;
    device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some(label),
        contents,
        usage,
    })
}

/// A buffer of `size` bytes for `usage`, its contents left to the passes.
pub fn empty_buffer(
    device: &wgpu::Device,
    label: &str,
    size: usize,
    usage: wgpu::BufferUsages,
) -> wgpu::Buffer {
    device.create_buffer(&wgpu::BufferDescriptor {
        label: Some(label),
        size: size as u64,
        usage,
        mapped_at_creation: false,
    })
}

/// The buffer kept in `slot` when it holds `needed` bytes, else a new one of `usage` (the
/// next power of two, at least `least` bytes) kept there instead: a buffer written anew
/// at each submission, grown to what the largest needed.
pub fn kept_buffer(
    device: &wgpu::Device,
    slot: &mut Option<wgpu::Buffer>,
    (label, usage): (&str, wgpu::BufferUsages),
    needed: u64,
    least: u64,
) -> wgpu::Buffer {
    if slot.as_ref().is_none_or(|b| b.size() < needed) {
        *slot = Some(device.create_buffer(&wgpu::BufferDescriptor {
            label: Some(label),
            size: needed.next_power_of_two().max(least),
            usage,
            mapped_at_creation: false,
        }));
    }
    slot.clone().expect("kept above")
}

/// A buffer to read `size` bytes back into.
pub fn readback_buffer(device: &wgpu::Device, label: &str, size: u64) -> wgpu::Buffer {
    device.create_buffer(&wgpu::BufferDescriptor {
        label: Some(label),
        size,
        usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    })
}

/// RGBA32F rows read back (padded to `row` bytes) as pixels.
pub fn rgba_pixels(bytes: &[u8], (w, h): (u32, u32), row: u32) -> Vec<[f32; 4]> {
    let mut pixels = Vec::with_capacity((w * h) as usize);
    for y in 0..h as usize {
        let start = y * row as usize;
        let floats: &[f32] = bytemuck::cast_slice(&bytes[start..start + w as usize * 16]);
        pixels.extend(floats.chunks_exact(4).map(|c| [c[0], c[1], c[2], c[3]]));
    }
    pixels
}

/// A render pipeline drawing one full-screen triangle (`vs_main` of `common.wgsl`) with
/// fragment entry `entry` into `targets` RGBA32F targets, no blending.
pub fn full_screen_pipeline(
    device: &wgpu::Device,
    label: &str,
    layouts: &[&wgpu::BindGroupLayout],
    module: &wgpu::ShaderModule,
    entry: &str,
    targets: usize,
) -> wgpu::RenderPipeline {
    let formats = vec![wgpu::TextureFormat::Rgba32Float; targets];
    full_screen_pipeline_into(device, label, layouts, module, entry, &formats)
}

/// [`full_screen_pipeline`] into targets of `formats`.
pub fn full_screen_pipeline_into(
    device: &wgpu::Device,
    label: &str,
    layouts: &[&wgpu::BindGroupLayout],
    module: &wgpu::ShaderModule,
    entry: &str,
    formats: &[wgpu::TextureFormat],
) -> wgpu::RenderPipeline {
    let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
        label: Some(label),
        bind_group_layouts: &layouts.iter().map(|l| Some(*l)).collect::<Vec<_>>(),
        immediate_size: 0,
    });
    let targets: Vec<_> = formats
        .iter()
        .map(|&format| {
            Some(wgpu::ColorTargetState {
                format,
                blend: None,
                write_mask: wgpu::ColorWrites::ALL,
            })
        })
        .collect();
    device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some(label),
        layout: Some(&layout),
        vertex: wgpu::VertexState {
            module,
            entry_point: Some("vs_main"),
            compilation_options: Default::default(),
            buffers: &[],
        },
        primitive: wgpu::PrimitiveState::default(),
        depth_stencil: None,
        multisample: wgpu::MultisampleState::default(),
        fragment: Some(wgpu::FragmentState {
            module,
            entry_point: Some(entry),
            compilation_options: Default::default(),
            targets: &targets,
        }),
        multiview_mask: None,
        cache: None,
    })
}

/// A compute pipeline of `module`'s `entry` with bind groups of `layouts`.
pub fn compute_pipeline(
    device: &wgpu::Device,
    label: &str,
    layouts: &[&wgpu::BindGroupLayout],
    module: &wgpu::ShaderModule,
    entry: &str,
) -> wgpu::ComputePipeline {
    let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
        label: Some(label),
        bind_group_layouts: &layouts.iter().map(|l| Some(*l)).collect::<Vec<_>>(),
        immediate_size: 0,
    });
    device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
        label: Some(label),
        layout: Some(&layout),
        module,
        entry_point: Some(entry),
        compilation_options: Default::default(),
        cache: None,
    })
}

/// A colour attachment of `view` drawn over what it holds.
pub fn loaded(view: &wgpu::TextureView) -> Option<wgpu::RenderPassColorAttachment<'_>> {
    Some(wgpu::RenderPassColorAttachment {
        view,
        depth_slice: None,
        resolve_target: None,
        ops: wgpu::Operations {
            load: wgpu::LoadOp::Load,
            store: wgpu::StoreOp::Store,
        },
    })
}
