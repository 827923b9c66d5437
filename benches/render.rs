//! Frame time of the renderer: the wgpu renderer (lavapipe on machines without a GPU)
//! against the CPU reference in one run, per variant. The field is `FRF_BENCH_FIELD` (e.g. a paper-size field from
//! `frf ingest`), or else the tiny stage's oracle field, built first (about 10 s).
//! Frames are the field's image size, from a camera between grid views. Relighting a
//! pose under the built-in sky, or the map `FRF_BENCH_ENV` (an HDR file; a new light: the
//! GPU's relight pass, waited for; the CPU twin; the host's coefficients and suns before
//! either), its suns by the views' fitted normals against the same suns by the basis
//! alone. Run: `cargo bench --bench render`.

#![allow(clippy::unwrap_used)] // benchmarks: a failed unwrap is a failed run

use std::path::PathBuf;

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use frf_core::env::EnvMap;
use frf_eval::views::between_view_cameras;
use frf_reflectance::FieldFile;
use frf_reflectance::project::FloorModel;
use frf_render::gpu::Gpu;
use frf_render::morph::Variant;
use frf_render::renderer::Renderer;
use frf_render::resident::{Lighting, PoseSource, ResidentPose};

fn field() -> PathBuf {
    match std::env::var("FRF_BENCH_FIELD") {
        Ok(path) => PathBuf::from(path),
        Err(_) => frf_testkit::tiny_field().field.clone(),
    }
}

fn bench(c: &mut Criterion) {
    let path = field();
    let field = FieldFile::open(&path).unwrap();
    let pose = field.header().poses[0].pose;
    let env = match std::env::var("FRF_BENCH_ENV") {
        Ok(path) => EnvMap::load(std::path::Path::new(&path)).unwrap(),
        Err(_) => EnvMap::sky(),
    };
    let lighting = Lighting::Environment {
        env,
        floor: FloorModel::Environment,
    };
    let source = PoseSource::load(&field, pose, &lighting).unwrap();
    let camera = between_view_cameras(&source.geometry, 1)
        .unwrap()
        .remove(0)
        .camera;
    let mut group = c.benchmark_group("render");
    group.sample_size(10);
    group.throughput(Throughput::Elements(
        camera.width as u64 * camera.height as u64,
    ));
    let renderers = [
        (
            "gpu",
            Renderer::new(&source, Some(Gpu::new().unwrap())).unwrap(),
        ),
        ("cpu", Renderer::new(&source, None).unwrap()),
    ];
    eprintln!(
        "{}: {}x{}, resident {:.1} MB; {}",
        path.display(),
        camera.width,
        camera.height,
        renderers[0].1.resident_bytes() as f64 / 1e6,
        renderers[0].1.device()
    );
    for variant in [Variant::FourWay, Variant::Linear] {
        for (name, r) in &renderers {
            group.bench_function(format!("{}/{name}", variant.name()), |b| {
                b.iter(|| r.render(&camera, variant).unwrap())
            });
        }
    }
    group.finish();
    relight(c, &field, &source, &lighting);
}

/// A pose relit, its sun by the normals and by the basis alone (normals left out).
fn relight(c: &mut Criterion, field: &FieldFile, by_normals: &PoseSource, lighting: &Lighting) {
    let by_basis = PoseSource {
        normals: std::sync::Arc::new(vec![Vec::new(); by_normals.normals.len()]),
        ..by_normals.clone()
    }
    .relit(field, lighting, None)
    .unwrap();
    assert!(!by_normals.suns.is_empty() && by_basis.suns.is_empty());
    eprintln!("relight: {} suns by the normals", by_normals.suns.len());
    let gpu = Gpu::new().unwrap();
    let mut group = c.benchmark_group("relight");
    group.sample_size(10);
    for (name, source) in [("sun by normals", by_normals), ("sun by basis", &by_basis)] {
        let mut pose = gpu.upload_pose(source).unwrap();
        group.bench_function(format!("{name}/gpu"), |b| {
            b.iter(|| {
                gpu.relight_pose(&mut pose, source).unwrap();
                gpu.read_scales(&pose).unwrap()
            })
        });
        group.bench_function(format!("{name}/cpu"), |b| {
            b.iter(|| ResidentPose::relight_cpu(source))
        });
        // The host's part of a new light, before either: the map projected for every
        // view, the suns found and their maps of the hull made.
        group.bench_function(format!("{name}/host"), |b| {
            b.iter(|| source.relit(field, lighting, None).unwrap())
        });
    }
    group.finish();
    // The ratio itself, the two ways measured in turn so that a slow spell of this shared
    // machine falls on both: the median of the rounds' ratios.
    let mut pose = [by_normals, &by_basis].map(|s| gpu.upload_pose(s).unwrap());
    let gpu_ratio = in_turn(|k| {
        let source = [by_normals, &by_basis][k];
        gpu.relight_pose(&mut pose[k], source).unwrap();
        gpu.read_scales(&pose[k]).unwrap();
    });
    let cpu_ratio = in_turn(|k| {
        ResidentPose::relight_cpu([by_normals, &by_basis][k]);
    });
    eprintln!(
        "relight, sun by the normals over by the basis (median of {ROUNDS} rounds of one \
         each in turn): GPU {gpu_ratio}, CPU reference {cpu_ratio}"
    );
}

/// Rounds of [`in_turn`].
const ROUNDS: usize = 25;

/// `run(0)`'s time over `run(1)`'s, the median of [`ROUNDS`] rounds of one each in turn,
/// and each one's median time.
fn in_turn(mut run: impl FnMut(usize)) -> String {
    let median = |mut v: Vec<f64>| {
        v.sort_by(f64::total_cmp);
        v[v.len() / 2]
    };
    let mut times = [Vec::new(), Vec::new()];
    for _ in 0..ROUNDS {
        for (k, times) in times.iter_mut().enumerate() {
            let t = std::time::Instant::now();
            run(k);
            times.push(t.elapsed().as_secs_f64());
        }
    }
    let ratios = times[0].iter().zip(&times[1]).map(|(a, b)| a / b).collect();
    let [a, b] = times.map(median);
    format!(
        "{:.2}x ({:.1} / {:.1} ms)",
        median(ratios),
        a * 1e3,
        b * 1e3
    )
}

criterion_group!(benches, bench);
criterion_main!(benches);
