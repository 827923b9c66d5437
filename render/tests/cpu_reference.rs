//! The CPU reference renderer: the morph's defining properties on a synthetic pose, the
//! stiff and extreme cases of the brief (vertices and edges, cameras on the axis, above
//! the grid, inside the cylinder, at grazing angles), and the four-way morph beating the
//! simpler interpolations against the virtual stage's truth.

#![allow(clippy::unwrap_used)] // tests: a failed unwrap is a failed test

use frf_core::camera::Camera;
use frf_core::grid::Neighbour;
use frf_reflectance::flowcodec::quant::LogQuantizer;
use frf_render::cpu::{render_cpu, render_pixel};
use frf_render::cylinder::{Clamp, CylinderHit};
use frf_render::morph::e06::{morph, source_pixel};
use frf_render::morph::{Variant, quad_views};
use frf_render::resident::{LitViews, ResidentPose, decode_flow};

use glam::{Vec2, Vec3};

const W: u32 = 24;
const H: u32 = 32;

/// A synthetic 8x2 grid: views are gradients, each neighbour's flow a constant shift
/// (codes chosen so that every direction differs), cameras on a ring around the subject.
fn pose() -> ResidentPose {
    let (columns, rows) = (8usize, 2usize);
    let q = LogQuantizer::new(0.5, 8.0).unwrap();
    let mut cameras = Vec::new();
    let mut prelit = Vec::new();
    let mut flows = Vec::new();
    for u in 0..columns {
        for v in 0..rows {
            let d = frf_core::light::direction_from_azimuth_elevation(
                -(u as f32) * 0.785,
                0.3 * v as f32,
            );
            let eye = Vec3::new(0.0, 0.9, 0.0) + d * 4.0;
            cameras
                .push(Camera::look_at(eye, Vec3::new(0.0, 0.9, 0.0), Vec3::Y, 0.5, W, H).unwrap());
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

fn hit(u: usize, v: usize, beta: f32, gamma: f32) -> CylinderHit {
    CylinderHit {
        u,
        v,
        beta,
        gamma,
        point: Vec3::ZERO,
        t: 1.0,
        clamped: Clamp::None,
    }
}

fn close(a: [f32; 4], b: [f32; 4]) -> bool {
    (0..4).all(|k| (a[k] - b[k]).abs() <= 1e-5 * (1.0 + b[k].abs()))
}

#[test]
fn the_four_way_morph_returns_each_source_at_its_vertex() {
    let p = pose();
    let s = Vec2::new(10.3, 17.6);
    for (k, (b, g)) in [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0), (1.0, 1.0)]
        .into_iter()
        .enumerate()
    {
        let h = hit(3, 0, b, g);
        let view = quad_views(&p.geometry, &h)[k];
        assert!(
            close(
                morph(&p, &h, s, Variant::FourWayE06),
                p.sample_prelit(view, s)
            ),
            "vertex {k}"
        );
    }
}

#[test]
fn the_four_way_morph_reduces_to_the_two_way_morph_on_every_edge() {
    let p = pose();
    let s = Vec2::new(7.5, 20.25);
    let two = |pv: usize, qv: usize, dir_pq: Neighbour, t: f32| {
        // b I_P(s + t F_{Q→P}) + t I_Q(s + b F_{P→Q})
        let b = 1.0 - t;
        let fp = p.sample_flow(qv, dir_pq.opposite(), s);
        let fq = p.sample_flow(pv, dir_pq, s);
        let (x, y) = (
            p.sample_prelit(pv, s + t * fp),
            p.sample_prelit(qv, s + b * fq),
        );
        [0, 1, 2, 3].map(|k| b * x[k] + t * y[k])
    };
    for t in [0.0, 0.3, 0.71, 1.0] {
        let [a, b, c, d] = quad_views(&p.geometry, &hit(6, 0, 0.0, 0.0));
        assert!(
            close(
                morph(&p, &hit(6, 0, t, 0.0), s, Variant::FourWayE06),
                two(a, b, Neighbour::Right, t)
            ),
            "γ = 0"
        );
        assert!(
            close(
                morph(&p, &hit(6, 0, t, 1.0), s, Variant::FourWayE06),
                two(c, d, Neighbour::Right, t)
            ),
            "γ = 1"
        );
        assert!(
            close(
                morph(&p, &hit(6, 0, 0.0, t), s, Variant::FourWayE06),
                two(a, c, Neighbour::Up, t)
            ),
            "β = 0"
        );
        assert!(
            close(
                morph(&p, &hit(6, 0, 1.0, t), s, Variant::FourWayE06),
                two(b, d, Neighbour::Up, t)
            ),
            "β = 1"
        );
        // On γ = 0 the two-way variant is the same morph.
        assert!(close(
            morph(&p, &hit(6, 0, t, 0.0), s, Variant::TwoWay),
            two(a, b, Neighbour::Right, t)
        ));
    }
    // The wrapping quad uses column 0 as its right side.
    let [a, b, _, _] = quad_views(&p.geometry, &hit(7, 0, 0.5, 0.0));
    assert_eq!((a, b), (14, 0));
}

#[test]
fn flow_codes_decode_and_unknown_is_zero() {
    let q = LogQuantizer::new(0.5, 8.0).unwrap();
    assert_eq!(decode_flow([i8::MIN, 3], &q), Vec2::ZERO);
    let f = decode_flow([q.encode(2.0), q.encode(-1.0)], &q);
    assert!((f - Vec2::new(2.0, -1.0)).length() < q.error_bound(2.0) * 1.5);
}

#[test]
fn rendering_from_a_capture_camera_reproduces_its_view() {
    let p = pose();
    let view = 5 * 2 + 1;
    let cam = p.geometry.cameras[view];
    let (img, stats) = render_cpu(&p, &cam, Variant::FourWay);
    assert_eq!(stats.missed, 0);
    let mut worst = 0.0f32;
    for y in 0..H {
        for x in 0..W {
            let want = p.sample_prelit(view, Vec2::new(x as f32, y as f32));
            let got = img.get(x as usize, y as usize);
            for k in 0..4 {
                worst = worst.max((want[k] - got[k]).abs());
            }
        }
    }
    assert!(worst < 2e-3, "largest difference {worst}");
}

#[test]
fn extreme_cameras_give_finite_bounded_output_and_say_what_happened() {
    let p = pose();
    let target = Vec3::new(0.0, 0.9, 0.0);
    let peak = p.scales.iter().copied().fold(0.0, f32::max);
    let cases = [
        (
            "on the axis, looking out",
            Vec3::new(0.0, 0.9, 0.0),
            Vec3::new(0.0, 0.9, -1.0),
        ),
        ("above the grid", Vec3::new(0.3, 9.0, 0.4), target),
        ("below the grid", Vec3::new(0.3, -6.0, 5.0), target),
        (
            "grazing the top row",
            Vec3::new(5.0, 3.0, 0.1),
            Vec3::new(-5.0, 2.9, 0.0),
        ),
        ("inside, off axis", Vec3::new(1.0, 1.0, 1.0), target),
        ("far away", Vec3::new(40.0, 10.0, 40.0), target),
        (
            "down the axis, wide",
            Vec3::new(0.0, 9.0, 0.0),
            Vec3::new(0.001, 0.0, 0.0),
        ),
        (
            "down the axis, narrow",
            Vec3::new(0.0, 9.0, 0.0),
            Vec3::new(0.001, 0.0, 0.0),
        ),
    ];
    for (name, eye, look) in cases {
        // A 0.5 mrad field keeps every ray within 4 km of the axis' direction: parallel
        // to the walls as far as they reach.
        let fov = if name.ends_with("narrow") { 1e-3 } else { 0.8 };
        let cam = Camera::look_at(eye, look, Vec3::Y, fov, 24, 18).unwrap();
        let (img, stats) = render_cpu(&p, &cam, Variant::FourWay);
        for px in img.pixels() {
            assert!(
                px.iter().all(|c| c.is_finite()),
                "{name}: non-finite output"
            );
            assert!(
                px[3] >= -1e-5 && px[3] <= 1.0 + 1e-5,
                "{name}: alpha {}",
                px[3]
            );
            assert!(
                px[..3].iter().all(|&c| c >= -1e-5 && c <= peak + 1e-3),
                "{name}: colour {px:?}"
            );
        }
        let total = stats.inside + stats.clamped_above + stats.clamped_below + stats.missed;
        assert_eq!(total, 24 * 18, "{name}");
        match name {
            "above the grid" => assert!(stats.clamped_above > 0, "{name}: {stats:?}"),
            "below the grid" => assert!(stats.clamped_below > 0, "{name}: {stats:?}"),
            // Rays fanning out from above the axis reach the walls above the top row.
            "down the axis, wide" => assert!(stats.clamped_above > 0, "{name}: {stats:?}"),
            "down the axis, narrow" => assert_eq!(stats.missed, 24 * 18, "{name}: {stats:?}"),
            _ => {}
        }
    }
}

#[test]
fn the_source_pixel_of_a_vertex_ray_is_its_own_pixel() {
    let p = pose();
    let cyl = &p.geometry.cylinder;
    let cam = p.geometry.cameras[4 * 2];
    for pixel in [
        Vec2::new(0.0, 0.0),
        Vec2::new(11.5, 16.0),
        Vec2::new(23.0, 31.0),
    ] {
        let dir = cam.ray_direction(pixel);
        let h = cyl.intersect(cam.centre(), dir).unwrap();
        let s = source_pixel(&p.geometry, &h, cam.centre(), dir, true).unwrap();
        assert!((s - pixel).length() < 1e-2, "{s} vs {pixel}");
        let (px, _) = render_pixel(&p, cyl, &cam, pixel, Variant::Linear);
        assert!(px.iter().all(|c| c.is_finite()));
    }
}
