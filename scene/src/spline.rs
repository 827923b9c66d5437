//! Smooth curves through timed keys, shared by camera paths ([`crate::path`]) and walkers'
//! paths ([`crate::walk`]): cubic Hermite segments between consecutive keys whose
//! tangents come from the neighbouring keys over their time spans (Catmull–Rom for
//! unevenly spaced keys, so that the velocity stays continuous across a key), one-sided
//! at the first and last key. Times are 64-bit (as every time of a scene), values 32-bit.

use glam::Vec3;

/// Where time `t` falls among `times` (strictly increasing, at least two): the segment
/// `i` (between keys `i` and `i + 1`), the fraction `s` of the way along it, and its span
/// `h` in seconds. `t` is clamped to the keys' span.
pub fn segment(times: &[f64], t: f64) -> (usize, f32, f64) {
    let n = times.len();
    let t = t.clamp(times[0], times[n - 1]);
    let i = times.partition_point(|&k| k <= t).clamp(1, n - 1) - 1;
    let h = times[i + 1] - times[i];
    // The fraction in 64 bits, then 32 for the values.
    (i, ((t - times[i]) / h) as f32, h)
}

/// The tangent at key `j` of values `value(k)` at `times`, scaled to a segment of `h`
/// seconds: the change over its neighbours (one-sided at the ends) times `h` over their
/// time span. The ratio of spans first, so that keys a subnormal time apart do not divide
/// by it (an infinite tangent times a tiny `h`).
pub fn tangent(times: &[f64], value: &dyn Fn(usize) -> Vec3, j: usize, h: f64) -> Vec3 {
    let (l, r) = (j.saturating_sub(1), (j + 1).min(times.len() - 1));
    (value(r) - value(l)) * (h / (times[r] - times[l])) as f32
}

/// The cubic Hermite curve from `p0` (tangent `m0`) to `p1` (tangent `m1`) at fraction `s`.
pub fn hermite(p0: Vec3, p1: Vec3, m0: Vec3, m1: Vec3, s: f32) -> Vec3 {
    let (s2, s3) = (s * s, s * s * s);
    p0 * (2.0 * s3 - 3.0 * s2 + 1.0)
        + m0 * (s3 - 2.0 * s2 + s)
        + p1 * (-2.0 * s3 + 3.0 * s2)
        + m1 * (s3 - s2)
}

/// The derivative of [`hermite`] with respect to `s` (divide by the segment's span for a
/// velocity).
pub fn hermite_derivative(p0: Vec3, p1: Vec3, m0: Vec3, m1: Vec3, s: f32) -> Vec3 {
    let s2 = s * s;
    p0 * (6.0 * s2 - 6.0 * s)
        + m0 * (3.0 * s2 - 4.0 * s + 1.0)
        + p1 * (-6.0 * s2 + 6.0 * s)
        + m1 * (3.0 * s2 - 2.0 * s)
}

/// The Catmull–Rom curve through `value(k)` at `times` (at least two keys), at `t`.
pub fn catmull_rom(times: &[f64], value: &dyn Fn(usize) -> Vec3, t: f64) -> Vec3 {
    let (i, s, h) = segment(times, t);
    let (m0, m1) = (tangent(times, value, i, h), tangent(times, value, i + 1, h));
    hermite(value(i), value(i + 1), m0, m1, s)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_derivative_is_the_curves_slope() {
        let (p0, p1) = (Vec3::new(0.0, 1.0, 2.0), Vec3::new(3.0, -1.0, 0.5));
        let (m0, m1) = (Vec3::new(1.0, 0.0, -2.0), Vec3::new(-0.5, 2.0, 1.0));
        for s in [0.0f32, 0.3, 0.5, 0.9] {
            let e = 1e-3;
            let numeric =
                (hermite(p0, p1, m0, m1, s + e) - hermite(p0, p1, m0, m1, s - e)) / (2.0 * e);
            let exact = hermite_derivative(p0, p1, m0, m1, s);
            assert!((numeric - exact).length() < 1e-2, "{numeric} vs {exact}");
        }
        // The ends: the keys and their tangents.
        assert_eq!(hermite(p0, p1, m0, m1, 0.0), p0);
        assert!((hermite(p0, p1, m0, m1, 1.0) - p1).length() < 1e-6);
        assert_eq!(hermite_derivative(p0, p1, m0, m1, 0.0), m0);
        assert!((hermite_derivative(p0, p1, m0, m1, 1.0) - m1).length() < 1e-5);
    }

    #[test]
    fn segments_clamp_to_the_span() {
        let times = [0.0, 1.0, 3.0];
        assert_eq!(segment(&times, -1.0), (0, 0.0, 1.0));
        assert_eq!(segment(&times, 2.0), (1, 0.5, 2.0));
        assert_eq!(segment(&times, 9.0), (1, 1.0, 2.0));
    }
}
