//! Runs independent benchmark cells on a few threads. Every cell is deterministic on its own, so
//! the results do not depend on the thread count; they come back in job order.

use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::Mutex;

/// Runs `work` on every job, `threads` at a time, until done or `stop` is raised; `report` sees
/// each result with how many are done and how many there are. Results are in job order (jobs
/// skipped after a stop are missing).
pub fn run_jobs<J: Sync, R: Send>(
    jobs: &[J],
    threads: usize,
    stop: &AtomicBool,
    work: &(dyn Fn(&J) -> R + Sync),
    report: &(dyn Fn(&R, usize, usize) + Sync),
) -> Vec<R> {
    let next = AtomicUsize::new(0);
    let done = AtomicUsize::new(0);
    let out: Mutex<Vec<(usize, R)>> = Mutex::new(Vec::with_capacity(jobs.len()));
    std::thread::scope(|s| {
        for _ in 0..threads.max(1) {
            s.spawn(|| loop {
                if stop.load(Ordering::Relaxed) {
                    break;
                }
                let k = next.fetch_add(1, Ordering::Relaxed);
                let Some(job) = jobs.get(k) else {
                    break;
                };
                let r = work(job);
                let n = done.fetch_add(1, Ordering::Relaxed) + 1;
                report(&r, n, jobs.len());
                if let Ok(mut o) = out.lock() {
                    o.push((k, r));
                }
            });
        }
    });
    let mut out = out.into_inner().unwrap_or_else(|e| e.into_inner());
    out.sort_by_key(|(k, _)| *k);
    out.into_iter().map(|(_, r)| r).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn results_come_back_in_job_order_whatever_the_threads() {
        let jobs: Vec<u64> = (0..37).collect();
        let stop = AtomicBool::new(false);
        let one = run_jobs(&jobs, 1, &stop, &|j| j * j, &|_, _, _| {});
        let three = run_jobs(&jobs, 3, &stop, &|j| j * j, &|_, _, _| {});
        assert_eq!(one, three);
        assert_eq!(one[6], 36);
        let stopped = AtomicBool::new(true);
        assert!(run_jobs(&jobs, 2, &stopped, &|j| *j, &|_, _, _| {}).is_empty());
    }
}
