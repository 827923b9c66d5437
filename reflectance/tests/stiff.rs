//! Stiff and extreme cases of the reflectance field's arithmetic: logarithmic flow codes
//! at zero, at the saturation limit and far beyond it (they saturate to ±127, never wrap
//! or turn into the unknown code), quantizers whose parameters leave `f32`; canonical
//! Huffman tables of one symbol and of 256 equiprobable ones; the projection of an
//! environment holding a tiny sun 1e5 times the sky (its energy against an analytic f64
//! value, and the naive f32 sum it avoids), lights exactly at the horizon, environments
//! of a single texel row or column; relighting with all-zero and with huge coefficients.
//! Every expectation is computed independently of the code under test (closed forms,
//! f64 sums); where a bound is not exact, the comment says where it comes from.

#![allow(clippy::unwrap_used)] // tests: a failed unwrap is a failed test

use std::f64::consts::PI;

use frf_core::env::EnvMap;
use frf_core::image::{FlowImage, Image, Rgb, RgbImage};
use frf_reflectance::field::{ConditionRecord, LightRecord};
use frf_reflectance::flowcodec::huffman::HuffmanTable;
use frf_reflectance::flowcodec::quant::{LogQuantizer, UNKNOWN_CODE};
use frf_reflectance::flowcodec::{self, quantize};
use frf_reflectance::project::{FloorModel, Projector};
use frf_reflectance::relight::relight;

// ---------------------------------------------------------------------------------------
// Logarithmic flow codes.

#[test]
fn flow_codes_at_zero_are_zero_exactly() {
    for (s, m) in [(0.5f32, 32.0f32), (1e-3, 1e3), (20.0, 1.0)] {
        let q = LogQuantizer::new(s, m).unwrap();
        for x in [0.0f32, -0.0, f32::MIN_POSITIVE, -1e-30, 1e-45] {
            assert_eq!(q.encode(x), 0, "s {s} M {m}: {x:e}");
        }
        assert_eq!(q.decode(0), 0.0);
    }
}

#[test]
fn flow_codes_saturate_at_the_extreme_code_and_decode_to_the_range() {
    // Documented: magnitudes above the range M saturate (never wrap), the extreme code
    // ±127 decodes to ±M (s ((1 + M/s)^(127/127) − 1) = M), −128 is reserved for unknown
    // flow, and only magnitudes above 1e9 (the Middlebury marker) are unknown.
    for (s, m) in [(0.5f32, 32.0f32), (0.05, 80.0), (3.0, 3.0), (1e-3, 1e6)] {
        let q = LogQuantizer::new(s, m).unwrap();
        for x in [m, m * 1.0001, m * 2.0, 1e4, 1e8, 1e9] {
            if x < m {
                continue;
            }
            assert_eq!(q.encode(x), 127, "s {s} M {m}: {x:e}");
            assert_eq!(q.encode(-x), -127, "s {s} M {m}: {:e}", -x);
        }
        // Relative error of exp/ln in f32: a few ulps (1e-6 relative at most).
        assert!(
            (q.decode(127) - m).abs() <= 1e-6 * m,
            "{} vs {m}",
            q.decode(127)
        );
        assert_eq!(q.decode(-127), -q.decode(127));
        // The code just below the limit is below the range: the codes are monotone.
        assert!(q.decode(126) < q.decode(127));
        // Beyond the marker, unknown (and that decodes to the marker).
        assert_eq!(q.encode(2e9), UNKNOWN_CODE);
        assert_eq!(q.encode(f32::MAX), UNKNOWN_CODE);
        assert_eq!(q.encode(f32::NEG_INFINITY), UNKNOWN_CODE);
        assert_eq!(q.decode(UNKNOWN_CODE), frf_core::flo::UNKNOWN);
        // A sweep from 0 to the marker: codes never decrease and never go negative.
        let mut last = 0i8;
        for i in 0..=900 {
            let x = 10f32.powf(i as f32 / 100.0) - 1.0; // 0 .. 1e9
            let c = q.encode(x.min(1e9));
            assert!(c >= last && c >= 0, "x {x}: code {c} after {last}");
            last = c;
        }
        assert_eq!(last, 127);
    }
}

#[test]
fn quantizers_whose_parameters_leave_f32_are_refused() {
    // range / scale = 1e60 overflows f32 (the step k = ln(1 + M/s)/127 is infinite: every
    // code would decode to infinity); 1e-60 underflows to 0 (k = 0: every value, even 0,
    // would encode to 127). Both are refused where a quantizer is made or read.
    let e = LogQuantizer::new(1e-30, 1e30).unwrap_err().to_string();
    assert!(
        e.contains("M / s inf: expected a ratio f32 can hold"),
        "{e}"
    );
    let e = LogQuantizer::new(1e30, 1e-30).unwrap_err().to_string();
    assert!(e.contains("M / s 0: expected a ratio f32 can hold"), "{e}");
    // Wide but representable (M / s = 1e20, M below the 1e9 unknown marker): still
    // exact at both ends.
    let q = LogQuantizer::new(1e-12, 1e8).unwrap();
    assert_eq!(q.encode(0.0), 0);
    assert_eq!(q.encode(1e8), 127);
    assert!((q.decode(127) - 1e8).abs() <= 1e-5 * 1e8);
}

// ---------------------------------------------------------------------------------------
// Canonical Huffman tables.

fn counts(symbols: &[u8]) -> [u64; 256] {
    let mut c = [0u64; 256];
    for &s in symbols {
        c[s as usize] += 1;
    }
    c
}

#[test]
fn a_huffman_table_of_one_symbol_round_trips_at_one_bit_each() {
    // One symbol gets a 1-bit code (a code of length 0 cannot be written), the canonical
    // first code, 0: n symbols are n zero bits.
    for (symbol, n) in [(0u8, 1usize), (42, 1000), (255, 4097)] {
        let symbols = vec![symbol; n];
        let table = HuffmanTable::from_counts(&counts(&symbols));
        let lengths = table.lengths();
        assert_eq!(lengths[symbol as usize], 1);
        assert_eq!(lengths.iter().filter(|&&l| l > 0).count(), 1);
        let bytes = table.encode(&symbols).unwrap();
        assert_eq!(bytes.len(), n.div_ceil(8));
        assert!(bytes.iter().all(|&b| b == 0));
        let read = HuffmanTable::from_bytes(&table.to_bytes()).unwrap();
        assert_eq!(read, table);
        assert_eq!(read.decode(&bytes, n).unwrap(), symbols);
    }
    // The codec end to end: a constant flow map codes one symbol per plane.
    let q = LogQuantizer::new(0.5, 16.0).unwrap();
    let flow: FlowImage = Image::new(7, 5, [2.25f32, -0.75]);
    for predicted in [false, true] {
        let coded = flowcodec::encode(&flow, &q, predicted).unwrap();
        let (w, h, codes) = flowcodec::decode_codes(&coded).unwrap();
        assert_eq!((w, h, codes), (7, 5, quantize(&flow, &q)));
    }
}

#[test]
fn a_huffman_table_of_256_equiprobable_symbols_is_8_bits_each_and_the_identity() {
    // Equal counts give a complete tree of depth 8; the canonical code then numbers the
    // symbols in order: symbol s is coded as the byte s, so the stream is the input.
    let symbols: Vec<u8> = (0..4096u32)
        .map(|i| (i.wrapping_mul(2_654_435_761) >> 24) as u8)
        .collect();
    let mut equal = [0u64; 256];
    equal.iter_mut().for_each(|c| *c = 16);
    let table = HuffmanTable::from_counts(&equal);
    assert!(table.lengths().iter().all(|&l| l == 8));
    let bytes = table.encode(&symbols).unwrap();
    assert_eq!(bytes.len(), symbols.len(), "8 bits per symbol");
    assert_eq!(bytes, symbols);
    let read = HuffmanTable::from_bytes(&table.to_bytes()).unwrap();
    assert_eq!(read.decode(&bytes, symbols.len()).unwrap(), symbols);
    // Nearly equal counts (1 to 2: no symbol has twice another's) give the same depth.
    let mut uneven = [0u64; 256];
    for (s, c) in uneven.iter_mut().enumerate() {
        *c = 1000 + s as u64 * 3;
    }
    assert!(
        HuffmanTable::from_counts(&uneven)
            .lengths()
            .iter()
            .all(|&l| l == 8)
    );
}

// ---------------------------------------------------------------------------------------
// Projection and relighting.

/// One condition per direction, each a single light of `intensity` (dome frame).
fn conditions(dirs: &[[f32; 3]], intensity: f32) -> Vec<ConditionRecord> {
    dirs.iter()
        .enumerate()
        .map(|(k, d)| ConditionRecord {
            name: format!("c{k}"),
            floor: false,
            lights: vec![LightRecord {
                direction: glam::Vec3::from(*d).normalize().to_array(),
                intensity: [intensity; 3],
                solid_angle_sr: 0.1,
            }],
        })
        .collect()
}

/// Directions spread over the sphere (a Fibonacci lattice), none at the horizon.
fn spread(n: usize) -> Vec<[f32; 3]> {
    (0..n)
        .map(|i| {
            let y = 1.0 - (i as f32 + 0.5) / n as f32 * 2.0;
            let r = (1.0 - y * y).sqrt();
            let a = i as f32 * 2.399_963;
            [r * a.cos(), y, r * a.sin()]
        })
        .collect()
}

/// The solid angle of a texel of row `y` of a `w x h` latitude–longitude map, in f64:
/// `(2π / w)(cos(π y / h) − cos(π (y + 1) / h))`.
fn solid_angle(w: usize, h: usize, y: usize) -> f64 {
    let (a, b) = (PI * y as f64 / h as f64, PI * (y + 1) as f64 / h as f64);
    2.0 * PI / w as f64 * (a.cos() - b.cos())
}

/// Sum over conditions of the light projected on each, per channel, in f64.
fn total(regions: &[Rgb]) -> [f64; 3] {
    let mut t = [0.0f64; 3];
    for r in regions {
        for c in 0..3 {
            t[c] += r[c] as f64;
        }
    }
    t
}

#[test]
fn a_tiny_sun_1e5_times_the_sky_projects_its_energy_within_1e_4() {
    // A 1024 x 512 sky of radiance 1 with one texel of 1e5 (the sun: 1.2e-5 of the
    // sphere's area, 23 % of its light). Every texel of a row has the same solid angle,
    // which sum to 4π over the sphere: the total is 4π + (1e5 − 1) ω(sun's row), in f64.
    let (w, h) = (1024usize, 512usize);
    let (sun_x, sun_y) = (300usize, 128usize);
    let sun = 1e5f32;
    let img = Image::from_fn(w, h, |x, y| {
        if (x, y) == (sun_x, sun_y) {
            [sun; 3]
        } else {
            [1.0; 3]
        }
    });
    let env = EnvMap::from_image(img).unwrap();
    let exact = 4.0 * PI + (sun as f64 - 1.0) * solid_angle(w, h, sun_y);
    let projector = Projector::new(&conditions(&spread(24), 1.0)).unwrap();
    let regions = projector.region_light(&env, 0.0, FloorModel::Environment);
    let projected = total(&regions);
    let err = (projected[0] - exact).abs() / exact;
    assert!(err < 1e-4, "projected {} vs {exact}: {err:e}", projected[0]);
    // The sun's region holds at least the sun.
    let k = projector.condition_of(env.direction_of(sun_x as f32, sun_y as f32));
    assert!(regions[k][0] as f64 >= (sun as f64) * solid_angle(w, h, sun_y));
    // The naive sum it avoids: one f32 accumulator over the texels in memory order
    // (each L ω rounded to f32 as well). Its error grows with the 524 288 additions into
    // a sum up to 16 (ulp 1.9e-6 against terms of ≤ 3.8e-5); the projection sums each
    // row and the rows in f64 and rounds once per region.
    let mut naive = 0.0f32;
    for y in 0..h {
        let omega = env.texel_solid_angle(y);
        for p in env.image().row(y) {
            naive += p[0] * omega;
        }
    }
    // Measured: projection 1.2e-7, naive 9.7e-4, which would fail the 1e-4 bound.
    let naive_err = (naive as f64 - exact).abs() / exact;
    eprintln!("relative error: projection {err:e}, naive f32 sum {naive_err:e}");
    assert!(
        naive_err > 1e-4 && naive_err > 100.0 * err,
        "naive {naive_err:e} vs projection {err:e}"
    );
}

#[test]
fn lights_exactly_at_the_horizon_split_the_sphere_into_their_voronoi_cells() {
    // Four conditions with one light each at azimuths 0°, 90°, 180°, 270° on the
    // horizon: their cells are the four quarter-spheres about the vertical axis. Under a
    // uniform radiance 1 each holds π sr of light; under a sky of 1 above the horizon and
    // black below, π/2. Lights of intensity 2: coefficients π/2 and π/4. (The lookup grid
    // and the texels are both offset by half a cell from the quarter boundaries, so the
    // split is exact up to f32 rounding: 1e-5 relative.)
    let dirs = [
        [1.0, 0.0, 0.0],
        [0.0, 0.0, 1.0],
        [-1.0, 0.0, 0.0],
        [0.0, 0.0, -1.0],
    ];
    let projector = Projector::new(&conditions(&dirs, 2.0)).unwrap();
    let sphere = EnvMap::uniform([1.0; 3], 128);
    let sky = EnvMap::from_image(Image::from_fn(256, 128, |_, y| {
        if y < 64 { [1.0; 3] } else { [0.0; 3] }
    }))
    .unwrap();
    for (env, want) in [(&sphere, PI / 2.0), (&sky, PI / 4.0)] {
        let k = projector.project(env, 0.0, FloorModel::Environment);
        for (i, c) in k.iter().enumerate() {
            for v in c {
                assert!(
                    (*v as f64 - want).abs() < 1e-5 * want,
                    "condition {i}: {c:?} vs {want}"
                );
            }
        }
        // Relit: a basis image of 1 per condition gives 4 · want everywhere.
        let basis: Vec<RgbImage> = (0..4).map(|_| Image::new(3, 2, [1.0f32; 3])).collect();
        let img = relight(&basis, &k).unwrap();
        for p in img.pixels() {
            assert!((p[0] as f64 - 4.0 * want).abs() < 4e-5 * want, "{p:?}");
        }
    }
}

#[test]
fn an_environment_of_one_texel_row_or_column_projects_its_light_exactly() {
    // A 64 x 1 map: one row of texels spanning the whole sphere, each 4π/64 sr, their
    // centres on the horizon at 64 azimuths: the four horizon lights' quarters take 16
    // each: π per condition for radiance 1. A 1 x 64 map: one column, every texel centre
    // at azimuth 180° (toward −z, the map's centre): the whole 4π goes to the light
    // toward −z.
    let dirs = [
        [1.0, 0.0, 0.0],
        [0.0, 0.0, 1.0],
        [-1.0, 0.0, 0.0],
        [0.0, 0.0, -1.0],
    ];
    let projector = Projector::new(&conditions(&dirs, 1.0)).unwrap();
    let row = EnvMap::from_image(Image::new(64, 1, [1.0f32; 3])).unwrap();
    let light = projector.region_light(&row, 0.0, FloorModel::Environment);
    for (i, r) in light.iter().enumerate() {
        assert!(
            (r[0] as f64 - PI).abs() < 1e-5 * PI,
            "row map, condition {i}: {r:?}"
        );
    }
    let column = EnvMap::from_image(Image::new(1, 64, [1.0f32; 3])).unwrap();
    let light = projector.region_light(&column, 0.0, FloorModel::Environment);
    let minus_z = projector.condition_of(glam::Vec3::NEG_Z);
    assert_eq!(minus_z, 3);
    for (i, r) in light.iter().enumerate() {
        let want = if i == minus_z { 4.0 * PI } else { 0.0 };
        assert!(
            (r[0] as f64 - want).abs() < 1e-5 * 4.0 * PI,
            "column map, {i}: {r:?}"
        );
    }
    // And a single texel: the whole sphere, 4π, in one region.
    let one = EnvMap::from_image(Image::new(1, 1, [1.0f32; 3])).unwrap();
    let t = total(&projector.region_light(&one, 0.0, FloorModel::Environment));
    assert!((t[0] - 4.0 * PI).abs() < 1e-5 * 4.0 * PI, "{t:?}");
}

#[test]
fn all_zero_coefficients_relight_to_exact_black() {
    // A black environment projects to coefficients of exactly 0 (sums of 0 · ω), and
    // zero coefficients skip every basis image: the output is 0.0 exactly, even over
    // basis images holding huge values.
    let projector = Projector::new(&conditions(&spread(12), 1.0)).unwrap();
    let black = EnvMap::uniform([0.0; 3], 32);
    let k = projector.project(&black, 0.7, FloorModel::Environment);
    assert!(k.iter().flatten().all(|&v| v == 0.0), "{k:?}");
    let basis: Vec<RgbImage> = (0..12)
        .map(|i| Image::from_fn(5, 4, |x, y| [1e30, (x + y + i) as f32, 1e-30]))
        .collect();
    let img = relight(&basis, &k).unwrap();
    assert!(img.pixels().iter().all(|p| *p == [0.0; 3]));
    let lambert = projector.project(
        &black,
        0.0,
        FloorModel::LambertianGround { albedo: [0.5; 3] },
    );
    assert!(lambert.iter().flatten().all(|&v| v == 0.0));
}

#[test]
fn huge_coefficients_relight_exactly_while_finite_and_are_refused_on_overflow() {
    // Relighting is linear: coefficients of ±1e30 on basis values ≤ 1 give values
    // ≤ 3e30, far inside f32 (3.4e38): the right answer is the product, checked against
    // f64 (one rounding per product and per sum: 1e-6 relative). Basis values of 1e9
    // times 1e30 exceed f32: there is no finite right answer, and returning infinity
    // would poison everything downstream, so the input is refused with an error.
    let basis: Vec<RgbImage> = (0..3)
        .map(|i| {
            Image::from_fn(6, 5, |x, y| {
                [x as f32 / 5.0, y as f32 / 4.0, 0.1 * i as f32]
            })
        })
        .collect();
    let k = [
        [1e30f32, -1e30, 1e30],
        [1e30, 1e30, 0.0],
        [-3e29, 0.0, 1e30],
    ];
    let img = relight(&basis, &k).unwrap();
    for (i, p) in img.pixels().iter().enumerate() {
        for c in 0..3 {
            let want: f64 = (0..3)
                .map(|b| k[b][c] as f64 * basis[b].pixels()[i][c] as f64)
                .sum();
            assert!(p[c].is_finite(), "{p:?}");
            assert!((p[c] as f64 - want).abs() <= 1e-6 * 3e30, "{p:?} vs {want}");
        }
    }
    let bright: Vec<RgbImage> = vec![Image::new(4, 4, [1e9f32; 3])];
    let err = relight(&bright, &[[1e30; 3]]).unwrap_err();
    assert!(err.to_string().contains("overflow"), "{err}");
    // At the edge: 3e38 is finite, and returned as such.
    let edge = relight(&[Image::new(2, 2, [3.0f32; 3])], &[[1e38; 3]]).unwrap();
    assert!(
        edge.pixels()
            .iter()
            .all(|p| (p[0] as f64 - 3e38).abs() < 1e-6 * 3e38)
    );
}
