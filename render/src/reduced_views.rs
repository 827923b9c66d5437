//! Views reduced to a level of detail ([`crate::detail`]), kept between the poses made
//! resident: a crowd makes the same pose resident once per walker heading and again for
//! every new light, and each walker at a level reads the same few views. Kept within a
//! budget of bytes (least recently used out), a view's reduced image (basis codes and
//! alpha) and each of its reduced flows are read, decoded and reduced once; a walker's
//! residency then costs its relighting coefficients and the relight itself.

use std::sync::Arc;

use frf_core::lru::Lru;
use frf_reflectance::imagecodec::BasisCodes;

use crate::error::Result;

/// A view's basis codes and alpha codes reduced to a level, of the whole reduced image.
#[derive(Debug)]
pub struct ReducedImage {
    /// The basis codes.
    pub basis: BasisCodes,
    /// The alpha codes.
    pub alpha: Vec<u8>,
    /// The fitted normals' codes (none where the field holds none).
    pub normals: Vec<[u8; 2]>,
}

impl ReducedImage {
    fn bytes(&self) -> u64 {
        let tiles: usize = self.basis.tiles.iter().map(|t| 3 * t.len()).sum();
        (tiles + self.alpha.len() + 2 * self.normals.len()) as u64
    }
}

/// What is kept: a view's image, or one of its flows (codes, extended), per pose, view
/// (`u`-major), neighbour and level.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Key {
    Image {
        pose: u32,
        view: usize,
        level: u8,
    },
    Flow {
        pose: u32,
        view: usize,
        neighbour: usize,
        level: u8,
    },
}

#[derive(Clone)]
enum Entry {
    Image(Arc<ReducedImage>),
    Flow(Arc<Vec<[i8; 2]>>),
}

impl Entry {
    fn bytes(&self) -> u64 {
        match self {
            Entry::Image(i) => i.bytes(),
            Entry::Flow(f) => 2 * f.len() as u64,
        }
    }
}

/// The kept reduced views (empty, and keeping nothing, until a budget is set).
#[derive(Default)]
pub struct ReducedViews {
    kept: Lru<Key, Entry>,
}

impl ReducedViews {
    /// Keeps at most `bytes` (0: nothing).
    pub fn with_budget(bytes: u64) -> Self {
        let views = Self::default();
        views.kept.set_budget(bytes);
        views
    }

    /// Reads served from kept views, and views reduced.
    pub fn counts(&self) -> (u64, u64) {
        self.kept.counts()
    }

    fn get_or(&self, key: Key, make: impl FnOnce() -> Result<Entry>) -> Result<Entry> {
        self.kept.get_or(key, Entry::bytes, make)
    }

    /// View `view` of pose `pose` at `level`, made by `make` unless kept.
    pub fn image(
        &self,
        (pose, view, level): (u32, usize, u8),
        make: impl FnOnce() -> Result<ReducedImage>,
    ) -> Result<Arc<ReducedImage>> {
        let key = Key::Image { pose, view, level };
        match self.get_or(key, || Ok(Entry::Image(Arc::new(make()?))))? {
            Entry::Image(i) => Ok(i),
            Entry::Flow(_) => unreachable!("an image key holds an image"),
        }
    }

    /// The flow of view `view` of pose `pose` toward neighbour `neighbour` at `level`,
    /// made by `make` unless kept.
    pub fn flow(
        &self,
        (pose, view, neighbour, level): (u32, usize, usize, u8),
        make: impl FnOnce() -> Result<Vec<[i8; 2]>>,
    ) -> Result<Arc<Vec<[i8; 2]>>> {
        let key = Key::Flow {
            pose,
            view,
            neighbour,
            level,
        };
        match self.get_or(key, || Ok(Entry::Flow(Arc::new(make()?))))? {
            Entry::Flow(f) => Ok(f),
            Entry::Image(_) => unreachable!("a flow key holds a flow"),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn image(n: usize) -> ReducedImage {
        ReducedImage {
            basis: BasisCodes {
                width: n,
                height: 1,
                tiles: vec![vec![[1; 3]; n]],
                scales: vec![1.0],
            },
            alpha: vec![255; n],
            normals: Vec::new(),
        }
    }

    #[test]
    fn views_are_made_once_within_the_budget_and_the_oldest_leave() {
        // Each image holds 4 * n bytes; the budget holds two of n = 10.
        let kept = ReducedViews::with_budget(80);
        let mut made = 0;
        for view in [0, 1, 0, 1, 2, 0] {
            kept.image((3, view, 1), || {
                made += 1;
                Ok(image(10))
            })
            .unwrap();
        }
        // 0, 1 made; 0, 1 kept; 2 made (0 leaves: 1 was used after it); 0 made again.
        assert_eq!(made, 4);
        assert_eq!(kept.counts(), (2, 4));
        // Another level or pose is another view; a flow is not an image.
        kept.image((3, 0, 2), || Ok(image(1))).unwrap();
        kept.flow((3, 0, 0, 1), || Ok(vec![[0, 0]; 4])).unwrap();
        assert_eq!(kept.counts(), (2, 6));
        // Nothing is kept without a budget.
        let none = ReducedViews::default();
        for _ in 0..2 {
            none.image((0, 0, 1), || Ok(image(1))).unwrap();
        }
        assert_eq!(none.counts(), (0, 2));
    }
}
