//! The bad-input corpus of `tests/bad/` through the binary: every case is refused with the
//! exit status of bad input (2) or of a damaged file (3), a message naming the file and
//! the problem, and no output left behind (no flow file, no render directory).

#![allow(clippy::unwrap_used)] // tests: a failed unwrap is a failed test

use std::path::{Path, PathBuf};

/// A case: the command (`{bad}` is the corpus directory, `{out}` a path in a fresh
/// scratch directory that must stay empty, `{field}` and `{capture}` the tiny stage's
/// field and capture), the file it names and the words of the problem.
struct Case {
    args: &'static [&'static str],
    file: &'static str,
    problem: &'static [&'static str],
}

const CASES: &[Case] = &[
    Case {
        args: &[
            "render",
            "{bad}/not_a_field.frf",
            "--orbit",
            "3,1.2",
            "--env",
            "sky",
            "--out",
            "{out}/o",
        ],
        file: "not_a_field.frf",
        problem: &["not a field file"],
    },
    Case {
        args: &[
            "render",
            "{bad}/short.frf",
            "--orbit",
            "3,1.2",
            "--env",
            "sky",
            "--out",
            "{out}/o",
        ],
        file: "short.frf",
        problem: &["too short for a field file"],
    },
    Case {
        args: &[
            "render",
            "{field}",
            "--camera",
            "{bad}/camera_backwards.toml",
            "--env",
            "sky",
            "--out",
            "{out}/o",
        ],
        file: "camera_backwards.toml",
        problem: &["key 1", "does not follow"],
    },
    // An output that is a directory, refused before the work (each used to do all of it,
    // then fail at the rename leaving a full-size temporary file beside it).
    Case {
        args: &[
            "stage",
            "field",
            "--capture",
            "{capture}",
            "--out",
            "{bad}/cap_missing",
        ],
        file: "cap_missing",
        problem: &["a directory is there"],
    },
    Case {
        args: &["ingest", "{capture}", "--out", "{bad}/cap_missing"],
        file: "cap_missing",
        problem: &["a directory is there"],
    },
    Case {
        args: &["merge", "{field}", "--out", "{bad}/cap_missing"],
        file: "cap_missing",
        problem: &["a directory is there"],
    },
    // A footer whose version disagrees with the preamble's (it used to be read).
    Case {
        args: &["info", "{bad}/footer_version.frf"],
        file: "footer_version.frf",
        problem: &["footer says format version 99", "preamble 1"],
    },
    // A viewer script in Latin-1 (it exited 5 naming no line).
    Case {
        args: &["view", "{field}", "--script", "{bad}/script_not_utf8.txt"],
        file: "script_not_utf8.txt",
        problem: &["line 2 is not UTF-8 text"],
    },
    // Orbit flags named as the user wrote them (they were named as a camera path's TOML
    // keys: "key 0: fov_deg 0 is outside (0.1, 170)", "key 0: a value is not finite").
    Case {
        args: &[
            "render", "{field}", "--orbit", "3,1.2", "--fov", "0", "--out", "{out}/o",
        ],
        file: "--fov",
        problem: &["a vertical field of view is within (0.1, 170)"],
    },
    Case {
        args: &[
            "render", "{field}", "--orbit", "3,1.2", "--fov", "nan", "--out", "{out}/o",
        ],
        file: "--fov",
        problem: &["an angle is a finite number"],
    },
    Case {
        args: &[
            "render", "{field}", "--orbit", "3,1.2", "--start", "inf", "--out", "{out}/o",
        ],
        file: "--start",
        problem: &["an angle is a finite number"],
    },
    // Orbit values the flags' parsers pass and the orbit refuses: named as the flags, with
    // the value and what is allowed (they were "orbit radius 0.0001 m is outside ...").
    Case {
        args: &[
            "render",
            "{field}",
            "--env",
            "sky",
            "--orbit",
            "0.0001,1.2",
            "--out",
            "{out}/o",
        ],
        file: "--orbit radius 0.0001",
        problem: &["expected more than 0.001 and less than 10000 metres"],
    },
    Case {
        args: &[
            "render",
            "{field}",
            "--env",
            "sky",
            "--orbit",
            "3,1.2,4000",
            "--out",
            "{out}/o",
        ],
        file: "--orbit sweep 4000",
        problem: &["expected -3600 to 3600 degrees"],
    },
    Case {
        args: &[
            "render",
            "{field}",
            "--env",
            "sky",
            "--orbit",
            "3,1.2",
            "--exposure",
            "40",
            "--out",
            "{out}/o",
        ],
        file: "--exposure 40",
        problem: &["expected -30 to 30 stops"],
    },
    // A memory budget of nothing: refused by the flag with nothing written (it was refused
    // at the first frame, after settings.json was written into a new --out).
    Case {
        args: &[
            "render",
            "{field}",
            "--orbit",
            "3,1.2",
            "--memory-budget",
            "0",
            "--out",
            "{out}/o",
        ],
        file: "--memory-budget",
        problem: &["'0'", "is not in 1.."],
    },
    // Chunks damaged in five places: `frf info` read only the index and said nothing;
    // `--check` reads every chunk, names the first damaged one and counts the rest.
    Case {
        args: &["info", "{bad}/damaged_chunks.frf", "--check"],
        file: "damaged_chunks.frf",
        problem: &["checksum mismatch", "more of the"],
    },
    // A pose range bounded before it is allocated (it used to take 23 GB, then be killed
    // with its lock left behind).
    Case {
        args: &[
            "merge",
            "{field}",
            "--expect",
            "0..4294967295",
            "--out",
            "{out}/m.frf",
        ],
        file: "--expect",
        problem: &["a cycle holds at most 100000"],
    },
    Case {
        args: &[
            "render",
            "{field}",
            "--orbit",
            "3,1.2",
            "--env",
            "{bad}/env_overflow.hdr",
            "--cpu",
            "--out",
            "{out}/o",
        ],
        file: "env_overflow.hdr",
        problem: &["total light", "32-bit floats", "scale the map down"],
    },
    Case {
        args: &[
            "render",
            "{field}",
            "--orbit",
            "3,1.2",
            "--env",
            "{bad}/env_black.hdr",
            "--cpu",
            "--out",
            "{out}/o",
        ],
        file: "env_black.hdr",
        problem: &["every texel is zero or negative", "lights nothing"],
    },
    Case {
        args: &[
            "render",
            "{field}",
            "--orbit",
            "3,1.2",
            "--env",
            "{bad}/good4.png",
            "--cpu",
            "--out",
            "{out}/o",
        ],
        file: "good4.png",
        problem: &["8-bit image is not a high-dynamic-range environment"],
    },
    Case {
        args: &["render", "{bad}/scene_size_not_a_pair.toml", "--plan"],
        file: "scene_size_not_a_pair.toml",
        problem: &["output.size", "3 values"],
    },
    Case {
        args: &["render", "{bad}/scene_size_not_numbers.toml", "--plan"],
        file: "scene_size_not_numbers.toml",
        problem: &["invalid type", "\"x\"", "line 19"],
    },
    Case {
        args: &["render", "{bad}/scene_nan_offset.toml", "--plan"],
        file: "scene_nan_offset.toml",
        problem: &["instance[0].time_offset", "NaN"],
    },
    Case {
        args: &["render", "{bad}/scene_device.toml", "--plan"],
        file: "scene_device.toml",
        problem: &["not a regular file"],
    },
    Case {
        args: &[
            "render",
            "{field}",
            "--orbit",
            "3,1.2",
            "--env",
            "sky",
            "--cpu",
            "--out",
            "{bad}/good4.png",
        ],
        file: "good4.png",
        problem: &["a file is there, not a directory"],
    },
    Case {
        args: &["render", "{bad}/scene_unknown_key.toml", "--plan"],
        file: "scene_unknown_key.toml",
        problem: &["unknown field `colour_grade`", "line 2"],
    },
    Case {
        args: &["render", "{bad}/scene_wrong_type.toml", "--plan"],
        file: "scene_wrong_type.toml",
        problem: &["invalid type", "line 3"],
    },
    Case {
        args: &["render", "{bad}/scene_missing_field.toml", "--plan"],
        file: "scene_missing_field.toml",
        problem: &["missing field `lighting`"],
    },
    Case {
        args: &["render", "{bad}/scene_out_of_range.toml", "--plan"],
        file: "scene_out_of_range.toml",
        problem: &["time.fps", "-10"],
    },
    Case {
        args: &["ingest", "{bad}/cap_wrong_type", "--out", "{out}/f.frf"],
        file: "capture.toml",
        problem: &["invalid type", "\"one\""],
    },
    Case {
        args: &["ingest", "{bad}/cap_unknown", "--out", "{out}/f.frf"],
        file: "capture.toml",
        problem: &["unknown field `flash`"],
    },
    Case {
        args: &["ingest", "{bad}/cap_missing", "--out", "{out}/f.frf"],
        file: "capture.toml",
        problem: &["missing field `timing`", "(a section or key is missing)"],
    },
    Case {
        args: &["ingest", "{bad}/cap_range", "--out", "{out}/f.frf"],
        file: "capture.toml",
        problem: &["cameras[0].width", "outside"],
    },
    Case {
        args: &[
            "flow",
            "{bad}/huge.png",
            "{bad}/good4.png",
            "--out",
            "{out}/f.flo",
        ],
        file: "huge.png",
        problem: &["limit"],
    },
    Case {
        args: &[
            "flow",
            "{bad}/truncated.png",
            "{bad}/good4.png",
            "--out",
            "{out}/f.flo",
        ],
        file: "truncated.png",
        problem: &["end of file"],
    },
    Case {
        args: &[
            "flow",
            "{bad}/good4.png",
            "{bad}/good5x4.png",
            "--out",
            "{out}/f.flo",
        ],
        file: "good5x4.png",
        problem: &["5x4", "4x4", "same size"],
    },
    Case {
        args: &[
            "flow",
            "{bad}/good4.png",
            "{bad}/good4.png",
            "--init",
            "{bad}/bad_magic.flo",
            "--out",
            "{out}/f.flo",
        ],
        file: "bad_magic.flo",
        problem: &["magic"],
    },
    Case {
        args: &[
            "flow",
            "{bad}/good4.png",
            "{bad}/good4.png",
            "--init",
            "{bad}/bad_size.flo",
            "--out",
            "{out}/f.flo",
        ],
        file: "bad_size.flo",
        problem: &["1000000000x1000000000", "outside"],
    },
    Case {
        args: &[
            "flow",
            "{bad}/good4.png",
            "{bad}/good4.png",
            "--init",
            "{bad}/short.flo",
            "--out",
            "{out}/f.flo",
        ],
        file: "short.flo",
        problem: &["truncated"],
    },
    Case {
        args: &[
            "flow",
            "{bad}/good4.png",
            "{bad}/good4.png",
            "--init",
            "{bad}/wrong_dims.flo",
            "--out",
            "{out}/f.flo",
        ],
        file: "wrong_dims.flo",
        problem: &["8x8", "4x4"],
    },
    Case {
        args: &[
            "render",
            "{field}",
            "--env",
            "{bad}/nan.exr",
            "--orbit",
            "3,1.2",
            "--frames",
            "1",
            "--out",
            "{out}/render",
        ],
        file: "nan.exr",
        problem: &["pixel (5, 1) is not finite"],
    },
    Case {
        args: &[
            "render",
            "{field}",
            "--env",
            "{bad}/huge.hdr",
            "--orbit",
            "3,1.2",
            "--frames",
            "1",
            "--out",
            "{out}/render",
        ],
        file: "huge.hdr",
        problem: &["limit"],
    },
    // Bytes appended to a whole field (were reported as a truncation).
    Case {
        args: &["info", "{bad}/appended.frf"],
        file: "appended.frf",
        problem: &["300 bytes follow the field's end"],
    },
    // A field where a scene belongs (was "line 1 is not UTF-8 text").
    Case {
        args: &["bench", "frame", "{bad}/appended.frf"],
        file: "appended.frf",
        problem: &["is a field file, not a scene file"],
    },
    // A mask selecting no pixel (scored every light inf dB, SSIM 1, exit 0), and nothing
    // made for `--images`.
    Case {
        args: &[
            "eval-olat",
            "{bad}/olat_black_mask",
            "--images",
            "{out}/images",
        ],
        file: "mask.png",
        problem: &["selects no pixel"],
    },
    // Intensities of 1e-38 (the photographs scaled by 1e38: -740 dB and NaN, exit 0).
    Case {
        args: &[
            "ingest-olat",
            "{bad}/olat_tiny_intensity",
            "--out",
            "{out}/f.frf",
        ],
        file: "light_intensities.txt",
        problem: &["line 1", "is not within"],
    },
    // A JPEG quality of 0 (exited 70, internal, naming no flag).
    Case {
        args: &[
            "ingest-olat",
            "{bad}/olat_black_mask",
            "--out",
            "{out}/f.frf",
            "--jpeg-quality",
            "0",
        ],
        file: "--jpeg-quality",
        problem: &["1..=100"],
    },
];

fn corpus() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/bad")
}

#[test]
fn every_bad_input_is_refused_naming_the_file_and_the_problem() {
    let field = &frf_testkit::tiny_field().field;
    let capture = frf_testkit::tiny_field().capture();
    let mut failures = Vec::new();
    for case in CASES {
        let out = tempfile::tempdir().unwrap();
        let args: Vec<String> = case
            .args
            .iter()
            .map(|a| {
                a.replace("{bad}", corpus().to_str().unwrap())
                    .replace("{out}", out.path().to_str().unwrap())
                    .replace("{field}", field.to_str().unwrap())
                    .replace("{capture}", capture.to_str().unwrap())
            })
            .collect();
        let o = crate::common::frf_command(&args).output().unwrap();
        let stderr = String::from_utf8_lossy(&o.stderr);
        let left: Vec<_> = std::fs::read_dir(out.path()).unwrap().collect();
        let named = stderr.contains(case.file);
        let explained = case.problem.iter().all(|w| stderr.contains(w));
        // Bad input is the caller's to correct (2) or a damaged file (3): never a panic's
        // 101, the GPU's 4 or the operating system's 5.
        let refused = matches!(o.status.code(), Some(2) | Some(3));
        if !(refused && named && explained && left.is_empty()) {
            failures.push(format!(
                "{}: status {:?}, names the file {named}, explains {explained}, left {} entries:\n{stderr}",
                args.join(" "),
                o.status.code(),
                left.len()
            ));
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

#[test]
fn the_corpus_is_exactly_the_files_the_cases_name() {
    // Every file of tests/bad is used by a case (or is a valid partner, or the README).
    let used: Vec<&str> = CASES
        .iter()
        .flat_map(|c| c.args.iter())
        .filter_map(|a| a.strip_prefix("{bad}/"))
        .collect();
    for entry in std::fs::read_dir(corpus()).unwrap() {
        let name = entry.unwrap().file_name().into_string().unwrap();
        assert!(
            name == "README.md" || used.contains(&name.as_str()),
            "tests/bad/{name} is not read by any case"
        );
    }
}

/// A frame of 8 bits per channel in a capture that declares 16-bit linear frames would
/// be read at 1/257 of its scale's precision (or, rescaled by mistake, 257 times too
/// dark): ingest refuses it naming the frame, before writing anything. (A capture is too
/// large for the corpus; this one is made here.)
#[test]
fn an_8_bit_frame_in_a_16_bit_capture_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let cap = crate::common::staged_capture(dir.path());
    let frame = frf_core::capture::Capture::open(&cap)
        .unwrap()
        .frame_path(0, 3, 1, 5);
    let linear = frf_core::io::read_rgb(&frame).unwrap();
    frf_core::io::write_png8_srgb(&frame, &linear, 1.0).unwrap();
    let out = dir.path().join("out");
    std::fs::create_dir(&out).unwrap();
    let o = crate::common::frf(&[
        "ingest",
        cap.to_str().unwrap(),
        "--flow-preset",
        "fast",
        "--no-eval",
        "--out",
        out.join("f.frf").to_str().unwrap(),
    ]);
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(
        !o.status.success() && o.status.code() != Some(101),
        "{stderr}"
    );
    assert!(
        stderr.contains(&frame.display().to_string())
            && stderr.contains("8 bits per channel where the capture declares 16-bit frames"),
        "{stderr}"
    );
    assert_eq!(
        std::fs::read_dir(&out).unwrap().count(),
        0,
        "ingest left output"
    );
}

/// A path is a path, not a string: a field and an output directory whose names are not
/// UTF-8 render, and the settings and report name them (issue 23: this ended in a panic
/// while writing the settings).
#[cfg(unix)]
#[test]
fn paths_that_are_not_utf8_render_and_are_named() {
    use std::ffi::OsStr;
    use std::os::unix::ffi::OsStrExt;
    let dir = tempfile::tempdir().unwrap();
    let field = dir.path().join(OsStr::from_bytes(b"walker\xff.frf"));
    std::fs::copy(&frf_testkit::tiny_field().field, &field).unwrap();
    let out = dir.path().join(OsStr::from_bytes(b"shot\xfe"));
    let mut args: Vec<&OsStr> = vec![OsStr::new("render"), field.as_os_str()];
    args.extend(
        [
            "--orbit", "3,1.2", "--env", "sky", "--frames", "1", "--size", "24x24", "--cpu",
            "--out",
        ]
        .map(OsStr::new),
    );
    args.push(out.as_os_str());
    let o = crate::common::frf_command(&args).output().unwrap();
    let said = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{said}");
    assert!(!said.contains("panicked"), "{said}");
    let settings: serde_json::Value =
        serde_json::from_slice(&std::fs::read(out.join("settings.json")).unwrap()).unwrap();
    let named = settings["files"]["field"]["path"].as_str().unwrap();
    assert!(named.ends_with("walker\u{fffd}.frf"), "{named}");
    assert!(out.join("frame_0000.png").exists());
}

/// An angle that is not a finite number is refused on the command line as the scene file
/// refuses it (issue 23: `--yaw nan` rendered a wrong picture with exit 0).
#[test]
fn a_yaw_that_is_not_finite_is_refused_by_every_command() {
    let field = frf_testkit::tiny_field()
        .field
        .to_str()
        .unwrap()
        .to_string();
    let out = tempfile::tempdir().unwrap();
    let o_dir = out.path().join("o");
    for yaw in ["nan", "inf", "-inf"] {
        // `--yaw=-inf`: clap reads `-inf` alone as flags.
        let yaw = format!("--yaw={yaw}");
        let yaw = yaw.as_str();
        for args in [
            vec![
                "render",
                &field,
                "--orbit",
                "3,1.2",
                "--env",
                "sky",
                yaw,
                "--out",
                o_dir.to_str().unwrap(),
            ],
            vec!["bench", "interp", "--field", &field, "--env", "sky", yaw],
            vec!["view", &field, yaw],
        ] {
            let o = crate::common::frf(&args);
            let said = String::from_utf8_lossy(&o.stderr);
            assert_eq!(o.status.code(), Some(2), "{args:?}: {said}");
            assert!(
                said.contains("--yaw") && said.contains("finite"),
                "{args:?}: {said}"
            );
        }
    }
    assert!(!o_dir.exists(), "nothing is written");
}

/// A FIFO given as a field or a scene is refused by name at once: opening it would wait
/// for a writer (issue 23: it hung).
#[cfg(unix)]
#[test]
fn a_fifo_given_as_a_field_or_a_scene_is_refused_at_once() {
    let dir = tempfile::tempdir().unwrap();
    for name in ["pipe.frf", "pipe.toml"] {
        let fifo = dir.path().join(name);
        let made = std::process::Command::new("mkfifo")
            .arg(&fifo)
            .status()
            .unwrap();
        assert!(made.success());
        let o = crate::common::frf(&["render", fifo.to_str().unwrap(), "--plan"]);
        let said = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(3), "{said}");
        assert!(
            said.contains(name) && said.contains("not a regular file"),
            "{said}"
        );
    }
}

/// An environment that fails to load ends with its own fault's status, as the library
/// says it (issue 59: `frf eval` and `frf bench` turned the error into a message, and
/// every such failure into a usage error, 2): the status `frf render` gives the same map,
/// 3 (damaged) for a garbage map and 5 (I/O) for a missing one; the message names the
/// environment and the file.
#[test]
fn an_environment_that_fails_to_load_keeps_its_fault() {
    let dir = tempfile::tempdir().unwrap();
    let garbage = dir.path().join("garbage.hdr");
    std::fs::write(&garbage, b"#?RADIANCE\nthis is not a picture\n").unwrap();
    let missing = dir.path().join("missing.hdr");
    let field = frf_testkit::tiny_field()
        .field
        .to_str()
        .unwrap()
        .to_string();
    for (map, status) in [(&garbage, 3), (&missing, 5)] {
        let map = map.to_str().unwrap();
        let out = dir.path().join("o");
        let out = out.to_str().unwrap();
        let rendered = crate::common::frf(&[
            "render", &field, "--orbit", "3,1.2", "--env", map, "--cpu", "--out", out,
        ]);
        let o = crate::common::frf(&[
            "bench", "interp", "--field", &field, "--env", map, "--size", "16x16",
        ]);
        let said = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(status), "{said}");
        assert_eq!(o.status.code(), rendered.status.code(), "{said}");
        assert!(said.contains("environment") && said.contains(map), "{said}");
    }
}
