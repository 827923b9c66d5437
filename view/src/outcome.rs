//! What a viewer session measured, for a person ([`Outcome::summary`]) and as JSON
//! ([`Outcome::json`]): frames drawn, GPU time and time between frames (medians), poses
//! made resident, screenshots and the recorded move.

use crate::{Ended, Outcome};

/// The median of `v`, `None` when empty.
fn median(v: &[f64]) -> Option<f64> {
    let mut s = v.to_vec();
    s.sort_by(f64::total_cmp);
    s.get(s.len() / 2).copied()
}

impl Outcome {
    /// The session for a person, a line each.
    pub fn summary(&self) -> Vec<String> {
        let mut lines = Vec::new();
        let gpu = median(&self.gpu_ms);
        let frame = median(&self.frame_ms);
        lines.push(format!(
        "frf view: {}. {} frames drawn on {}; GPU time per frame {} (timestamps); time between frames {} ({})",
        match self.ended {
            Ended::Quit => "closed",
            Ended::WindowClosed => "the window was closed",
        },
        self.frames,
        self.adapter,
        gpu.map_or("n/a".into(), |ms| format!("{ms:.2} ms median")),
        frame.map_or("n/a".into(), |ms| format!("{ms:.1} ms median")),
        frame.map_or("n/a".into(), |ms| format!("{:.1} fps", 1e3 / ms)),
    ));
        let (made, seconds) = self.residency;
        if made > 0 {
            lines.push(format!(
                "  poses made resident (read and relit for a light): {made}, {:.2} s each",
                seconds / made as f64
            ));
        }
        for s in &self.screenshots {
            lines.push(format!("  wrote {}", s.display()));
        }
        if let Some((path, keys, note)) = &self.recorded {
            lines.push(format!(
                "  recorded {keys} camera keys to {}: `frf render {} --out DIR` renders the move",
                path.display(),
                path.display()
            ));
            if let Some(n) = note {
                lines.push(format!("  note: {n}"));
            }
        }
        lines
    }

    /// The session as JSON (pretty).
    pub fn json(&self) -> String {
        let gpu = median(&self.gpu_ms);
        let frame = median(&self.frame_ms);
        let (made, seconds) = self.residency;
        let report = serde_json::json!({
            "ended": format!("{:?}", self.ended),
            "adapter": self.adapter,
            "frames": self.frames,
            "gpu_ms_median": gpu,
            "gpu_ms": self.gpu_ms,
            "frame_ms_median": frame,
            "fps_median": frame.map(|ms| 1e3 / ms),
            "screenshots": self.screenshots.iter().map(|p| p.display().to_string()).collect::<Vec<_>>(),
            "recorded": self.recorded.as_ref().map(|r| r.0.display().to_string()),
            "poses_made_resident": made,
            "residency_seconds": seconds,
        });
        serde_json::to_string_pretty(&report).unwrap_or_default()
    }
}
