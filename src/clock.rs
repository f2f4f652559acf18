//! Elapsed wall-clock time that also works in a web page: `std::time::Instant::now` panics on
//! wasm32-unknown-unknown, where JavaScript's `Date.now()` (whole milliseconds) stands in.

use std::time::Duration;

/// Time since [`Stopwatch::start`].
#[derive(Clone, Copy, Debug)]
pub(crate) struct Stopwatch {
    #[cfg(not(target_arch = "wasm32"))]
    started: std::time::Instant,
    #[cfg(target_arch = "wasm32")]
    started_ms: f64,
}

impl Stopwatch {
    pub(crate) fn start() -> Self {
        Stopwatch {
            #[cfg(not(target_arch = "wasm32"))]
            started: std::time::Instant::now(),
            #[cfg(target_arch = "wasm32")]
            started_ms: js_sys::Date::now(),
        }
    }

    pub(crate) fn elapsed(&self) -> Duration {
        #[cfg(not(target_arch = "wasm32"))]
        return self.started.elapsed();
        #[cfg(target_arch = "wasm32")]
        return Duration::from_secs_f64((js_sys::Date::now() - self.started_ms).max(0.0) / 1e3);
    }
}
