//! Time the host spends in calls of one kind (submitting work, waiting on the device),
//! by the wall clock and by the calling thread's CPU time: on a software adapter that
//! runs submitted work on the calling thread, the CPU time inside submissions is the
//! device's work, and a frame's CPU time less it is the host's own, unlike its wall time
//! free of what other processes took of the machine.

use std::sync::atomic::{AtomicU64, Ordering};
use std::time::{Duration, Instant};

use frf_core::thread_clock::thread_cpu;

/// Wall and CPU nanoseconds spent in the calls counted so far.
#[derive(Default)]
pub(super) struct Spent {
    wall_ns: AtomicU64,
    cpu_ns: AtomicU64,
}

impl Spent {
    /// Runs `f`, counting its wall and CPU time.
    pub fn run<T>(&self, f: impl FnOnce() -> T) -> T {
        let (start, cpu) = (Instant::now(), thread_cpu());
        let out = f();
        let ns = |d: Duration| d.as_nanos() as u64;
        self.wall_ns
            .fetch_add(ns(start.elapsed()), Ordering::Relaxed);
        if let (Some(before), Some(after)) = (cpu, thread_cpu()) {
            self.cpu_ns
                .fetch_add(ns(after.saturating_sub(before)), Ordering::Relaxed);
        }
        out
    }

    /// Wall time spent so far.
    pub fn wall(&self) -> Duration {
        Duration::from_nanos(self.wall_ns.load(Ordering::Relaxed))
    }

    /// CPU time of the calling threads spent so far (zero where the system does not say).
    pub fn cpu(&self) -> Duration {
        Duration::from_nanos(self.cpu_ns.load(Ordering::Relaxed))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A call that sleeps counts its wall time and almost no CPU time.
    #[test]
    fn a_sleep_is_wall_time_not_cpu_time() {
        let spent = Spent::default();
        let out = spent.run(|| {
            std::thread::sleep(Duration::from_millis(30));
            7
        });
        assert_eq!(out, 7);
        assert!(
            spent.wall() >= Duration::from_millis(30),
            "{:?}",
            spent.wall()
        );
        assert!(spent.cpu() < Duration::from_millis(10), "{:?}", spent.cpu());
    }
}
