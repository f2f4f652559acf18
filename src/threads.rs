//! Work split over the machine's threads, that also runs in a web page (one thread there:
//! wasm32-unknown-unknown has none to spawn).

/// Calls `work(first, part)` for consecutive parts of `items`, one a thread, `first` being
/// the index of the part's first item in `items`; returns when all are done.
pub(crate) fn in_parts<T: Send>(items: &mut [T], work: impl Fn(usize, &mut [T]) + Sync) {
    let threads = available();
    let part = items.len().div_ceil(threads).max(1);
    if threads == 1 {
        return work(0, items);
    }
    let work = &work;
    std::thread::scope(|s| {
        for (k, items) in items.chunks_mut(part).enumerate() {
            s.spawn(move || work(k * part, items));
        }
    });
}

/// The threads [`in_parts`] splits work over: the machine's (1 in a web page).
pub(crate) fn available() -> usize {
    if cfg!(target_arch = "wasm32") {
        1
    } else {
        std::thread::available_parallelism().map_or(1, |n| n.get())
    }
}
