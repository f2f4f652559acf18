//! What a render is asked for ([`RenderOptions`]: depth, BVH preset, ray directions,
//! traversal, rays per pixel) and the constants that specialise the kernels to a scene's
//! surfaces.

use crate::bvh::BvhQuality;
use crate::lens::gpu::DirectionSource;
use crate::scene::{Features, Surface};

/// The WGSL id of a surface kind.
pub fn surface_id(surface: Surface) -> u32 {
    match surface {
        Surface::Diffuse => crate::shared::SURFACE_DIFFUSE,
        Surface::Mirror => crate::shared::SURFACE_MIRROR,
        Surface::Glass => crate::shared::SURFACE_GLASS,
    }
}

/// How to render.
#[derive(Clone, Copy, Debug)]
pub struct RenderOptions {
    /// Deepest reflection/refraction (0: primary rays and shadows only).
    pub max_depth: u32,
    /// BVH build preset.
    pub bvh: BvhQuality,
    /// Where primary ray directions come from.
    pub directions: DirectionSource,
    /// How rays find their hits.
    pub traversal: Traversal,
    /// Rays per pixel (a square: samples on a rotated grid, box-filtered; see
    /// [`super::sampling`]). Ground-truth outputs stay the one ray through the pixel's centre.
    /// With `adaptive`, the most a pixel takes.
    pub spp: u32,
    /// Adaptive sampling ([`super::AdaptivePass`]): rays where neighbouring samples disagree,
    /// fewer than one a pixel where the image is smooth; `None` samples every pixel alike.
    pub adaptive: Option<Adaptive>,
    /// How a pixel's colour is made from the rays traced ([`PixelFilter`]): by default its own
    /// rays' mean.
    pub filter: PixelFilter,
}

/// How a pixel's colour is made from the rays traced.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum PixelFilter {
    /// Each pixel the mean of its own rays (a box filter over its square): the reference's
    /// filter, and what supersampled pixels always take.
    #[default]
    Box,
    /// In a frame of one ray a pixel at most (uniform `--spp 1`, adaptive `auto:T:1`, whose
    /// other pixels are interpolated), each pixel takes the mean over its square of the
    /// bilinear (tent) interpolation through its own and its eight neighbours' centres, in
    /// linear radiance: weights 3/4 for the pixel and 1/8 for each neighbour along each
    /// axis, the quadratic B-spline at whole-pixel offsets (the box ⊛ tent), renormalised over
    /// the neighbours the lens covers. One centre sample aliases at edges and texture detail;
    /// this estimate of the pixel's box average trades a little blur for it (`trace::Tent`,
    /// `wgsl/tent.wgsl`). With more rays a pixel it changes nothing: supersampling already
    /// estimates the box average, and adaptive sampling's one-ray pixels beside supersampled
    /// ones are those whose colour it found linear across them.
    Tent,
}

impl PixelFilter {
    /// Both filters, as `--filter` lists them.
    pub const ALL: [PixelFilter; 2] = [PixelFilter::Box, PixelFilter::Tent];

    /// The name `--filter` takes and setups' labels carry (`rt@1spp+tent`).
    pub fn name(&self) -> &'static str {
        match self {
            PixelFilter::Box => "box",
            PixelFilter::Tent => "tent",
        }
    }

    /// Whether the filter changes anything under `sampling`: the tent only at one ray a
    /// pixel at most (uniform 1, adaptive `auto:T:1`).
    pub fn applies_to(&self, sampling: Sampling) -> bool {
        match self {
            PixelFilter::Box => true,
            PixelFilter::Tent => sampling.max_spp() == 1,
        }
    }
}

impl std::str::FromStr for PixelFilter {
    type Err = crate::error::Error;

    fn from_str(text: &str) -> crate::error::Result<Self> {
        Self::ALL
            .into_iter()
            .find(|f| f.name() == text)
            .ok_or_else(|| {
                crate::error::Error::Option(format!(
                    "pixel filter {text:?}: the filters are box (each pixel its own rays' mean) \
                     and tent (one-ray pixels blended with their neighbours)"
                ))
            })
    }
}

/// Adaptive sampling's settings (see `trace::AdaptivePass`); the most rays a pixel takes are
/// [`RenderOptions::spp`] (plus its centre's).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Adaptive {
    /// How far apart two samples' displayed colours (clamped, sRGB-encoded, the largest
    /// channel, as [`crate::compare`] measures error) may be before the pixels between them
    /// get rays of their own, and a traced pixel its full supersampling: 0.02 is 2 % of full
    /// scale. At 0 every pixel takes every sample, as uniform sampling does.
    pub threshold: f32,
    /// Whether pixels that took no ray of their own (interpolated) still get their centre's
    /// first hit traced, so the ground-truth outputs (range, normal, id) are exact everywhere.
    /// Without it those pixels' geometry is zero and their id `NO_HIT`.
    pub ground_truth: bool,
    /// Whether the first pass traces every pixel's centre (at least one ray a pixel,
    /// `auto:T:MAX:1`) instead of one pixel a block of `ADAPTIVE_BLOCK`² (1/16 of a ray a
    /// pixel, interpolated where the image is smooth, then refined level by level). Fewer
    /// passes that depend on each other, for more rays where the image is smooth: on a large
    /// GPU a pass of a few thousand rays costs about one ray's latency however few it
    /// traces, and there the passes set an adaptive frame's time; on a CPU it depends on
    /// the scene (the book's "Adaptive sampling" measures both).
    pub every_pixel: bool,
}

impl Adaptive {
    /// The default threshold of `--spp auto`.
    pub const DEFAULT_THRESHOLD: f32 = 0.02;
}

/// How adaptive sampling spreads a listed pixel's samples over invocations of its sampling
/// kernel (`trace_samples` in `wgsl/adaptive.wgsl`); both give the same image, bit for bit.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SampleLanes {
    /// An invocation a sample (up to a workgroup's), the pixel's first adding them up: a GPU
    /// has far more lanes than a short list has pixels, and with an invocation a pixel an
    /// H200 waited on a few long ones (supersampling a few thousand pixels took 3 to 5 ms).
    PerSample,
    /// An invocation a pixel, its samples in a loop: a CPU's few SIMD lanes are filled by any
    /// list, and there the other layout's barriers and serial sums cost more than they save
    /// (lavapipe, the Cornell box at 256 × 192: 180 against 113 ns a supersampled ray).
    PerPixel,
}

impl SampleLanes {
    /// The layout for `device`: an invocation a pixel on a CPU (lavapipe, SwiftShader), a
    /// sample on a GPU.
    pub fn for_device(device: &wgpu::Device) -> SampleLanes {
        match device.adapter_info().device_type {
            wgpu::DeviceType::Cpu => SampleLanes::PerPixel,
            _ => SampleLanes::PerSample,
        }
    }
}

/// How the tracer's rays find their hits; lens and shading code are the same for both.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Traversal {
    /// The obvhs CWBVH, traversed in WGSL (`wgsl/bvh.wgsl`): runs on any adapter.
    #[default]
    Software,
    /// Hardware ray queries over an acceleration structure built by the driver
    /// (`wgsl/bvh_rq.wgsl`); needs `Features::EXPERIMENTAL_RAY_QUERY`.
    RayQuery,
}

impl Default for RenderOptions {
    fn default() -> Self {
        Self {
            max_depth: 5,
            bvh: BvhQuality::default(),
            directions: DirectionSource::Computed,
            traversal: Traversal::Software,
            spp: 1,
            adaptive: None,
            filter: PixelFilter::Box,
        }
    }
}

impl RenderOptions {
    /// The sampling `spp` and `adaptive` make, as `--spp` names it.
    pub fn sampling(&self) -> Sampling {
        match self.adaptive {
            Some(Adaptive {
                threshold,
                every_pixel,
                ..
            }) => Sampling::Adaptive {
                threshold,
                max_spp: self.spp,
                every_pixel,
            },
            None => Sampling::Uniform(self.spp),
        }
    }
}

/// The overrides of `wgsl/surface.wgsl` for a scene's features: code for what the scene does
/// not use is dead.
pub fn surface_constants(f: Features) -> [(&'static str, f64); 6] {
    let flag = |b: bool| f64::from(u8::from(b));
    [
        ("HAS_MIRRORS", flag(f.mirrors)),
        ("HAS_GLASS", flag(f.glass)),
        ("HAS_TEXTURES", flag(f.textures)),
        ("SMOOTH_NORMALS", flag(f.smooth_normals)),
        ("INSTANCED", flag(f.instanced)),
        ("MOVING", flag(f.moving)),
    ]
}

/// How many rays a pixel's colour takes, as `--spp` and a setup's label write it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Sampling {
    /// `N`: every pixel `N` rays (a square: samples on a rotated grid, box-filtered).
    Uniform(u32),
    /// `auto[:THRESHOLD[:MAX[:LEAST]]]`: adaptive sampling ([`super::AdaptivePass`]) at the
    /// threshold ([`super::Adaptive::threshold`], 0.02 by default), at most `MAX` samples a
    /// pixel (16 by default), starting from one ray a 4 × 4 block (`LEAST` 1/16, the default)
    /// or from one through every pixel (`LEAST` 1: [`super::Adaptive::every_pixel`]).
    Adaptive {
        /// Displayed-colour difference at which samples disagree.
        threshold: f32,
        /// The most samples a pixel takes (a square).
        max_spp: u32,
        /// Whether every pixel takes at least its centre's ray.
        every_pixel: bool,
    },
}

impl Sampling {
    /// The most samples adaptive sampling takes a pixel unless told: 16, as `render`'s uniform
    /// default.
    pub const DEFAULT_MAX_SPP: u32 = 16;

    /// Reads `N` or `auto[:THRESHOLD[:MAX[:LEAST]]]`; errors say what is wrong and what is
    /// accepted.
    pub fn parse(text: &str) -> crate::error::Result<Self> {
        let bad = |why: String| {
            crate::error::Error::Option(format!(
                "{text:?}: {why}; rays per pixel are N (a square: 1, 4, 9, 16, ...) or \
                 auto[:THRESHOLD[:MAX[:LEAST]]] (adaptive, e.g. auto, auto:0.05, auto:0.01:64, \
                 auto:0.02:16:1)"
            ))
        };
        let check = |spp: u32| super::sampling::samples_per_side(spp).map(|_| spp);
        let Some(rest) = text.strip_prefix("auto") else {
            let spp: u32 = text.parse().map_err(|_| bad("not a number".into()))?;
            return Ok(Sampling::Uniform(check(spp)?));
        };
        let mut parts = rest.split(':');
        if parts.next() != Some("") {
            return Err(bad("auto takes its values after colons".into()));
        }
        let threshold = match parts.next() {
            None => Adaptive::DEFAULT_THRESHOLD,
            Some(t) => match t.parse::<f32>() {
                Ok(t) if t >= 0.0 && t.is_finite() => t,
                _ => {
                    return Err(bad(format!(
                        "the threshold {t:?} is not a number of 0 or more"
                    )));
                }
            },
        };
        let max_spp = match parts.next() {
            None => Self::DEFAULT_MAX_SPP,
            Some(m) => check(
                m.parse()
                    .map_err(|_| bad(format!("the most rays {m:?} is not a number")))?,
            )?,
        };
        let every_pixel = match parts.next() {
            None | Some("1/16") => false,
            Some("1") => true,
            Some(least) => {
                return Err(bad(format!(
                    "the least rays a pixel {least:?} is 1/16 (one ray a 4 × 4 block first, \
                     the default) or 1 (every pixel's centre first)"
                )));
            }
        };
        if parts.next().is_some() {
            return Err(bad("too many parts".into()));
        }
        Ok(Sampling::Adaptive {
            threshold,
            max_spp,
            every_pixel,
        })
    }

    /// Reads a sampling and its pixel filter as `compare` labels a setup's, and the viewer and
    /// the web page take them: `--spp`'s text, then optionally `+FILTER` (`1+tent`,
    /// `auto:0.1:1+tent`); the box filter without.
    pub fn parse_filtered(text: &str) -> crate::error::Result<(Self, PixelFilter)> {
        let (sampling, filter) = match text.split_once('+') {
            Some((sampling, filter)) => (sampling, filter.parse()?),
            None => (text, PixelFilter::Box),
        };
        Ok((Sampling::parse(sampling)?, filter))
    }

    /// The most samples a pixel takes.
    pub fn max_spp(&self) -> u32 {
        match *self {
            Sampling::Uniform(spp) => spp,
            Sampling::Adaptive { max_spp, .. } => max_spp,
        }
    }

    /// Adaptive sampling's threshold, if adaptive.
    pub fn threshold(&self) -> Option<f32> {
        match *self {
            Sampling::Uniform(_) => None,
            Sampling::Adaptive { threshold, .. } => Some(threshold),
        }
    }

    /// The render options' `spp` and `adaptive` for this sampling.
    pub fn options(&self, ground_truth: bool) -> (u32, Option<Adaptive>) {
        let adaptive = match *self {
            Sampling::Uniform(_) => None,
            Sampling::Adaptive {
                threshold,
                every_pixel,
                ..
            } => Some(Adaptive {
                threshold,
                ground_truth,
                every_pixel,
            }),
        };
        (self.max_spp(), adaptive)
    }

    /// As a setup's label writes it: `16spp`, `auto:0.02`, `auto:0.01:64`, `auto:0.02:16:1`.
    pub fn label(&self) -> String {
        match *self {
            Sampling::Uniform(spp) => format!("{spp}spp"),
            _ => self.to_string(),
        }
    }
}

impl std::fmt::Display for Sampling {
    /// As `--spp` takes it: `16`, `auto:0.02`, `auto:0.01:64`, `auto:0.02:16:1`.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match *self {
            Sampling::Uniform(spp) => write!(f, "{spp}"),
            Sampling::Adaptive {
                threshold,
                max_spp,
                every_pixel: true,
            } => write!(f, "auto:{threshold}:{max_spp}:1"),
            Sampling::Adaptive {
                threshold, max_spp, ..
            } if max_spp == Self::DEFAULT_MAX_SPP => write!(f, "auto:{threshold}"),
            Sampling::Adaptive {
                threshold, max_spp, ..
            } => write!(f, "auto:{threshold}:{max_spp}"),
        }
    }
}

impl std::str::FromStr for Sampling {
    type Err = crate::error::Error;

    fn from_str(text: &str) -> crate::error::Result<Self> {
        Sampling::parse(text)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sampling_reads_and_writes_its_names() {
        for (text, wanted) in [
            ("16", Sampling::Uniform(16)),
            (
                "auto",
                Sampling::Adaptive {
                    threshold: 0.02,
                    max_spp: 16,
                    every_pixel: false,
                },
            ),
            (
                "auto:0.05",
                Sampling::Adaptive {
                    threshold: 0.05,
                    max_spp: 16,
                    every_pixel: false,
                },
            ),
            (
                "auto:0:64",
                Sampling::Adaptive {
                    threshold: 0.0,
                    max_spp: 64,
                    every_pixel: false,
                },
            ),
            (
                "auto:0.1:4:1",
                Sampling::Adaptive {
                    threshold: 0.1,
                    max_spp: 4,
                    every_pixel: true,
                },
            ),
        ] {
            let read = Sampling::parse(text).unwrap();
            assert_eq!(read, wanted, "{text}");
            assert_eq!(Sampling::parse(&read.to_string()).unwrap(), read);
            // Through the render options and back.
            let (spp, adaptive) = read.options(true);
            let options = RenderOptions {
                spp,
                adaptive,
                ..RenderOptions::default()
            };
            assert_eq!(options.sampling(), read, "{text}");
        }
        assert_eq!(Sampling::Uniform(4).label(), "4spp");
        for filter in PixelFilter::ALL {
            assert_eq!(filter.name().parse::<PixelFilter>().unwrap(), filter);
        }
        let message = "gauss".parse::<PixelFilter>().unwrap_err().to_string();
        assert!(
            message.contains("box") && message.contains("tent"),
            "{message}"
        );
        let tent = Sampling::parse_filtered("auto:0.1:1+tent").unwrap();
        assert_eq!(
            tent,
            (Sampling::parse("auto:0.1:1").unwrap(), PixelFilter::Tent)
        );
        assert_eq!(
            Sampling::parse_filtered("4").unwrap(),
            (Sampling::Uniform(4), PixelFilter::Box)
        );
        assert!(Sampling::parse_filtered("1+gauss").is_err());
        assert!(Sampling::parse_filtered("3+tent").is_err());
        // The tent changes frames of one ray a pixel at most: uniform 1, and auto:T:1.
        let applies = |text: &str| PixelFilter::Tent.applies_to(Sampling::parse(text).unwrap());
        assert!(applies("1") && applies("auto:0.1:1") && applies("auto:0:1"));
        assert!(!applies("4") && !applies("16") && !applies("auto") && !applies("auto:0.1:4"));
        assert_eq!(Sampling::parse("auto").unwrap().label(), "auto:0.02");
        assert_eq!(
            Sampling::parse("auto:0.02:16:1").unwrap().label(),
            "auto:0.02:16:1"
        );
        assert_eq!(
            Sampling::parse("auto:0.02:16:1/16").unwrap(),
            Sampling::parse("auto").unwrap()
        );
        for bad in [
            "",
            "8",
            "auto:",
            "auto:-1",
            "auto:x",
            "auto:0.1:8",
            "auto:0.1:4:2",
            "auto:0.1:4:1:1",
            "autox",
        ] {
            let message = Sampling::parse(bad).unwrap_err().to_string();
            assert!(
                message.contains(&format!("{bad:?}")) || message.contains("square"),
                "{bad}: {message}"
            );
        }
    }
}
