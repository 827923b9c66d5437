//! What a field file holds and how well it is compressed: bytes by kind, and the ratios
//! the original reported (docs/design.md section 3.6): flow against its 8-bit quantized size
//! (the original: 34 %), basis images against 16-bit linear RGB (the original: 16:1).

use serde::{Deserialize, Serialize};

use crate::container::{ChunkKind, FieldFile, ReadAt};

/// Bytes of the file by kind of content.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
pub struct Bytes {
    /// Flow maps.
    pub flow: u64,
    /// Basis image mosaics.
    pub images: u64,
    /// Alpha planes.
    pub alpha: u64,
    /// Shadow maps.
    pub shadows: u64,
    /// Visual hulls.
    pub hulls: u64,
    /// Pose-to-pose flow maps.
    #[serde(default)]
    pub pose_flow: u64,
    /// Fitted normals (the sun's relighting).
    #[serde(default)]
    pub normals: u64,
    /// Preamble, index and footer.
    pub other: u64,
}

/// Contents and compression of a field file.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FieldStats {
    /// Bytes by kind.
    pub bytes: Bytes,
    /// Flow bytes as a fraction of the same maps stored as 8-bit codes (2 bytes per
    /// pixel): lower is better.
    pub flow_ratio_vs_8bit: f64,
    /// 16-bit linear RGB size of the basis images (6 bytes per pixel) divided by their
    /// stored size: the compression ratio, higher is better.
    pub image_ratio_vs_16bit: f64,
    /// Poses stored.
    pub poses: usize,
    /// Views per pose.
    pub views: usize,
    /// Flow maps stored.
    pub flow_maps: usize,
    /// Basis images stored.
    pub basis_images: usize,
    /// Shadow attenuation maps stored (one per upper condition of each pose with maps).
    pub shadow_maps: usize,
    /// Visual hulls stored (one per pose).
    pub hulls: usize,
    /// Pose-to-pose flow maps stored.
    #[serde(default)]
    pub pose_flow_maps: usize,
}

impl<R: ReadAt> FieldFile<R> {
    /// Statistics from the index alone (no chunk is read).
    pub fn stats(&self) -> FieldStats {
        let h = self.header();
        let pixels = h.width as u64 * h.height as u64;
        let mut bytes = Bytes::default();
        let (mut flow_maps, mut basis_views, mut shadow_poses, mut hulls, mut pose_flow_maps) =
            (0usize, 0usize, 0usize, 0usize, 0usize);
        for c in self.chunks() {
            match c.key.kind {
                ChunkKind::Flow(_) => {
                    bytes.flow += c.length;
                    flow_maps += 1;
                }
                ChunkKind::Basis => {
                    bytes.images += c.length;
                    basis_views += 1;
                }
                ChunkKind::Alpha => bytes.alpha += c.length,
                ChunkKind::Normals => bytes.normals += c.length,
                ChunkKind::Shadows => {
                    bytes.shadows += c.length;
                    shadow_poses += 1;
                }
                ChunkKind::Hull => {
                    bytes.hulls += c.length;
                    hulls += 1;
                }
                ChunkKind::PoseFlow(_) => {
                    bytes.pose_flow += c.length;
                    pose_flow_maps += 1;
                }
            }
        }
        bytes.other = self.size()
            - (bytes.flow
                + bytes.images
                + bytes.alpha
                + bytes.shadows
                + bytes.hulls
                + bytes.pose_flow
                + bytes.normals);
        let shadow_maps = shadow_poses * h.shadows.as_ref().map_or(0, |s| s.conditions.len());
        let basis_images = basis_views * h.conditions.len();
        let ratio = |num: f64, den: f64| if den > 0.0 { num / den } else { 0.0 };
        FieldStats {
            bytes,
            flow_ratio_vs_8bit: ratio(bytes.flow as f64, (flow_maps as u64 * pixels * 2) as f64),
            image_ratio_vs_16bit: ratio(
                (basis_images as u64 * pixels * 6) as f64,
                bytes.images as f64,
            ),
            poses: h.poses.len(),
            views: h.views_per_pose(),
            flow_maps,
            basis_images,
            shadow_maps,
            hulls,
            pose_flow_maps,
        }
    }

    /// The field for a person, a line each (`frf info`): grid, poses, codecs, bytes by
    /// kind and what each holds.
    pub fn describe(&self) -> String {
        let mut lines = Vec::new();
        let h = self.header();
        let s = self.stats();
        let mb = |b: u64| b as f64 / 1e6;
        lines.push(format!("{}", self.path().display()));
        lines.push(format!("  source: {}", h.description));
        lines.push(format!(
            "  grid: {} x {} views ({}), {}x{} pixels, {} basis conditions ({} floor)",
            h.columns,
            h.rows,
            if h.wraps { "closed ring" } else { "open" },
            h.width,
            h.height,
            h.conditions.len(),
            h.conditions.iter().filter(|c| c.floor).count()
        ));
        lines.push(format!(
            "  poses: {:?}",
            h.poses.iter().map(|p| p.pose).collect::<Vec<_>>()
        ));
        for p in &h.poses {
            lines.push(format!(
                "  pose {}: flow log quantizer s = {:.4} px, M = {:.2} px",
                p.pose, p.flow_quantizer.scale, p.flow_quantizer.range
            ));
        }
        let predicted = if h.flow_predicted {
            "predicted from neighbours"
        } else {
            "not predicted"
        };
        lines.push(format!("  flow codes: {predicted}"));
        lines.push(format!("  JPEG quality: {}", h.jpeg_quality));
        lines.push("  bytes by kind (MB):".to_string());
        for (kind, b) in [
            ("basis images", s.bytes.images),
            ("flow maps", s.bytes.flow),
            ("pose flow maps", s.bytes.pose_flow),
            ("alpha", s.bytes.alpha),
            ("shadow maps", s.bytes.shadows),
            ("visual hulls", s.bytes.hulls),
            ("fitted normals", s.bytes.normals),
            ("index and framing", s.bytes.other),
        ] {
            lines.push(format!("    {kind:<18} {:>10.3}", mb(b)));
        }
        lines.push(format!(
            "  flow: {} maps, {:.1} % of their 8-bit quantized size",
            s.flow_maps,
            100.0 * s.flow_ratio_vs_8bit
        ));
        lines.push(format!(
            "  pose-to-pose flow: {} maps (to the next and the previous captured pose of each view)",
            s.pose_flow_maps
        ));
        lines.push(format!(
            "  basis images: {} images, {:.1}:1 against 16-bit linear RGB",
            s.basis_images, s.image_ratio_vs_16bit
        ));
        match &h.shadows {
            Some(spec) => lines.push(format!(
                "  shadows: {} maps ({} conditions per pose), {} x {} texels over {} m x {} m",
                s.shadow_maps,
                spec.conditions.len(),
                spec.ground.texels,
                spec.ground.texels,
                spec.ground.extent_m,
                spec.ground.extent_m
            )),
            None => lines.push("  shadows: none".to_string()),
        }
        match &h.hulls {
            Some(spec) => lines.push(format!(
                "  visual hulls: {} ({} m voxels, {} views may disagree)",
                s.hulls, spec.voxel_m, spec.misses
            )),
            None => lines.push("  visual hulls: none".to_string()),
        }
        lines.join("\n")
    }
}
