//! `fisheye validate`: lens models against rendered checkerboards.

use std::path::PathBuf;

use anyhow::{Result, bail};
use fisheye_rt::gpu::GpuContext;
use fisheye_rt::lens::ImageSize;

use crate::args::CalibArgs;
use crate::study::{finish, out_folder};

#[derive(clap::Args)]
pub(crate) struct ValidateArgs {
    /// Lens specs to validate (repeatable); by default every preset (at 512x512) and each
    /// calibrated model's example (at the size it is calibrated for), as `fisheye lens list`
    /// shows them.
    #[arg(long)]
    pub(crate) lens: Vec<String>,
    /// Image size for --lens, WIDTHxHEIGHT.
    #[arg(long, default_value = "512x512")]
    pub(crate) size: ImageSize,
    #[command(flatten)]
    pub(crate) calib: CalibArgs,
    /// Rays per pixel side of the rendered images (1 to 8); by default the most, up to 4,
    /// whose image fits one storage binding.
    #[arg(long)]
    pub(crate) supersample: Option<u32>,
    /// Folder for the results; by default a new folder `fisheye-validate-N` here.
    #[arg(long, short)]
    pub(crate) out: Option<PathBuf>,
}

pub(crate) fn run_validate(args: &ValidateArgs) -> Result<()> {
    if let Some(s) = args.supersample.filter(|s| !(1..=8).contains(s)) {
        bail!("--supersample {s}: must be 1 to 8");
    }
    let lenses = if args.calib.calib.is_some() {
        vec![fisheye_rt::validate::LensToValidate {
            name: args.calib.describe(),
            camera: args.calib.camera(None, args.size)?,
        }]
    } else if args.lens.is_empty() {
        fisheye_rt::validate::default_lenses()?
    } else {
        args.lens
            .iter()
            .map(|spec| {
                Ok(fisheye_rt::validate::LensToValidate {
                    name: spec.clone(),
                    camera: args.calib.camera(Some(spec), args.size)?,
                })
            })
            .collect::<Result<Vec<_>>>()?
    };
    let out = out_folder(args.out.as_deref(), "validate")?;
    let ctx = GpuContext::new()?;
    println!("adapter: {}", ctx.adapter_name());
    let count = lenses.len();
    let mut progress = crate::progress::Progress::new(count, "lenses");
    let report = fisheye_rt::validate::run(&ctx, &lenses, args.supersample, &mut |k, name| {
        progress.update(k, name);
    })?;
    progress.update(count, "done");
    let warning = report.write(&out)?;
    finish(&report.markdown(), &out, warning);
    let failed: Vec<&str> = report
        .lenses
        .iter()
        .filter(|l| !l.passed)
        .map(|l| l.lens.as_str())
        .collect();
    if !failed.is_empty() {
        bail!(
            "{} of {count} lens(es) failed validation: {}",
            failed.len(),
            failed.join(", ")
        );
    }
    Ok(())
}
