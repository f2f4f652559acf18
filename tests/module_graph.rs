//! The house rules, read from the sources. The library's modules depend on each other in one
//! direction: the graph of which file names which (`crate::a::b`, `super::x`, and a `mod.rs`
//! re-exporting its children) has no cycle, no module reads one of a higher layer ([`LAYERS`],
//! the order `src/lib.rs` describes), `shared` and `split` read nothing of the crate, and
//! `shader` reads only them. Comments, the `#[cfg(test)] mod tests` at a file's end and test
//! files (`tests.rs`, `tests/`) are left out: tests may reach anywhere. No source file of
//! the repository is longer than [`MAX_LINES`], each file's module doc is its own, and every
//! file or folder a comment names from the repository's root exists.

use std::collections::{BTreeMap, BTreeSet};
use std::path::Path;

#[path = "common/paths.rs"]
mod paths;

/// Module path (`lens::gpu`; `` for lib.rs) of every file under `src/`, with its code.
fn modules() -> BTreeMap<String, String> {
    fn walk(dir: &Path, out: &mut BTreeMap<String, String>) {
        for entry in std::fs::read_dir(dir).unwrap() {
            let path = entry.unwrap().path();
            if path.is_dir() {
                walk(&path, out);
            } else if path.extension().is_some_and(|e| e == "rs") {
                let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
                let relative = path.strip_prefix(&src).unwrap().with_extension("");
                let mut parts: Vec<String> = relative
                    .iter()
                    .map(|p| p.to_string_lossy().into_owned())
                    .collect();
                if matches!(parts.last().map(String::as_str), Some("mod" | "lib")) {
                    parts.pop();
                }
                if parts == ["main"] || parts.iter().any(|p| p == "tests") {
                    continue; // the binary, and test modules kept in files of their own
                }
                out.insert(
                    parts.join("::"),
                    code(&std::fs::read_to_string(&path).unwrap()),
                );
            }
        }
    }
    let mut out = BTreeMap::new();
    walk(&Path::new(env!("CARGO_MANIFEST_DIR")).join("src"), &mut out);
    out
}

/// A file's code without comments and without its trailing test module.
fn code(text: &str) -> String {
    let text = text.split("#[cfg(test)]\nmod tests").next().unwrap();
    text.lines()
        .map(|l| l.split("//").next().unwrap())
        .collect::<Vec<_>>()
        .join("\n")
}

/// The paths a `use` tree names, braces expanded, with the name each binds: `a::{b, c::d as
/// e}` gives `(a::b, b)` and `(a::c::d, e)`.
fn expand(tree: &str) -> Vec<(String, String)> {
    let tree = tree.trim();
    let Some(open) = tree.find('{') else {
        let (path, alias) = match tree.split_once(" as ") {
            Some((p, a)) => (p.trim(), a.trim()),
            None => (tree, tree.rsplit("::").next().unwrap()),
        };
        return vec![(path.to_string(), alias.to_string())];
    };
    let prefix = &tree[..open];
    let inner = &tree[open + 1..tree.rfind('}').unwrap()];
    // The items at the top level of the braces.
    let (mut depth, mut start, mut items) = (0, 0, Vec::new());
    for (i, c) in inner.char_indices() {
        match c {
            '{' => depth += 1,
            '}' => depth -= 1,
            ',' if depth == 0 => {
                items.push(&inner[start..i]);
                start = i + 1;
            }
            _ => {}
        }
    }
    items.push(&inner[start..]);
    items
        .into_iter()
        .map(str::trim)
        .filter(|i| !i.is_empty())
        .flat_map(|i| match i {
            "self" => vec![(
                prefix.trim_end_matches("::").to_string(),
                prefix
                    .trim_end_matches("::")
                    .rsplit("::")
                    .next()
                    .unwrap()
                    .to_string(),
            )],
            _ => expand(&format!("{prefix}{i}")),
        })
        .collect()
}

/// The simple paths after each whole-word `prefix` (`crate::`, `super::`) in `code`.
fn inline_paths<'a>(code: &'a str, prefix: &str) -> Vec<&'a str> {
    code.match_indices(prefix)
        .filter(|(i, _)| {
            !code[..*i]
                .chars()
                .next_back()
                .is_some_and(|c| c.is_alphanumeric() || c == '_')
        })
        .map(|(i, _)| {
            let rest = &code[i..];
            let end = rest
                .find(|c: char| !(c.is_alphanumeric() || c == '_' || c == ':'))
                .unwrap_or(rest.len());
            rest[..end].trim_end_matches(':')
        })
        .collect()
}

/// A path (`crate::x`, `super::x`, `self::x`, or a child's `x::y`) written in module `name`,
/// relative to the crate root; `None` for another crate's.
fn absolute(name: &str, path: &str, modules: &BTreeMap<String, String>) -> Option<String> {
    let join = |base: &str, rest: &str| match (base.is_empty(), rest.is_empty()) {
        (true, _) => rest.to_string(),
        (_, true) => base.to_string(),
        _ => format!("{base}::{rest}"),
    };
    let parent = name.rsplit_once("::").map_or("", |(p, _)| p);
    if let Some(rest) = path.strip_prefix("crate::") {
        Some(rest.to_string())
    } else if let Some(rest) = path.strip_prefix("super::") {
        Some(join(parent, rest))
    } else if let Some(rest) = path.strip_prefix("self::") {
        Some(join(name, rest))
    } else {
        let first = path.split("::").next().unwrap();
        modules
            .contains_key(&join(name, first))
            .then(|| join(name, path))
    }
}

/// The modules and, per module, the names it re-exports (`pub use`) with their paths.
struct Crate {
    modules: BTreeMap<String, String>,
    reexports: BTreeMap<String, BTreeMap<String, String>>,
}

impl Crate {
    /// The module that defines what `path` names, following re-exports.
    fn resolve(&self, path: &str, hops: u32) -> Option<String> {
        let parts: Vec<&str> = path.split("::").collect();
        let k = (1..=parts.len())
            .rev()
            .find(|&k| self.modules.contains_key(&parts[..k].join("::")))?;
        let module = parts[..k].join("::");
        let Some(target) = parts.get(k).and_then(|n| self.reexports[&module].get(*n)) else {
            return Some(module);
        };
        if hops >= 8 {
            return Some(module);
        }
        let full = std::iter::once(target.as_str())
            .chain(parts[k + 1..].iter().copied())
            .collect::<Vec<_>>()
            .join("::");
        self.resolve(&full, hops + 1).or(Some(module))
    }
}

/// Which modules each module reads. A `pub use` passes names through and is no dependency of
/// its own: readers of the name depend on the module that defines it.
fn graph() -> BTreeMap<String, BTreeSet<String>> {
    let modules = modules();
    let mut uses = BTreeMap::new();
    let mut reexports = BTreeMap::new();
    for (name, code) in &modules {
        let (mut used, mut exported) = (Vec::new(), BTreeMap::new());
        for statement in code.split(';') {
            let statement = statement.trim();
            let Some((head, tree)) = statement.rsplit_once("use ") else {
                continue;
            };
            let head = head.lines().last().unwrap_or("").trim();
            let public = head.starts_with("pub");
            if !(head.is_empty() || public) {
                continue;
            }
            for (path, alias) in expand(tree) {
                if let Some(path) = absolute(name, &path, &modules) {
                    if public {
                        exported.insert(alias, path);
                    } else {
                        used.push(path);
                    }
                }
            }
        }
        for prefix in ["crate::", "super::"] {
            let inline = inline_paths(code, prefix);
            used.extend(
                inline
                    .into_iter()
                    .filter_map(|p| absolute(name, p, &modules)),
            );
        }
        uses.insert(name.clone(), used);
        reexports.insert(name.clone(), exported);
    }
    let krate = Crate { modules, reexports };
    uses.into_iter()
        .map(|(name, used)| {
            let to: BTreeSet<String> = used
                .iter()
                .filter_map(|p| krate.resolve(p, 0))
                .filter(|m| *m != name)
                .collect();
            (name, to)
        })
        .collect()
}

/// A cycle of the graph, if it has one (depth-first).
fn cycle(edges: &BTreeMap<String, BTreeSet<String>>) -> Option<Vec<String>> {
    fn visit(
        node: &str,
        edges: &BTreeMap<String, BTreeSet<String>>,
        path: &mut Vec<String>,
        done: &mut BTreeSet<String>,
    ) -> Option<Vec<String>> {
        if let Some(i) = path.iter().position(|p| p == node) {
            return Some(path[i..].to_vec());
        }
        if done.contains(node) {
            return None;
        }
        path.push(node.to_string());
        for next in &edges[node] {
            if let Some(c) = visit(next, edges, path, done) {
                return Some(c);
            }
        }
        path.pop();
        done.insert(node.to_string());
        None
    }
    let mut done = BTreeSet::new();
    edges
        .keys()
        .find_map(|start| visit(start, edges, &mut Vec::new(), &mut done))
}

#[test]
fn modules_depend_one_way() {
    let edges = graph();
    // The reading sees what it should: the tracer reads the shader assembly and the BVH, and
    // names re-exported by `lens` lead to the files that define them.
    assert!(edges["trace::pass"].contains("shader") && edges["trace::gpu_scene"].contains("bvh"));
    assert!(
        edges["lens::gpu"].contains("lens::camera"),
        "{:?}",
        edges["lens::gpu"]
    );
    if let Some(c) = cycle(&edges) {
        panic!("the modules form a cycle: {}", c.join(" -> "));
    }
    for leaf in ["shared", "split"] {
        assert!(edges[leaf].is_empty(), "{leaf} reads {:?}", edges[leaf]);
    }
    let shader: Vec<&String> = edges["shader"].iter().collect();
    assert_eq!(
        shader,
        ["shared", "split"],
        "shader reads more than the leaves"
    );
}

/// The check itself finds a cycle where there is one.
#[test]
fn a_cycle_is_found() {
    let mut edges = graph();
    edges.get_mut("shared").unwrap().insert("trace".into());
    let c = cycle(&edges).expect("shared -> trace -> ... -> shared");
    assert!(c.contains(&"shared".to_string()) && c.contains(&"trace".to_string()));
}

/// The layers, lowest first: a module may read its own layer's and lower ones. A module's
/// layer is that of its top-level folder (`lens::gpu` is `lens`'s).
const LAYERS: [&[&str]; 8] = [
    // What the GPU and Rust share, and a clock and threads that work in a web page, read by
    // everything.
    &["shared", "split", "clock", "threads"],
    // Shader assembly, errors, bounded input, rigid transforms.
    &["shader", "error", "input", "pose"],
    // Lens models, the device, and its trigonometry measured.
    &["lens", "gpu", "precision"],
    // Scenes and their BVH.
    &["scene", "bvh"],
    // The passes: the tracer, the cube map, the rasterizer.
    &["trace", "cube", "raster"],
    // What renders frames and datasets from the passes.
    &["renderer", "dataset"],
    // The tool box of the `fisheye` command (feature `cli`) and the peer (`peer-embree`).
    &[
        "bench", "compare", "report", "plot", "demo", "validate", "peer",
    ],
    // The `fisheye` command (`src/bin/fisheye/`).
    &["bin"],
];

/// The layer of module `name`.
fn layer(name: &str) -> usize {
    let top = name.split("::").next().unwrap();
    LAYERS
        .iter()
        .position(|l| l.contains(&top))
        .unwrap_or_else(|| panic!("module {name} is in no layer of LAYERS: add it"))
}

/// The edges that go up a layer.
fn upward(edges: &BTreeMap<String, BTreeSet<String>>) -> Vec<String> {
    edges
        .iter()
        .filter(|(name, _)| !name.is_empty())
        .flat_map(|(name, to)| {
            to.iter()
                .filter(|t| !t.is_empty() && layer(t) > layer(name))
                .map(move |t| {
                    format!(
                        "{name} (layer {}) reads {t} (layer {})",
                        layer(name),
                        layer(t)
                    )
                })
        })
        .collect()
}

#[test]
fn no_module_reads_a_higher_layer() {
    let edges = graph();
    let up = upward(&edges);
    assert!(
        up.is_empty(),
        "lower layers read higher ones:\n{}",
        up.join("\n")
    );
    // The check finds such an edge where there is one.
    let mut bad = edges.clone();
    bad.get_mut("lens").unwrap().insert("renderer".into());
    assert_eq!(upward(&bad), ["lens (layer 2) reads renderer (layer 5)"]);
}

/// Files stay small enough to read in one sitting.
const MAX_LINES: usize = 700;

/// The files under `dir` (not `target/`, `.git/` or other hidden folders) whose names end in
/// one of `extensions`, with their texts.
fn sources(dir: &Path, extensions: &[&str], out: &mut Vec<(String, String)>) {
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        let name = path.file_name().unwrap().to_string_lossy().into_owned();
        if path.is_dir() {
            // Build outputs and fetched packages are not sources (web/dist: `web/build`'s).
            let built = name == "target" || name == "node_modules" || name == "dist";
            if !(name.starts_with('.') || built) {
                sources(&path, extensions, out);
            }
        } else if extensions.iter().any(|e| name.ends_with(e)) {
            let text = std::fs::read_to_string(&path).unwrap();
            out.push((path.display().to_string(), text));
        }
    }
}

/// The repository's sources in every language, and its scripts without an extension, with
/// their texts.
fn all_sources() -> Vec<(String, String)> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut out = Vec::new();
    let extensions = [
        ".rs", ".wgsl", ".py", ".sh", ".js", ".mjs", ".html", ".css", ".toml",
    ];
    sources(root, &extensions, &mut out);
    for script in [
        ".ci/run",
        ".ci/test",
        ".ci/install-lavapipe",
        "web/build",
        "web/test/run",
    ] {
        let text = std::fs::read_to_string(root.join(script)).unwrap();
        out.push((script.to_string(), text));
    }
    out
}

#[test]
fn no_source_file_is_over_700_lines() {
    let counts: Vec<(String, usize)> = all_sources()
        .into_iter()
        .map(|(path, text)| (path, text.lines().count()))
        .collect();
    // The walk sees the sources: the tracer's kernel and this file among them.
    assert!(counts.iter().any(|(p, _)| p.ends_with("wgsl/trace.wgsl")));
    assert!(
        counts
            .iter()
            .any(|(p, _)| p.ends_with("tests/module_graph.rs"))
    );
    let long: Vec<String> = counts
        .iter()
        .filter(|(_, n)| *n > MAX_LINES)
        .map(|(p, n)| format!("{p}: {n} lines"))
        .collect();
    assert!(
        long.is_empty(),
        "over {MAX_LINES} lines, split along what each part does:\n{}",
        long.join("\n")
    );
}

/// The prose of a Rust file's module doc: its `//!` lines outside code fences, trimmed, of
/// [`DOC_LINE`] characters or more.
fn module_doc_prose(text: &str) -> Vec<String> {
    let mut fenced = false;
    let mut out = Vec::new();
    for line in text.lines().map(str::trim) {
        let Some(doc) = line.strip_prefix("//!") else {
            continue;
        };
        let doc = doc.trim();
        if doc.starts_with("```") {
            fenced = !fenced;
        } else if !fenced && doc.chars().count() >= DOC_LINE {
            out.push(doc.to_string());
        }
    }
    out
}

/// Lines shorter than this may well be the same in two docs.
const DOC_LINE: usize = 40;

/// Each line of module-doc prose that stands again in another of `files` (path, text), with
/// the file it stood in first and the one it stands in again.
fn repeated_doc_lines(files: &[(String, String)]) -> Vec<String> {
    let mut first: BTreeMap<String, &str> = BTreeMap::new();
    let mut repeated = Vec::new();
    for (path, text) in files {
        for line in module_doc_prose(text) {
            match first.get(&line) {
                Some(&other) if other != path => {
                    repeated.push(format!("{other} and {path}: {line}"))
                }
                Some(_) => {}
                None => {
                    first.insert(line, path);
                }
            }
        }
    }
    repeated
}

/// A module's doc says what that module does: a file split off a module that keeps a copy of
/// its parent's doc (as five once did, their copies gone stale) says what it is not.
#[test]
fn each_module_doc_is_its_own() {
    let mut files = Vec::new();
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    sources(&src, &[".rs"], &mut files);
    assert!(files.iter().any(|(p, _)| p.ends_with("src/lib.rs")));
    let repeated = repeated_doc_lines(&files);
    assert!(
        repeated.is_empty(),
        "module docs that repeat another file's:\n{}",
        repeated.join("\n")
    );
    // The check finds a copy, and not code examples or short lines.
    let parent = "//! Calibration files: read and write the camera intrinsics of three tools.\n\
                  //! ```\n//! use fisheye_rt::lens::calib::read_the_calibration_file;\n//! ```\n";
    let child = format!("//! Writing a calibration.\n\n{parent}");
    let pair = |a: &str, b: &str| [("a".into(), a.into()), ("b".into(), b.into())];
    assert_eq!(
        repeated_doc_lines(&pair(parent, &child)),
        ["a and b: Calibration files: read and write the camera intrinsics of three tools."]
    );
    let example = "//! ```\n//! use fisheye_rt::lens::calib::read_the_calibration_file;\n//! ```\n";
    assert!(repeated_doc_lines(&pair(example, example)).is_empty());
    assert!(repeated_doc_lines(&pair("//! Short.", "//! Short.")).is_empty());
}

/// The comment of a line of a file named `path`: after `//` in Rust, WGSL and JavaScript,
/// after `#` elsewhere.
fn comment<'a>(path: &str, line: &'a str) -> Option<&'a str> {
    let slashes = [".rs", ".wgsl", ".js", ".mjs"]
        .iter()
        .any(|e| path.ends_with(e));
    let mark = if slashes { "//" } else { "#" };
    line.split_once(mark).map(|(_, c)| c)
}

/// The paths from the repository's root that a comment names (`src/trace/cpu/`), as
/// [`paths::names_a_path`] tells them.
fn paths_in(comment: &str) -> Vec<&str> {
    let path_char = |c: char| c.is_alphanumeric() || "_.-/".contains(c);
    comment
        .split(|c: char| !path_char(c))
        .map(|word| word.trim_end_matches('.'))
        .filter(|word| paths::names_a_path(word))
        .collect()
}

/// Every file or folder that a comment of the sources names from the repository's root
/// exists, so that moving or splitting a file cannot leave a comment sending the reader to
/// one that is gone (the calibrated models' `calibrated.rs` once, after it became a folder).
#[test]
fn paths_named_in_comments_exist() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut checked = 0;
    let mut missing = Vec::new();
    for (path, text) in all_sources() {
        for (i, line) in text.lines().enumerate() {
            for named in comment(&path, line).map(paths_in).unwrap_or_default() {
                if !root.join(named).exists() {
                    missing.push(format!("{path}:{}: {named}", i + 1));
                }
                checked += 1;
            }
        }
    }
    assert!(missing.is_empty(), "missing:\n{}", missing.join("\n"));
    assert!(checked >= 100, "{checked} paths");
    // What counts: a path from a top folder, not a placeholder, a URL's or a build's.
    assert_eq!(
        paths_in(
            " see src/lens/calibrated.rs. and tests/docs.rs, results/NAME, bvh/binary.rs, \
             https://example.org/src/x.rs, web/dist/x.js, web/test/node_modules, .ci/test"
        ),
        ["src/lens/calibrated.rs", "tests/docs.rs", ".ci/test"]
    );
    assert_eq!(
        comment("a.rs", "let x = 1; // src/lib.rs"),
        Some(" src/lib.rs")
    );
    assert_eq!(
        comment("run", "cd web # web/test/run"),
        Some(" web/test/run")
    );
    assert_eq!(comment("a.rs", "#[test]"), None);
}
