//! Lens specs (`equisolid:f=0.93`, `general:f=1,k1=0.5,k2=0.5,fov=180`, `samyang-7.5mm`) and
//! the named presets from the thesis's validation table.

use super::calibrated::{CalibratedLens, CalibratedModel, Intrinsics};
use super::model::{ClassicLens, Lens, LensModel};
use crate::error::LensError;

/// A named real lens: the model and model focal length (normalized units) the thesis fitted
/// to photographs of a calibration grid.
#[derive(Clone, Copy, Debug)]
pub struct Preset {
    /// The name used in specs.
    pub name: &'static str,
    /// Camera body, lens and zoom setting.
    pub description: &'static str,
    /// The fitted mapping.
    pub model: LensModel,
    /// The fitted focal length, normalized units.
    pub f: f64,
}

/// Every preset lens is a 180° fisheye: presets are limited to that field of view.
pub const PRESET_FOV_DEGREES: f64 = 180.0;

/// The thesis's validation table: each camera and lens, the best-fitting classic model and its
/// focal length in normalized units.
pub const PRESETS: [Preset; 7] = [
    Preset {
        name: "nikkor-8-15mm-d500@15mm",
        description: "Nikon D500 + Nikkor AF-S Fisheye 8-15 mm at 15 mm",
        model: LensModel::Orthographic,
        f: 1.54,
    },
    Preset {
        name: "nikkor-8-15mm-d500@12mm",
        description: "Nikon D500 + Nikkor AF-S Fisheye 8-15 mm at 12 mm",
        model: LensModel::Orthographic,
        f: 1.35,
    },
    Preset {
        name: "nikkor-8-15mm-d3x@10mm",
        description: "Nikon D3x + Nikkor AF-S Fisheye 8-15 mm at 10 mm",
        model: LensModel::Orthographic,
        f: 0.72,
    },
    Preset {
        name: "nikkor-8-15mm-d3x@8mm",
        description: "Nikon D3x + Nikkor AF-S Fisheye 8-15 mm at 8 mm",
        model: LensModel::Orthographic,
        f: 0.62,
    },
    Preset {
        name: "samyang-7.5mm",
        description: "Olympus E-PL1 + Samyang 7.5 mm fisheye",
        model: LensModel::Equisolid,
        f: 0.93,
    },
    Preset {
        name: "canon-8-15mm@15mm",
        description: "Canon EOS-1Ds Mark III + Canon EF 8-15 mm at 15 mm",
        model: LensModel::Equidistant,
        f: 0.785,
    },
    Preset {
        name: "canon-8-15mm@8mm",
        description: "Canon EOS-1Ds Mark III + Canon EF 8-15 mm at 8 mm",
        model: LensModel::Equidistant,
        f: 0.42,
    },
];

impl Preset {
    /// The preset as a lens (limited to [`PRESET_FOV_DEGREES`]).
    pub fn lens(&self) -> ClassicLens {
        ClassicLens::new(self.model, self.f)
            .and_then(|l| l.with_max_fov(PRESET_FOV_DEGREES.to_radians()))
            .expect("preset parameters are valid")
    }
}

/// Parses a lens spec: `NAME[:key=value,...]`, where NAME is
/// - a classic model (keys `f`, and `k1`, `k2` for `general`; `fov` in degrees for all),
/// - a preset (keys `f` and `fov` override the preset's), or
/// - a calibrated model (see [`CalibratedModel::NAMES`] for each one's keys): intrinsics `fx`,
///   `fy` (default `fx`), `cx`, `cy` in pixels with OpenCV's convention that the centre of the
///   top-left pixel is (0, 0), as calibration files write them; `fov` in degrees. Scaramuzza
///   and f-theta take `cx`, `cy` and optional scales `fx`, `fy` (default 1: their polynomials
///   are in pixels). `ucm` takes `alpha`, or Mei's `xi` (then `fx`, `fy` are Mei's γ).
///
/// ```
/// use fisheye_rt::lens::{parse_spec, LensModel};
/// let lens = parse_spec("equisolid:f=0.93,fov=180").unwrap();
/// assert_eq!(lens.classic().unwrap().model(), LensModel::Equisolid);
/// assert!(parse_spec("equisolid:f=-1").is_err());
/// let kb = parse_spec("kb:fx=280,cx=319.5,cy=239.5,k1=-0.01,k2=0.002,k3=0,k4=0").unwrap();
/// assert_eq!(kb.name(), "kb");
/// ```
pub fn parse_spec(spec: &str) -> Result<Lens, LensError> {
    let err = |reason: String| LensError::Spec {
        spec: spec.to_string(),
        reason,
    };
    let (name, params) = spec.trim().split_once(':').unwrap_or((spec.trim(), ""));
    if name == "prescription" {
        return Err(err(
            "a lens prescription's camera depends on the image's size: \
             lens::glass::camera_for makes it"
                .into(),
        ));
    }
    let mut values: Vec<(&str, f64)> = Vec::new();
    for pair in params.split(',').map(str::trim).filter(|p| !p.is_empty()) {
        let (key, value) = pair
            .split_once('=')
            .ok_or_else(|| err(format!("{pair:?} is not key=value")))?;
        let key = key.trim();
        let value: f64 = value
            .trim()
            .parse()
            .map_err(|_| err(format!("{key} = {value:?} is not a number")))?;
        if values.iter().any(|(k, _)| *k == key) {
            return Err(err(format!("{key} is given twice")));
        }
        values.push((key, value));
    }
    let known: &[&str] = if PRESETS.iter().any(|p| p.name == name) {
        &["f", "fov"]
    } else {
        match name {
            "general" => &["f", "k1", "k2", "fov"],
            "rectilinear" | "pinhole" | "stereographic" | "equidistant" | "equisolid"
            | "orthographic" => &["f", "fov"],
            "kb" => &["fx", "fy", "cx", "cy", "k1", "k2", "k3", "k4", "fov"],
            "ds" => &["fx", "fy", "cx", "cy", "xi", "alpha", "fov"],
            "ucm" => &["fx", "fy", "cx", "cy", "alpha", "xi", "fov"],
            "eucm" => &["fx", "fy", "cx", "cy", "alpha", "beta", "fov"],
            "fov-model" => &["fx", "fy", "cx", "cy", "w", "fov"],
            "scaramuzza" => &[
                "fx", "fy", "cx", "cy", "a0", "a1", "a2", "a3", "a4", "c", "d", "e", "fov",
            ],
            "ftheta" => &["fx", "fy", "cx", "cy", "k1", "k2", "k3", "k4", "k5", "fov"],
            "radtan" => &["fx", "fy", "cx", "cy", "k1", "k2", "p1", "p2", "k3", "fov"],
            _ => {
                return Err(err(format!(
                    "unknown model or preset {name:?} (see `fisheye lens list`)"
                )));
            }
        }
    };
    if let Some((key, _)) = values.iter().find(|(k, _)| !known.contains(k)) {
        return Err(err(format!(
            "{name} takes no parameter {key:?} (it takes: {})",
            known.join(", ")
        )));
    }
    let get = |key: &str| values.iter().find(|(k, _)| *k == key).map(|(_, v)| *v);
    let need = |key: &str| {
        get(key).ok_or_else(|| err(format!("{name} needs {key}, e.g. {name}:{key}=...")))
    };
    let fov = get("fov");

    if let Some(preset) = PRESETS.iter().find(|p| p.name == name) {
        let lens = ClassicLens::new(preset.model, get("f").unwrap_or(preset.f))?;
        return Ok(lens
            .with_max_fov(fov.unwrap_or(PRESET_FOV_DEGREES).to_radians())?
            .into());
    }
    let classic = match name {
        "rectilinear" | "pinhole" => Some(LensModel::Rectilinear),
        "stereographic" => Some(LensModel::Stereographic),
        "equidistant" => Some(LensModel::Equidistant),
        "equisolid" => Some(LensModel::Equisolid),
        "orthographic" => Some(LensModel::Orthographic),
        "general" => Some(LensModel::General {
            k1: need("k1")?,
            k2: need("k2")?,
        }),
        _ => None,
    };
    if let Some(model) = classic {
        let lens = ClassicLens::new(model, need("f")?)?;
        return Ok(match fov {
            Some(deg) => lens.with_max_fov(deg.to_radians())?,
            None => lens,
        }
        .into());
    }

    let zero = |key: &str| get(key).unwrap_or(0.0);
    let polynomial = matches!(name, "scaramuzza" | "ftheta");
    let fx = if polynomial {
        get("fx").unwrap_or(1.0)
    } else {
        need("fx")?
    };
    let mut intrinsics = Intrinsics {
        fx,
        fy: get("fy").unwrap_or(fx),
        cx: need("cx")? + 0.5,
        cy: need("cy")? + 0.5,
    };
    let model = match name {
        "kb" => CalibratedModel::KannalaBrandt {
            k: [zero("k1"), zero("k2"), zero("k3"), zero("k4")],
        },
        "ds" => CalibratedModel::DoubleSphere {
            xi: need("xi")?,
            alpha: need("alpha")?,
        },
        "ucm" => match (get("alpha"), get("xi")) {
            (Some(alpha), None) => CalibratedModel::Unified { alpha },
            (None, Some(xi)) => {
                if !(xi.is_finite() && xi >= 0.0) {
                    return Err(LensError::parameter("xi", xi, "must be finite and ≥ 0"));
                }
                intrinsics.fx /= 1.0 + xi;
                intrinsics.fy /= 1.0 + xi;
                CalibratedModel::Unified {
                    alpha: xi / (1.0 + xi),
                }
            }
            _ => return Err(err("ucm needs either alpha or Mei's xi".into())),
        },
        "eucm" => CalibratedModel::ExtendedUnified {
            alpha: need("alpha")?,
            beta: need("beta")?,
        },
        "fov-model" => CalibratedModel::Fov { w: need("w")? },
        "scaramuzza" => CalibratedModel::Scaramuzza {
            a: [need("a0")?, zero("a1"), zero("a2"), zero("a3"), zero("a4")],
            c: get("c").unwrap_or(1.0),
            d: zero("d"),
            e: zero("e"),
        },
        "ftheta" => CalibratedModel::FTheta {
            k: [need("k1")?, zero("k2"), zero("k3"), zero("k4"), zero("k5")],
        },
        _ => CalibratedModel::RadTan {
            k: [zero("k1"), zero("k2"), zero("k3")],
            p: [zero("p1"), zero("p2")],
        },
    };
    let lens = match fov {
        Some(deg) => CalibratedLens::with_fov(model, intrinsics, deg.to_radians())?,
        None => CalibratedLens::new(model, intrinsics)?,
    };
    Ok(lens.into())
}
