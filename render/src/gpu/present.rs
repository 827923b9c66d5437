//! The present pass (`shaders/present.wgsl`): a frame drawn into its kept targets
//! ([`super::composite::DrawnFrame`]) shown in a window's surface texture, with nothing
//! read back: one layer (composite, walkers alone, backdrop, alpha or shadow), exposed,
//! letterboxed to keep its aspect, sRGB-encoded in the shader when the surface format is
//! not an sRGB one. Built per surface format; its bind groups are kept per set of targets.

use super::bind::{FLOAT, full_screen_pipeline_into, texture_2d, uniform, uniform_buffer};
use super::composite::DrawnFrame;
use super::kept::Kept;
use super::timing::Timestamps;
use super::{Gpu, shaders};
use frf_shaders::types::GpuPresent;

/// What a window shows of a frame.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum ShownLayer {
    /// The walkers over their shadowed backdrop.
    #[default]
    Composite,
    /// The walkers alone (premultiplied, over a checkerboard).
    Subject,
    /// The backdrop without shadow.
    Backdrop,
    /// The composite's alpha, as grey.
    Alpha,
    /// The relative irradiance of the ground (1 unshadowed).
    Shadow,
}

impl ShownLayer {
    /// Every layer, in menu order.
    pub const ALL: [ShownLayer; 5] = [
        ShownLayer::Composite,
        ShownLayer::Subject,
        ShownLayer::Backdrop,
        ShownLayer::Alpha,
        ShownLayer::Shadow,
    ];

    /// Its name (in menus and scripts).
    pub fn name(self) -> &'static str {
        match self {
            ShownLayer::Composite => "composite",
            ShownLayer::Subject => "subject",
            ShownLayer::Backdrop => "backdrop",
            ShownLayer::Alpha => "alpha",
            ShownLayer::Shadow => "shadow",
        }
    }

    /// The layer called `name`.
    pub fn parse(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|l| l.name() == name)
    }

    fn code(self) -> u32 {
        match self {
            ShownLayer::Composite => 0,
            ShownLayer::Subject => 1,
            ShownLayer::Backdrop => 2,
            ShownLayer::Alpha => 3,
            ShownLayer::Shadow => 4,
        }
    }
}

/// Bind groups kept: a viewer shows one frame size at a time, rarely two.
const KEPT_GROUPS: usize = 2;

/// The present pass for one surface format.
pub struct PresentPass {
    layout: wgpu::BindGroupLayout,
    pipeline: wgpu::RenderPipeline,
    params: wgpu::Buffer,
    encode: bool,
    /// Per set of composite targets (their id).
    groups: Kept<u64, wgpu::BindGroup>,
}

impl PresentPass {
    /// Builds the pass drawing into textures of `format`.
    pub fn new(gpu: &Gpu, format: wgpu::TextureFormat) -> Self {
        let device = &gpu.device;
        let module = shaders::module(device, "present", shaders::PRESENT);
        let f = wgpu::ShaderStages::FRAGMENT;
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("present"),
            entries: &[
                uniform::<GpuPresent>(0, f),
                texture_2d(1, FLOAT),
                texture_2d(2, FLOAT),
                texture_2d(3, FLOAT),
                texture_2d(4, FLOAT),
            ],
        });
        let pipeline = full_screen_pipeline_into(
            device,
            "present",
            &[&layout],
            &module,
            "fs_present",
            &[format],
        );
        Self {
            layout,
            pipeline,
            params: uniform_buffer(device, "present", size_of::<GpuPresent>()),
            encode: !format.is_srgb(),
            groups: Kept::new(KEPT_GROUPS),
        }
    }

    /// Records into `encoder` `frame`'s `layer`, times `2^exposure_stops`, into `target`
    /// (a surface texture of `target_size`), letterboxed; the pass's beginning and end
    /// timed into `timestamps` (two queries) when given.
    #[allow(clippy::too_many_arguments)] // one pass's every input, named at the call
    pub fn draw(
        &self,
        gpu: &Gpu,
        encoder: &mut wgpu::CommandEncoder,
        frame: &DrawnFrame,
        target: &wgpu::TextureView,
        target_size: (u32, u32),
        layer: ShownLayer,
        exposure_stops: f32,
        timestamps: Timestamps,
    ) {
        let (origin, extent) = letterbox(frame.size(), target_size);
        let params = GpuPresent {
            origin,
            extent,
            layer: layer.code(),
            encode: self.encode as u32,
            exposure: 2f32.powf(exposure_stops),
            pad: 0,
        };
        gpu.queue
            .write_buffer(&self.params, 0, bytemuck::bytes_of(&params));
        let targets = &frame.targets;
        let group = self.groups.get(targets.id, || {
            let views = [0, 1, 2, 3]
                .map(|k| targets.targets[k].create_view(&wgpu::TextureViewDescriptor::default()));
            let mut entries = vec![wgpu::BindGroupEntry {
                binding: 0,
                resource: self.params.as_entire_binding(),
            }];
            for (k, v) in views.iter().enumerate() {
                entries.push(wgpu::BindGroupEntry {
                    binding: 1 + k as u32,
                    resource: wgpu::BindingResource::TextureView(v),
                });
            }
            gpu.device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("present"),
                layout: &self.layout,
                entries: &entries,
            })
        });
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("present"),
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view: target,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations {
                    load: wgpu::LoadOp::Clear(wgpu::Color::BLACK),
                    store: wgpu::StoreOp::Store,
                },
            })],
            depth_stencil_attachment: None,
            timestamp_writes: super::timing::render_pass_writes(timestamps),
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, &*group, &[]);
        pass.draw(0..3, 0..1);
    }
}

/// Where a frame of `frame` pixels sits in a window of `window` pixels: centred, as
/// large as fits with its aspect kept (top-left corner and size).
pub fn letterbox(frame: (u32, u32), window: (u32, u32)) -> ([f32; 2], [f32; 2]) {
    let (fw, fh) = (frame.0.max(1) as f32, frame.1.max(1) as f32);
    let (ww, wh) = (window.0.max(1) as f32, window.1.max(1) as f32);
    let scale = (ww / fw).min(wh / fh);
    let extent = [fw * scale, fh * scale];
    ([(ww - extent[0]) / 2.0, (wh - extent[1]) / 2.0], extent)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_frame_keeps_its_aspect_in_any_window() {
        assert_eq!(
            letterbox((320, 240), (640, 480)),
            ([0.0, 0.0], [640.0, 480.0])
        );
        // A wide window: bars left and right.
        assert_eq!(
            letterbox((320, 240), (1000, 480)),
            ([180.0, 0.0], [640.0, 480.0])
        );
        // A tall one: bars above and below.
        assert_eq!(
            letterbox((200, 100), (200, 300)),
            ([0.0, 100.0], [200.0, 100.0])
        );
        for name in ShownLayer::ALL.map(ShownLayer::name) {
            assert_eq!(ShownLayer::parse(name).map(ShownLayer::name), Some(name));
        }
        assert_eq!(ShownLayer::parse("depth"), None);
    }
}
