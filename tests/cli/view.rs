//! `frf view` in a window under Xvfb, on the GPU (lavapipe on machines without one): a
//! scripted screenshot equals `frf render` of the same camera (the CPU reference) within
//! the GPU-vs-CPU tolerance, on a field and on a scene of two walkers; a recorded move
//! renders to the frames it was recorded at; every control a script has changes the
//! frame as it should; keys and the mouse (sent by xdotool) work as a person's; closing
//! the window (destroyed by another client, as `xdotool windowclose` does), a lost
//! display and no display end with a message, never a panic.
//!
//! Needs `xvfb-run` and `xdotool` (scripts/setup.sh installs them) and a GPU adapter; on
//! a machine without one (`FRF_SKIP_GPU=1`) the viewer cannot run and these tests say so.

#![allow(clippy::unwrap_used)] // tests: a failed unwrap is a failed test

use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::sync::Mutex;

use crate::common::{frf, stderr};

/// Largest difference of linear values between the GPU and the CPU reference
/// (`tests/gpu_vs_cpu.rs`).
const GPU_VS_CPU: f32 = 2e-3;

/// `xvfb-run -a` picks a display number racily: one viewer at a time.
static ONE_AT_A_TIME: Mutex<()> = Mutex::new(());

fn field() -> &'static PathBuf {
    &frf_testkit::tiny_field().field
}

/// Whether the viewer can run here: a GPU adapter, and Xvfb (else a failure saying what
/// to install).
fn can_view() -> bool {
    if frf_testkit::cpu_flag().is_some() {
        eprintln!("no GPU adapter (FRF_SKIP_GPU=1): the viewer needs one; not tested");
        return false;
    }
    for tool in ["xvfb-run", "xdotool"] {
        let found = Command::new("sh")
            .args(["-c", &format!("command -v {tool}")])
            .output()
            .is_ok_and(|o| o.status.success());
        assert!(
            found,
            "{tool} is missing: run scripts/setup.sh (xvfb, xauth, xdotool)"
        );
    }
    true
}

/// Runs `sh -c script` under a fresh Xvfb display, `$FRF` the binary. The script starts
/// once the display answers; a display that never did (a server that lost a race for
/// its number on a shared machine, seen once in CI) is tried again on a new one. The
/// status is the script's own: xvfb-run replaces it with 5 when it fails to remove its
/// own temporary directory afterwards (seen once on this machine), so the script says
/// its status on its last line of stderr.
fn under_xvfb(script: &str) -> Output {
    use std::os::unix::process::ExitStatusExt;

    let _one = ONE_AT_A_TIME.lock().unwrap_or_else(|e| e.into_inner());
    let ready = "for i in $(seq 50); do xdotool getdisplaygeometry >/dev/null 2>&1 && break; \
                 sleep 0.2; done\n";
    const SAID: &str = "under-xvfb status ";
    let run = || {
        let mut o = Command::new("xvfb-run")
            .args(["-a", "-s", "-screen 0 800x600x24", "sh", "-c"])
            .arg(format!(
                "{ready}{script}\nstatus=$?\necho \"{SAID}$status\" >&2\nexit $status"
            ))
            .env("FRF", env!("CARGO_BIN_EXE_frf"))
            .env("XDG_RUNTIME_DIR", std::env::temp_dir())
            .output()
            .unwrap();
        let said = stderr(&o);
        let own = (said.lines())
            .rev()
            .find_map(|l| l.strip_prefix(SAID))
            .and_then(|c| c.trim().parse::<i32>().ok());
        if let Some(code) = own {
            o.status = std::process::ExitStatus::from_raw(code << 8);
        }
        o
    };
    let first = run();
    if stderr(&first).contains("no display to open a window on") {
        return run();
    }
    first
}

/// `frf view INPUT --script FILE` (of `script`) with `args`, under Xvfb.
fn view(dir: &Path, input: &Path, script: &str, args: &str) -> Output {
    let file = dir.join("script.txt");
    std::fs::write(&file, script).unwrap();
    under_xvfb(&format!(
        "\"$FRF\" view '{}' --script '{}' {args}",
        input.display(),
        file.display()
    ))
}

fn ok(o: Output) -> Output {
    assert!(o.status.success(), "{}", stderr(&o));
    o
}

fn read_rgba(path: &Path) -> (u32, u32, Vec<f32>) {
    let img = image::open(path).unwrap().to_rgba32f();
    (img.width(), img.height(), img.into_raw())
}

fn largest_difference(a: &Path, b: &Path) -> f32 {
    let (wa, ha, pa) = read_rgba(a);
    let (wb, hb, pb) = read_rgba(b);
    assert_eq!((wa, ha), (wb, hb), "{} and {}", a.display(), b.display());
    pa.iter()
        .zip(&pb)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f32::max)
}

/// Largest difference of 8-bit PNGs, in levels.
fn largest_level_difference(a: &Path, b: &Path) -> u8 {
    let a = image::open(a).unwrap().to_rgba8().into_raw();
    let b = image::open(b).unwrap().to_rgba8().into_raw();
    assert_eq!(a.len(), b.len());
    a.iter().zip(&b).map(|(x, y)| x.abs_diff(*y)).max().unwrap()
}

#[test]
fn a_screenshot_equals_frf_render_of_the_same_camera() {
    if !can_view() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let script = format!(
        "camera 2.2 1.3 2.6  0 0.9 0  32\nscreenshot {0}/shot.exr\nscreenshot {0}/shot.png\nquit\n",
        d.display()
    );
    // Under the sky and a low sun of the viewer's own (relit by the field's normals).
    let o = ok(view(d, field(), &script, "--size 96x72 --sun 60,25 --json"));
    let report: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(report["ended"], "Quit", "{report}");
    assert!(report["frames"].as_u64().unwrap() >= 1, "{report}");
    std::fs::write(
        d.join("path.toml"),
        "[[key]]\ntime = 0.0\nposition = [2.2, 1.3, 2.6]\nlook_at = [0.0, 0.9, 0.0]\nfov_deg = 32.0\n",
    )
    .unwrap();
    let out = d.join("render");
    let o = frf(&[
        "render",
        field().to_str().unwrap(),
        "--camera",
        d.join("path.toml").to_str().unwrap(),
        "--env",
        "sky",
        "--sun",
        "60,25",
        "--backdrop",
        "env",
        "--size",
        "96x72",
        "--frames",
        "1",
        "--cpu",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let worst = largest_difference(&d.join("shot.exr"), &out.join("frame_0000.exr"));
    assert!(worst <= GPU_VS_CPU, "largest difference {worst}");
    // The PNG as frf render writes its frames: within a level of rounding.
    let levels = largest_level_difference(&d.join("shot.png"), &out.join("frame_0000.png"));
    assert!(levels <= 1, "{levels} levels");
}

#[test]
fn a_scene_of_two_walkers_is_shown_as_frf_render_draws_it() {
    if !can_view() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let scene = d.join("two.toml");
    std::fs::write(
        &scene,
        format!(
            r#"field = "{}"

[time]
end = 0.4
fps = 10.0

[output]
size = [80, 60]

[lighting]
env = "sky"
yaw_deg = 30.0

[camera]
[[camera.key]]
time = 0.0
position = [0.5, 1.6, 4.5]
look_at = [0.5, 0.9, 0.0]
fov_deg = 45.0

[composite]
backdrop = "env"
shadow = "maps"

[[instance]]
position = [0.0, 0.0, 0.0]

[[instance]]
position = [1.0, 0.0, -0.5]
heading_deg = 90.0
time_offset = 0.1
"#,
            field().display()
        ),
    )
    .unwrap();
    let script = format!("time 0.2\nscreenshot {}/t02.exr\nquit\n", d.display());
    ok(view(d, &scene, &script, "--size 80x60"));
    let out = d.join("render");
    let o = frf(&[
        "render",
        scene.to_str().unwrap(),
        "--frames",
        "2..3",
        "--cpu",
        // The viewer draws every walker at full detail.
        "--detail",
        "0",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let worst = largest_difference(&d.join("t02.exr"), &out.join("frame_0002.exr"));
    assert!(worst <= GPU_VS_CPU, "largest difference {worst}");
}

#[test]
fn a_recorded_move_renders_to_the_frames_it_was_recorded_at() {
    if !can_view() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    // Keys 6 frames apart at 24 frames per second: frames 0, 6 and 12 of the render.
    let script = format!(
        "time 0\ncamera 2.2 1.3 2.6  0 0.9 0  32\nkey\nscreenshot {0}/k0.exr\n\
         time 0.25\norbit 40 5\nkey\nscreenshot {0}/k1.exr\n\
         time 0.5\norbit 40 -10\ndolly 0.8\nkey\nscreenshot {0}/k2.exr\nquit\n",
        d.display()
    );
    let shot = d.join("shot.toml");
    let o = ok(view(
        d,
        field(),
        &script,
        &format!("--size 64x48 --record '{}'", shot.display()),
    ));
    assert!(
        stderr(&o).contains("recorded 3 camera keys"),
        "{}",
        stderr(&o)
    );
    // Rendered on the GPU as the viewer drew it (the CPU reference is the first test's).
    let out = d.join("render");
    let o = frf(&[
        "render",
        shot.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    for (k, frame) in [(0, 0), (1, 6), (2, 12)] {
        let worst = largest_difference(
            &d.join(format!("k{k}.exr")),
            &out.join(format!("frame_{frame:04}.exr")),
        );
        assert!(worst <= GPU_VS_CPU, "key {k}: largest difference {worst}");
    }
    // Recording with no key is refused by name, and writes nothing.
    let empty = d.join("empty.toml");
    let o = view(
        d,
        field(),
        "quit\n",
        &format!("--size 64x48 --record '{}'", empty.display()),
    );
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("nothing recorded"), "{}", stderr(&o));
    assert!(!empty.exists());
}

/// The mean of channel `c` over the image at `path`, and over its corners (2x2 each).
fn means(path: &Path, c: usize) -> (f32, f32) {
    let (w, h, p) = read_rgba(path);
    let at = |x: u32, y: u32| p[((y * w + x) * 4) as usize + c];
    let all = (0..h)
        .flat_map(|y| (0..w).map(move |x| (x, y)))
        .map(|(x, y)| at(x, y))
        .sum::<f32>()
        / (w * h) as f32;
    let corners = [(0, 0), (w - 2, 0), (0, h - 2), (w - 2, h - 2)]
        .iter()
        .flat_map(|&(x, y)| [(x, y), (x + 1, y), (x, y + 1), (x + 1, y + 1)])
        .map(|(x, y)| at(x, y))
        .sum::<f32>()
        / 16.0;
    (all, corners)
}

#[test]
fn every_control_of_a_script_changes_the_frame_as_it_should() {
    if !can_view() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let shot = |name: &str| d.join(format!("{name}.exr"));
    let script = format!(
        "camera 1.8 2.4 2.2  0 0.5 0  40\n\
         screenshot {base}\n\
         yaw 120\nscreenshot {yaw}\n\
         env uniform\nscreenshot {uniform}\n\
         env sky\nyaw 0\nintensity 2\nscreenshot {bright}\nintensity 1\n\
         variant nearest\nscreenshot {nearest}\nvariant fourway\n\
         layer shadow\nscreenshot {shadow}\n\
         shadow off\nscreenshot {no_shadow}\nshadow on\n\
         layer composite\nbackdrop none\nscreenshot {no_backdrop}\n\
         layer alpha\nscreenshot {alpha}\nlayer composite\nbackdrop env\n\
         view 9 2\nscreenshot {view}\norbit 4 1\nsnap\nscreenshot {snapped}\n\
         quit\n",
        base = shot("base").display(),
        yaw = shot("yaw").display(),
        uniform = shot("uniform").display(),
        bright = shot("bright").display(),
        nearest = shot("nearest").display(),
        shadow = shot("shadow").display(),
        no_shadow = shot("no_shadow").display(),
        no_backdrop = shot("no_backdrop").display(),
        alpha = shot("alpha").display(),
        view = shot("view").display(),
        snapped = shot("snapped").display(),
    );
    ok(view(d, field(), &script, "--size 64x48"));
    let differs = |a: &str, b: &str| largest_difference(&shot(a), &shot(b)) > 0.01;
    assert!(differs("base", "yaw"), "turning the light relights");
    assert!(differs("base", "uniform"), "another environment relights");
    assert!(
        differs("base", "nearest"),
        "another interpolation draws otherwise"
    );
    // Twice the light: twice the radiance.
    let (base, _) = means(&shot("base"), 1);
    let (bright, _) = means(&shot("bright"), 1);
    assert!((bright / base - 2.0).abs() < 0.02, "{bright} / {base}");
    // The shadow layer: darker than 1 under the walker, 1 with the shadow off.
    let (shadow, _) = means(&shot("shadow"), 1);
    let (no_shadow, _) = means(&shot("no_shadow"), 1);
    assert!(shadow < 0.99, "{shadow}");
    assert!((no_shadow - 1.0).abs() < 1e-4, "{no_shadow}");
    // No backdrop: transparent corners; the alpha layer shows the walker alone.
    let (_, corners) = means(&shot("no_backdrop"), 3);
    assert_eq!(corners, 0.0);
    let (alpha, alpha_corners) = means(&shot("alpha"), 0);
    assert!(
        alpha > 0.02 && alpha_corners == 0.0,
        "{alpha} {alpha_corners}"
    );
    // Snapping back from a little off a captured view returns to it.
    assert!(
        !differs("view", "snapped"),
        "snap returns to the captured view"
    );
}

#[test]
fn a_bad_script_or_request_is_refused_by_name() {
    if !can_view() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    // Checked before any window opens.
    let script = d.join("bad.txt");
    std::fs::write(&script, "time 0\nfly 3\n").unwrap();
    let o = frf(&[
        "view",
        field().to_str().unwrap(),
        "--script",
        script.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("bad.txt:2"), "{}", stderr(&o));
    // Refused while running: a view the grid does not have, an environment not offered.
    for (line, words) in [
        ("view 99 0", "no captured view (99, 0)"),
        ("env mars.hdr", "no environment \"mars.hdr\" offered"),
    ] {
        let o = view(d, field(), &format!("{line}\nquit\n"), "--size 64x48");
        assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
        let said = stderr(&o);
        assert!(
            said.contains("script.txt:1") && said.contains(words),
            "{said}"
        );
        assert!(!said.contains("panicked"), "{said}");
    }
}

#[test]
fn keys_and_the_mouse_drive_the_viewer_as_a_person_does() {
    if !can_view() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let shot = d.join("keys.toml");
    // The panel hidden (F1), a key at the captured view, a drag that orbits, the light
    // turned a step (]), a pose forward (.), a second key, Escape.
    let log = d.join("view.log");
    let o = under_xvfb(&format!(
        "\"$FRF\" view '{}' --size 240x180 --record '{}' 2>'{log}' &\n\
         P=$!\n\
         for i in $(seq 60); do W=$(xdotool search --onlyvisible --name 'frf view' | head -1); [ -n \"$W\" ] && break; sleep 0.5; done\n\
         sleep 2; xdotool windowfocus $W mousemove 100 90; sleep 1\n\
         xdotool key F1; sleep 1; xdotool key k; sleep 1\n\
         xdotool mousedown 1 mousemove 130 90 sleep 0.3 mousemove 160 100 sleep 0.3 mouseup 1; sleep 1\n\
         xdotool key bracketright; sleep 1; xdotool key period; sleep 1; xdotool key k; sleep 1\n\
         xdotool key Escape\n\
         wait $P; echo \"rc=$?\"; cat '{log}' >&2",
        field().display(),
        shot.display(),
        log = log.display(),
    ));
    let said = format!("{}{}", String::from_utf8_lossy(&o.stdout), stderr(&o));
    assert!(said.contains("rc=0"), "{said}");
    assert!(said.contains("recorded 2 camera keys"), "{said}");
    let scene = frf_scene::Scene::load(&shot).unwrap();
    assert!((scene.lighting[0].yaw_deg - 15.0).abs() < 1e-3);
    let frf_scene::path::Trajectory::Path(path) = &scene.camera else {
        panic!("a recorded move is a path of keys");
    };
    let [a, b] = &path.keys[..] else {
        panic!("{:?}", path.keys);
    };
    // One pose later, seen from elsewhere on the same orbit.
    assert!(b.time > a.time, "{a:?} {b:?}");
    assert!(
        a.position != b.position && a.look_at == b.look_at,
        "{a:?} {b:?}"
    );
}

#[test]
fn closing_the_window_or_losing_the_display_ends_with_a_message() {
    if !can_view() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let script = d.join("wait.txt");
    std::fs::write(&script, "wait 1000000\n").unwrap();
    let started = format!(
        "\"$FRF\" view '{}' --size 96x72 --script '{}' &\nP=$!\n\
         for i in $(seq 60); do W=$(xdotool search --onlyvisible --name 'frf view' | head -1); [ -n \"$W\" ] && break; sleep 0.5; done\n\
         sleep 1\n",
        field().display(),
        script.display()
    );
    // Closed by the window system.
    let o = under_xvfb(&format!(
        "{started}xdotool windowclose $W\nwait $P; echo \"rc=$?\""
    ));
    let said = format!("{}{}", String::from_utf8_lossy(&o.stdout), stderr(&o));
    // Seen closed (exit 0), or used in the moment it went away (said, exit 5).
    assert!(
        (said.contains("rc=0") && said.contains("the window was closed"))
            || (said.contains("rc=5") && said.contains("the window went away")),
        "{said}"
    );
    assert!(!said.contains("panicked"), "{said}");
    // The display going away (its connection killed): Xlib's message, no panic.
    let o = under_xvfb(&format!(
        "{started}xdotool windowkill $W\nwait $P; echo \"rc=$?\""
    ));
    let said = format!("{}{}", String::from_utf8_lossy(&o.stdout), stderr(&o));
    assert!(
        !said.contains("panicked") && !said.contains("rc=101"),
        "{said}"
    );
    assert!(!said.contains("rc=0"), "{said}");
    // No display at all.
    let o = crate::common::frf_command(&["view", field().to_str().unwrap()])
        .env_remove("DISPLAY")
        .env_remove("WAYLAND_DISPLAY")
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(5), "{}", stderr(&o));
    assert!(stderr(&o).contains("no display"), "{}", stderr(&o));
    assert!(!stderr(&o).contains("panicked"));
}
