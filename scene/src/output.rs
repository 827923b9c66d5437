//! What `frf render` writes, and resuming it: per frame an 8-bit sRGB PNG (straight
//! alpha) and a linear premultiplied EXR (and EXR layers on request), written atomically;
//! when every frame of the shot is there, a contact sheet and an animated preview; and a
//! report (`render.json`, or `render_frames_A-B.json` for part of a shot).
//!
//! A directory remembers the settings it was rendered with (`settings.json`, without the
//! frame range; the caller makes them say what the frames are made from): a rerun with the
//! same settings skips the frames already written, so an interrupted render resumes and
//! the tasks of a farm job can share one directory; other settings are refused, naming
//! what differs, while any frame is there, rather than mixed in.
//!
//! Each frame ends with its record, `frame_NNNN.json` (its time, poses, timings, pixel
//! statistics and the sizes of its files), written after its files: a frame is kept only
//! when its record is there and its files have the sizes it lists, so a frame cut short
//! (or without a record) is rendered again, and a report of a resumed run counts the kept
//! frames' statistics and timings from their records.

use std::path::{Path, PathBuf};

use frf_core::atomic::write_bytes_atomic;
use frf_core::contact;
use frf_core::image::{Image, RgbImage, Rgba};
use frf_core::io::{read_rgba, write_exr_rgb, write_exr_rgba, write_png8_srgb, write_png8_srgba};
use frf_core::preview::{fit_width, write_apng, write_gif};
use frf_reflectance::container::ReadAt;
use serde::{Deserialize, Serialize};

use super::plan::ShotFrame;
use super::settings::RenderSettings;
use super::shot::{Shot, ShotCounters, ShotResult};
use super::{Preview, Scene};
use crate::error::{Result, SceneError};
use frf_render::cpu::FrameStats;

fn json_error(e: serde_json::Error) -> SceneError {
    SceneError::Internal(format!("a render's report does not serialize: {e}"))
}

/// Frames on the contact sheet (evenly spaced).
const SHEET_FRAMES: usize = 12;
/// Widest animated preview, pixels.
const PREVIEW_WIDTH: usize = 480;

/// One frame, as the report lists it and as its record (`frame_NNNN.json`) keeps it.
#[derive(Serialize, Deserialize, Clone)]
struct FrameRecord {
    index: usize,
    time: f64,
    poses: Vec<u32>,
    made_resident: Vec<u32>,
    /// Kept from an earlier run (its timings are that run's).
    resumed: bool,
    /// Rendering it, read back included.
    seconds: Option<f64>,
    /// Encoding and writing its files (overlapped with the next frame's rendering).
    seconds_writing: Option<f64>,
    pixels_inside: usize,
    pixels_clamped_above: usize,
    pixels_clamped_below: usize,
    pixels_missed: usize,
    /// The frame's files, their sizes and checksums (in the record only).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    files: Vec<FileRecord>,
}

/// One file of a frame as written: what a resume compares it with.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
struct FileRecord {
    /// Its name in the output directory.
    name: String,
    /// Its size, bytes.
    bytes: u64,
    /// The CRC-32 of its bytes: a frame overwritten in place at the same size is seen.
    crc32: u32,
}

impl FrameRecord {
    fn stats(&self) -> FrameStats {
        FrameStats {
            inside: self.pixels_inside,
            clamped_above: self.pixels_clamped_above,
            clamped_below: self.pixels_clamped_below,
            missed: self.pixels_missed,
        }
    }
}

/// The files of one rendered frame, not yet written.
pub struct FrameFiles {
    dir: PathBuf,
    frame: frf_render::renderer::Frame,
    record: FrameRecord,
}

impl FrameFiles {
    /// Which frame.
    pub fn index(&self) -> usize {
        self.record.index
    }

    /// Encodes and writes them (each file atomically), exposed by `exposure_stops` for
    /// the PNG, then the frame's record (`seconds_writing` is the time taken so far).
    pub fn write(&self, exposure_stops: f32) -> Result<()> {
        let t = std::time::Instant::now();
        let scale = 2f32.powf(exposure_stops);
        let (dir, i) = (&self.dir, self.record.index);
        let mut written = Vec::new();
        if let Some(l) = &self.frame.layers {
            written.push(layer_path(dir, i, "subject"));
            write_exr_rgba(&layer_path(dir, i, "subject"), &l.subject)?;
            written.push(layer_path(dir, i, "shadow"));
            write_exr_rgb(&layer_path(dir, i, "shadow"), &l.shadow)?;
            written.push(layer_path(dir, i, "backdrop"));
            write_exr_rgba(&layer_path(dir, i, "backdrop"), &l.backdrop)?;
        }
        write_exr_rgba(&frame_path(dir, i, "exr"), &self.frame.composite)?;
        write_png8_srgba(&frame_path(dir, i, "png"), &self.frame.composite, scale)?;
        written.extend([frame_path(dir, i, "exr"), frame_path(dir, i, "png")]);
        let mut record = self.record.clone();
        for path in written {
            let (bytes, crc32) = frf_core::io::content_identity(&path)?;
            let name = path.file_name().unwrap_or_default().to_string_lossy();
            record.files.push(FileRecord {
                name: name.into_owned(),
                bytes,
                crc32,
            });
        }
        record.seconds_writing = Some(t.elapsed().as_secs_f64());
        let text = serde_json::to_string_pretty(&record).map_err(json_error)?;
        write_bytes_atomic(&record_path(dir, i), text.as_bytes())?;
        Ok(())
    }
}

/// Whether a frame already in the directory may be kept.
pub enum Kept {
    /// Yes: its record.
    Yes(Box<FrameRecordRef>),
    /// No: not there (or not resuming).
    No,
    /// No, and why: its files are there but differ from its record.
    Damaged(String),
}

/// A kept frame's record, opaque outside this module.
pub struct FrameRecordRef(FrameRecord);

/// An output directory being filled.
pub struct Output {
    dir: PathBuf,
    /// Whether this run made the directory (it did not exist).
    made_dir: bool,
    resume: bool,
    total: usize,
    records: Vec<FrameRecord>,
    totals: FrameStats,
}

fn frame_path(dir: &Path, i: usize, ext: &str) -> PathBuf {
    dir.join(format!("frame_{i:04}.{ext}"))
}

fn layer_path(dir: &Path, i: usize, layer: &str) -> PathBuf {
    dir.join(format!("frame_{i:04}_{layer}.exr"))
}

fn record_path(dir: &Path, i: usize) -> PathBuf {
    frame_path(dir, i, "json")
}

/// Whether `dir` holds any frame file (a frame, a layer or a record).
fn holds_frames(dir: &Path) -> bool {
    std::fs::read_dir(dir).is_ok_and(|entries| {
        entries.flatten().any(|e| {
            let name = e.file_name();
            let name = name.to_string_lossy();
            name.starts_with("frame_")
                && [".png", ".exr", ".json"].iter().any(|x| name.ends_with(x))
        })
    })
}

/// The keys (dotted paths) at which two settings differ, at most a few.
fn differences(old: &serde_json::Value, new: &serde_json::Value) -> Vec<String> {
    fn walk(a: &serde_json::Value, b: &serde_json::Value, at: &str, out: &mut Vec<String>) {
        use serde_json::Value::Object;
        if out.len() >= 4 || a == b {
            return;
        }
        match (a, b) {
            (Object(a), Object(b)) => {
                let keys: std::collections::BTreeSet<&String> = a.keys().chain(b.keys()).collect();
                for k in keys {
                    let null = serde_json::Value::Null;
                    let at = if at.is_empty() {
                        k.clone()
                    } else {
                        format!("{at}.{k}")
                    };
                    walk(
                        a.get(k).unwrap_or(&null),
                        b.get(k).unwrap_or(&null),
                        &at,
                        out,
                    );
                }
            }
            _ => out.push(at.to_string()),
        }
    }
    let mut out = Vec::new();
    walk(old, new, "", &mut out);
    out
}

/// Premultiplied RGBA over a mid-gray backdrop, for the contact sheet.
fn over_gray(img: &Image<Rgba>) -> RgbImage {
    let gray = 0.18;
    Image::from_fn(img.width(), img.height(), |x, y| {
        let p = img.get(x, y);
        let a = p[3].clamp(0.0, 1.0);
        [0, 1, 2].map(|c| p[c] + (1.0 - a) * gray)
    })
}

impl Output {
    /// Opens `dir` for a shot of `total` frames rendered with `settings` (a rerun with
    /// the same settings resumes; `overwrite` renders every frame again).
    pub fn open(
        dir: &Path,
        settings: &RenderSettings,
        overwrite: bool,
        total: usize,
    ) -> Result<Self> {
        if dir.exists() && !dir.is_dir() {
            return Err(SceneError::Output {
                dir: dir.to_path_buf(),
                problem: "a file is there, not a directory (--out)".into(),
            });
        }
        let made_dir = !dir.exists();
        std::fs::create_dir_all(dir).map_err(|e| frf_core::CoreError::io(dir, e))?;
        let mut settings = serde_json::to_value(settings).map_err(json_error)?;
        // A frame range may change between runs into one directory (array jobs); the
        // shot's frame count may not.
        if let Some(args) = settings.get_mut("args").and_then(|a| a.as_object_mut()) {
            args.remove("frames");
        }
        settings["frames_total"] = total.into();
        let text = serde_json::to_string_pretty(&settings).map_err(json_error)?;
        let path = dir.join("settings.json");
        let old: Option<serde_json::Value> = std::fs::read_to_string(&path)
            .ok()
            .and_then(|s| serde_json::from_str(&s).ok());
        let same = old.as_ref() == Some(&settings);
        if !same && !overwrite && holds_frames(dir) {
            let what = match &old {
                Some(old) => format!("they differ in {}", differences(old, &settings).join(", ")),
                None => "its settings.json is missing or unreadable".into(),
            };
            return Err(SceneError::Output {
                dir: dir.to_path_buf(),
                problem: format!(
                    "holds frames of a render with other settings ({what}); use --overwrite or another --out"
                ),
            });
        }
        write_bytes_atomic(&path, text.as_bytes())?;
        Ok(Self {
            dir: dir.to_path_buf(),
            made_dir,
            resume: same && !overwrite,
            total,
            records: Vec::new(),
            totals: FrameStats::default(),
        })
    }

    /// Whether frame `i` is there already and may be kept: its record is there and its
    /// files have the sizes and checksums the record lists.
    pub fn kept(&self, i: usize) -> Kept {
        if !self.resume {
            return Kept::No;
        }
        let path = record_path(&self.dir, i);
        let Some(record) = std::fs::read(&path)
            .ok()
            .and_then(|b| serde_json::from_slice::<FrameRecord>(&b).ok())
            .filter(|r| r.index == i && !r.files.is_empty())
        else {
            return match frame_path(&self.dir, i, "png").exists() {
                true => Kept::Damaged(format!("{} is missing or unreadable", path.display())),
                false => Kept::No,
            };
        };
        for f in &record.files {
            let file = self.dir.join(&f.name);
            match frf_core::io::content_identity(&file) {
                Ok((bytes, _)) if bytes != f.bytes => {
                    return Kept::Damaged(format!(
                        "{} holds {bytes} bytes, its record says {} (cut short?)",
                        file.display(),
                        f.bytes
                    ));
                }
                Ok((_, crc)) if crc != f.crc32 => {
                    return Kept::Damaged(format!(
                        "{}: its bytes differ from those its record lists (changed since)",
                        file.display()
                    ));
                }
                Ok(_) => {}
                Err(_) => return Kept::Damaged(format!("{} is missing", file.display())),
            }
        }
        Kept::Yes(Box::new(FrameRecordRef(record)))
    }

    /// Removes what [`Output::open`] wrote when no frame is in the directory: a run that
    /// failed before its first frame leaves no directory it made (nor a settings file in
    /// a directory it found empty).
    pub fn abandon_if_empty(&self) {
        if holds_frames(&self.dir) {
            return;
        }
        let _ = std::fs::remove_file(self.dir.join("settings.json"));
        if self.made_dir {
            // Only when empty: anything else in it is not ours to remove.
            let _ = std::fs::remove_dir(&self.dir);
        }
    }

    /// Notes that frame `i` was kept from an earlier run, with its record.
    pub fn resumed(&mut self, kept: FrameRecordRef) {
        let mut record = kept.0;
        record.resumed = true;
        record.files.clear();
        self.totals = self.totals.merge(record.stats());
        self.records.push(record);
    }

    /// Records a rendered frame (`seconds` to render it) and returns its files, to be
    /// written by [`FrameFiles::write`], on another thread while the next frame renders.
    pub fn accept(&mut self, f: &ShotFrame, r: ShotResult, seconds: f64) -> FrameFiles {
        let s = r.frame.stats;
        self.totals = self.totals.merge(s);
        let record = FrameRecord {
            index: f.index,
            time: f.time,
            poses: r.poses,
            made_resident: r.made_resident,
            resumed: false,
            seconds: Some(seconds),
            seconds_writing: None,
            pixels_inside: s.inside,
            pixels_clamped_above: s.clamped_above,
            pixels_clamped_below: s.clamped_below,
            pixels_missed: s.missed,
            files: Vec::new(),
        };
        self.records.push(record.clone());
        FrameFiles {
            dir: self.dir.clone(),
            frame: r.frame,
            record,
        }
    }

    /// Notes how long writing frame `i`'s files took.
    pub fn written(&mut self, i: usize, seconds: f64) {
        if let Some(r) = self.records.iter_mut().rev().find(|r| r.index == i) {
            r.seconds_writing = Some(seconds);
        }
    }

    /// Writes the contact sheet and the preview (when every frame of the shot is there)
    /// and the report; returns a summary for people.
    pub fn finish<R: ReadAt>(
        self,
        scene: &Scene,
        shot: &Shot<'_, R>,
        setup_seconds: f64,
        wall_seconds: f64,
        bytes_read: u64,
    ) -> Result<String> {
        let extras = self.write_sheet_and_preview(scene)?;
        let timings = self.timings();
        let name = self.report_name();
        let t = self.totals;
        let report = RenderReport {
            device: shot.device(),
            adapter: shot.adapter(),
            frames_total: self.total,
            frames_rendered: timings.rendered,
            frames_resumed: self.records.len() - timings.rendered,
            seconds_setup: setup_seconds,
            timings_of: timings.of,
            seconds_per_frame_median: timings.median,
            seconds_per_frame_mean: timings.mean,
            seconds_writing_per_frame_mean: timings.writing_mean,
            seconds_wall: wall_seconds,
            plan: &shot.plan().counts,
            planned: shot.planned(),
            poses_substituted: &shot.plan().poses_substituted,
            bytes_read_measured: bytes_read,
            residency: shot.counters(),
            pixels_inside: t.inside,
            pixels_clamped_above: t.clamped_above,
            pixels_clamped_below: t.clamped_below,
            pixels_missed: t.missed,
            frames: &self.records,
        };
        write_bytes_atomic(
            &self.dir.join(&name),
            serde_json::to_string_pretty(&report)
                .map_err(json_error)?
                .as_bytes(),
        )?;
        Ok(self.summary(&report, &timings, &name, &extras))
    }

    /// The contact sheet and the animated preview, when every frame of the shot is in
    /// the directory; the names of what was written.
    fn write_sheet_and_preview(&self, scene: &Scene) -> Result<Vec<String>> {
        let scale = 2f32.powf(scene.exposure);
        let all_there = (0..self.total).all(|i| frame_path(&self.dir, i, "exr").exists());
        let mut extras = Vec::new();
        if !all_there {
            return Ok(extras);
        }
        let frames: Vec<Image<Rgba>> = (0..self.total)
            .map(|i| read_rgba(&frame_path(&self.dir, i, "exr")))
            .collect::<frf_core::Result<_>>()?;
        let every = self.total.div_ceil(SHEET_FRAMES).max(1);
        let sheet: Vec<RgbImage> = frames.iter().step_by(every).map(over_gray).collect();
        let columns = sheet.len().min(SHEET_FRAMES / 2);
        write_png8_srgb(
            &self.dir.join("contact.png"),
            &contact::sheet(&sheet, columns),
            scale,
        )?;
        extras.push("contact.png".to_string());
        if self.total > 1 {
            let small = fit_width(&frames, PREVIEW_WIDTH);
            match scene.preview {
                Preview::Apng => {
                    write_apng(
                        &self.dir.join("preview.png"),
                        &small,
                        scene.fps as f32,
                        scale,
                    )?;
                    extras.push("preview.png (animated)".into());
                }
                Preview::Gif => {
                    write_gif(
                        &self.dir.join("preview.gif"),
                        &small,
                        scene.fps as f32,
                        scale,
                    )?;
                    extras.push("preview.gif".into());
                }
                Preview::None => {}
            }
        }
        Ok(extras)
    }

    /// The timings of the frames this run rendered; when it rendered none, those its
    /// records kept from the runs that did.
    fn timings(&self) -> Timings {
        let rendered = self.records.iter().filter(|r| !r.resumed).count();
        let timed_now = rendered > 0;
        let timed = |r: &&FrameRecord| r.resumed != timed_now;
        let seconds: Vec<f64> = self
            .records
            .iter()
            .filter(timed)
            .filter_map(|r| r.seconds)
            .collect();
        let writing: Vec<f64> = self
            .records
            .iter()
            .filter(timed)
            .filter_map(|r| r.seconds_writing)
            .collect();
        let of = match (timed_now, seconds.is_empty()) {
            (true, _) => "the frames this run rendered",
            (false, false) => "the resumed frames, when earlier runs rendered them",
            (false, true) => "no frame (nothing timed)",
        };
        let median = (!seconds.is_empty()).then(|| frf_render::gpu::timing::median_min(&seconds).0);
        let mean_of = |v: &[f64]| (!v.is_empty()).then(|| v.iter().sum::<f64>() / v.len() as f64);
        Timings {
            rendered,
            timed_now,
            of,
            median,
            mean: mean_of(&seconds),
            writing_mean: mean_of(&writing),
        }
    }

    /// `render.json` for a whole shot, `render_frames_A-B.json` for part of one.
    fn report_name(&self) -> String {
        let (first, last) = (
            self.records.iter().map(|r| r.index).min().unwrap_or(0),
            self.records.iter().map(|r| r.index).max().unwrap_or(0),
        );
        if first == 0 && last + 1 == self.total {
            "render.json".to_string()
        } else {
            format!("render_frames_{first}-{}.json", last + 1)
        }
    }

    /// The summary for people of a run that wrote `report` as `name` and `extras`.
    fn summary(
        &self,
        report: &RenderReport,
        timings: &Timings,
        name: &str,
        extras: &[String],
    ) -> String {
        let t = self.totals;
        let all = (t.inside + t.clamped_above + t.clamped_below + t.missed).max(1);
        let pct = |n: usize| 100.0 * n as f64 / all as f64;
        let c = report.residency;
        let (wall_seconds, setup_seconds) = (report.seconds_wall, report.seconds_setup);
        let timings = match (timings.median, timings.mean, timings.writing_mean) {
            (Some(median), Some(mean), writing) => format!(
                "{median:.3} s/frame median to render ({mean:.3} mean), {} s mean to write \
                 (on its own thread){}",
                writing.map_or("?".into(), |w| format!("{w:.3}")),
                if timings.timed_now {
                    ""
                } else {
                    ", as the resumed frames' earlier runs measured"
                }
            ),
            _ => "no frame timed".into(),
        };
        format!(
            "{} frames in {}: {timings}, {wall_seconds:.2} s wall; setup {setup_seconds:.2} s; \
             {} resumed; poses made resident {} ({} relit for a new lighting, {} dropped for the memory budget, \
             peak {:.1} MB, {:.2} s); {:.2} MB read from the field\n\
             pixels: {:.1} % re-binned inside the grid, {:.1} % clamped to the top row, {:.1} % to the bottom row, \
             {:.1} % missed; {} written{}",
            report.frames_rendered,
            self.dir.display(),
            report.frames_resumed,
            c.poses_made_resident,
            c.relights,
            c.evictions,
            c.peak_resident_bytes as f64 / 1e6,
            c.residency_seconds,
            report.bytes_read_measured as f64 / 1e6,
            pct(t.inside),
            pct(t.clamped_above),
            pct(t.clamped_below),
            pct(t.missed),
            name,
            if extras.is_empty() {
                " (contact sheet and preview once every frame is there)".to_string()
            } else {
                format!(", {}", extras.join(", "))
            }
        )
    }
}

/// The timings a run's report gives.
struct Timings {
    /// Frames this run rendered.
    rendered: usize,
    /// The timings are this run's (else the resumed frames').
    timed_now: bool,
    /// Which frames the timings are of, in words.
    of: &'static str,
    median: Option<f64>,
    mean: Option<f64>,
    writing_mean: Option<f64>,
}

/// `render.json`: what a run rendered, how long it took, what it read.
#[derive(Serialize)]
struct RenderReport<'a> {
    device: String,
    /// The GPU adapter, why it was taken, and every one considered.
    #[serde(skip_serializing_if = "Option::is_none")]
    adapter: Option<&'a frf_render::gpu::adapter::AdapterReport>,
    frames_total: usize,
    frames_rendered: usize,
    frames_resumed: usize,
    seconds_setup: f64,
    /// Which frames the timings below are of.
    timings_of: &'a str,
    seconds_per_frame_median: Option<f64>,
    seconds_per_frame_mean: Option<f64>,
    seconds_writing_per_frame_mean: Option<f64>,
    seconds_wall: f64,
    plan: &'a super::plan::PlanCounts,
    planned: bool,
    /// Poses the scene asks for that the field lacks, and the pose drawn instead.
    poses_substituted: &'a [(u32, u32)],
    bytes_read_measured: u64,
    residency: &'a ShotCounters,
    pixels_inside: usize,
    pixels_clamped_above: usize,
    pixels_clamped_below: usize,
    pixels_missed: usize,
    frames: &'a [FrameRecord],
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A run that fails before its first frame leaves nothing: the directory it made is
    /// removed; in a directory it found, only the settings it wrote (issue 35:
    /// `--memory-budget` refused at the first frame left a new `--out` with its settings).
    #[test]
    fn a_run_without_a_frame_leaves_no_directory_or_settings() -> Result<()> {
        let root = tempfile::tempdir().map_err(|e| frf_core::CoreError::io(Path::new("."), e))?;
        let settings = RenderSettings {
            args: serde_json::json!({}),
            files: Default::default(),
            scene: None,
            size: (4, 3),
        };
        let made = root.path().join("new");
        Output::open(&made, &settings, false, 3)?.abandon_if_empty();
        assert!(!made.exists());

        let found = root.path().join("found");
        std::fs::create_dir(&found).map_err(|e| frf_core::CoreError::io(&found, e))?;
        std::fs::write(found.join("notes.txt"), "mine")
            .map_err(|e| frf_core::CoreError::io(&found, e))?;
        Output::open(&found, &settings, false, 3)?.abandon_if_empty();
        assert!(found.join("notes.txt").exists() && !found.join("settings.json").exists());

        // With a frame in it, nothing is removed.
        std::fs::write(frame_path(&found, 0, "png"), "x")
            .map_err(|e| frf_core::CoreError::io(&found, e))?;
        Output::open(&found, &settings, true, 3)?.abandon_if_empty();
        assert!(found.join("settings.json").exists());
        Ok(())
    }
}
