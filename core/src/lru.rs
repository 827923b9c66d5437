//! Values kept within a budget of bytes, the least recently used leaving first, shared
//! between threads: a value costly to make (a view decoded, a view reduced) is made once
//! while it is kept. The budget is 0 (nothing kept) until it is set.

use std::sync::{Mutex, MutexGuard};

/// The kept values by key, with their bytes.
pub struct Lru<K, V> {
    inner: Mutex<State<K, V>>,
}

struct State<K, V> {
    budget: u64,
    bytes: u64,
    /// Most recently used last.
    entries: Vec<(K, V, u64)>,
    hits: u64,
    misses: u64,
}

impl<K, V> Default for Lru<K, V> {
    fn default() -> Self {
        Self {
            inner: Mutex::new(State {
                budget: 0,
                bytes: 0,
                entries: Vec::new(),
                hits: 0,
                misses: 0,
            }),
        }
    }
}

impl<K: PartialEq, V: Clone> Lru<K, V> {
    fn lock(&self) -> MutexGuard<'_, State<K, V>> {
        self.inner.lock().unwrap_or_else(|e| e.into_inner())
    }

    /// Keeps at most `bytes` (0: nothing; the kept values beyond it leave).
    pub fn set_budget(&self, bytes: u64) {
        let mut s = self.lock();
        s.budget = bytes;
        s.shrink();
    }

    /// Values served from the kept ones, and values made, so far.
    pub fn counts(&self) -> (u64, u64) {
        let s = self.lock();
        (s.hits, s.misses)
    }

    /// The value of `key`, made by `make` unless it is kept (then kept when its `bytes`
    /// fit the budget). Made outside the lock: other keys are made in parallel.
    pub fn get_or<E>(
        &self,
        key: K,
        bytes: impl FnOnce(&V) -> u64,
        make: impl FnOnce() -> Result<V, E>,
    ) -> Result<V, E> {
        {
            let mut s = self.lock();
            if let Some(i) = s.entries.iter().position(|(k, _, _)| *k == key) {
                let entry = s.entries.remove(i);
                let found = entry.1.clone();
                s.entries.push(entry);
                s.hits += 1;
                return Ok(found);
            }
        }
        let made = make()?;
        let size = bytes(&made);
        let mut s = self.lock();
        s.misses += 1;
        if size <= s.budget && !s.entries.iter().any(|(k, _, _)| *k == key) {
            s.bytes += size;
            s.entries.push((key, made.clone(), size));
            s.shrink();
        }
        Ok(made)
    }
}

impl<K, V> State<K, V> {
    fn shrink(&mut self) {
        while self.bytes > self.budget && !self.entries.is_empty() {
            let (_, _, size) = self.entries.remove(0);
            self.bytes -= size;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn values_are_made_once_within_the_budget_and_the_least_recent_leave() {
        let kept: Lru<u32, u32> = Lru::default();
        let made = std::cell::Cell::new(0);
        let get = |k: u32| {
            kept.get_or(
                k,
                |_| 10,
                || {
                    made.set(made.get() + 1);
                    Ok::<_, ()>(k * 2)
                },
            )
            .unwrap()
        };
        // No budget: nothing kept.
        assert_eq!((get(1), get(1)), (2, 2));
        assert_eq!(made.get(), 2);
        // Room for two: 1, 2 made; 1 served; 3 made, pushing out 2 (1 was used after it).
        kept.set_budget(25);
        get(1);
        get(2);
        get(1);
        get(3);
        assert_eq!(made.get(), 5);
        get(1);
        assert_eq!(made.get(), 5);
        get(2);
        assert_eq!(made.get(), 6);
        assert_eq!(kept.counts(), (2, 6));
        // A value larger than the budget is made and not kept.
        kept.set_budget(5);
        get(4);
        get(4);
        assert_eq!(made.get(), 8);
        // An error is passed on and nothing is kept.
        assert_eq!(kept.get_or(9, |_| 1, || Err("bad")), Err("bad"));
    }
}
