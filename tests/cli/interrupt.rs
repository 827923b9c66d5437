//! Interruption and the disk, through the binary: a render killed mid-way leaves only
//! whole frames under their final names and its rerun resumes the rest; a render whose
//! disk fills (a file-size limit) reports the file and the problem, leaves no partial
//! frame behind and does not panic; a read-only output directory is refused, naming it.

#![allow(clippy::unwrap_used)] // tests: a failed unwrap is a failed test

use std::path::Path;
use std::process::{Command, Stdio};
use std::time::Duration;

use crate::common::frf_command;

fn render_args(field: &Path, out: &Path, frames: &str) -> Vec<String> {
    let mut args: Vec<String> = [
        "render",
        field.to_str().unwrap(),
        "--env",
        "sky",
        "--orbit",
        "3.2,1.3",
        "--size",
        "64x48",
        "--frames",
        frames,
        "--out",
        out.to_str().unwrap(),
    ]
    .map(String::from)
    .to_vec();
    if let Some(flag) = frf_testkit::cpu_flag() {
        args.push(flag.into());
    }
    args
}

/// Frame files under their final names, and temporary files, in `dir`.
fn frames_and_temporaries(dir: &Path) -> (Vec<String>, Vec<String>) {
    let names: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().into_string().unwrap())
        .collect();
    let frames = names
        .iter()
        .filter(|n| n.starts_with("frame_"))
        .cloned()
        .collect();
    let temporaries = names
        .iter()
        .filter(|n| n.ends_with(".tmp"))
        .cloned()
        .collect();
    (frames, temporaries)
}

#[test]
fn a_killed_render_leaves_whole_frames_and_its_rerun_resumes() {
    let field = &frf_testkit::tiny_field().field;
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("shot");
    let args = render_args(field, &out, "40");
    let mut child = frf_command(&args)
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    // Killed (SIGKILL: no chance to clean up) once its first frames are there. The wait
    // ends either way: the render writes its frames or exits (a failure here).
    while !out.join("frame_0002.png").exists() {
        assert!(
            child.try_wait().unwrap().is_none(),
            "the render ended before it could be interrupted"
        );
        std::thread::sleep(Duration::from_millis(5));
    }
    child.kill().unwrap();
    child.wait().unwrap();
    let (frames, _) = frames_and_temporaries(&out);
    assert!(
        !out.join("render.json").exists(),
        "killed before the report"
    );
    // Every frame under its final name is whole: it decodes.
    for name in frames.iter().filter(|n| n.ends_with(".png")) {
        image::open(out.join(name)).unwrap_or_else(|e| panic!("{name}: {e}"));
    }
    let kept = frames.iter().filter(|n| n.ends_with(".png")).count();
    // The rerun resumes: the frames already there are kept, the rest rendered.
    let o = frf_command(&args).output().unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let report: serde_json::Value =
        serde_json::from_slice(&std::fs::read(out.join("render.json")).unwrap()).unwrap();
    let resumed = report["frames_resumed"].as_u64().unwrap() as usize;
    assert!(
        resumed + 1 >= kept && resumed >= 1,
        "resumed {resumed} of {kept} frames kept"
    );
    assert_eq!(
        report["frames_rendered"].as_u64().unwrap() as usize + resumed,
        40
    );
    let (frames, temporaries) = frames_and_temporaries(&out);
    assert_eq!(frames.iter().filter(|n| n.ends_with(".png")).count(), 40);
    // A frame cut by the kill may leave its temporary file; never a final name.
    assert!(
        temporaries.iter().all(|t| t.starts_with(".frame_")),
        "{temporaries:?}"
    );
}

#[test]
fn a_full_disk_is_reported_naming_the_file_without_partial_frames() {
    let field = &frf_testkit::tiny_field().field;
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("shot");
    let args = render_args(field, &out, "3");
    // A file-size limit of 4 KiB stands for a full disk: a 64x48 RGBA32F EXR is larger.
    // SIGXFSZ is ignored so that the write fails with EFBIG instead of killing the process.
    let quoted: Vec<String> = args.iter().map(|a| format!("'{a}'")).collect();
    let script = format!(
        "trap '' XFSZ; ulimit -f 4; exec '{}' {}",
        env!("CARGO_BIN_EXE_frf"),
        quoted.join(" ")
    );
    let o = Command::new("bash")
        .args(["-c", &script])
        .env("XDG_RUNTIME_DIR", std::env::temp_dir())
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(!o.status.success(), "{stderr}");
    assert_ne!(o.status.code(), Some(101), "panicked: {stderr}");
    assert!(
        stderr.contains("frame_0000") && stderr.to_lowercase().contains("file too large"),
        "{stderr}"
    );
    // Failed before its first frame: the directory it made is gone with its settings.
    assert!(!out.exists(), "left {:?}", frames_and_temporaries(&out));
}

/// A command that obeys file permissions: as root (CI), `frf` runs without the
/// capabilities that override them (`setpriv` from util-linux), so a read-only directory
/// is read-only to it too. `None` where root cannot drop them (a sandbox without the
/// capability to change its bounding set).
fn unprivileged_frf(args: &[String]) -> Option<Command> {
    const DROP: &str = "--bounding-set=-dac_override,-dac_read_search,-fowner";
    let uid = Command::new("id").arg("-u").output().unwrap();
    let cmd = if String::from_utf8_lossy(&uid.stdout).trim() == "0" {
        let can = Command::new("setpriv").args([DROP, "--", "true"]).status();
        if !can.is_ok_and(|s| s.success()) {
            return None;
        }
        let mut c = Command::new("setpriv");
        c.args([DROP, "--"])
            .arg(env!("CARGO_BIN_EXE_frf"))
            .args(args)
            .env("XDG_RUNTIME_DIR", std::env::temp_dir());
        c
    } else {
        frf_command(args)
    };
    Some(cmd)
}

/// Asserts that a run failed without panicking, naming `named` and "Permission denied".
fn assert_refused_for_permission(o: &std::process::Output, named: &str) {
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(!o.status.success(), "{stderr}");
    assert_ne!(o.status.code(), Some(101), "panicked: {stderr}");
    assert!(
        stderr.contains(named) && stderr.to_lowercase().contains("permission denied"),
        "{stderr}"
    );
}

#[test]
fn a_read_only_output_directory_is_refused_naming_it() {
    use std::os::unix::fs::PermissionsExt;
    let field = &frf_testkit::tiny_field().field;
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("shot");
    std::fs::create_dir(&out).unwrap();
    std::fs::set_permissions(&out, std::fs::Permissions::from_mode(0o555)).unwrap();
    let Some(mut render) = unprivileged_frf(&render_args(field, &out, "2")) else {
        eprintln!("skipped: running as root, and the capabilities cannot be dropped");
        return;
    };
    let o = render.output().unwrap();
    std::fs::set_permissions(&out, std::fs::Permissions::from_mode(0o755)).unwrap();
    // The error names an output file (not its temporary name) in the directory.
    assert_refused_for_permission(&o, &format!("{}/settings.json:", out.display()));
    assert!(std::fs::read_dir(&out).unwrap().next().is_none());

    // A field written into a read-only directory: refused, nothing left there.
    let cap = crate::common::staged_capture(dir.path());
    let fields = dir.path().join("fields");
    std::fs::create_dir(&fields).unwrap();
    std::fs::set_permissions(&fields, std::fs::Permissions::from_mode(0o555)).unwrap();
    let target = fields.join("a.frf");
    let args = [
        "ingest",
        cap.to_str().unwrap(),
        "--out",
        target.to_str().unwrap(),
    ]
    .map(String::from);
    let o = unprivileged_frf(&args).unwrap().output().unwrap();
    std::fs::set_permissions(&fields, std::fs::Permissions::from_mode(0o755)).unwrap();
    // Named: the field, or its resumable parts beside it.
    assert_refused_for_permission(&o, target.to_str().unwrap());
    assert!(std::fs::read_dir(&fields).unwrap().next().is_none());
}

/// An interrupted write of one file (Ctrl-C during `frf ingest`) ends with status 130 and
/// leaves neither its lock file nor its temporaries (`ingest-olat` once left
/// `.NAME.frf.lock`).
#[test]
fn an_interrupted_ingest_leaves_no_lock_or_temporary() {
    let dir = tempfile::tempdir().unwrap();
    let cap = crate::common::staged_capture(dir.path());
    // Ctrl-C and SIGTERM, to an ingest and to `stage field`, as the README says (only
    // SIGINT to an ingest was tested).
    for (k, (command, signal)) in [
        ("ingest", "INT"),
        ("ingest", "TERM"),
        ("stage field", "TERM"),
    ]
    .into_iter()
    .enumerate()
    {
        let out = dir.path().join(format!("out{k}"));
        std::fs::create_dir(&out).unwrap();
        let field = out.join("f.frf");
        let mut args: Vec<&str> = command.split(' ').collect();
        match command {
            "ingest" => args.extend([cap.to_str().unwrap(), "--no-eval"]),
            _ => args.extend(["--capture", cap.to_str().unwrap()]),
        }
        args.extend(["--out", field.to_str().unwrap()]);
        let mut child = frf_command(&args)
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .spawn()
            .unwrap();
        let lock = out.join(".f.frf.lock");
        while !lock.exists() {
            assert!(
                child.try_wait().unwrap().is_none(),
                "{command} ended before it could be interrupted"
            );
            std::thread::sleep(Duration::from_millis(5));
        }
        let sent = Command::new("kill")
            .args([&format!("-{signal}"), &child.id().to_string()])
            .status()
            .unwrap();
        assert!(sent.success());
        let status = child.wait().unwrap();
        assert_eq!(
            status.code(),
            Some(130),
            "{command}, SIG{signal}: {status:?}"
        );
        let left: Vec<_> = std::fs::read_dir(&out)
            .unwrap()
            .map(|e| e.unwrap().file_name())
            .collect();
        assert!(left.is_empty(), "{command}, SIG{signal}: {left:?}");
    }
}
