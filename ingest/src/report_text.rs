//! An ingest's report for a person ([`IngestReport::describe`]): what was written, the
//! time per step, and the errors against the virtual stage's truth where it was measured.

use std::path::Path;

use crate::pipeline::IngestReport;

impl IngestReport {
    /// The report for a person, a line each, of a field written to `out`.
    pub fn describe(&self, out: &Path) -> String {
        let r = self;
        let mut lines = Vec::new();

        lines.push(format!(
            "field written to {}: {} poses of {} views, {}x{} pixels, flow {}, edges {}",
            out.display(),
            r.poses.len(),
            r.views,
            r.width,
            r.height,
            r.settings.flow_preset,
            r.settings.edge
        ));
        let resumed = r.poses.iter().filter(|p| p.resumed).count();
        if resumed > 0 {
            lines.push(format!(
            "  {resumed} poses were already finished and resumed; their time is not counted below"
        ));
        }
        lines.push("  time per step (wall seconds, all poses of this run):".to_string());
        for s in &r.steps {
            lines.push(format!("    {:<36} {:>8.1}", s.name, s.seconds));
        }
        lines.push(format!("  whole run: {:.1} s wall", r.seconds));
        let f = |v: Option<f64>, unit: &str, digits: usize| match v {
            Some(v) => format!("{v:.digits$}{unit}"),
            None => "not measured (no stage truth, --no-eval, or nothing to measure at this size)"
                .into(),
        };
        lines.push("  against the virtual stage's truth:".to_string());
        let pair = |after: Option<f64>, before: Option<f64>| match (after, before) {
            (Some(a), Some(b)) => format!("{a:.4} ({b:.4} before edge decontamination)"),
            _ => f(after, "", 4),
        };
        let mut rows = vec![
            ("alpha IoU", f(r.alpha_iou, "", 4)),
            ("alpha mean absolute error", f(r.alpha_mae, "", 4)),
            (
                "registered basis PSNR (subject)",
                f(r.registration_psnr, " dB", 2),
            ),
            ("same frames unregistered", f(r.unregistered_psnr, " dB", 2)),
            (
                "edge band error over black",
                pair(r.edge_band_error_dark, r.edge_band_error_dark_raw),
            ),
            (
                "edge band error over bright",
                pair(r.edge_band_error_bright, r.edge_band_error_bright_raw),
            ),
            (
                "flow EPE inside matte, horizontal",
                f(r.flow_epe_horizontal, " px", 3),
            ),
            (
                "flow EPE inside matte, vertical",
                f(r.flow_epe_vertical, " px", 3),
            ),
        ];
        if r.settings.pose_flows {
            rows.push((
                "flow EPE inside matte, pose to pose",
                match (r.pose_flow_epe, r.pose_flow_motion) {
                    (Some(e), Some(m)) => format!("{e:.3} px (the true motion: {m:.3} px)"),
                    (e, _) => f(e, " px", 3),
                },
            ));
        }
        rows.push(("visual hull IoU (voxels)", f(r.hull_iou, "", 4)));
        for (label, value) in rows {
            lines.push(format!("    {label:<36}{value}"));
        }
        lines.push(format!(
            "  field: flow {:.1} % of 8-bit codes, basis images {:.1}:1 vs 16-bit linear, {:.2} MB",
            100.0 * r.field.flow_ratio_vs_8bit,
            r.field.image_ratio_vs_16bit,
            (r.field.bytes.flow
                + r.field.bytes.images
                + r.field.bytes.alpha
                + r.field.bytes.shadows
                + r.field.bytes.hulls
                + r.field.bytes.other) as f64
                / 1e6
        ));
        lines.join("\n")
    }
}
