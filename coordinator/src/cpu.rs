//! The coordinator process's own CPU time, for the figures that report what a step cost it
//! (`bench-telemetry`, `bench-scale`, a distributed plan's rounds).

use std::time::Duration;

/// CPU time of this process so far (user + system), from `/proc/self/stat`; `None` elsewhere.
pub fn cpu_time() -> Option<Duration> {
    let stat = std::fs::read_to_string("/proc/self/stat").ok()?;
    // Fields after the command name (which may hold spaces) start after the last ')'.
    let rest = stat.rsplit_once(')')?.1;
    let f: Vec<&str> = rest.split_whitespace().collect();
    // utime and stime are fields 14 and 15 of the line, 12 and 13 after the ')'.
    let ticks: u64 = f.get(11)?.parse::<u64>().ok()? + f.get(12)?.parse::<u64>().ok()?;
    // Linux reports them in USER_HZ, 100 on every architecture Shoal runs on.
    Some(Duration::from_millis(ticks * 10))
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::time::Instant;

    #[test]
    fn cpu_time_grows_with_work() {
        let Some(a) = cpu_time() else {
            return; // not Linux: nothing to read
        };
        let mut x = 0u64;
        let t = Instant::now();
        while t.elapsed() < Duration::from_millis(300) {
            x = x.wrapping_mul(6364136223846793005).wrapping_add(1);
        }
        std::hint::black_box(x);
        let b = cpu_time().unwrap_or(a);
        assert!(b > a, "{a:?} → {b:?}");
    }
}
