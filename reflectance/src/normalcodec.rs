//! The codec of a view's fitted normals (docs/design.md section 3.3): per texel, the
//! unit normal as two 8-bit octahedral codes (the sphere folded onto a square, each
//! axis in 254 steps: at most about 0.6° from the normal encoded), `(0, 0)` where no
//! normal was fitted; the codes compressed with zstd. Two bytes a texel before
//! compression: small beside the basis mosaic, and what the sun's relighting needs
//! (its ratio of shadings depends on the normal alone, [`crate::light_fit`]).
//!
//! Layout: `[width u32][height u32][zstd(u8 x, u8 y per texel)]`.

use glam::{Vec2, Vec3};

use crate::error::{ReflectanceError, Result};
use crate::imagecodec::ZSTD_LEVEL;

/// Steps of an octahedral axis; codes `1..=STEPS + 1`, 0 meaning "no normal".
const STEPS: f32 = 254.0;

/// The octahedral codes of a unit normal (never `(0, 0)`).
pub fn normal_code(n: Vec3) -> [u8; 2] {
    let n = n / (n.x.abs() + n.y.abs() + n.z.abs()).max(1e-20);
    let p = if n.z >= 0.0 {
        Vec2::new(n.x, n.y)
    } else {
        // The lower half folded over the square's corners.
        let sign = |v: f32| if v >= 0.0 { 1.0 } else { -1.0 };
        Vec2::new((1.0 - n.y.abs()) * sign(n.x), (1.0 - n.x.abs()) * sign(n.y))
    };
    let q = |v: f32| (1.0 + ((v.clamp(-1.0, 1.0) + 1.0) * 0.5 * STEPS).round()) as u8;
    [q(p.x), q(p.y)]
}

/// The unit normal of octahedral codes, `None` for `(0, 0)` (the GPU's relighting
/// decodes the same way, `shaders/relight.wgsl`).
pub fn normal_of(code: [u8; 2]) -> Option<Vec3> {
    if code == [0, 0] {
        return None;
    }
    let f = |c: u8| (c.max(1) as f32 - 1.0) / STEPS * 2.0 - 1.0;
    let (x, y) = (f(code[0]), f(code[1]));
    let z = 1.0 - x.abs() - y.abs();
    let t = (-z).max(0.0);
    let x = if x >= 0.0 { x - t } else { x + t };
    let y = if y >= 0.0 { y - t } else { y + t };
    Some(Vec3::new(x, y, z).normalize())
}

/// Encodes a `width` x `height` view's normals (see the module text).
pub fn encode_normals(width: usize, height: usize, normals: &[Option<Vec3>]) -> Result<Vec<u8>> {
    if normals.len() != width * height {
        return Err(ReflectanceError::Mismatch {
            what: "normals".into(),
            expected: (width * height).to_string(),
            got: normals.len().to_string(),
        });
    }
    let raw: Vec<u8> = normals
        .iter()
        .flat_map(|n| match n {
            Some(n) if n.is_finite() && n.length_squared() > 0.0 => normal_code(*n),
            _ => [0, 0],
        })
        .collect();
    let packed = zstd::bulk::compress(&raw, ZSTD_LEVEL).map_err(|e| ReflectanceError::Codec {
        what: "zstd",
        problem: e.to_string(),
    })?;
    let mut out = Vec::with_capacity(8 + packed.len());
    out.extend_from_slice(&(width as u32).to_le_bytes());
    out.extend_from_slice(&(height as u32).to_le_bytes());
    out.extend_from_slice(&packed);
    Ok(out)
}

/// Decodes [`encode_normals`]'s bytes to the width, height and per texel codes.
pub fn decode_normal_codes(bytes: &[u8]) -> Result<(usize, usize, Vec<[u8; 2]>)> {
    if bytes.len() < 8 {
        return Err(ReflectanceError::Corrupt("normals header truncated".into()));
    }
    let word = |at: usize| {
        u32::from_le_bytes([bytes[at], bytes[at + 1], bytes[at + 2], bytes[at + 3]]) as usize
    };
    let (w, h) = (word(0), word(4));
    let max = frf_core::io::limits::MAX_DIMENSION as usize;
    if w == 0 || h == 0 || w > max || h > max {
        return Err(ReflectanceError::Corrupt(format!(
            "normals header claims {w}x{h} texels"
        )));
    }
    let raw = crate::unzstd::decompress_exact(&bytes[8..], w * h * 2, "normal codes")?;
    Ok((w, h, raw.chunks_exact(2).map(|c| [c[0], c[1]]).collect()))
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    proptest! {
        #[test]
        fn a_normal_comes_back_within_a_degree(
            x in -1.0f32..1.0, y in -1.0f32..1.0, z in -1.0f32..1.0
        ) {
            let n = Vec3::new(x, y, z);
            prop_assume!(n.length() > 0.05);
            let n = n.normalize();
            let back = normal_of(normal_code(n)).unwrap();
            prop_assert!(back.angle_between(n).to_degrees() < 1.0, "{n} -> {back}");
        }
    }

    #[test]
    fn normals_round_trip_and_bad_bytes_are_refused() {
        let normals = vec![Some(Vec3::Z), None, Some(-Vec3::Z), Some(Vec3::X)];
        let bytes = encode_normals(2, 2, &normals).unwrap();
        let (w, h, codes) = decode_normal_codes(&bytes).unwrap();
        assert_eq!((w, h), (2, 2));
        let back: Vec<Option<Vec3>> = codes.into_iter().map(normal_of).collect();
        assert_eq!(back[1], None);
        for (a, b) in normals.iter().zip(&back) {
            if let (Some(a), Some(b)) = (a, b) {
                assert!(a.angle_between(*b) < 1e-3, "{a} {b}");
            }
        }
        assert!(decode_normal_codes(&bytes[..bytes.len() - 3]).is_err());
        assert!(decode_normal_codes(&bytes[..5]).is_err());
        assert!(encode_normals(3, 2, &normals).is_err());
    }
}
