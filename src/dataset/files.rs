//! A dataset's folder on disk: the arrays' format, the plan written once and checked by every
//! run, the temporary files killed runs leave, and the merge that checks every file of the
//! plan and writes `manifest.json`.

use std::path::{Path, PathBuf};

use serde_json::Value;

use crate::error::{Error, Result};
use crate::trace::write_file;

/// The file format of the ground-truth arrays.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ArrayFile {
    /// NumPy `.npy`.
    Npy,
    /// OpenEXR `.exr`.
    Exr,
}

impl ArrayFile {
    pub(super) fn extension(self) -> &'static str {
        match self {
            Self::Npy => "npy",
            Self::Exr => "exr",
        }
    }
}

/// The plan's file in a dataset's folder: written by every run before it renders, and
/// compared, so that runs with other settings cannot mix their frames into it.
pub(super) const PLAN: &str = "plan.json";
/// The manifest's file, written by [`merge`] once every frame is complete.
const MANIFEST: &str = "manifest.json";
/// What the plan and manifest say they are, for loaders to check.
pub(super) const LAYOUT: &str = "fisheye-rt dataset 1";

/// Writes the plan into `folder`, or checks that the one there is the same.
pub(super) fn check_plan(folder: &Path, plan: &str) -> Result<()> {
    let path = folder.join(PLAN);
    match std::fs::read(&path) {
        Ok(existing) if existing == plan.as_bytes() => Ok(()),
        Ok(existing) => {
            let line = String::from_utf8_lossy(&existing)
                .lines()
                .zip(plan.lines())
                .position(|(a, b)| a != b)
                .map_or(String::new(), |l| format!(" (first at line {})", l + 1));
            Err(Error::Dataset {
                path,
                message: format!(
                    "holds the plan of another dataset{line}: its scene, trajectory, rig or \
                     settings differ from these. Render into another folder, or remove this \
                     one to start again"
                ),
            })
        }
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => write_file(&path, plan.as_bytes()),
        Err(reason) => Err(Error::Io { path, reason }),
    }
}

/// Removes the temporary files (`.NAME.PID.tmp`) a killed run left in `dir` for poses in
/// `range` (another shard's are its own business: it may be writing them now).
pub(super) fn remove_leftovers(dir: &Path, range: &std::ops::Range<usize>) -> Result<()> {
    let entries = match std::fs::read_dir(dir) {
        Ok(entries) => entries,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(()),
        Err(reason) => {
            return Err(Error::Io {
                path: dir.to_path_buf(),
                reason,
            });
        }
    };
    for entry in entries.flatten() {
        let name = entry.file_name().to_string_lossy().to_string();
        let Some(rest) = name.strip_prefix('.').filter(|_| name.ends_with(".tmp")) else {
            continue;
        };
        let index = rest.split('_').next().and_then(|i| i.parse::<usize>().ok());
        if index.is_some_and(|i| range.contains(&i)) {
            std::fs::remove_file(entry.path()).map_err(|reason| Error::Io {
                path: entry.path(),
                reason,
            })?;
        }
    }
    Ok(())
}

/// Checks that every file the plan in `folder` lists exists and writes `manifest.json` (the
/// plan, which lists every frame's files and poses); the error lists the incomplete poses
/// by shard-independent ranges.
pub fn merge(folder: &Path) -> Result<PathBuf> {
    let plan_path = folder.join(PLAN);
    let bad = |message: String| Error::Dataset {
        path: plan_path.clone(),
        message,
    };
    let text = match std::fs::read_to_string(&plan_path) {
        Ok(text) => text,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
            return Err(Error::Dataset {
                path: folder.to_path_buf(),
                message: "holds no dataset (no plan.json): `fisheye dataset render` makes one"
                    .into(),
            });
        }
        Err(reason) => {
            return Err(Error::Io {
                path: plan_path,
                reason,
            });
        }
    };
    let plan: Value =
        serde_json::from_str(&text).map_err(|e| bad(format!("not a dataset plan: {e}")))?;
    if plan["layout"] != LAYOUT {
        return Err(bad(format!("not a dataset plan of layout {LAYOUT:?}")));
    }
    let frames = plan["frames"]
        .as_array()
        .ok_or_else(|| bad("no frames list".into()))?;
    let mut missing: Vec<usize> = Vec::new();
    for (p, frame) in frames.iter().enumerate() {
        let files = frame["views"]
            .as_array()
            .into_iter()
            .flatten()
            .flat_map(|v| v["files"].as_object().into_iter().flatten())
            .filter_map(|(_, f)| f.as_str());
        if files.into_iter().any(|f| !folder.join(f).is_file()) {
            missing.push(p);
        }
    }
    if !missing.is_empty() {
        return Err(Error::Dataset {
            path: folder.to_path_buf(),
            message: format!(
                "{} of {} poses are incomplete ({}): render their shards (again) and merge then",
                missing.len(),
                frames.len(),
                ranges(&missing)
            ),
        });
    }
    let path = folder.join(MANIFEST);
    write_file(&path, text.as_bytes())?;
    Ok(path)
}

/// `[0, 1, 2, 5, 7, 8]` as `0-2, 5, 7-8` (at most eight runs, then how many more).
fn ranges(indices: &[usize]) -> String {
    let mut runs: Vec<(usize, usize)> = Vec::new();
    for &i in indices {
        match runs.last_mut() {
            Some((_, end)) if *end + 1 == i => *end = i,
            _ => runs.push((i, i)),
        }
    }
    let mut text: Vec<String> = runs
        .iter()
        .take(8)
        .map(|&(a, b)| {
            if a == b {
                a.to_string()
            } else {
                format!("{a}-{b}")
            }
        })
        .collect();
    if runs.len() > 8 {
        text.push(format!("and {} more runs", runs.len() - 8));
    }
    text.join(", ")
}
