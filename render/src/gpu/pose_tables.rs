//! What the frame pass reads of a resident pose besides its copy's own part ([`super::prelit`]):
//! its cameras (the view table), the quad table, the code tables, its proxy and hull,
//! the cylinder's column index and the quads' frames. They depend only on the pose (its
//! cameras, its hull, its flows' quantizer), not on the views a plan read nor on the
//! light, so every copy of a pose at a level of detail (walkers under their own light or
//! heading, read by plans of their own, the pose's motion views) shares one set, and with
//! it one bind group a pair of pages (pre-lit, flows): the frame pass draws every render of
//! those copies in one dispatch (docs/design.md section 4.9). The set is found again by
//! what it holds (the bytes it uploaded and the hull it binds).

use std::sync::{Arc, Mutex, Weak};

use frf_core::camera::Camera;
use glam::Quat;

use super::Gpu;
use super::bind::{buffer_with, table_bytes};
use super::formats::PRELIT_TEXELS_BINDING;
use super::kept::unique_id;
use super::prelit::{FlowRange, PrelitRange};
use crate::geometry::PoseGeometry;
use crate::resident::{PoseFlows, srgb_lut};
use frf_shaders::types::{GpuQuad, GpuQuadFrame, GpuView};

/// A resident pose's tables (see the module docs).
pub(super) struct PoseTables {
    /// What names them: every byte they uploaded but the hull's, and the hull (by address,
    /// held).
    key: (Vec<u8>, Option<Arc<frf_reflectance::hull::VoxelHull>>),
    /// Names them in the keys of bind groups.
    id: u64,
    /// The view table (the cameras).
    pub(super) views: wgpu::Buffer,
    quads: wgpu::Buffer,
    tables: wgpu::Buffer,
    proxy: wgpu::Buffer,
    hull: wgpu::Buffer,
    index: wgpu::Buffer,
    frames: wgpu::Buffer,
    pub(super) quad_count: u32,
    /// Their bind group with each pair of pages (pre-lit, flows) a copy lies in, made on
    /// first use.
    groups: Mutex<Vec<((usize, usize), wgpu::BindGroup)>>,
}

/// The tables of the poses resident, found again while a pose holds them.
#[derive(Default)]
pub(super) struct TablesKept(Mutex<Vec<Weak<PoseTables>>>);

/// Where a resident copy's flows are.
pub(super) enum Flows {
    /// A range of the shared pages, shared by the copies made from the same flows.
    Shared(Arc<FlowRange>),
    /// A texture array of its own (decoded flows, the benchmark's).
    Texture(wgpu::Texture),
}

/// A view table's entry: `camera`'s orientation, centre and intrinsics.
pub(super) fn gpu_view(camera: &Camera) -> GpuView {
    let k = &camera.intrinsics;
    GpuView {
        rotation: Quat::from_mat3(&camera.world_from_camera.rotation).to_array(),
        centre: camera.centre().to_array(),
        pad: 0.0,
        intrinsics: [k.fx, k.fy, k.cx, k.cy],
    }
}

/// The bytes of the tables of `geometry` with `flows`' code table but the hull's (named by
/// the hull itself, copied only when the tables are made), in the order [`PoseTables`]
/// holds them: views, quads, code tables, proxy, column index, frames.
fn table_parts(geometry: &PoseGeometry, flows: &PoseFlows) -> [Vec<u8>; 6] {
    let views: Vec<GpuView> = geometry.cameras.iter().map(gpu_view).collect();
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
    let (index, ranges) = geometry.cylinder.column_index_gpu();
    let mut index_bytes = bytemuck::bytes_of(&index).to_vec();
    index_bytes.extend_from_slice(bytemuck::cast_slice(&ranges));
    let proxy = geometry.proxy.gpu_info();
    let frames: Vec<GpuQuadFrame> = geometry
        .frames
        .iter()
        .map(|f| crate::rectified::gpu_frame(f.as_ref()))
        .collect();
    [
        bytemuck::cast_slice(&views).to_vec(),
        bytemuck::cast_slice(&quads).to_vec(),
        table_bytes(&[srgb_lut(), flows.table]),
        bytemuck::bytes_of(&proxy).to_vec(),
        index_bytes,
        bytemuck::cast_slice(&frames).to_vec(),
    ]
}

impl Gpu {
    /// The tables of `geometry` (with `flows`' code table): those a resident copy of the
    /// same pose holds when `shared` (the renderer's own pass: a kept bind group is made
    /// for one layout), else new ones.
    pub(super) fn pose_tables(
        &self,
        shared: bool,
        geometry: &PoseGeometry,
        flows: &PoseFlows,
    ) -> Arc<PoseTables> {
        let made = table_parts(geometry, flows);
        let key = (made.concat(), geometry.proxy.hull_shared().cloned());
        let same = |t: &PoseTables| {
            t.key.0 == key.0
                && match (&t.key.1, &key.1) {
                    (Some(a), Some(b)) => Arc::ptr_eq(a, b),
                    (None, None) => true,
                    _ => false,
                }
        };
        let mut kept = self.pose_tables.0.lock().unwrap_or_else(|e| e.into_inner());
        kept.retain(|t| t.strong_count() > 0);
        if shared && let Some(t) = kept.iter().filter_map(Weak::upgrade).find(|t| same(t)) {
            return t;
        }
        let [views, quads, tables, proxy, index, frames] = &made;
        let (_, hull_words) = geometry.proxy.gpu();
        let storage = |label: &str, contents: &[u8]| {
            buffer_with(&self.device, label, contents, wgpu::BufferUsages::STORAGE)
        };
        let tables = Arc::new(PoseTables {
            id: unique_id(),
            views: storage("views", views),
            quads: storage("quads", quads),
            tables: buffer_with(&self.device, "tables", tables, wgpu::BufferUsages::UNIFORM),
            proxy: storage("proxy", proxy),
            hull: storage("hull", bytemuck::cast_slice(&hull_words)),
            index: storage("column index", index),
            frames: storage("quad frames", frames),
            quad_count: geometry.cylinder.quads().len() as u32,
            groups: Mutex::new(Vec::new()),
            key,
        });
        if shared {
            kept.push(Arc::downgrade(&tables));
        }
        tables
    }

    /// The bind group of `tables` with a copy's `prelit` range, its `flows` and the
    /// texture of its pre-lit texels, if any, for the frame pass's `layout` (and its
    /// `sampler`), and the key that names it (renders of equal keys are drawn in one
    /// dispatch): one a pair of pages where nothing is a texture, kept.
    pub(super) fn pose_group(
        &self,
        (layout, sampler): (&wgpu::BindGroupLayout, &wgpu::Sampler),
        tables: &PoseTables,
        (prelit, flows, texels): (&PrelitRange, &Flows, Option<&wgpu::Texture>),
    ) -> (wgpu::BindGroup, (u64, usize, usize)) {
        let array = |t: &wgpu::Texture| {
            t.create_view(&wgpu::TextureViewDescriptor {
                dimension: Some(wgpu::TextureViewDimension::D2Array),
                ..Default::default()
            })
        };
        let flows_view = match flows {
            Flows::Texture(t) => Some(array(t)),
            Flows::Shared(_) => None,
        };
        let texels_view = texels.map(array);
        let make = || {
            let mut entries = vec![
                entry(0, prelit.page().as_entire_binding()),
                entry(
                    1,
                    match (flows, &flows_view) {
                        (_, Some(view)) => wgpu::BindingResource::TextureView(view),
                        (Flows::Shared(r), None) => r.page().as_entire_binding(),
                        (Flows::Texture(_), None) => unreachable!("made above"),
                    },
                ),
                entry(2, tables.views.as_entire_binding()),
                entry(3, tables.quads.as_entire_binding()),
                entry(4, tables.tables.as_entire_binding()),
                entry(5, tables.proxy.as_entire_binding()),
                entry(6, tables.hull.as_entire_binding()),
                entry(7, tables.index.as_entire_binding()),
                entry(8, wgpu::BindingResource::Sampler(sampler)),
                entry(9, tables.frames.as_entire_binding()),
            ];
            if let Some(view) = &texels_view {
                entries.push(entry(
                    PRELIT_TEXELS_BINDING,
                    wgpu::BindingResource::TextureView(view),
                ));
            }
            self.device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("pose"),
                layout,
                entries: &entries,
            })
        };
        match (flows, texels) {
            (Flows::Shared(f), None) => {
                let pages = (prelit.page_key(), f.page_key());
                let mut groups = tables.groups.lock().unwrap_or_else(|e| e.into_inner());
                let group = match groups.iter().find(|(p, _)| *p == pages) {
                    Some((_, g)) => g.clone(),
                    None => {
                        let g = make();
                        groups.push((pages, g.clone()));
                        g
                    }
                };
                (group, (tables.id, pages.0, pages.1))
            }
            // A texture is the copy's own: so is its bind group.
            _ => (make(), (tables.id, unique_id() as usize, 0)),
        }
    }
}

fn entry(binding: u32, resource: wgpu::BindingResource<'_>) -> wgpu::BindGroupEntry<'_> {
    wgpu::BindGroupEntry { binding, resource }
}
