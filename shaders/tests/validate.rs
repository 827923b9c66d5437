//! The WGSL of this crate: every file parses and validates with naga as compiled (the
//! shared definitions of `common.wgsl`, then the pass; the frame pass with every choice of
//! its sampling snippets), and every Pod mirror of [`frf_shaders::types`] has the size and
//! member offsets naga lays out for its WGSL twin. Needs no GPU.

#![allow(clippy::unwrap_used)] // tests: a failed unwrap is a failed test

use std::mem::{offset_of, size_of};

use frf_shaders as shaders;
use frf_shaders::types::{
    GpuColumnIndex, GpuComposite, GpuFrame, GpuHullAt, GpuInstance, GpuLightFitParams, GpuPresent,
    GpuProxy, GpuQuad, GpuQuadFrame, GpuRelightJob, GpuShadowJob, GpuSunDepthJob, GpuSunMap,
    GpuSunOccluder, GpuTimeMorph, GpuTurnJob, GpuTurnParams, GpuTurnRelight, GpuView,
};
use naga::valid::{Capabilities, ValidationFlags, Validator};

fn module(source: &str, name: &str) -> naga::Module {
    let module = naga::front::wgsl::parse_str(source)
        .unwrap_or_else(|e| panic!("{name}: {}", e.emit_to_string(source)));
    Validator::new(ValidationFlags::all(), Capabilities::default())
        .validate(&module)
        .unwrap_or_else(|e| panic!("{name}: {}", e.emit_to_string(source)));
    module
}

#[test]
fn every_wgsl_file_parses_and_validates_as_compiled() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).to_path_buf();
    let mut passes = 0;
    for entry in std::fs::read_dir(&dir).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().is_none_or(|e| e != "wgsl") {
            continue;
        }
        let name = path.file_name().unwrap().to_string_lossy().into_owned();
        let text = std::fs::read_to_string(&path).unwrap();
        if name == "common.wgsl" {
            module(&text, &name);
            assert_eq!(text, shaders::COMMON, "{name} as compiled");
        } else if name == "rebin.wgsl" {
            // The frame pass, composed with every choice of its sampling snippets.
            assert_eq!(text, shaders::REBIN, "{name} as compiled");
            // Every morph: the interpolations 0 to 4, without refinements, through the
            // proxy, occlusion-aware.
            for (image, prelit) in shaders::PRELIT {
                for (flow, flows) in shaders::FLOW {
                    for morph in (0..5).flat_map(|kind| [(kind, 0), (kind, 1), (kind, 3)]) {
                        let name = format!("{image}/{flow} {morph:?}");
                        let m = module(&shaders::frame_pass(prelit, flows, morph), &name);
                        // vs_main, fs_main, cs_main, cs_classes.
                        assert_eq!(m.entry_points.len(), 4, "{name}");
                    }
                }
            }
        } else if name == "sun_depth.wgsl" {
            assert_eq!(text, shaders::SUN_DEPTH, "{name} as compiled");
            let m = module(&shaders::sun_depth_pass(), &name);
            // vs_main (of every pass), sun_depth.
            assert_eq!(m.entry_points.len(), 2, "{name}");
        } else {
            let m = module(&shaders::composed(&text), &name);
            assert!(!m.entry_points.is_empty(), "{name} has no entry point");
            passes += 1;
        }
    }
    // The renderer's passes are exactly the files here.
    assert_eq!(passes, shaders::PASSES.len(), "passes in {}", dir.display());
    for (name, pass) in shaders::PASSES {
        module(&shaders::composed(pass), name);
    }
}

#[test]
fn every_piece_of_the_frame_pass_is_compiled_into_it() {
    // The pieces in the folders (sampling snippets, re-binning, morphs) are validated as
    // part of the frame pass: each must be in it for some choice of storage.
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).to_path_buf();
    let sources: Vec<String> = shaders::PRELIT
        .into_iter()
        .flat_map(|(_, prelit)| {
            shaders::FLOW.map(|(_, flow)| shaders::frame_pass(prelit, flow, (4, 1)))
        })
        .collect();
    let mut pieces = 0;
    for folder in ["sample", "rebin", "morph"] {
        for entry in std::fs::read_dir(dir.join(folder)).unwrap() {
            let path = entry.unwrap().path();
            let text = std::fs::read_to_string(&path).unwrap();
            assert!(
                sources.iter().any(|s| s.contains(&text)),
                "{} is in no frame pass",
                path.display()
            );
            pieces += 1;
        }
    }
    assert!(pieces >= 9, "{pieces} pieces");
}

#[test]
fn a_broken_shader_is_refused() {
    // The validation above can fail: a type error in an otherwise valid pass.
    let broken = shaders::REBIN.replacen("fn ", "fn broken() -> f32 { return 1u; }\nfn ", 1);
    let source = shaders::frame_pass(shaders::PRELIT_CODES, shaders::FLOW_CODES, (4, 1))
        .replace(shaders::REBIN, &broken);
    let parsed = naga::front::wgsl::parse_str(&source);
    let problem = match parsed {
        Err(e) => e.message().to_string(),
        Ok(m) => Validator::new(ValidationFlags::all(), Capabilities::default())
            .validate(&m)
            .map(|_| String::new())
            .unwrap_or_else(|e| e.as_inner().to_string()),
    };
    assert!(
        problem.contains("broken") || problem.contains("return"),
        "{problem:?}"
    );
}

/// Size and member offsets of the WGSL struct `name`, as naga lays it out.
fn layout(module: &naga::Module, name: &str) -> (u32, Vec<(String, u32)>) {
    let mut layouter = naga::proc::Layouter::default();
    layouter.update(module.to_ctx()).unwrap();
    let (handle, ty) = module
        .types
        .iter()
        .find(|(_, t)| t.name.as_deref() == Some(name))
        .unwrap_or_else(|| panic!("no struct {name}"));
    let naga::TypeInner::Struct { members, .. } = &ty.inner else {
        panic!("{name} is not a struct");
    };
    let fields = members
        .iter()
        .map(|m| (m.name.clone().unwrap_or_default(), m.offset))
        .collect();
    (layouter[handle].size, fields)
}

macro_rules! check_layout {
    ($module:expr, $wgsl:literal, $rust:ty, [$($field:ident),* $(,)?]) => {{
        let (size, fields) = layout($module, $wgsl);
        assert_eq!(size as usize, size_of::<$rust>(), "size of {}", $wgsl);
        let rust: Vec<(String, u32)> =
            vec![$((stringify!($field).to_string(), offset_of!($rust, $field) as u32)),*];
        assert_eq!(fields, rust, "fields of {}", $wgsl);
    }};
}

#[test]
fn pod_structs_match_naga_layouts() {
    let sun_depth = module(&shaders::sun_depth_pass(), "sun_depth");
    check_layout!(
        &sun_depth,
        "SunDepthJob",
        GpuSunDepthJob,
        [toward, axis_x, axis_y, size, texel]
    );
    check_layout!(&sun_depth, "SunMap", GpuSunMap, [map, hulls]);
    check_layout!(&sun_depth, "HullAt", GpuHullAt, [proxy, at]);
    check_layout!(
        &sun_depth,
        "SunOccluder",
        GpuSunOccluder,
        [hull, there_x, there_y, there_z, there_t]
    );
    let rebin = module(
        &shaders::frame_pass(shaders::PRELIT_CODES, shaders::FLOW_CODES, (4, 1)),
        "rebin",
    );
    check_layout!(&rebin, "View", GpuView, [rotation, centre, pad, intrinsics]);
    check_layout!(
        &rebin,
        "Quad",
        GpuQuad,
        [p00, u, e1, v, e2, wall, e3, wall_gamma, normal, pad]
    );
    check_layout!(
        &rebin,
        "Frame",
        GpuFrame,
        [
            axis_x,
            axis_y,
            axis_z,
            centre,
            intrinsics,
            size,
            variant,
            quad_count,
            columns,
            rows,
            crop_origin,
            crop_size,
            flags,
            depth,
            bounds,
            place,
            prelit,
            tiles
        ]
    );
    check_layout!(
        &rebin,
        "Proxy",
        GpuProxy,
        [origin, voxel, dims, present, axis, block_words_at, block]
    );
    check_layout!(
        &rebin,
        "ColumnIndex",
        GpuColumnIndex,
        [
            axis,
            reference,
            orientation,
            r_min,
            r_max,
            spans,
            quads_per_span,
            enabled
        ]
    );
    check_layout!(
        &rebin,
        "QuadFrame",
        GpuQuadFrame,
        [
            axis_x,
            axis_y,
            axis_n,
            intrinsics,
            to_rectified,
            from_rectified,
            centres,
            fixation_depth,
            valid,
            pad
        ]
    );
    // The column index's ranges follow its header in one buffer.
    let (_, fields) = layout(&rebin, "ColumnLookup");
    let ranges = size_of::<GpuColumnIndex>() as u32;
    assert_eq!(
        fields,
        [("header".to_string(), 0), ("ranges".to_string(), ranges)]
    );
    let relight = module(&shaders::composed(shaders::RELIGHT), "relight");
    check_layout!(
        &relight,
        "Job",
        GpuRelightJob,
        [
            basis_offset,
            coefficients_at,
            coefficient_offset,
            tiles,
            view,
            layer,
            relit_offset,
            surface,
            peak,
            heads_at,
            codes_at,
            texels,
            width,
            x0,
            y0,
            sun_slots,
            camera
        ]
    );
    let turn = module(&shaders::composed(shaders::TURN_LIGHT), "turn_light");
    check_layout!(
        &turn,
        "TurnParams",
        GpuTurnParams,
        [
            relights,
            samples,
            sun_slots,
            coarse_w,
            coarse_h,
            ratio_floor,
            trust_low,
            trust_high
        ]
    );
    check_layout!(
        &turn,
        "TurnRelight",
        GpuTurnRelight,
        [
            jobs_at,
            jobs,
            items,
            conditions_at,
            conditions,
            words_at,
            mask,
            light_at,
            coefficients_at,
            pad1,
            pad2,
            pad3
        ]
    );
    check_layout!(
        &turn,
        "TurnJob",
        GpuTurnJob,
        [
            coefficient_offset,
            tiles,
            turn,
            normals,
            scales,
            pad1,
            pad2,
            pad3
        ]
    );
    let light_fit = module(&shaders::composed(shaders::LIGHT_FIT), "light_fit");
    check_layout!(
        &light_fit,
        "LightFitParams",
        GpuLightFitParams,
        [texels, lights, nearest, pad0, light, indices, weights, view]
    );
    let shadow = module(&shaders::composed(shaders::SHADOW), "shadow");
    check_layout!(
        &shadow,
        "ShadowJob",
        GpuShadowJob,
        [maps_at, maps, texels, weights_at, layer, pad]
    );
    let present = module(&shaders::composed(shaders::PRESENT), "present");
    check_layout!(
        &present,
        "Present",
        GpuPresent,
        [origin, extent, layer, encode, exposure, pad]
    );
    let composite = module(&shaders::composed(shaders::COMPOSITE), "composite");
    check_layout!(
        &composite,
        "Composite",
        GpuComposite,
        [
            backdrop,
            ground_look,
            has_shadow,
            shadow_texels,
            ground_radiance,
            env_size,
            env_yaw,
            shadow_extent,
            instances,
            tile_columns,
            tile_side,
            by_depth
        ]
    );
    check_layout!(
        &composite,
        "Instance",
        GpuInstance,
        [col_x, col_y, col_z, translation, bounds, place]
    );
    let time_morph = module(&shaders::composed(shaders::TIME_MORPH), "time_morph");
    check_layout!(
        &time_morph,
        "TimeMorph",
        GpuTimeMorph,
        [
            to_image, bounds, at_poses, at_motions, at_morph, s, by_depth, morph_page, pad, pages
        ]
    );
}
