//! From radiance to a picture and into a file: exposure, a tone curve and sRGB for images
//! people look at; linear radiance for OpenEXR; every file written to a temporary name beside
//! it and renamed into place, so a failure leaves no partial file.

use std::path::{Path, PathBuf};

use crate::error::{Error, Result};
use crate::lens::ImageSize;

/// The sRGB transfer function (IEC 61966-2-1) of a linear value in [0, 1].
pub fn linear_to_srgb(x: f32) -> f32 {
    if x <= 0.0031308 {
        12.92 * x
    } else {
        1.055 * x.powf(1.0 / 2.4) - 0.055
    }
}

/// Masked pixels' colour in [`super::RenderOutput::to_image`] (sRGB).
pub const MASKED_RGB: [u8; 3] = [0, 0, 0];

/// The image of linear colours whose `w` is the lens's coverage (as [`super::RenderOutput::colour`]):
/// sRGB-encoded and clamped, alpha the coverage (opaque where a pixel is covered, transparent
/// where not, between at the edge of the image circle with several rays per pixel).
pub fn colour_image(size: ImageSize, colour: &[[f32; 4]]) -> image::RgbaImage {
    colour_image_with(size, colour, &Display::default())
}

/// Writes an image as PNG (creating the parent folder; atomically, see [`write_atomically`]).
pub fn save_png<P>(image: &image::ImageBuffer<P, Vec<P::Subpixel>>, path: &Path) -> Result<()>
where
    P: image::PixelWithColorType,
    [P::Subpixel]: image::EncodableLayout,
{
    write_atomically(path, |temporary| {
        image
            .save_with_format(temporary, image::ImageFormat::Png)
            .map_err(|reason| Error::Image {
                path: path.to_path_buf(),
                reason,
            })
    })
}

/// The curve that maps exposed linear radiance to [0, 1] before sRGB encoding.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Tone {
    /// Values above 1 are clipped: the linear image as it is, and what comparisons measure.
    #[default]
    Clamp,
    /// Narkowicz's fit of the ACES filmic reference rendering transform ("ACES Filmic Tone
    /// Mapping Curve", 2015): `x(2.51x + 0.03) / (x(2.43x + 0.59) + 0.14)`, clamped. Highlights
    /// roll off instead of clipping: 0.80 at x = 1, 0.90 at 1.8, 1 (clipped) only from x ≈ 7.24.
    Aces,
}

impl Tone {
    /// The curve at `x` (linear, ≥ 0), in [0, 1]; infinite `x` is 1.
    pub fn map(self, x: f32) -> f32 {
        match self {
            Tone::Clamp => x.clamp(0.0, 1.0),
            // Clipped from x ≈ 7.24 on: returned before the quotient, whose terms overflow to
            // ∞ / ∞ (not a number) from x ≈ 1e19 on.
            Tone::Aces if x >= ACES_CLIPPED => 1.0,
            Tone::Aces => {
                let x = x.max(0.0);
                (x * (2.51 * x + 0.03) / (x * (2.43 * x + 0.59) + 0.14)).clamp(0.0, 1.0)
            }
        }
    }
}

/// A value from which [`Tone::Aces`] is 1: past the root of 0.08x² − 0.56x − 0.14 (≈ 7.24),
/// where the curve reaches 1.
const ACES_CLIPPED: f32 = 8.0;

/// `x` times `scale` (`2^exposure`), where no light stays none at any exposure: 0 × ∞ (an
/// exposure past 2^128, f32's largest) would be not a number.
fn exposed(x: f32, scale: f32) -> f32 {
    if x > 0.0 { x * scale } else { 0.0 }
}

/// How radiance is shown: scaled by `2^exposure` (stops, EV), then the tone curve.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Display {
    /// Exposure in stops: +1 doubles the radiance.
    pub exposure: f32,
    /// The tone curve.
    pub tone: Tone,
}

impl Display {
    /// A linear radiance value as displayed, in [0, 1] before sRGB encoding.
    pub fn map(&self, x: f32) -> f32 {
        self.tone.map(exposed(x, self.exposure.exp2()))
    }
}

/// The middle grey that [`auto_exposure`] maps an image's log-average luminance to: the
/// "key" of a normal-key scene in Reinhard et al. 2002, §3.1.
pub const KEY: f64 = 0.18;

/// The exposure in stops that maps the log-average luminance of the pixels the lens covers
/// (`w > 0`) to [`KEY`]: Reinhard, Stark, Shirley and Ferwerda, "Photographic Tone Reproduction
/// for Digital Images" (SIGGRAPH 2002), eq. 1 and 2: `L̄ = exp(mean(ln(δ + L)))`, scale
/// `a / L̄`, here `log2(a / L̄)`. Luminance is Rec. 709's `0.2126 R + 0.7152 G + 0.0722 B`
/// and δ = 10⁻⁴ keeps black pixels finite. Computed in f64; 0 where no pixel is covered.
pub fn auto_exposure(colour: &[[f32; 4]]) -> f32 {
    const DELTA: f64 = 1e-4;
    let (sum, n) = colour
        .iter()
        .filter(|c| c[3] > 0.0)
        .map(|c| {
            let [r, g, b] = [c[0], c[1], c[2]].map(|v| f64::from(v).max(0.0));
            (DELTA + 0.2126 * r + 0.7152 * g + 0.0722 * b).ln()
        })
        .fold((0.0, 0usize), |(s, n), l| (s + l, n + 1));
    if n == 0 {
        return 0.0;
    }
    let log_average = (sum / n as f64).exp();
    (KEY / log_average).log2() as f32
}

/// The files colour images are written as, chosen by the path's extension and a bit depth.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ColourFile {
    /// `.png`, 8 bits a channel, sRGB, alpha the lens's coverage.
    Png8,
    /// `.png` with 16 bits a channel.
    Png16,
    /// `.exr` with 16-bit (half) float channels: linear radiance times `2^exposure` (no tone
    /// curve), RGBA, alpha the coverage. Half floats hold values up to 65504 with 11
    /// significant bits.
    ExrHalf,
    /// `.exr` with 32-bit float channels.
    ExrFloat,
}

impl ColourFile {
    /// The format for `path`: `.png` (`bits` 8, the default, or 16) or `.exr` (16, the
    /// default, or 32); anything else is an error naming the path and what is accepted, so
    /// that it comes before any work is done.
    pub fn for_path(path: &Path, bits: Option<u32>) -> Result<Self> {
        let extension = path
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_lowercase);
        let refused = |what: &str| {
            Err(Error::Option(format!(
                "{}: {what} bits a channel: PNG is written with 8 or 16, OpenEXR with 16 (half) \
                 or 32 (float)",
                path.display()
            )))
        };
        match (extension.as_deref(), bits) {
            (Some("png"), None | Some(8)) => Ok(ColourFile::Png8),
            (Some("png"), Some(16)) => Ok(ColourFile::Png16),
            (Some("exr"), None | Some(16)) => Ok(ColourFile::ExrHalf),
            (Some("exr"), Some(32)) => Ok(ColourFile::ExrFloat),
            (Some("png" | "exr"), Some(bits)) => refused(&bits.to_string()),
            _ => Err(Error::Option(format!(
                "{}: the colour image is written as .png (8 or 16 bits) or .exr (linear half or \
                 float); use one of those extensions",
                path.display()
            ))),
        }
    }
}

/// Writes the colour of a render (as [`super::RenderOutput::colour`]: linear RGB, w the
/// coverage) to `path` as `file`, shown through `display` (EXR: exposure only).
pub fn write_colour(
    path: &Path,
    size: ImageSize,
    colour: &[[f32; 4]],
    display: &Display,
    file: ColourFile,
) -> Result<()> {
    write_atomically(path, |temporary| {
        let image_error = |reason| Error::Image {
            path: path.to_path_buf(),
            reason,
        };
        match file {
            ColourFile::Png8 => colour_image_with(size, colour, display)
                .save_with_format(temporary, image::ImageFormat::Png)
                .map_err(image_error),
            ColourFile::Png16 => {
                let mut out = Vec::with_capacity(colour.len() * 4);
                for c in colour {
                    out.extend(shown(c, display, 65535.0).map(|v| v as u16));
                }
                let image = image::ImageBuffer::<image::Rgba<u16>, _>::from_raw(
                    size.width,
                    size.height,
                    out,
                )
                .expect("width × height RGBA16 pixels");
                image
                    .save_with_format(temporary, image::ImageFormat::Png)
                    .map_err(image_error)
            }
            ColourFile::ExrHalf => write_exr(
                temporary,
                size,
                colour,
                display,
                exr::prelude::f16::from_f32,
            )
            .map_err(|e| exr_error(path, e)),
            ColourFile::ExrFloat => {
                write_exr(temporary, size, colour, display, |v| v).map_err(|e| exr_error(path, e))
            }
        }
    })
}

/// Linear RGB times `2^exposure` and the coverage as alpha, each converted by `sample`.
fn write_exr<T: exr::prelude::IntoSample>(
    path: &Path,
    size: ImageSize,
    colour: &[[f32; 4]],
    display: &Display,
    sample: impl Fn(f32) -> T + Sync,
) -> exr::error::UnitResult {
    let scale = display.exposure.exp2();
    let width = size.width as usize;
    exr::prelude::write_rgba_file(path, width, size.height as usize, |x, y| {
        let c = colour[y * width + x];
        (
            sample(exposed(c[0], scale)),
            sample(exposed(c[1], scale)),
            sample(exposed(c[2], scale)),
            sample(c[3]),
        )
    })
}

fn exr_error(path: &Path, error: exr::error::Error) -> Error {
    Error::Io {
        path: path.to_path_buf(),
        reason: std::io::Error::other(error.to_string()),
    }
}

/// A pixel's displayed RGBA in `0..=max`: sRGB of the displayed value, alpha the coverage;
/// uncovered pixels are [`MASKED_RGB`] and transparent.
fn shown(c: &[f32; 4], display: &Display, max: f32) -> [f32; 4] {
    if c[3] <= 0.0 {
        let [r, g, b] = MASKED_RGB.map(|v| f32::from(v) / 255.0 * max);
        return [r, g, b, 0.0];
    }
    let rgb = [c[0], c[1], c[2]].map(|v| (linear_to_srgb(display.map(v)) * max).round());
    [rgb[0], rgb[1], rgb[2], (c[3].clamp(0.0, 1.0) * max).round()]
}

/// The 8-bit image of linear colours whose `w` is the lens's coverage, shown through
/// `display`: sRGB-encoded, alpha the coverage.
pub fn colour_image_with(
    size: ImageSize,
    colour: &[[f32; 4]],
    display: &Display,
) -> image::RgbaImage {
    let out = colour
        .iter()
        .flat_map(|c| shown(c, display, 255.0).map(|v| v as u8))
        .collect();
    image::RgbaImage::from_raw(size.width, size.height, out).expect("width × height RGBA8 pixels")
}

/// Runs `write` on a temporary file beside `path` (creating `path`'s folder first) and renames
/// it into place: a failure leaves neither a partial file nor the temporary one. A `path`
/// that exists and is not a regular file (a folder, a device, a FIFO) is refused first: a
/// rename would replace it.
pub fn write_atomically(path: &Path, write: impl FnOnce(&Path) -> Result<()>) -> Result<()> {
    let io = |path: &Path| {
        let path = path.to_path_buf();
        move |reason| Error::Io { path, reason }
    };
    refuse_non_regular(path)?;
    let parent = path.parent().filter(|p| !p.as_os_str().is_empty());
    if let Some(parent) = parent {
        std::fs::create_dir_all(parent).map_err(io(parent))?;
    }
    let name = path
        .file_name()
        .map_or_else(Default::default, |n| n.to_string_lossy());
    let temporary: PathBuf = parent
        .unwrap_or(Path::new("."))
        .join(format!(".{name}.{}.tmp", std::process::id()));
    let written =
        write(&temporary).and_then(|()| std::fs::rename(&temporary, path).map_err(io(path)));
    if written.is_err() {
        let _ = std::fs::remove_file(&temporary);
    }
    written
}

/// Writes `contents` to `path` through [`write_atomically`].
pub fn write_file(path: &Path, contents: &[u8]) -> Result<()> {
    write_atomically(path, |temporary| {
        std::fs::write(temporary, contents).map_err(|reason| Error::Io {
            path: path.to_path_buf(),
            reason,
        })
    })
}

/// Refuses, before any work, an output file that could not be written: a `path` that exists
/// and is not a regular file ([`refuse_non_regular`]), a folder for it that cannot be made, or
/// one that takes no new file (read-only, sysfs, another user's). It makes the folder (as
/// [`write_atomically`] would) and creates and removes a probe file there.
pub fn check_writable(path: &Path) -> Result<()> {
    refuse_non_regular(path)?;
    let parent = path.parent().filter(|p| !p.as_os_str().is_empty());
    probe_folder(parent.unwrap_or(Path::new(".")), path)
}

/// As [`check_writable`], for an output folder: `dir` is made if missing and must take new
/// files.
pub fn check_writable_folder(dir: &Path) -> Result<()> {
    probe_folder(dir, dir)
}

/// Makes `dir` and creates and removes a file in it; errors name `output`, what is to be
/// written.
fn probe_folder(dir: &Path, output: &Path) -> Result<()> {
    let fail = |reason: std::io::Error| Error::Io {
        path: output.to_path_buf(),
        reason: std::io::Error::new(
            reason.kind(),
            format!("cannot be written ({reason}); nothing was rendered"),
        ),
    };
    std::fs::create_dir_all(dir).map_err(fail)?;
    let probe = dir.join(format!(".fisheye-probe.{}.tmp", std::process::id()));
    std::fs::OpenOptions::new()
        .write(true)
        .create_new(true)
        .open(&probe)
        .map_err(fail)?;
    std::fs::remove_file(&probe).map_err(fail)
}

/// Refuses a `path` that exists and is not a regular file (a folder, a device such as
/// `/dev/full`, a named pipe, a symbolic link), naming what it is; a missing path is fine. Tools
/// call it before work whose result goes there.
pub fn refuse_non_regular(path: &Path) -> Result<()> {
    match std::fs::symlink_metadata(path) {
        Ok(meta) if !meta.is_file() => Err(Error::Io {
            path: path.to_path_buf(),
            reason: std::io::Error::other(format!(
                "{}, not a regular file; give a file name to write",
                crate::input::what_it_is(&meta)
            )),
        }),
        _ => Ok(()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Auto exposure against Reinhard et al.'s formula: a grey image of luminance L gets
    /// log2(0.18 / (δ + L)); scaling the radiance by 2^k lowers it by k stops (up to δ);
    /// uncovered pixels do not count; no covered pixel gives 0.
    #[test]
    fn auto_exposure_maps_the_log_average_to_the_key() {
        for l in [0.01f32, 0.18, 1.0, 37.5] {
            let ev = auto_exposure(&[[l, l, l, 1.0]; 12]);
            let wanted = (0.18 / (1e-4 + f64::from(l))).log2() as f32;
            assert!((ev - wanted).abs() < 1e-5, "{l}: {ev} vs {wanted}");
        }
        // Half the pixels at 4, half at 1/4 (luminance weights sum to 1): log-average 1.
        let mixed: Vec<[f32; 4]> = (0..10)
            .map(|i| {
                if i % 2 == 0 {
                    [4.0; 4]
                } else {
                    [0.25, 0.25, 0.25, 1.0]
                }
            })
            .collect();
        assert!((auto_exposure(&mixed) - 0.18f32.log2()).abs() < 1e-3);
        let brighter: Vec<[f32; 4]> = mixed.iter().map(|c| c.map(|v| v * 8.0)).collect();
        assert!((auto_exposure(&mixed) - auto_exposure(&brighter) - 3.0).abs() < 1e-3);
        let mut masked = mixed.clone();
        masked.push([1e6, 1e6, 1e6, 0.0]);
        assert_eq!(auto_exposure(&masked), auto_exposure(&mixed));
        assert_eq!(auto_exposure(&[[5.0, 5.0, 5.0, 0.0]]), 0.0);
    }

    /// The curves against their formulas, and exposure in stops.
    #[test]
    fn exposure_and_tone_curves_follow_their_formulas() {
        for x in [0.0f32, 0.01, 0.18, 0.5, 1.0, 1.8, 4.0, 100.0] {
            let aces = x * (2.51 * x + 0.03) / (x * (2.43 * x + 0.59) + 0.14);
            assert_eq!(Tone::Aces.map(x), aces.clamp(0.0, 1.0), "{x}");
            assert_eq!(Tone::Clamp.map(x), x.min(1.0));
        }
        // ACES rolls highlights off: below 1 well past x = 1, clipped from x ≈ 7.24 (the root
        // of 0.08x² − 0.56x − 0.14), monotonic.
        assert!((Tone::Aces.map(1.0) - 0.8038).abs() < 1e-4);
        assert!((Tone::Aces.map(1.8) - 0.9021).abs() < 1e-4);
        assert!(Tone::Aces.map(7.2) < 1.0 && Tone::Aces.map(7.3) == 1.0);
        let samples: Vec<f32> = (0..200).map(|i| Tone::Aces.map(i as f32 * 0.05)).collect();
        assert!(samples.windows(2).all(|w| w[1] >= w[0]));
        let plus_one = Display {
            exposure: 1.0,
            tone: Tone::Clamp,
        };
        assert_eq!(plus_one.map(0.25), 0.5);
        let minus_two = Display {
            exposure: -2.0,
            tone: Tone::Clamp,
        };
        assert_eq!(minus_two.map(2.0), 0.5);
        // The clipped part of ACES is 1 however bright (the quotient alone is ∞ / ∞ from
        // about 1e19 on), and the curves the same on either side of where it is cut short.
        let quotient = |x: f32| x * (2.51 * x + 0.03) / (x * (2.43 * x + 0.59) + 0.14);
        assert!(quotient(1e20).is_nan());
        for x in [7.9f32, 8.0, 8.1, 1e20, f32::MAX, f32::INFINITY] {
            assert_eq!(Tone::Aces.map(x), 1.0, "{x}");
        }
    }

    /// Exposures past f32's range (2^128 is ∞, 2^-150 is 0) show light as white and none as
    /// black, not as not-a-number (which encoded black: `render --exposure 1e9` was black).
    #[test]
    fn exposures_past_f32s_range_saturate() {
        for tone in [Tone::Aces, Tone::Clamp] {
            let bright = Display {
                exposure: 1e9,
                tone,
            };
            assert_eq!(
                (bright.map(1e-30), bright.map(0.5), bright.map(0.0)),
                (1.0, 1.0, 0.0)
            );
            let dark = Display {
                exposure: -1e9,
                tone,
            };
            assert_eq!((dark.map(1e30), dark.map(0.0)), (0.0, 0.0));
        }
    }

    #[test]
    fn colour_files_by_extension_and_depth() {
        let ok = |p: &str, bits| ColourFile::for_path(Path::new(p), bits).unwrap();
        assert_eq!(ok("a.png", None), ColourFile::Png8);
        assert_eq!(ok("a.png", Some(8)), ColourFile::Png8);
        assert_eq!(ok("a.PNG", Some(16)), ColourFile::Png16);
        assert_eq!(ok("dir/a.exr", None), ColourFile::ExrHalf);
        assert_eq!(ok("a.exr", Some(32)), ColourFile::ExrFloat);
        for (bad, bits, wanted) in [
            ("a.jpg", None, "use one of those extensions"),
            ("a", Some(8), ".exr (linear half or float)"),
            ("a.exr", Some(8), "8 bits a channel"),
            ("a.png", Some(32), "PNG is written with 8 or 16"),
        ] {
            let message = ColourFile::for_path(Path::new(bad), bits)
                .unwrap_err()
                .to_string();
            assert!(
                message.contains(bad) && message.contains(wanted),
                "{message}"
            );
        }
    }

    /// A write that fails half-way leaves neither the file nor its temporary; one that
    /// succeeds replaces the old file whole; a folder in the way is refused untouched.
    #[test]
    fn writes_are_all_or_nothing() {
        let dir = std::env::temp_dir().join(format!("fisheye-atomic-{}", std::process::id()));
        let path = dir.join("new/out.bin");
        let failed = write_atomically(&path, |temporary| {
            std::fs::write(temporary, b"half of it").unwrap();
            Err(Error::Option("the encoder failed".into()))
        });
        assert!(
            failed
                .unwrap_err()
                .to_string()
                .contains("the encoder failed")
        );
        let left: Vec<_> = std::fs::read_dir(dir.join("new")).unwrap().collect();
        assert!(left.is_empty(), "left behind: {left:?}");

        std::fs::write(&path, b"old").unwrap();
        write_atomically(&path, |temporary| {
            assert_eq!(
                std::fs::read(&path).unwrap(),
                b"old",
                "replaced before the rename"
            );
            std::fs::write(temporary, b"new").map_err(|reason| Error::Io {
                path: temporary.to_path_buf(),
                reason,
            })
        })
        .unwrap();
        assert_eq!(std::fs::read(&path).unwrap(), b"new");
        assert_eq!(std::fs::read_dir(dir.join("new")).unwrap().count(), 1);

        let folder = dir.join("folder.png");
        std::fs::create_dir(&folder).unwrap();
        let refused = write_atomically(&folder, |_| panic!("written")).unwrap_err();
        assert!(
            refused.to_string().contains("a folder, not a regular file"),
            "{refused}"
        );
        assert!(folder.is_dir());
        std::fs::remove_dir_all(dir).unwrap();
    }
}
