//! Error against run time of every stage's settings (`frf report`): the rows a sweep
//! measures, the Pareto front of each stage's metric, and the outputs a person reads
//! (plots, [`plot`]; one offline page, [`html`]) beside the JSON a machine reads.
//!
//! A row is one setting of one knob of one stage, scored by one metric: its error against
//! the virtual stage's truth and the seconds it took. Whether lower or higher is better
//! depends on the metric ([`Better`]); a setting is on the Pareto front of its stage and
//! metric when no other setting is both at least as fast and at least as good, and
//! strictly one of them.

pub mod html;
pub mod plot;

use serde::{Deserialize, Serialize};

/// The stages every report of `frf report` measures (peers add their own plot).
pub const STAGES: &[&str] = &[
    "inter-view flow",
    "registration and mattes",
    "flow storage",
    "basis compression",
    "novel views",
    "camera paths",
    "frame size",
    "capture size",
    "renderer",
    "shadows",
    "composite",
    "time between poses",
];

/// Which way a metric improves.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Better {
    /// Errors: EPE, MAE.
    Lower,
    /// Scores: PSNR, SSIM, IoU.
    Higher,
}

impl Better {
    /// The direction of a metric, from its name: PSNR, SSIM and IoU are scores, anything
    /// else (EPE, MAE, differences) an error.
    pub fn of(metric: &str) -> Self {
        let m = metric.to_ascii_lowercase();
        if ["psnr", "ssim", "iou"].iter().any(|s| m.contains(s)) {
            Better::Higher
        } else {
            Better::Lower
        }
    }
}

/// One setting of one knob of one stage, scored by one metric.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Row {
    /// Pipeline stage (`"inter-view flow"`, `"novel views"`, ...).
    pub stage: String,
    /// The knob turned (`"flow preset"`, `"jpeg quality"`, ...).
    pub knob: String,
    /// Its value, as written on the command line.
    pub value: String,
    /// What the error measures, with its unit (`"EPE px"`, `"subject PSNR dB"`).
    pub metric: String,
    /// The error (or score) against the truth.
    pub error: f64,
    /// Run time of this setting, seconds (what was timed is in [`Row::timed`]).
    pub seconds: f64,
    /// What the seconds are (`"per view"`, `"per frame"`, `"ingest of one pose"`).
    pub timed: String,
    /// Whether this is the setting a user gets without asking.
    pub default: bool,
    /// The command that reproduces the measurement.
    pub command: String,
}

/// A peer's point on a stage's plot (e.g. OpenCV's flow methods), read from its own
/// script's output.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PeerPoint {
    /// The stage whose plot it joins.
    pub stage: String,
    /// The metric it is scored by (as the rows of that plot).
    pub metric: String,
    /// Method name.
    pub method: String,
    /// Its error.
    pub error: f64,
    /// Its seconds.
    pub seconds: f64,
}

/// Where the report was measured.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Machine {
    /// Logical CPU cores.
    pub cores: usize,
    /// The GPU adapter the renders ran on (lavapipe is a CPU).
    pub adapter: String,
    /// Operating system and architecture.
    pub os: String,
}

/// A whole report.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Report {
    /// The capture swept.
    pub capture: String,
    /// `git describe` of the source, or "unknown".
    pub commit: String,
    /// Where it ran.
    pub machine: Machine,
    /// The reduced sweep of `--quick`?
    pub quick: bool,
    /// Wall time of the sweep's measurements, seconds (those kept from an interrupted
    /// run included).
    pub seconds_total: f64,
    /// Every measured setting.
    pub rows: Vec<Row>,
    /// Peers' points, where their output was given.
    pub peers: Vec<PeerPoint>,
}

impl Report {
    /// The stages, in the order their rows first appear.
    pub fn stages(&self) -> Vec<&str> {
        let mut out: Vec<&str> = Vec::new();
        for r in &self.rows {
            if !out.contains(&r.stage.as_str()) {
                out.push(&r.stage);
            }
        }
        out
    }

    /// A stage's metrics, in the order they first appear.
    pub fn metrics(&self, stage: &str) -> Vec<&str> {
        let mut out: Vec<&str> = Vec::new();
        for r in self.rows.iter().filter(|r| r.stage == stage) {
            if !out.contains(&r.metric.as_str()) {
                out.push(&r.metric);
            }
        }
        out
    }

    /// The rows of one stage and metric.
    pub fn series(&self, stage: &str, metric: &str) -> Vec<&Row> {
        self.rows
            .iter()
            .filter(|r| r.stage == stage && r.metric == metric)
            .collect()
    }

    /// The problems that make a report incomplete: a stage of `expected` without rows,
    /// or an error or time that is not a finite number. Empty when complete.
    pub fn problems(&self, expected: &[&str]) -> Vec<String> {
        let mut out: Vec<String> = expected
            .iter()
            .filter(|s| !self.rows.iter().any(|r| r.stage == **s))
            .map(|s| format!("stage {s:?} has no rows"))
            .collect();
        for r in &self.rows {
            if !r.error.is_finite() || !r.seconds.is_finite() || r.seconds < 0.0 {
                out.push(format!(
                    "{} / {} = {} / {}: error {} in {} s",
                    r.stage, r.knob, r.value, r.metric, r.error, r.seconds
                ));
            }
        }
        out
    }
}

/// Indices of the rows on the Pareto front (fewer seconds and a better error), in order
/// of increasing seconds.
pub fn pareto_front(rows: &[&Row]) -> Vec<usize> {
    let better = |a: f64, b: f64, dir: Better| match dir {
        Better::Lower => a <= b,
        Better::Higher => a >= b,
    };
    let mut front: Vec<usize> = (0..rows.len())
        .filter(|&i| {
            let (a, dir) = (rows[i], Better::of(&rows[i].metric));
            !rows.iter().enumerate().any(|(j, b)| {
                j != i
                    && b.seconds <= a.seconds
                    && better(b.error, a.error, dir)
                    && (b.seconds < a.seconds || b.error != a.error)
            })
        })
        .collect();
    front.sort_by(|&a, &b| rows[a].seconds.total_cmp(&rows[b].seconds));
    front
}

#[cfg(test)]
mod tests {
    use super::*;

    fn row(metric: &str, value: &str, error: f64, seconds: f64) -> Row {
        Row {
            stage: "s".into(),
            knob: "k".into(),
            value: value.into(),
            metric: metric.into(),
            error,
            seconds,
            timed: "per run".into(),
            default: false,
            command: String::new(),
        }
    }

    #[test]
    fn the_front_keeps_exactly_the_undominated_settings() {
        // Lower is better: b dominates d (faster and better); c is slow but best.
        let rows = [
            row("EPE px", "a", 1.0, 1.0),
            row("EPE px", "b", 0.5, 2.0),
            row("EPE px", "c", 0.2, 9.0),
            row("EPE px", "d", 0.6, 3.0),
            row("EPE px", "e", 1.0, 1.0), // a tie with a: neither dominates
        ];
        let refs: Vec<&Row> = rows.iter().collect();
        assert_eq!(pareto_front(&refs), vec![0, 4, 1, 2]);
        // Higher is better: the same numbers as scores reverse who wins.
        let rows: Vec<Row> = rows
            .iter()
            .map(|r| row("PSNR dB", &r.value, r.error, r.seconds))
            .collect();
        let refs: Vec<&Row> = rows.iter().collect();
        assert_eq!(pareto_front(&refs), vec![0, 4]);
    }

    #[test]
    fn an_incomplete_report_says_what_is_missing() {
        let mut r = Report {
            capture: "c".into(),
            commit: "x".into(),
            machine: Machine {
                cores: 2,
                adapter: "none".into(),
                os: "linux".into(),
            },
            quick: true,
            seconds_total: 1.0,
            rows: vec![row("EPE px", "a", f64::NAN, 1.0)],
            peers: vec![],
        };
        let p = r.problems(&["s", "novel views"]);
        assert_eq!(p.len(), 2, "{p:?}");
        assert!(
            p[0].contains("novel views") && p[1].contains("NaN"),
            "{p:?}"
        );
        r.rows[0].error = 0.5;
        assert!(r.problems(&["s"]).is_empty());
        assert_eq!(Better::of("subject PSNR dB"), Better::Higher);
        assert_eq!(Better::of("alpha IoU"), Better::Higher);
        assert_eq!(Better::of("EPE px"), Better::Lower);
    }

    #[test]
    fn plots_and_the_page_show_every_setting() {
        let mut rows = vec![
            row("EPE px", "fast", 0.9, 0.2),
            row("EPE px", "balanced", 0.5, 1.0),
            row("EPE px", "accurate", 0.45, 6.0),
            row("alpha IoU", "fast", 0.97, 0.2),
        ];
        rows[1].default = true;
        let report = Report {
            capture: "cap<1>".into(),
            commit: "abc".into(),
            machine: Machine {
                cores: 2,
                adapter: "llvmpipe".into(),
                os: "linux x86_64".into(),
            },
            quick: true,
            seconds_total: 12.0,
            rows,
            peers: vec![PeerPoint {
                stage: "s".into(),
                metric: "EPE px".into(),
                method: "Farneback".into(),
                error: 1.2,
                seconds: 0.05,
            }],
        };
        let svg = plot::svg(&report, "s").unwrap();
        for text in [
            "s: EPE px",
            "s: alpha IoU",
            "\nbalanced\n",
            "Farneback",
            "Pareto front",
        ] {
            assert!(svg.contains(text), "the plot lacks {text:?}");
        }
        if let Some(png) = plot::png(&report, "s").unwrap() {
            let img = image::load_from_memory(&png).unwrap();
            assert_eq!((img.width(), img.height()), plot::size(&report, "s"));
        }
        let page = html::page(&report, false);
        assert!(
            page.contains("cap&lt;1&gt;") && page.contains("s.svg"),
            "{page}"
        );
        assert_eq!(page.matches("<tr class=front>").count(), 3 + 1);
        assert_eq!(html::plot_name("novel views (GPU)"), "novel_views_gpu");
    }
}
