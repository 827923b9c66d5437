//! The shot loop every front end runs: each frame of a shot rendered ([`Shot::render`])
//! and its files encoded and written on a thread of their own while the next frame
//! renders (at most two waiting), so that a sequence runs at the slower of rendering and
//! encoding; frames already in the output are kept ([`Output::kept`]).

use std::sync::mpsc::{channel, sync_channel};
use std::time::Instant;

use frf_core::progress::Progress;
use frf_reflectance::container::ReadAt;

use super::output::{FrameFiles, Kept, Output};
use super::plan::ShotFrame;
use super::shot::Shot;
use crate::error::{RenderError, Result};

/// Renders `frames` of `shot` into `output` (with their layers when `layers`, the PNGs
/// exposed by `exposure_stops`), one progress phase of a step per frame. Stops at the
/// first error, of rendering or of writing; what was written stays (a rerun resumes).
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
            let r = match shot.render(f, layers) {
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
        let wrote = writer.join().unwrap_or_else(|_| {
            Err(RenderError::BadParameter(
                "the frame writer panicked".into(),
            ))
        });
        result.and(wrote)
    });
    for (i, seconds) in written.try_iter() {
        output.written(i, seconds);
    }
    rendered?;
    progress.finish();
    Ok(())
}
