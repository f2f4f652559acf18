//! Which words of the docs and comments name a file or folder from the repository's root
//! (shared by `tests/docs.rs` and `tests/module_graph.rs`, which check that each exists).

/// The repository's folders that such a path starts from; what the builds and package
/// managers write (`target/`, `web/dist/`, `node_modules/`) is not among what is checked.
const TOP_FOLDERS: [&str; 13] = [
    ".ci", "benches", "docs", "examples", "fuzz", "lenses", "python", "results", "scenes", "src",
    "tests", "web", "wgsl",
];

/// Whether `word` names a path from the repository's root that must exist: it starts with
/// one of [`TOP_FOLDERS`] and a slash, holds no placeholder (`results/<gpu>/`,
/// `results/NAME`, `src/*.rs`) and is not in what the builds write.
pub fn names_a_path(word: &str) -> bool {
    let top = word.split('/').next().unwrap();
    let capitals =
        |part: &str| part.len() > 1 && part.chars().all(|c| c.is_ascii_uppercase() || c == '_');
    let placeholder =
        word.contains(|c: char| "<>*{}[] $".contains(c)) || word.split('/').any(capitals);
    let built = word.starts_with("web/dist") || word.contains("node_modules");
    word.contains('/') && TOP_FOLDERS.contains(&top) && !placeholder && !built
}
