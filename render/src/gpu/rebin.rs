//! The frame pass (`shaders/rebin.wgsl`): for every pixel of the virtual camera, a
//! full-screen triangle re-bins the ray through the cylinder of camera centres and morphs
//! the quad's pre-lit views there, into an RGBA32F target (premultiplied linear RGBA);
//! pixel classes (inside, clamped above or below, missed) are counted. Twin of
//! [`crate::cpu::render_cpu`].

use std::sync::Arc;

use frf_core::camera::Camera;
use frf_core::image::{Image, Rgba};

use super::Gpu;
use super::bind::{
    compute_pipeline, full_screen_pipeline, loaded, readback_buffer, sampler, storage, storage_min,
    storage_texture_array, texture_array, uniform, uniform_buffer,
};
use super::formats::{PRELIT_TEXELS_BINDING, PoseFormats};
use super::pose::{GpuPose, PoseBinding};
use super::readback::Readback;
use crate::cpu::FrameStats;
use crate::error::Result;
use crate::footprint::PixelBox;
use crate::morph::Variant;
use frf_shaders::types::{GpuColumnIndex, GpuFrame, GpuProxy, GpuQuad, GpuQuadFrame, GpuView};

/// Whether a pass runs as a full-screen triangle or as a compute dispatch.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum PassKind {
    /// Fragment shader into a colour attachment.
    Fragment,
    /// Compute shader (8 x 8 workgroups) into a storage texture.
    Compute,
}

impl PassKind {
    /// Both.
    pub const ALL: [PassKind; 2] = [PassKind::Fragment, PassKind::Compute];

    /// Its name in reports.
    pub fn name(self) -> &'static str {
        match self {
            PassKind::Fragment => "fragment",
            PassKind::Compute => "compute",
        }
    }
}

/// Workgroups of 8 x 8 covering `size`.
pub(super) fn workgroups(size: (u32, u32)) -> (u32, u32) {
    (size.0.div_ceil(8), size.1.div_ceil(8))
}

/// Numbers the 8x8 tiles of `frames`' bounds one after another, as one dispatch of the
/// compute frame pass draws them (`tiles` of their records; the first holds how many
/// renders there are); the tiles in all.
pub(super) fn number_tiles(frames: &mut [GpuFrame]) -> u32 {
    let mut first = 0;
    for f in frames.iter_mut() {
        let [x0, y0, x1, y1] = f.bounds;
        let (across, down) = workgroups((x1.saturating_sub(x0), y1.saturating_sub(y0)));
        f.tiles = [first, across, across * down, 0];
        first += across * down;
    }
    let renders = frames.len() as u32;
    if let Some(f) = frames.first_mut() {
        f.tiles[3] = renders;
    }
    first
}

/// The workgroups of a dispatch of `tiles` tiles: rows of the most a dimension holds.
pub(super) fn tile_groups(tiles: u32) -> (u32, u32) {
    const MOST: u32 = 65535;
    (tiles.min(MOST), tiles.div_ceil(MOST))
}

/// The frame pass's layouts and pipelines for one [`PoseFormats`].
pub struct RebinPass {
    /// How a pose is bound for these pipelines: the storage they read, the layout and
    /// sampler of bind group 1.
    pub pose: PoseBinding,
    pub(super) frame_layout: wgpu::BindGroupLayout,
    pub(super) compute_layout: wgpu::BindGroupLayout,
    pub(super) classes_layout: wgpu::BindGroupLayout,
    device: wgpu::Device,
    /// Per morph ([`Variant::index`] and [`Variant::flags`]), its module and pipelines,
    /// made the first time a frame is drawn with it.
    pipelines: std::sync::Mutex<Vec<(MorphKey, Arc<MorphPipelines>)>>,
}

/// A morph as the frame pass's constants hold it: `KIND` ([`Variant::index`]) and `FLAGS`
/// ([`Variant::flags`]).
type MorphKey = (u32, u32);

/// Bytes from one frame record to the next in the frames' buffer (`FrameRecord` of
/// `shaders/rebin.wgsl`: a [`GpuFrame`] and its padding): a multiple of every device's
/// uniform offset alignment, so a slot's range starts at its own.
const FRAME_STRIDE: usize = 256;
/// Records a slot's range binds: its own and those after it, read by a dispatch that
/// draws as many renders of one pose (`frames` of `shaders/rebin.wgsl`).
const FRAMES_BOUND: usize = 256;
/// What a slot binds of the frames' buffer.
pub(super) type FrameRecords = [[u8; FRAME_STRIDE]; FRAMES_BOUND];
const _: () = assert!(std::mem::size_of::<GpuFrame>() <= FRAME_STRIDE);

/// The frame pass's pipelines of one morph (its module compiled with the constants `KIND`
/// and `FLAGS`, [`frf_shaders::frame_pass`]).
pub(super) struct MorphPipelines {
    pub(super) fragment: wgpu::RenderPipeline,
    pub(super) compute: wgpu::ComputePipeline,
    pub(super) classes: wgpu::ComputePipeline,
}

impl RebinPass {
    /// Builds the pass on `device` for poses stored as `formats`.
    pub fn new(device: &wgpu::Device, formats: PoseFormats) -> Self {
        let both = wgpu::ShaderStages::FRAGMENT | wgpu::ShaderStages::COMPUTE;
        let layout = |label: &str, entries: &[wgpu::BindGroupLayoutEntry]| {
            device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
                label: Some(label),
                entries,
            })
        };
        let frame_layout = layout("frame", &[uniform::<FrameRecords>(0, both)]);
        let compute_layout = layout(
            "frame (compute)",
            &[
                uniform::<FrameRecords>(0, both),
                storage::<[u32; 4]>(1, false, wgpu::ShaderStages::COMPUTE),
                storage_texture_array(2, wgpu::TextureFormat::Rgba32Float),
                storage_texture_array(3, wgpu::TextureFormat::R32Float),
            ],
        );
        let classes_layout = layout(
            "frame (classes)",
            &[
                uniform::<FrameRecords>(0, both),
                storage::<[u32; 4]>(1, false, wgpu::ShaderStages::COMPUTE),
            ],
        );
        // Binding 0: the shared pages (the copies' heads, and their codes); 1: flows;
        // `PRELIT_TEXELS_BINDING`: pre-lit texels of a texture ([`super::formats`]).
        let mut pose_entries = vec![
            storage::<u32>(0, true, both),
            formats.flow.layout_entry(1),
            storage::<GpuView>(2, true, both),
            storage::<GpuQuad>(3, true, both),
            uniform::<[[f32; 256]; 2]>(4, both),
            storage::<GpuProxy>(5, true, both),
            storage::<u32>(6, true, both),
            // The column index's header and at least one span's range.
            storage_min(7, true, both, (size_of::<GpuColumnIndex>() + 8) as u64),
            sampler(8, both),
            storage::<GpuQuadFrame>(9, true, both),
        ];
        if formats.image.in_texture() {
            pose_entries.push(texture_array(
                PRELIT_TEXELS_BINDING,
                wgpu::TextureSampleType::Float { filterable: true },
            ));
        }
        let pose_layout = layout("pose", &pose_entries);
        let sampler = device.create_sampler(&wgpu::SamplerDescriptor {
            label: Some("bilinear"),
            mag_filter: wgpu::FilterMode::Linear,
            min_filter: wgpu::FilterMode::Linear,
            ..Default::default()
        });
        Self {
            pose: PoseBinding {
                formats,
                layout: pose_layout,
                sampler,
            },
            frame_layout,
            compute_layout,
            classes_layout,
            device: device.clone(),
            pipelines: std::sync::Mutex::new(Vec::new()),
        }
    }

    /// The pipelines of `variant` (made on first use: compiling the frame pass takes a
    /// software adapter a good fraction of a second a pipeline).
    pub(super) fn pipelines(&self, variant: Variant) -> Arc<MorphPipelines> {
        let key = (variant.index(), variant.flags());
        let mut made = self.pipelines.lock().unwrap_or_else(|e| e.into_inner());
        if let Some((_, p)) = made.iter().find(|(k, _)| *k == key) {
            return p.clone();
        }
        let device = &self.device;
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("rebin"),
            source: wgpu::ShaderSource::Wgsl(self.pose.formats.rebin_source(key).into()),
        });
        let pose_layout = &self.pose.layout;
        let compute = |label, layout, entry| {
            compute_pipeline(device, label, &[layout, pose_layout], &module, entry)
        };
        let p = Arc::new(MorphPipelines {
            fragment: full_screen_pipeline(
                device,
                "rebin",
                &[&self.frame_layout, pose_layout],
                &module,
                "fs_main",
                1,
            ),
            compute: compute("rebin", &self.compute_layout, "cs_main"),
            classes: compute("classes", &self.classes_layout, "cs_classes"),
        });
        made.push((key, p.clone()));
        p
    }
}

/// A frame's subjects, drawn and still on the GPU: each instance's render within its
/// pixel box, packed into the pages of the targets' texture ([`Place`]; instances in
/// drawing order, back to front), premultiplied RGBA32F, and the pixel-class counters
/// summed over the instances.
pub(super) struct Subjects {
    targets: Arc<SubjectTargets>,
    /// Pixels outside the walkers' bounds, summed over the walkers: not shaded, missed.
    outside: usize,
    /// Per walker (in drawing order), where its render lies.
    places: Vec<Place>,
    /// Pages the walkers' renders take (the first); room for the morphs in time follows
    /// them ([`Subjects::morph_place`]).
    render_pages: u32,
    /// Where each morph in time asked for is to lie, on the pages after the renders'.
    morphs: Vec<Place>,
    /// Per walker, where the composite reads it: its render, or its morph in time.
    shown: Vec<Place>,
}

/// What happened to a frame's pixels: the counters' bytes as the class pass left them
/// (the pixels shaded, then those clamped above, below and missed), and the pixels
/// outside the walkers' bounds (missed).
pub(super) fn frame_stats(counts: &[u8], outside: usize) -> FrameStats {
    let counts: &[u32] = bytemuck::cast_slice(counts);
    let counted = counts[1] as usize + counts[2] as usize + counts[3] as usize;
    FrameStats {
        inside: (counts[0] as usize).saturating_sub(counted),
        clamped_above: counts[1] as usize,
        clamped_below: counts[2] as usize,
        missed: counts[3] as usize + outside,
    }
}

impl Subjects {
    /// Pixels outside the walkers' bounds, summed over the walkers.
    pub(super) fn outside(&self) -> usize {
        self.outside
    }

    /// The texture array of the subjects.
    pub fn texture(&self) -> &wgpu::Texture {
        self.targets.texture()
    }

    /// Beside it, the walkers' depths (written by renders drawn with depth).
    pub fn depth_texture(&self) -> &wgpu::Texture {
        &self.targets.depth
    }

    /// The id of the targets they are drawn into ([`SubjectTargets::id`]).
    pub fn id(&self) -> u64 {
        self.targets.id
    }

    /// Where walker `k` (in drawing order) lies, and the view of its page.
    pub(super) fn place(&self, k: usize) -> (Place, &wgpu::TextureView) {
        let place = self.places[k];
        (place, self.targets.page_view(place.page))
    }

    /// Pages the walkers' renders take, before the morphs'.
    pub(super) fn render_pages(&self) -> u32 {
        self.render_pages
    }

    /// Where morph `j` (of those asked for when drawn) is to lie.
    pub(super) fn morph_place(&self, j: usize) -> Place {
        self.morphs[j]
    }

    /// Walker `k` is shown by morph `j` ([`Subjects::shown`]).
    pub(super) fn show_morph(&mut self, k: usize, j: usize) {
        self.shown[k] = self.morphs[j];
    }

    /// Where the composite reads walker `k`: its render, or its morph in time.
    pub(super) fn shown(&self, k: usize) -> Place {
        self.shown[k]
    }
}

/// The frame uniform of `camera` for `pose` (`pose` `None`: the camera alone, for passes
/// that do not read a pose).
pub(super) fn frame_uniform(pose: Option<&GpuPose>, camera: &Camera, variant: Variant) -> GpuFrame {
    let r = camera.world_from_camera.rotation;
    let k = &camera.intrinsics;
    let mut f = GpuFrame {
        axis_x: r.x_axis.extend(0.0).to_array(),
        axis_y: r.y_axis.extend(0.0).to_array(),
        axis_z: r.z_axis.extend(0.0).to_array(),
        centre: camera.centre().extend(1.0).to_array(),
        intrinsics: [k.fx, k.fy, k.cx, k.cy],
        size: [camera.width, camera.height],
        variant: variant.index(),
        quad_count: 0,
        columns: 1,
        rows: 1,
        crop_origin: [0, 0],
        crop_size: [1, 1],
        flags: variant.flags(),
        depth: 0,
        bounds: PixelBox::whole(camera.width, camera.height).to_array(),
        place: [0; 4],
        prelit: [0; 4],
        tiles: [0; 4],
    };
    number_tiles(std::slice::from_mut(&mut f));
    if let Some(pose) = pose {
        f.quad_count = pose.tables.quad_count;
        f.prelit = pose.prelit_words();
        f.columns = pose.geometry.columns as u32;
        f.rows = pose.geometry.rows as u32;
        f.crop_origin = [pose.geometry.crop.x0, pose.geometry.crop.y0];
        f.crop_size = [pose.geometry.crop.width, pose.geometry.crop.height];
    }
    f
}

/// Where a walker's render lies in its targets ([`crate::atlas`]): pixel `p` of the frame
/// at texel `p + offset` of layer `page`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) struct Place {
    pub page: u32,
    pub offset: [i32; 2],
}

impl Place {
    /// The frame's own pixels, on layer 0.
    pub const FRAME: Place = Place {
        page: 0,
        offset: [0, 0],
    };

    /// As the frame uniform's `place` holds it.
    pub fn to_array(self) -> [i32; 4] {
        [self.offset[0], self.offset[1], self.page as i32, 0]
    }

    /// Where frame pixel `(x, y)` lies in the page.
    pub fn texel(self, x: u32, y: u32) -> (u32, u32) {
        (
            (x as i64 + self.offset[0] as i64) as u32,
            (y as i64 + self.offset[1] as i64) as u32,
        )
    }
}

/// One render of a frame: its slot of the targets (its frame uniform), where it lies,
/// the camera that sees it (in its subject frame) and the pixels it may show in.
#[derive(Debug, Clone, Copy)]
pub(super) struct DrawnRender {
    pub place: Place,
    pub camera: Camera,
    pub within: PixelBox,
}

/// The places of renders within `boxes` packed into pages of `size` ([`crate::atlas`]),
/// the first on page `first_page`; and the pages they take.
pub(super) fn places(boxes: &[PixelBox], size: (u32, u32), first_page: u32) -> (Vec<Place>, u32) {
    let sizes: Vec<(u32, u32)> = boxes.iter().map(PixelBox::size).collect();
    let (placed, pages) = crate::atlas::pack(&sizes, size);
    let places = placed
        .iter()
        .zip(boxes)
        .map(|(at, b)| Place {
            page: first_page + at.page,
            offset: [at.x as i32 - b.x0 as i32, at.y as i32 - b.y0 as i32],
        })
        .collect();
    (places, pages)
}

/// A frame's targets and per-frame buffers for one size, number of renders (slots) and
/// of pages, made once and kept ([`Gpu::subject_targets`]): the pages (a texture array of
/// the frame's size into which the renders are packed, each within its pixel box,
/// [`Place`]), their views, the pixel-class counters, staging buffers to read them back
/// through, and per slot a frame uniform (written with `write_buffer`) with the bind
/// groups of the fragment, compute and class passes.
pub(super) struct SubjectTargets {
    /// Names these targets in the keys of bind groups made of them ([`super::kept`]).
    pub(super) id: u64,
    texture: wgpu::Texture,
    /// The renders' depths, texel for texel beside `texture` (R32Float).
    depth: wgpu::Texture,
    pages: Vec<wgpu::TextureView>,
    slots: Vec<SlotTargets>,
    /// Every slot's frame uniform, each at its multiple of `stride`: a frame writes them
    /// all in one write ([`SubjectTargets::write_frames`]).
    uniforms: wgpu::Buffer,
    stride: usize,
    stats: wgpu::Buffer,
    /// Staging buffers of the counters and of page 0.
    stats_readback: wgpu::Buffer,
    readback: Readback,
}

struct SlotTargets {
    fragment: wgpu::BindGroup,
    compute: wgpu::BindGroup,
    classes: wgpu::BindGroup,
}

impl SubjectTargets {
    pub(super) fn new(
        device: &wgpu::Device,
        pass: &RebinPass,
        size: (u32, u32),
        slots: u32,
        pages: u32,
    ) -> Self {
        let texture = device.create_texture(&wgpu::TextureDescriptor {
            label: Some("subjects"),
            size: wgpu::Extent3d {
                width: size.0,
                height: size.1,
                depth_or_array_layers: pages,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: wgpu::TextureFormat::Rgba32Float,
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT
                | wgpu::TextureUsages::STORAGE_BINDING
                | wgpu::TextureUsages::COPY_SRC
                | wgpu::TextureUsages::COPY_DST
                | wgpu::TextureUsages::TEXTURE_BINDING,
            view_formats: &[],
        });
        let array_view = |t: &wgpu::Texture| {
            t.create_view(&wgpu::TextureViewDescriptor {
                dimension: Some(wgpu::TextureViewDimension::D2Array),
                ..Default::default()
            })
        };
        // One 2D view a page (layer) of `t`.
        let page_views = |t: &wgpu::Texture| -> Vec<wgpu::TextureView> {
            (0..pages)
                .map(|page| {
                    t.create_view(&wgpu::TextureViewDescriptor {
                        dimension: Some(wgpu::TextureViewDimension::D2),
                        base_array_layer: page,
                        array_layer_count: Some(1),
                        ..Default::default()
                    })
                })
                .collect()
        };
        let all = array_view(&texture);
        let depth = device.create_texture(&wgpu::TextureDescriptor {
            label: Some("subject depths"),
            size: wgpu::Extent3d {
                width: size.0,
                height: size.1,
                depth_or_array_layers: pages,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: wgpu::TextureFormat::R32Float,
            usage: wgpu::TextureUsages::STORAGE_BINDING
                | wgpu::TextureUsages::TEXTURE_BINDING
                | wgpu::TextureUsages::COPY_SRC
                | wgpu::TextureUsages::COPY_DST,
            view_formats: &[],
        });
        let all_depth = array_view(&depth);
        let stats = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("stats"),
            size: 16,
            usage: wgpu::BufferUsages::STORAGE
                | wgpu::BufferUsages::COPY_SRC
                | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let group = |label, layout, entries: &[wgpu::BindGroupEntry]| {
            device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some(label),
                layout,
                entries,
            })
        };
        let pages = page_views(&texture);
        // A slot's range holds the records after it too ([`FRAMES_BOUND`]).
        let stride = FRAME_STRIDE;
        let uniforms = uniform_buffer(device, "frames", stride * (slots as usize + FRAMES_BOUND));
        let slots = (0..slots as usize)
            .map(|slot| {
                let frame = wgpu::BindGroupEntry {
                    binding: 0,
                    resource: wgpu::BindingResource::Buffer(wgpu::BufferBinding {
                        buffer: &uniforms,
                        offset: (slot * stride) as u64,
                        size: std::num::NonZeroU64::new(size_of::<FrameRecords>() as u64),
                    }),
                };
                let stats = wgpu::BindGroupEntry {
                    binding: 1,
                    resource: stats.as_entire_binding(),
                };
                SlotTargets {
                    fragment: group("frame", &pass.frame_layout, std::slice::from_ref(&frame)),
                    compute: group(
                        "frame (compute)",
                        &pass.compute_layout,
                        &[
                            frame.clone(),
                            stats.clone(),
                            wgpu::BindGroupEntry {
                                binding: 2,
                                resource: wgpu::BindingResource::TextureView(&all),
                            },
                            wgpu::BindGroupEntry {
                                binding: 3,
                                resource: wgpu::BindingResource::TextureView(&all_depth),
                            },
                        ],
                    ),
                    classes: group("frame (classes)", &pass.classes_layout, &[frame, stats]),
                }
            })
            .collect();
        Self {
            id: super::kept::unique_id(),
            texture,
            depth,
            pages,
            slots,
            uniforms,
            stride,
            stats,
            stats_readback: readback_buffer(device, "stats readback", 16),
            readback: Readback::new(device, "subject readback", size),
        }
    }
}

impl SubjectTargets {
    /// The texture array of the pages.
    pub(super) fn texture(&self) -> &wgpu::Texture {
        &self.texture
    }

    /// Writes the frame uniforms of slots `0..frames.len()`, in one write.
    pub(super) fn write_frames(&self, queue: &wgpu::Queue, frames: &[GpuFrame]) {
        let size = std::mem::size_of::<GpuFrame>();
        let mut bytes = vec![0u8; self.stride * frames.len()];
        for (slot, frame) in frames.iter().enumerate() {
            bytes[slot * self.stride..][..size].copy_from_slice(bytemuck::bytes_of(frame));
        }
        queue.write_buffer(&self.uniforms, 0, &bytes);
    }

    /// The view of `page`.
    pub(super) fn page_view(&self, page: u32) -> &wgpu::TextureView {
        &self.pages[page as usize]
    }

    /// The depths' texture array.
    pub(super) fn depth_texture(&self) -> &wgpu::Texture {
        &self.depth
    }

    /// The fragment pass's frame bind group of `slot`.
    pub(super) fn fragment_group(&self, slot: usize) -> &wgpu::BindGroup {
        &self.slots[slot].fragment
    }

    /// The compute pass's frame bind group of `slot`.
    pub(super) fn compute_group(&self, slot: usize) -> &wgpu::BindGroup {
        &self.slots[slot].compute
    }
}

impl RebinPass {
    /// Records pose `pose` drawn by the frame uniform already written to `slot`'s buffer
    /// (whose bounds are `within` and place `place`), into its place in `targets`, by
    /// `stage`, with the pass's timestamps when given: the pixels `within` are shaded;
    /// the rest of the page is left as it was (nothing reads a render outside its box:
    /// the composite and the morph in time read within it; other renders share the
    /// page). Its pixel classes (of the pixels within) are counted into the targets'
    /// counters by the compute pass itself, and after a fragment pass by a pass of their
    /// own when `classes`.
    #[allow(clippy::too_many_arguments)] // one pass's every input, named at the call
    pub(super) fn record(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        targets: &SubjectTargets,
        (slot, place): (usize, Place),
        pose_group: &wgpu::BindGroup,
        (stage, variant): (PassKind, Variant),
        within: PixelBox,
        timestamps: Option<(&wgpu::QuerySet, u32)>,
        classes: bool,
    ) {
        let t = &targets.slots[slot];
        let pipelines = self.pipelines(variant);
        let size = within.size();
        match stage {
            PassKind::Fragment => {
                let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                    label: Some("rebin"),
                    color_attachments: &[loaded(targets.page_view(place.page))],
                    depth_stencil_attachment: None,
                    timestamp_writes: super::timing::render_pass_writes(timestamps),
                    occlusion_query_set: None,
                    multiview_mask: None,
                });
                if within.pixels() > 0 {
                    let (x, y) = place.texel(within.x0, within.y0);
                    pass.set_scissor_rect(x, y, size.0, size.1);
                    pass.set_pipeline(&pipelines.fragment);
                    pass.set_bind_group(0, &t.fragment, &[]);
                    pass.set_bind_group(1, pose_group, &[]);
                    pass.draw(0..3, 0..1);
                }
            }
            PassKind::Compute => {
                let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                    label: Some("rebin"),
                    timestamp_writes: super::timing::compute_pass_writes(timestamps),
                });
                pass.set_pipeline(&pipelines.compute);
                pass.set_bind_group(0, &t.compute, &[]);
                pass.set_bind_group(1, pose_group, &[]);
                // The slot's record numbers the tiles of `within` ([`number_tiles`]).
                let (x, y) = workgroups(size);
                let (x, y) = tile_groups(x * y);
                if x * y > 0 {
                    pass.dispatch_workgroups(x, y, 1);
                }
            }
        }
        // The compute pass counts as it shades; a fragment pass needs its own.
        if classes && stage == PassKind::Fragment && within.pixels() > 0 {
            let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("classes"),
                timestamp_writes: None,
            });
            pass.set_pipeline(&pipelines.classes);
            pass.set_bind_group(0, &t.classes, &[]);
            pass.set_bind_group(1, pose_group, &[]);
            let (x, y) = workgroups(size);
            pass.dispatch_workgroups(x, y, 1);
        }
    }
}

impl RebinPass {
    /// Records the compute frame pass of `dispatches` (each its first slot in
    /// `targets`, the pose whose bind group its renders share, and its tiles, numbered by
    /// [`number_tiles`] in its slots' records) in one pass, with the pass's timestamps
    /// when given; each render counts its pixel classes as it shades.
    pub(super) fn record_compute(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        targets: &SubjectTargets,
        dispatches: &[(usize, &GpuPose, u32)],
        variant: Variant,
        timestamps: Option<(&wgpu::QuerySet, u32)>,
    ) {
        let pipelines = self.pipelines(variant);
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("rebin"),
            timestamp_writes: super::timing::compute_pass_writes(timestamps),
        });
        pass.set_pipeline(&pipelines.compute);
        for &(slot, pose, tiles) in dispatches {
            let (x, y) = tile_groups(tiles);
            pass.set_bind_group(0, &targets.slots[slot].compute, &[]);
            pass.set_bind_group(1, &pose.bind_group, &[]);
            pass.dispatch_workgroups(x, y, 1);
        }
    }
}

/// The dispatches of the compute frame pass drawing `poses` (in slot order): renders of
/// one bind group in consecutive slots, [`FRAMES_BOUND`] at most, are one; each its first
/// slot and its length.
fn runs(poses: &[&GpuPose]) -> Vec<(usize, usize)> {
    let mut out = Vec::new();
    let mut at = 0;
    while at < poses.len() {
        let key = poses[at].group_key;
        let run = (poses[at..].iter().take(FRAMES_BOUND))
            .take_while(|p| p.group_key == key)
            .count();
        out.push((at, run));
        at += run;
    }
    out
}

impl Gpu {
    /// The kept targets of frames of `size` with `slots` renders on `pages` pages (made
    /// on first use; the few most recently used are kept).
    pub(super) fn subject_targets(
        &self,
        size: (u32, u32),
        slots: u32,
        pages: u32,
    ) -> Arc<SubjectTargets> {
        self.targets.get((size, slots, pages), || {
            SubjectTargets::new(&self.device, &self.rebin, size, slots, pages)
        })
    }

    /// Records the frame pass of every instance into `encoder`: each pose drawn by its
    /// camera (in its subject frame) within its pixel box, the boxes packed into pages
    /// of `size` ([`Place`]), in the order given (back to front; the composite pass puts
    /// each over the ones before it), and their pixel classes counted (the pixels
    /// outside a box as missed). Room is kept on pages after theirs for a morph in time
    /// of each box of `morphs` ([`super::time_morph`]).
    pub(super) fn draw_subjects(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        (instances, morphs): (&[(&GpuPose, Camera, PixelBox)], &[PixelBox]),
        size: (u32, u32),
        (variant, depth): (Variant, bool),
        timestamps: Option<(&wgpu::QuerySet, u32)>,
    ) -> Subjects {
        let boxes: Vec<PixelBox> = instances.iter().map(|i| i.2).collect();
        let (places, render_pages) = places(&boxes, size, 0);
        let (morph_places, morph_pages) = if morphs.is_empty() {
            (Vec::new(), 0)
        } else {
            self::places(morphs, size, render_pages)
        };
        let pages = render_pages + morph_pages;
        let targets = self.subject_targets(size, instances.len().max(1) as u32, pages);
        // The pixels shaded; the pass counts those clamped or missed beside them.
        let shaded = instances.iter().map(|i| i.2.pixels() as u32).sum::<u32>();
        self.queue
            .write_buffer(&targets.stats, 0, bytemuck::cast_slice(&[shaded, 0, 0, 0]));
        let outside = instances
            .iter()
            .map(|i| size.0 as usize * size.1 as usize - i.2.pixels())
            .sum();
        let renders: Vec<(&GpuPose, DrawnRender)> = instances
            .iter()
            .zip(&places)
            .map(|(&(pose, camera, within), &place)| {
                let drawn = DrawnRender {
                    place,
                    camera,
                    within,
                };
                (pose, drawn)
            })
            .collect();
        self.draw_renders(
            encoder,
            &targets,
            &renders,
            (variant, depth),
            timestamps,
            true,
        );
        Subjects {
            targets,
            outside,
            shown: places.clone(),
            places,
            render_pages,
            morphs: morph_places,
        }
    }

    /// Records `renders` (render `k` into slot `k` of `targets`): their frame uniforms
    /// (camera, box and place) written in one write, then their frame passes. The
    /// compute path records every render in one pass (its timestamps, when given, span
    /// them all); the fragment path a pass each ([`RebinPass::record`], `timestamps` on
    /// the first), and their pixel classes when `classes`.
    pub(super) fn draw_renders(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        targets: &SubjectTargets,
        renders: &[(&GpuPose, DrawnRender)],
        (variant, depth): (Variant, bool),
        timestamps: Option<(&wgpu::QuerySet, u32)>,
        classes: bool,
    ) {
        // Renders of one bind group next to each other (their slots in that order), so
        // that the compute pass draws them in one dispatch ([`RebinPass::record_compute`]).
        let mut order: Vec<usize> = (0..renders.len()).collect();
        if self.stage == PassKind::Compute {
            // Where each render lands is in its record, so any order draws the same.
            order.sort_by_key(|&k| renders[k].0.group_key);
        }
        let renders: Vec<&(&GpuPose, DrawnRender)> = order.iter().map(|&k| &renders[k]).collect();
        let mut frames: Vec<GpuFrame> = renders
            .iter()
            .map(|(pose, d)| {
                let mut frame = frame_uniform(Some(pose), &d.camera, variant);
                frame.bounds = d.within.to_array();
                frame.place = d.place.to_array();
                frame.depth = depth as u32;
                frame
            })
            .collect();
        // Each dispatch's tiles numbered across its renders (an empty box has none).
        let poses: Vec<&GpuPose> = renders.iter().map(|r| r.0).collect();
        let dispatches: Vec<(usize, &GpuPose, u32)> = runs(&poses)
            .into_iter()
            .map(|(at, run)| (at, poses[at], number_tiles(&mut frames[at..at + run])))
            .filter(|d| d.2 > 0)
            .collect();
        targets.write_frames(&self.queue, &frames);
        match self.stage {
            PassKind::Compute => {
                let timestamps = self.pass_timestamps("frame", timestamps);
                (self.rebin).record_compute(encoder, targets, &dispatches, variant, timestamps);
                self.dispatched("frame", dispatches.len());
            }
            PassKind::Fragment => {
                self.dispatched("frame", renders.len());
                for (slot, (pose, d)) in renders.iter().enumerate() {
                    self.rebin.record(
                        encoder,
                        targets,
                        (slot, d.place),
                        &pose.bind_group,
                        (PassKind::Fragment, variant),
                        d.within,
                        self.pass_timestamps("frame", timestamps.filter(|_| slot == 0)),
                        classes,
                    );
                }
            }
        }
    }

    /// Copies the pixel-class counters of a drawn frame into the staging buffer `into`
    /// (16 bytes).
    pub(super) fn copy_stats(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        subject: &Subjects,
        into: &wgpu::Buffer,
    ) {
        encoder.copy_buffer_to_buffer(&subject.targets.stats, 0, into, 0, 16);
    }

    /// The counters [`Gpu::copy_stats`] copied into its targets' own staging buffer
    /// (after its submission).
    fn read_stats(&self, subject: &Subjects) -> Result<FrameStats> {
        let counts = self.read_buffer(&subject.targets.stats_readback)?;
        Ok(frame_stats(&counts, subject.outside))
    }

    /// Copies (layer 0 of) an RGBA32F texture of `size` into a new staging buffer, for
    /// one-off reads; frames read back through their targets' own.
    pub(super) fn copy_rgba(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        texture: &wgpu::Texture,
        size: (u32, u32),
    ) -> Readback {
        let readback = Readback::new(&self.device, "readback", size);
        readback.copy(encoder, texture);
        readback
    }

    /// Renders the subject of a frame of `camera` (subject frame) with `variant`:
    /// premultiplied linear RGBA, and what happened to its pixels.
    pub fn render(
        &self,
        pose: &GpuPose,
        camera: &Camera,
        variant: Variant,
    ) -> Result<(Image<Rgba>, FrameStats)> {
        self.scoped("rendering a frame", || {
            let size = (camera.width, camera.height);
            let mut encoder = self
                .device
                .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                    label: Some("frame"),
                });
            let whole = PixelBox::whole(size.0, size.1);
            let subject = self.draw_subjects(
                &mut encoder,
                (&[(pose, *camera, whole)], &[]),
                size,
                (variant, false),
                None,
            );
            let t = &subject.targets;
            t.readback.copy(&mut encoder, &t.texture);
            self.copy_stats(&mut encoder, &subject, &t.stats_readback);
            self.submit([encoder.finish()]);
            Ok((self.read_rgba(&t.readback)?, self.read_stats(&subject)?))
        })
    }
}
