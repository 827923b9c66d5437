//! GPU resources kept between frames, per key (a frame size, a number of walkers): the
//! few most recently used stay, the least recently used is dropped when a new key needs
//! room. A frame holds its resources through an `Arc`, so dropping one from the pool never
//! pulls it from under a frame still using it.

use std::sync::{Arc, Mutex};

/// A pool of at most `capacity` resources of type `T`, keyed by `K`, least recently used
/// evicted first.
pub struct Kept<K, T> {
    capacity: usize,
    /// Most recently used last.
    entries: Mutex<Vec<(K, Arc<T>)>>,
}

impl<K: PartialEq, T> Kept<K, T> {
    /// An empty pool keeping at most `capacity` (at least one).
    pub fn new(capacity: usize) -> Self {
        Self {
            capacity: capacity.max(1),
            entries: Mutex::new(Vec::new()),
        }
    }

    /// The resource of `key`, made by `make` on first use; either way it becomes the most
    /// recently used.
    pub fn get(&self, key: K, make: impl FnOnce() -> T) -> Arc<T> {
        // A poisoned lock only means a thread panicked while holding it; the list is whole.
        let mut entries = self.entries.lock().unwrap_or_else(|e| e.into_inner());
        let found = entries.iter().position(|(k, _)| *k == key);
        let entry = match found {
            Some(i) => entries.remove(i),
            None => {
                if entries.len() >= self.capacity {
                    entries.remove(0);
                }
                (key, Arc::new(make()))
            }
        };
        let value = entry.1.clone();
        entries.push(entry);
        value
    }
}

/// A number no other resource of this process has: what a kept bind group's key names a
/// resource by (an address may be reused once the resource is gone; this may not).
pub fn unique_id() -> u64 {
    static NEXT: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(0);
    NEXT.fetch_add(1, std::sync::atomic::Ordering::Relaxed)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_least_recently_used_is_dropped() {
        let pool = Kept::new(2);
        let made = std::cell::Cell::new(0);
        let make = |v: u32| {
            made.set(made.get() + 1);
            v
        };
        assert_eq!(*pool.get(1, || make(10)), 10);
        assert_eq!(*pool.get(2, || make(20)), 20);
        // 1 used again: 2 is now the least recently used, and goes when 3 comes.
        assert_eq!(*pool.get(1, || make(11)), 10);
        assert_eq!(*pool.get(3, || make(30)), 30);
        assert_eq!(*pool.get(1, || make(12)), 10);
        assert_eq!(*pool.get(2, || make(21)), 21);
        assert_eq!(made.get(), 4);
    }
}
