//! `index.html`: every stage's plot and its table of settings on one page that needs
//! nothing but the files beside it (no script, no network).

use std::fmt::Write;

use super::{Report, pareto_front};

fn escape(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

/// The file name of a stage's plot, without extension.
pub fn plot_name(stage: &str) -> String {
    let mut name: String = stage
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() {
                c.to_ascii_lowercase()
            } else {
                '_'
            }
        })
        .collect();
    while name.contains("__") {
        name = name.replace("__", "_");
    }
    name.trim_matches('_').to_string()
}

/// The page; `png` says whether PNG plots were drawn (else the SVGs are shown).
pub fn page(report: &Report, png: bool) -> String {
    let mut h = String::new();
    let m = &report.machine;
    let _ = write!(
        h,
        "<!doctype html>\n<html><head><meta charset=\"utf-8\"><title>frf report: {cap}</title>\n\
         <style>body{{font-family:sans-serif;max-width:1200px;margin:2em auto;color:#222}}\
         table{{border-collapse:collapse;margin:1em 0}}td,th{{border:1px solid #ccc;padding:3px 8px;text-align:right}}\
         th{{background:#f4f4f4}}td.l{{text-align:left}}tr.front td{{font-weight:bold}}img{{max-width:100%}}\
         code{{font-size:85%}}</style></head><body>\n\
         <h1>Error against run time</h1>\n<p>Capture <code>{cap}</code>, commit <code>{commit}</code>, \
         {cores} cores, renderer adapter: {adapter}, {os}; {kind} sweep in {total:.0} s. \
         Bold rows are on the Pareto front of their metric (no other setting is both faster \
         and better); ✓ marks the default. Times are wall-clock on this machine, which may \
         be shared: compare settings within one report.</p>\n",
        cap = escape(&report.capture),
        commit = escape(&report.commit),
        cores = m.cores,
        adapter = escape(&m.adapter),
        os = escape(&m.os),
        kind = if report.quick { "quick" } else { "full" },
        total = report.seconds_total,
    );
    for stage in report.stages() {
        let name = plot_name(stage);
        let ext = if png { "png" } else { "svg" };
        let _ = write!(
            h,
            "<h2>{s}</h2>\n<p><a href=\"{name}.svg\"><img src=\"{name}.{ext}\" alt=\"{s}: error against seconds\"></a></p>\n",
            s = escape(stage)
        );
        for metric in report.metrics(stage) {
            let series = report.series(stage, metric);
            let front = pareto_front(&series);
            let _ = writeln!(
                h,
                "<table><tr><th>knob</th><th>value</th><th>{}</th><th>seconds</th><th>timed</th><th>default</th><th>command</th></tr>",
                escape(metric)
            );
            for (i, r) in series.iter().enumerate() {
                let _ = writeln!(
                    h,
                    "<tr{}><td class=l>{}</td><td class=l>{}</td><td>{:.4}</td><td>{:.4}</td><td class=l>{}</td><td>{}</td><td class=l><code>{}</code></td></tr>",
                    if front.contains(&i) {
                        " class=front"
                    } else {
                        ""
                    },
                    escape(&r.knob),
                    escape(&r.value),
                    r.error,
                    r.seconds,
                    escape(&r.timed),
                    if r.default { "✓" } else { "" },
                    escape(&r.command),
                );
            }
            h.push_str("</table>\n");
        }
    }
    if !report.peers.is_empty() {
        h.push_str("<h2>Peers</h2>\n<table><tr><th>stage</th><th>method</th><th>metric</th><th>error</th><th>seconds</th></tr>\n");
        for p in &report.peers {
            let _ = writeln!(
                h,
                "<tr><td class=l>{}</td><td class=l>{}</td><td class=l>{}</td><td>{:.4}</td><td>{:.4}</td></tr>",
                escape(&p.stage),
                escape(&p.method),
                escape(&p.metric),
                p.error,
                p.seconds
            );
        }
        h.push_str("</table>\n");
    }
    h.push_str("<p>The numbers: <a href=\"report.json\">report.json</a>.</p>\n</body></html>\n");
    h
}
