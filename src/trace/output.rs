//! What a render produces: radiance, the primary hit's geometry and ids, per pixel.

use std::path::Path;

use glam::DVec3;

use crate::error::{Error, Result};
use crate::lens::ImageSize;

use super::NO_HIT;
use super::display::{colour_image, write_atomically};

/// One rendered frame, row-major.
///
/// ```
/// use fisheye_rt::lens::{parse_spec, ImageSize, LensCamera};
/// use fisheye_rt::trace::{render, RenderOptions, NO_HIT};
/// use fisheye_rt::{gpu::GpuContext, scene::builtin};
/// let scene = builtin::scene("default").expect("a built-in scene");
/// let camera = LensCamera::new(parse_spec("samyang-7.5mm")?, ImageSize::new(32, 24)?);
/// let out = render(&GpuContext::new()?, &scene, &camera, &RenderOptions::default())?;
/// let (rays, hits) = out.counts(); // pixels with a ray at their centre; those that hit
/// assert!(0 < hits && hits <= rays && rays <= 32 * 24);
/// assert_eq!(out.ids.iter().filter(|&&id| id != NO_HIT).count(), hits);
/// # Ok::<(), fisheye_rt::Error>(())
/// ```
#[derive(Clone, Debug)]
pub struct RenderOutput {
    /// Image size.
    pub size: ImageSize,
    /// Linear RGB radiance; `w` is the share of the pixel the lens covers (1 or 0 with one ray
    /// per pixel: the validity mask), and the pixel is all zero where it covers none.
    pub colour: Vec<[f32; 4]>,
    /// World-space shading normal (xyz) and distance from the camera (w) of the primary hit;
    /// zero on a miss or a masked pixel.
    pub geometry: Vec<[f32; 4]>,
    /// Scene triangle index of the primary hit, [`NO_HIT`] on a miss or a masked pixel.
    pub ids: Vec<u32>,
}

impl RenderOutput {
    /// Whether pixel `i` (row-major) has a ray (with several per pixel: any).
    pub fn valid(&self, i: usize) -> bool {
        self.colour[i][3] > 0.0
    }

    /// The colour image, sRGB-encoded and clamped, opaque where a pixel has a ray and
    /// transparent (alpha 0) where it is masked.
    pub fn to_image(&self) -> image::RgbaImage {
        colour_image(self.size, &self.colour)
    }

    /// The spp map of a frame of `spp` uniform rays a pixel, row-major: `spp` at each pixel
    /// with a ray ([`RenderOutput::valid`]), 0 elsewhere.
    pub fn uniform_rays(&self, spp: u32) -> Vec<u32> {
        (0..self.colour.len())
            .map(|i| if self.valid(i) { spp } else { 0 })
            .collect()
    }

    /// Number of pixels with a ray, and of those whose primary ray hit something.
    pub fn counts(&self) -> (usize, usize) {
        let valid = (0..self.colour.len()).filter(|&i| self.valid(i)).count();
        let hits = self.ids.iter().filter(|&&id| id != NO_HIT).count();
        (valid, hits)
    }
}

/// A per-pixel array `fisheye render --outputs` can write beside the image, as NPY (row-major,
/// image rows first; float32 unless noted) or OpenEXR (ZIP-compressed, one file per array: a
/// scalar in channel `Y`, the id as uint32 in channel `id`, a vector in `R`, `G`, `B`, so that
/// any EXR viewer shows it).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Channel {
    /// Euclidean distance from the camera to the primary hit, H×W; 0 on a miss or mask.
    Range,
    /// World-space shading normal at the primary hit, H×W×3; zero on a miss or mask.
    Normal,
    /// Scene triangle index of the primary hit, H×W uint32; 0xffffffff on a miss or mask.
    Id,
    /// World-space unit direction of the pixel's ray (f64 lens model), H×W×3; zero where masked.
    Direction,
    /// 1 where the pixel has a ray, 0 where the lens masks it, H×W uint8.
    Mask,
    /// The primary hit's depth along the optical axis, the camera frame's z (a z-buffer's
    /// depth, where range is the distance along the ray), H×W; negative for a hit behind the
    /// camera's plane (a field beyond 180°), 0 on a miss or mask.
    Depth,
    /// The primary hit in the camera's frame (x right, y down, z forward: range times the
    /// pixel's camera-frame direction), H×W×3; zero on a miss or mask.
    Point,
}

/// Each pixel's centre ray from the f64 lens model, row-major, `None` where the lens masks
/// the pixel: in the camera's frame ([`crate::lens::LensCamera::directions`]), which the
/// depth and the point read, and in world space (turned by the pose, at each line's time
/// under a rolling shutter), which the direction and the mask read. A slice no array asked
/// for may be empty.
#[derive(Clone, Copy, Debug, Default)]
pub struct PixelRays<'a> {
    /// In the camera's frame.
    pub camera: &'a [Option<DVec3>],
    /// In world space.
    pub world: &'a [Option<DVec3>],
}

impl Channel {
    /// Every channel, in the order `--outputs` lists them.
    pub const ALL: [Channel; 7] = [
        Self::Range,
        Self::Normal,
        Self::Id,
        Self::Direction,
        Self::Mask,
        Self::Depth,
        Self::Point,
    ];

    /// Whether the array is the centre ray's hit, traced on the GPU (range, normal, id, and
    /// depth and point from the range), rather than the lens's own (direction, mask):
    /// adaptive sampling traces the hits of the pixels it interpolates only where one is
    /// wanted.
    pub fn traced(&self) -> bool {
        !matches!(self, Self::Direction | Self::Mask)
    }

    /// Whether the array reads the pixels' rays in the camera's frame ([`PixelRays::camera`]).
    pub fn camera_rays(&self) -> bool {
        matches!(self, Self::Depth | Self::Point)
    }

    /// Whether the array reads the pixels' rays in world space ([`PixelRays::world`]).
    pub fn world_rays(&self) -> bool {
        matches!(self, Self::Direction | Self::Mask)
    }

    /// The name on the command line and in file names.
    pub fn name(&self) -> &'static str {
        match self {
            Self::Range => "range",
            Self::Normal => "normal",
            Self::Id => "id",
            Self::Direction => "direction",
            Self::Mask => "mask",
            Self::Depth => "depth",
            Self::Point => "point",
        }
    }
}

fn write_array<T: npyz::Serialize + npyz::AutoSerialize>(
    path: &Path,
    shape: &[u64],
    data: impl IntoIterator<Item = T>,
) -> Result<()> {
    write_atomically(path, |temporary| {
        let io = |reason| Error::Io {
            path: path.to_path_buf(),
            reason,
        };
        let file = std::fs::File::create(temporary).map_err(io)?;
        use npyz::WriterBuilder;
        let mut writer = npyz::WriteOptions::new()
            .default_dtype()
            .shape(shape)
            .writer(std::io::BufWriter::new(file))
            .begin_nd()
            .map_err(io)?;
        writer.extend(data).map_err(io)?;
        writer.finish().map_err(io)
    })
}

/// One array of a [`Channel`], row-major, image rows first.
#[derive(Clone, Debug, PartialEq)]
pub enum Values {
    /// Floats: the components a pixel (1: H×W, else H×W×n) and the values.
    F32(usize, Vec<f32>),
    /// One `u32` a pixel.
    U32(Vec<u32>),
    /// One `u8` a pixel.
    U8(Vec<u8>),
}

impl RenderOutput {
    /// The values of `channel` as the files hold them, `rays` the pixels' (the slices
    /// `channel` reads: [`Channel::camera_rays`], [`Channel::world_rays`]).
    pub fn values(&self, channel: Channel, rays: PixelRays) -> Values {
        // The hit in the camera's frame: range along the f64 lens model's direction.
        let points = || {
            assert_eq!(
                rays.camera.len(),
                self.geometry.len(),
                "the depth and the point read every pixel's camera-frame ray"
            );
            self.geometry.iter().zip(rays.camera).map(|(g, d)| match d {
                Some(d) if g[3] > 0.0 => (f64::from(g[3]) * *d).as_vec3(),
                _ => glam::Vec3::ZERO,
            })
        };
        let directions = rays.world;
        match channel {
            Channel::Range => Values::F32(1, self.geometry.iter().map(|g| g[3]).collect()),
            Channel::Normal => Values::F32(
                3,
                self.geometry
                    .iter()
                    .flat_map(|g| [g[0], g[1], g[2]])
                    .collect(),
            ),
            Channel::Id => Values::U32(self.ids.clone()),
            Channel::Direction => Values::F32(
                3,
                directions
                    .iter()
                    .flat_map(|d| d.unwrap_or(DVec3::ZERO).as_vec3().to_array())
                    .collect(),
            ),
            Channel::Mask => {
                // The lens's own mask at pixel centres (the GPU's agrees bit for bit), also
                // where several rays per pixel make the colour's `w` a coverage.
                Values::U8(directions.iter().map(|d| u8::from(d.is_some())).collect())
            }
            Channel::Depth => Values::F32(1, points().map(|p| p.z).collect()),
            Channel::Point => Values::F32(3, points().flat_map(|p| p.to_array()).collect()),
        }
    }

    /// Writes one channel as an NPY file; `rays` as for [`RenderOutput::values`].
    pub fn write_npy(&self, channel: Channel, rays: PixelRays, path: &Path) -> Result<()> {
        write_npy(path, self.size, self.values(channel, rays))
    }

    /// Writes one channel as an OpenEXR file (see [`Channel`] for the channel names); the mask
    /// is stored as float 0 or 1.
    pub fn write_exr(&self, channel: Channel, rays: PixelRays, path: &Path) -> Result<()> {
        write_exr(path, self.size, channel.name(), self.values(channel, rays))
    }
}

/// Writes an image's array as NPY: H×W, or H×W×n for n components a pixel.
pub fn write_npy(path: &Path, size: ImageSize, values: Values) -> Result<()> {
    let (h, w) = (u64::from(size.height), u64::from(size.width));
    match values {
        Values::F32(1, v) => write_array(path, &[h, w], v),
        Values::F32(n, v) => write_array(path, &[h, w, n as u64], v),
        Values::U32(v) => write_array(path, &[h, w], v),
        Values::U8(v) => write_array(path, &[h, w], v),
    }
}

/// Writes an spp map (the rays each pixel's colour took, row-major) as the path's extension
/// says: `.exr` as a float in channel `Y` of a layer named `spp`, as the range is (every
/// count to 257 exact in float), which any viewer shows; else NPY, `uint32`.
pub fn write_rays_map(path: &Path, size: ImageSize, map: &[u32]) -> Result<()> {
    if path.extension().is_some_and(|e| e == "exr") {
        let counts = map.iter().map(|&n| n as f32).collect();
        write_exr(path, size, "spp", Values::F32(1, counts))
    } else {
        write_npy(path, size, Values::U32(map.to_vec()))
    }
}

/// Writes an image's array as OpenEXR, its layer named `name`: a scalar in channel `Y` (a
/// `u8` as float 0 to 255), a `u32` in `id`, components in `R`, `G`, `B` (as many as it has).
pub fn write_exr(path: &Path, size: ImageSize, name: &str, values: Values) -> Result<()> {
    use exr::prelude::{
        AnyChannel, AnyChannels, Encoding, FlatSamples, Image, Layer, LayerAttributes, SmallVec,
        WritableImage,
    };
    let list: SmallVec<[AnyChannel<FlatSamples>; 4]> = match values {
        Values::F32(1, v) => [AnyChannel::new("Y", FlatSamples::F32(v))]
            .into_iter()
            .collect(),
        Values::F32(n, v) => ["R", "G", "B"]
            .iter()
            .take(n)
            .enumerate()
            .map(|(k, name)| {
                let component = v.iter().skip(k).step_by(n).copied().collect();
                AnyChannel::new(*name, FlatSamples::F32(component))
            })
            .collect(),
        Values::U32(v) => [AnyChannel::new("id", FlatSamples::U32(v))]
            .into_iter()
            .collect(),
        Values::U8(v) => [AnyChannel::new(
            "Y",
            FlatSamples::F32(v.into_iter().map(f32::from).collect()),
        )]
        .into_iter()
        .collect(),
    };
    let size = (size.width as usize, size.height as usize);
    let layer = Layer::new(
        size,
        LayerAttributes::named(name),
        Encoding::SMALL_LOSSLESS,
        AnyChannels::sort(list),
    );
    write_atomically(path, |temporary| {
        Image::from_layer(layer)
            .write()
            .to_file(temporary)
            .map_err(|e| Error::Io {
                path: path.to_path_buf(),
                reason: std::io::Error::other(e.to_string()),
            })
    })
}

/// Colours of the spp map's ramp from no ray to the most, at even steps: viridis's ends and
/// quarter points (van der Walt and Smith's matplotlib colour map, chosen for being
/// perceptually uniform and readable with colour-blindness).
const RAMP: [[f32; 3]; 5] = [
    [0.267, 0.005, 0.329],
    [0.229, 0.322, 0.546],
    [0.128, 0.567, 0.551],
    [0.369, 0.789, 0.383],
    [0.993, 0.906, 0.144],
];

/// How the spp map's key names the colours of its ramp.
const RAMP_NAMES: [&str; 5] = ["dark violet", "blue", "teal", "green", "yellow"];

/// The key to [`spp_picture`]'s colours with `most` rays at the top: the rays each colour of
/// its ramp stands for, `dark violet 0 (interpolated), blue 1.1, teal 3.2, green 7.7, yellow
/// 17 rays a pixel` for 17 (a colour between two stands for rays between theirs).
pub fn spp_key(most: u32) -> String {
    let top = f64::from(most.max(1)).ln_1p();
    let steps = (RAMP.len() - 1) as f64;
    let stops: Vec<String> = RAMP_NAMES
        .iter()
        .enumerate()
        .map(|(k, name)| {
            // The ramp's colour k is at log(1 + rays) = k / steps of log(1 + most).
            let rays = (top * k as f64 / steps).exp_m1();
            match k {
                0 => format!("{name} 0 (interpolated)"),
                _ if k == RAMP.len() - 1 => format!("{name} {most}"),
                _ if rays < 10.0 => format!("{name} {rays:.1}"),
                _ => format!("{name} {rays:.0}"),
            }
        })
        .collect();
    format!("{} rays a pixel", stops.join(", "))
}

/// A picture of the rays each pixel took (`rays`, row-major, as
/// [`AdaptivePass::read_rays`](super::AdaptivePass::read_rays) gives them): dark violet for
/// none (interpolated), then along viridis to yellow at `most`, on a logarithmic scale
/// (log(1 + rays)); transparent where `colour`'s mask says the lens covers nothing.
pub fn spp_picture(
    size: crate::lens::ImageSize,
    rays: &[u32],
    colour: &[[f32; 4]],
    most: u32,
) -> image::RgbaImage {
    let top = f64::from(most.max(1)).ln_1p();
    let mut picture = image::RgbaImage::new(size.width, size.height);
    for ((pixel, &n), c) in picture.pixels_mut().zip(rays).zip(colour) {
        if c[3] <= 0.0 {
            continue;
        }
        let x = (f64::from(n).ln_1p() / top).clamp(0.0, 1.0) * (RAMP.len() - 1) as f64;
        let (i, f) = ((x.floor() as usize).min(RAMP.len() - 2), x - x.floor());
        let f = if x >= (RAMP.len() - 1) as f64 {
            1.0
        } else {
            f as f32
        };
        let rgb: [f32; 3] = std::array::from_fn(|k| RAMP[i][k] + (RAMP[i + 1][k] - RAMP[i][k]) * f);
        *pixel = image::Rgba([
            (rgb[0] * 255.0).round() as u8,
            (rgb[1] * 255.0).round() as u8,
            (rgb[2] * 255.0).round() as u8,
            255,
        ]);
    }
    picture
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The key says what the picture shows: a pixel with a stop's rays (rounded to whole
    /// rays) is drawn nearest that stop's colour of the ramp, none and the most exactly. (With
    /// the most 16 rays and more, as `render`'s maps have by default: below that the middle
    /// stops fall between whole rays, which no pixel takes.)
    #[test]
    fn the_spp_key_names_the_colours_the_picture_draws() {
        assert_eq!(
            spp_key(17),
            "dark violet 0 (interpolated), blue 1.1, teal 3.2, green 7.7, yellow 17 rays a pixel"
        );
        let size = crate::lens::ImageSize::new(1, 1).unwrap();
        for most in [17, 65, 257] {
            let key = spp_key(most);
            let counts: Vec<f64> = key
                .trim_end_matches(" rays a pixel")
                .split(", ")
                .map(|stop| stop.split(' ').find_map(|w| w.parse().ok()).unwrap())
                .collect();
            assert_eq!(counts.len(), RAMP.len(), "{key}");
            for (k, rays) in counts.into_iter().enumerate() {
                let picture =
                    spp_picture(size, &[rays.round() as u32], &[[0.0, 0.0, 0.0, 1.0]], most);
                let drawn = picture.get_pixel(0, 0).0;
                let distance = |c: &[f32; 3]| -> f32 {
                    (0..3)
                        .map(|i| (f32::from(drawn[i]) / 255.0 - c[i]).powi(2))
                        .sum()
                };
                let nearest = (0..RAMP.len())
                    .min_by(|&a, &b| distance(&RAMP[a]).total_cmp(&distance(&RAMP[b])))
                    .unwrap();
                assert_eq!(nearest, k, "{key}: {rays} rays drawn as {drawn:?}");
                if k == 0 || k == RAMP.len() - 1 {
                    assert!(distance(&RAMP[k]) < 1e-4, "{key}: {drawn:?}");
                }
            }
        }
    }
}
