//! Docs that run: every command and code block of the README and the book (`docs/src/`) is
//! run or checked here, so that they cannot rot. A fence's info string says how (its first
//! word is the language, further words are comma-separated):
//!
//! - `sh`: run by bash (`set -euo pipefail`) in a scratch folder of the page's own, with the
//!   `fisheye` built for these tests first on `PATH` and the repository's `scenes/`,
//!   `examples/` and `lenses/` linked in; it must succeed.
//! - `sh,no_run`: shown only; its first line must be a comment saying why it is not run.
//! - `toml,file=NAME` (or `yaml`, `json`): written into the scratch folder for the blocks
//!   after it; every `toml` and `yaml` block must parse.
//! - `rust`: compiled and run as a doctest (`src/lib.rs` includes each page that has one).
//! - `python`: run by `python/tests/test_fisheye_rt.py` once the package is built.
//! - `text`: output or a synopsis, not code.
//!
//! The README's first block is CI's own two commands (`.ci/run` runs them as written), and
//! the commands in its "I want to…" table run here too.

use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::atomic::{AtomicUsize, Ordering};

#[path = "common/paths.rs"]
mod paths;

/// A fenced block: its info string, its text, and the line it starts on.
struct Block {
    info: String,
    text: String,
    line: usize,
}

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

/// The fenced blocks of a Markdown text.
fn blocks(markdown: &str) -> Vec<Block> {
    let mut out = Vec::new();
    let mut open: Option<Block> = None;
    for (i, line) in markdown.lines().enumerate() {
        match (&mut open, line.strip_prefix("```")) {
            (None, Some(info)) => {
                open = Some(Block {
                    info: info.trim().to_string(),
                    text: String::new(),
                    line: i + 1,
                })
            }
            (Some(_), Some("")) => out.push(open.take().expect("an open block")),
            (Some(block), _) => {
                block.text.push_str(line);
                block.text.push('\n');
            }
            (None, None) => {}
        }
    }
    assert!(open.is_none(), "a fenced block is never closed");
    out
}

/// The book's pages, in the order SUMMARY.md lists them, and SUMMARY.md itself.
fn pages() -> Vec<PathBuf> {
    let src = root().join("docs/src");
    let summary = std::fs::read_to_string(src.join("SUMMARY.md")).unwrap();
    let mut pages: Vec<PathBuf> = summary
        .split("](")
        .skip(1)
        .map(|rest| src.join(&rest[..rest.find(')').unwrap()]))
        .collect();
    for page in &pages {
        assert!(
            page.is_file(),
            "SUMMARY.md lists {}, which is missing",
            page.display()
        );
    }
    pages.push(src.join("SUMMARY.md"));
    pages
}

/// A scratch folder for `name`, with `fisheye` on a `PATH` of its own and the repository's
/// scenes and examples beside it.
fn scratch(name: &str) -> (PathBuf, String) {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join("docs")
        .join(name);
    let _ = std::fs::remove_dir_all(&dir);
    let bin = dir.join(".bin");
    std::fs::create_dir_all(&bin).unwrap();
    std::os::unix::fs::symlink(env!("CARGO_BIN_EXE_fisheye"), bin.join("fisheye")).unwrap();
    for linked in ["scenes", "examples", "lenses"] {
        std::os::unix::fs::symlink(root().join(linked), dir.join(linked)).unwrap();
    }
    let path = format!(
        "{}:{}",
        bin.display(),
        std::env::var("PATH").unwrap_or_default()
    );
    (dir, path)
}

/// Runs `script` by bash in `dir`; panics with its output if it fails.
fn run(script: &str, dir: &Path, path: &str, what: &str) {
    let output = Command::new("bash")
        .arg("-c")
        .arg(format!("set -euo pipefail\n{script}"))
        .current_dir(dir)
        .env("PATH", path)
        .output()
        .unwrap();
    assert!(
        output.status.success(),
        "{what} failed:\n{script}\nstdout:\n{}\nstderr:\n{}",
        String::from_utf8_lossy(&output.stdout),
        String::from_utf8_lossy(&output.stderr)
    );
}

/// Runs or checks every block of `page` as the module's documentation says.
fn check_page(page: &Path) {
    let name = page.file_stem().unwrap().to_string_lossy().into_owned();
    let text = std::fs::read_to_string(page).unwrap();
    let (dir, path) = scratch(&name);
    for block in blocks(&text) {
        let mut words = block.info.split(',').map(str::trim);
        let language = words.next().unwrap_or("");
        let options: Vec<&str> = words.collect();
        let at = format!("{}:{}", page.display(), block.line);
        let file = options.iter().find_map(|o| o.strip_prefix("file="));
        if let Some(file) = file {
            std::fs::write(dir.join(file), &block.text).unwrap();
        }
        match (language, options.as_slice()) {
            ("sh", []) => run(&block.text, &dir, &path, &at),
            ("sh", ["no_run"]) => assert!(
                block.text.starts_with("# not run by the tests"),
                "{at}: a block that is not run says why on its first line"
            ),
            ("toml", _) => {
                if let Err(e) = block.text.parse::<toml::Table>() {
                    panic!("{at}: not TOML: {e}");
                }
            }
            ("yaml", _) => {
                if let Err(e) = yaml_rust2::YamlLoader::load_from_str(&block.text) {
                    panic!("{at}: not YAML: {e}");
                }
            }
            ("rust", _) => {
                let lib = std::fs::read_to_string(root().join("src/lib.rs")).unwrap();
                let included = page.strip_prefix(root()).unwrap().display().to_string();
                assert!(
                    lib.contains(&format!("include_str!(\"../{included}\")")),
                    "{at}: src/lib.rs does not run this page's Rust as doctests"
                );
            }
            ("python" | "text", []) => {}
            _ => panic!(
                "{at}: a block of `{}` is neither run nor checked",
                block.info
            ),
        }
    }
    // What the page wrote is left only when it fails (to look at); CI's disk is small.
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn every_book_page_runs() {
    let pages = pages();
    assert!(pages.len() >= 13, "{} pages", pages.len());
    // Two pages at a time, each taking the next page left: most of a page's time is one
    // `fisheye` process compiling its kernels on one core.
    let next = AtomicUsize::new(0);
    std::thread::scope(|scope| {
        for _ in 0..2 {
            scope.spawn(|| {
                while let Some(page) = pages.get(next.fetch_add(1, Ordering::Relaxed)) {
                    check_page(page);
                }
            });
        }
    });
}

/// The README: at most 300 lines, its pictures small and present, its Rust and Python run
/// elsewhere (doctests, pytest), the two commands CI runs first, and every command of its
/// table run here.
#[test]
fn the_readme_is_a_front_page_whose_commands_run() {
    let readme = std::fs::read_to_string(root().join("README.md")).unwrap();
    let lines = readme.lines().count();
    assert!(
        lines <= 300,
        "the README has {lines} lines; the book holds the rest"
    );
    let all = blocks(&readme);
    assert_eq!(all[0].info, "sh");
    let ci = std::fs::read_to_string(root().join(".ci/run")).unwrap();
    assert!(
        ci.contains("README.md"),
        ".ci/run runs the README's first block"
    );
    for block in &all[1..] {
        assert!(
            matches!(block.info.as_str(), "rust" | "python"),
            "README.md:{}: a `{}` block; commands go in the table or the book",
            block.line,
            block.info
        );
    }
    // Pictures: present and at most 300 KB each, the book's too.
    for entry in std::fs::read_dir(root().join("docs/src/images")).unwrap() {
        let path = entry.unwrap().path();
        let bytes = std::fs::metadata(&path).unwrap().len();
        assert!(bytes <= 300 << 10, "{} is {bytes} bytes", path.display());
    }
    for link in readme.split("](").skip(1) {
        let target = &link[..link.find(')').unwrap()];
        let target = target.split('#').next().unwrap();
        if target.starts_with("http") || target.is_empty() {
            continue;
        }
        let file = root().join(target);
        assert!(file.exists(), "README links {target}, which is missing");
        if target.ends_with(".png") || target.ends_with(".webp") {
            let bytes = std::fs::metadata(&file).unwrap().len();
            assert!(bytes <= 300 << 10, "{target} is {bytes} bytes");
        }
    }
    // The table's commands, unescaped as Markdown shows them.
    let (dir, path) = scratch("readme");
    let mut commands = 0;
    let table = readme.split("## I want to").nth(1).unwrap();
    let table = table.split("\n## ").next().unwrap();
    for row in table.lines().filter(|l| l.starts_with("| ")).skip(1) {
        let cells: Vec<&str> = row.rsplitn(3, " |").collect();
        let cell = cells[1].rsplit("| ").next().unwrap();
        for (k, code) in cell.split('`').enumerate() {
            if k % 2 == 1 && code.contains("fisheye ") {
                run(&code.replace("\\|", "|"), &dir, &path, row);
                commands += 1;
            }
        }
    }
    assert!(commands >= 10, "{commands} commands in the table");
}

/// mdbook's anchor for a heading: its text lowercased (Unicode's lowercase, as mdbook's is),
/// spaces as hyphens, and no punctuation but hyphens and underscores (inline code and
/// emphasis marks dropped with it).
fn anchor(heading: &str) -> String {
    heading
        .chars()
        .filter(|&c| c.is_alphanumeric() || c == '_' || c == '-' || c.is_whitespace())
        .flat_map(|c| if c.is_whitespace() { '-' } else { c }.to_lowercase())
        .collect()
}

/// The anchors of a Markdown file's headings (outside fenced blocks).
fn anchors(markdown: &str) -> Vec<String> {
    prose(markdown)
        .lines()
        .filter_map(|line| line.strip_prefix('#'))
        .map(|line| anchor(line.trim_start_matches('#').trim()))
        .collect()
}

/// A Markdown file without its fenced blocks.
fn prose(markdown: &str) -> String {
    let mut fenced = false;
    let mut kept = String::new();
    for line in markdown.lines() {
        if line.starts_with("```") {
            fenced = !fenced;
        } else if !fenced {
            kept.push_str(line);
            kept.push('\n');
        }
    }
    kept
}

/// The READMEs under `folder`, at any depth.
fn readmes(folder: &Path) -> Vec<PathBuf> {
    let mut found = Vec::new();
    for entry in std::fs::read_dir(folder).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() {
            found.extend(readmes(&path));
        } else if path.file_name().is_some_and(|name| name == "README.md") {
            found.push(path);
        }
    }
    found
}

/// The book's pages, the README and the results' READMEs.
fn every_markdown_page() -> Vec<PathBuf> {
    let mut pages = pages();
    pages.push(root().join("README.md"));
    pages.extend(readmes(&root().join("results")));
    pages
}

/// Every relative link of the README, the book and the results' READMEs reaches a file or
/// folder that exists, and a link to a heading (`page.md#anchor`, or `#anchor` on the same
/// page) reaches one that the page has, so that moving a section cannot leave a link
/// pointing nowhere.
#[test]
fn links_reach_their_files_and_headings() {
    let mut checked = 0;
    for page in every_markdown_page() {
        let text = std::fs::read_to_string(&page).unwrap();
        for link in prose(&text).split("](").skip(1) {
            let target = &link[..link.find(')').unwrap()];
            if target.contains("://") || target.starts_with("mailto:") {
                continue;
            }
            let (path, heading) = target.split_once('#').unwrap_or((target, ""));
            let file = if path.is_empty() {
                page.clone()
            } else {
                page.parent().unwrap().join(path)
            };
            let at = format!("{} links {target}", page.display());
            assert!(file.exists(), "{at}, which is missing");
            if !heading.is_empty() {
                let linked = std::fs::read_to_string(&file).unwrap();
                assert!(
                    anchors(&linked).iter().any(|a| a == heading),
                    "{at}, a heading {} does not have",
                    file.display()
                );
            }
            checked += 1;
        }
    }
    assert!(checked >= 100, "{checked} links");
}

/// The paths from the repository's root that a Markdown text names in inline code
/// (`src/trace/pass.rs`, `tests/dataset/`) outside fenced blocks, as
/// [`paths::names_a_path`] tells them.
fn named_paths(markdown: &str) -> Vec<String> {
    let prose = prose(markdown);
    prose
        .split('`')
        .skip(1)
        .step_by(2)
        .filter(|code| paths::names_a_path(code))
        .map(str::to_string)
        .collect()
}

/// Every file or folder the README, the book and the results' READMEs name in inline code
/// from the repository's root exists, so that moving or splitting a file cannot leave the
/// docs sending a reader to one that is gone (the f64 reference's `cpu.rs` once, after it
/// became a folder).
#[test]
fn paths_the_docs_name_exist() {
    let mut checked = 0;
    for page in every_markdown_page() {
        let text = std::fs::read_to_string(&page).unwrap();
        for path in named_paths(&text) {
            assert!(
                root().join(&path).exists(),
                "{} names `{path}`, which is missing",
                page.display()
            );
            checked += 1;
        }
    }
    assert!(checked >= 100, "{checked} paths");
    // What counts as a path: from a top folder, no placeholder, not generated, not fenced.
    assert_eq!(
        named_paths(
            "`src/lib.rs`, `bvh/stages.rs`, `results/<gpu>/`, `web/dist/`, `fisheye render`\n\
             ```sh\ncat `tests/docs.rs`\n```\n`tests/`"
        ),
        ["src/lib.rs", "tests/"]
    );
}

#[test]
fn anchors_follow_mdbook() {
    assert_eq!(
        anchor("The tent filter: one ray, less aliasing"),
        "the-tent-filter-one-ray-less-aliasing"
    );
    assert_eq!(
        anchor("Through a prescription's glass"),
        "through-a-prescriptions-glass"
    );
    assert_eq!(anchor("`compare` and `bench`"), "compare-and-bench");
    assert_eq!(anchor("Šibenik at 512×384"), "šibenik-at-512384");
}
