//! The calling thread's CPU time: what a benchmark reads to tell the host's own work from
//! the time it lost to other processes on a shared machine, which a wall clock counts.
//! Linux keeps it, in nanoseconds, as the first field of `/proc/thread-self/schedstat`;
//! elsewhere, or where that cannot be read, there is none.

use std::time::Duration;

/// CPU time the calling thread has run so far; `None` where the system does not say.
pub fn thread_cpu() -> Option<Duration> {
    let text = std::fs::read_to_string("/proc/thread-self/schedstat").ok()?;
    let ns: u64 = text.split_whitespace().next()?.parse().ok()?;
    Some(Duration::from_nanos(ns))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Spinning advances the thread's CPU time by about the wall time spun; sleeping
    /// does not advance it.
    #[test]
    fn spinning_counts_and_sleeping_does_not() {
        let Some(start) = thread_cpu() else {
            eprintln!("skipped: no thread CPU time on this system");
            return;
        };
        let spin = std::time::Instant::now();
        let mut x = 0u64;
        while spin.elapsed() < Duration::from_millis(50) {
            x = x.wrapping_add(std::hint::black_box(1));
        }
        std::hint::black_box(x);
        let spun = thread_cpu().expect("read once") - start;
        // At least a fifth of the wall time, even on a loaded machine.
        assert!(spun >= Duration::from_millis(10), "{spun:?}");
        let before = thread_cpu().expect("read once");
        std::thread::sleep(Duration::from_millis(100));
        let slept = thread_cpu().expect("read once") - before;
        assert!(slept < Duration::from_millis(20), "{slept:?}");
    }
}
