mod common;
use common::*;
use frf_flow::*;

#[test]
fn probe() {
    let t = Texture::new(7);
    for d in [[0.3f32, 0.0], [2.5, 1.3], [6.0, -3.0], [0.0, 0.0]] {
        let a = t.image(200, 160, [0.0, 0.0]);
        let b = t.image(200, 160, d);
        for p in Preset::ALL {
            let f = estimate_flow(&a, &b, &FlowParams::preset(p)).unwrap();
            let mean: Vec<f32> = (0..2)
                .map(|c| f.pixels().iter().map(|v| v[c]).sum::<f32>() / f.pixels().len() as f32)
                .collect();
            eprintln!(
                "{d:?} {p:?}: epe {:.4} (margin 10: {:.4}) mean {:?}",
                epe_constant(&f, d, 0),
                epe_constant(&f, d, 10),
                mean
            );
        }
    }
}
