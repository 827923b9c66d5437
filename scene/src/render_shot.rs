//! The shot loop every front end runs: each frame of a shot drawn and submitted
//! ([`Shot::submit`]), the frame before it read back meanwhile ([`Shot::finish`]), and its
//! files encoded and written on a thread of their own while the next frames render (at
//! most two waiting), so that a sequence runs at the slowest of drawing, reading back and
//! encoding, with no wait for the GPU per frame; frames already in the output are kept
//! ([`Output::kept`]). [`render_to_dir`]
//! runs a whole shot into a directory, as `frf render` does.

use std::sync::mpsc::{RecvTimeoutError, channel, sync_channel};
use std::time::{Duration, Instant};

use std::path::Path;

use frf_core::progress::Progress;
use frf_reflectance::FieldFile;
use frf_reflectance::container::ReadAt;
use frf_render::renderer::Device;

use super::output::{FrameFiles, Kept, Output};
use super::plan::ShotFrame;
use super::settings::RenderSettings;
use super::shot::{Shot, ShotInFlight, ShotOptions, ShotResult};
use super::shot_report::shot_preamble;
use crate::Scene;
use crate::error::{Result, SceneError};

/// What the shot loop draws from: a frame drawn and submitted, and read back later, once
/// the next frame is submitted. [`Shot`] is one; a test stands in its own.
pub trait FrameSource {
    /// A frame submitted and not yet read back.
    type InFlight;
    /// Draws and submits `frame` (with its layers when `layers`).
    fn submit(&mut self, frame: &ShotFrame, layers: bool) -> Result<Self::InFlight>;
    /// Reads back a frame [`FrameSource::submit`] drew.
    fn finish(&mut self, drawn: Self::InFlight) -> Result<ShotResult>;
}

impl<R: ReadAt> FrameSource for Shot<'_, R> {
    type InFlight = ShotInFlight;

    fn submit(&mut self, frame: &ShotFrame, layers: bool) -> Result<ShotInFlight> {
        Shot::submit(self, frame, layers)
    }

    fn finish(&mut self, drawn: ShotInFlight) -> Result<ShotResult> {
        Shot::finish(self, drawn)
    }
}

/// A frame in flight: which, what was drawn, and the seconds its drawing and submitting
/// took.
type InFlight<'f, T> = (&'f ShotFrame, T, f64);

/// Renders `frames` of `shot` into `output` (with their layers when `layers`, the PNGs
/// exposed by `exposure_stops`), one progress phase of a step per frame. Frame N+1 is
/// drawn and submitted before frame N is read back (a ring of staging sets on the GPU,
/// [`frf_render::gpu::readback`]), and N's files are written on a thread of their own
/// while later frames render: every frame is written once, in order. Stops at the first
/// error, of rendering or of writing, after writing the frames drawn before it; what was
/// written stays (a rerun resumes), and a directory this run made that holds no frame is
/// removed.
pub fn render_shot<S: FrameSource>(
    shot: &mut S,
    frames: &[ShotFrame],
    output: &mut Output,
    (layers, exposure_stops): (bool, f32),
    progress: &dyn Progress,
) -> Result<()> {
    progress.phase("frames", frames.len());
    let (to_writer, from_loop) = sync_channel::<FrameFiles>(2);
    let (to_loop, written) = channel::<(usize, f64)>();
    let rendered: Result<()> = std::thread::scope(|scope| {
        let writer = scope.spawn(move || -> Result<()> {
            for files in from_loop {
                let t = Instant::now();
                files.write(exposure_stops)?;
                let _ = to_loop.send((files.index(), t.elapsed().as_secs_f64()));
            }
            Ok(())
        });
        let deliver =
            |shot: &mut S, output: &mut Output, (f, drawn, seconds): InFlight<'_, S::InFlight>| {
                let t = Instant::now();
                let r = while_saying(progress, f.index, STILL_RENDERING_EVERY, || {
                    shot.finish(drawn)
                })?;
                let files = output.accept(f, r, seconds + t.elapsed().as_secs_f64());
                progress.step();
                // A writer that stopped on an error says which below.
                Ok::<bool, SceneError>(to_writer.send(files).is_ok())
            };
        let mut result = Ok(());
        let mut in_flight: Option<InFlight<'_, S::InFlight>> = None;
        for f in frames {
            match output.kept(f.index) {
                Kept::Yes(record) => {
                    output.resumed(*record);
                    progress.step();
                    continue;
                }
                Kept::Damaged(why) => {
                    progress.note(&format!("frame {}: {why}; rendering it again", f.index));
                }
                Kept::No => {}
            }
            let t = Instant::now();
            let drawn = while_saying(progress, f.index, STILL_RENDERING_EVERY, || {
                shot.submit(f, layers)
            });
            let seconds = t.elapsed().as_secs_f64();
            // The frame before is read back while this one is drawn, and written even
            // when this one failed.
            if let Some(before) = in_flight.take() {
                match deliver(shot, output, before) {
                    Ok(true) => {}
                    Ok(false) => break,
                    Err(e) => {
                        result = Err(e);
                        break;
                    }
                }
            }
            match drawn {
                Ok(drawn) => in_flight = Some((f, drawn, seconds)),
                Err(e) => {
                    result = Err(e);
                    break;
                }
            }
        }
        if let Some(last) = in_flight.take() {
            result = result.and(deliver(shot, output, last).map(|_| ()));
        }
        drop(to_writer);
        let wrote = writer
            .join()
            .unwrap_or_else(|_| Err(SceneError::Internal("the frame writer panicked".into())));
        result.and(wrote)
    });
    for (i, seconds) in written.try_iter() {
        output.written(i, seconds);
    }
    if rendered.is_err() {
        // Failed before its first frame: a new output directory is not left behind with
        // only the settings in it.
        output.abandon_if_empty();
    }
    rendered?;
    progress.finish();
    Ok(())
}

/// How long a frame renders before the user is told it still does, and how often again.
pub const STILL_RENDERING_EVERY: Duration = Duration::from_secs(20);

/// Runs `render` (frame `index`), saying `every` ([`STILL_RENDERING_EVERY`]) that the
/// frame is still rendering: a large frame on a software GPU takes minutes, and a bar that
/// counts frames would stand still meanwhile (and is hidden in a log).
fn while_saying<T>(
    progress: &dyn Progress,
    index: usize,
    every: Duration,
    render: impl FnOnce() -> Result<T>,
) -> Result<T> {
    let (done, wait) = channel::<()>();
    std::thread::scope(|scope| {
        scope.spawn(move || {
            let start = Instant::now();
            while let Err(RecvTimeoutError::Timeout) = wait.recv_timeout(every) {
                progress.note(&format!(
                    "frame {index}: still rendering, {:.0} s so far",
                    start.elapsed().as_secs_f64()
                ));
            }
        });
        let r = render();
        let _ = done.send(());
        r
    })
}

/// A shot rendered into a directory: the scene on a field, the frames asked for (of
/// the shot's `total`), their size, and the directory with the settings it keeps.
pub struct ShotJob<'a> {
    /// The scene.
    pub scene: &'a Scene,
    /// The field it is rendered from.
    pub field: &'a FieldFile,
    /// The field's path, as given.
    pub field_path: &'a Path,
    /// The frames to render.
    pub frames: &'a [ShotFrame],
    /// Frames of the whole shot.
    pub total: usize,
    /// Frame size.
    pub size: (u32, u32),
    /// The output directory.
    pub out_dir: &'a Path,
    /// What its frames are made from (`settings.json`).
    pub settings: &'a RenderSettings,
    /// Render every frame again even where the directory holds it.
    pub overwrite: bool,
}

/// Renders `job` with `options` into its directory (resuming) on the GPU, or the CPU
/// reference with `cpu`, saying what the plan reads before the first frame through
/// `say`; the summary for people (its setup time counts opening the device).
pub fn render_to_dir(
    job: &ShotJob,
    cpu: bool,
    options: ShotOptions,
    progress: &dyn Progress,
    say: &mut dyn FnMut(&str),
) -> Result<String> {
    let start = Instant::now();
    let device = Device::open(cpu)?;
    let mut shot = Shot::new(job.scene, job.field, device, job.frames, options)?;
    let setup_seconds = start.elapsed().as_secs_f64();
    // Opened once every input has been read and checked: a bad environment, plate or
    // field leaves no output directory behind.
    let mut output = Output::open(job.out_dir, job.settings, job.overwrite, job.total)?;
    let shape = (job.frames.len(), job.total, job.size);
    let preamble = shot_preamble(
        job.scene,
        &mut shot,
        job.field_path,
        shape,
        options.traced_lights,
    )?;
    for line in preamble {
        say(&line);
    }
    let scene = job.scene;
    render_shot(
        &mut shot,
        job.frames,
        &mut output,
        (scene.layers, scene.exposure),
        progress,
    )?;
    let wall_seconds = start.elapsed().as_secs_f64();
    let bytes_read = job.field.bytes_read();
    output.finish(scene, &shot, setup_seconds, wall_seconds, bytes_read)
}

#[cfg(test)]
mod tests {
    use std::sync::Mutex;

    use super::*;
    use crate::settings::RenderSettings;

    /// Keeps the notes.
    #[derive(Default)]
    struct Notes(Mutex<Vec<String>>);

    impl Progress for Notes {
        fn phase(&self, _what: &str, _total: usize) {}
        fn step(&self) {}
        fn note(&self, what: &str) {
            self.0
                .lock()
                .unwrap_or_else(|e| e.into_inner())
                .push(what.into());
        }
    }

    /// A stand-in for a shot: frame `i` is a 2x2 image of red `i`. It logs what it is
    /// asked, and fails to draw frame `fail_at`.
    struct Numbered {
        log: Vec<String>,
        fail_at: Option<usize>,
    }

    impl Numbered {
        fn new(fail_at: Option<usize>) -> Self {
            Self {
                log: Vec::new(),
                fail_at,
            }
        }
    }

    impl FrameSource for Numbered {
        type InFlight = usize;

        fn submit(&mut self, frame: &ShotFrame, _layers: bool) -> Result<usize> {
            self.log.push(format!("draw {}", frame.index));
            if self.fail_at == Some(frame.index) {
                return Err(SceneError::Internal(format!(
                    "frame {} failed",
                    frame.index
                )));
            }
            Ok(frame.index)
        }

        fn finish(&mut self, i: usize) -> Result<ShotResult> {
            self.log.push(format!("read {i}"));
            let composite =
                frf_core::image::Image::from_vec(2, 2, vec![[i as f32, 0., 0., 1.]; 4])?;
            Ok(ShotResult {
                frame: frf_render::renderer::Frame {
                    composite,
                    layers: None,
                    stats: Default::default(),
                },
                poses: vec![0],
                between: vec![None],
                made_resident: Vec::new(),
            })
        }
    }

    fn frames(n: usize) -> Vec<ShotFrame> {
        let camera = frf_core::camera::Camera::look_at(
            glam::Vec3::new(0., 1., 3.),
            glam::Vec3::ZERO,
            glam::Vec3::Y,
            0.8,
            2,
            2,
        )
        .unwrap();
        (0..n)
            .map(|index| ShotFrame {
                index,
                time: index as f64 / 10.0,
                camera,
            })
            .collect()
    }

    fn output(dir: &Path, total: usize) -> Output {
        let settings = RenderSettings {
            args: serde_json::json!({"size": "2x2"}),
            files: Default::default(),
            scene: None,
            size: (2, 2),
        };
        Output::open(dir, &settings, false, total).unwrap()
    }

    /// Runs the loop of `frames` frames of `source` into `dir`.
    fn run(source: &mut Numbered, dir: &Path, frames_n: usize) -> Result<()> {
        let mut out = output(dir, frames_n);
        render_shot(
            source,
            &frames(frames_n),
            &mut out,
            (false, 0.0),
            &Notes::default(),
        )
    }

    /// The red of frame `i`'s EXR, when it is there.
    fn red(dir: &Path, i: usize) -> Option<f32> {
        let path = dir.join(format!("frame_{i:04}.exr"));
        frf_core::io::read_rgba(&path)
            .ok()
            .map(|img| img.pixels()[0][0])
    }

    fn recorded(dir: &Path, i: usize) -> bool {
        dir.join(format!("frame_{i:04}.json")).exists()
    }

    #[test]
    fn the_ring_draws_a_frame_before_reading_the_last_back_and_writes_each_once_in_order() {
        let dir = tempfile::tempdir().unwrap();
        let mut source = Numbered::new(None);
        run(&mut source, dir.path(), 4).unwrap();
        assert_eq!(
            source.log,
            [
                "draw 0", "draw 1", "read 0", "draw 2", "read 1", "draw 3", "read 2", "read 3"
            ]
        );
        for i in 0..4 {
            assert_eq!(red(dir.path(), i), Some(i as f32), "frame {i}");
            assert!(recorded(dir.path(), i), "frame {i}");
        }
        // Written in order: each record no older than the one before.
        let modified = |i: usize| {
            std::fs::metadata(dir.path().join(format!("frame_{i:04}.json")))
                .and_then(|m| m.modified())
                .unwrap()
        };
        for i in 1..4 {
            assert!(
                modified(i) >= modified(i - 1),
                "frame {i} written before {}",
                i - 1
            );
        }
    }

    #[test]
    fn a_frame_that_fails_to_draw_stops_the_ring_after_writing_those_before_and_a_rerun_resumes() {
        let dir = tempfile::tempdir().unwrap();
        let mut failing = Numbered::new(Some(3));
        let e = run(&mut failing, dir.path(), 5).unwrap_err().to_string();
        assert!(e.contains("frame 3 failed"), "{e}");
        // Frame 2 was in flight when 3 failed: it is read back and written.
        assert_eq!(
            failing.log,
            [
                "draw 0", "draw 1", "read 0", "draw 2", "read 1", "draw 3", "read 2"
            ]
        );
        for i in 0..3 {
            assert_eq!(red(dir.path(), i), Some(i as f32), "frame {i}");
        }
        assert!(!recorded(dir.path(), 3) && red(dir.path(), 3).is_none());
        // The rerun draws only what is missing.
        let mut rerun = Numbered::new(None);
        run(&mut rerun, dir.path(), 5).unwrap();
        assert_eq!(rerun.log, ["draw 3", "draw 4", "read 3", "read 4"]);
        for i in 0..5 {
            assert_eq!(red(dir.path(), i), Some(i as f32), "frame {i}");
        }
    }

    #[test]
    fn a_failed_write_stops_the_ring_cleanly_naming_the_file() {
        let dir = tempfile::tempdir().unwrap();
        let mut out = output(dir.path(), 6);
        // Frame 2's PNG cannot be renamed into place: a directory holds its name.
        std::fs::create_dir(dir.path().join("frame_0002.png")).unwrap();
        let mut source = Numbered::new(None);
        let notes = Notes::default();
        let e = render_shot(&mut source, &frames(6), &mut out, (false, 0.0), &notes)
            .unwrap_err()
            .to_string();
        assert!(e.contains("frame_0002.png"), "{e}");
        for i in 0..2 {
            assert_eq!(red(dir.path(), i), Some(i as f32), "frame {i}");
            assert!(recorded(dir.path(), i));
        }
        // No frame from the failed one on is kept (the writer stopped there; the
        // frames already drawn are dropped), and no temporary file is left behind.
        assert!((2..6).all(|i| !recorded(dir.path(), i)));
        let leftovers: Vec<_> = std::fs::read_dir(dir.path())
            .unwrap()
            .filter_map(|e| e.ok())
            .map(|e| e.file_name().to_string_lossy().into_owned())
            .filter(|n| n.ends_with(".tmp"))
            .collect();
        assert!(leftovers.is_empty(), "{leftovers:?}");
    }

    #[test]
    fn a_long_frame_is_said_to_be_still_rendering_and_a_short_one_is_not() {
        let notes = Notes::default();
        let every = Duration::from_millis(20);
        let r = while_saying(&notes, 7, every, || {
            std::thread::sleep(Duration::from_millis(150));
            Ok(3)
        });
        assert_eq!(r.ok(), Some(3));
        let said = notes.0.lock().unwrap_or_else(|e| e.into_inner()).clone();
        assert!(said.len() >= 2, "{said:?}");
        assert!(said[0].starts_with("frame 7: still rendering"), "{said:?}");
        let quiet = Notes::default();
        let r = while_saying(&quiet, 0, Duration::from_secs(60), || Ok(()));
        assert!(r.is_ok());
        assert!(quiet.0.lock().unwrap_or_else(|e| e.into_inner()).is_empty());
    }
}
