//! Flows extended beyond the subject when a pose is made resident (docs/design.md
//! section 4.2): every unknown flow texel takes the code of the nearest known one
//! (4-connected steps, ties to the first reached in row order).
//!
//! A field stores flow only on the subject and a few pixels around it; beyond, it is
//! unknown, and reading it as zero displacement would stop a silhouette pixel at the
//! edge of the stored flow while the subject's edge moves on: the anti-aliased border
//! of a limb that moves by 3 pixels would be torn from it. The solved morph reads each
//! view's flow at the pixels around the subject that the output's background maps to;
//! carrying the edge's flow outward keeps the border moving with the edge. This costs
//! nothing to store (the field is unchanged) and one pass over each flow when a pose is
//! loaded.

use frf_core::filter::extend_nearest;
use frf_reflectance::flowcodec::quant::UNKNOWN_CODE;

/// Whether a texel's code pair is known.
fn known(c: [i8; 2]) -> bool {
    c[0] != UNKNOWN_CODE && c[1] != UNKNOWN_CODE
}

/// Gives every unknown texel of a `width x height` flow the code of its nearest known
/// texel ([`frf_core::filter::extend_nearest`]). A flow with no known texel stays
/// unknown.
pub fn extend_flow(codes: &mut [[i8; 2]], width: usize, height: usize) {
    extend_nearest(codes, width, height, |&c| known(c));
}

#[cfg(test)]
mod tests {
    use super::*;

    const U: [i8; 2] = [UNKNOWN_CODE, UNKNOWN_CODE];

    #[test]
    fn unknown_texels_take_the_nearest_known_code() {
        let mut codes = vec![U; 5 * 3];
        codes[5 + 1] = [3, -4];
        codes[5 + 4] = [7, 8];
        extend_flow(&mut codes, 5, 3);
        assert_eq!(codes[0], [3, -4]);
        assert_eq!(codes[2 * 5], [3, -4]);
        assert_eq!(codes[4], [7, 8]);
        assert_eq!(codes[2 * 5 + 3], [7, 8]);
        assert!(codes.iter().all(|&c| known(c)));
    }

    #[test]
    fn a_flow_with_nothing_known_stays_unknown() {
        let mut codes = vec![U; 6];
        extend_flow(&mut codes, 3, 2);
        assert!(codes.iter().all(|&c| c == U));
    }
}
