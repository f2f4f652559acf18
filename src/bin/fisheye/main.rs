//! `fisheye`: the command-line tool. See `fisheye --help` and the README. This file parses
//! the command line and hands each command to its module.

mod args;
mod dataset;
mod info;
mod lens;
mod progress;
mod render;
mod study;
mod validate;
use anyhow::Result;
use clap::{Parser, Subcommand};
use fisheye_rt::scene::builtin;

use crate::lens::{LensCommand, convert, demo, fit, info, list, project, unproject};
use crate::render::RenderArgs;
use crate::study::{BenchArgs, CompareArgs, run_bench, run_compare};
use crate::validate::ValidateArgs;

#[derive(Parser)]
#[command(
    name = "fisheye",
    version,
    about = "Fisheye lens rendering by ray tracing in wgpu compute shaders"
)]
pub(crate) struct Cli {
    #[command(subcommand)]
    pub(crate) command: Command,
}

#[derive(Subcommand)]
pub(crate) enum Command {
    /// Render a scene through a lens by ray tracing; with no arguments, the built-in default
    /// scene through a 180° fisheye to fisheye.png.
    Render(RenderArgs),
    /// Time every method (direct RT, ray queries, cube maps at several face sizes) along a
    /// camera path, fisheye and pinhole: fps statistics and per-pass GPU times, as JSON, a
    /// Markdown table and a PNG of fps along the path, in the --out folder.
    Bench(BenchArgs),
    /// Measure every setup's time and error (MSE and ꟻLIP) against a many-ray reference, and
    /// direct RT's family (over rays per pixel) against the cube maps' (over face sizes) at
    /// equal error: JSON, a Markdown table, error maps and time-against-error PNGs with the
    /// Pareto front and each family's envelope, in the --out folder.
    Compare(CompareArgs),
    /// Check lens models against rendered images: render the built-in `grid` checkerboard
    /// through each lens, find its corners in the image to a fraction of a pixel without the
    /// lens model, and compare them with where the model projects them. Writes a Markdown
    /// table, JSON, an overlay per lens and an error plot into the --out folder; exits
    /// non-zero if a lens misses the bound.
    Validate(ValidateArgs),
    /// Synthetic datasets: a rig of calibrated cameras along a trajectory (TUM, KITTI,
    /// EuRoC), every camera rendered at every pose with its ground truth, in shards for
    /// several machines that resume after a kill; then the manifest.
    Dataset {
        #[command(subcommand)]
        command: dataset::DatasetCommand,
    },
    /// List the built-in scenes.
    Scenes,
    /// Show the GPU adapter, its optional features and limits, and measure the precision of
    /// WGSL's trigonometric builtins against this project's replacements on it; with
    /// --scene, what a scene takes on the device.
    Info(info::InfoArgs),
    /// Lens models: list them, map pixels and directions, draw what they do.
    Lens {
        #[command(subcommand)]
        command: LensCommand,
    },
}

pub(crate) fn main() {
    if let Err(error) = run(Cli::parse()) {
        eprintln!("error: {error:#}");
        std::process::exit(1);
    }
}

pub(crate) fn run(cli: Cli) -> Result<()> {
    match cli.command {
        Command::Render(args) => render::render(&args),
        Command::Bench(args) => run_bench(&args),
        Command::Compare(args) => run_compare(&args),
        Command::Validate(args) => validate::run_validate(&args),
        Command::Dataset { command } => dataset::run(&command),
        Command::Scenes => {
            for (name, what) in builtin::SCENES {
                println!("builtin:{name:<14} {what}");
            }
            Ok(())
        }
        Command::Info(args) => info::info(&args),
        Command::Lens { command } => match command {
            LensCommand::List => {
                list();
                Ok(())
            }
            LensCommand::Unproject(args) => unproject(&args),
            LensCommand::Project(args) => project(&args),
            LensCommand::Fit(args) => fit(&args),
            LensCommand::Convert {
                camera,
                format,
                out,
            } => convert(&camera, format.into(), &out),
            LensCommand::Demo { lens, size, out } => demo(lens, size, out),
            LensCommand::Info { spec, size, json } => info(&spec, size, json),
        },
    }
}
