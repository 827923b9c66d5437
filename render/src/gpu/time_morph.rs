//! The GPU twin of [`crate::motion::time_morph`]: walkers between two captured poses.
//! Pose `k`'s render is drawn into the walker's place in the frame's subjects, as any
//! walker's; pose `k'`'s render and both poses' motion renders into targets kept for
//! frames between poses; `shaders/time_morph.wgsl` morphs them in time, every walker in
//! one dispatch, into a place kept for it on the subjects' pages after the renders'
//! (so that the pass never reads a page it writes), where the composite reads the walker
//! ([`Subjects::shown`]). All of it within the walker's pixel box alone, each render
//! packed with others into pages ([`crate::atlas`]): nothing reads a render outside its
//! box, so a far walker's morph costs its own pixels, not the frame's.
use frf_core::camera::Camera;
use frf_shaders::types::GpuTimeMorph;
use glam::Mat2;

use super::bind::{bind_group, buffer_with, storage, storage_texture_array, texture_array};
use super::pose::GpuPose;
use super::rebin::{DrawnRender, Place, SubjectTargets, Subjects, places, workgroups};
use super::timing::compute_pass_writes;
use super::{Gpu, shaders};
use crate::footprint::PixelBox;
use crate::morph::Variant;

/// A walker between two captured poses: the later pose, both poses' motion toward the
/// other, and the fraction of the way.
pub struct GpuBetween<'a> {
    /// Pose `k'`, relit alike.
    pub after: &'a GpuPose,
    /// Pose `k`'s motion toward `k'`.
    pub before_motion: &'a GpuPose,
    /// Pose `k'`'s motion toward `k`.
    pub after_motion: &'a GpuPose,
    /// The fraction of the way from `k` to `k'`.
    pub s: f32,
}

/// The pipeline of the morph in time.
pub struct TimeMorphPass {
    layout: wgpu::BindGroupLayout,
    pipeline: wgpu::ComputePipeline,
}

impl TimeMorphPass {
    /// Compiles the pass on `device`.
    pub fn new(device: &wgpu::Device) -> Self {
        let module = shaders::module(device, "time morph", shaders::TIME_MORPH);
        let texture = |binding| {
            texture_array(
                binding,
                wgpu::TextureSampleType::Float { filterable: false },
            )
        };
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("time morph"),
            entries: &[
                storage::<GpuTimeMorph>(0, true, wgpu::ShaderStages::COMPUTE),
                texture(1),
                texture(2),
                storage_texture_array(3, wgpu::TextureFormat::Rgba32Float),
                texture(4),
                texture(5),
                storage_texture_array(6, wgpu::TextureFormat::R32Float),
            ],
        });
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("time morph"),
            bind_group_layouts: &[Some(&layout)],
            immediate_size: 0,
        });
        let pipeline = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
            label: Some("time morph"),
            layout: Some(&pipeline_layout),
            module: &module,
            entry_point: Some("morph_in_time"),
            compilation_options: Default::default(),
            cache: None,
        });
        Self { layout, pipeline }
    }
}

/// A walker between poses: its index in the frame's subjects, its poses, and the camera
/// that sees it (its subject frame).
pub(super) struct BetweenDraw<'a> {
    pub layer: usize,
    pub between: &'a GpuBetween<'a>,
    pub camera: Camera,
    /// The pixels it may show in.
    pub within: crate::footprint::PixelBox,
}

impl Gpu {
    /// Records the morph in time of every walker of `walkers` into `encoder`, from its
    /// render in `subjects` (where pose `k` is already drawn) into the place kept there
    /// for it (walker `j` of `walkers`, morph `j`), which then shows it (see the module
    /// docs).
    pub(super) fn morph_in_time(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        subjects: &mut Subjects,
        walkers: &[BetweenDraw],
        size: (u32, u32),
        (variant, by_depth): (Variant, bool),
    ) {
        if walkers.is_empty() {
            return;
        }
        // Three renders a walker (pose k', and both poses' motion) packed into pages.
        let boxes: Vec<PixelBox> = walkers.iter().flat_map(|w| [w.within; 3]).collect();
        let (renders, pages) = places(&boxes, size, 0);
        let slots = 3 * walkers.len() as u32;
        let scratch = self.between_targets.get((size, slots, pages), || {
            SubjectTargets::new(&self.device, &self.rebin, size, slots, pages)
        });
        // Every walker's three renders, in one go, then their morphs in one pass.
        let drawn = between_renders(walkers, &renders);
        self.draw_renders(encoder, &scratch, &drawn, (variant, by_depth), None, false);
        let group = self.morph_group(&scratch, subjects, walkers, &renders, by_depth);
        // One dispatch for every walker (a layer of workgroups each) over the largest box.
        let (x, y) = walkers
            .iter()
            .map(|w| workgroups(w.within.size()))
            .fold((0, 0), |(a, b), (x, y)| (a.max(x), b.max(y)));
        if x * y > 0 {
            let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("time morph"),
                timestamp_writes: compute_pass_writes(self.pass_timestamps("time morph", None)),
            });
            pass.set_pipeline(&self.time_morph.pipeline);
            self.dispatched("time morph", 1);
            pass.set_bind_group(0, &group, &[]);
            pass.dispatch_workgroups(x, y, walkers.len() as u32);
        }
        // The composite reads each walker's morph where it was written.
        for (j, w) in walkers.iter().enumerate() {
            subjects.show_morph(w.layer, j);
        }
    }

    /// The morphs' bind group (`renders`: three places a walker on `scratch`; walker
    /// `j`'s morph at the subjects' morph place `j`, on the pages after the renders'):
    /// every walker's record in one buffer, the pages as arrays.
    fn morph_group(
        &self,
        scratch: &SubjectTargets,
        subjects: &Subjects,
        walkers: &[BetweenDraw],
        renders: &[Place],
        by_depth: bool,
    ) -> wgpu::BindGroup {
        let render_pages = subjects.render_pages();
        let records: Vec<GpuTimeMorph> = walkers
            .iter()
            .enumerate()
            .map(|(j, w)| {
                let (before, _) = subjects.place(w.layer);
                let [after, before_motion, after_motion] = [0, 1, 2].map(|k| renders[3 * j + k]);
                let pair =
                    |a: Place, b: Place| [a.offset[0], a.offset[1], b.offset[0], b.offset[1]];
                let m: Mat2 = frf_core::subject_motion::motion_to_image(&w.camera);
                let morph = subjects.morph_place(j);
                GpuTimeMorph {
                    to_image: [m.x_axis.x, m.x_axis.y, m.y_axis.x, m.y_axis.y],
                    bounds: w.within.to_array(),
                    at_poses: pair(before, after),
                    at_motions: pair(before_motion, after_motion),
                    at_morph: pair(morph, morph),
                    s: w.between.s,
                    by_depth: by_depth as u32,
                    morph_page: morph.page - render_pages,
                    pad: 0,
                    pages: [
                        before.page,
                        after.page,
                        before_motion.page,
                        after_motion.page,
                    ],
                }
            })
            .collect();
        let buffer = buffer_with(
            &self.device,
            "time morphs",
            bytemuck::cast_slice(&records),
            wgpu::BufferUsages::STORAGE,
        );
        let layers = |t: &wgpu::Texture, first: u32, count: Option<u32>| {
            t.create_view(&wgpu::TextureViewDescriptor {
                dimension: Some(wgpu::TextureViewDimension::D2Array),
                base_array_layer: first,
                array_layer_count: count,
                ..Default::default()
            })
        };
        // The subjects' renders read, their morphs' pages written: apart.
        let views = [
            layers(subjects.texture(), 0, Some(render_pages)),
            layers(scratch.texture(), 0, None),
            layers(subjects.texture(), render_pages, None),
            layers(subjects.depth_texture(), 0, Some(render_pages)),
            layers(scratch.depth_texture(), 0, None),
            layers(subjects.depth_texture(), render_pages, None),
        ];
        let resources = std::iter::once(buffer.as_entire_binding())
            .chain(views.iter().map(wgpu::BindingResource::TextureView))
            .collect();
        bind_group(
            &self.device,
            "time morph",
            &self.time_morph.layout,
            resources,
        )
    }
}

/// Every walker's three renders (pose `k'` and both poses' motion) at their places
/// (`renders`, three a walker).
fn between_renders<'a>(
    walkers: &[BetweenDraw<'a>],
    renders: &[Place],
) -> Vec<(&'a GpuPose, DrawnRender)> {
    walkers
        .iter()
        .enumerate()
        .flat_map(|(j, w)| {
            let b = w.between;
            [b.after, b.before_motion, b.after_motion]
                .into_iter()
                .enumerate()
                .map(move |(k, pose)| {
                    let drawn = DrawnRender {
                        place: renders[3 * j + k],
                        camera: w.camera,
                        within: w.within,
                    };
                    (pose, drawn)
                })
        })
        .collect()
}
