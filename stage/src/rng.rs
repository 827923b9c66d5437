//! Counter-based random numbers: every random value of the stage is a hash of the seed
//! and of *what* it is for (cycle, frame, pixel, ...), never of the order in which
//! threads happen to run, so a capture is bit-identical for a seed on any number of cores.

/// SplitMix64's finalizer (Steele, Lea & Flood, OOPSLA 2014): a bijective 64-bit mix.
#[inline]
pub fn mix64(mut x: u64) -> u64 {
    x = x.wrapping_add(0x9E37_79B9_7F4A_7C15);
    x = (x ^ (x >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    x = (x ^ (x >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    x ^ (x >> 31)
}

/// Hashes a sequence of keys into one 64-bit value.
#[inline]
pub fn hash(keys: &[u64]) -> u64 {
    keys.iter()
        .fold(0x51_7CC1_B727_220A, |h, &k| mix64(h ^ mix64(k)))
}

/// A uniform value in `[0, 1)` from a hash.
#[inline]
pub fn uniform(h: u64) -> f32 {
    (h >> 40) as f32 / (1u64 << 24) as f32
}

/// A standard normal value from a hash (Box–Muller on two derived uniforms).
#[inline]
pub fn gaussian(h: u64) -> f32 {
    let u1 = uniform(mix64(h ^ 0x1234_5678)).max(1e-7);
    let u2 = uniform(mix64(h ^ 0x8765_4321));
    (-2.0 * u1.ln()).sqrt() * (std::f32::consts::TAU * u2).cos()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn gaussian_has_unit_moments() {
        let n = 200_000;
        let (mut s, mut s2) = (0.0f64, 0.0f64);
        for i in 0..n {
            let g = gaussian(hash(&[7, i])) as f64;
            s += g;
            s2 += g * g;
        }
        let mean = s / n as f64;
        let var = s2 / n as f64 - mean * mean;
        // Standard error of the mean is 1/sqrt(n) ≈ 0.0022; allow 3 of them.
        assert!(mean.abs() < 0.007, "mean {mean}");
        assert!((var - 1.0).abs() < 0.02, "variance {var}");
    }

    #[test]
    fn uniform_is_in_range() {
        for i in 0..10_000 {
            let u = uniform(hash(&[i]));
            assert!((0.0..1.0).contains(&u));
        }
    }
}
