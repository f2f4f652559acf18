//! Root finding with a stated bound: Newton's iteration, guarded so that every iteration at
//! least halves the bracket (see the parent module's "Root finding, and its bound").

/// The most iterations [`solve`] takes for a bracket of width `w0` and tolerance `tol`:
/// `⌈log₂(w0/tol)⌉` (see the module docs).
pub fn newton_bound(w0: f64, tol: f64) -> u32 {
    (w0 / tol).log2().ceil().max(0.0) as u32
}

/// Solves `h(x) = 0` in `[lo, hi]`, `h(lo) ≤ 0 ≤ h(hi)`, by the guarded Newton iteration of the
/// module docs; `h` returns the value and the derivative. Returns the root and the number of
/// iterations.
pub fn solve(h: impl Fn(f64) -> (f64, f64), mut lo: f64, mut hi: f64, x0: f64) -> (f64, u32) {
    let tol = 4.0 * f64::EPSILON * hi.abs().max(lo.abs()).max(f64::MIN_POSITIVE);
    let mut x = x0.clamp(lo, hi);
    let mut iterations = 0;
    // Narrows the bracket by the sign of h at `at`; true if `at` is the root.
    let narrow = |at: f64, value: f64, lo: &mut f64, hi: &mut f64| {
        if value < 0.0 {
            *lo = at;
        } else {
            *hi = at;
        }
        value == 0.0
    };
    loop {
        iterations += 1;
        let before = hi - lo;
        let (mut value, mut slope) = h(x);
        if narrow(x, value, &mut lo, &mut hi) {
            return (x, iterations);
        }
        if hi - lo > 0.5 * before {
            let mid = 0.5 * (lo + hi);
            let (mid_value, mid_slope) = h(mid);
            if narrow(mid, mid_value, &mut lo, &mut hi) {
                return (mid, iterations);
            }
            // Newton goes on from whichever point is closer to a root.
            if mid_value.abs() < value.abs() {
                (x, value, slope) = (mid, mid_value, mid_slope);
            }
        }
        let newton = x - value / slope;
        if (newton - x).abs() <= tol {
            return (newton.clamp(lo, hi), iterations);
        }
        let inside = newton > lo && newton < hi;
        if hi - lo <= tol {
            return (0.5 * (lo + hi), iterations);
        }
        x = if inside { newton } else { 0.5 * (lo + hi) };
    }
}

/// The end of the part of `[0, hi]` from 0 on which `f` is defined and increasing: a scan of
/// 4096 samples, refined by bisection to about `hi·1e-9` where `f` turns (to the last bit
/// where it stops being defined). Returns the end and whether `f` turned there (rather than
/// ceasing to be defined, or reaching `hi`).
pub(super) fn increasing_part(f: impl Fn(f64) -> Option<f64>, hi: f64) -> (f64, bool) {
    const SAMPLES: u32 = 4096;
    let step = hi / f64::from(SAMPLES);
    let delta = step * 1e-6;
    let good = |x: f64| match (f(x), f((x - delta).max(0.0))) {
        (Some(a), Some(b)) => a > b,
        _ => false,
    };
    let Some(mut previous) = f(0.0) else {
        return (0.0, false);
    };
    for i in 1..=SAMPLES {
        let x = step * f64::from(i);
        match f(x) {
            Some(value) if value > previous && good(x) => previous = value,
            _ => {
                let (mut a, mut b) = (x - step, x);
                for _ in 0..80 {
                    let mid = 0.5 * (a + b);
                    if mid <= a || mid >= b {
                        break;
                    }
                    if good(mid) {
                        a = mid;
                    } else {
                        b = mid;
                    }
                }
                // It turned if f goes on beyond (the next sample), rather than ending there.
                return (a, f(a + step).is_some());
            }
        }
    }
    (hi, false)
}
