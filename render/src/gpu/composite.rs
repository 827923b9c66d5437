//! The composite pass (`shaders/composite.wgsl`): after the frame pass has drawn the
//! subject, a full-screen triangle puts it over the backdrop (environment, plate or
//! nothing) whose ground is darkened by the pose's relit shadow, into three RGBA32F
//! targets: the composite, the relative irradiance per pixel and the backdrop. Twin of
//! [`crate::composite::compose`].

use frf_core::camera::Camera;
use frf_core::image::{Image, Rgba};
use wgpu::util::DeviceExt;

use frf_core::camera::Rigid;
use std::sync::Arc;

use super::composite_targets::CompositeTargets;
use super::rebin::Subjects;
use super::time_morph::{BetweenDraw, GpuBetween};
use super::timing::Timestamps;

use super::Gpu;
use super::bind::bind_group;
use super::pose::{GpuPose, RelitShadowInfo};
use super::readback::PendingFrame;
use super::rebin::{frame_stats, frame_uniform};
use super::shadow::ShadowDraw;
use crate::RenderError;
use crate::composite::{Backdrop, GroundLook, Layers, back_to_front};
use crate::cpu::FrameStats;
use crate::error::Result;
use crate::footprint::{PixelBox, TILE, TileLists, ground_box};
use crate::morph::Variant;
use frf_shaders::types::{GpuComposite, GpuInstance};

/// A walker to draw: its resident pose and where it stands.
pub struct GpuInstanceRef<'a> {
    /// The pose it shows, relit for its heading.
    pub pose: &'a GpuPose,
    /// Its subject frame in the world.
    pub world_from_subject: Rigid,
    /// Between `pose` and a later pose ([`crate::motion`]).
    pub between: Option<GpuBetween<'a>>,
    /// The pixels where it may show: only these are shaded; `None`, the whole frame.
    pub within: Option<PixelBox>,
}

impl GpuInstanceRef<'_> {
    /// The pose whose shadow the walker casts: the nearer of two between poses.
    fn shadow_pose(&self) -> &GpuPose {
        match &self.between {
            Some(b) if b.s >= 0.5 => b.after,
            _ => self.pose,
        }
    }
}

/// A frame drawn into the kept targets of its size and not read back
/// ([`Gpu::encode_composite`]).
pub struct DrawnFrame {
    pub(super) targets: Arc<CompositeTargets>,
    subjects: Subjects,
}

impl DrawnFrame {
    /// Width and height, pixels.
    pub fn size(&self) -> (u32, u32) {
        let t = &self.targets.targets[0];
        (t.width(), t.height())
    }
}

/// A backdrop resident on the GPU.
pub struct GpuBackdrop {
    /// Names the backdrop in the keys of bind groups made of it ([`super::kept`]).
    id: u64,
    params: GpuComposite,
    env: wgpu::Texture,
    plate: wgpu::Texture,
    plate_size: Option<(u32, u32)>,
}

/// Uploads linear RGB texels of `size` as an RGBA32F texture.
fn upload_rgb(gpu: &Gpu, label: &str, size: (u32, u32), texels: &[[f32; 3]]) -> wgpu::Texture {
    let data: Vec<f32> = texels
        .iter()
        .flat_map(|p| [p[0], p[1], p[2], 1.0])
        .collect();
    gpu.device.create_texture_with_data(
        &gpu.queue,
        &wgpu::TextureDescriptor {
            label: Some(label),
            size: wgpu::Extent3d {
                width: size.0,
                height: size.1,
                depth_or_array_layers: 1,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: wgpu::TextureFormat::Rgba32Float,
            usage: wgpu::TextureUsages::TEXTURE_BINDING,
            view_formats: &[],
        },
        wgpu::util::TextureDataOrder::LayerMajor,
        bytemuck::cast_slice(&data),
    )
}

impl Gpu {
    /// Makes `backdrop` resident.
    pub fn upload_backdrop(&self, backdrop: &Backdrop) -> Result<GpuBackdrop> {
        self.scoped("uploading the backdrop", || {
            let one = |label| upload_rgb(self, label, (1, 1), &[[0.0; 3]]);
            let mut params = GpuComposite {
                backdrop: 0,
                ground_look: 0,
                has_shadow: 0,
                shadow_texels: 1,
                ground_radiance: [0.0; 4],
                env_size: [1, 1],
                env_yaw: 0.0,
                shadow_extent: 1.0,
                instances: 0,
                tile_columns: 0,
                tile_side: TILE,
                by_depth: 0,
            };
            let (env, plate, plate_size) = match backdrop {
                Backdrop::None => (one("no environment"), one("no plate"), None),
                Backdrop::Environment {
                    env,
                    ground,
                    ground_radiance,
                } => {
                    let img = env.image();
                    let size = (img.width() as u32, img.height() as u32);
                    params.backdrop = 1;
                    params.ground_look = matches!(ground, GroundLook::Albedo(_)) as u32;
                    params.ground_radiance = [
                        ground_radiance[0],
                        ground_radiance[1],
                        ground_radiance[2],
                        0.0,
                    ];
                    params.env_size = [size.0, size.1];
                    params.env_yaw = env.yaw();
                    (
                        upload_rgb(self, "environment", size, img.pixels()),
                        one("no plate"),
                        None,
                    )
                }
                Backdrop::Plate(img) => {
                    let size = (img.width() as u32, img.height() as u32);
                    params.backdrop = 2;
                    (
                        one("no environment"),
                        upload_rgb(self, "plate", size, img.pixels()),
                        Some(size),
                    )
                }
            };
            Ok(GpuBackdrop {
                id: super::kept::unique_id(),
                params,
                env,
                plate,
                plate_size,
            })
        })
    }

    /// Renders a frame of `camera` (world frame): every walker's pose drawn by the
    /// camera as its subject frame sees it (back to front, [`back_to_front`]; where
    /// walkers overlap, by their depths at each pixel), composited
    /// over `backdrop` with the product of their relit shadows; with `layers`, the
    /// walkers alone, the relative irradiance and the backdrop too.
    pub fn render_composite(
        &self,
        instances: &[GpuInstanceRef],
        backdrop: &GpuBackdrop,
        camera: &Camera,
        variant: Variant,
        layers: bool,
    ) -> Result<(Image<Rgba>, Option<Layers>, FrameStats)> {
        let pending = self.submit_composite(instances, backdrop, camera, variant, layers)?;
        self.finish_drawn(pending)
    }

    /// Draws and submits a frame as [`Gpu::render_composite`] does, without waiting for
    /// it: [`Gpu::finish_drawn`] reads it back, after the next frame is submitted when a
    /// sequence overlaps its readback with drawing.
    pub fn submit_composite(
        &self,
        instances: &[GpuInstanceRef],
        backdrop: &GpuBackdrop,
        camera: &Camera,
        variant: Variant,
        layers: bool,
    ) -> Result<PendingFrame> {
        let mut encoder = self
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("composite"),
            });
        let drawn =
            self.encode_composite(&mut encoder, instances, backdrop, camera, variant, None)?;
        self.submit_drawn(encoder, &drawn, layers)
    }

    /// Draws a frame as [`Gpu::submit_composite`] does, submits it without copying
    /// anything back (a frame shown where it is drawn: what a viewer presenting it
    /// waits for) and waits until the device has drawn it.
    pub fn draw_composite_unread(
        &self,
        instances: &[GpuInstanceRef],
        backdrop: &GpuBackdrop,
        camera: &Camera,
        variant: Variant,
    ) -> Result<()> {
        let mut encoder = self
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("composite (unread)"),
            });
        self.encode_composite(&mut encoder, instances, backdrop, camera, variant, None)?;
        let submission = self.submit([encoder.finish()]);
        self.waiting(|| {
            self.device.poll(wgpu::PollType::Wait {
                submission_index: Some(submission),
                timeout: None,
            })
        })
        .map_err(super::wgpu_err("waiting on a frame"))?;
        Ok(())
    }

    /// Reads back the frame `encoder` draws (`drawn`, [`Gpu::encode_composite`]): submits
    /// it with the copies, and returns the composite, the layers when `layers`, and what
    /// happened to the walkers' pixels.
    pub fn read_drawn(
        &self,
        encoder: wgpu::CommandEncoder,
        drawn: &DrawnFrame,
        layers: bool,
    ) -> Result<(Image<Rgba>, Option<Layers>, FrameStats)> {
        let pending = self.submit_drawn(encoder, drawn, layers)?;
        self.finish_drawn(pending)
    }

    /// Submits the frame `encoder` draws (`drawn`, [`Gpu::encode_composite`]) with the
    /// copies of its composite (with `layers`, its layers too) and counters into a
    /// staging set of its own ([`super::readback`]), and asks for them mapped; nothing
    /// waits. The next frame may be drawn and submitted before this one is finished
    /// ([`Gpu::finish_drawn`]).
    pub fn submit_drawn(
        &self,
        mut encoder: wgpu::CommandEncoder,
        drawn: &DrawnFrame,
        layers: bool,
    ) -> Result<PendingFrame> {
        self.scoped("submitting a frame", || {
            let t = &drawn.targets;
            // Composite, then (with layers) subject, shadow and backdrop.
            let read: &'static [usize] = if layers { &[0, 3, 1, 2] } else { &[0] };
            let staging = self.staging_for(drawn.size());
            staging.copy(&mut encoder, &t.targets, read);
            self.copy_stats(&mut encoder, &drawn.subjects, staging.stats());
            let submission = self.submit([encoder.finish()]);
            let outside = drawn.subjects.outside();
            Ok(PendingFrame::mapping(staging, read, outside, submission))
        })
    }

    /// Waits for `frame` ([`Gpu::submit_drawn`]; frames submitted after it are not
    /// waited for) and returns the composite, the layers when they were asked for, and
    /// what happened to the walkers' pixels.
    pub fn finish_drawn(
        &self,
        frame: PendingFrame,
    ) -> Result<(Image<Rgba>, Option<Layers>, FrameStats)> {
        self.scoped("reading a frame back", || {
            let (images, counts, outside) = self.read_pending(frame)?;
            let mut images = images.into_iter();
            let composite = images.next().ok_or_else(|| {
                RenderError::Misuse("a frame read back without its composite".into())
            })?;
            let layers = match (images.next(), images.next(), images.next()) {
                (Some(subject), Some(shadow), Some(backdrop)) => Some(Layers {
                    subject,
                    shadow: shadow.map(|p| [p[0], p[1], p[2]]),
                    backdrop,
                }),
                _ => None,
            };
            Ok((composite, layers, frame_stats(&counts, outside)))
        })
    }

    /// Records into `encoder` a frame of `camera` as [`Gpu::render_composite`] draws it,
    /// into kept targets, and reads nothing back: what a window shows
    /// ([`super::present`]), or [`Gpu::read_drawn`] reads. The first walker's frame pass
    /// writes `timestamps` (two queries) when given.
    pub fn encode_composite(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        instances: &[GpuInstanceRef],
        backdrop: &GpuBackdrop,
        camera: &Camera,
        variant: Variant,
        timestamps: Timestamps,
    ) -> Result<DrawnFrame> {
        if let Some((w, h)) = backdrop.plate_size
            && (w, h) != (camera.width, camera.height)
        {
            return Err(RenderError::Mismatch {
                what: "the plate (a plate is seen by its own camera)".into(),
                expected: format!("the camera's {}x{}", camera.width, camera.height),
                got: format!("{w}x{h}"),
            });
        }
        if instances.is_empty() {
            return Err(RenderError::Misuse("a frame with no walker".into()));
        }
        let shadow_info = shared_shadow(instances)?;
        self.scoped("compositing a frame", || {
            let size = (camera.width, camera.height);
            let order = back_to_front(
                camera,
                &instances
                    .iter()
                    .map(|i| i.world_from_subject.translation)
                    .collect::<Vec<_>>(),
            );
            let whole = PixelBox::whole(size.0, size.1);
            // The composite and the morph in time read a layer only within its box.
            let drawn: Vec<(&GpuPose, Camera, PixelBox)> = order
                .iter()
                .map(|&k| {
                    let i = &instances[k];
                    let seen = camera.transformed(&i.world_from_subject.inverse());
                    (i.pose, seen, i.within.unwrap_or(whole))
                })
                .collect();
            // Walkers that may overlap are put over each other by depth, pixel by pixel.
            let by_depth = drawn.len() > 1;
            let between: Vec<BetweenDraw> = order
                .iter()
                .enumerate()
                .filter_map(|(layer, &k)| {
                    let b = instances[k].between.as_ref()?;
                    Some(BetweenDraw {
                        layer,
                        between: b,
                        camera: drawn[layer].1,
                        within: drawn[layer].2,
                    })
                })
                .collect();
            // Room for each morph in time on the subjects' pages after the renders'.
            let morphs: Vec<PixelBox> = between.iter().map(|b| b.within).collect();
            let mut subjects = self.draw_subjects(
                encoder,
                (&drawn, &morphs),
                size,
                (variant, by_depth),
                timestamps,
            );
            self.morph_in_time(encoder, &mut subjects, &between, size, (variant, by_depth));
            let n_shadow = shadow_info.map_or(1, |s| s.texels);
            let t = self.composite_targets((size, order.len() as u32, n_shadow));
            let (gpu_instances, touched, shadows) =
                place_walkers(instances, &order, &drawn, &subjects, shadow_info);
            self.record_shadows(encoder, &shadows, &t.shadows)?;
            let mut params = backdrop.params;
            if let Some(info) = shadow_info {
                params.has_shadow = 1;
                params.shadow_texels = info.texels;
                params.shadow_extent = info.extent_m;
            }
            params.instances = order.len() as u32;
            params.by_depth = by_depth as u32;
            let tiles = TileLists::new(size.0, size.1, &touched);
            params.tile_columns = tiles.columns;
            params.tile_side = TILE;
            let write = |buffer: &wgpu::Buffer, bytes: &[u8]| {
                self.queue.write_buffer(buffer, 0, bytes);
            };
            write(
                &t.frame,
                bytemuck::bytes_of(&frame_uniform(None, camera, variant)),
            );
            write(&t.params, bytemuck::bytes_of(&params));
            write(&t.instances, bytemuck::cast_slice(&gpu_instances));
            write(&t.tiles, bytemuck::cast_slice(&tiles.words));
            self.record_composite(encoder, &t, &subjects, backdrop);
            Ok(DrawnFrame {
                targets: t,
                subjects,
            })
        })
    }
}

impl Gpu {
    /// Records the composite pass over targets `t`: `subjects` over `backdrop`, with the
    /// walkers' shadows (the uniforms already written).
    fn record_composite(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        t: &CompositeTargets,
        subjects: &Subjects,
        backdrop: &GpuBackdrop,
    ) {
        // Made once per drawn subjects and backdrop, and kept with the targets.
        let image_group = t.image_groups.get((subjects.id(), backdrop.id), || {
            let array_view = |t: &wgpu::Texture| {
                t.create_view(&wgpu::TextureViewDescriptor {
                    dimension: Some(wgpu::TextureViewDimension::D2Array),
                    ..Default::default()
                })
            };
            let view = |t: &wgpu::Texture| t.create_view(&wgpu::TextureViewDescriptor::default());
            let views = [
                array_view(subjects.texture()),
                view(&backdrop.env),
                view(&backdrop.plate),
                array_view(&t.shadows),
                array_view(subjects.depth_texture()),
            ];
            bind_group(
                &self.device,
                "composite images",
                &self.composite.image_layout,
                views
                    .iter()
                    .map(wgpu::BindingResource::TextureView)
                    .collect(),
            )
        });
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("composite"),
            timestamp_writes: super::timing::compute_pass_writes(
                self.pass_timestamps("composite", None),
            ),
        });
        pass.set_pipeline(&self.composite.pipeline);
        self.dispatched("composite", 1);
        pass.set_bind_group(0, &t.frame_group, &[]);
        pass.set_bind_group(1, &*image_group, &[]);
        let size = t.targets[0].size();
        let (x, y) = super::rebin::workgroups((size.width, size.height));
        pass.dispatch_workgroups(x, y, 1);
    }
}

/// The walkers' relit shadows: one patch of ground, each at its own level of detail
/// (texels a side); the array holds the finest. `None` when no walker has maps.
fn shared_shadow(instances: &[GpuInstanceRef]) -> Result<Option<RelitShadowInfo>> {
    let infos: Vec<RelitShadowInfo> = instances
        .iter()
        .filter_map(|i| i.shadow_pose().shadow.as_ref().map(|s| s.info()))
        .collect();
    let shadow_info = infos.first().map(|first| RelitShadowInfo {
        texels: infos.iter().map(|i| i.texels).max().unwrap_or(1),
        extent_m: first.extent_m,
    });
    if let Some(info) = shadow_info
        && infos.iter().any(|i| i.extent_m != info.extent_m)
    {
        return Err(RenderError::Misuse(
            "walkers with shadow maps of different patches of ground".into(),
        ));
    }
    Ok(shadow_info)
}

/// Each walker, back to front (`order`; `drawn`: its render's pose, camera and box),
/// placed for the composite: its instance, the pixels it may touch (its render's box,
/// and where it sees its shadow's patch of ground), and its shadow to draw into its
/// layer of the targets' shadows.
fn place_walkers<'a>(
    instances: &'a [GpuInstanceRef],
    order: &[usize],
    drawn: &[(&GpuPose, Camera, PixelBox)],
    subjects: &Subjects,
    shadow_info: Option<RelitShadowInfo>,
) -> (Vec<GpuInstance>, Vec<PixelBox>, Vec<ShadowDraw<'a>>) {
    let mut gpu_instances = Vec::with_capacity(order.len());
    let mut shadows = Vec::new();
    // Per walker, the pixels it may touch: its render's box, and where it sees its
    // shadow's patch of ground.
    let mut touched = Vec::with_capacity(order.len());
    for (layer, &k) in order.iter().enumerate() {
        let i = &instances[k];
        let m = i.world_from_subject.inverse();
        let shadow = i.shadow_pose().shadow.as_ref();
        let texels = shadow.map_or(0, |s| s.info().texels);
        if let Some(shadow) = shadow {
            shadows.push(ShadowDraw {
                shadow,
                layer: layer as u32,
            });
        }
        let shadow_box = match shadow_info {
            Some(info) if texels > 0 => ground_box(&drawn[layer].1, 0.5 * info.extent_m),
            _ => None,
        };
        touched.push(drawn[layer].2.union(shadow_box.unwrap_or(PixelBox::EMPTY)));
        gpu_instances.push(GpuInstance {
            col_x: m.rotation.x_axis.extend(0.0).to_array(),
            col_y: m.rotation.y_axis.extend(0.0).to_array(),
            col_z: m.rotation.z_axis.extend(0.0).to_array(),
            translation: m.translation.extend(texels as f32).to_array(),
            bounds: drawn[layer].2.to_array(),
            place: subjects.shown(layer).to_array(),
        });
    }
    (gpu_instances, touched, shadows)
}
