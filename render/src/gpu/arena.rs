//! Buffers shared by many poses, each pose holding a range of one of a few pages, so that
//! one dispatch can read or write every pose's part (docs/design.md section 4.9). A range
//! stays where it was placed for as long as its holder keeps it (bind groups made over it
//! stay valid) and is given back when the holder drops it, but taken again only after the
//! next submission ([`Arena::recycle`]): work recorded before it may still read or write
//! the range, and a new holder's first writes (uploads) go to the queue ahead of that
//! work. A page is a fixed-size buffer;
//! a range that does not fit in any page's free room opens a new page (one as large as
//! the range where it outgrows the page size), so nothing ever moves.
//!
//! The bookkeeping of a page's free room ([`Spans`]) is plain host code, tested apart.

use std::sync::{Arc, Mutex, MutexGuard};

/// Free room of one page: disjoint spans (start, length), in order, merged where they
/// touch.
#[derive(Debug, Clone, PartialEq, Eq)]
pub(super) struct Spans {
    free: Vec<(u64, u64)>,
}

impl Spans {
    /// A page of `size` bytes, all free.
    pub(super) fn new(size: u64) -> Self {
        Self {
            free: if size > 0 {
                vec![(0, size)]
            } else {
                Vec::new()
            },
        }
    }

    /// Takes `size` bytes starting at a multiple of `align` (a power of two) from the
    /// first free span they fit in; where they start, or `None` where none holds them.
    pub(super) fn take(&mut self, size: u64, align: u64) -> Option<u64> {
        debug_assert!(align.is_power_of_two() && size > 0);
        let (i, at) = self.free.iter().enumerate().find_map(|(i, &(s, len))| {
            let at = s.next_multiple_of(align);
            (at + size <= s + len).then_some((i, at))
        })?;
        let (s, len) = self.free[i];
        let after = (at + size, s + len - at - size);
        match (at > s, after.1 > 0) {
            (false, false) => {
                self.free.remove(i);
            }
            (false, true) => self.free[i] = after,
            (true, false) => self.free[i] = (s, at - s),
            (true, true) => {
                self.free[i] = (s, at - s);
                self.free.insert(i + 1, after);
            }
        }
        Some(at)
    }

    /// Gives back the `size` bytes at `at` (taken before), merged with the free spans on
    /// either side.
    pub(super) fn give(&mut self, at: u64, size: u64) {
        let i = self.free.partition_point(|&(s, _)| s < at);
        debug_assert!(i == 0 || self.free[i - 1].0 + self.free[i - 1].1 <= at);
        debug_assert!(i == self.free.len() || at + size <= self.free[i].0);
        let joins_before = i > 0 && self.free[i - 1].0 + self.free[i - 1].1 == at;
        let joins_after = i < self.free.len() && at + size == self.free[i].0;
        match (joins_before, joins_after) {
            (true, true) => {
                self.free[i - 1].1 += size + self.free[i].1;
                self.free.remove(i);
            }
            (true, false) => self.free[i - 1].1 += size,
            (false, true) => self.free[i] = (at, size + self.free[i].1),
            (false, false) => self.free.insert(i, (at, size)),
        }
    }

    /// Bytes free.
    #[cfg(test)]
    fn free_bytes(&self) -> u64 {
        self.free.iter().map(|s| s.1).sum()
    }
}

/// One page: its buffer, its free room, and the ranges given back since the last
/// submission (free once it is sent).
struct Page {
    buffer: wgpu::Buffer,
    spans: Mutex<Spans>,
    retired: Mutex<Vec<(u64, u64)>>,
}

impl Page {
    fn spans(&self) -> MutexGuard<'_, Spans> {
        self.spans.lock().unwrap_or_else(|e| e.into_inner())
    }
}

/// Pages of one kind of data (their usage), each [`Arena::page_bytes`] or larger.
pub(super) struct Arena {
    label: &'static str,
    usage: wgpu::BufferUsages,
    page_bytes: u64,
    /// Where a range may start: the device's storage-binding offset alignment.
    align: u64,
    pages: Mutex<Vec<Arc<Page>>>,
}

/// A range of an arena's page, given back when dropped.
pub(super) struct ArenaRange {
    page: Arc<Page>,
    offset: u64,
    size: u64,
}

impl Drop for ArenaRange {
    fn drop(&mut self) {
        (self.page.retired.lock())
            .unwrap_or_else(|e| e.into_inner())
            .push((self.offset, self.size));
    }
}

impl ArenaRange {
    /// The page's buffer (every range of the page shares it).
    pub(super) fn buffer(&self) -> &wgpu::Buffer {
        &self.page.buffer
    }

    /// Where it starts in the buffer, in bytes.
    pub(super) fn offset(&self) -> u64 {
        self.offset
    }

    /// Where it starts in the buffer, in `vec4`s (16 bytes).
    pub(super) fn vec4_offset(&self) -> u32 {
        (self.offset / 16) as u32
    }

    /// Its bytes.
    pub(super) fn size(&self) -> u64 {
        self.size
    }

    /// What names it: its page and offset.
    pub(super) fn key(&self) -> (usize, u64) {
        (Arc::as_ptr(&self.page) as usize, self.offset)
    }
}

impl Arena {
    /// An arena of pages of `page_bytes` with `usage`, for `device` (ranges start at its
    /// storage-binding offset alignment, so that each can be bound alone).
    pub(super) fn new(
        device: &wgpu::Device,
        label: &'static str,
        usage: wgpu::BufferUsages,
        page_bytes: u64,
    ) -> Self {
        let limits = device.limits();
        Self {
            label,
            usage,
            page_bytes: page_bytes.min(limits.max_storage_buffer_binding_size),
            align: (limits.min_storage_buffer_offset_alignment as u64).max(16),
            pages: Mutex::new(Vec::new()),
        }
    }

    /// A range of `bytes` (rounded up to 16), in the first page with room, else in a new
    /// page made on `device`.
    pub(super) fn take(&self, device: &wgpu::Device, bytes: u64) -> ArenaRange {
        let size = bytes.max(16).next_multiple_of(16);
        let mut pages = self.pages.lock().unwrap_or_else(|e| e.into_inner());
        for page in pages.iter() {
            if let Some(offset) = page.spans().take(size, self.align) {
                return ArenaRange {
                    page: page.clone(),
                    offset,
                    size,
                };
            }
        }
        let page_size = size.max(self.page_bytes);
        let mut spans = Spans::new(page_size);
        let offset = spans.take(size, self.align).expect("a new page holds it");
        let page = Arc::new(Page {
            buffer: device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(self.label),
                size: page_size,
                usage: self.usage,
                mapped_at_creation: false,
            }),
            spans: Mutex::new(spans),
            retired: Mutex::new(Vec::new()),
        });
        pages.push(page.clone());
        ArenaRange { page, offset, size }
    }

    /// Makes the ranges given back before a submission free again, once it is sent: the
    /// work that may read them is then ahead, in the queue, of any later write to them.
    pub(super) fn recycle(&self) {
        let pages = self.pages.lock().unwrap_or_else(|e| e.into_inner());
        for page in pages.iter() {
            let retired =
                std::mem::take(&mut *page.retired.lock().unwrap_or_else(|e| e.into_inner()));
            let mut spans = page.spans();
            for (at, size) in retired {
                spans.give(at, size);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A range given back is not taken again before the next submission (work recorded
    /// before may still read it, and a new holder's uploads would be queued ahead of that
    /// work: a walker relit from another's coefficients), and is after it.
    #[test]
    fn a_range_given_back_is_taken_again_only_after_a_submission() {
        let Some(gpu) = crate::gpu::Gpu::for_tests() else {
            return;
        };
        let (device, arena) = (gpu.device(), &gpu.coefficients);
        let first = arena.take(device, 1000);
        let at = first.offset();
        drop(first);
        let second = arena.take(device, 1000);
        assert_ne!(second.offset(), at, "taken again before a submission");
        gpu.submit([]);
        let third = arena.take(device, 1000);
        assert_eq!(third.offset(), at, "free again after the submission");
        drop(second);
    }

    /// Ranges taken never overlap and start aligned; room given back is merged and taken
    /// again, until the page is whole again.
    #[test]
    fn spans_taken_are_disjoint_aligned_and_come_back_whole() {
        let mut spans = Spans::new(4096);
        let mut taken: Vec<(u64, u64)> = Vec::new();
        // Sizes that leave gaps under a 256-byte alignment.
        for (k, size) in [100u64, 256, 16, 700, 48, 1000].into_iter().enumerate() {
            let at = spans.take(size, 256).expect("room");
            assert_eq!(at % 256, 0, "range {k} starts at {at}");
            for &(a, s) in &taken {
                assert!(
                    at + size <= a || a + s <= at,
                    "{at}+{size} overlaps {a}+{s}"
                );
            }
            taken.push((at, size));
        }
        // Full: nothing of 4096 fits now, and a range too large for the room is refused.
        assert_eq!(spans.take(4096, 256), None);
        // The gaps before alignment are still free room.
        let gaps = 4096 - taken.iter().map(|t| t.1).sum::<u64>();
        assert_eq!(spans.free_bytes(), gaps);
        // Given back out of order, the page is one span again.
        for i in [3usize, 0, 5, 1, 4, 2] {
            let (at, size) = taken[i];
            spans.give(at, size);
        }
        assert_eq!(spans, Spans::new(4096));
        // Room given back is taken again at the same place.
        let a = spans.take(512, 256).unwrap();
        let b = spans.take(512, 256).unwrap();
        spans.give(a, 512);
        assert_eq!(spans.take(300, 256), Some(a));
        assert_eq!((a, b), (0, 512));
    }
}
