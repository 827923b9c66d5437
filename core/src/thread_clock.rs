//! The calling thread's CPU time: what a benchmark reads to tell the host's own work from
//! the time it lost to other processes on a shared machine, which a wall clock counts.
//! On Unix, the thread's CPU-time clock (`CLOCK_THREAD_CPUTIME_ID`, up to date when
//! read, unlike `/proc`'s figures, which lag by up to a scheduler tick); elsewhere none.

use std::time::Duration;

/// CPU time the calling thread has run so far; `None` where the system does not say.
#[cfg(unix)]
pub fn thread_cpu() -> Option<Duration> {
    use nix::time::{ClockId, clock_gettime};
    let t = clock_gettime(ClockId::CLOCK_THREAD_CPUTIME_ID).ok()?;
    Some(Duration::new(
        u64::try_from(t.tv_sec()).ok()?,
        u32::try_from(t.tv_nsec()).ok()?,
    ))
}

/// CPU time the calling thread has run so far; `None` where the system does not say.
#[cfg(not(unix))]
pub fn thread_cpu() -> Option<Duration> {
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Work advances the thread's CPU time, by no more than the wall time it took (give
    /// or take the two clocks' disagreement on a virtual machine, where the thread's
    /// clock is the guest scheduler's: a CI run saw 14.7 ms of work in a wall time read
    /// just short of it); sleeping does not advance it.
    #[test]
    fn work_counts_and_sleeping_does_not() {
        let wall = std::time::Instant::now();
        let Some(start) = thread_cpu() else {
            eprintln!("skipped: no thread CPU time on this system");
            return;
        };
        let mut x = 0u64;
        for i in 0..20_000_000u64 {
            x = x.wrapping_mul(31).wrapping_add(std::hint::black_box(i));
        }
        std::hint::black_box(x);
        let worked = thread_cpu().expect("read once") - start;
        let elapsed = wall.elapsed();
        assert!(
            worked > Duration::ZERO && worked <= elapsed + elapsed / 10 + Duration::from_millis(2),
            "{worked:?} of work in {elapsed:?}"
        );
        let before = thread_cpu().expect("read once");
        std::thread::sleep(Duration::from_millis(100));
        let slept = thread_cpu().expect("read once") - before;
        assert!(slept < Duration::from_millis(5), "{slept:?}");
    }
}
