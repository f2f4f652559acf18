//! `compare`'s plots, per lens and metric: time against error (`tradeoff.LENS.png`,
//! `tradeoff-flip.LENS.png`: every setup), and where the lens has traced cubes, rays against
//! error (`rays.LENS.png`, `rays-flip.LENS.png`: direct RT and the traced cube, whose texels
//! are rays; the verdict in samples).

use std::path::Path;

use super::verdicts::{Cost, envelope, is_cube, is_rt, is_traced_cube, is_uniform, samples, time};
use super::{CompareEntry, CompareReport, Metric};
use crate::compare::pareto_front;
use crate::error::Result;
use crate::plot;
use crate::renderer::Method;
use crate::report::file_stem;

/// One kind of plot: its file, its cost axis and the setups it shows.
struct Kind {
    file: &'static str,
    cost: Cost,
    cost_label: &'static str,
    shows: fn(&CompareEntry) -> bool,
    cubes: &'static str,
}

const TIME: Kind = Kind {
    file: "tradeoff",
    cost: time,
    cost_label: "GPU ms per frame (log)",
    shows: |_| true,
    cubes: "cube maps over face sizes",
};

const RAYS: Kind = Kind {
    file: "rays",
    cost: samples,
    cost_label: "primary rays, or traced cube texels, per frame (log)",
    // `rq` traces `rt`'s rays to the same image: one of them is enough.
    shows: |e| e.method == Method::Rt.name() || is_traced_cube(e),
    cubes: "traced cube over face sizes",
};

impl CompareReport {
    /// Draws `lens`'s plots into `out`.
    pub(super) fn plots(&self, out: &Path, lens: &str) -> Result<()> {
        let traced = self
            .entries
            .iter()
            .any(|e| e.lens == lens && is_traced_cube(e));
        for (metric, suffix, axis) in [
            (Metric::Mse, "", "MSE against the reference (log)"),
            (
                Metric::Flip,
                "-flip",
                "mean ꟻLIP against the reference (log)",
            ),
        ] {
            for (kind, drawn) in [(&TIME, true), (&RAYS, traced)] {
                if drawn {
                    let file = format!("{}{suffix}.{}.png", kind.file, file_stem(lens));
                    self.plot(&out.join(file), lens, metric, axis, kind)?;
                }
            }
        }
        Ok(())
    }

    fn plot(&self, path: &Path, lens: &str, metric: Metric, axis: &str, kind: &Kind) -> Result<()> {
        let entries: Vec<&CompareEntry> = self
            .entries
            .iter()
            .filter(|e| e.lens == lens && (kind.shows)(e))
            .collect();
        let front: Vec<(f64, f64)> = entries
            .iter()
            .map(|e| ((kind.cost)(e), e.error_in(metric)))
            .collect();
        let points: Vec<plot::TradeOff> = entries
            .iter()
            .zip(pareto_front(&front))
            .map(|(e, pareto)| plot::TradeOff {
                label: match e.cube_size {
                    Some(size) => size.to_string(),
                    // `16spp`, `auto:0.1`: the sampling, after the method's name.
                    None => e
                        .setup
                        .split_once('@')
                        .map_or(&*e.setup, |(_, s)| s)
                        .to_string(),
                },
                method: e.method,
                cost: (kind.cost)(e),
                error: e.error_in(metric),
                pareto,
            })
            .collect();
        let family = |pick| envelope(entries.iter().copied(), metric, pick, kind.cost).points;
        let envelopes = [
            plot::Series {
                label: "direct RT, uniform and adaptive".into(),
                points: family(is_rt),
            },
            plot::Series {
                label: kind.cubes.into(),
                points: family(is_cube),
            },
            plot::Series {
                label: "direct RT, uniform rays, box filter".into(),
                points: family(is_uniform),
            },
        ];
        let title = format!(
            "{}: {lens}, {} ({})",
            self.run.scene, self.run.size, self.run.machine.adapter
        );
        plot::cost_against_error(path, &title, kind.cost_label, axis, &points, &envelopes)
    }
}
