//! The camera paths people render, scored: any trajectory (`frf eval --orbit` or
//! `--camera`), and a named suite of orbits placed against the capture's own cylinder of
//! cameras, so that each exercises one way of leaving the grid's quad centres.
//!
//! The suite is measured from the pose's cameras: `R` the bottom row's distance from the
//! vertical axis, `y0` its height (the capture cameras look at the subject's centre from
//! it), `y1` the top row's height. Every orbit looks at `(0, y0, 0)`, loops once, with a
//! vertical field of view of 35°:
//!
//! | name          | radius  | height            | what it tests                           |
//! |---------------|---------|-------------------|-----------------------------------------|
//! | `inside-low`  | 0.67 R  | y0 + 0.3 m        | inside the cylinder: rays below the grid |
//! | `inside-high` | 0.55 R  | y1 − 0.2 m        | inside, high: rays above and below       |
//! | `near`        | 0.97 R  | (y0 + y1) / 2     | just inside the cameras                 |
//! | `outside`     | 1.6 R   | (y0 + y1) / 2     | outside, inside the rows                |
//! | `above`       | 0.9 R   | y1 + 1 m          | above the top camera, looking down      |
//! | `below`       | R       | y0 − 0.6 m        | below the bottom camera, looking up     |
//!
//! For the stage's rig (4.5 m, rows at 0°, 17° and 34° about a target 0.9 m up) the first
//! is the orbit of radius 3 m at 1.2 m on which the seam at the neck was seen.

use frf_render::geometry::PoseGeometry;
use frf_render::path::{Orbit, Trajectory};
use glam::Vec3;

use crate::error::{EvalError, Result};

/// A named trajectory of the suite.
#[derive(Debug, Clone)]
pub struct NamedPath {
    /// Name in reports.
    pub name: &'static str,
    /// What it tests.
    pub about: &'static str,
    /// The trajectory.
    pub trajectory: Trajectory,
}

/// Vertical field of view of the suite's orbits, degrees.
const SUITE_FOV_DEG: f32 = 35.0;

/// `R`, `y0` and `y1` of a pose's grid (see the module docs).
fn rig(geometry: &PoseGeometry) -> Result<(f32, f32, f32)> {
    let row = |v: usize| -> Vec<Vec3> {
        (0..geometry.columns)
            .map(|u| geometry.cameras[geometry.view(u, v)].centre())
            .collect()
    };
    if geometry.columns == 0 || geometry.rows == 0 || geometry.cameras.is_empty() {
        return Err(EvalError::BadParameter("a pose without cameras".into()));
    }
    let (bottom, top) = (row(0), row(geometry.rows - 1));
    let n = bottom.len() as f32;
    let radius = bottom
        .iter()
        .map(|c| (c.x * c.x + c.z * c.z).sqrt())
        .sum::<f32>()
        / n;
    let y0 = bottom.iter().map(|c| c.y).sum::<f32>() / n;
    let y1 = top.iter().map(|c| c.y).sum::<f32>() / top.len() as f32;
    if !(radius.is_finite() && radius > 1e-3 && y0.is_finite() && y1.is_finite()) {
        return Err(EvalError::BadParameter(format!(
            "a grid of radius {radius} m, rows at {y0} and {y1} m"
        )));
    }
    Ok((radius, y0, y1))
}

/// The suite of paths for a pose's grid (see the module docs).
pub fn suite(geometry: &PoseGeometry) -> Result<Vec<NamedPath>> {
    let (r, y0, y1) = rig(geometry)?;
    let mid = 0.5 * (y0 + y1);
    let orbit = |radius: f32, height: f32| {
        Trajectory::Orbit(Orbit {
            radius,
            height,
            start_deg: 0.0,
            sweep_deg: 360.0,
            look_at: Vec3::new(0.0, y0, 0.0),
            fov_deg: SUITE_FOV_DEG,
        })
    };
    Ok(vec![
        NamedPath {
            name: "inside-low",
            about: "inside the cylinder, low: rays below the grid",
            trajectory: orbit(0.67 * r, y0 + 0.3),
        },
        NamedPath {
            name: "inside-high",
            about: "inside the cylinder, high: rays above and below the grid",
            trajectory: orbit(0.55 * r, y1 - 0.2),
        },
        NamedPath {
            name: "near",
            about: "just inside the cameras",
            trajectory: orbit(0.97 * r, mid),
        },
        NamedPath {
            name: "outside",
            about: "outside the cameras, between the rows",
            trajectory: orbit(1.6 * r, mid),
        },
        NamedPath {
            name: "above",
            about: "above the top camera, looking down",
            trajectory: orbit(0.9 * r, y1 + 1.0),
        },
        NamedPath {
            name: "below",
            about: "below the bottom camera, looking up",
            trajectory: orbit(r, y0 - 0.6),
        },
    ])
}

#[cfg(test)]
mod tests {
    use super::*;
    use frf_core::camera::Camera;
    use frf_render::geometry::Crop;

    #[test]
    fn the_suite_sits_where_its_names_say_on_a_stage_like_grid() {
        let mut cameras = Vec::new();
        for u in 0..36 {
            for e in [0.0f32, 17.0, 34.0] {
                let d = frf_core::light::direction_from_azimuth_elevation(
                    -(u as f32 * 10.0).to_radians(),
                    e.to_radians(),
                );
                let eye = Vec3::new(0.0, 0.9, 0.0) + d * 4.5;
                cameras.push(
                    Camera::look_at(eye, Vec3::new(0.0, 0.9, 0.0), Vec3::Y, 0.5, 32, 48).unwrap(),
                );
            }
        }
        let crop = Crop {
            x0: 0,
            y0: 0,
            width: 32,
            height: 48,
        };
        let g = PoseGeometry::new(0, 36, 3, true, (32, 48), crop, cameras, |_, _| false);
        let paths = suite(&g).unwrap();
        let at = |name: &str| match paths.iter().find(|p| p.name == name).unwrap().trajectory {
            Trajectory::Orbit(o) => o,
            _ => unreachable!(),
        };
        let low = at("inside-low");
        assert!((low.radius - 3.015).abs() < 0.01 && (low.height - 1.2).abs() < 1e-3);
        assert!(at("above").height > 0.9 + 4.5 * 34f32.to_radians().sin());
        assert!(at("below").height < 0.9);
        assert!(at("outside").radius > 4.5 && at("near").radius < 4.5);
        // Each path renders: its cameras are valid.
        for p in &paths {
            assert_eq!(p.trajectory.cameras(4, 32, 24).unwrap().len(), 4);
        }
    }
}
