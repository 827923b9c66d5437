//! One-light-at-a-time photographs: a calibrated set of one camera's photographs, each
//! lit by one distant light, in the layout such sets share (DiLiGenT's): `NNN.png` (8- or
//! 16-bit, numbered from 001 in the order of the lights), `light_directions.txt` (one
//! unit vector a line, in the camera's frame: x right, y up, z toward the camera),
//! optionally `light_intensities.txt` (`r g b` a line, which the images are divided by)
//! and `mask.png` (white where the object is).
//!
//! Pixel values are taken as stored, as linear radiance: such sets are taken with a
//! camera whose response is linear or was linearised. Every problem is refused naming
//! the file, and the line of a text file: a missing image, a light file whose length
//! does not match the images, a direction that is not finite or not of unit length, an
//! image of another size.

use std::path::{Path, PathBuf};

use frf_core::CoreError;
use frf_core::image::RgbImage;
use frf_core::io::read_rgb;
use glam::Vec3;

use crate::error::Result;

/// How far from unit length a light direction may be (calibration files round to six
/// digits).
pub const UNIT_TOLERANCE: f32 = 0.02;

/// A calibrated one-light-at-a-time set, read and checked.
pub struct OlatSet {
    /// The directory it was read from.
    pub dir: PathBuf,
    /// Per light, its photograph divided by its intensity (linear).
    pub images: Vec<RgbImage>,
    /// Per light, the unit direction toward it (camera frame).
    pub directions: Vec<Vec3>,
    /// Where the object is (`mask.png`; every pixel when there is none).
    pub mask: Vec<bool>,
}

impl OlatSet {
    /// Reads the set in `dir` (see the module text).
    pub fn read(dir: &Path) -> Result<Self> {
        let directions_path = dir.join("light_directions.txt");
        let directions: Vec<Vec3> = read_rows(&directions_path)?
            .into_iter()
            .map(|(line, v)| {
                let d = Vec3::from_array(v);
                if (d.length() - 1.0).abs() > UNIT_TOLERANCE {
                    return Err(CoreError::bad_file(
                        &directions_path,
                        format!(
                            "line {line}: the direction {v:?} is not of unit length (its length is {:.4})",
                            d.length()
                        ),
                    ));
                }
                Ok(d.normalize())
            })
            .collect::<Result<_, CoreError>>()?;
        if directions.is_empty() {
            return Err(CoreError::bad_file(&directions_path, "holds no light").into());
        }
        let intensities_path = dir.join("light_intensities.txt");
        let intensities: Vec<[f32; 3]> = if intensities_path.exists() {
            let rows = read_rows(&intensities_path)?;
            if rows.len() != directions.len() {
                return Err(CoreError::bad_file(
                    &intensities_path,
                    format!(
                        "{} lines, but light_directions.txt has {}: one intensity a light",
                        rows.len(),
                        directions.len()
                    ),
                )
                .into());
            }
            for (line, v) in &rows {
                if v.iter()
                    .any(|&c| !(INTENSITY_RANGE.0..=INTENSITY_RANGE.1).contains(&c))
                {
                    return Err(CoreError::bad_file(
                        &intensities_path,
                        format!(
                            "line {line}: the intensity {v:?} is not within {:e} to {:e} \
                             (the photographs are divided by it: a light's relative strength)",
                            INTENSITY_RANGE.0, INTENSITY_RANGE.1
                        ),
                    )
                    .into());
                }
            }
            rows.into_iter().map(|(_, v)| v).collect()
        } else {
            vec![[1.0; 3]; directions.len()]
        };
        let mut images: Vec<RgbImage> = Vec::with_capacity(directions.len());
        for (k, i) in intensities.iter().enumerate() {
            let path = dir.join(format!("{:03}.png", k + 1));
            if !path.exists() {
                return Err(CoreError::bad_file(
                    &path,
                    format!(
                        "missing: light_directions.txt lists {} lights, one image each",
                        directions.len()
                    ),
                )
                .into());
            }
            let img = read_rgb(&path)?;
            if let Some(first) = images.first()
                && first.size() != img.size()
            {
                return Err(CoreError::bad_file(
                    &path,
                    format!(
                        "is {}x{}, but 001.png is {}x{}",
                        img.width(),
                        img.height(),
                        first.width(),
                        first.height()
                    ),
                )
                .into());
            }
            images.push(img.map(|p| [p[0] / i[0], p[1] / i[1], p[2] / i[2]]));
        }
        let extra = dir.join(format!("{:03}.png", directions.len() + 1));
        if extra.exists() {
            return Err(CoreError::bad_file(
                &directions_path,
                format!(
                    "lists {} lights, but {} is there too: one line a light",
                    directions.len(),
                    extra.display()
                ),
            )
            .into());
        }
        let (w, h) = images[0].size();
        let mask_path = dir.join("mask.png");
        let mask = if mask_path.exists() {
            let m = read_rgb(&mask_path)?;
            if m.size() != (w, h) {
                return Err(CoreError::bad_file(
                    &mask_path,
                    format!(
                        "is {}x{}, but the images are {w}x{h}",
                        m.width(),
                        m.height()
                    ),
                )
                .into());
            }
            let mask: Vec<bool> = m
                .pixels()
                .iter()
                .map(|p| p[0] + p[1] + p[2] > 1.5)
                .collect();
            if !mask.contains(&true) {
                return Err(CoreError::bad_file(
                    &mask_path,
                    "selects no pixel (white marks the object): nothing would be scored",
                )
                .into());
            }
            mask
        } else {
            vec![true; w * h]
        };
        Ok(Self {
            dir: dir.to_path_buf(),
            images,
            directions,
            mask,
        })
    }
}

/// The intensities a light file may give, per channel: relative strengths of the
/// lights (calibrated sets give 0.2 to 5). Outside, dividing a 16-bit photograph by it
/// reaches values whose squared errors overflow (1e-38 gave −740 dB and NaN).
pub const INTENSITY_RANGE: (f32, f32) = (1e-6, 1e6);

/// The rows of three numbers of the light file at `path` ([`parse_rows`]).
fn read_rows(path: &Path) -> Result<Vec<(usize, [f32; 3])>, CoreError> {
    let text = std::fs::read_to_string(path).map_err(|e| CoreError::io(path, e))?;
    parse_rows(path, &text)
}

/// The rows of three numbers of a light file's `text`, with their line numbers (blank
/// lines and `#` comments skipped); a row that is not three finite numbers is refused
/// naming the file (`path`) and line.
pub fn parse_rows(path: &Path, text: &str) -> Result<Vec<(usize, [f32; 3])>, CoreError> {
    let mut rows = Vec::new();
    for (k, line) in text.lines().enumerate() {
        let line_no = k + 1;
        let line = line.trim();
        if line.is_empty() || line.starts_with('#') {
            continue;
        }
        let values: Vec<&str> = line
            .split(|c: char| c.is_whitespace() || c == ',')
            .filter(|s| !s.is_empty())
            .collect();
        let parsed: Option<Vec<f32>> = values.iter().map(|v| v.parse::<f32>().ok()).collect();
        match parsed {
            Some(v) if v.len() == 3 && v.iter().all(|x| x.is_finite()) => {
                rows.push((line_no, [v[0], v[1], v[2]]));
            }
            Some(v) if v.len() == 3 => {
                return Err(CoreError::bad_file(
                    path,
                    format!("line {line_no}: `{line}` is not finite"),
                ));
            }
            _ => {
                return Err(CoreError::bad_file(
                    path,
                    format!("line {line_no}: `{line}` is not three numbers"),
                ));
            }
        }
    }
    Ok(rows)
}

#[cfg(test)]
mod tests {
    use super::*;
    use frf_core::image::Image;
    use frf_core::io::write_png8_srgb;

    /// A set of `n` lights of 4x3 images in a new directory.
    fn set(n: usize) -> tempfile::TempDir {
        let dir = tempfile::tempdir().unwrap();
        let mut lines = String::new();
        for k in 0..n {
            let a = k as f32;
            let d = Vec3::new(a.cos() * 0.5, a.sin() * 0.5, 0.75f32.sqrt());
            lines.push_str(&format!("{} {} {}\n", d.x, d.y, d.z));
            let img = Image::from_vec(4, 3, vec![[0.5, 0.4, 0.3]; 12]).unwrap();
            write_png8_srgb(&dir.path().join(format!("{:03}.png", k + 1)), &img, 1.0).unwrap();
        }
        std::fs::write(dir.path().join("light_directions.txt"), lines).unwrap();
        dir
    }

    fn refused(dir: &Path) -> String {
        match OlatSet::read(dir) {
            Err(e) => e.to_string(),
            Ok(_) => panic!("{} was read", dir.display()),
        }
    }

    #[test]
    fn a_set_is_read_with_its_lights_in_order() {
        let dir = set(4);
        let s = OlatSet::read(dir.path()).unwrap();
        assert_eq!(s.images.len(), 4);
        assert_eq!(s.directions.len(), 4);
        assert!((s.directions[1].length() - 1.0).abs() < 1e-5);
        assert!(s.mask.iter().all(|&m| m));
    }

    #[test]
    fn a_missing_image_is_refused_by_name() {
        let dir = set(4);
        std::fs::remove_file(dir.path().join("003.png")).unwrap();
        let e = refused(dir.path());
        assert!(e.contains("003.png") && e.contains("missing"), "{e}");
    }

    #[test]
    fn a_light_file_of_the_wrong_length_is_refused() {
        let dir = set(4);
        let path = dir.path().join("light_directions.txt");
        let text = std::fs::read_to_string(&path).unwrap();
        let short: Vec<&str> = text.lines().take(3).collect();
        std::fs::write(&path, short.join("\n")).unwrap();
        let e = refused(dir.path());
        assert!(
            e.contains("light_directions.txt") && e.contains("3 lights"),
            "{e}"
        );
        std::fs::write(&path, &text).unwrap();
        std::fs::write(dir.path().join("light_intensities.txt"), "1 1 1\n1 1 1\n").unwrap();
        let e = refused(dir.path());
        assert!(
            e.contains("light_intensities.txt") && e.contains("2 lines"),
            "{e}"
        );
    }

    #[test]
    fn non_unit_and_nan_directions_are_refused_naming_the_line() {
        let dir = set(3);
        let path = dir.path().join("light_directions.txt");
        std::fs::write(&path, "0 0 1\n0 0.5 0.5\n0 0 1\n").unwrap();
        let e = refused(dir.path());
        assert!(e.contains("line 2") && e.contains("unit length"), "{e}");
        std::fs::write(&path, "0 0 1\n0 0 1\nNaN 0 1\n").unwrap();
        let e = refused(dir.path());
        assert!(e.contains("line 3") && e.contains("not finite"), "{e}");
        std::fs::write(&path, "0 0 1\n0 1\n0 0 1\n").unwrap();
        let e = refused(dir.path());
        assert!(e.contains("line 2") && e.contains("three numbers"), "{e}");
    }

    #[test]
    fn images_of_another_size_are_refused_by_name() {
        let dir = set(3);
        let img = Image::from_vec(5, 3, vec![[0.5, 0.4, 0.3]; 15]).unwrap();
        write_png8_srgb(&dir.path().join("002.png"), &img, 1.0).unwrap();
        let e = refused(dir.path());
        assert!(e.contains("002.png") && e.contains("5x3"), "{e}");
        let dir = set(3);
        write_png8_srgb(&dir.path().join("mask.png"), &img, 1.0).unwrap();
        let e = refused(dir.path());
        assert!(e.contains("mask.png"), "{e}");
    }

    #[test]
    fn intensities_divide_the_images() {
        let dir = set(2);
        std::fs::write(dir.path().join("light_intensities.txt"), "2 2 2\n1 1 1\n").unwrap();
        let s = OlatSet::read(dir.path()).unwrap();
        let (a, b) = (s.images[0].pixels()[0][0], s.images[1].pixels()[0][0]);
        assert!((2.0 * a - b).abs() < 1e-6, "{a} {b}");
    }
}
