//! Data-parallel helpers over scoped threads. Items are handed out one at a time from a shared
//! counter, so a thread that finishes its items early takes the next one instead of waiting for
//! a slower thread's fixed share (populations differ in cost: the ones whose particles skirt
//! obstacles or other vehicles pay for more of the closed-form tests). Every item is processed
//! by a pure function of itself, so results never depend on the thread count or the order in
//! which threads take items.

use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Mutex;

/// Runs `work` on the calling thread and on `threads − 1` scoped helpers. A panic in a helper
/// reaches the caller with its own payload (the scope alone would replace it with "a scoped
/// thread panicked").
fn on_threads(threads: usize, work: impl Fn() + Sync) {
    let work = &work;
    std::thread::scope(|scope| {
        let helpers: Vec<_> = (1..threads).map(|_| scope.spawn(work)).collect();
        work();
        for h in helpers {
            if let Err(payload) = h.join() {
                std::panic::resume_unwind(payload);
            }
        }
    });
}

/// Calls `f` on every item, spread over `threads` scoped threads.
pub fn for_each_mut<T: Send>(items: &mut [T], threads: usize, f: impl Fn(&mut T) + Sync) {
    let threads = threads.max(1).min(items.len());
    if threads <= 1 {
        items.iter_mut().for_each(f);
        return;
    }
    // One uncontended lock per item: the safe way to hand a `&mut` to whichever thread claims it.
    let slots: Vec<Mutex<&mut T>> = items.iter_mut().map(Mutex::new).collect();
    let next = AtomicUsize::new(0);
    on_threads(threads, || loop {
        let k = next.fetch_add(1, Ordering::Relaxed);
        let Some(slot) = slots.get(k) else { break };
        // Only this thread ever locks slot k; a poisoned lock means `f` panicked on another
        // item, and that panic is re-raised when the scope ends.
        if let Ok(mut item) = slot.lock() {
            f(&mut item);
        }
    });
}

/// Maps every item with `f`, spread over `threads` scoped threads, keeping the order.
pub fn map<T: Sync, U: Send>(items: &[T], threads: usize, f: impl Fn(&T) -> U + Sync) -> Vec<U> {
    let threads = threads.max(1).min(items.len());
    if threads <= 1 {
        return items.iter().map(f).collect();
    }
    let next = AtomicUsize::new(0);
    let done: Mutex<Vec<(usize, U)>> = Mutex::new(Vec::with_capacity(items.len()));
    on_threads(threads, || {
        let mut mine = Vec::new();
        loop {
            let k = next.fetch_add(1, Ordering::Relaxed);
            let Some(item) = items.get(k) else { break };
            mine.push((k, f(item)));
        }
        if let Ok(mut all) = done.lock() {
            all.append(&mut mine);
        }
    });
    // A panic in `f` (a bug) has been re-raised by the scope before this point, so every item
    // is here exactly once.
    let mut all = done.into_inner().unwrap_or_else(|e| e.into_inner());
    all.sort_unstable_by_key(|(k, _)| *k);
    all.into_iter().map(|(_, u)| u).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn results_do_not_depend_on_threads() {
        let items: Vec<u64> = (0..37).collect();
        for t in [1, 2, 3, 8, 64] {
            assert_eq!(
                map(&items, t, |x| x * x),
                items.iter().map(|x| x * x).collect::<Vec<_>>()
            );
            let mut v = items.clone();
            for_each_mut(&mut v, t, |x| *x += 1);
            assert_eq!(v, (1..38).collect::<Vec<u64>>());
        }
        // No items, and more threads than items.
        assert!(map(&[] as &[u64], 4, |x| *x).is_empty());
        let mut none: [u64; 0] = [];
        for_each_mut(&mut none, 4, |x| *x += 1);
        assert_eq!(map(&[3u64], 4, |x| x + 1), vec![4]);
    }

    #[test]
    #[should_panic(expected = "item 29")]
    fn a_panic_in_f_reaches_the_caller_whichever_thread_ran_it() {
        let items: Vec<u64> = (0..40).collect();
        map(&items, 2, |&x| {
            assert!(x != 29, "item {x}");
            x
        });
    }
}
