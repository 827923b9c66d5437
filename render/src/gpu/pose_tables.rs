//! What the frame pass reads of a resident pose besides its pre-lit views: its flows (a
//! texture array), its view and quad tables, the code tables, its proxy and hull, the
//! cylinder's column index and the quads' frames. They depend only on the pose's views
//! and flows, so every relit copy of one pose's views (walkers under their own light or
//! heading, the pose's motion views) shares one set, and with it one bind group a page of
//! pre-lit views ([`super::prelit`]): the frame pass draws every render of those copies
//! in a page in one dispatch (docs/design.md section 4.9). A pose whose pre-lit views are
//! a texture (the benchmark's sRGB8 storage) holds its scales in its view table and so
//! shares none.

use std::sync::{Arc, Mutex, Weak};

use glam::Quat;

use super::Gpu;
use super::bind::{buffer_with, table_bytes};
use super::kept::unique_id;
use super::prelit::PrelitRange;
use crate::geometry::PoseGeometry;
use crate::rectified::gpu_frame;
use crate::resident::{PoseFlows, srgb_lut};
use frf_shaders::types::{GpuQuad, GpuQuadFrame, GpuView};

/// A resident pose's tables (see the module docs).
pub(super) struct PoseTables {
    /// What they were made from (what names them while they live).
    geometry: Arc<PoseGeometry>,
    flows: Arc<PoseFlows>,
    /// Names them in the keys of bind groups.
    id: u64,
    flows_view: wgpu::TextureView,
    /// The view table (the cameras, and for a texture-stored pose its scales).
    pub(super) views: wgpu::Buffer,
    quads: wgpu::Buffer,
    tables: wgpu::Buffer,
    proxy: wgpu::Buffer,
    hull: wgpu::Buffer,
    index: wgpu::Buffer,
    frames: wgpu::Buffer,
    pub(super) quad_count: u32,
    /// Their bind group with each page of pre-lit views a copy lies in, made on first use.
    groups: Mutex<Vec<(usize, wgpu::BindGroup)>>,
}

/// The tables of the poses resident, found again by the views and flows they were made
/// from while a pose holds them.
#[derive(Default)]
pub(super) struct TablesKept(Mutex<Vec<Weak<PoseTables>>>);

/// Where a pose's pre-lit views are, as its bind group binds them.
pub(super) enum PrelitAt<'a> {
    /// A range of the shared pages.
    Shared(&'a PrelitRange),
    /// A texture array of its own.
    Texture(&'a wgpu::Texture),
}

impl Gpu {
    /// The tables of `geometry` and `flows`: those a resident copy of the same views holds
    /// when the pre-lit views are shared (`scales` `None`) and the pass that draws them
    /// is the renderer's (`renderers`), else new ones
    /// (`scales`: a texture-stored pose's, written into its view table), whose flows
    /// texture `flows_texture` makes.
    pub(super) fn pose_tables(
        &self,
        renderers: bool,
        (geometry, flows): (&Arc<PoseGeometry>, &Arc<PoseFlows>),
        scales: Option<&[f32]>,
        flows_texture: impl FnOnce() -> wgpu::Texture,
    ) -> Arc<PoseTables> {
        let mut kept = self.pose_tables.0.lock().unwrap_or_else(|e| e.into_inner());
        kept.retain(|t| t.strong_count() > 0);
        // Only the renderer's own pass shares (a kept bind group is made for one layout).
        let shared = scales.is_none() && renderers;
        if shared {
            let found = kept
                .iter()
                .filter_map(Weak::upgrade)
                .find(|t| Arc::ptr_eq(&t.geometry, geometry) && Arc::ptr_eq(&t.flows, flows));
            if let Some(t) = found {
                return t;
            }
        }
        let ones = vec![1.0; geometry.views()];
        let tables = Arc::new(self.make_tables(
            (geometry, flows),
            scales.unwrap_or(&ones),
            &flows_texture(),
        ));
        if shared {
            kept.push(Arc::downgrade(&tables));
        }
        tables
    }

    fn make_tables(
        &self,
        (geometry, flows): (&Arc<PoseGeometry>, &Arc<PoseFlows>),
        scales: &[f32],
        flows_texture: &wgpu::Texture,
    ) -> PoseTables {
        let gpu_views: Vec<GpuView> = geometry
            .cameras
            .iter()
            .zip(scales)
            .zip(&geometry.flow_layers)
            .zip(&geometry.prelit_layers)
            .map(|(((cam, &scale), l), &prelit_layer)| {
                let q = Quat::from_mat3(&cam.world_from_camera.rotation);
                let k = &cam.intrinsics;
                GpuView {
                    rotation: q.to_array(),
                    centre: cam.centre().to_array(),
                    scale,
                    intrinsics: [k.fx, k.fy, k.cx, k.cy],
                    flow_layers: *l,
                    prelit_layer,
                    pad0: 0,
                    pad1: 0,
                    pad2: 0,
                }
            })
            .collect();
        let quads: Vec<GpuQuad> = geometry
            .cylinder
            .quads()
            .iter()
            .map(|q| GpuQuad {
                p00: q.p00.to_array(),
                u: q.u,
                e1: q.e1.to_array(),
                v: q.v,
                e2: q.e2.to_array(),
                wall: q.wall,
                e3: q.e3.to_array(),
                wall_gamma: q.wall_gamma,
                normal: q.normal.to_array(),
                pad: 0.0,
            })
            .collect();
        let buffer = |label: &str, contents: &[u8]| {
            buffer_with(&self.device, label, contents, wgpu::BufferUsages::STORAGE)
        };
        let (index, ranges) = geometry.cylinder.column_index_gpu();
        let mut index_bytes = bytemuck::bytes_of(&index).to_vec();
        index_bytes.extend_from_slice(bytemuck::cast_slice(&ranges));
        let (proxy, hull_words) = geometry.proxy.gpu();
        let frames: Vec<GpuQuadFrame> = geometry
            .frames
            .iter()
            .map(|f| gpu_frame(f.as_ref()))
            .collect();
        PoseTables {
            geometry: geometry.clone(),
            flows: flows.clone(),
            id: unique_id(),
            flows_view: flows_texture.create_view(&wgpu::TextureViewDescriptor {
                dimension: Some(wgpu::TextureViewDimension::D2Array),
                ..Default::default()
            }),
            views: buffer_with(
                &self.device,
                "views",
                bytemuck::cast_slice(&gpu_views),
                wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
            ),
            quads: buffer("quads", bytemuck::cast_slice(&quads)),
            tables: buffer_with(
                &self.device,
                "tables",
                &table_bytes(&[srgb_lut(), flows.table]),
                wgpu::BufferUsages::UNIFORM,
            ),
            proxy: buffer("proxy", bytemuck::bytes_of(&proxy)),
            hull: buffer("hull", bytemuck::cast_slice(&hull_words)),
            index: buffer("column index", &index_bytes),
            frames: buffer("quad frames", bytemuck::cast_slice(&frames)),
            quad_count: quads.len() as u32,
            groups: Mutex::new(Vec::new()),
        }
    }

    /// The bind group of `tables` with the pre-lit views `prelit` for the frame pass's
    /// `layout` (and its `sampler`), and the key
    /// that names it (renders of equal keys are drawn in one dispatch): one a page of the
    /// shared pages, kept.
    pub(super) fn pose_group(
        &self,
        (layout, sampler): (&wgpu::BindGroupLayout, &wgpu::Sampler),
        tables: &PoseTables,
        prelit: PrelitAt<'_>,
    ) -> (wgpu::BindGroup, (u64, usize)) {
        let make = |resource: wgpu::BindingResource<'_>| {
            self.device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("pose"),
                layout,
                entries: &[
                    wgpu::BindGroupEntry {
                        binding: 0,
                        resource,
                    },
                    entry(1, wgpu::BindingResource::TextureView(&tables.flows_view)),
                    entry(2, tables.views.as_entire_binding()),
                    entry(3, tables.quads.as_entire_binding()),
                    entry(4, tables.tables.as_entire_binding()),
                    entry(5, tables.proxy.as_entire_binding()),
                    entry(6, tables.hull.as_entire_binding()),
                    entry(7, tables.index.as_entire_binding()),
                    entry(8, wgpu::BindingResource::Sampler(sampler)),
                    entry(9, tables.frames.as_entire_binding()),
                ],
            })
        };
        match prelit {
            PrelitAt::Shared(range) => {
                let page = range.page_key();
                let mut groups = tables.groups.lock().unwrap_or_else(|e| e.into_inner());
                let group = match groups.iter().find(|(p, _)| *p == page) {
                    Some((_, g)) => g.clone(),
                    None => {
                        let g = make(range.page().as_entire_binding());
                        groups.push((page, g.clone()));
                        g
                    }
                };
                (group, (tables.id, page))
            }
            PrelitAt::Texture(texture) => {
                let view = texture.create_view(&wgpu::TextureViewDescriptor {
                    dimension: Some(wgpu::TextureViewDimension::D2Array),
                    ..Default::default()
                });
                (
                    make(wgpu::BindingResource::TextureView(&view)),
                    (tables.id, 0),
                )
            }
        }
    }
}

fn entry(binding: u32, resource: wgpu::BindingResource<'_>) -> wgpu::BindGroupEntry<'_> {
    wgpu::BindGroupEntry { binding, resource }
}
