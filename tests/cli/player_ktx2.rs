//! A walker exported with GPU-compressed atlases (`frf export --tier compact --textures
//! ktx2 --basis-textures ktx2`, issue 60): its codes' error stated by the export, its KTX2
//! images the only ones the Khronos validator warns of (it does not know
//! KHR_texture_basisu, which admits them), the player drawing it (transcoded to the GPU's
//! block format by three's KTX2Loader) within the targets against `frf render`,
//! and a damaged KTX2 image refused by name. (The full tier's three channels in one UASTC
//! image cost 3.7 dB at a captured view: export/tests/round_trip.rs, docs/export.md.)

#![allow(clippy::unwrap_used)] // tests: a failed unwrap is a failed test

use std::path::Path;
use std::process::Command;

use serde_json::Value;

use crate::common::{frf, stderr};
use crate::player::{frf_frame, grid_camera, player, screenshot, subject_psnr};

/// The views the test's cameras see through: a captured view, a quad's centre by it, and
/// the sunlit view, each with its grid neighbours (a sixth of the grid: the export's
/// UASTC encoding is its slowest part).
const VIEWS: &str = "2,0;2,1;2,2;3,0;3,1;3,2;4,0;4,1;4,2;19,0;19,1;20,0;20,1;21,0;21,1";

/// `frf export` of the tiny field's pose 0's [`VIEWS`] in the compact tier with its
/// basis, the transfer's atlases as `transfer` and the basis' as `basis`: the report.
fn export(field: &Path, (transfer, basis): (&str, &str), out: &Path) -> Value {
    let o = frf(&[
        "export",
        field.to_str().unwrap(),
        "--poses",
        "0",
        "--views",
        VIEWS,
        "--tier",
        "compact",
        "--basis",
        "--textures",
        transfer,
        "--basis-textures",
        basis,
        "--out",
        out.to_str().unwrap(),
        "--json",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let text = String::from_utf8_lossy(&o.stdout);
    serde_json::from_str(&text[text.find('{').unwrap()..]).unwrap()
}

/// The player's frame of `glb` against frf's of `field`, at the grid's `(u, v)` of
/// `document`, lit by `sh` and `sun`: subject PSNR, dB.
fn against_frf(
    (glb, field, document): (&Path, &Path, &Value),
    (u, v): (f32, f32),
    (sh, sun): (&Path, Option<&str>),
    dir: &Path,
) -> f64 {
    let shot = grid_camera(document, u, v);
    let case = dir.join(format!("{u}-{v}-{}", sun.unwrap_or("none")));
    std::fs::create_dir_all(&case).unwrap();
    let reference = frf_frame(field, sh, &shot, "64x90", sun, &case);
    let out = case.join("player.png");
    let o = screenshot(glb, sh, &shot, "64x90", sun, &out);
    assert!(o.status.success(), "{}", stderr(&o));
    subject_psnr(&reference, &out)
}

#[test]
fn ktx2_walkers_are_drawn_as_frf_renders_them() {
    let f = frf_testkit::tiny_field();
    let dir = tempfile::tempdir().unwrap();
    let sh = dir.path().join("sky.json");
    let o = frf(&["env-sh", "sky", "--out", sh.to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    let all = dir.path().join("all.glb");
    let report = export(&f.field, ("ktx2", "ktx2"), &all);
    // The codes' error as a reader decodes them, per atlas (measured on these views: the
    // compact transfer's one channel 46.0 dB, the basis' three 40.4).
    let errors = report["atlas_error"].as_array().unwrap();
    assert_eq!(errors.len(), 2, "{report}");
    for e in errors {
        let psnr = e["psnr_db"].as_f64().unwrap();
        assert!(psnr > 38.0 && psnr.is_finite(), "{e}");
        assert_eq!(e["mime"], "image/ktx2", "{e}");
    }

    // The validator: no error; its only warnings are on the KTX2 images (two each: a
    // media type and a format it does not know).
    let v = Command::new("node")
        .arg(player().join("validate.mjs"))
        .arg(&all)
        .output()
        .expect("node runs (scripts/setup.sh installs it)");
    let line = String::from_utf8_lossy(&v.stdout);
    let r: Value = serde_json::from_str(line.trim()).unwrap();
    assert_eq!(r["errors"], 0, "{line}");
    let document = frf_export::read::Export::open(&all).unwrap().document;
    let ktx2_images: Vec<u64> = (document["images"].as_array().unwrap().iter())
        .enumerate()
        .filter(|(_, i)| i["mimeType"] == "image/ktx2")
        .map(|(k, _)| k as u64)
        .collect();
    // A transfer and a basis atlas a view.
    assert_eq!(ktx2_images.len(), 2 * VIEWS.split(';').count());
    let warned: Vec<u64> = (r["warned_images"].as_array().unwrap().iter())
        .map(|i| i.as_u64().unwrap())
        .collect();
    assert_eq!(warned, ktx2_images, "{line}");
    assert_eq!(
        r["warnings"].as_u64().unwrap(),
        2 * ktx2_images.len() as u64,
        "{line}"
    );
    assert!(
        document["extensionsUsed"]
            .as_array()
            .unwrap()
            .contains(&"KHR_texture_basisu".into())
    );

    // Drawn against frf: the targets at a captured view, between views and with
    // frf's default sun relit by the basis (measured 35.9, 43.6 and 34.1 dB; the JPEG
    // export's 35.5, 43.7 and 34.9).
    let field = f.field.as_path();
    let at = |uv, sun| against_frf((&all, field, &document), uv, (&sh, sun), dir.path());
    let captured = at((3.0, 1.0), None);
    let between = at((3.5, 0.5), None);
    let sunlit = at((20.0, 0.0), Some("60,40"));
    eprintln!(
        "KTX2: {captured:.2} dB at a captured view, {between:.2} between views, {sunlit:.2} sunlit"
    );
    assert!(captured >= 35.0, "{captured:.2} dB");
    assert!(between >= 33.0, "{between:.2} dB");
    assert!(sunlit >= 30.0, "{sunlit:.2} dB");

    // A KTX2 image whose identifier is damaged is refused by name, nothing written.
    let bytes = std::fs::read(&all).unwrap();
    let (doc, bin) = frf_export::glb::unpack(&bytes).unwrap();
    let mut bin = bin.to_vec();
    let view = &doc["bufferViews"][doc["images"][ktx2_images[0] as usize]["bufferView"]
        .as_u64()
        .unwrap() as usize];
    let offset = view["byteOffset"].as_u64().unwrap_or(0) as usize;
    bin[offset..offset + 12].fill(0);
    let damaged = dir.path().join("damaged.glb");
    std::fs::write(&damaged, frf_export::glb::pack(&doc, &bin)).unwrap();
    let out = dir.path().join("refused.png");
    let shot = grid_camera(&document, 3.0, 1.0);
    let o = screenshot(&damaged, &sh, &shot, "64x90", None, &out);
    assert!(!o.status.success());
    assert!(
        stderr(&o).contains("damaged.glb") && stderr(&o).contains("does not transcode"),
        "{}",
        stderr(&o)
    );
    assert!(!out.exists());
}
