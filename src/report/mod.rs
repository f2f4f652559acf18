//! `fisheye bench` and `fisheye compare` as library calls: run every setup on every lens,
//! and write what they measured into a folder as JSON, a Markdown table and PNG plots (error
//! maps too, for compare). Each file names the machine ([`Machine`]).

mod benchmark;
mod comparison;

use std::path::Path;

use serde::Serialize;

pub use benchmark::{BenchEntry, BenchReport, bench};
pub use comparison::{
    Ceiling, CompareEntry, CompareReport, Level, Metric, RayLevel, Verdict, compare,
};

use crate::bench::Machine;
pub use crate::bench::PathKind;
use crate::error::{Error, Result};
use crate::gpu::GpuContext;
use crate::lens::LensCamera;
use crate::plot;
use crate::renderer::{Offscreen, SceneSet, Setup};
use crate::scene::Scene;

/// A lens to measure, with the name reports give it.
pub struct LensRun {
    /// The spec it was made from (`canon-8-15mm@8mm`, `rectilinear:f=1`).
    pub name: String,
    /// The camera.
    pub camera: LensCamera,
}

/// What is being measured, shared by both commands.
pub struct Study<'a> {
    /// The device.
    pub ctx: &'a GpuContext,
    /// The scene as loaded.
    pub scene: &'a Scene,
    /// How the scene was named on the command line.
    pub scene_name: String,
    /// The scene on the GPU.
    pub scenes: &'a SceneSet,
    /// The lenses.
    pub lenses: &'a [LensRun],
    /// The setups to run on each lens; those the adapter cannot run are skipped and listed.
    pub setups: &'a [Setup],
    /// Shadow-map size of rasterized faces.
    pub shadow_size: u32,
}

/// Progress of a long run, for a progress bar: `done` of `total` frames, and what runs now.
pub struct Progress<'a> {
    /// Frames rendered so far.
    pub done: usize,
    /// Frames in the whole run.
    pub total: usize,
    /// The lens and setup being rendered.
    pub what: &'a str,
}

impl Study<'_> {
    /// The setups the adapter can run, and a line per setup it cannot.
    fn runnable(&self) -> (Vec<Setup>, Vec<String>) {
        let mut skipped = Vec::new();
        let setups = self
            .setups
            .iter()
            .filter(|s| match s.method.missing_feature(self.ctx) {
                Some(feature) => {
                    skipped.push(format!("{}: the adapter has no {feature}", s.label()));
                    false
                }
                None => true,
            })
            .copied()
            .collect();
        (setups, skipped)
    }

    /// Why `lens` cannot run `setup`, where it cannot: a prescription's glass is traced by
    /// direct sampling only (a cube map resamples by direction), so its cube setups are
    /// skipped and listed, and `rays=fit` measures its fitted model there.
    fn cannot(lens: &LensRun, setup: &Setup) -> Option<String> {
        (lens.camera.glass.is_some() && setup.method.cube().is_some()).then(|| {
            format!(
                "{} {}: the glass is traced by direct sampling only (rays=fit in the spec \
                 measures its fitted model)",
                lens.name,
                setup.label()
            )
        })
    }

    fn run(&self) -> Run {
        Run {
            machine: Machine::describe(self.ctx),
            scene: self.scene_name.clone(),
            triangles: self.scene.len(),
            size: self
                .lenses
                .first()
                .map_or(String::new(), |l| l.camera.size.to_string()),
        }
    }

    fn renderer(&self, lens: &LensRun, setup: Setup) -> Result<Offscreen> {
        Offscreen::new(self.ctx, &lens.camera, self.scenes, setup, self.shadow_size)
    }
}

/// Where a run was made, and of what: the head of both reports.
#[derive(Serialize)]
pub struct Run {
    /// The machine.
    pub machine: Machine,
    /// The scene as named.
    pub scene: String,
    /// Its triangle count.
    pub triangles: usize,
    /// Image size.
    pub size: String,
}

/// File-name-safe form of a label: letters, digits, `-`, `.` and `@` kept, the rest `_`.
pub fn file_stem(label: &str) -> String {
    label
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || "-.@".contains(c) {
                c
            } else {
                '_'
            }
        })
        .collect()
}

pub(crate) fn write_text(path: &Path, text: &str) -> Result<()> {
    crate::trace::write_file(path, text.as_bytes())
}

pub(crate) fn write_json(path: &Path, value: &impl Serialize) -> Result<()> {
    let text = serde_json::to_string_pretty(value).expect("reports serialize");
    write_text(path, &(text + "\n"))
}

/// Writes `NAME.json` and `NAME.md` into `out`, then a plot per lens (in order, each once)
/// with `draw`; returns why there are no plots, if there is no font for them.
fn write_report<'a>(
    out: &Path,
    name: &str,
    report: &impl Serialize,
    markdown: &str,
    lenses: impl Iterator<Item = &'a str>,
    mut draw: impl FnMut(&str) -> Result<()>,
) -> Result<Option<String>> {
    write_json(&out.join(format!("{name}.json")), report)?;
    write_text(&out.join(format!("{name}.md")), markdown)?;
    if let Err(why) = plot::font() {
        return Ok(Some(why));
    }
    let mut lenses: Vec<&str> = lenses.collect();
    lenses.dedup();
    for lens in lenses {
        draw(lens)?;
    }
    Ok(None)
}

/// Refuses `frames` 0 for [`bench`] and [`compare`]: their times are medians of the frames
/// timed.
fn check_frames(frames: usize) -> Result<()> {
    if frames == 0 {
        return Err(Error::Option(
            "frames 0: a median needs at least one timed frame".into(),
        ));
    }
    Ok(())
}

pub(crate) fn machine_lines(m: &Machine) -> String {
    format!(
        "- adapter: {}\n- driver: {}\n- CPU: {} ({} logical)\n- date: {}\n",
        m.adapter, m.driver, m.cpu, m.cpus, m.date
    )
}

/// `ratio` (another time over RT's) as "2.50x faster" or, below 1, "1.49x slower".
fn speed_ratio(ratio: f64) -> String {
    if ratio >= 1.0 {
        format!("{ratio:.2}x faster")
    } else {
        format!("{:.2}x slower", 1.0 / ratio)
    }
}

/// A value in ms or fps to three significant figures, as the tables print them.
fn sig(v: f64) -> String {
    if v >= 100.0 {
        format!("{v:.0}")
    } else if v >= 10.0 {
        format!("{v:.1}")
    } else {
        format!("{v:.2}")
    }
}

fn is_pinhole(lens: &str) -> bool {
    lens == "pinhole" || lens.starts_with("rectilinear")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn speed_ratios_read_as_faster_or_slower() {
        assert_eq!(speed_ratio(2.5), "2.50x faster");
        assert_eq!(speed_ratio(1.0), "1.00x faster");
        assert_eq!(speed_ratio(0.5), "2.00x slower");
    }
}
