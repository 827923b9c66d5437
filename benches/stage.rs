//! Speed of the virtual light stage: one capture frame (a basis condition with shadow
//! rays, and a track frame) at the tiny and small presets' sizes, and a truth image under
//! an environment reduced to 512 lights. Run: `cargo bench --bench stage`.

#![allow(clippy::unwrap_used)] // benchmarks: a failed unwrap is a failed run

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use frf_core::env::EnvMap;
use frf_stage::truth::environment_lights;
use frf_stage::{Preset, Stage, StageConfig};

fn bench(c: &mut Criterion) {
    let mut group = c.benchmark_group("stage");
    group.sample_size(10);
    for preset in [Preset::Tiny, Preset::Small] {
        let stage = Stage::new(StageConfig::preset(preset)).unwrap();
        let pixels = (stage.config().width * stage.config().height) as u64;
        group.throughput(Throughput::Elements(pixels));
        let name = format!("{preset:?}").to_lowercase();
        group.bench_function(format!("{name}/basis_frame"), |b| {
            b.iter(|| stage.capture_frame(0, 3, 1, 12).unwrap())
        });
        group.bench_function(format!("{name}/track_frame"), |b| {
            b.iter(|| stage.capture_frame(0, 3, 1, 16).unwrap())
        });
        let lights = environment_lights(&EnvMap::sky(), 512);
        let camera = stage.subject_camera(0, 3, 1).unwrap();
        group.bench_function(format!("{name}/truth_512_lights"), |b| {
            b.iter(|| stage.truth_image(0, &camera, &lights))
        });
    }
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
