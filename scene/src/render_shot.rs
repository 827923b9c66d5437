//! The shot loop every front end runs: each frame of a shot rendered ([`Shot::render`])
//! and its files encoded and written on a thread of their own while the next frame
//! renders (at most two waiting), so that a sequence runs at the slower of rendering and
//! encoding; frames already in the output are kept ([`Output::kept`]). [`render_to_dir`]
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
use super::shot::{Shot, ShotOptions};
use super::shot_report::shot_preamble;
use crate::Scene;
use crate::error::{Result, SceneError};

/// Renders `frames` of `shot` into `output` (with their layers when `layers`, the PNGs
/// exposed by `exposure_stops`), one progress phase of a step per frame. Stops at the
/// first error, of rendering or of writing; what was written stays (a rerun resumes), and
/// a directory this run made that holds no frame is removed.
pub fn render_shot<R: ReadAt>(
    shot: &mut Shot<'_, R>,
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
        let mut result = Ok(());
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
            let r = match while_saying(progress, f.index, STILL_RENDERING_EVERY, || {
                shot.render(f, layers)
            }) {
                Ok(r) => r,
                Err(e) => {
                    result = Err(e);
                    break;
                }
            };
            let files = output.accept(f, r, t.elapsed().as_secs_f64());
            if to_writer.send(files).is_err() {
                // The writer stopped on an error: it says which below.
                break;
            }
            progress.step();
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
