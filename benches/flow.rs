//! Criterion benchmark of the flow presets at the capture's 320x448, on a synthetic
//! textured pair with a smooth, spatially varying flow (a rotation and zoom about the
//! centre, up to ~6 px): `cargo bench --bench flow`. Speed is reported here, never
//! asserted in tests.

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use frf_core::image::{Image, RgbImage};
use frf_flow::{FlowParams, Preset, estimate_flow};

const WIDTH: usize = 320;
const HEIGHT: usize = 448;

/// Band-limited texture: a few dozen sinusoids (frequencies below 0.6 rad/px).
fn texture(x: f32, y: f32) -> [f32; 3] {
    let mut c = [0.5f32; 3];
    for k in 0..24 {
        let kf = k as f32;
        let angle = kf * 2.39996;
        let freq = 0.05 + 0.02 * kf;
        let phase = kf * 1.3;
        let s = (freq * (angle.cos() * x + angle.sin() * y) + phase).sin() * 0.04;
        for (i, v) in c.iter_mut().enumerate() {
            *v += s * (1.0 + 0.3 * ((kf + i as f32) * 0.7).sin());
        }
    }
    c
}

/// `A(s) = T(s)`, `B(s + F(s)) ≈ T(s)` with `F` a 2-degree rotation and 2% zoom.
fn pair() -> (RgbImage, RgbImage) {
    let (cx, cy) = (WIDTH as f32 / 2.0, HEIGHT as f32 / 2.0);
    let (angle, scale) = (2.0f32.to_radians(), 1.02f32);
    let a = Image::from_fn(WIDTH, HEIGHT, |x, y| texture(x as f32, y as f32));
    // B(p) = T(M⁻¹(p − c) + c), M = scale · rotation.
    let b = Image::from_fn(WIDTH, HEIGHT, |x, y| {
        let (dx, dy) = (x as f32 - cx, y as f32 - cy);
        let (c, s) = (angle.cos(), angle.sin());
        let (ux, uy) = ((c * dx + s * dy) / scale, (-s * dx + c * dy) / scale);
        texture(ux + cx, uy + cy)
    });
    (a, b)
}

fn presets(c: &mut Criterion) {
    let (a, b) = pair();
    let mut group = c.benchmark_group("flow_320x448");
    group.throughput(Throughput::Elements((WIDTH * HEIGHT) as u64));
    group.sample_size(10);
    for preset in Preset::ALL {
        let params = FlowParams::preset(preset);
        group.bench_function(preset.name(), |bench| {
            bench.iter(|| estimate_flow(&a, &b, &params).expect("valid input"))
        });
    }
    let wide = FlowParams::preset(Preset::Balanced).wide_search();
    group.bench_function("balanced_wide_search", |bench| {
        bench.iter(|| estimate_flow(&a, &b, &wide).expect("valid input"))
    });
    group.finish();
}

criterion_group!(benches, presets);
criterion_main!(benches);
