//! Views' basis images kept decoded between reads ([`FieldFile::keep_decoded`]): a scene
//! of many walkers makes the same pose resident once per walker heading and relights it
//! whenever the light changes, and each time the same views' mosaics would be read and
//! decoded again. Within a stated budget of bytes (the least recently used leave first),
//! a view's decoded codes are read and decoded once and shared; the budget is 0 (nothing
//! kept) until a caller sets it.
//!
//! [`FieldFile::keep_decoded`]: crate::FieldFile::keep_decoded

use std::sync::Arc;

use frf_core::lru::Lru;

use crate::chunk::ChunkKey;
use crate::imagecodec::BasisCodes;

/// The kept views, within their budget ([`Lru`]).
#[derive(Default)]
pub struct DecodedBasis {
    kept: Lru<ChunkKey, Arc<BasisCodes>>,
}

/// Bytes a view's codes hold.
fn size(b: &BasisCodes) -> u64 {
    b.tiles.iter().map(|t| 3 * t.len() as u64).sum::<u64>() + 4 * b.scales.len() as u64
}

impl DecodedBasis {
    /// Keeps at most `bytes` of decoded views (0: none; the kept ones beyond it leave).
    pub fn set_budget(&self, bytes: u64) {
        self.kept.set_budget(bytes);
    }

    /// The view of `key`, decoded by `decode` unless it is kept.
    pub fn get_or(
        &self,
        key: ChunkKey,
        decode: impl FnOnce() -> crate::Result<BasisCodes>,
    ) -> crate::Result<Arc<BasisCodes>> {
        self.kept
            .get_or(key, |c| size(c), || Ok(Arc::new(decode()?)))
    }

    /// Reads served from kept views, and decodes made, so far.
    pub fn counts(&self) -> (u64, u64) {
        self.kept.counts()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::container::ChunkKind;

    fn view(pose: u32) -> (ChunkKey, BasisCodes) {
        let key = ChunkKey {
            pose,
            u: 0,
            v: 0,
            kind: ChunkKind::Basis,
        };
        let codes = BasisCodes {
            width: 10,
            height: 10,
            tiles: vec![vec![[pose as u8; 3]; 100]],
            scales: vec![1.0],
        };
        (key, codes)
    }

    #[test]
    fn a_view_is_decoded_once_within_the_budget_and_again_beyond_it() {
        let kept = DecodedBasis::default();
        let decodes = std::cell::Cell::new(0);
        let get = |pose: u32| {
            let (key, codes) = view(pose);
            kept.get_or(key, || {
                decodes.set(decodes.get() + 1);
                Ok(codes)
            })
            .unwrap()
        };
        // No budget: nothing kept.
        get(1);
        get(1);
        assert_eq!(decodes.get(), 2);
        // Room for two views (304 bytes each): the third pushes out the least recent.
        kept.set_budget(700);
        assert_eq!(get(1).tiles[0][0], [1; 3]);
        get(2);
        get(1);
        assert_eq!(decodes.get(), 4);
        get(3);
        get(1);
        assert_eq!(decodes.get(), 5, "1 was used after 2: 2 left");
        get(2);
        assert_eq!(decodes.get(), 6);
        assert_eq!(kept.counts(), (2, 6));
        // A smaller budget drops what no longer fits.
        kept.set_budget(0);
        get(2);
        assert_eq!(decodes.get(), 7);
    }
}
