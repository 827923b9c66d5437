//! Camera paths off the grid on the tiny stage's oracle field, against the stage's truth:
//! an orbit inside the cylinder of cameras, low, whose rays toward the head leave the
//! grid below its bottom row, renders without a seam (the largest row-to-row jump of the
//! subject stays within 1.5 times the truth's, seen through the views' pixels), where
//! reading those rays along their direction tore the head from the body.

#![allow(clippy::unwrap_used)] // tests: a failed unwrap is a failed test

use frf_core::env::EnvMap;
use frf_core::filter::gaussian_blur;
use frf_eval::metrics::max_row_jump;
use frf_eval::paths::suite;
use frf_eval::views::{score, truth_frame};
use frf_render::morph::Variant;
use frf_render::renderer::Renderer;

#[test]
fn an_orbit_inside_the_cylinder_has_no_seam() {
    let tiny = frf_testkit::tiny_field();
    let env = EnvMap::sky();
    let source = tiny.source(&env);
    let paths = suite(&source.geometry).unwrap();
    let inside = paths.iter().find(|p| p.name == "inside-low").unwrap();
    // Frames much larger than the 64x90 views: a tear stays a tear while the true
    // image's row-to-row change shrinks.
    let cameras = inside.trajectory.cameras(2, 360, 360).unwrap();
    let lights = env.median_cut(64);
    let renderer = Renderer::new(&source, None).unwrap();
    // A view's pixel seen from the orbit, in frame pixels: no renderer of the views
    // is sharper than they are, so the truth is compared as seen through their pixels.
    let (view, orbit) = (&source.geometry.cameras[0], &cameras[0]);
    let distance = |c: &frf_core::camera::Camera| c.centre().length();
    let pixel = (orbit.intrinsics.fy / distance(orbit)) / (view.intrinsics.fy / distance(view));
    for (i, camera) in cameras.iter().enumerate() {
        let sharp = truth_frame(&tiny.stage, 0, camera, &lights).unwrap();
        let truth = gaussian_blur(&sharp, 0.5 * pixel);
        let truth_jump = max_row_jump(&truth);
        let scored = |v: Variant| {
            let (img, stats) = renderer.render(camera, v).unwrap();
            score(v.name(), &truth, &img, &stats, 0.0)
        };
        let (new, old) = (scored(Variant::FourWay), scored(Variant::FourWayNoProxy));
        eprintln!(
            "frame {i}: {:.1} % clamped; largest row jump: truth {truth_jump:.3}, four-way \
             {:.3} ({:.2} dB), along the ray's direction {:.3} ({:.2} dB)",
            100.0 * new.clamped_share,
            new.max_row_jump,
            new.psnr_subject,
            old.max_row_jump,
            old.psnr_subject
        );
        assert!(new.clamped_share > 0.05, "the orbit leaves the grid");
        assert!(
            new.max_row_jump <= 1.5 * truth_jump,
            "frame {i}: a seam: {} against the truth's {truth_jump}",
            new.max_row_jump
        );
        // What the test guards against: reading those rays along their direction.
        assert!(
            old.max_row_jump > 1.5 * truth_jump,
            "frame {i}: {}",
            old.max_row_jump
        );
        assert!(new.psnr_subject > old.psnr_subject);
    }
}
