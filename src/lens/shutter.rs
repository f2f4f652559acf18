//! When a camera's pixels see the scene ([`Shutter`]): a global shutter at one instant, or a
//! rolling shutter reading lines one after another, each over an exposure.
//!
//! Kalibr's convention for a rolling shutter (its camchain's `line_delay`): the line of pixel
//! centres at OpenCV `y = v` is read at the frame's stamp plus `v · line_delay`. Here a line is
//! a row read top to bottom unless [`Readout`] says otherwise, and each line's exposure is
//! centred on its time. `wgsl/frame.wgsl` gives each primary ray its time this way.

/// The order lines are read in.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Readout {
    /// Rows, the top first (the usual sensor, and Kalibr's model).
    #[default]
    TopToBottom,
    /// Rows, the bottom first (a sensor mounted upside down).
    BottomToTop,
    /// Columns, the left first.
    LeftToRight,
    /// Columns, the right first.
    RightToLeft,
}

impl Readout {
    /// Every order with its name.
    pub const ALL: [(&'static str, Readout); 4] = [
        ("top-to-bottom", Self::TopToBottom),
        ("bottom-to-top", Self::BottomToTop),
        ("left-to-right", Self::LeftToRight),
        ("right-to-left", Self::RightToLeft),
    ];

    /// The order's name.
    pub fn name(self) -> &'static str {
        Self::ALL
            .iter()
            .find(|(_, r)| *r == self)
            .map_or("", |(n, _)| n)
    }

    /// Its WGSL id (`shared::READOUT_ORDERS`, in the same order).
    pub(crate) fn id(self) -> u32 {
        crate::shared::READOUT_ORDERS[self as usize].1
    }
}

impl std::str::FromStr for Readout {
    type Err = String;

    fn from_str(text: &str) -> Result<Self, String> {
        Self::ALL
            .iter()
            .find(|(n, _)| *n == text)
            .map(|(_, r)| *r)
            .ok_or_else(|| {
                let names: Vec<&str> = Self::ALL.iter().map(|(n, _)| *n).collect();
                format!("{text:?} is not a readout order: {}", names.join(", "))
            })
    }
}

/// When a camera's pixels see the scene: lines read `line_delay` seconds apart in `readout`
/// order, each exposed for `exposure` seconds centred on its time. Both zero: a global
/// shutter at the frame's stamp ([`Shutter::GLOBAL`]).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Shutter {
    /// Seconds between two lines' readouts (Kalibr's `line_delay`); 0 for a global shutter.
    pub line_delay: f64,
    /// Seconds each line is exposed; 0 for an instant (no motion blur).
    pub exposure: f64,
    /// The order lines are read in.
    pub readout: Readout,
}

impl Shutter {
    /// A global shutter exposed for an instant: every ray at the frame's stamp.
    pub const GLOBAL: Shutter = Shutter {
        line_delay: 0.0,
        exposure: 0.0,
        readout: Readout::TopToBottom,
    };

    /// A shutter of these times, or an error naming the one that is negative or not finite.
    pub fn new(line_delay: f64, exposure: f64, readout: Readout) -> Result<Self, String> {
        for (name, value) in [("line delay", line_delay), ("exposure time", exposure)] {
            if !(value.is_finite() && value >= 0.0) {
                return Err(format!(
                    "the {name} {value} s is not a number of seconds of 0 or more"
                ));
            }
        }
        Ok(Self {
            line_delay,
            exposure,
            readout,
        })
    }

    /// Whether rays of one frame are at different times (a line delay or an exposure).
    pub fn moves(&self) -> bool {
        self.line_delay > 0.0 || self.exposure > 0.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::lens::{ImageSize, LensCamera, parse_spec};

    /// Lines are read in the order named, `line_delay` apart; the span runs from the first
    /// line's exposure's start to the last's end; bad times are refused by name.
    #[test]
    fn lines_are_timed_in_readout_order() {
        let size = ImageSize::new(4, 3).unwrap();
        let camera = |line_delay, exposure, readout| {
            LensCamera::new(parse_spec("equidistant:f=0.5").unwrap(), size)
                .with_shutter(Shutter::new(line_delay, exposure, readout).unwrap())
        };
        let at = |readout, x, y| camera(0.5, 0.0, readout).line_time(x, y);
        assert_eq!(at(Readout::TopToBottom, 3, 2), 1.0);
        assert_eq!(at(Readout::BottomToTop, 3, 2), 0.0);
        assert_eq!(at(Readout::LeftToRight, 3, 0), 1.5);
        assert_eq!(at(Readout::RightToLeft, 3, 0), 0.0);
        let rolling = camera(0.5, 0.2, Readout::LeftToRight);
        assert_eq!(rolling.exposure_span(), (-0.1, 1.6));
        assert!(rolling.shutter.moves() && !Shutter::GLOBAL.moves());
        assert_eq!(
            camera(0.0, 0.0, Readout::TopToBottom).exposure_span(),
            (0.0, 0.0)
        );
        for (line_delay, exposure, wanted) in [
            (-1.0, 0.0, "line delay -1"),
            (0.0, f64::NAN, "exposure time NaN"),
        ] {
            let error = Shutter::new(line_delay, exposure, Readout::TopToBottom).unwrap_err();
            assert!(error.contains(wanted), "{error}");
        }
        for (name, readout) in Readout::ALL {
            assert_eq!(name.parse::<Readout>(), Ok(readout));
            assert_eq!(readout.name(), name);
        }
        assert!(
            "up".parse::<Readout>()
                .unwrap_err()
                .contains("top-to-bottom")
        );
    }
}
