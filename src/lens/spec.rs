//! Lens specs (`equisolid:f=0.93`, `general:f=1,k1=0.5,k2=0.5,fov=180`, `samyang-7.5mm`) and
//! the named presets from the thesis's validation table.

use super::model::{Lens, LensModel};
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
    pub fn lens(&self) -> Lens {
        Lens::new(self.model, self.f)
            .and_then(|l| l.with_max_fov(PRESET_FOV_DEGREES.to_radians()))
            .expect("preset parameters are valid")
    }
}

/// Parses a lens spec: `NAME[:key=value,...]`, where NAME is a model (keys `f`, and `k1`, `k2`
/// for `general`; `fov` in degrees for all) or a preset (keys override the preset's).
///
/// ```
/// use fisheye_rt::lens::{parse_spec, LensModel};
/// let lens = parse_spec("equisolid:f=0.93,fov=180").unwrap();
/// assert_eq!(lens.model(), LensModel::Equisolid);
/// assert!(parse_spec("equisolid:f=-1").is_err());
/// ```
pub fn parse_spec(spec: &str) -> Result<Lens, LensError> {
    let err = |reason: String| LensError::Spec {
        spec: spec.to_string(),
        reason,
    };
    let (name, params) = spec.trim().split_once(':').unwrap_or((spec.trim(), ""));
    let mut f = None;
    let mut k1 = None;
    let mut k2 = None;
    let mut fov = None;
    for pair in params.split(',').map(str::trim).filter(|p| !p.is_empty()) {
        let (key, value) = pair
            .split_once('=')
            .ok_or_else(|| err(format!("{pair:?} is not key=value")))?;
        let value: f64 = value
            .trim()
            .parse()
            .map_err(|_| err(format!("{key} = {value:?} is not a number")))?;
        let slot = match key.trim() {
            "f" => &mut f,
            "k1" => &mut k1,
            "k2" => &mut k2,
            "fov" => &mut fov,
            other => {
                return Err(err(format!(
                    "unknown parameter {other:?} (known: f, k1, k2, fov)"
                )));
            }
        };
        if slot.replace(value).is_some() {
            return Err(err(format!("{key} is given twice")));
        }
    }

    let lens = if let Some(preset) = PRESETS.iter().find(|p| p.name == name) {
        if k1.is_some() || k2.is_some() {
            return Err(err(format!("preset {name} takes only f and fov")));
        }
        let lens = Lens::new(preset.model, f.unwrap_or(preset.f))?;
        lens.with_max_fov(fov.unwrap_or(PRESET_FOV_DEGREES).to_radians())?
    } else {
        let model = match name {
            "rectilinear" | "pinhole" => LensModel::Rectilinear,
            "stereographic" => LensModel::Stereographic,
            "equidistant" => LensModel::Equidistant,
            "equisolid" => LensModel::Equisolid,
            "orthographic" => LensModel::Orthographic,
            "general" => LensModel::General {
                k1: k1.ok_or_else(|| err("general needs k1".into()))?,
                k2: k2.ok_or_else(|| err("general needs k2".into()))?,
            },
            _ => {
                return Err(err(format!(
                    "unknown model or preset {name:?} (see `fisheye lens list`)"
                )));
            }
        };
        if !matches!(model, LensModel::General { .. }) && (k1.is_some() || k2.is_some()) {
            return Err(err(format!("{name} takes no k1 or k2 (only general does)")));
        }
        let f = f.ok_or_else(|| err(format!("{name} needs f, e.g. {name}:f=0.5")))?;
        let lens = Lens::new(model, f)?;
        match fov {
            Some(deg) => lens.with_max_fov(deg.to_radians())?,
            None => lens,
        }
    };
    Ok(lens)
}
