//! Packing walkers' pixel boxes into pages of a frame's size: the GPU draws each walker
//! of a frame into its own box of pixels (`crate::footprint::PixelBox`) and reads its
//! render only there, so the renders need not each take a frame-sized layer. A distant
//! walker's box is a few thousand pixels; forty of them share one page instead of
//! holding forty frame-sized layers (at 1920x1080 in RGBA32F, 33 MB each).
//!
//! Shelf packing: boxes from the tallest down, left to right along a shelf as tall as
//! its first box, a new shelf below when a box does not fit across, a new page when it
//! does not fit below. A box is never larger than the page (it lies within the frame),
//! so every box finds a place, at worst on a page of its own: never more pages than
//! boxes, which is what one layer a walker took.

/// Where a box lies in the pages: page, and the texel of its first column and row.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Placement {
    /// Page (array layer).
    pub page: u32,
    /// Column of the box's first column.
    pub x: u32,
    /// Row of the box's first row.
    pub y: u32,
}

/// Places boxes of `sizes` (width, height; each at most `page`) on pages of size `page`;
/// returns each box's placement, in the order given, and the pages used (at least 1).
pub fn pack(sizes: &[(u32, u32)], page: (u32, u32)) -> (Vec<Placement>, u32) {
    let mut order: Vec<usize> = (0..sizes.len()).collect();
    // Tallest first, then widest, then as given: the same boxes pack the same way.
    order.sort_by_key(|&i| (std::cmp::Reverse(sizes[i].1), std::cmp::Reverse(sizes[i].0)));
    let mut placed = vec![
        Placement {
            page: 0,
            x: 0,
            y: 0
        };
        sizes.len()
    ];
    // The open shelf: its page, top row, height, and the next free column.
    let (mut page_of, mut top, mut height, mut next) = (0u32, 0u32, 0u32, 0u32);
    for i in order {
        let (w, h) = (sizes[i].0.min(page.0), sizes[i].1.min(page.1));
        if w == 0 || h == 0 {
            // Nothing drawn: any place does.
            continue;
        }
        if next + w > page.0 {
            // A new shelf below this one.
            top += height;
            height = 0;
            next = 0;
        }
        if top + h > page.1 {
            page_of += 1;
            top = 0;
            height = 0;
            next = 0;
        }
        if height == 0 {
            height = h;
        }
        placed[i] = Placement {
            page: page_of,
            x: next,
            y: top,
        };
        next += w;
    }
    (placed, page_of + 1)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn overlap(a: (Placement, (u32, u32)), b: (Placement, (u32, u32))) -> bool {
        let ((pa, (wa, ha)), (pb, (wb, hb))) = (a, b);
        pa.page == pb.page
            && pa.x < pb.x + wb
            && pb.x < pa.x + wa
            && pa.y < pb.y + hb
            && pb.y < pa.y + ha
    }

    fn check(sizes: &[(u32, u32)], page: (u32, u32)) -> u32 {
        let (placed, pages) = pack(sizes, page);
        assert_eq!(placed.len(), sizes.len());
        for (i, (&p, &(w, h))) in placed.iter().zip(sizes).enumerate() {
            assert!(p.page < pages, "box {i} on page {} of {pages}", p.page);
            assert!(
                p.x + w <= page.0 && p.y + h <= page.1,
                "box {i} {p:?} {w}x{h}"
            );
            for (j, (&q, &s)) in placed.iter().zip(sizes).enumerate().skip(i + 1) {
                let empty = w * h == 0 || s.0 * s.1 == 0;
                assert!(
                    empty || !overlap((p, (w, h)), (q, s)),
                    "boxes {i} and {j} overlap"
                );
            }
        }
        assert!(pages as usize <= sizes.len().max(1));
        pages
    }

    #[test]
    fn boxes_lie_within_their_page_and_never_overlap() {
        // Forty walkers' boxes of a distant crowd share one page of 640x360.
        let crowd: Vec<(u32, u32)> = (0..40).map(|i| (18 + i % 7, 40 + (i * 5) % 23)).collect();
        assert_eq!(check(&crowd, (640, 360)), 1);
        // Whole frames take a page each, and a box beside them finds room after.
        assert_eq!(check(&[(64, 48), (64, 48), (10, 10)], (64, 48)), 3);
        // A pseudo-random mix, small pages: every box placed, none overlapping.
        let mut seed = 25u32;
        let mixed: Vec<(u32, u32)> = (0..300)
            .map(|_| {
                seed = seed.wrapping_mul(1_103_515_245).wrapping_add(12_345);
                ((seed >> 8) % 97, (seed >> 16) % 61)
            })
            .collect();
        let pages = check(&mixed, (100, 64));
        let area: u32 = mixed.iter().map(|(w, h)| w * h).sum();
        // Shelves waste some room, not most of it.
        assert!(pages <= 3 * area.div_ceil(100 * 64), "{pages} pages");
    }

    #[test]
    fn no_boxes_still_give_a_page() {
        assert_eq!(pack(&[], (8, 8)), (Vec::new(), 1));
        assert_eq!(check(&[(0, 0), (0, 5)], (8, 8)), 1);
    }
}
