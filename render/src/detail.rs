//! Level of detail: a pose's views at a reduced resolution, for walkers whose projected
//! size is a fraction of the captured view's. Level `L` box-filters every `2^L x 2^L`
//! block of the pre-lit basis images (in linear light), the alpha and the flows (the
//! known ones, averaged, then divided by `2^L`: a flow is a displacement in pixels), and
//! scales the cameras' intrinsics to the reduced image (a reduced texel's centre is its
//! block's centre). Geometry in metres (the cylinder of camera centres, the hull) is
//! unchanged. The renderer reads a reduced pose exactly as a full one
//! ([`crate::resident::PoseSource::load_at`]); reduced views are kept between the poses
//! made resident ([`crate::reduced_views`]).
//!
//! [`detail_level`] chooses the level from the pixels per metre a walker covers in the
//! frame against the captured views' own: the coarsest level whose texels are still no
//! larger than [`DETAIL_MARGIN`] of the frame's pixels (the margin measured against full
//! detail: docs/results/render.md, "Level of detail").

use frf_core::camera::Camera;
use frf_reflectance::flowcodec::quant::UNKNOWN_CODE;
use frf_reflectance::imagecodec::{BasisCodes, gamma_lut};
use frf_reflectance::normalcodec::{normal_code, normal_of};

use crate::geometry::Crop;

/// The coarsest level used.
pub const MAX_LEVEL: u8 = 3;

/// A level's texel may cover up to this many of the frame's pixels, along each axis.
pub const DETAIL_MARGIN: f32 = 1.0;

/// The level of detail for a walker seen at `seen` pixels per metre from views that
/// captured it at `captured` (see the module docs).
pub fn detail_level(captured: f32, seen: f32) -> u8 {
    if !(captured.is_finite() && seen.is_finite()) || seen <= 0.0 || captured <= 0.0 {
        return 0;
    }
    let mut level = 0;
    while level < MAX_LEVEL && seen * (1u32 << (level + 1)) as f32 <= captured * DETAIL_MARGIN {
        level += 1;
    }
    level
}

/// `camera` seeing the image reduced to `level` (same pose, intrinsics scaled so that a
/// reduced texel's centre sits at its block's centre).
pub fn reduced_camera(camera: &Camera, level: u8) -> Camera {
    let f = (1u32 << level) as f32;
    let mut c = *camera;
    c.intrinsics.fx /= f;
    c.intrinsics.fy /= f;
    c.intrinsics.cx = (camera.intrinsics.cx + 0.5) / f - 0.5;
    c.intrinsics.cy = (camera.intrinsics.cy + 0.5) / f - 0.5;
    c.width = camera.width.div_ceil(1 << level);
    c.height = camera.height.div_ceil(1 << level);
    c
}

/// The crop of the reduced image covering `crop`'s blocks.
fn reduced_crop(crop: Crop, level: u8) -> Crop {
    let x0 = crop.x0 >> level;
    let y0 = crop.y0 >> level;
    let x1 = (crop.x0 + crop.width).div_ceil(1 << level);
    let y1 = (crop.y0 + crop.height).div_ceil(1 << level);
    Crop {
        x0,
        y0,
        width: x1 - x0,
        height: y1 - y0,
    }
}

/// Box-filters `texels` (cropped by `from`) into the crop `to` of the image reduced by
/// `level`: per reduced texel, the full texels of its block inside `from` are `add`ed
/// into an accumulator (from its default) and `finish`ed with their count. A reduced
/// texel whose `kept` entry is 0 is not filtered: it is `U`'s default.
fn reduce<T, A: Default, U: Default>(
    texels: &[T],
    from: Crop,
    to: Crop,
    level: u8,
    kept: Option<&[u8]>,
    add: impl Fn(&mut A, &T),
    finish: impl Fn(A, u32) -> U,
) -> Vec<U> {
    let n = 1u32 << level;
    let (fx1, fy1) = (from.x0 + from.width, from.y0 + from.height);
    let mut out = Vec::with_capacity(to.texels());
    for y in to.y0..to.y0 + to.height {
        let rows = (y * n).max(from.y0)..((y + 1) * n).min(fy1);
        for x in to.x0..to.x0 + to.width {
            if kept.is_some_and(|k| k[out.len()] == 0) {
                out.push(U::default());
                continue;
            }
            let cols = (x * n).max(from.x0)..((x + 1) * n).min(fx1);
            let mut acc = A::default();
            let mut count = 0;
            for fy in rows.clone() {
                let row = ((fy - from.y0) * from.width) as usize;
                for fx in cols.clone() {
                    add(&mut acc, &texels[row + (fx - from.x0) as usize]);
                    count += 1;
                }
            }
            out.push(finish(acc, count));
        }
    }
    out
}

/// The 8-bit gamma code nearest to the linear value `x` (in `[0, 1]`), through `lut`.
fn gamma_code(lut: &[f32; 256], x: f32) -> u8 {
    let i = lut.partition_point(|&v| v < x).min(255);
    if i > 0 && (x - lut[i - 1]) < (lut[i] - x) {
        (i - 1) as u8
    } else {
        i as u8
    }
}

/// Entries of [`gamma_codes`]' table, over `sqrt(x)` (fine enough near black to tell
/// every code apart).
const GAMMA_STEPS: usize = 1 << 16;

/// [`gamma_code`] of `x` by table: the code nearest to `x` at the table's resolution.
fn gamma_codes() -> &'static [u8] {
    static TABLE: std::sync::OnceLock<Vec<u8>> = std::sync::OnceLock::new();
    TABLE.get_or_init(|| {
        let lut = gamma_lut();
        (0..GAMMA_STEPS)
            .map(|i| {
                let r = i as f32 / (GAMMA_STEPS - 1) as f32;
                gamma_code(&lut, r * r)
            })
            .collect()
    })
}

/// The gamma code of linear `x` through [`gamma_codes`]' table.
fn fast_gamma_code(table: &[u8], x: f32) -> u8 {
    let r = x.clamp(0.0, 1.0).sqrt();
    table[(r * (GAMMA_STEPS - 1) as f32).round() as usize]
}

/// The flow code whose displacement in `table` ([`crate::resident::flow_lut`],
/// increasing with the code) is nearest to `x`.
fn flow_code(table: &[f32; 256], x: f32) -> i8 {
    // Index 0 is the unknown code's.
    let known = &table[1..];
    let i = known.partition_point(|&v| v < x).min(known.len() - 1);
    let i = if i > 0 && (x - known[i - 1]) < (known[i] - x) {
        i - 1
    } else {
        i
    };
    (i as i32 + 1 - 128) as i8
}

/// Basis codes `b` (cropped by `from`) reduced by `level` into the crop `to`: each
/// block averaged in linear light and coded again. A texel transparent at this level (0
/// in `alpha`, the alpha reduced alike) holds no light, the colour being premultiplied:
/// its codes are 0, as relighting takes them (and it is not filtered).
pub fn reduce_basis(b: &BasisCodes, from: Crop, to: Crop, level: u8, alpha: &[u8]) -> BasisCodes {
    let lut = gamma_lut();
    let codes = gamma_codes();
    let add = |sum: &mut [f32; 3], t: &[u8; 3]| {
        for c in 0..3 {
            sum[c] += lut[t[c] as usize];
        }
    };
    let finish = |sum: [f32; 3], n: u32| sum.map(|s| fast_gamma_code(codes, s / n.max(1) as f32));
    BasisCodes {
        width: to.width as usize,
        height: to.height as usize,
        tiles: b
            .tiles
            .iter()
            .map(|tile| reduce(tile, from, to, level, Some(alpha), add, finish))
            .collect(),
        scales: b.scales.clone(),
    }
}

/// Fitted normals' octahedral codes (cropped by `from`, [`normal_of`]) reduced by
/// `level` into the crop `to`: the fitted normals of each block averaged and coded again;
/// none where none is fitted, and where `alpha` (the reduced alpha codes) is 0.
pub fn reduce_normals(
    codes: &[[u8; 2]],
    from: Crop,
    to: Crop,
    level: u8,
    alpha: &[u8],
) -> Vec<[u8; 2]> {
    let add = |sum: &mut glam::Vec3, c: &[u8; 2]| {
        if let Some(n) = normal_of(*c) {
            *sum += n;
        }
    };
    let finish = |sum: glam::Vec3, _| sum.try_normalize().map_or([0, 0], normal_code);
    reduce(codes, from, to, level, Some(alpha), add, finish)
}

/// Alpha codes (cropped by `from`) reduced by `level` into the crop `to`.
pub fn reduce_alpha(a: &[u8], from: Crop, to: Crop, level: u8) -> Vec<u8> {
    let add = |sum: &mut u32, &v: &u8| *sum += v as u32;
    let finish = |sum: u32, n: u32| ((sum + n / 2) / n.max(1)) as u8;
    reduce(a, from, to, level, None, add, finish)
}

/// Flow codes (cropped by `from`, decoded and coded again through `table`,
/// [`crate::resident::flow_lut`]) reduced by `level` into the crop `to`: the known texels
/// of each block averaged and divided by `2^level`; unknown where none is known.
pub fn reduce_flow(
    flow: &[[i8; 2]],
    table: &[f32; 256],
    from: Crop,
    to: Crop,
    level: u8,
) -> Vec<[i8; 2]> {
    let scale = 1.0 / (1u32 << level) as f32;
    let add = |acc: &mut (f32, f32, u32), c: &[i8; 2]| {
        if c[0] != UNKNOWN_CODE && c[1] != UNKNOWN_CODE {
            acc.0 += table[(c[0] as i32 + 128) as usize];
            acc.1 += table[(c[1] as i32 + 128) as usize];
            acc.2 += 1;
        }
    };
    let finish = |(u, v, known): (f32, f32, u32), _| {
        if known == 0 {
            return [UNKNOWN_CODE; 2];
        }
        let f = scale / known as f32;
        [flow_code(table, u * f), flow_code(table, v * f)]
    };
    reduce(flow, from, to, level, None, add, finish)
}

/// The whole image of `size` reduced by `level`, as a crop (and its size).
pub fn reduced_image(size: (u32, u32), level: u8) -> ((u32, u32), Crop) {
    let whole = Crop {
        x0: 0,
        y0: 0,
        width: size.0,
        height: size.1,
    };
    let to = reduced_crop(whole, level);
    ((to.width, to.height), to)
}

#[cfg(test)]
mod tests {
    use glam::Vec3;

    use super::*;

    #[test]
    fn normals_reduce_to_the_mean_of_the_fitted_ones_of_each_block() {
        let crop = |w, h| Crop {
            x0: 0,
            y0: 0,
            width: w,
            height: h,
        };
        let a = Vec3::new(1.0, 0.0, 1.0).normalize();
        let b = Vec3::new(-1.0, 0.0, 1.0).normalize();
        // A 4 x 1 strip: a block of two normals, and a block of one normal and none.
        let codes = [normal_code(a), normal_code(b), normal_code(a), [0, 0]];
        let out = reduce_normals(&codes, crop(4, 1), crop(2, 1), 1, &[255, 255]);
        assert!(normal_of(out[0]).unwrap().angle_between(Vec3::Z) < 0.01);
        assert!(normal_of(out[1]).unwrap().angle_between(a) < 0.01);
        // A transparent reduced texel holds none.
        let out = reduce_normals(&codes, crop(4, 1), crop(2, 1), 1, &[0, 255]);
        assert_eq!(out[0], [0, 0]);
    }

    #[test]
    fn the_level_halves_with_the_pixels_per_metre() {
        assert_eq!(detail_level(100.0, 100.0), 0);
        assert_eq!(detail_level(100.0, 60.0), 0);
        assert_eq!(detail_level(100.0, 50.0), 1);
        assert_eq!(detail_level(100.0, 25.0), 2);
        assert_eq!(detail_level(100.0, 1.0), MAX_LEVEL);
        assert_eq!(detail_level(100.0, 0.0), 0);
        assert_eq!(detail_level(f32::NAN, 10.0), 0);
    }

    #[test]
    fn reduced_basis_codes_average_in_linear_light_and_hold_no_light_where_transparent() {
        // A 4x2 image, two tiles, reduced by one level into two texels.
        let tile = |a: u8, b: u8| {
            vec![
                [a; 3], [b; 3], [9; 3], [9; 3], [a; 3], [b; 3], [9; 3], [9; 3],
            ]
        };
        let b = BasisCodes {
            width: 4,
            height: 2,
            tiles: vec![tile(0, 255), tile(200, 200)],
            scales: vec![1.0, 2.0],
        };
        let full = Crop {
            x0: 0,
            y0: 0,
            width: 4,
            height: 2,
        };
        let (_, to) = reduced_image((4, 2), 1);
        // Both texels opaque: each block averaged in linear light.
        let r = reduce_basis(&b, full, to, 1, &[255, 255]);
        let lut = gamma_lut();
        let mid = fast_gamma_code(gamma_codes(), (lut[0] + lut[255]) / 2.0);
        assert!(mid > 128, "linear light, not codes, averaged: {mid}");
        assert_eq!(r.tiles[0], vec![[mid; 3], [9; 3]]);
        assert_eq!(r.tiles[1], vec![[200; 3], [9; 3]]);
        assert_eq!(r.scales, b.scales);
        // The second transparent: its codes are 0 in every tile.
        let r = reduce_basis(&b, full, to, 1, &[255, 0]);
        assert_eq!(r.tiles[0], vec![[mid; 3], [0; 3]]);
        assert_eq!(r.tiles[1], vec![[200; 3], [0; 3]]);
    }

    #[test]
    fn a_reduced_crop_covers_the_blocks_of_the_full_one() {
        let c = reduced_crop(
            Crop {
                x0: 3,
                y0: 4,
                width: 10,
                height: 7,
            },
            1,
        );
        // Columns 3..13 are in blocks 1..7, rows 4..11 in blocks 2..6.
        assert_eq!((c.x0, c.y0, c.width, c.height), (1, 2, 6, 4));
    }

    #[test]
    fn flow_codes_invert_the_table() {
        let q = frf_reflectance::flowcodec::quant::LogQuantizer::new(0.05, 40.0).unwrap();
        let table = crate::resident::flow_lut(&q);
        for c in -127..=127i8 {
            assert_eq!(flow_code(&table, table[(c as i32 + 128) as usize]), c);
        }
    }

    #[test]
    fn gamma_codes_invert_the_table() {
        let lut = gamma_lut();
        let table = gamma_codes();
        for c in 0..=255u8 {
            assert_eq!(gamma_code(&lut, lut[c as usize]), c);
            assert_eq!(fast_gamma_code(table, lut[c as usize]), c);
        }
    }

    #[test]
    fn a_reduced_camera_sees_a_point_at_the_block_it_fell_in() {
        let cam = crate::synthetic::bench_camera((160, 120)).unwrap();
        let p = Vec3::new(0.1, 1.2, 0.05);
        let full = cam.project(p).unwrap();
        let half = reduced_camera(&cam, 1).project(p).unwrap();
        // Full pixel x (centre at x) lies in block floor((x + 0.5) / 2), centre 2k + 0.5.
        assert!(((full.x + 0.5) / 2.0 - 0.5 - half.x).abs() < 1e-4);
        assert!(((full.y + 0.5) / 2.0 - 0.5 - half.y).abs() < 1e-4);
    }
}
