//! An export read back as a player reads it: the GLB's transfer relit by an L2 light
//! against frf's own relighting of the field's basis images under the same light (its
//! map, `FloorModel::Environment`), view by view inside the matte; the hull meshes and
//! the walk animation present; damaged files and bad options refused by name.

#![allow(clippy::unwrap_used)] // tests: a failed unwrap is a failed test

use std::path::Path;

use frf_core::env::SH_MAP_HEIGHT;
use frf_core::image::{GrayImage, RgbImage};
use frf_core::sh::ShLight;
use frf_export::read::Export;
use frf_export::{ExportOptions, ExportReport, Textures, Tier, ViewSelection, export};
use frf_reflectance::FieldFile;
use frf_reflectance::project::FloorModel;
use frf_reflectance::relight::relight;
use tempfile::TempDir;

/// `field` exported with `options` into a new directory, read back, and opened: the
/// directory (kept while the test runs), the report, the export and the field.
fn exported(field: &Path, options: &ExportOptions) -> (TempDir, ExportReport, Export, FieldFile) {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("walker.glb");
    let report = export(field, &out, options).unwrap();
    let glb = Export::open(&out).unwrap();
    (dir, report, glb, FieldFile::open(field).unwrap())
}

/// PSNR of `got` against `want` (its brightest channel the peak) over the texels `alpha`
/// covers by more than half, and the samples it read (three a texel).
fn matte_psnr(want: &RgbImage, got: &RgbImage, alpha: &GrayImage) -> (f64, usize) {
    let (mut se, mut n, mut peak) = (0.0f64, 0usize, 0.0f32);
    for ((w, g), &a) in want.pixels().iter().zip(got.pixels()).zip(alpha.pixels()) {
        if a > 0.5 {
            for c in 0..3 {
                se += ((w[c] - g[c]) as f64).powi(2);
                peak = peak.max(w[c]);
            }
            n += 3;
        }
    }
    (
        10.0 * (peak as f64 * peak as f64 / (se / n as f64)).log10(),
        n,
    )
}

/// The built-in sky's L2 light.
fn light() -> ShLight {
    frf_core::env::EnvMap::sky().to_sh()
}

#[test]
fn the_exported_transfer_relights_as_frf_does() {
    relights_as_frf(Tier::Full, Textures::Jpeg, 40.0);
}

#[test]
fn the_compact_tier_relights_near_frf() {
    relights_as_frf(Tier::Compact, Textures::Jpeg, 38.0);
}

/// KTX2 atlases (UASTC) read back by the export's own reader. The full tier's three
/// channels share a block's endpoints: 36.6-40.9 dB against JPEG's 41.1-44.9 at these
/// views; the compact tier's one channel has them to itself: 41.1-44.0 against 39.8-43.2.
#[test]
fn ktx2_atlases_relight_near_frf() {
    relights_as_frf(Tier::Full, Textures::Ktx2, 35.0);
    relights_as_frf(Tier::Compact, Textures::Ktx2, 40.0);
}

/// Exports three views in `tier`, atlases as `textures`, and checks them relit against
/// frf above `floor_db`.
fn relights_as_frf(tier: Tier, textures: Textures, floor_db: f64) {
    let f = frf_testkit::tiny_field();
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("walker.glb");
    let views = vec![(0, 0), (7, 1), (20, 2)];
    let options = ExportOptions {
        tier,
        views: ViewSelection::List(views.clone()),
        textures,
        ..ExportOptions::default()
    };
    let report = export(&f.field, &out, &options).unwrap();
    assert_eq!((report.poses, report.views), (1, 3));
    assert!(report.triangles > 100);
    let glb = Export::open(&out).unwrap();
    let field = FieldFile::open(&f.field).unwrap();
    let projector = field.projector().unwrap();
    let light = light();
    // The L2 sky rings below zero opposite its sun; its signed map is the same light.
    let map = frf_core::env::EnvMap::from_sh(&light, SH_MAP_HEIGHT).unwrap();
    for (u, v) in views {
        let turntable = field.header().poses[0].views[field.header().view_index(u, v)]
            .turntable_deg
            .to_radians();
        let a = projector.project(&map, turntable, FloorModel::Environment);
        let want = relight(&field.basis(0, u, v).unwrap(), &a).unwrap();
        let got = glb.relight(0, u, v, &light).unwrap();
        let alpha = glb.alpha(0, u, v).unwrap();
        let (psnr, n) = matte_psnr(&want, &got, &alpha);
        assert!(n > 300, "view {u},{v}: {n} samples");
        eprintln!(
            "{tier:?} {textures:?} view {u},{v}: exported transfer against frf's relighting {psnr:.2} dB"
        );
        assert!(
            psnr > floor_db,
            "{tier:?} {textures:?} view {u},{v}: {psnr:.2} dB"
        );
    }
    // The schema names exactly the keys of what the writer wrote and the reader parsed
    // (the types of `frf_export::model`), at every object it describes.
    let schema: serde_json::Value = serde_json::from_str(include_str!(
        "../schema/FRF_flowed_reflectance_field.schema.json"
    ))
    .unwrap();
    let written = serde_json::to_value(glb.field()).unwrap();
    let problems = schema_keys(&schema, &written, &schema, "extension");
    assert!(problems.is_empty(), "{}", problems.join("\n"));
    // Control: a key the schema does not name, and one it names gone, are both found.
    let mut changed = written.clone();
    changed["grid"]["depth"] = serde_json::json!(1);
    changed["poses"][0]["views"][0]
        .as_object_mut()
        .unwrap()
        .remove("turntable_deg");
    let found = schema_keys(&schema, &changed, &schema, "extension").join("\n");
    assert!(
        found.contains("extension.grid.depth: not in the schema"),
        "{found}"
    );
    assert!(
        found.contains("views[0].turntable_deg: in the schema, not written"),
        "{found}"
    );
    let ext = glb.field();
    let pose = &ext.poses[0];
    // Every camera of the grid.
    assert_eq!(pose.cameras.len(), ext.grid.columns * ext.grid.rows);
    for view in &pose.views {
        let atlases = if tier == Tier::Full && textures == Textures::Jpeg {
            3
        } else {
            1
        };
        assert_eq!(view.transfer.images.len(), atlases);
        assert_eq!(view.transfer.colour.is_none(), tier == Tier::Full);
    }
    // The walk's speed and stride, as the field records them.
    let walk = ext.walk.expect("the tiny stage records its belt's speed");
    let field = frf_reflectance::FieldFile::open(&frf_testkit::tiny_field().field).unwrap();
    let h = field.header();
    let speed = h
        .gait_speed_mps
        .expect("the tiny stage records its belt's speed");
    assert!((walk.speed_mps - speed).abs() < 1e-9, "{walk:?}");
    assert!((walk.stride_m - speed * h.cycle_seconds).abs() < 1e-9);
    assert!(!walk.measured);
    // The walk: a node per pose under the walker, an animation switching them.
    let d = &glb.document;
    assert_eq!(d["nodes"][0]["children"].as_array().unwrap().len(), 1);
    assert_eq!(d["animations"][0]["channels"].as_array().unwrap().len(), 1);
    assert!(d["meshes"][0]["primitives"][0]["attributes"]["POSITION"].is_u64());
}

/// Where `value` and the JSON schema `schema` (of root `root`) disagree on keys: at every
/// object the schema describes (`properties`), a key it does not name, one it names that
/// is absent, or one it requires that is null. Follows `$ref` into `$defs`, `items`,
/// `anyOf` (null, or one branch that fits) and `additionalProperties`.
fn schema_keys(
    schema: &serde_json::Value,
    value: &serde_json::Value,
    root: &serde_json::Value,
    at: &str,
) -> Vec<String> {
    if let Some(r) = schema["$ref"].as_str() {
        let name = r.trim_start_matches("#/$defs/");
        return schema_keys(&root["$defs"][name], value, root, at);
    }
    if let Some(branches) = schema["anyOf"].as_array() {
        if value.is_null() {
            return Vec::new();
        }
        let fits = branches
            .iter()
            .filter(|b| b["type"] != "null")
            .map(|b| schema_keys(b, value, root, at))
            .min_by_key(Vec::len);
        return fits.unwrap_or_default();
    }
    let mut out = Vec::new();
    if let (Some(props), Some(object)) = (schema["properties"].as_object(), value.as_object()) {
        for key in object.keys().filter(|k| !props.contains_key(*k)) {
            out.push(format!("{at}.{key}: not in the schema"));
        }
        for (key, sub) in props {
            match object.get(key) {
                None => out.push(format!("{at}.{key}: in the schema, not written")),
                Some(v) => out.extend(schema_keys(sub, v, root, &format!("{at}.{key}"))),
            }
        }
        let required = schema["required"].as_array().into_iter().flatten();
        for key in required.filter_map(|k| k.as_str()) {
            if object.get(key).is_none_or(serde_json::Value::is_null) {
                out.push(format!("{at}.{key}: required, null"));
            }
        }
    }
    if let (Some(items), Some(array)) = (schema.get("items"), value.as_array()) {
        for (i, v) in array.iter().enumerate() {
            out.extend(schema_keys(items, v, root, &format!("{at}[{i}]")));
        }
    }
    if let (Some(each), Some(object)) = (
        schema.get("additionalProperties").filter(|a| a.is_object()),
        value.as_object(),
    ) {
        for (key, v) in object {
            out.extend(schema_keys(each, v, root, &format!("{at}.{key}")));
        }
    }
    out
}

/// `bytes` with the first `from` replaced by `to` (of the same length).
fn replaced(bytes: &[u8], from: &[u8], to: &[u8]) -> Vec<u8> {
    let at = bytes.windows(from.len()).position(|w| w == from).unwrap();
    let mut out = bytes.to_vec();
    out[at..at + to.len()].copy_from_slice(to);
    out
}

#[test]
fn damaged_exports_and_bad_options_are_refused_by_name() {
    let f = frf_testkit::tiny_field();
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("walker.glb");
    let options = ExportOptions {
        views: ViewSelection::Ring(1),
        ..ExportOptions::default()
    };
    export(&f.field, &out, &options).unwrap();
    let bytes = std::fs::read(&out).unwrap();
    let cases: Vec<(Vec<u8>, &str)> = vec![
        (bytes[..bytes.len() - 100].to_vec(), "truncated"),
        ([bytes.as_slice(), b"tail"].concat(), "appended"),
        (b"PK\x03\x04 not a glb".to_vec(), "no glTF magic"),
        (
            replaced(&bytes, b"\"version\":1,\"walk\"", b"\"version\":9,\"walk\""),
            "version 9",
        ),
    ];
    let bad = dir.path().join("bad.glb");
    for (b, want) in cases {
        std::fs::write(&bad, b).unwrap();
        let e = Export::open(&bad).unwrap_err().to_string();
        assert!(e.contains("bad.glb") && e.contains(want), "{want}: {e}");
    }
    // Options outside the field, and a field that is not a grid: no file written.
    let refused = dir.path().join("refused.glb");
    for (options, want) in [
        (
            ExportOptions {
                views: ViewSelection::Ring(3),
                ..ExportOptions::default()
            },
            "ring 3",
        ),
        (
            ExportOptions {
                views: ViewSelection::List(vec![(36, 0)]),
                ..ExportOptions::default()
            },
            "36,0",
        ),
        (
            ExportOptions {
                poses: Some(vec![5]),
                ..ExportOptions::default()
            },
            "pose 5",
        ),
        (
            ExportOptions {
                jpeg_quality: 0,
                ..ExportOptions::default()
            },
            "--jpeg-quality 0",
        ),
        (
            ExportOptions {
                mesh_voxel_m: f32::NAN,
                ..ExportOptions::default()
            },
            "--mesh-voxel",
        ),
    ] {
        let e = export(&f.field, &refused, &options)
            .unwrap_err()
            .to_string();
        assert!(e.contains(want), "{want}: {e}");
        assert!(!refused.exists());
    }
}

#[test]
fn a_field_without_normals_exports_without_them_and_says_so() {
    use frf_reflectance::FieldWriter;
    use frf_reflectance::chunk::ChunkKind;
    let f = frf_testkit::tiny_field();
    let dir = tempfile::tempdir().unwrap();
    // The tiny field less its normals' chunks.
    let field = FieldFile::open(&f.field).unwrap();
    let bare = dir.path().join("bare.frf");
    let mut w = FieldWriter::create(&bare, field.header().clone()).unwrap();
    let keys: Vec<_> = field.chunks().map(|c| c.key).collect();
    for key in keys.into_iter().filter(|k| k.kind != ChunkKind::Normals) {
        w.add_chunk(key, &field.read_chunk(&key).unwrap()).unwrap();
    }
    w.finish().unwrap();
    let out = dir.path().join("bare.glb");
    let options = ExportOptions {
        views: ViewSelection::List(vec![(3, 1)]),
        ..ExportOptions::default()
    };
    let report = export(&bare, &out, &options).unwrap();
    assert!(
        report.notes.iter().any(|n| n.contains("no fitted normals")),
        "{:?}",
        report.notes
    );
    let glb = Export::open(&out).unwrap();
    assert!(glb.view(0, 3, 1).unwrap().normals.is_none());
    // Relighting by the transfer does not need them.
    assert!(glb.relight(0, 3, 1, &light()).is_ok());
}

#[test]
fn flows_are_the_fields_within_a_code_and_extended_beyond_the_subject() {
    let f = frf_testkit::tiny_field();
    let options = ExportOptions {
        views: ViewSelection::List(vec![(5, 1)]),
        ..ExportOptions::default()
    };
    let (_dir, _, glb, field) = exported(&f.field, &options);
    let view = glb.view(0, 5, 1).unwrap();
    let index = view.flows["right"];
    let png = image::load_from_memory(glb.image_bytes(index).unwrap())
        .unwrap()
        .into_luma_alpha16();
    let want = field
        .flow(0, 5, 1, frf_core::grid::Neighbour::Right)
        .unwrap()
        .unwrap();
    let (mut known, mut unknown) = (0, 0);
    for (p, w) in png.pixels().zip(want.pixels()) {
        let got = [p[0], p[1]].map(|q| q as f32 / 256.0 - 128.0);
        if w[0].abs() < frf_core::flo::UNKNOWN_THRESHOLD {
            known += 1;
            for c in 0..2 {
                assert!(
                    (got[c] - w[c]).abs() <= 0.5 / 256.0 + 1e-4,
                    "{got:?} vs {w:?}"
                );
            }
        } else {
            // Beyond the subject: a flow the field holds near it, not the unknown code.
            unknown += 1;
            assert!(got.iter().all(|g| g.abs() < 64.0), "{got:?}");
        }
    }
    assert!(
        known > 500 && unknown > 500,
        "{known} known, {unknown} extended"
    );
}

/// A view's motion toward the next pose and a pose's ground-shadow maps come back from the
/// export as frf computes them (`frf_core::subject_motion::view_motion_m` of the field's
/// pose flow; the field's attenuation maps) within half a code, and each pose says where
/// its motion leads.
#[test]
fn motion_and_ground_shadows_are_the_fields_within_a_code() {
    let f = frf_testkit::tiny_two_poses();
    let options = ExportOptions {
        views: ViewSelection::List(vec![(5, 1)]),
        ..ExportOptions::default()
    };
    let (_dir, _, glb, field) = exported(&f.field, &options);
    let h = field.header();
    let ext = &glb.document["extensions"]["FRF_flowed_reflectance_field"];
    assert_eq!(
        ext["poses"][0]["motion_to"],
        serde_json::json!({"next": 3, "prev": 3})
    );
    assert_eq!(
        ext["poses"][1]["motion_to"],
        serde_json::json!({"next": 0, "prev": 0})
    );
    // Motion: pose 0's view 5,1 toward pose 3 (the same column within the cycle).
    let view = glb.view(0, 5, 1).unwrap();
    let motion = &view.motion["next"];
    let png = image::load_from_memory(glb.image_bytes(motion.image).unwrap())
        .unwrap()
        .into_luma_alpha16();
    let camera = |pose: u32| {
        h.pose(pose).unwrap().views[h.view_index(5, 1)]
            .camera
            .to_camera()
            .unwrap()
    };
    let flow = field
        .pose_flow(0, 5, 1, frf_core::grid::PoseStep::Next)
        .unwrap()
        .unwrap();
    let (w, hh) = flow.size();
    let want =
        frf_core::subject_motion::view_motion_m(&camera(0), &camera(3), &flow, (w, hh), |k| {
            (k % w, k / w)
        })
        .unwrap();
    let mut moving = 0;
    for (p, m) in png.pixels().zip(&want) {
        let got = [p[0], p[1]].map(|q| (f32::from(q) - 32768.0) * motion.step_m);
        assert!(
            (got[0] - m.x).abs() <= 0.5 * motion.step_m + 1e-7
                && (got[1] - m.y).abs() <= 0.5 * motion.step_m + 1e-7,
            "{got:?} vs {m}"
        );
        moving += usize::from(m.length() > 0.005);
    }
    assert!(moving > 200, "{moving} texels move by more than 5 mm");
    // Ground shadow: the maps stacked, one above the other.
    let maps = field.shadows(0).unwrap().unwrap();
    let index = ext["poses"][0]["ground_shadow"].as_u64().unwrap() as usize;
    let png = image::load_from_memory(glb.image_bytes(index).unwrap())
        .unwrap()
        .into_luma8();
    let n = ext["ground_shadow"]["texels"].as_u64().unwrap() as u32;
    assert_eq!(png.dimensions(), (n, n * maps.len() as u32));
    assert_eq!(
        ext["ground_shadow"]["weights"].as_array().unwrap().len(),
        maps.len()
    );
    let mut shaded = 0;
    for (m, map) in maps.iter().enumerate() {
        for (k, &a) in map.pixels().iter().enumerate() {
            let (x, y) = ((k as u32) % n, (k as u32) / n + m as u32 * n);
            let got = f32::from(png.get_pixel(x, y)[0]) / 255.0;
            assert!(
                (got - a).abs() <= 0.5 / 255.0 + 1e-6,
                "map {m} texel {k}: {got} vs {a}"
            );
            shaded += usize::from(a < 0.5);
        }
    }
    assert!(shaded > 10, "{shaded} texels shaded");
}

/// `--basis`: each view's basis images come back as the field holds them (every condition,
/// inside the matte, within the JPEG's error: above 40 dB of the condition's peak), with
/// the field's conditions; without it, a view holds none and reading them is refused.
#[test]
fn basis_images_are_the_fields_within_the_jpegs_error() {
    let f = frf_testkit::tiny_field();
    let views = ViewSelection::List(vec![(3, 1)]);
    let options = ExportOptions {
        views: views.clone(),
        basis: true,
        ..ExportOptions::default()
    };
    let (dir, report, glb, field) = exported(&f.field, &options);
    let basis_bytes = report.section_bytes[8].1;
    let transfer_bytes = report.section_bytes[0].1;
    assert!(
        basis_bytes > transfer_bytes,
        "{basis_bytes} vs {transfer_bytes}"
    );
    assert_eq!(
        glb.field().basis.as_ref().unwrap().conditions,
        field.header().conditions
    );
    let (got, want) = (glb.basis(0, 3, 1).unwrap(), field.basis(0, 3, 1).unwrap());
    let alpha = glb.alpha(0, 3, 1).unwrap();
    assert_eq!(got.len(), want.len());
    for (k, (g, w)) in got.iter().zip(&want).enumerate() {
        let (psnr, n) = matte_psnr(w, g, &alpha);
        assert!(
            n > 300 && psnr > 40.0,
            "condition {k}: {psnr:.2} dB over {n}"
        );
    }
    // Without --basis: none, and asking for them is refused by name.
    let plain = dir.path().join("plain.glb");
    let options = ExportOptions {
        views,
        ..ExportOptions::default()
    };
    export(&f.field, &plain, &options).unwrap();
    let glb = Export::open(&plain).unwrap();
    assert!(glb.field().basis.is_none());
    let e = glb.basis(0, 3, 1).unwrap_err().to_string();
    assert!(
        e.contains("plain.glb") && e.contains("no basis images"),
        "{e}"
    );
}
