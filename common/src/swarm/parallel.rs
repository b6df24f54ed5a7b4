//! Data-parallel helpers over scoped threads. Work is split into contiguous chunks and every
//! item is processed by a pure function of itself, so results never depend on the thread count.

/// Calls `f` on every item, spread over `threads` scoped threads.
pub fn for_each_mut<T: Send>(items: &mut [T], threads: usize, f: impl Fn(&mut T) + Sync) {
    let threads = threads.max(1);
    if threads == 1 || items.len() < 2 {
        items.iter_mut().for_each(f);
        return;
    }
    let chunk = items.len().div_ceil(threads);
    let f = &f;
    std::thread::scope(|scope| {
        for part in items.chunks_mut(chunk) {
            scope.spawn(move || part.iter_mut().for_each(f));
        }
    });
}

/// Maps every item with `f`, spread over `threads` scoped threads, keeping the order.
pub fn map<T: Sync, U: Send>(items: &[T], threads: usize, f: impl Fn(&T) -> U + Sync) -> Vec<U> {
    let threads = threads.max(1);
    if threads == 1 || items.len() < 2 {
        return items.iter().map(f).collect();
    }
    let chunk = items.len().div_ceil(threads);
    let f = &f;
    std::thread::scope(|scope| {
        let handles: Vec<_> = items
            .chunks(chunk)
            .map(|part| scope.spawn(move || part.iter().map(f).collect::<Vec<U>>()))
            .collect();
        handles
            .into_iter()
            // A panic in `f` is a bug; re-raise it on the caller's thread.
            .flat_map(|h| h.join().unwrap_or_else(|e| std::panic::resume_unwind(e)))
            .collect()
    })
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
    }
}
