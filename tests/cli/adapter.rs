//! Which GPU adapter renders, through the binary: `frf info --gpu` lists the adapters and
//! the choice; on the GL backend (`WGPU_BACKEND=gl`; CI installs Mesa's GL driver for it)
//! a render either runs or is refused naming what GL lacks and suggesting `--cpu`, and
//! leaves no frame behind; an adapter named that does not exist is refused naming it.

#![allow(clippy::unwrap_used)] // tests: a failed unwrap is a failed test

use crate::common::{frf, frf_command, stderr};

#[test]
fn info_gpu_names_the_adapter_that_renders_and_why() {
    let o = frf(&["info", "--gpu", "--json"]);
    if !o.status.success() {
        // No adapter at all, allowed only where the tests are told so (FRF_SKIP_GPU):
        // said clearly, with the GPU's status.
        assert!(
            std::env::var_os("FRF_SKIP_GPU").is_some(),
            "info --gpu failed on a machine meant to have an adapter: {}",
            stderr(&o)
        );
        assert_eq!(o.status.code(), Some(4), "{}", stderr(&o));
        assert!(stderr(&o).contains("--cpu"), "{}", stderr(&o));
        return;
    }
    let report: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert!(!report["name"].as_str().unwrap().is_empty());
    assert!(report["why"].as_str().unwrap().contains("pass"), "{report}");
    let candidates = report["candidates"].as_array().unwrap();
    // The one taken can run every pass, and it is listed first among those that can.
    let first_able = candidates
        .iter()
        .find(|c| c["lacks"].as_array().unwrap().is_empty())
        .unwrap();
    assert!(
        first_able["adapter"]
            .as_str()
            .unwrap()
            .starts_with(report["name"].as_str().unwrap()),
        "{report}"
    );

    // Naming an adapter that does not exist is the caller's mistake (status 2).
    let o = frf(&["--adapter", "no-such-adapter", "info", "--gpu"]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("no-such-adapter"), "{}", stderr(&o));
}

#[test]
fn on_the_gl_backend_a_render_runs_or_is_refused_suggesting_the_cpu() {
    let field = &frf_testkit::tiny_field().field;
    let gl = |args: &[&str]| {
        frf_command(args)
            .env("WGPU_BACKEND", "gl")
            .output()
            .unwrap()
    };
    let info = gl(&["info", "--gpu"]);
    let said = String::from_utf8_lossy(&info.stdout).into_owned();
    eprintln!("info --gpu on GL: {said}{}", stderr(&info));
    let out = tempfile::tempdir().unwrap();
    let dir = out.path().join("frames");
    let render = gl(&[
        "render",
        field.to_str().unwrap(),
        "--env",
        "sky",
        "--orbit",
        "3.0,1.2",
        "--frames",
        "1",
        "--out",
        dir.to_str().unwrap(),
    ]);
    if info.status.success() {
        // A GL adapter that can run every pass renders like any other.
        assert!(said.contains("(Gl"), "{said}");
        assert!(render.status.success(), "{}", stderr(&render));
        assert!(dir.join("frame_0000.png").exists());
    } else {
        // GL lacks what the passes need (or there is no GL driver): refused, naming the
        // problem and the way out, with the GPU's status (4).
        for o in [&info, &render] {
            assert_eq!(o.status.code(), Some(4), "{}", stderr(o));
            assert!(stderr(o).contains("--cpu"), "{}", stderr(o));
        }
        assert!(!dir.join("frame_0000.png").exists());
        // The CPU reference renders where the GPU cannot.
        let cpu = gl(&[
            "render",
            field.to_str().unwrap(),
            "--env",
            "sky",
            "--orbit",
            "3.0,1.2",
            "--frames",
            "1",
            "--cpu",
            "--out",
            dir.to_str().unwrap(),
        ]);
        assert!(cpu.status.success(), "{}", stderr(&cpu));
    }
}

/// Outside a desktop session (no `XDG_RUNTIME_DIR`, as under a batch scheduler) a command
/// that opens no window prints nothing about a display server: Mesa's device-selection
/// layer probed Wayland and libwayland printed "error: XDG_RUNTIME_DIR is invalid or not
/// set" once per adapter enumeration, in the same words as the program's own errors
/// (issue 35).
#[test]
fn a_command_without_a_window_does_not_probe_for_a_display() {
    let mut c = frf_command(&["info", "--gpu"]);
    c.env_remove("XDG_RUNTIME_DIR")
        .env_remove("WAYLAND_DISPLAY")
        .env_remove("NODEVICE_SELECT")
        .env_remove("MESA_VK_DEVICE_SELECT");
    let o = c.output().unwrap();
    let said = stderr(&o);
    assert!(!said.contains("XDG_RUNTIME_DIR"), "{said}");
    assert!(!said.contains("error:") || !o.status.success(), "{said}");
}
