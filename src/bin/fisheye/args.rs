//! The arguments several commands share: scene shading, lens and calibration, methods,
//! output formats, and the camera pose.

use std::path::PathBuf;

use anyhow::{Result, bail};
use clap::ValueEnum;
use fisheye_rt::bvh::BvhQuality;
use fisheye_rt::cube::CubeMethod;
use fisheye_rt::dataset::Between;
use fisheye_rt::dataset::labels::Label;
use fisheye_rt::lens::calib::{self, CalibFormat};
use fisheye_rt::lens::glass::camera_for;
use fisheye_rt::lens::gpu::DirectionSource;
use fisheye_rt::lens::{DirectionFormula, ImageSize, LensCamera};
use fisheye_rt::raster::RasterMethod;
use fisheye_rt::renderer;
use fisheye_rt::scene::Scene;
use fisheye_rt::trace::{Channel, PixelFilter, Sampling, Tone};

/// How the scene is built and shaded, for `render`, `bench` and `compare`.
#[derive(clap::Args)]
pub(crate) struct ShadingArgs {
    /// Shadow-map size in texels per side and layer (rasterized `cube-*` methods).
    #[arg(long, default_value_t = 2048)]
    pub(crate) shadow_size: u32,
    /// Deepest reflection/refraction bounce (0 to 8).
    #[arg(long, default_value_t = 5,
          value_parser = clap::value_parser!(u32).range(0..=i64::from(fisheye_rt::shared::MAX_DEPTH_LIMIT)))]
    pub(crate) max_depth: u32,
    /// BVH build preset.
    #[arg(long, value_enum, default_value = "fast")]
    pub(crate) bvh: Quality,
}

/// The scene, lenses, setups and outputs `bench` and `compare` share with `render`.
#[derive(clap::Args)]
pub(crate) struct StudyArgs {
    /// The scene, as for `render`.
    #[arg(default_value = "builtin:default")]
    pub(crate) scene: String,
    /// Which scene of a glTF file (from 0); its default scene if not given.
    #[arg(long)]
    pub(crate) gltf_scene: Option<usize>,
    /// Lens specs to measure (repeatable); or give --calib.
    #[arg(long, default_value = "canon-8-15mm@8mm")]
    pub(crate) lens: Vec<String>,
    /// The pinhole baseline measured beside the lenses, at the same image size.
    #[arg(long, default_value = "rectilinear:f=1")]
    pub(crate) pinhole: String,
    /// Leave the pinhole baseline out.
    #[arg(long)]
    pub(crate) no_pinhole: bool,
    /// Image size in pixels, WIDTHxHEIGHT.
    #[arg(long, default_value = "1024x768")]
    pub(crate) size: ImageSize,
    #[command(flatten)]
    pub(crate) calib: CalibArgs,
    /// Camera pose instead of the scene's (as for `render`); the orbit path circles its
    /// look-at point.
    #[arg(long, allow_hyphen_values = true)]
    pub(crate) camera: Option<String>,
    /// Methods to measure (comma-separated); by default every one the adapter has.
    #[arg(long, value_enum, value_delimiter = ',')]
    pub(crate) method: Vec<Method>,
    /// Cube face sizes to measure the cube-map methods at (comma-separated).
    #[arg(long, value_delimiter = ',', default_value = "512,1024,1920")]
    pub(crate) cube_size: Vec<u32>,
    /// Rays per pixel to measure direct tracing at (comma-separated): squares N for uniform
    /// sampling, auto:THRESHOLD, auto:THRESHOLD:MAX or auto:THRESHOLD:MAX:LEAST for adaptive
    /// sampling (as `render --spp`). Direct RT is a family over these as the cube maps are
    /// over face sizes.
    #[arg(
        long,
        value_delimiter = ',',
        default_value = "1,4,16,auto:0.1:1,auto:0.1:4,auto:0.1,auto:0.02,auto:0.02:64,auto:0.1:4:1"
    )]
    pub(crate) spp: Vec<Sampling>,
    /// Pixel filters to measure direct tracing with (comma-separated, as `render --filter`):
    /// each sampling once per filter that changes its pixels (the tent at one ray a pixel at
    /// most: 1 and auto:T:1), labelled `rt@1spp+tent`.
    #[arg(long, value_delimiter = ',', default_value = "box,tent")]
    pub(crate) filter: Vec<PixelFilter>,
    #[command(flatten)]
    pub(crate) shading: ShadingArgs,
    /// Folder for the results; by default a new folder `fisheye-COMMAND-N` here.
    #[arg(long, short)]
    pub(crate) out: Option<PathBuf>,
}

#[derive(Clone, Copy, ValueEnum)]
pub(crate) enum PathArg {
    Walk,
    Orbit,
}

#[derive(Clone, Copy, PartialEq, Eq, ValueEnum)]
pub(crate) enum Method {
    Rt,
    Rq,
    CubeRt,
    CubeForward,
    CubeDeferred,
    CubeSingle,
}

impl Method {
    /// The library's method.
    pub(crate) fn method(self) -> renderer::Method {
        let raster = |m| renderer::Method::Cube(CubeMethod::Raster(m));
        match self {
            Self::Rt => renderer::Method::Rt,
            Self::Rq => renderer::Method::Rq,
            Self::CubeRt => renderer::Method::Cube(CubeMethod::Traced),
            Self::CubeForward => raster(RasterMethod::Forward),
            Self::CubeDeferred => raster(RasterMethod::Deferred),
            Self::CubeSingle => raster(RasterMethod::SinglePass),
        }
    }
}

/// `render --exposure`: stops, or `auto` (Reinhard et al.'s log-average luminance mapped to
/// middle grey).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum Exposure {
    Stops(f32),
    Auto,
}

impl std::str::FromStr for Exposure {
    type Err = String;

    fn from_str(text: &str) -> std::result::Result<Self, String> {
        if text == "auto" {
            return Ok(Exposure::Auto);
        }
        match text.parse::<f32>() {
            Ok(stops) if stops.is_finite() => Ok(Exposure::Stops(stops)),
            _ => Err(format!("{text:?}: give `auto` or a finite number of stops")),
        }
    }
}

/// The tone curve of `render --tone`.
#[derive(Clone, Copy, ValueEnum)]
pub(crate) enum ToneArg {
    Aces,
    Clamp,
}

impl From<ToneArg> for Tone {
    fn from(t: ToneArg) -> Self {
        match t {
            ToneArg::Aces => Tone::Aces,
            ToneArg::Clamp => Tone::Clamp,
        }
    }
}

#[derive(Clone, Copy, PartialEq, Eq, ValueEnum)]
pub(crate) enum ArrayFormat {
    Npy,
    Exr,
}

/// The pixel filter that makes `--spp`'s images as `--filter` asks: the box, with a note
/// saying so, where the filter changes nothing at that sampling ([`PixelFilter::applies_to`]).
pub(crate) fn filter_for(filter: PixelFilter, spp: Sampling) -> PixelFilter {
    if filter.applies_to(spp) {
        return filter;
    }
    eprintln!(
        "note: --filter {} changes frames of one ray a pixel; at --spp {spp} each pixel keeps \
         its rays' mean",
        filter.name()
    );
    PixelFilter::Box
}

/// Parses `--camera` ([`Scene::parse_camera`]).
pub(crate) fn parse_camera(text: &str, scene: &Scene) -> Result<fisheye_rt::scene::Camera> {
    scene.parse_camera(text).map_err(anyhow::Error::msg)
}

#[derive(Clone, Copy, ValueEnum)]
pub(crate) enum Formula {
    Stable,
    Thesis,
}

impl From<Formula> for DirectionFormula {
    fn from(f: Formula) -> Self {
        match f {
            Formula::Stable => DirectionFormula::Stable,
            Formula::Thesis => DirectionFormula::Thesis,
        }
    }
}

/// A calibration file in place of `--lens` and `--size`.
#[derive(clap::Args)]
pub(crate) struct CalibArgs {
    /// Calibration file (OpenCV YAML/XML, Kalibr camchain YAML or Basalt JSON): its camera,
    /// at its resolution, instead of --lens and --size.
    #[arg(long, conflicts_with_all = ["lens", "size"])]
    pub(crate) calib: Option<PathBuf>,
    /// Which camera of a multi-camera calibration file (0 is the first).
    #[arg(long, default_value_t = 0, requires = "calib")]
    pub(crate) calib_camera: usize,
}

impl CalibArgs {
    /// How reports name the camera of `--calib`: the file, and the camera if not the first.
    pub(crate) fn describe(&self) -> String {
        let path = self
            .calib
            .as_deref()
            .map_or(String::new(), |p| p.display().to_string());
        match self.calib_camera {
            0 => path,
            n => format!("{path}#{n}"),
        }
    }

    /// The camera of `--calib`, or else `--lens` (required then) at `size`; warns when the
    /// lens's field of view is clipped where its mapping turns and the image reaches past it.
    pub(crate) fn camera(&self, lens: Option<&str>, size: ImageSize) -> Result<LensCamera> {
        let camera = match &self.calib {
            Some(path) => {
                let cameras = calib::read(path)?;
                let Some(c) = cameras.get(self.calib_camera) else {
                    bail!(
                        "{} holds {} camera(s); --calib-camera {} is not one",
                        path.display(),
                        cameras.len(),
                        self.calib_camera
                    );
                };
                c.camera()
            }
            None => {
                let Some(spec) = lens else {
                    bail!("give a lens: --lens SPEC or --calib FILE");
                };
                camera_for(spec, size)?
            }
        };
        // Warned about only where the image reaches past the clip: where the turn ends the
        // domain, a corner without a ray lies beyond it.
        let (w, h) = (f64::from(camera.size.width), f64::from(camera.size.height));
        let corner_lost = [(0.0, 0.0), (w, 0.0), (0.0, h), (w, h)]
            .into_iter()
            .any(|(x, y)| camera.unproject(glam::DVec2::new(x, y)).is_none());
        let visible_turn = camera
            .lens
            .calibrated()
            .and_then(|l| l.turns_at())
            .filter(|_| corner_lost);
        if let Some(turn) = visible_turn {
            eprintln!(
                "warning: {}: the mapping stops increasing at θ = {:.2}°, so the field of view \
                 is clipped to {:.2}° (pixels beyond have no ray)",
                camera.lens.name(),
                turn.to_degrees(),
                2.0 * turn.to_degrees()
            );
        }
        Ok(camera)
    }
}

#[derive(clap::Args)]
pub(crate) struct CameraArgs {
    /// Lens spec: a model with parameters (`equisolid:f=0.93`, `general:f=1,k1=0.5,k2=0.5`,
    /// `equidistant:f=0.42,fov=180`, `kb:fx=190,cx=255,cy=255,k1=0.003`), or a preset
    /// (`samyang-7.5mm`); see `fisheye lens list`. Or give --calib.
    #[arg(long)]
    pub(crate) lens: Option<String>,
    /// Image size in pixels, WIDTHxHEIGHT.
    #[arg(long, default_value = "1024x768")]
    pub(crate) size: ImageSize,
    #[command(flatten)]
    pub(crate) calib: CalibArgs,
}

impl CameraArgs {
    pub(crate) fn camera(&self) -> Result<LensCamera> {
        self.calib.camera(self.lens.as_deref(), self.size)
    }
}

/// The camera, and how `lens project|unproject` evaluate it.
#[derive(clap::Args)]
pub(crate) struct PointArgs {
    #[command(flatten)]
    pub(crate) camera: CameraArgs,
    /// How directions are built from θ: the stable default, or the thesis's formula.
    #[arg(long, value_enum, default_value = "stable")]
    pub(crate) formula: Formula,
    /// Evaluate the lens with its WGSL (f32) code on the GPU instead of the f64 reference.
    #[arg(long)]
    pub(crate) gpu: bool,
    /// Pixel coordinates in and out: `corner` (the project's: the top-left pixel's corner is
    /// (0, 0), its centre (0.5, 0.5)) or `opencv` (OpenCV's and most calibration tools':
    /// pixel centres at whole numbers, the top-left pixel's centre at (0, 0)).
    #[arg(long, value_enum, default_value = "corner")]
    pub(crate) pixel_origin: PixelOrigin,
}

/// Where pixel coordinates start.
#[derive(Clone, Copy, ValueEnum)]
pub(crate) enum PixelOrigin {
    Corner,
    #[value(name = "opencv")]
    OpenCv,
}

impl From<PixelOrigin> for fisheye_rt::lens::points::PixelOrigin {
    fn from(origin: PixelOrigin) -> Self {
        match origin {
            PixelOrigin::Corner => Self::Corner,
            PixelOrigin::OpenCv => Self::OpenCv,
        }
    }
}

impl PointArgs {
    pub(crate) fn camera(&self) -> Result<LensCamera> {
        Ok(self.camera.camera()?.with_formula(self.formula.into()))
    }
}

#[derive(Clone, Copy, ValueEnum)]
pub(crate) enum Quality {
    Fastest,
    VeryFast,
    Fast,
    Medium,
    Slow,
}

impl From<Quality> for BvhQuality {
    fn from(q: Quality) -> Self {
        match q {
            Quality::Fastest => BvhQuality::Fastest,
            Quality::VeryFast => BvhQuality::VeryFast,
            Quality::Fast => BvhQuality::Fast,
            Quality::Medium => BvhQuality::Medium,
            Quality::Slow => BvhQuality::Slow,
        }
    }
}

#[derive(Clone, Copy, ValueEnum)]
pub(crate) enum Output {
    Range,
    Normal,
    Id,
    Direction,
    Mask,
    /// The hit's depth along the optical axis (the camera frame's z; range is along the ray).
    Depth,
    /// The hit in the camera's frame (x right, y down, z forward), H×W×3.
    Point,
    /// The rays each pixel took: `render`'s picture and array, a dataset's array.
    Spp,
    /// Optical flow to the next frame and its covisibility (`dataset render` only).
    Flow,
    /// Optical flow to the previous frame and its covisibility (`dataset render` only).
    FlowBackward,
    /// Each hit's motion in the camera's frame by the next frame (`dataset render` only).
    SceneFlow,
    /// Each pixel's object, with the label map (`dataset render` only).
    Instance,
    /// Each pixel's class, with the label map (`dataset render` only).
    Semantic,
}

impl Output {
    /// The ground-truth array of this output; `None` for the spp map, which is counted
    /// rather than traced, and for the outputs between frames ([`Output::between`]).
    pub(crate) fn channel(self) -> Option<Channel> {
        Some(match self {
            Output::Range => Channel::Range,
            Output::Normal => Channel::Normal,
            Output::Id => Channel::Id,
            Output::Direction => Channel::Direction,
            Output::Mask => Channel::Mask,
            Output::Depth => Channel::Depth,
            Output::Point => Channel::Point,
            Output::Spp
            | Output::Flow
            | Output::FlowBackward
            | Output::SceneFlow
            | Output::Instance
            | Output::Semantic => return None,
        })
    }

    /// The segmentation output, for a dataset.
    pub(crate) fn label(self) -> Option<Label> {
        match self {
            Output::Instance => Some(Label::Instance),
            Output::Semantic => Some(Label::Semantic),
            _ => None,
        }
    }

    /// The output between a frame and its neighbours, for a dataset.
    pub(crate) fn between(self) -> Option<Between> {
        match self {
            Output::Flow => Some(Between::Flow),
            Output::FlowBackward => Some(Between::FlowBackward),
            Output::SceneFlow => Some(Between::SceneFlow),
            _ => None,
        }
    }
}

#[derive(Clone, Copy, ValueEnum)]
pub(crate) enum Directions {
    Computed,
    Table,
}

impl From<Directions> for DirectionSource {
    fn from(d: Directions) -> Self {
        match d {
            Directions::Computed => DirectionSource::Computed,
            Directions::Table => DirectionSource::Table,
        }
    }
}

/// A scene from `builtin:NAME`, a scene file, an OBJ file or glTF file (its scene
/// `gltf_scene`, else its default); warnings go to stderr.
pub(crate) fn load_scene_with(spec: &str, gltf_scene: Option<usize>) -> Result<Scene> {
    let loaded = fisheye_rt::scene::load_with(spec, gltf_scene)?;
    for warning in &loaded.warnings {
        eprintln!("warning: {warning}");
    }
    Ok(loaded.scene)
}

/// Calibration file formats, for `lens convert`.
#[derive(Clone, Copy, ValueEnum)]
pub(crate) enum Format {
    OpencvYaml,
    OpencvXml,
    Kalibr,
    Basalt,
}

impl From<Format> for CalibFormat {
    fn from(f: Format) -> Self {
        match f {
            Format::OpencvYaml => CalibFormat::OpenCvYaml,
            Format::OpencvXml => CalibFormat::OpenCvXml,
            Format::Kalibr => CalibFormat::Kalibr,
            Format::Basalt => CalibFormat::Basalt,
        }
    }
}
