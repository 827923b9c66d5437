//! Stiff and extreme cases of the morph and of the re-binning through the cylinder, on the
//! CPU reference (no GPU needed): bilinear positions exactly at and within 1e-7 of a
//! quad's vertices (the morph returns the corner view); virtual cameras exactly at a grid
//! camera, on the cylinder's axis, above and below the grid, grazing the cylinder, facing
//! away from it, and with fields of view of 0.01° and 179.9°. Each case asserts a value
//! from an independent computation (geometry of the ring of cameras, the corner view's
//! own samples), and every ray is also checked to give the same hit through the column
//! index as through the loop over every quad (`intersect` vs `intersect_brute`). The shadow's
//! stiff cases are in `stiff_shadows.rs`; camera paths and scenes at their limits in the
//! scene crate (`scene/tests/stiff.rs`); the morph's defining properties away from these
//! limits in `cpu_reference.rs`.

#![allow(clippy::unwrap_used)] // tests: a failed unwrap is a failed test

use frf_core::camera::Camera;
use frf_core::grid::Neighbour;
use frf_core::light::direction_from_azimuth_elevation;
use frf_reflectance::flowcodec::quant::LogQuantizer;
use frf_render::cpu::{render_cpu, render_pixel};
use frf_render::cylinder::{Clamp, Cylinder, CylinderHit, bilinear_weights};
use frf_render::morph::e06::{morph, source_pixel};
use frf_render::morph::{Kind, Variant, quad_views};
use frf_render::resident::{LitViews, ResidentPose};
use glam::{Vec2, Vec3};

// ---------------------------------------------------------------------------------------
// The stage's grid, for the re-binning cases.

/// Radius of the stage's ring of cameras, metres, and the point they look at.
const RADIUS: f32 = 4.5;
const TARGET: Vec3 = Vec3::new(0.0, 0.9, 0.0);
/// Elevations of its three rows, degrees; its columns are 10° apart.
const ELEVATIONS: [f32; 3] = [0.0, 17.0, 34.0];
const COLUMNS: usize = 36;
/// How far the walls above and below the grid reach, metres (`WALL_HEIGHT_M`).
const WALL: f32 = 1.0e3;

/// The centre of stage camera `(u, v)`: azimuth `−10° u`, elevation `ELEVATIONS[v]`.
fn centre(u: usize, v: usize) -> Vec3 {
    TARGET
        + direction_from_azimuth_elevation(
            -(u as f32 * 10.0).to_radians(),
            ELEVATIONS[v].to_radians(),
        ) * RADIUS
}

/// The cylinder of the stage's 36 x 3 grid (a ring).
fn stage() -> (Vec<Vec3>, Cylinder) {
    let centres: Vec<Vec3> = (0..COLUMNS)
        .flat_map(|u| (0..3).map(move |v| centre(u, v)))
        .collect();
    let cyl = Cylinder::new(&centres, COLUMNS, 3, true);
    assert!(
        cyl.has_column_index(),
        "the comparison below needs the index"
    );
    (centres, cyl)
}

/// The hit of the ray, asserted to be the same through the column index as through the
/// loop over every quad, and finite.
fn hit(cyl: &Cylinder, origin: Vec3, dir: Vec3) -> Option<CylinderHit> {
    let indexed = cyl.intersect(origin, dir);
    assert_eq!(
        indexed,
        cyl.intersect_brute(origin, dir),
        "index vs loop at {origin} along {dir}"
    );
    if let Some(h) = indexed {
        assert!(
            h.point.is_finite() && h.t.is_finite() && h.beta.is_finite() && h.gamma.is_finite(),
            "{h:?}"
        );
        assert!((0.0..=1.0).contains(&h.beta) && (0.0..=1.0).contains(&h.gamma));
    }
    indexed
}

/// `(u + β, v + γ)` of a hit, `u + β` taken modulo the columns.
fn grid_position(h: &CylinderHit) -> Vec2 {
    Vec2::new(
        (h.u as f32 + h.beta).rem_euclid(COLUMNS as f32),
        h.v as f32 + h.gamma,
    )
}

/// Distance between two column positions on the ring (modulo the columns).
fn column_distance(a: f32, b: f32) -> f32 {
    let d = (a - b).rem_euclid(COLUMNS as f32);
    d.min(COLUMNS as f32 - d)
}

/// The horizontal distance from the axis at which the line `origin + t dir` passes
/// (seen from above).
fn line_distance_from_axis(origin: Vec3, dir: Vec3) -> f32 {
    let o = Vec2::new(origin.x - TARGET.x, origin.z - TARGET.z);
    let d = Vec2::new(dir.x, dir.z).normalize();
    o.perp_dot(d).abs()
}

// ---------------------------------------------------------------------------------------
// A small synthetic pose (as in `cpu_reference.rs`), for the morph and the renderer.

const W: u32 = 24;
const H: u32 = 32;
const POSE_COLUMNS: usize = 8;
const POSE_RADIUS: f32 = 4.0;
const POSE_ELEVATIONS: [f32; 2] = [0.0, 0.3];

/// An 8x2 ring of cameras 4 m from the subject; views are colour ramps, each neighbour's
/// flow a constant shift (different per direction and view).
fn pose() -> ResidentPose {
    let (columns, rows) = (POSE_COLUMNS, POSE_ELEVATIONS.len());
    let q = LogQuantizer::new(0.5, 8.0).unwrap();
    let mut cameras = Vec::new();
    let mut prelit = Vec::new();
    let mut flows = Vec::new();
    for u in 0..columns {
        for (v, &elevation) in POSE_ELEVATIONS.iter().enumerate() {
            let d = direction_from_azimuth_elevation(-(u as f32) * 0.785, elevation);
            let eye = TARGET + d * POSE_RADIUS;
            cameras.push(Camera::look_at(eye, TARGET, Vec3::Y, 0.5, W, H).unwrap());
            let seed = (u * 2 + v) as u32;
            prelit.push(
                (0..W * H)
                    .map(|i| {
                        let (x, y) = (i % W, i / W);
                        [
                            ((x * 9 + seed * 17) % 256) as u8,
                            ((y * 7 + seed * 5) % 256) as u8,
                            (seed * 13 % 256) as u8,
                            200,
                        ]
                    })
                    .collect::<Vec<_>>(),
            );
            let mut f: [Option<Vec<[i8; 2]>>; 4] = Default::default();
            for n in Neighbour::ALL {
                if n.of(u, v, columns, rows, true).is_some() {
                    let code = [
                        q.encode(0.7 + n.index() as f32 + 0.1 * seed as f32),
                        q.encode(-0.4 * n.index() as f32),
                    ];
                    f[n.index()] = Some(vec![code; (W * H) as usize]);
                }
            }
            flows.push(f);
        }
    }
    ResidentPose::from_views(LitViews {
        grid: (columns, rows, true),
        size: (W, H),
        cameras,
        prelit,
        scales: (0..columns * rows).map(|i| 1.0 + i as f32 * 0.1).collect(),
        codes: flows,
        quantizer: q,
    })
}

fn quad_hit(u: usize, v: usize, beta: f32, gamma: f32, point: Vec3) -> CylinderHit {
    CylinderHit {
        u,
        v,
        beta,
        gamma,
        point,
        t: 1.0,
        clamped: Clamp::None,
    }
}

const VERTICES: [(f32, f32); 4] = [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0), (1.0, 1.0)];

/// Every variant, the ablations included.
fn variants() -> impl Iterator<Item = Variant> {
    Variant::ALL.into_iter().chain(Variant::ABLATIONS)
}

/// The variants that interpolate at the pixel of the interpolated camera (all but the
/// solved morph, whose vertex properties are tested through whole rays).
fn at_pixel_variants() -> impl Iterator<Item = Variant> {
    variants().filter(|v| v.kind() != Kind::FourWay)
}

/// The largest premultiplied value a pixel of the pose may take: its largest scale
/// (colour) and 1 (alpha).
fn peak(p: &ResidentPose) -> f32 {
    p.scales.iter().copied().fold(1.0, f32::max)
}

/// Every pixel finite, alpha in [0, 1], colour in [0, peak] (a convex blend of the views).
fn assert_bounded(p: &ResidentPose, img: &frf_core::image::Image<[f32; 4]>, name: &str) {
    let peak = peak(p);
    for px in img.pixels() {
        assert!(px.iter().all(|c| c.is_finite()), "{name}: {px:?}");
        assert!((-1e-6..=1.0 + 1e-6).contains(&px[3]), "{name}: {px:?}");
        assert!(
            px[..3].iter().all(|&c| (-1e-6..=peak + 1e-5).contains(&c)),
            "{name}: {px:?}"
        );
    }
}

// ---------------------------------------------------------------------------------------
// The morph at and next to the vertices.

#[test]
fn at_a_vertex_every_variant_returns_the_corner_view_bit_for_bit() {
    // At (β, γ) ∈ {0, 1}² one source has weight exactly 1 and is displaced by 0 · F:
    // the sum is 1 · I(s), which is I(s) exactly in floating point.
    let p = pose();
    for s in [
        Vec2::new(10.3, 17.6),
        Vec2::new(0.0, 0.0),
        Vec2::new(23.0, 31.0),
    ] {
        for u in [0, 3, POSE_COLUMNS - 1] {
            for (k, (b, g)) in VERTICES.into_iter().enumerate() {
                let h = quad_hit(u, 0, b, g, Vec3::ZERO);
                let view = quad_views(&p.geometry, &h)[k];
                let want = p.sample_prelit(view, s);
                for variant in at_pixel_variants() {
                    assert_eq!(
                        morph(&p, &h, s, variant),
                        want,
                        "{variant:?} at ({b}, {g}) of column {u}, s = {s}"
                    );
                }
                // The weights are the unit vector of the corner exactly.
                let mut unit = [0.0; 4];
                unit[k] = 1.0;
                assert_eq!(bilinear_weights(b, g), unit);
            }
        }
    }
}

#[test]
fn within_1e_7_of_a_vertex_the_morph_is_the_corner_view_within_1e_6() {
    // Near a vertex the other sources weigh at most ~2e-7 together and the corner's own
    // displacement is at most 1e-7 · 8 px (the quantizer's range): the first-order change
    // is ≤ 2e-7 · 2.6 (the largest value) + 8e-7 px · 2.6/px (steepest ramp step), about
    // 2.6e-6 at worst, and a few f32 roundings of values up to 2.6 (ulp 2.4e-7). Bound:
    // 1e-6 relative to max(1, |value|), plus the ramp term for the flowed variants.
    let p = pose();
    let eps = 1e-7f32;
    let near = |x: f32| if x == 0.0 { eps } else { 1.0 - eps };
    let s = Vec2::new(10.3, 17.6);
    let mut worst = 0.0f32;
    for (k, (b, g)) in VERTICES.into_iter().enumerate() {
        for (nb, ng) in [(near(b), g), (b, near(g)), (near(b), near(g))] {
            let h = quad_hit(2, 0, nb, ng, Vec3::ZERO);
            let view = quad_views(&p.geometry, &h)[k];
            let want = p.sample_prelit(view, s);
            // The weights: the corner's within 2.5e-7 of 1, the others within 1.5e-7 of 0.
            let w = bilinear_weights(nb, ng);
            for (i, wi) in w.into_iter().enumerate() {
                let target = if i == k { 1.0 } else { 0.0 };
                assert!(
                    (wi - target).abs() <= 2.5e-7,
                    "weights {w:?} near vertex {k}"
                );
            }
            for variant in at_pixel_variants() {
                let got = morph(&p, &h, s, variant);
                for c in 0..4 {
                    let err = (got[c] - want[c]).abs() / want[c].abs().max(1.0);
                    worst = worst.max(err);
                    assert!(
                        err <= 1e-6,
                        "{variant:?} at ({nb}, {ng}): {got:?} vs {want:?}"
                    );
                }
            }
        }
    }
    eprintln!("largest relative difference next to a vertex: {worst:e}");
}

#[test]
fn within_1e_7_of_a_vertex_the_sample_position_is_the_corner_cameras_pixel() {
    // A ray through the corner camera's centre: at the exact vertex the interpolated
    // camera is that camera, so the source pixel is where the ray crosses its image
    // (the pixel it was cast through). 1e-7 away, the camera turns by ≤ 1e-7 · 0.785 rad
    // (the angle between neighbours), moving the pixel by ≤ 1e-7 · 0.785 · f (f ≈ 63 px):
    // 5e-6 px; the rest is f32 resolution at 30 px (ulp 1.9e-6). Bound 1e-4 px.
    let p = pose();
    for (k, (b, g)) in VERTICES.into_iter().enumerate() {
        let base = quad_hit(5, 0, b, g, Vec3::ZERO);
        let view = quad_views(&p.geometry, &base)[k];
        let cam = p.geometry.cameras[view];
        for pixel in [
            Vec2::new(3.0, 4.0),
            Vec2::new(11.5, 15.5),
            Vec2::new(22.0, 30.0),
        ] {
            let dir = cam.ray_direction(pixel);
            let exact = quad_hit(5, 0, b, g, cam.centre());
            let s = source_pixel(&p.geometry, &exact, cam.centre(), dir, true).unwrap();
            assert!((s - pixel).length() < 1e-4, "vertex {k}: {s} vs {pixel}");
            let (nb, ng) = (
                if b == 0.0 { 1e-7 } else { 1.0 - 1e-7 },
                if g == 0.0 { 1e-7 } else { 1.0 - 1e-7 },
            );
            let near = quad_hit(5, 0, nb, ng, cam.centre());
            let s_near = source_pixel(&p.geometry, &near, cam.centre(), dir, true).unwrap();
            assert!(
                (s_near - pixel).length() < 1e-4,
                "vertex {k}: {s_near} vs {pixel}"
            );
        }
    }
}

// ---------------------------------------------------------------------------------------
// Re-binning: where rays cross the cylinder.

#[test]
fn a_camera_exactly_at_a_grid_camera_hits_that_cameras_vertex() {
    // A ray from a point of the (convex) cylinder into it enters there: t = 0 at the
    // vertex, so (u + β, v + γ) is the camera's (u, v) up to float rounding (1e-3).
    let (_, cyl) = stage();
    for (u, v) in [(0, 0), (0, 2), (7, 1), (17, 0), (35, 1), (35, 2)] {
        let eye = centre(u, v);
        let cam = Camera::look_at(eye, TARGET, Vec3::Y, 0.48, 9, 13).unwrap();
        for pixel in [
            Vec2::new(4.0, 6.0),
            Vec2::new(0.0, 0.0),
            Vec2::new(8.0, 12.0),
            Vec2::new(0.0, 12.0),
            Vec2::new(8.0, 0.0),
        ] {
            let dir = cam.ray_direction(pixel);
            let h = hit(&cyl, eye, dir).unwrap();
            let at = grid_position(&h);
            assert!(
                column_distance(at.x, u as f32) < 1e-3 && (at.y - v as f32).abs() < 1e-3,
                "camera ({u}, {v}), pixel {pixel}: hit at {at}"
            );
            assert!((h.point - eye).length() < 1e-3 && h.t.abs() < 1e-3, "{h:?}");
        }
    }
}

#[test]
fn a_camera_on_the_axis_sees_the_far_side_behind_it_at_the_right_column() {
    // On the axis at the bottom row's height, looking out horizontally: the ray's line
    // crosses the ring of the bottom row, a regular 36-gon of circumradius R, where the
    // entry is behind the camera (t < 0), at azimuth α of −dir. Between columns u and
    // u + 1 (azimuths −10° u and −10° (u + 1)), at φ = −α − 10° u past column u, the law
    // of sines in the triangle (axis, column u, hit) gives the fraction along the chord:
    // β = sin φ / (2 sin 5° · sin(95° − φ)), and the distance R sin 85° / sin(95° − φ).
    let (_, cyl) = stage();
    let origin = TARGET;
    for step in 0..144 {
        let azimuth = (step as f32 * 2.5).to_radians();
        let dir = direction_from_azimuth_elevation(azimuth, 0.0);
        let h = hit(&cyl, origin, dir).unwrap();
        assert!(h.t < 0.0, "the entry lies behind an inside camera: {h:?}");
        // −dir has azimuth α = azimuth + 180°; columns run toward negative azimuth.
        let a = (-(step as f64 * 2.5 + 180.0)).rem_euclid(360.0);
        let u = (a / 10.0).floor();
        let phi = (a - 10.0 * u).to_radians();
        let five = 5f64.to_radians();
        let beta = phi.sin() / (2.0 * five.sin() * (95f64.to_radians() - phi).sin());
        let distance = RADIUS as f64 * 85f64.to_radians().sin() / (95f64.to_radians() - phi).sin();
        let at = grid_position(&h);
        assert!(
            column_distance(at.x, (u + beta) as f32) < 1e-3 && at.y.abs() < 1e-3,
            "azimuth {azimuth}: hit at {at}, expected column {}",
            u + beta
        );
        assert!(
            (-h.t as f64 - distance).abs() < 1e-3,
            "t {} vs −{distance}",
            h.t
        );
    }
    // Higher up, between the rows: still behind, on the far side, between the rows'
    // radii (R cos 17° cos 5° ≤ r ≤ R).
    let origin = Vec3::new(0.0, 1.5, 0.0);
    for step in 0..36 {
        let dir = direction_from_azimuth_elevation((step as f32 * 10.0 + 3.0).to_radians(), 0.0);
        let h = hit(&cyl, origin, dir).unwrap();
        let r = Vec2::new(h.point.x, h.point.z).length();
        assert!(h.t < 0.0 && h.clamped == Clamp::None && h.v == 0, "{h:?}");
        assert!((h.point.y - 1.5).abs() < 1e-4, "{h:?}");
        let lo = RADIUS * 17f32.to_radians().cos() * 5f32.to_radians().cos();
        assert!((lo - 1e-4..=RADIUS + 1e-4).contains(&r), "radius {r}");
    }
    // Straight along the axis: parallel to every wall and quad's reach, nothing.
    assert_eq!(hit(&cyl, Vec3::new(0.0, 9.0, 0.0), Vec3::NEG_Y), None);
    assert_eq!(hit(&cyl, TARGET, Vec3::Y), None);
}

#[test]
fn rays_above_and_below_the_grid_are_clamped_to_the_end_rows() {
    // A camera 20 m above (or below) the stage, 9 m out, looking horizontally across it
    // (rays within ±0.6 rad of horizontal stay within 10 m of its height over the 15 m
    // that matter: far above the top row at 3.42 m, far within the walls' 1 km reach).
    // Seen from above, a line that passes within the top row's inner radius
    // R cos 34° cos 5° of the axis meets the wall above it; one beyond R cos 34° misses.
    // Likewise below with the bottom row's radii R cos 5° and R.
    let (_, cyl) = stage();
    for (height, clamp, v, gamma, radius) in [
        (
            20.0,
            Clamp::Above,
            1,
            1.0,
            RADIUS * 34f32.to_radians().cos(),
        ),
        (-20.0, Clamp::Below, 0, 0.0, RADIUS),
    ] {
        let eye = Vec3::new(0.0, height, 9.0);
        let cam = Camera::look_at(eye, Vec3::new(0.0, height, 0.0), Vec3::Y, 1.2, 32, 24).unwrap();
        let inner = radius * 5f32.to_radians().cos();
        let (mut hits, mut misses) = (0, 0);
        for y in 0..24 {
            for x in 0..32 {
                let dir = cam.ray_direction(Vec2::new(x as f32, y as f32));
                let reach = line_distance_from_axis(eye, dir);
                let h = hit(&cyl, eye, dir);
                if reach < inner - 1e-3 {
                    let h = h.unwrap_or_else(|| panic!("{clamp:?}: ray at {reach} m missed"));
                    assert_eq!((h.clamped, h.v, h.gamma), (clamp, v, gamma), "{h:?}");
                    assert!(h.t > 0.0 && (h.point.y - eye.y).abs() < 10.0, "{h:?}");
                    hits += 1;
                } else if reach > radius + 1e-3 {
                    assert_eq!(h, None, "{clamp:?}: ray at {reach} m");
                    misses += 1;
                }
            }
        }
        assert!(
            hits > 100 && misses > 100,
            "{clamp:?}: {hits} hits, {misses} misses"
        );
    }
}

#[test]
fn grazing_rays_hit_or_miss_as_the_rings_support_says() {
    // Horizontal lines at 2 m, between the bottom row (0.9 m) and the middle one
    // (2.216 m): there the cylinder's cross-section is the polygon of its column edges
    // (straight segments between the rows' centres) cut at that height. A line with
    // unit normal n (seen from above) at offset c meets it iff c ≤ max_vertices(v · n):
    // lines 1 mm inside the support hit near the tangent point, lines 1 mm outside miss.
    // Within 1e-5 m of tangency only the index-vs-loop agreement and finiteness are
    // asserted (either answer is right to float precision).
    let (_, cyl) = stage();
    let y = 2.0f32;
    let section: Vec<Vec2> = (0..COLUMNS)
        .map(|u| {
            let (a, b) = (centre(u, 0), centre(u, 1));
            let p = a + (b - a) * ((y - a.y) / (b.y - a.y));
            Vec2::new(p.x, p.z)
        })
        .collect();
    for angle_deg in [0.0f32, 2.5, 5.0, 37.0, 90.0, 181.0] {
        let a = angle_deg.to_radians();
        let d = Vec2::new(-a.cos(), a.sin()); // direction of travel, seen from above
        let n = Vec2::new(d.y, -d.x); // its normal
        let (support, tangent) = section
            .iter()
            .map(|v| (v.dot(n), *v))
            .max_by(|p, q| p.0.total_cmp(&q.0))
            .unwrap();
        for (offset, expect_hit) in [
            (-1e-2, Some(true)),
            (-1e-3, Some(true)),
            (-1e-5, None),
            (0.0, None),
            (1e-5, None),
            (1e-3, Some(false)),
            (1e-2, Some(false)),
        ] {
            let c = support + offset;
            let o = n * c - d * 20.0;
            let (origin, dir) = (Vec3::new(o.x, y, o.y), Vec3::new(d.x, 0.0, d.y));
            let h = hit(&cyl, origin, dir);
            match expect_hit {
                Some(true) => {
                    let h = h.unwrap_or_else(|| panic!("{angle_deg}°, {offset}: missed"));
                    // It enters within a chord's half-length (sqrt(2 r δ) ≤ 0.3 m for
                    // δ ≤ 1 cm) plus an edge (0.78 m, where the support is an edge) of
                    // the tangent vertex, ahead of the origin.
                    let p = Vec2::new(h.point.x, h.point.z);
                    assert!((p - tangent).length() < 1.1, "{angle_deg}°: {h:?}");
                    assert!(h.t > 15.0 && h.clamped == Clamp::None && h.v == 0, "{h:?}");
                }
                Some(false) => assert_eq!(h, None, "{angle_deg}°, {offset}"),
                None => {}
            }
        }
    }
}

#[test]
fn a_camera_facing_away_sees_nothing_and_renders_transparent_black() {
    // From 9 m out looking further out: every ray has dir.z > 0 from z = 9, while the
    // whole cylinder (walls included) lies within z ≤ 4.5: the line meets it only behind.
    let (_, cyl) = stage();
    let eye = Vec3::new(0.0, 1.5, 9.0);
    let cam = Camera::look_at(eye, Vec3::new(0.0, 1.5, 20.0), Vec3::Y, 2.0, 25, 19).unwrap();
    for y in 0..19 {
        for x in 0..25 {
            let dir = cam.ray_direction(Vec2::new(x as f32, y as f32));
            assert!(dir.z > 0.0);
            assert_eq!(hit(&cyl, eye, dir), None);
        }
    }
    let p = pose();
    let (img, stats) = render_cpu(&p, &cam, Variant::FourWay);
    assert_eq!(stats.missed, 25 * 19, "{stats:?}");
    assert!(img.pixels().iter().all(|px| *px == [0.0; 4]));
}

#[test]
fn a_field_of_view_of_a_hundredth_of_a_degree_sees_one_point() {
    // All rays lie within 8.7e-5 rad of the central one: on the stage's ring 4.5 m away
    // they spread over < 1 mm, < 1e-3 of a column. In the renderer the source pixels
    // spread over ≤ 1.7e-4 rad · 63 px/rad = 0.011 px (the steepest ramp step of the pose
    // is 2.6 per px, at its wrap: ≤ 0.029) and the weights by ≤ 1e-3 (≤ 2.6e-3 in
    // value): every pixel is the central one within 0.035.
    let (_, cyl) = stage();
    let eye = Vec3::new(0.0, 1.5, 9.0);
    let look = Vec3::new(0.0, 1.5, 0.0);
    let narrow = 0.01f32.to_radians();
    let cam = Camera::look_at(eye, look, Vec3::Y, narrow, 25, 19).unwrap();
    let central = hit(&cyl, eye, (look - eye).normalize()).unwrap();
    assert_eq!(central.clamped, Clamp::None);
    for y in 0..19 {
        for x in 0..25 {
            let h = hit(&cyl, eye, cam.ray_direction(Vec2::new(x as f32, y as f32))).unwrap();
            assert_eq!(h.clamped, Clamp::None);
            // Column 0 faces the camera: compare columns modulo the ring.
            let (a, b) = (grid_position(&h), grid_position(&central));
            assert!(
                column_distance(a.x, b.x) < 1e-3 && (a.y - b.y).abs() < 1e-3,
                "{a} vs {b}"
            );
        }
    }
    let p = pose();
    let (img, stats) = render_cpu(&p, &cam, Variant::FourWay);
    assert_eq!(stats.inside, 25 * 19, "{stats:?}");
    assert_bounded(&p, &img, "0.01°");
    let centre_px = img.get(12, 9);
    assert!(centre_px[3] > 0.5, "the subject is seen: {centre_px:?}");
    let worst = img
        .pixels()
        .iter()
        .flat_map(|px| (0..4).map(move |c| (px[c] - centre_px[c]).abs()))
        .fold(0.0f32, f32::max);
    eprintln!("0.01°: largest difference from the centre pixel {worst}");
    assert!(worst < 0.035, "largest difference from the centre {worst}");
}

#[test]
fn a_field_of_view_of_179_9_degrees_classifies_its_extreme_rays() {
    // 25 x 19 pixels, vertical field 179.9°: the focal length is f = 9.5 / tan(89.95°)
    // ≈ 8.3e-3 px, so one pixel off the centre is already 89.5° away from the view
    // direction. From 9 m out
    // at 1.5 m, looking at the axis:
    // - the centre pixel (12, 9) is the view direction itself: the same hit as any field;
    // - one pixel up (down), the ray climbs (falls) 1/f m per metre it runs toward the
    //   axis: it reaches the top (bottom) row's ring, ≤ 5.3 m (≤ 4.5 m) away, within the
    //   walls' 1 km: clamped above (below);
    // - nine pixels up or down, it climbs 9/f per metre: > 1 km before it gets there,
    //   missed; the middle row's ends run sideways at 9 m from the axis: missed.
    let (_, cyl) = stage();
    let eye = Vec3::new(0.0, 1.5, 9.0);
    let look = Vec3::new(0.0, 1.5, 0.0);
    let cam = Camera::look_at(eye, look, Vec3::Y, 179.9f32.to_radians(), 25, 19).unwrap();
    let f = cam.intrinsics.fy;
    let top_run = 9.0 - RADIUS * 34f32.to_radians().cos();
    let bottom_run = 9.0 - RADIUS;
    assert!(
        top_run / f < WALL && bottom_run / f < WALL,
        "one pixel off stays on the walls"
    );
    assert!(
        9.0 * (bottom_run.min(top_run) - 0.1) / f > 2.0 * WALL,
        "nine off leave them"
    );
    let narrow = Camera::look_at(eye, look, Vec3::Y, 1.0, 25, 19).unwrap();
    let at = |c: &Camera, x: f32, y: f32| hit(&cyl, eye, c.ray_direction(Vec2::new(x, y)));
    assert_eq!(at(&cam, 12.0, 9.0), at(&narrow, 12.0, 9.0));
    assert_eq!(at(&cam, 12.0, 9.0).unwrap().clamped, Clamp::None);
    let above = at(&cam, 12.0, 8.0).unwrap();
    assert_eq!(
        (above.clamped, above.v, above.gamma),
        (Clamp::Above, 1, 1.0)
    );
    let below = at(&cam, 12.0, 10.0).unwrap();
    assert_eq!(
        (below.clamped, below.v, below.gamma),
        (Clamp::Below, 0, 0.0)
    );
    for (x, y) in [
        (12.0, 0.0),
        (12.0, 18.0),
        (0.0, 9.0),
        (24.0, 9.0),
        (0.0, 0.0),
    ] {
        assert_eq!(at(&cam, x, y), None, "pixel ({x}, {y})");
    }
    // Every ray: index and loop agree (in `hit`).
    for y in 0..19 {
        for x in 0..25 {
            at(&cam, x as f32, y as f32);
        }
    }
    // The renderer: finite, bounded, the centre pixel the narrow camera's, the rays that
    // meet nothing transparent black.
    let p = pose();
    let (img, stats) = render_cpu(&p, &cam, Variant::FourWay);
    assert_bounded(&p, &img, "179.9°");
    assert_eq!(
        stats.inside + stats.clamped_above + stats.clamped_below + stats.missed,
        25 * 19
    );
    let (want, _) = render_pixel(
        &p,
        &p.geometry.cylinder,
        &narrow,
        Vec2::new(12.0, 9.0),
        Variant::FourWay,
    );
    assert_eq!(img.get(12, 9), want);
    assert!(want[3] > 0.5, "{want:?}");
    for (x, y) in [(12, 0), (12, 18), (0, 9), (24, 9)] {
        assert_eq!(img.get(x, y), [0.0; 4], "pixel ({x}, {y})");
    }
}
