//! CPU time of the calling thread, for budgets whose verdict must not
//! depend on how loaded the machine is (the stress sweeps' per-run budget,
//! the reference engine's `cpu_time_limit`).
//!
//! On Unix it is `clock_gettime(CLOCK_THREAD_CPUTIME_ID)`: the time the
//! kernel ran this thread, user and system, at nanosecond resolution,
//! whatever else runs on the machine. Elsewhere there is no such clock in
//! the standard library, and the budget falls back to wall-clock time
//! (measured from the first call on the thread), which a loaded machine
//! stretches.

/// A stopwatch of the calling thread's CPU time (s) since it was started.
///
/// Read it on the thread that started it: another thread has its own
/// clock.
#[derive(Clone, Copy, Debug)]
pub(crate) struct CpuWatch {
    start: f64,
}

impl CpuWatch {
    /// Starts the watch now.
    pub(crate) fn start() -> Self {
        CpuWatch {
            start: thread_cpu_seconds(),
        }
    }

    /// CPU time (s) this thread has used since [`CpuWatch::start`].
    pub(crate) fn seconds(&self) -> f64 {
        thread_cpu_seconds() - self.start
    }
}

/// CPU time (s) the calling thread has used since it began.
#[cfg(unix)]
fn thread_cpu_seconds() -> f64 {
    let mut ts = libc::timespec {
        tv_sec: 0,
        tv_nsec: 0,
    };
    // SAFETY: `ts` is a valid, writable timespec; the clock id is a
    // constant the C library defines. On failure (no such clock) the
    // fallback below is used.
    let rc = unsafe { libc::clock_gettime(libc::CLOCK_THREAD_CPUTIME_ID, &mut ts) };
    if rc == 0 {
        ts.tv_sec as f64 + 1e-9 * ts.tv_nsec as f64
    } else {
        wall_seconds()
    }
}

#[cfg(not(unix))]
fn thread_cpu_seconds() -> f64 {
    wall_seconds()
}

/// Wall-clock seconds since the first call on this thread (the fallback).
fn wall_seconds() -> f64 {
    thread_local! {
        static ORIGIN: std::time::Instant = std::time::Instant::now();
    }
    ORIGIN.with(|o| o.elapsed().as_secs_f64())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Against the wall clock, an independent clock: a thread that spins
    /// uses CPU time at most as fast as wall time passes (one thread runs
    /// on at most one core) and, spinning, a good part of it; a thread
    /// that sleeps uses next to none.
    #[test]
    fn the_watch_counts_this_threads_work_not_its_sleep() {
        let w = CpuWatch::start();
        let wall = std::time::Instant::now();
        let mut x = 0u64;
        while wall.elapsed().as_secs_f64() < 0.2 {
            x = std::hint::black_box(x.wrapping_mul(6364136223846793005).wrapping_add(1));
        }
        let spun = w.seconds();
        let elapsed = wall.elapsed().as_secs_f64();
        assert!(spun <= elapsed + 1e-3, "{spun} s of CPU in {elapsed} s");
        assert!(spun > 0.0, "no CPU time counted while spinning");
        let before = w.seconds();
        std::thread::sleep(std::time::Duration::from_millis(200));
        let slept = w.seconds() - before;
        #[cfg(unix)]
        assert!(slept < 0.05, "{slept} s of CPU counted while asleep");
        let _ = slept;
    }
}
