//! The CPU time this process has used, all threads, user and system: a clock that other
//! programs' load does not advance. A search that stops at a time cap counted on it (the budget
//! levels' search of the `voxlod` crate) tries the same candidates on a busy machine as on a
//! quiet one, where a wall clock would stop it sooner the busier the machine.
//!
//! Cost: one system call per reading.
//!
//! ```
//! let timer = voxlod_core::cpu_clock::CpuTimer::start();
//! let sum: u64 = (0..1_000_000u64).map(|i| i ^ (i >> 3)).sum();
//! assert!(sum > 0 && timer.seconds() >= 0.0);
//! ```

/// CPU seconds this process has used so far (all threads, user and system time); off Linux
/// (no `getrusage` through our libc dependency), wall-clock seconds since the first reading.
pub fn process_cpu_seconds() -> f64 {
    #[cfg(target_os = "linux")]
    {
        // SAFETY: `rusage` is plain old data, and getrusage fills it through a valid pointer.
        let mut usage: libc::rusage = unsafe { std::mem::zeroed() };
        if unsafe { libc::getrusage(libc::RUSAGE_SELF, &mut usage) } == 0 {
            let seconds = |t: libc::timeval| t.tv_sec as f64 + t.tv_usec as f64 * 1e-6;
            return seconds(usage.ru_utime) + seconds(usage.ru_stime);
        }
    }
    static FIRST: std::sync::OnceLock<std::time::Instant> = std::sync::OnceLock::new();
    FIRST
        .get_or_init(std::time::Instant::now)
        .elapsed()
        .as_secs_f64()
}

/// CPU time since a start, as [`std::time::Instant`] measures wall time.
#[derive(Clone, Copy, Debug)]
pub struct CpuTimer {
    start: f64,
}

impl CpuTimer {
    /// A timer from now.
    pub fn start() -> CpuTimer {
        CpuTimer {
            start: process_cpu_seconds(),
        }
    }

    /// CPU seconds used by the process (all its threads) since the start.
    pub fn seconds(&self) -> f64 {
        (process_cpu_seconds() - self.start).max(0.0)
    }
}

#[cfg(all(test, target_os = "linux"))]
mod tests {
    use super::*;

    /// The process's user and system time from `/proc/self/stat` (fields 14 and 15, in clock
    /// ticks): an independent reading of the same clock, to a tick.
    fn proc_stat_seconds() -> f64 {
        let stat = std::fs::read_to_string("/proc/self/stat").unwrap();
        let fields: Vec<&str> = stat[stat.rfind(')').unwrap() + 2..].split(' ').collect();
        // After the command's closing parenthesis, field 3 (state) comes first.
        let ticks: f64 = fields[11].parse::<f64>().unwrap() + fields[12].parse::<f64>().unwrap();
        ticks / unsafe { libc::sysconf(libc::_SC_CLK_TCK) } as f64
    }

    /// Around work on two threads, the clock agrees with the kernel's own account in
    /// `/proc/self/stat` to a few ticks (other tests of this process may run meanwhile, on
    /// both readings alike), and it has advanced by that work.
    #[test]
    fn agrees_with_the_kernels_account() {
        let work = || (0..20_000_000u64).fold(1u64, |x, i| x.wrapping_mul(6364136223846793005) ^ i);
        for _ in 0..3 {
            let (ours, theirs) = (process_cpu_seconds(), proc_stat_seconds());
            assert!((ours - theirs).abs() < 0.05, "{ours} s against {theirs} s");
            let timer = CpuTimer::start();
            let other = std::thread::spawn(work);
            let x = work() ^ other.join().unwrap();
            let (ours, theirs) = (process_cpu_seconds(), proc_stat_seconds());
            assert!(
                (ours - theirs).abs() < 0.05,
                "{ours} s against {theirs} s ({x})"
            );
            assert!(timer.seconds() > 0.0);
        }
    }
}
