//! The web player (`player/`) in a real browser: Debian's Chromium driven headless by
//! puppeteer-core on software GL (SwiftShader), as `scripts/setup.sh` installs them. The
//! tiny oracle field's walker is exported, lit by the built-in sky's L2 light, drawn by
//! `node player/screenshot.mjs` and by `frf render` from the same camera and pose, and
//! the two frames compared (subject PSNR); damaged files are refused by the player by
//! name with nothing written, and a walker without normals is drawn without its sun and
//! said so.

#![allow(clippy::unwrap_used)] // tests: a failed unwrap is a failed test

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use frf_core::io::srgb_to_linear;
use serde_json::Value;

use crate::common::{frf, stderr};

pub(crate) fn player() -> PathBuf {
    Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/player")).to_path_buf()
}

/// A camera of the screenshot's flags: centre, a point looked at, vertical fov (degrees).
pub(crate) struct Shot {
    pub(crate) eye: [f32; 3],
    pub(crate) look_at: [f32; 3],
    pub(crate) fov_deg: f32,
}

/// The camera blended bilinearly from pose 0's grid cameras at fractional `(u, v)`:
/// a captured view at integers, a quad's centre at halves.
pub(crate) fn grid_camera(document: &Value, u: f32, v: f32) -> Shot {
    grid_camera_of(document, 0, u, v)
}

/// [`grid_camera`] of the export's `at`-th pose's cameras.
pub(crate) fn grid_camera_of(document: &Value, at: usize, u: f32, v: f32) -> Shot {
    let ext = &document["extensions"]["FRF_flowed_reflectance_field"];
    let rows = ext["grid"]["rows"].as_u64().unwrap() as usize;
    let columns = ext["grid"]["columns"].as_u64().unwrap() as usize;
    let cameras = ext["poses"][at]["cameras"].as_array().unwrap();
    let (u0, v0) = (u.floor() as usize, v.floor() as usize);
    let (fu, fv) = (u - u0 as f32, v - v0 as f32);
    let mut eye = [0.0f32; 3];
    let mut forward = [0.0f32; 3];
    let mut fy = 0.0;
    for (du, dv, w) in [
        (0, 0, (1.0 - fu) * (1.0 - fv)),
        (1, 0, fu * (1.0 - fv)),
        (0, 1, (1.0 - fu) * fv),
        (1, 1, fu * fv),
    ] {
        if w == 0.0 {
            continue;
        }
        let c = &cameras[((u0 + du) % columns) * rows + (v0 + dv).min(rows - 1)];
        let m = &c["world_from_camera"];
        for (i, (e, f)) in eye.iter_mut().zip(forward.iter_mut()).enumerate() {
            *e += w * m[i][3].as_f64().unwrap() as f32;
            *f += w * m[i][2].as_f64().unwrap() as f32;
        }
        fy += w * c["intrinsics"][1].as_f64().unwrap() as f32;
    }
    let height = cameras[0]["height"].as_f64().unwrap() as f32;
    Shot {
        eye,
        look_at: [0, 1, 2].map(|i| eye[i] + forward[i]),
        fov_deg: (2.0 * (height / 2.0 / fy).atan()).to_degrees(),
    }
}

pub(crate) fn list(v: [f32; 3]) -> String {
    format!("{},{},{}", v[0], v[1], v[2])
}

/// `node player/screenshot.mjs` of `shot`, pose 0.
pub(crate) fn screenshot(
    glb: &Path,
    sh: &Path,
    shot: &Shot,
    size: &str,
    sun: Option<&str>,
    out: &Path,
) -> Output {
    screenshot_pose(glb, sh, shot, (size, sun), out, 0)
}

/// [`screenshot`] of `pose`.
fn screenshot_pose(
    glb: &Path,
    sh: &Path,
    shot: &Shot,
    (size, sun): (&str, Option<&str>),
    out: &Path,
    pose: u32,
) -> Output {
    assert!(
        player().join("node_modules/puppeteer-core").exists(),
        "the player's npm packages are missing: run scripts/setup.sh"
    );
    let mut c = Command::new("node");
    c.arg(player().join("screenshot.mjs"))
        .arg("--glb")
        .arg(glb)
        .args(["--pose", &pose.to_string(), "--size", size, "--json"])
        .arg(format!("--camera={}", list(shot.eye)))
        .arg(format!("--look-at={}", list(shot.look_at)))
        .args(["--fov", &shot.fov_deg.to_string()])
        .arg("--sh")
        .arg(sh)
        .arg("--out")
        .arg(out);
    if let Some(s) = sun {
        c.args(["--sun", s]);
    }
    c.output()
        .expect("node runs (scripts/setup.sh installs it)")
}

/// `frf render` of `shot` (one frame, no ground shadow), its PNG's path.
pub(crate) fn frf_frame(
    field: &Path,
    sh: &Path,
    shot: &Shot,
    size: &str,
    sun: Option<&str>,
    dir: &Path,
) -> PathBuf {
    frf_frame_pose(field, sh, shot, (size, sun), dir, None)
}

/// [`frf_frame`] of `pose` (`None`: the field's first).
fn frf_frame_pose(
    field: &Path,
    sh: &Path,
    shot: &Shot,
    (size, sun): (&str, Option<&str>),
    dir: &Path,
    pose: Option<u32>,
) -> PathBuf {
    let path = dir.join("camera.toml");
    std::fs::write(
        &path,
        format!(
            "[[key]]\ntime = 0.0\nposition = [{}]\nlook_at = [{}]\nfov_deg = {}\n",
            list(shot.eye),
            list(shot.look_at),
            shot.fov_deg
        ),
    )
    .unwrap();
    let out = dir.join("frf");
    let mut args = vec![
        "render".to_string(),
        field.display().to_string(),
        "--env".into(),
        sh.display().to_string(),
        "--camera".into(),
        path.display().to_string(),
        "--frames".into(),
        "1".into(),
        "--shadow".into(),
        "none".into(),
        "--detail".into(),
        "0".into(),
        "--size".into(),
        size.into(),
        "--out".into(),
        out.display().to_string(),
    ];
    if let Some(s) = sun {
        // The player's --sun is frf's.
        args.extend(["--sun".into(), s.to_string()]);
    }
    if let Some(p) = pose {
        args.extend(["--pose".into(), p.to_string()]);
    }
    args.extend(frf_testkit::cpu_flag().map(String::from));
    let refs: Vec<&str> = args.iter().map(String::as_str).collect();
    let o = frf(&refs);
    assert!(o.status.success(), "{}", stderr(&o));
    out.join("frame_0000.png")
}

/// Subject PSNR of `b` against `a` (8-bit sRGB, straight alpha): linear premultiplied
/// colour over the pixels either covers by half, peak `a`'s brightest.
pub(crate) fn subject_psnr(a: &Path, b: &Path) -> f64 {
    let load = |p: &Path| image::open(p).unwrap().to_rgba8();
    let (a, b) = (load(a), load(b));
    assert_eq!(a.dimensions(), b.dimensions());
    let lin = |p: &image::Rgba<u8>| {
        let alpha = p[3] as f64 / 255.0;
        (
            [0, 1, 2].map(|c| srgb_to_linear(p[c] as f32 / 255.0) as f64 * alpha),
            alpha,
        )
    };
    let (mut se, mut n, mut peak) = (0.0, 0usize, 0.0f64);
    for (pa, pb) in a.pixels().zip(b.pixels()) {
        let ((ca, aa), (cb, ab)) = (lin(pa), lin(pb));
        if aa > 0.5 || ab > 0.5 {
            for c in 0..3 {
                se += (ca[c] - cb[c]).powi(2);
                peak = peak.max(ca[c]);
            }
            n += 3;
        }
    }
    assert!(n > 300, "{n} subject samples");
    10.0 * (peak * peak / (se / n as f64)).log10()
}

/// The tiny oracle field's pose 0 exported, and the built-in sky's L2 light.
pub(crate) fn exported(dir: &Path) -> (PathBuf, PathBuf) {
    let f = frf_testkit::tiny_field();
    let glb = dir.join("walker.glb");
    let o = frf(&[
        "export",
        f.field.to_str().unwrap(),
        "--poses",
        "0",
        "--out",
        glb.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let sh = dir.join("sky.json");
    let o = frf(&["env-sh", "sky", "--out", sh.to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    (glb, sh)
}

#[test]
fn the_player_in_chromium_draws_what_frf_renders() {
    let f = frf_testkit::tiny_field();
    let dir = tempfile::tempdir().unwrap();
    let (glb, sh) = exported(dir.path());
    let document = frf_export::read::Export::open(&glb).unwrap().document;
    // (u, v, sun, least subject PSNR): a captured view, a quad's centre, a captured view
    // with a sun lighting by the normals (the targets).
    for (k, u, v, sun, least) in [
        (3.0, 1.0, None, 35.0),
        (3.5, 0.5, None, 30.0),
        (20.0, 0.0, Some("60,40,0.53,3"), 30.0),
        // frf's default sun (E = 10; measured 30.8 dB).
        (20.0, 0.0, Some("60,40"), 30.0),
        // A sun below the horizon: frf lights the walker from below softly, through its
        // floor conditions; the player adds the sun's L2 projection to its light (it lit
        // the walker by its normals). Measured 19.5 dB here (24.4 by the normals) and
        // 28.6 from the front (21.0 by the normals): the L2 band limit of a point light.
        (20.0, 0.0, Some("60,-30,0.53,10"), 18.0),
    ]
    .into_iter()
    .enumerate()
    .map(|(k, (u, v, sun, least))| (k, u, v, sun, least))
    {
        let shot = grid_camera(&document, u, v);
        let case = dir.path().join(format!("{k}-{u}-{v}"));
        std::fs::create_dir_all(&case).unwrap();
        let out = case.join("player.png");
        let o = screenshot(&glb, &sh, &shot, "64x90", sun, &out);
        assert!(
            o.status.success(),
            "{}{}",
            String::from_utf8_lossy(&o.stdout),
            stderr(&o)
        );
        let report: Value = serde_json::from_slice(&o.stdout).unwrap();
        assert_eq!(report["pose"], 0);
        let reference = frf_frame(&f.field, &sh, &shot, "64x90", sun, &case);
        let psnr = subject_psnr(&reference, &out);
        eprintln!("player against frf render at ({u}, {v}), sun {sun:?}: {psnr:.2} dB");
        assert!(
            psnr >= least,
            "({u}, {v}), sun {sun:?}: {psnr:.2} dB < {least}"
        );
        if sun.is_some_and(|s| s.contains(",-")) {
            assert!(
                report["notes"].to_string().contains("below the horizon"),
                "{report}"
            );
        }
    }
    // A sun too bright for half floats saturates the walker (it drew it dark: mean 9.6
    // against 109 without a sun). frf's own frame of it is not the reference: it shows
    // black texels where its basis' prediction of so bright a sun goes negative.
    let shot = grid_camera(&document, 20.0, 0.0);
    let (bright, none) = (dir.path().join("bright.png"), dir.path().join("none.png"));
    for (sun, out) in [(Some("60,40,0.53,1e30"), &bright), (None, &none)] {
        let o = screenshot(&glb, &sh, &shot, "64x90", sun, out);
        assert!(o.status.success(), "{}", stderr(&o));
    }
    let mean = |p: &Path| {
        let img = image::open(p).unwrap().to_rgba8();
        let lit: Vec<f64> = (img.pixels())
            .filter(|p| p[3] > 200)
            .map(|p| f64::from(p[0]) + f64::from(p[1]) + f64::from(p[2]))
            .collect();
        lit.iter().sum::<f64>() / lit.len().max(1) as f64
    };
    let (b, n) = (mean(&bright), mean(&none));
    assert!(
        b > n,
        "a sun of 1e30: subject mean {b:.1} against {n:.1} without"
    );
}

/// The tiny preset's `poses` staged without perturbation in `dir` and their oracle field
/// (`frf stage field` with `extra` arguments), the capture's images removed: its path.
pub(crate) fn staged_field(dir: &Path, poses: &str, extra: &[&str]) -> PathBuf {
    let (capture, field) = (dir.join("capture"), dir.join("staged.frf"));
    let made = frf(&[
        "stage",
        "--preset",
        "tiny",
        "--poses",
        poses,
        "--perturbation",
        "0",
        "--lights-per-axis",
        "1",
        "--out",
        capture.to_str().unwrap(),
    ]);
    assert!(made.status.success(), "{}", stderr(&made));
    let mut args = vec!["stage", "field", "--capture", capture.to_str().unwrap()];
    args.extend(extra);
    args.extend(["--out", field.to_str().unwrap()]);
    let made = frf(&args);
    assert!(made.status.success(), "{}", stderr(&made));
    std::fs::remove_dir_all(&capture).unwrap();
    field
}

/// The GLB `bytes` with its JSON chunk changed by `edit`, packed again as the exporter
/// packs it.
pub(crate) fn with_json(bytes: &[u8], edit: impl FnOnce(&mut Value)) -> Vec<u8> {
    let (mut doc, bin) = frf_export::glb::unpack(bytes).unwrap();
    edit(&mut doc);
    frf_export::glb::pack(&doc, bin)
}

#[test]
fn the_player_refuses_damaged_walkers_and_draws_one_without_normals_without_its_sun() {
    let dir = tempfile::tempdir().unwrap();
    let (glb, sh) = exported(dir.path());
    let bytes = std::fs::read(&glb).unwrap();
    let shot = Shot {
        eye: [0.0, 1.0, 4.5],
        look_at: [0.0, 0.9, 0.0],
        fov_deg: 30.0,
    };
    let truncated = dir.path().join("truncated.glb");
    std::fs::write(&truncated, &bytes[..bytes.len() - 1000]).unwrap();
    let future = dir.path().join("future.glb");
    std::fs::write(
        &future,
        with_json(&bytes, |d| {
            d["extensions"]["FRF_flowed_reflectance_field"]["version"] = 2.into()
        }),
    )
    .unwrap();
    for (file, want) in [
        (&truncated, "truncated.glb: its header says"),
        (
            &future,
            "future.glb: FRF_flowed_reflectance_field version 2",
        ),
    ] {
        let out = dir.path().join("refused.png");
        let o = screenshot(file, &sh, &shot, "32x45", None, &out);
        assert!(!o.status.success());
        assert!(stderr(&o).contains(want), "{}", stderr(&o));
        assert!(!out.exists(), "nothing is written for {}", file.display());
    }

    // Where the frame cannot go, or the walker is no file, it is said before anything
    // renders (a directory as --out rendered for seconds, then left DIR.tmp-PID and a
    // stack trace; a directory as --glb said "404 Not Found").
    let nowhere = dir.path().join("nodir").join("x.png");
    for (glb_at, out, want) in [
        (glb.as_path(), dir.path(), "a directory"),
        (glb.as_path(), nowhere.as_path(), "does not exist"),
        (dir.path(), &dir.path().join("y.png"), "not a file"),
    ] {
        let o = screenshot(glb_at, &sh, &shot, "32x45", None, out);
        assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
        assert!(stderr(&o).contains(want), "{}", stderr(&o));
        assert!(
            !stderr(&o).contains("    at "),
            "a stack trace: {}",
            stderr(&o)
        );
    }
    let left: Vec<_> = std::fs::read_dir(dir.path())
        .unwrap()
        .filter_map(|e| e.ok())
        .filter(|e| e.file_name().to_string_lossy().contains(".tmp-"))
        .collect();
    assert!(left.is_empty(), "left behind: {left:?}");

    // Normals gone: the sun cannot light it; the SH part draws, and the player says so.
    let bare = dir.path().join("bare.glb");
    std::fs::write(
        &bare,
        with_json(&bytes, |d| {
            for p in d["extensions"]["FRF_flowed_reflectance_field"]["poses"]
                .as_array_mut()
                .unwrap()
            {
                for v in p["views"].as_array_mut().unwrap() {
                    v["normals"] = Value::Null;
                }
            }
        }),
    )
    .unwrap();
    let (lit, plain) = (dir.path().join("sun.png"), dir.path().join("plain.png"));
    let o = screenshot(&bare, &sh, &shot, "32x45", Some("60,40,0.53,10"), &lit);
    assert!(o.status.success(), "{}", stderr(&o));
    let report: Value = serde_json::from_slice(&o.stdout).unwrap();
    assert!(
        report["notes"][0]
            .as_str()
            .unwrap()
            .contains("no fitted normals"),
        "{report}"
    );
    let o = screenshot(&bare, &sh, &shot, "32x45", None, &plain);
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(
        image::open(&lit).unwrap().to_rgba8(),
        image::open(&plain).unwrap().to_rgba8(),
        "without normals a sun adds nothing"
    );
}

/// The player reads an SH light file as frf does (issue 59): what frf refuses it refuses
/// (a negative band 0, a total light beyond 1e30, a version given as a string, another
/// convention, named by its field), and a byte-order mark is read past by both. It drew
/// the files frf refuses.
#[test]
fn the_player_reads_sh_files_as_frf_does() {
    let dir = tempfile::tempdir().unwrap();
    let sh = dir.path().join("sky.json");
    assert!(
        frf(&["env-sh", "sky", "--out", sh.to_str().unwrap()])
            .status
            .success()
    );
    let text = std::fs::read_to_string(&sh).unwrap();
    let doc: Value = serde_json::from_str(&text).unwrap();
    let edited = |edit: &dyn Fn(&mut Value)| {
        let mut d = doc.clone();
        edit(&mut d);
        serde_json::to_string_pretty(&d).unwrap()
    };
    let cases: Vec<(&str, String, Option<&str>)> = vec![
        ("as written", text.clone(), None),
        ("with a byte-order mark", format!("\u{feff}{text}"), None),
        (
            "band 0 negative",
            edited(&|d| d["coefficients"][0][1] = (-1.0).into()),
            Some("band 0 (its total light) is negative in channel 1"),
        ),
        (
            "beyond 1e30",
            edited(&|d| d["coefficients"][0][0] = 1e30.into()),
            Some("beyond what relighting can sum"),
        ),
        (
            "version a string",
            edited(&|d| d["version"] = "1".into()),
            Some("version \"1\""),
        ),
        (
            "another convention",
            edited(&|d| d["convention"]["condon_shortley_phase"] = true.into()),
            Some("condon_shortley_phase true"),
        ),
    ];
    let module = player().join("src/sh.js");
    for (what, content, refused) in cases {
        let path = dir.path().join("case.json");
        std::fs::write(&path, &content).unwrap();
        let by_frf = frf_core::sh::ShLight::load(&path);
        assert_eq!(by_frf.is_err(), refused.is_some(), "{what}: frf {by_frf:?}");
        let script = format!(
            "import {{ readFileSync }} from 'node:fs';\n\
             const m = await import({module:?});\n\
             const doc = JSON.parse({expected:?});\n\
             try {{ m.parseShLight(readFileSync({path:?}, 'utf8'), 'case.json', doc.convention); console.log('read'); }}\n\
             catch (e) {{ console.log('refused: ' + e.message); }}",
            module = format!("file://{}", module.display()),
            expected = text,
            path = path.display().to_string(),
        );
        let o = Command::new("node")
            .args(["--input-type=module", "-e", &script])
            .output()
            .unwrap();
        let said = String::from_utf8_lossy(&o.stdout).trim().to_string();
        match refused {
            None => assert_eq!(said, "read", "{what}: {said} {}", stderr(&o)),
            Some(want) => assert!(
                said.starts_with("refused") && said.contains(want),
                "{what}: the player {said}"
            ),
        }
        if let (Err(e), Some(want)) = (&by_frf, refused)
            && what != "version a string"
        {
            assert!(e.to_string().contains(want), "{what}: frf {e}");
        }
    }
}

/// What the player cannot draw it says (issue 59): an export of one view or one ring of
/// views draws the walker nowhere or partly (it drew a transparent frame, exit 0, no
/// note), a camera far above the grid sees nothing of it, and a view relit by a `scale`
/// of null is refused (it was read as 0).
#[test]
fn the_player_says_what_it_cannot_draw() {
    let f = frf_testkit::tiny_field();
    let dir = tempfile::tempdir().unwrap();
    let (glb, sh) = exported(dir.path());
    let shot = Shot {
        eye: [0.0, 1.0, 4.5],
        look_at: [0.0, 0.9, 0.0],
        fov_deg: 30.0,
    };
    let notes = |glb: &Path, shot: &Shot, name: &str| {
        let out = dir.path().join(name);
        let o = screenshot(glb, &sh, shot, "32x45", None, &out);
        assert!(o.status.success(), "{}", stderr(&o));
        let report: Value = serde_json::from_slice(&o.stdout).unwrap();
        report["notes"].to_string()
    };
    for (views, want) in [
        ("0,0", "0 of the grid's"),
        ("ring:1", "quads hold their four views"),
    ] {
        let part = dir
            .path()
            .join(format!("part_{}.glb", views.replace([',', ':'], "_")));
        let o = frf(&[
            "export",
            f.field.to_str().unwrap(),
            "--poses",
            "0",
            "--views",
            views,
            "--out",
            part.to_str().unwrap(),
        ]);
        assert!(o.status.success(), "{}", stderr(&o));
        let said = notes(&part, &shot, "part.png");
        assert!(said.contains(want), "--views {views}: {said}");
    }
    // The whole export from the front: nothing to say; from far above: nothing seen.
    assert!(!notes(&glb, &shot, "front.png").contains("quads"));
    let above = Shot {
        eye: [0.0, 60.0, 0.5],
        look_at: [0.0, 0.9, 0.0],
        fov_deg: 30.0,
    };
    let said = notes(&glb, &above, "above.png");
    assert!(
        said.contains("nothing of the walker is in the frame"),
        "{said}"
    );
    // A scale of null.
    let bytes = std::fs::read(&glb).unwrap();
    let nulled = dir.path().join("nulled.glb");
    std::fs::write(
        &nulled,
        with_json(&bytes, |d| {
            d["extensions"]["FRF_flowed_reflectance_field"]["poses"][0]["views"][0]["transfer"]
                ["scale"][2] = Value::Null;
        }),
    )
    .unwrap();
    let out = dir.path().join("nulled.png");
    let o = screenshot(&nulled, &sh, &shot, "32x45", None, &out);
    assert!(!o.status.success());
    assert!(
        stderr(&o).contains("transfer scale and offset"),
        "{}",
        stderr(&o)
    );
    assert!(!out.exists());
}

/// A walker of two poses that differ (issue 59: the player's test exported one pose and
/// could not see a wrong one): the player draws pose 3 as frf renders it, and pose 0
/// drawn in its place (a player showing the wrong pose) misses by far.
#[test]
fn the_player_draws_the_pose_asked_for() {
    // The tiny preset's poses 0 and 3, exported (the fixture the walk's tests share).
    let fixture = crate::player_motion::two_poses();
    let (field, glb, sh) = (&fixture.field, &fixture.glb, &fixture.sh);
    let dir = tempfile::tempdir().unwrap();
    let document = frf_export::read::Export::open(glb).unwrap().document;
    // A captured view of pose 3 (the export's second).
    let shot = grid_camera_of(&document, 1, 3.0, 1.0);
    let reference = frf_frame_pose(field, sh, &shot, ("64x90", None), dir.path(), Some(3));
    let score = |pose: u32| {
        let out = dir.path().join(format!("player{pose}.png"));
        let o = screenshot_pose(glb, sh, &shot, ("64x90", None), &out, pose);
        assert!(o.status.success(), "{}", stderr(&o));
        let report: Value = serde_json::from_slice(&o.stdout).unwrap();
        assert_eq!(report["pose"], pose);
        subject_psnr(&reference, &out)
    };
    let (right, wrong) = (score(3), score(0));
    eprintln!("pose 3 against frf's pose 3: {right:.2} dB; pose 0 in its place {wrong:.2} dB");
    assert!(right >= 35.0, "{right:.2} dB");
    assert!(
        wrong < right - 5.0,
        "pose 0 {wrong:.2} dB against pose 3 {right:.2}"
    );
}

/// A pose decodes only the views its camera's rays reach (the frame pass' quads, read
/// back), and draws the same frame as with every view decoded (`--all-views`, the
/// control): from a captured view, a quad's centre and a camera above the grid.
#[test]
fn the_player_decodes_only_the_views_a_camera_reaches() {
    let dir = tempfile::tempdir().unwrap();
    let (glb, sh) = exported(dir.path());
    let document = frf_export::read::Export::open(&glb).unwrap().document;
    let mut above = grid_camera(&document, 3.0, 1.0);
    above.eye = [above.eye[0] * 0.5, 3.0, above.eye[2] * 0.5];
    for (k, shot) in [
        grid_camera(&document, 3.0, 1.0),
        grid_camera(&document, 20.5, 0.5),
        above,
    ]
    .into_iter()
    .enumerate()
    {
        let mut frames = Vec::new();
        for all in [false, true] {
            let out = dir.path().join(format!("{k}-{all}.png"));
            let mut c = Command::new("node");
            c.arg(player().join("screenshot.mjs"))
                .arg("--glb")
                .arg(&glb)
                .args(["--pose", "0", "--size", "64x90", "--json", "--sun", "60,40"])
                .arg(format!("--camera={}", list(shot.eye)))
                .arg(format!("--look-at={}", list(shot.look_at)))
                .args(["--fov", &shot.fov_deg.to_string()])
                .arg("--sh")
                .arg(&sh)
                .arg("--out")
                .arg(&out);
            if all {
                c.arg("--all-views");
            }
            let o = c.output().unwrap();
            assert!(o.status.success(), "{}", stderr(&o));
            let report: Value = serde_json::from_slice(&o.stdout).unwrap();
            let [decoded, views] =
                [0, 1].map(|i| report["views_decoded"]["0"][i].as_u64().unwrap());
            eprintln!("camera {k}, all views {all}: {decoded} of {views} views decoded");
            assert_eq!(views, 108);
            if all {
                assert_eq!(decoded, 108);
            } else {
                assert!((4..=60).contains(&decoded), "camera {k}: {decoded} decoded");
            }
            frames.push(std::fs::read(&out).unwrap());
        }
        assert!(frames[0] == frames[1], "camera {k}: the frames differ");
    }
}
