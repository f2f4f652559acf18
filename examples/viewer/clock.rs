//! The scene time of the viewer's moving scenes.

use std::time::{Duration, Instant};

/// The scene time of a moving scene: playing in a loop over its keys' span, or paused.
pub(crate) struct Clock {
    /// The first and last key times.
    span: (f64, f64),
    /// When the loop's time was `span.0`, while playing.
    started: Instant,
    /// The time it is paused at.
    pub(crate) paused: Option<f64>,
    /// Whether the view's method draws the scene as loaded.
    pub(crate) fixed: bool,
}

impl Clock {
    /// A clock over `span`, playing from its start, or paused at `paused`.
    pub(crate) fn new(span: (f64, f64), paused: Option<f64>) -> Self {
        Self {
            span,
            started: Instant::now(),
            paused,
            fixed: false,
        }
    }

    /// The scene time now.
    pub(crate) fn now(&self) -> f64 {
        if let Some(t) = self.paused {
            return t;
        }
        let (first, last) = self.span;
        let elapsed = self.started.elapsed().as_secs_f64();
        if last > first {
            first + elapsed % (last - first)
        } else {
            first
        }
    }

    /// Pauses, or plays on from the time it was paused at.
    pub(crate) fn toggle(&mut self) {
        match self.paused.take() {
            Some(t) => {
                let into = (t - self.span.0).max(0.0);
                self.started = Instant::now() - Duration::from_secs_f64(into);
            }
            None => self.paused = Some(self.now()),
        }
    }
}
