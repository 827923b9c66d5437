//! `frf export` as a user runs it: the tiny oracle field's walker written as a .glb that
//! the Khronos glTF validator passes with no error or warning (player/validate.mjs,
//! installed by scripts/setup.sh), its sizes reported, bad options and a field that is
//! not a grid refused by name with nothing written.

#![allow(clippy::unwrap_used)] // tests: a failed unwrap is a failed test

use std::path::Path;
use std::process::Command;

use crate::common::{frf, stderr};

/// The repository's `player/` directory.
fn player() -> &'static Path {
    Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/player"))
}

#[test]
fn export_writes_a_glb_the_khronos_validator_passes() {
    let f = frf_testkit::tiny_field();
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("walker.glb");
    let o = frf(&[
        "export",
        f.field.to_str().unwrap(),
        // Every part an export may hold (the basis images too) is validated.
        "--basis",
        "--out",
        out.to_str().unwrap(),
        "--json",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(text.contains("x the field's"), "{text}");
    let json_at = text.find('{').unwrap();
    let report: serde_json::Value = serde_json::from_str(&text[json_at..]).unwrap();
    assert_eq!(report["views"], 108);
    assert_eq!(
        report["bytes"].as_u64().unwrap(),
        std::fs::metadata(&out).unwrap().len()
    );

    assert!(
        player().join("node_modules/gltf-validator").exists(),
        "the player's npm packages are missing: run scripts/setup.sh"
    );
    let v = Command::new("node")
        .arg(player().join("validate.mjs"))
        .arg(&out)
        .output()
        .expect("node runs (scripts/setup.sh installs it)");
    let line = String::from_utf8_lossy(&v.stdout);
    assert!(
        v.status.success(),
        "{line} {}",
        String::from_utf8_lossy(&v.stderr)
    );
    let r: serde_json::Value = serde_json::from_str(line.trim()).unwrap();
    assert_eq!(
        (r["errors"].as_u64(), r["warnings"].as_u64()),
        (Some(0), Some(0)),
        "{line}"
    );
    // Every issue was counted (the cap of 50 stopped before the accessors were checked).
    assert_eq!(r["truncated"], false, "{line}");
    assert!(r["infos"].as_u64().unwrap() > 50, "{line}");

    // Controls: an accessor's `max` changed is an error the check reports (it said 0
    // errors, exit 0, under the cap); a truncated file, a missing one and none at all
    // are said in a line or refused, not a stack trace.
    let validate = |args: &[&Path]| {
        let v = Command::new("node")
            .arg(player().join("validate.mjs"))
            .args(args)
            .output()
            .unwrap();
        let line = String::from_utf8_lossy(&v.stdout).trim().to_string();
        (
            v.status.code(),
            line,
            String::from_utf8_lossy(&v.stderr).to_string(),
        )
    };
    let bytes = std::fs::read(&out).unwrap();
    let json_len = u32::from_le_bytes(bytes[12..16].try_into().unwrap()) as usize;
    let mut doc: serde_json::Value = serde_json::from_slice(&bytes[20..20 + json_len]).unwrap();
    let accessor = (doc["accessors"].as_array_mut().unwrap().iter_mut())
        .find(|a| a["max"].is_array())
        .unwrap();
    let max = accessor["max"][0].as_f64().unwrap();
    accessor["max"][0] = serde_json::json!(max + 1.0);
    let mut json = serde_json::to_vec(&doc).unwrap();
    json.resize(json.len().next_multiple_of(4), b' ');
    let rest = &bytes[20 + json_len..];
    let mut glb = bytes[..8].to_vec();
    glb.extend(((12 + 8 + json.len() + rest.len()) as u32).to_le_bytes());
    glb.extend((json.len() as u32).to_le_bytes());
    glb.extend(b"JSON");
    glb.extend(&json);
    glb.extend(rest);
    let broken = dir.path().join("broken.glb");
    std::fs::write(&broken, &glb).unwrap();
    let (code, line, err) = validate(&[&broken]);
    assert_eq!(code, Some(1), "{line} {err}");
    assert!(line.contains("ACCESSOR_MAX_MISMATCH"), "{line}");
    let truncated = dir.path().join("truncated.glb");
    std::fs::write(&truncated, &bytes[..bytes.len() / 3]).unwrap();
    for path in [truncated.as_path(), &dir.path().join("missing.glb")] {
        let (code, line, err) = validate(&[path]);
        assert_eq!(code, Some(1), "{line} {err}");
        let r: serde_json::Value =
            serde_json::from_str(&line).unwrap_or_else(|e| panic!("{e}: {line} {err}"));
        assert!(r["file"].is_string(), "{line}");
        assert!(
            r["errors"].as_u64().unwrap_or(1) > 0 || r["error"].is_string(),
            "{line}"
        );
        assert!(!err.contains("    at "), "a stack trace: {err}");
    }
    let (code, _, err) = validate(&[]);
    assert_eq!(code, Some(2), "{err}");
    assert!(err.contains("usage"), "{err}");
}

#[test]
fn export_refuses_bad_options_and_fields_it_cannot_export() {
    let f = frf_testkit::tiny_field();
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("walker.glb");
    for (flag, value, want) in [
        ("--views", "ring:3", "ring 3"),
        ("--views", "1;2", "expected U,V"),
        ("--poses", "7", "pose 7"),
        ("--jpeg-quality", "0", "--jpeg-quality 0"),
        ("--mesh-voxel", "0", "--mesh-voxel 0"),
        ("--tier", "tiny", "expected full or compact"),
        // Issue 59: a pose, view or heading given twice drew it twice; a heading of
        // 1e30 degrees was accepted.
        ("--poses", "0,0", "pose 0 is given twice"),
        ("--views", "0,0;0,0", "view 0,0 is given twice"),
        ("--headings", "0,0,0", "one direction"),
        ("--headings", "90,-270", "one direction"),
        ("--headings", "1e30,0", "-360 to 360"),
        // The size parser said 1 to 8192, the sheet's check 2048: one bound, said once.
        ("--sprite-size", "4096x4096", "1 to 2048 pixels a side"),
        ("--sprite-size", "0x10", "1 to 2048 pixels a side"),
        // Options of the sheet given to a glTF export were ignored silently.
        ("--sun", "60,40", "--sprites"),
        ("--env", "nosuch.hdr", "--sprites"),
        ("--exposure", "1", "--sprites"),
    ] {
        let o = frf(&[
            "export",
            f.field.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
            flag,
            value,
        ]);
        assert!(!o.status.success(), "{flag} {value} accepted");
        assert!(stderr(&o).contains(want), "{flag} {value}: {}", stderr(&o));
        assert!(!out.exists());
    }
    // The glTF's options given to a sheet, and an output named for the other mode's file.
    let sheet = dir.path().join("sheet.png");
    for (args, want) in [
        (
            vec![
                "--sprites",
                "--out",
                sheet.to_str().unwrap(),
                "--tier",
                "compact",
            ],
            "cannot be used with",
        ),
        (
            vec!["--out", sheet.to_str().unwrap()],
            "expected a .glb file, not .png",
        ),
        (
            vec!["--sprites", "--out", out.to_str().unwrap()],
            "expected a .png file, not .glb",
        ),
    ] {
        let mut all = vec!["export", f.field.to_str().unwrap()];
        all.extend(args.iter().copied());
        let o = frf(&all);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {}", stderr(&o));
        assert!(stderr(&o).contains(want), "{args:?}: {}", stderr(&o));
        assert!(!out.exists() && !sheet.exists());
    }
    // Not a field at all.
    let junk = dir.path().join("junk.frf");
    std::fs::write(&junk, b"not a field").unwrap();
    let o = frf(&[
        "export",
        junk.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(!o.status.success());
    assert!(stderr(&o).contains("junk.frf"), "{}", stderr(&o));
    assert!(!out.exists());
}

#[test]
fn export_sprites_writes_a_sheet_whose_frames_are_frf_renders() {
    let f = frf_testkit::tiny_field();
    let dir = tempfile::tempdir().unwrap();
    let sheet = dir.path().join("sheet.png");
    let mut args = vec![
        "export",
        f.field.to_str().unwrap(),
        "--sprites",
        "--out",
        sheet.to_str().unwrap(),
        "--headings",
        "0,90,200",
        "--sprite-size",
        "40x56",
    ];
    args.extend(frf_testkit::cpu_flag());
    let o = frf(&args);
    assert!(o.status.success(), "{}", stderr(&o));
    let png = image::open(&sheet).unwrap().to_rgba8();
    // The tiny field holds one pose: three rows of one column.
    assert_eq!(png.dimensions(), (40, 3 * 56));
    let json: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.path().join("sheet.json")).unwrap()).unwrap();
    assert_eq!(json["format"], "frf-sprites");
    let frames = json["frames"].as_array().unwrap();
    assert_eq!(frames.len(), 3);
    assert_eq!(
        (frames[1]["y"].as_u64(), frames[1]["heading_deg"].as_f64()),
        (Some(56), Some(90.0))
    );

    // Row 1 is what `frf render` draws from the camera on the orbit at azimuth 90.
    let out = dir.path().join("render");
    let mut args = vec![
        "render",
        f.field.to_str().unwrap(),
        "--env",
        "sky",
        "--orbit",
        "3.2,1.1",
        "--start",
        "90",
        "--frames",
        "1",
        "--size",
        "40x56",
        "--detail",
        "0",
        "--out",
        out.to_str().unwrap(),
    ];
    args.extend(frf_testkit::cpu_flag());
    let o = frf(&args);
    assert!(o.status.success(), "{}", stderr(&o));
    let frame = image::open(out.join("frame_0000.png")).unwrap().to_rgba8();
    let mut worst = 0i32;
    let mut covered = 0;
    for (x, y, p) in frame.enumerate_pixels() {
        let q = png.get_pixel(x, y + 56);
        covered += usize::from(p[3] > 128);
        for c in 0..4 {
            worst = worst.max((p[c] as i32 - q[c] as i32).abs());
        }
    }
    assert!(covered > 200, "{covered} pixels of the walker");
    assert!(
        worst <= 2,
        "the sheet's frame differs from frf render's by {worst} codes"
    );

    // Absurd options are refused by name, nothing written.
    for (flag, value, want) in [
        ("--headings", "0", "0 headings"),
        ("--sprite-size", "0x10", "0x10"),
        ("--sprite-orbit", "0,1", "radius"),
    ] {
        let bad = dir.path().join("bad.png");
        let o = frf(&[
            "export",
            f.field.to_str().unwrap(),
            "--sprites",
            "--out",
            bad.to_str().unwrap(),
            flag,
            value,
        ]);
        assert!(!o.status.success(), "{flag} {value}");
        assert!(stderr(&o).contains(want), "{flag} {value}: {}", stderr(&o));
        assert!(!bad.exists() && !dir.path().join("bad.json").exists());
    }
    // A sheet beyond what engines take is refused before anything renders (64 headings
    // of 2048x2048 asked for 32 GiB and more, unchecked).
    let bad = dir.path().join("huge.png");
    let o = frf(&[
        "export",
        f.field.to_str().unwrap(),
        "--sprites",
        "--out",
        bad.to_str().unwrap(),
        "--sprite-size",
        "2048x2048",
        "--headings",
        "9",
    ]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("2048x18432 pixels") && stderr(&o).contains("beyond 16384"),
        "{}",
        stderr(&o)
    );
    assert!(!bad.exists());
}

/// Issue 59: an output that names an input (by any path), or that another output of the
/// same run names, is refused with the input left as it was; an output that is not a
/// regular file is never replaced by a renamed temporary (a pipe refused, a device
/// written in place, its error reported); `env-sh` writes only what is named `.json`.
#[test]
fn an_output_never_replaces_an_input_or_a_file_that_is_not_regular() {
    let f = frf_testkit::tiny_field();
    let dir = tempfile::tempdir().unwrap();
    // A field named without an extension (an output named field.frf is refused first as
    // no .glb or .png).
    let field = dir.path().join("field");
    std::fs::copy(&f.field, &field).unwrap();
    let before = std::fs::read(&field).unwrap();
    let same = dir.path().join(".").join("field");
    for out in [&field, &same] {
        let o = frf(&[
            "export",
            field.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ]);
        assert!(!o.status.success(), "export over its field accepted");
        assert!(stderr(&o).contains("an input"), "{}", stderr(&o));
        let sprites = frf(&[
            "export",
            field.to_str().unwrap(),
            "--sprites",
            "--cpu",
            "--out",
            out.to_str().unwrap(),
        ]);
        assert!(!sprites.status.success(), "sprites over the field accepted");
        assert_eq!(
            std::fs::read(&field).unwrap(),
            before,
            "the field was replaced"
        );
    }
    // The sheet's JSON goes beside the image as NAME.json: an image named so is refused,
    // and so is a sheet whose JSON would replace the light it is lit by.
    let sheet_json = dir.path().join("sheet.json");
    let o = frf(&[
        "export",
        field.to_str().unwrap(),
        "--sprites",
        "--cpu",
        "--out",
        sheet_json.to_str().unwrap(),
    ]);
    assert!(!o.status.success());
    assert!(stderr(&o).contains(".json"), "{}", stderr(&o));
    assert!(!sheet_json.exists());
    let light = dir.path().join("light.json");
    assert!(
        frf(&["env-sh", "sky", "--out", light.to_str().unwrap()])
            .status
            .success()
    );
    let light_before = std::fs::read(&light).unwrap();
    let png = dir.path().join("light.png");
    let o = frf(&[
        "export",
        field.to_str().unwrap(),
        "--sprites",
        "--cpu",
        "--env",
        light.to_str().unwrap(),
        "--out",
        png.to_str().unwrap(),
    ]);
    assert!(
        !o.status.success(),
        "a sheet whose JSON replaces its light accepted"
    );
    assert_eq!(std::fs::read(&light).unwrap(), light_before);
    // env-sh over its own map.
    let map = dir.path().join("map.json");
    std::fs::copy(&light, &map).unwrap();
    let o = frf(&[
        "env-sh",
        map.to_str().unwrap(),
        "--out",
        map.to_str().unwrap(),
    ]);
    assert!(!o.status.success(), "env-sh over its map accepted");
    assert_eq!(std::fs::read(&map).unwrap(), light_before);
    // An SH light named as another kind of file (a field) is refused, the file kept.
    let field = dir.path().join("walk.frf");
    std::fs::write(&field, b"a field").unwrap();
    let o = frf(&["env-sh", "sky", "--out", field.to_str().unwrap()]);
    assert!(!o.status.success(), "an SH light written over walk.frf");
    assert!(stderr(&o).contains("not .frf"), "{}", stderr(&o));
    assert_eq!(std::fs::read(&field).unwrap(), b"a field");
    // A pipe is refused, not replaced by a regular file.
    let pipe = dir.path().join("pipe.json");
    assert!(
        Command::new("mkfifo")
            .arg(&pipe)
            .status()
            .unwrap()
            .success()
    );
    let o = frf(&["env-sh", "sky", "--out", pipe.to_str().unwrap()]);
    assert!(!o.status.success(), "a pipe replaced");
    assert!(stderr(&o).contains("not a regular file"), "{}", stderr(&o));
    use std::os::unix::fs::FileTypeExt;
    let kind = std::fs::symlink_metadata(&pipe).unwrap().file_type();
    assert!(kind.is_fifo(), "the pipe is now {kind:?}");
    // A device is written where it is: /dev/null takes it, /dev/full reports its error.
    if std::fs::metadata("/dev/full").is_ok_and(|m| m.file_type().is_char_device()) {
        assert!(
            frf(&["env-sh", "sky", "--out", "/dev/null"])
                .status
                .success()
        );
        let o = frf(&["env-sh", "sky", "--out", "/dev/full"]);
        assert!(
            !o.status.success(),
            "a write to /dev/full reported as written"
        );
        assert!(stderr(&o).contains("/dev/full"), "{}", stderr(&o));
        for device in ["/dev/null", "/dev/full"] {
            let kind = std::fs::symlink_metadata(device).unwrap().file_type();
            assert!(kind.is_char_device(), "{device} is now {kind:?}");
        }
    }
}
