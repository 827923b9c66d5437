//! A one-light-at-a-time set's light file of arbitrary text (`light_directions.txt`,
//! `light_intensities.txt`): parsing it must return its rows or an error naming the
//! line, never panic; every row accepted is three finite numbers on a line of the text,
//! in order. Read as directions, the rows `OlatSet::read` accepts (unit length within
//! `UNIT_TOLERANCE`) normalise to finite unit vectors; read as intensities, the rows it
//! accepts (within `INTENSITY_RANGE`) divide a photograph's values (0 to 1) to finite ones.
#![no_main]

use std::path::Path;

use frf_ingest::olat::{INTENSITY_RANGE, UNIT_TOLERANCE, parse_rows};
use glam::Vec3;
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let text = String::from_utf8_lossy(data);
    let Ok(rows) = parse_rows(Path::new("light_directions.txt"), &text) else {
        return;
    };
    let lines = text.lines().count();
    let mut last = 0;
    for &(line, v) in &rows {
        assert!(
            line > last && line <= lines,
            "row of line {line} after line {last}, of {lines} lines"
        );
        last = line;
        assert!(
            v.iter().all(|c| c.is_finite()),
            "line {line}: {v:?} accepted"
        );
        // As a direction.
        let d = Vec3::from_array(v);
        if (d.length() - 1.0).abs() <= UNIT_TOLERANCE {
            let n = d.normalize();
            assert!(
                n.is_finite() && (n.length() - 1.0).abs() <= 1e-5,
                "line {line}: the direction {v:?} normalises to {n}"
            );
        }
        // As an intensity.
        if v.iter()
            .all(|&c| (INTENSITY_RANGE.0..=INTENSITY_RANGE.1).contains(&c))
        {
            for c in v {
                for p in [0.0f32, f32::MIN_POSITIVE, 1.0 / 65535.0, 1.0] {
                    let q = p / c;
                    assert!(q.is_finite() && q >= 0.0, "line {line}: {p} / {c} is {q}");
                }
            }
        }
    }
});
