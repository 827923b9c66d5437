//! A pose's geometry as both renderers see it, computed once when the pose is loaded and
//! shared by its source, its CPU-resident form and its GPU upload: the grid, the crop,
//! the cameras (subject frame), the cylinder of their centres, the geometric proxy of
//! the subject ([`Proxy`]), and where each stored flow lives in the flow texture array.
//!
//! - **Crop.** Everything is cropped to the union of the views' mattes (grown by
//!   [`CROP_MARGIN_PX`], beyond the flows' margin): outside it every view is transparent
//!   black, so nothing is lost, and at the original's size about half the pixels go.

use frf_core::camera::Camera;
use frf_core::grid::Neighbour;
use frf_core::image::GrayImage;
use glam::Vec3;

use crate::cylinder::{Cylinder, CylinderHit};
use crate::footprint::SubjectBounds;
use crate::proxy::Proxy;
use crate::rectified::QuadFrame;
use frf_shaders::types::{GpuQuad, GpuView};

/// Pixels kept around the union of the mattes (the flows reach 3 beyond them).
pub const CROP_MARGIN_PX: u32 = 4;

/// Bytes of the decoding tables a resident pose carries (sRGB and flow: 2 x 256 f32).
const TABLE_BYTES: u64 = 2 * 256 * 4;

/// A rectangle of the full image, pixels.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Crop {
    /// Left column.
    pub x0: u32,
    /// Top row.
    pub y0: u32,
    /// Width.
    pub width: u32,
    /// Height.
    pub height: u32,
}

impl Crop {
    /// The union of the non-zero pixels of `alphas` (full images of `size`), grown by
    /// [`CROP_MARGIN_PX`]; one pixel when every alpha is zero.
    pub fn of_mattes(alphas: &[GrayImage], size: (u32, u32)) -> Self {
        Self::of_covered(
            alphas
                .iter()
                .map(|a| (a.width(), a.pixels().iter().map(|&v| v > 0.0))),
            size,
        )
    }

    /// [`Crop::of_mattes`] of 8-bit alpha codes (full images of `size`; an empty one
    /// covers nothing).
    pub fn of_alpha_codes(alphas: &[&[u8]], size: (u32, u32)) -> Self {
        Self::of_covered(
            alphas
                .iter()
                .map(|a| (size.0 as usize, a.iter().map(|&v| v > 0))),
            size,
        )
    }

    /// The union of the covered pixels of images (row length, and per pixel whether it
    /// is covered), grown by [`CROP_MARGIN_PX`] within `size`.
    fn of_covered<I: Iterator<Item = bool>>(
        images: impl Iterator<Item = (usize, I)>,
        size: (u32, u32),
    ) -> Self {
        let (mut x0, mut y0, mut x1, mut y1) = (u32::MAX, u32::MAX, 0u32, 0u32);
        for (width, covered) in images {
            for (i, c) in covered.enumerate() {
                if c {
                    let (x, y) = ((i % width) as u32, (i / width) as u32);
                    x0 = x0.min(x);
                    y0 = y0.min(y);
                    x1 = x1.max(x);
                    y1 = y1.max(y);
                }
            }
        }
        if x0 > x1 {
            return Self {
                x0: 0,
                y0: 0,
                width: 1,
                height: 1,
            };
        }
        let x0 = x0.saturating_sub(CROP_MARGIN_PX);
        let y0 = y0.saturating_sub(CROP_MARGIN_PX);
        let x1 = (x1 + CROP_MARGIN_PX).min(size.0 - 1);
        let y1 = (y1 + CROP_MARGIN_PX).min(size.1 - 1);
        Self {
            x0,
            y0,
            width: x1 - x0 + 1,
            height: y1 - y0 + 1,
        }
    }

    /// Texels in the crop.
    pub fn texels(&self) -> usize {
        self.width as usize * self.height as usize
    }

    /// The pixel `(x, y)` of the full image that texel `k` of the crop (row by row) is.
    pub fn pixel(&self, k: usize) -> (usize, usize) {
        (
            self.x0 as usize + k % self.width as usize,
            self.y0 as usize + k / self.width as usize,
        )
    }

    /// The crop's rows of a full image of row length `full_width`.
    pub fn rows_of<T: Copy>(&self, data: &[T], full_width: usize) -> Vec<T> {
        let mut out = Vec::with_capacity(self.texels());
        for y in self.y0..self.y0 + self.height {
            let row = y as usize * full_width;
            out.extend_from_slice(
                &data[row + self.x0 as usize..row + (self.x0 + self.width) as usize],
            );
        }
        out
    }
}

/// One pose's geometry (see the module docs).
#[derive(Debug, Clone)]
pub struct PoseGeometry {
    /// Pose index.
    pub pose: u32,
    /// Grid columns.
    pub columns: usize,
    /// Grid rows.
    pub rows: usize,
    /// Whether columns close into a ring.
    pub wraps: bool,
    /// Full image size.
    pub image_size: (u32, u32),
    /// The crop.
    pub crop: Crop,
    /// Cameras (subject frame), `u`-major.
    pub cameras: Vec<Camera>,
    /// The cylinder of the cameras' centres.
    pub cylinder: Cylinder,
    /// Per quad `(u, v)` of the grid (`u`-major, [`PoseGeometry::frame_rows`] per
    /// column): its rectified frame, `None` where its centres span no plane.
    pub frames: Vec<Option<QuadFrame>>,
    /// Per view, the layer of its flow toward each neighbour ([`Neighbour::ALL`] order)
    /// in the pose's flow array; `-1` where none is stored.
    pub flow_layers: Vec<[i32; 4]>,
    /// Stored flows (layers of the flow array).
    pub flow_layer_count: usize,
    /// Per view, its layer in the pose's pre-lit array; `-1` for a view not held (one a
    /// plan left out: transparent, and no memory spent on it).
    pub prelit_layers: Vec<i32>,
    /// Held views (layers of the pre-lit array).
    pub prelit_layer_count: usize,
    /// Where rays beyond the grid's rows meet the subject.
    pub proxy: Proxy,
    /// Where the subject can show: a ray that misses these bounds shows nothing of it.
    pub bounds: SubjectBounds,
    /// The level of detail its views were read at ([`crate::detail`]; 0: as captured).
    pub level: u8,
}

impl PoseGeometry {
    /// The geometry of a `columns x rows` grid of `cameras` whose stored flows are those
    /// for which `has_flow(view, neighbour)` holds.
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        pose: u32,
        columns: usize,
        rows: usize,
        wraps: bool,
        image_size: (u32, u32),
        crop: Crop,
        cameras: Vec<Camera>,
        has_flow: impl Fn(usize, Neighbour) -> bool,
    ) -> Self {
        let centres: Vec<Vec3> = cameras.iter().map(|c| c.centre()).collect();
        let cameras_len = cameras.len();
        let cylinder = Cylinder::new(&centres, columns, rows, wraps);
        let frame_rows = rows.saturating_sub(1).max(1);
        let view = |u: usize, v: usize| (u % columns) * rows + v.min(rows - 1);
        let frames = (0..columns * frame_rows)
            .map(|i| {
                let (u, v) = (i / frame_rows, i % frame_rows);
                let top = if rows > 1 { v + 1 } else { v };
                let at = |u, v| &cameras[view(u, v)];
                QuadFrame::new([at(u, v), at(u + 1, v), at(u, top), at(u + 1, top)])
            })
            .collect();
        let mut next = 0i32;
        let flow_layers = (0..cameras.len())
            .map(|i| {
                let mut layers = [-1i32; 4];
                for n in Neighbour::ALL {
                    if has_flow(i, n) {
                        layers[n.index()] = next;
                        next += 1;
                    }
                }
                layers
            })
            .collect();
        Self {
            pose,
            columns,
            rows,
            wraps,
            image_size,
            crop,
            cameras,
            cylinder,
            frames,
            flow_layers,
            flow_layer_count: next as usize,
            prelit_layers: (0..cameras_len as i32).collect(),
            prelit_layer_count: cameras_len,
            proxy: Proxy::default(),
            bounds: SubjectBounds::DESIGN,
            level: 0,
        }
    }

    /// The same geometry of views read at level of detail `level` (its `image_size`,
    /// `crop` and `cameras` already those of the reduced views).
    pub fn at_level(mut self, level: u8) -> Self {
        self.level = level;
        self
    }

    /// The same geometry holding only the views for which `held(view)` holds (the
    /// others are transparent and have no pre-lit layer).
    pub fn with_held(mut self, held: impl Fn(usize) -> bool) -> Self {
        let mut next = 0i32;
        for (i, layer) in self.prelit_layers.iter_mut().enumerate() {
            *layer = if held(i) {
                next += 1;
                next - 1
            } else {
                -1
            };
        }
        self.prelit_layer_count = next as usize;
        self
    }

    /// Whether view `i` is held (has a pre-lit layer).
    pub fn holds(&self, i: usize) -> bool {
        self.prelit_layers[i] >= 0
    }

    /// The same geometry with its subject within `bounds`.
    pub fn with_bounds(mut self, bounds: SubjectBounds) -> Self {
        self.bounds = bounds;
        self
    }

    /// The same geometry with `proxy` as its geometric proxy.
    pub fn with_proxy(mut self, proxy: Proxy) -> Self {
        self.proxy = proxy;
        self
    }

    /// Rows of quads per column of [`PoseGeometry::frames`]: the gaps between rows, or
    /// one for a grid of one row.
    pub fn frame_rows(&self) -> usize {
        self.rows.saturating_sub(1).max(1)
    }

    /// The rectified frame of the quad a hit lies in (rays clamped to a row: the quad of
    /// that row).
    pub fn quad_frame(&self, hit: &CylinderHit) -> Option<&QuadFrame> {
        let i = (hit.u % self.columns) * self.frame_rows() + hit.v.min(self.frame_rows() - 1);
        self.frames.get(i)?.as_ref()
    }

    /// Views in the grid.
    pub fn views(&self) -> usize {
        self.columns * self.rows
    }

    /// Index of view `(u, v)` (`u` taken modulo the columns, `v` clamped to the rows).
    pub fn view(&self, u: usize, v: usize) -> usize {
        (u % self.columns) * self.rows + v.min(self.rows - 1)
    }

    /// Bytes the pose holds where it is rendered, on the GPU or in the CPU's copy (the
    /// same layout): pre-lit RGBA8 texels per held view (at least one layer), RG8 flow codes per stored flow (at
    /// least one layer), the view and quad tables, the cylinder's column index, the
    /// decoding tables and the proxy.
    pub fn resident_bytes(&self) -> u64 {
        let texels = self.crop.texels() as u64;
        // Counted, not made: a crowd's relights ask every frame.
        let quads = self.cylinder.quad_count() as u64;
        texels
            * (4 * self.prelit_layer_count.max(1) as u64 + 2 * self.flow_layer_count.max(1) as u64)
            + self.views() as u64 * std::mem::size_of::<GpuView>() as u64
            + quads * std::mem::size_of::<GpuQuad>() as u64
            + self.cylinder.column_index_gpu_bytes() as u64
            + TABLE_BYTES
            + self.proxy.resident_bytes()
    }
}
