//! What a report writes, and what it reads besides its runs: `report.json`, the plots
//! and the page; the peer script's JSON; the commit.

use std::collections::BTreeMap;
use std::path::Path;
use std::process::Command;

use crate::report::{PeerPoint, Report, Row, html, plot};
use serde::Deserialize;

use crate::error::{EvalError, Result};

/// The peer script's JSON (`benches/flow_peers/run_peers.py`), as far as a report reads
/// it.
#[derive(Deserialize)]
struct PeersFile {
    #[serde(default)]
    meta: PeersMeta,
    /// Per method: its Middlebury means.
    summary: BTreeMap<String, PeerMeans>,
}

#[derive(Deserialize, Default)]
struct PeersMeta {
    command: Option<String>,
}

#[derive(Deserialize)]
struct PeerMeans {
    epe: f64,
    seconds: f64,
}

/// The Middlebury means of the peer script: our presets as rows, the rest as peers.
pub fn peer_rows(path: &Path, rows: &mut Vec<Row>, peers: &mut Vec<PeerPoint>) -> Result<()> {
    let text = std::fs::read_to_string(path).map_err(|e| frf_core::CoreError::io(path, e))?;
    let file: PeersFile = serde_json::from_str(&text).map_err(|e| {
        frf_core::CoreError::bad_file(
            path,
            format!(
                "not the peer script's output (a `summary` of methods, each with epe and \
                 seconds): {e}"
            ),
        )
    })?;
    let command = file
        .meta
        .command
        .as_deref()
        .unwrap_or("benches/flow_peers/run_peers.py");
    let stage = "optical flow (Middlebury)";
    for (method, m) in file.summary {
        let (epe, secs) = (m.epe, m.seconds);
        match method.strip_prefix("frf_") {
            Some(preset) => rows.push(Row {
                stage: stage.into(),
                knob: "flow preset".into(),
                value: preset.into(),
                metric: "EPE px".into(),
                error: epe,
                seconds: secs,
                timed: "one pair, mean of the Middlebury pairs".into(),
                default: preset == "balanced",
                command: command.into(),
            }),
            None => peers.push(PeerPoint {
                stage: stage.into(),
                metric: "EPE px".into(),
                method: method.clone(),
                error: epe,
                seconds: secs,
            }),
        }
    }
    Ok(())
}

/// `git describe` of the working directory's repository, or "unknown".
pub fn commit() -> String {
    Command::new("git")
        .args(["describe", "--always", "--dirty"])
        .output()
        .ok()
        .filter(|o| o.status.success())
        .and_then(|o| String::from_utf8(o.stdout).ok())
        .map(|s| s.trim().to_string())
        .unwrap_or_else(|| "unknown".into())
}

/// Writes `report.json`, every stage's plot and `index.html` (each atomically).
pub fn write_report(report: &Report, out: &Path) -> Result<()> {
    use frf_core::atomic::write_bytes_atomic;
    write_bytes_atomic(
        &out.join("report.json"),
        serde_json::to_string_pretty(report)
            .map_err(|e| EvalError::Misuse(format!("the report as JSON: {e}")))?
            .as_bytes(),
    )?;
    let mut png = true;
    for stage in report.stages() {
        let name = html::plot_name(stage);
        write_bytes_atomic(
            &out.join(format!("{name}.svg")),
            plot::svg(report, stage)?.as_bytes(),
        )?;
        match plot::png(report, stage)? {
            Some(bytes) => write_bytes_atomic(&out.join(format!("{name}.png")), &bytes)?,
            None => png = false,
        }
    }
    if !png {
        eprintln!("no system font found for the PNG plots' text: SVG plots only");
    }
    write_bytes_atomic(&out.join("index.html"), html::page(report, png).as_bytes())?;
    println!(
        "report of {} settings over {} stages in {:.0} s: {}",
        report.rows.len(),
        report.stages().len(),
        report.seconds_total,
        out.join("index.html").display()
    );
    for stage in report.stages() {
        for metric in report.metrics(stage) {
            let series = report.series(stage, metric);
            let front: Vec<String> = crate::report::pareto_front(&series)
                .into_iter()
                .map(|i| {
                    let r = series[i];
                    format!("{} {:.3} in {:.3} s", r.value, r.error, r.seconds)
                })
                .collect();
            println!("  {stage} / {metric}: front {}", front.join(" | "));
        }
    }
    Ok(())
}
