//! Whole views and poses in and out of a field file: encoding a [`ViewData`] into its
//! chunks (basis mosaic, alpha, one flow map per neighbour; pure, so views can be
//! encoded in parallel and written in order), and reading one view back from only its
//! own chunks.

use std::sync::{Arc, Weak};

use frf_core::grid::{Neighbour, PoseStep};
use frf_core::image::{FlowImage, GrayImage, RgbImage};

use crate::container::{ChunkKey, ChunkKind, FieldFile, FieldWriter, ReadAt, SharedHulls};
use crate::error::{ReflectanceError, Result};
use crate::field::{FieldHeader, ViewData};
use crate::flowcodec;
use crate::hull::VoxelHull;
use crate::imagecodec::{
    BasisCodes, decode_basis, decode_basis_codes, decode_planes, encode_basis, encode_planes,
};
use crate::light_fit::LightFit;
use crate::normalcodec::{decode_normal_codes, encode_normals, normal_of};

/// The encoded chunks of one view.
#[derive(Debug, Clone)]
pub struct EncodedView(Vec<(ChunkKind, Vec<u8>)>);

impl EncodedView {
    /// Appends another encoding's chunks (of the same view).
    pub fn extend(&mut self, other: EncodedView) {
        self.0.extend(other.0);
    }

    /// Total encoded bytes.
    pub fn bytes(&self) -> usize {
        self.0.iter().map(|c| c.1.len()).sum()
    }
}

fn check_size<P: Copy>(
    header: &FieldHeader,
    what: &str,
    w: usize,
    h: usize,
    img: &frf_core::image::Image<P>,
) -> Result<()> {
    if img.size() != (w, h) {
        return Err(ReflectanceError::Mismatch {
            what: what.into(),
            expected: format!("{}x{}", header.width, header.height),
            got: format!("{}x{}", img.width(), img.height()),
        });
    }
    Ok(())
}

/// Encodes a view's basis images and alpha with the header's codec parameters.
pub fn encode_images(
    header: &FieldHeader,
    basis: &[RgbImage],
    alpha: &GrayImage,
) -> Result<EncodedView> {
    let (w, h) = (header.width as usize, header.height as usize);
    if basis.len() != header.conditions.len() {
        return Err(ReflectanceError::Mismatch {
            what: "basis images per view".into(),
            expected: header.conditions.len().to_string(),
            got: basis.len().to_string(),
        });
    }
    for b in basis {
        check_size(header, "basis image", w, h, b)?;
    }
    check_size(header, "alpha", w, h, alpha)?;
    let mut chunks = vec![
        (ChunkKind::Basis, encode_basis(basis, header.jpeg_quality)?),
        (
            ChunkKind::Alpha,
            encode_planes(std::slice::from_ref(alpha))?,
        ),
    ];
    // Three lights at least fix a normal; a basis of fewer (a ring of photographs)
    // cannot be relit beyond itself.
    if header.conditions.len() >= FIT_CONDITIONS {
        let fit = LightFit::of_basis(basis, &header.conditions, alpha);
        chunks.push((ChunkKind::Normals, encode_normals(w, h, &fit.normals())?));
    }
    Ok(EncodedView(chunks))
}

/// Conditions a basis needs for its views' normals to be fitted and stored.
pub const FIT_CONDITIONS: usize = 3;

/// Encodes the flows present among `flows` as chunks of their kinds, with pose `pose`'s
/// quantizer.
fn encode_flow_chunks<'a>(
    header: &FieldHeader,
    pose: u32,
    flows: impl Iterator<Item = (ChunkKind, &'a Option<FlowImage>)>,
) -> Result<EncodedView> {
    let quantizer = header.pose(pose)?.flow_quantizer;
    let (w, h) = (header.width as usize, header.height as usize);
    let mut chunks = Vec::new();
    for (kind, flow) in flows {
        if let Some(flow) = flow {
            check_size(header, "flow", w, h, flow)?;
            chunks.push((
                kind,
                flowcodec::encode(flow, &quantizer, header.flow_predicted)?,
            ));
        }
    }
    Ok(EncodedView(chunks))
}

/// Encodes a view's flows (in [`Neighbour::ALL`] order) with pose `pose`'s quantizer.
pub fn encode_flows(
    header: &FieldHeader,
    pose: u32,
    flows: &[Option<FlowImage>; 4],
) -> Result<EncodedView> {
    let kinds = Neighbour::ALL.iter().map(|&n| ChunkKind::Flow(n));
    encode_flow_chunks(header, pose, kinds.zip(flows))
}

/// Encodes a view's pose-to-pose flows (in [`PoseStep::ALL`] order) with pose `pose`'s
/// quantizer.
pub fn encode_pose_flows(
    header: &FieldHeader,
    pose: u32,
    flows: &[Option<FlowImage>; 2],
) -> Result<EncodedView> {
    let kinds = PoseStep::ALL.iter().map(|&s| ChunkKind::PoseFlow(s));
    encode_flow_chunks(header, pose, kinds.zip(flows))
}

/// Encodes one view of pose `pose` with the header's codec parameters.
pub fn encode_view(header: &FieldHeader, pose: u32, view: &ViewData) -> Result<EncodedView> {
    let mut e = encode_images(header, &view.basis, &view.alpha)?;
    e.0.extend(encode_flows(header, pose, &view.flows)?.0);
    Ok(e)
}

impl FieldWriter {
    /// Writes an encoded view of pose `pose` at `(u, v)`.
    pub fn add_view(&mut self, pose: u32, u: usize, v: usize, view: &EncodedView) -> Result<()> {
        self.header()
            .pose(pose)
            .map_err(|e| naming(self.path(), e))?;
        for (kind, bytes) in &view.0 {
            let key = ChunkKey {
                pose,
                u: u as u32,
                v: v as u32,
                kind: *kind,
            };
            self.add_chunk(key, bytes)?;
        }
        Ok(())
    }

    /// Writes the shadow attenuation maps of a pose (one per condition of the header's
    /// shadow spec).
    pub fn add_shadows(&mut self, pose: u32, maps: &[GrayImage]) -> Result<()> {
        let spec =
            self.header().shadows.clone().ok_or_else(|| {
                ReflectanceError::Misuse("the header declares no shadow maps".into())
            })?;
        if maps.len() != spec.conditions.len() {
            return Err(ReflectanceError::Mismatch {
                what: "shadow maps".into(),
                expected: spec.conditions.len().to_string(),
                got: maps.len().to_string(),
            });
        }
        let key = ChunkKey {
            pose,
            u: 0,
            v: 0,
            kind: ChunkKind::Shadows,
        };
        self.add_chunk(key, &encode_planes(maps)?)
    }
}

impl FieldWriter {
    /// Writes the visual hull of a pose.
    pub fn add_hull(&mut self, pose: u32, hull: &VoxelHull) -> Result<()> {
        self.header().pose(pose)?;
        if self.header().hulls.is_none() {
            return Err(ReflectanceError::Misuse(
                "the header declares no visual hulls".into(),
            ));
        }
        self.add_chunk(key(pose, 0, 0, ChunkKind::Hull), &hull.encode()?)
    }
}

/// `e` with the field file `path` in front of its message, where it is the caller's
/// fault (other errors name their file already).
fn naming(path: &std::path::Path, e: ReflectanceError) -> ReflectanceError {
    match e {
        ReflectanceError::NoSuchPose {
            file: None,
            within,
            pose,
            held,
        } => ReflectanceError::NoSuchPose {
            file: Some(path.to_path_buf()),
            within,
            pose,
            held,
        },
        other => other,
    }
}

fn key(pose: u32, u: usize, v: usize, kind: ChunkKind) -> ChunkKey {
    ChunkKey {
        pose,
        u: u as u32,
        v: v as u32,
        kind,
    }
}

impl<R: ReadAt> FieldFile<R> {
    /// The basis images of a view, linear.
    pub fn basis(&self, pose: u32, u: usize, v: usize) -> Result<Vec<RgbImage>> {
        let k = key(pose, u, v, ChunkKind::Basis);
        let images = self.decode_chunk(&k, decode_basis)?;
        let (w, h) = (self.header().width as usize, self.header().height as usize);
        if images.len() != self.header().conditions.len()
            || images.iter().any(|i| i.size() != (w, h))
        {
            return Err(self.chunk_error(&k, "images of the wrong size or count".into()));
        }
        Ok(images)
    }

    /// The basis images of a view as their mosaic's 8-bit codes and tile scales (what a
    /// GPU relights from).
    pub fn basis_codes(&self, pose: u32, u: usize, v: usize) -> Result<BasisCodes> {
        Ok((*self.basis_codes_shared(pose, u, v)?).clone())
    }

    /// [`FieldFile::basis_codes`], shared: kept decoded within the budget
    /// [`FieldFile::keep_decoded`] sets, so that a view read again is not decoded again.
    pub fn basis_codes_shared(
        &self,
        pose: u32,
        u: usize,
        v: usize,
    ) -> Result<std::sync::Arc<BasisCodes>> {
        let k = key(pose, u, v, ChunkKind::Basis);
        self.decoded.get_or(k, || {
            let codes = self.decode_chunk(&k, decode_basis_codes)?;
            let (w, h) = (self.header().width as usize, self.header().height as usize);
            if codes.tiles.len() != self.header().conditions.len()
                || (codes.width, codes.height) != (w, h)
            {
                return Err(self.chunk_error(&k, "images of the wrong size or count".into()));
            }
            Ok(codes)
        })
    }

    /// The projector of the field's conditions ([`crate::project::Projector`]: environments to
    /// relighting coefficients), made once and shared by every pose relit.
    pub fn projector(&self) -> Result<&crate::project::Projector> {
        Ok(self.projector_shared()?)
    }

    /// [`FieldFile::projector`], to keep (what a [`crate::yaw_table::YawTable`] holds).
    pub fn projector_shared(&self) -> Result<&std::sync::Arc<crate::project::Projector>> {
        if let Some(p) = self.projector.get() {
            return Ok(p);
        }
        let made = std::sync::Arc::new(crate::project::Projector::new(&self.header().conditions)?);
        Ok(self.projector.get_or_init(|| made))
    }

    /// Keeps up to `bytes` of views' decoded basis images between reads (0, the default:
    /// none), the least recently used leaving first.
    pub fn keep_decoded(&self, bytes: u64) {
        self.decoded.set_budget(bytes);
    }

    /// Basis reads served from views kept decoded, and decodes made, so far.
    pub fn decoded_counts(&self) -> (u64, u64) {
        self.decoded.counts()
    }

    /// The alpha of a view.
    pub fn alpha(&self, pose: u32, u: usize, v: usize) -> Result<GrayImage> {
        let k = key(pose, u, v, ChunkKind::Alpha);
        let mut planes = self.decode_chunk(&k, decode_planes)?;
        let (w, h) = (self.header().width as usize, self.header().height as usize);
        match planes.pop() {
            Some(a) if planes.is_empty() && a.size() == (w, h) => Ok(a),
            _ => Err(self.chunk_error(&k, "not one plane of the field's size".into())),
        }
    }

    /// The octahedral codes of a view's fitted normals ([`crate::normalcodec`]), `None`
    /// where the field holds none (written before them, or of too few conditions).
    pub fn normal_codes(&self, pose: u32, u: usize, v: usize) -> Result<Option<Vec<[u8; 2]>>> {
        let k = key(pose, u, v, ChunkKind::Normals);
        if !self.has(&k) {
            return Ok(None);
        }
        let (w, h, codes) = self.decode_chunk(&k, decode_normal_codes)?;
        if (w, h) != (self.header().width as usize, self.header().height as usize) {
            return Err(self.chunk_error(&k, format!("normals of {w}x{h} texels")));
        }
        Ok(Some(codes))
    }

    /// A view's fitted normals (dome frame of its turntable angle), `None` where the
    /// field holds none.
    pub fn normals(
        &self,
        pose: u32,
        u: usize,
        v: usize,
    ) -> Result<Option<Vec<Option<glam::Vec3>>>> {
        Ok(self
            .normal_codes(pose, u, v)?
            .map(|c| c.into_iter().map(normal_of).collect()))
    }

    /// The 8-bit log codes (two planes, `u` then `v`) of the flow from a view to a
    /// neighbour, `None` where the neighbour does not exist.
    pub fn flow_codes(
        &self,
        pose: u32,
        u: usize,
        v: usize,
        n: Neighbour,
    ) -> Result<Option<Vec<i8>>> {
        self.flow_codes_of(key(pose, u, v, ChunkKind::Flow(n)))
    }

    /// The 8-bit log codes of the flow chunk `k`, `None` where the field lacks it.
    fn flow_codes_of(&self, k: ChunkKey) -> Result<Option<Vec<i8>>> {
        if !self.has(&k) {
            return Ok(None);
        }
        let (w, h, codes) = self.decode_chunk(&k, flowcodec::decode_codes)?;
        if (w, h) != (self.header().width as usize, self.header().height as usize) {
            return Err(self.chunk_error(&k, format!("flow map is {w}x{h}")));
        }
        Ok(Some(codes))
    }

    /// The flow from a view to a neighbour, `None` where the neighbour does not exist.
    pub fn flow(&self, pose: u32, u: usize, v: usize, n: Neighbour) -> Result<Option<FlowImage>> {
        let (w, h) = (self.header().width as usize, self.header().height as usize);
        let quantizer = self.header().pose(pose)?.flow_quantizer;
        self.flow_codes(pose, u, v, n)?
            .map(|codes| flowcodec::dequantize(w, h, &codes, &quantizer))
            .transpose()
    }

    /// The flow from a view to the same camera's view of the next or previous captured
    /// pose ([`PoseStep::of`]), `None` where the field holds none.
    pub fn pose_flow(
        &self,
        pose: u32,
        u: usize,
        v: usize,
        step: PoseStep,
    ) -> Result<Option<FlowImage>> {
        let (w, h) = (self.header().width as usize, self.header().height as usize);
        let quantizer = self.header().pose(pose)?.flow_quantizer;
        self.flow_codes_of(key(pose, u, v, ChunkKind::PoseFlow(step)))?
            .map(|codes| flowcodec::dequantize(w, h, &codes, &quantizer))
            .transpose()
    }

    /// Everything of one view, read from that view's chunks only.
    pub fn view(&self, pose: u32, u: usize, v: usize) -> Result<ViewData> {
        self.header()
            .pose(pose)
            .map_err(|e| naming(self.path(), e))?;
        let (columns, rows) = (self.header().columns, self.header().rows);
        if u >= columns || v >= rows {
            return Err(ReflectanceError::Missing {
                file: self.path().to_path_buf(),
                what: format!(
                    "view ({u}, {v}) is outside the field's {columns}x{rows} grid \
                     (u < {columns}, v < {rows})"
                ),
            });
        }
        let mut flows: [Option<FlowImage>; 4] = Default::default();
        for n in Neighbour::ALL {
            flows[n.index()] = self.flow(pose, u, v, n)?;
        }
        Ok(ViewData {
            basis: self.basis(pose, u, v)?,
            alpha: self.alpha(pose, u, v)?,
            flows,
        })
    }

    /// The shadow maps of a pose, if stored.
    pub fn shadows(&self, pose: u32) -> Result<Option<Vec<GrayImage>>> {
        let k = key(pose, 0, 0, ChunkKind::Shadows);
        if !self.has(&k) {
            return Ok(None);
        }
        self.decode_chunk(&k, decode_planes).map(Some)
    }

    /// The visual hull of a pose, if stored.
    pub fn hull(&self, pose: u32) -> Result<Option<VoxelHull>> {
        let k = key(pose, 0, 0, ChunkKind::Hull);
        if !self.has(&k) {
            return Ok(None);
        }
        self.decode_chunk(&k, VoxelHull::decode).map(Some)
    }

    /// [`FieldFile::hull`], shared: while one copy of a pose's hull is held (by a walker
    /// drawing the pose, say), every other reader gets that copy instead of decoding its
    /// own (the walkers of a crowd read one pose's hull once, and the GPU, which keys its
    /// uploads by the copy, uploads it once).
    pub fn hull_shared(&self, pose: u32) -> Result<Option<Arc<VoxelHull>>> {
        let held = |hulls: &SharedHulls| hulls.lock().ok()?.get(&pose)?.upgrade();
        if let Some(h) = held(&self.hulls) {
            return Ok(Some(h));
        }
        let Some(made) = self.hull(pose)?.map(Arc::new) else {
            return Ok(None);
        };
        let mut hulls = self.hulls.lock().unwrap_or_else(|e| e.into_inner());
        hulls.retain(|_, h| h.strong_count() > 0);
        // Another reader may have decoded it meanwhile: keep theirs.
        let kept = hulls.get(&pose).and_then(Weak::upgrade);
        let h = kept.unwrap_or_else(|| {
            hulls.insert(pose, Arc::downgrade(&made));
            made
        });
        Ok(Some(h))
    }
}
