//! Line-by-line checks of OBJ and MTL text before `tobj` reads it.
//!
//! tobj names only the kind of a parse error (no line), accepts some malformed lines silently
//! (a face of two vertices, a statement it does not know) and panics on others (`Kd 0.5`, a
//! colour of one number). So every line tobj would read is checked here first: a malformed line
//! is an error naming its line, and what tobj would skip silently is a warning.
//!
//! The syntax follows the Wavefront OBJ and MTL specifications (Wavefront Advanced Visualizer
//! manual, appendices B1 and B2), restricted to what tobj loads.

use std::collections::BTreeMap;

/// A malformed line: its 1-based number and what is wrong with it.
#[derive(Debug, PartialEq)]
pub(crate) struct LineError {
    pub line: usize,
    pub message: String,
}

/// What the OBJ check found besides errors.
#[derive(Debug, Default)]
pub(crate) struct ObjFacts {
    /// Statements that are skipped, one line per kind, naming its first line.
    pub warnings: Vec<String>,
    /// The `mtllib` files, in order of appearance.
    pub mtllibs: Vec<String>,
    /// Each material `usemtl` names, with the first line naming it.
    pub used_materials: BTreeMap<String, usize>,
}

/// OBJ statements of free-form geometry, grouping and display that tobj skips.
const OBJ_SKIPPED: [&str; 28] = [
    "vp",
    "cstype",
    "deg",
    "bmat",
    "step",
    "curv",
    "curv2",
    "surf",
    "parm",
    "trim",
    "hole",
    "scrv",
    "sp",
    "end",
    "con",
    "mg",
    "bevel",
    "c_interp",
    "d_interp",
    "lod",
    "shadow_obj",
    "trace_obj",
    "ctech",
    "stech",
    "maplib",
    "usemap",
    "call",
    "csh",
];

/// MTL statements tobj reads or keeps that the tracer does not use (PBR extensions included):
/// accepted without a word.
const MTL_IGNORED: [&str; 24] = [
    "map_Ka",
    "map_Ks",
    "map_Ns",
    "map_ns",
    "map_NS",
    "map_d",
    "map_Bump",
    "map_bump",
    "bump",
    "disp",
    "decal",
    "refl",
    "norm",
    "map_Ke",
    "map_Pr",
    "map_Pm",
    "Pr",
    "Pm",
    "Ps",
    "Pc",
    "Pcr",
    "aniso",
    "anisor",
    "sharpness",
];

/// Statements whose argument is a name or a file name, which may hold `#`.
fn takes_a_name(keyword: &str) -> bool {
    matches!(
        keyword,
        "mtllib" | "usemtl" | "o" | "g" | "newmtl" | "maplib" | "usemap"
    ) || ["map_", "bump", "disp", "decal", "refl", "norm"]
        .iter()
        .any(|p| keyword.starts_with(p))
}

/// The text as tobj should read it: each line without its leading blanks (tobj takes names
/// from the raw line) and, but for names, without a trailing `# comment` (tobj reads one as a
/// bad face index, and exporters write them after colours). Lines keep their numbers.
pub(crate) fn clean(text: &str) -> String {
    let mut out = String::with_capacity(text.len() + 1);
    for raw in text.lines() {
        let line = raw.trim_start();
        let keyword = line.split_whitespace().next().unwrap_or("");
        let kept = if takes_a_name(keyword) {
            line
        } else {
            line.split('#').next().unwrap_or("").trim_end()
        };
        out.push_str(kept);
        out.push('\n');
    }
    out
}

fn error(line: usize, message: impl Into<String>) -> LineError {
    LineError {
        line,
        message: message.into(),
    }
}

/// A word as messages quote it: whole, or its first 24 characters.
fn quoted(word: &str) -> String {
    match word.char_indices().nth(24) {
        Some((end, _)) => format!("{:?}...", &word[..end]),
        None => format!("{word:?}"),
    }
}

/// The numbers after a statement's keyword: between `min` and `max` of them, each a number
/// Rust (and so tobj) parses. With `f32_finite`, each must also stay finite as the f32 the
/// GPU takes it in (vertex positions need not: they stay f64 until the upload checks them).
fn numbers(
    line: usize,
    keyword: &str,
    words: &[&str],
    (min, max): (usize, usize),
    f32_finite: bool,
    form: &str,
) -> Result<Vec<f64>, LineError> {
    if words.len() < min || words.len() > max {
        return Err(error(
            line,
            format!("`{keyword}` takes {form}, found {} values", words.len()),
        ));
    }
    words
        .iter()
        .map(|w| {
            let why = match w.parse::<f64>() {
                Ok(x) if !f32_finite || (x as f32).is_finite() => return Ok(x),
                Ok(x) if x.is_finite() => "is beyond the f32 range the GPU computes in",
                Ok(_) => "is not a finite number",
                Err(_) => "is not a number",
            };
            Err(error(line, format!("`{keyword}`: {} {why}", quoted(w))))
        })
        .collect()
}

/// The text after a statement's keyword as tobj takes it for `mtllib` and `usemtl`: after the
/// first space, trimmed.
fn name_after_space(text: &str) -> &str {
    text.split_once(' ').map_or("", |(_, rest)| rest.trim())
}

/// What a face vertex refers to, by slot: a position, a texture coordinate, a normal.
const KINDS: [&str; 3] = ["position", "texture coordinate", "normal"];

/// One index of a face vertex: its slot in [`KINDS`] and the index (1-based, or negative
/// counting back).
struct Reference {
    slot: usize,
    index: isize,
}

/// Checks an OBJ file's text, as [`clean`] leaves it. Non-finite vertex coordinates are not
/// errors here: the loader drops their triangles with a warning naming the mesh.
pub(crate) fn check_obj(text: &str) -> Result<ObjFacts, LineError> {
    let mut facts = ObjFacts::default();
    // Positions, texture coordinates, normals so far.
    let mut counts = [0usize; 3];
    // Positive references, checked against the final counts (they may point forward).
    let mut forward: Vec<(usize, usize, isize)> = Vec::new();
    let mut coloured: Option<(bool, usize)> = None;
    let mut skipped: BTreeMap<String, (usize, usize)> = BTreeMap::new();
    for (i, raw) in text.lines().enumerate() {
        let line = i + 1;
        let words: Vec<&str> = raw.split_whitespace().collect();
        let Some((&keyword, args)) = words.split_first() else {
            continue;
        };
        match keyword {
            k if k.starts_with('#') => {}
            "v" => {
                let v = numbers(line, "v", args, (3, 6), false, "x y z [w] or x y z r g b")?;
                if v.len() == 5 {
                    return Err(error(
                        line,
                        "`v` takes x y z [w] or x y z r g b, found 5 values",
                    ));
                }
                if v.len() == 4 && !(v[3].is_finite() && v[3] != 0.0) {
                    return Err(error(line, "`v`: the weight w must be finite and non-zero"));
                }
                let has_colour = v.len() == 6;
                match coloured {
                    None => coloured = Some((has_colour, line)),
                    Some((c, first)) if c != has_colour => {
                        return Err(error(
                            line,
                            format!(
                                "vertex colours on some vertices only (line {first} {} one)",
                                if c { "has" } else { "has none" }
                            ),
                        ));
                    }
                    Some(_) => {}
                }
                counts[0] += 1;
            }
            "vt" => {
                numbers(line, "vt", args, (2, 3), true, "u v [w]")?;
                counts[1] += 1;
            }
            "vn" => {
                numbers(line, "vn", args, (3, 3), true, "x y z")?;
                counts[2] += 1;
            }
            "f" | "l" => {
                let least = if keyword == "f" { 3 } else { 2 };
                if args.len() < least {
                    return Err(error(
                        line,
                        format!(
                            "`{keyword}` needs at least {least} vertices, found {}",
                            args.len()
                        ),
                    ));
                }
                for word in args {
                    for Reference { slot, index } in references(line, word)? {
                        if index > 0 {
                            forward.push((line, slot, index));
                        } else if index.unsigned_abs() > counts[slot] {
                            return Err(error(
                                line,
                                format!(
                                    "{} index {index} reaches back past the first: only {} so \
                                     far",
                                    KINDS[slot], counts[slot]
                                ),
                            ));
                        }
                    }
                }
                if keyword == "l" {
                    skipped.entry("l".into()).or_insert((line, 0)).1 += 1;
                }
            }
            "mtllib" | "usemtl" => {
                let name = name_after_space(raw.trim_start());
                if name.is_empty() {
                    return Err(error(
                        line,
                        format!("`{keyword}` needs a name after a space"),
                    ));
                }
                if keyword == "mtllib" {
                    facts.mtllibs.push(name.to_string());
                } else {
                    facts.used_materials.entry(name.to_string()).or_insert(line);
                }
            }
            "o" | "g" | "s" => {}
            other => skipped.entry(other.into()).or_insert((line, 0)).1 += 1,
        }
    }
    for (line, slot, index) in forward {
        if index.unsigned_abs() > counts[slot] {
            return Err(error(
                line,
                format!(
                    "{} index {index} is out of range: the file has {}",
                    KINDS[slot], counts[slot]
                ),
            ));
        }
    }
    for (keyword, (first, count)) in skipped {
        let what = if keyword == "l" {
            "polylines have no area".to_string()
        } else if keyword == "p" {
            "points have no area".to_string()
        } else if OBJ_SKIPPED.contains(&keyword.as_str()) {
            "free-form geometry and display statements are not supported".to_string()
        } else {
            "not an OBJ statement".to_string()
        };
        let more = match count {
            1 => String::new(),
            n => format!(" (and {} more lines)", n - 1),
        };
        facts
            .warnings
            .push(format!("line {first}: `{keyword}` skipped: {what}{more}"));
    }
    Ok(facts)
}

/// A face vertex `v`, `v/vt`, `v//vn` or `v/vt/vn`: its references, each a non-zero integer.
fn references(line: usize, word: &str) -> Result<Vec<Reference>, LineError> {
    let parts: Vec<&str> = word.split('/').collect();
    if parts.len() > 3 || parts[0].is_empty() {
        return Err(error(
            line,
            format!("face vertex {word:?}: expected v, v/vt, v//vn or v/vt/vn"),
        ));
    }
    let mut out = Vec::new();
    for (slot, (part, kind)) in parts.iter().zip(KINDS).enumerate() {
        if part.is_empty() {
            continue;
        }
        let index: isize = part.parse().map_err(|_| {
            error(
                line,
                format!("face vertex {word:?}: {part:?} is not an integer index"),
            )
        })?;
        if index == 0 {
            return Err(error(
                line,
                format!("face vertex {word:?}: {kind} index 0 (OBJ indices start at 1)"),
            ));
        }
        out.push(Reference { slot, index });
    }
    Ok(out)
}

/// What the MTL check found besides errors.
#[derive(Debug, Default)]
pub(crate) struct MtlFacts {
    /// Statements the tracer does not know, one line per kind.
    pub warnings: Vec<String>,
}

/// Checks an MTL file's text, as [`clean`] leaves it.
pub(crate) fn check_mtl(text: &str) -> Result<MtlFacts, LineError> {
    let mut facts = MtlFacts::default();
    let mut unknown: BTreeMap<String, (usize, usize)> = BTreeMap::new();
    let mut material = false;
    for (i, raw) in text.lines().enumerate() {
        let line = i + 1;
        let words: Vec<&str> = raw.split_whitespace().collect();
        let Some((&keyword, args)) = words.split_first() else {
            continue;
        };
        if keyword.starts_with('#') {
            continue;
        }
        if keyword == "newmtl" {
            if args.is_empty() {
                return Err(error(line, "`newmtl` needs a material name"));
            }
            material = true;
            continue;
        }
        if !material {
            return Err(error(
                line,
                format!("`{keyword}` before any `newmtl`: it belongs to no material"),
            ));
        }
        match keyword {
            "Ka" | "Kd" | "Ks" | "Ke" => {
                if matches!(args.first(), Some(&"spectral" | &"xyz")) {
                    return Err(error(
                        line,
                        format!(
                            "`{keyword} {}` colours are not supported; give r g b",
                            args[0]
                        ),
                    ));
                }
                let c = numbers(line, keyword, args, (3, 3), true, "r g b")?;
                if c.iter().any(|&x| x < 0.0) {
                    return Err(error(line, format!("`{keyword}`: a colour must be ≥ 0")));
                }
            }
            "Tf" => {
                numbers(line, keyword, args, (1, 3), true, "r [g b]")?;
            }
            "Ns" | "Ni" | "d" | "Tr" => {
                let x = numbers(line, keyword, args, (1, 1), true, "one number")?[0];
                if keyword == "Ni" && x <= 0.0 {
                    return Err(error(
                        line,
                        format!("`Ni` {x}: an index of refraction is > 0"),
                    ));
                }
            }
            "illum" => {
                if args.len() != 1 || args[0].parse::<u8>().is_err() {
                    return Err(error(line, "`illum` takes one model number, 0 to 10"));
                }
            }
            "map_Kd" => {
                if raw
                    .trim()
                    .get(6..)
                    .is_none_or(|rest| rest.trim().is_empty())
                {
                    return Err(error(line, "`map_Kd` needs a file name"));
                }
            }
            k if MTL_IGNORED.contains(&k) => {
                if args.is_empty() {
                    return Err(error(line, format!("`{k}` needs a value")));
                }
            }
            other => unknown.entry(other.into()).or_insert((line, 0)).1 += 1,
        }
    }
    for (keyword, (first, count)) in unknown {
        let more = match count {
            1 => String::new(),
            n => format!(" (and {} more lines)", n - 1),
        };
        facts.warnings.push(format!(
            "line {first}: `{keyword}` is not an MTL statement; skipped{more}"
        ));
    }
    Ok(facts)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn obj_error(text: &str) -> LineError {
        check_obj(&clean(text)).expect_err(text)
    }

    #[test]
    fn obj_errors_name_the_line() {
        let head = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";
        let cases = [
            ("v 1 2\n", 1, "found 2 values"),
            ("v 0 0 0\nv 1 x 0\n", 2, "\"x\" is not a number"),
            ("v 1 2 3 4 5\n", 1, "found 5 values"),
            ("v 1 2 3 0\n", 1, "w must be finite and non-zero"),
            ("v 1 2 3\nv 1 2 3 1 1 1\n", 2, "vertex colours on some"),
            ("vt 0.5\n", 1, "`vt` takes u v [w]"),
            ("vn 0 1\n", 1, "`vn` takes x y z"),
            ("vn 0 1 nan\n", 1, "`vn`: \"nan\" is not a finite number"),
            ("vt 0 1e300\n", 1, "`vt`: \"1e300\" is beyond the f32 range"),
            (&format!("{head}f 1 2\n"), 4, "at least 3 vertices"),
            (&format!("{head}f 0 1 2\n"), 4, "index 0"),
            (
                &format!("{head}f -4 -2 -1\n"),
                4,
                "reaches back past the first",
            ),
            (
                &format!("{head}f 1 2 9\n"),
                4,
                "index 9 is out of range: the file has 3",
            ),
            (
                &format!("{head}f 1/1 2/1 3/1\n"),
                4,
                "texture coordinate index 1",
            ),
            (&format!("{head}f 1//2 2//2 3//2\n"), 4, "normal index 2"),
            (&format!("{head}f 1/2/3/4 2 3\n"), 4, "expected v, v/vt"),
            (&format!("{head}f a 2 3\n"), 4, "not an integer index"),
            (&format!("{head}f /1 2 3\n"), 4, "expected v, v/vt"),
            ("mtllib\n", 1, "needs a name"),
            ("usemtl\tred\n", 1, "needs a name after a space"),
        ];
        for (text, line, wanted) in cases {
            let e = obj_error(text);
            assert_eq!(e.line, line, "{text:?}: {e:?}");
            assert!(e.message.contains(wanted), "{text:?}: {e:?}");
        }
    }

    #[test]
    fn valid_obj_forms_pass_and_skipped_statements_warn() {
        let text = "# comment\nmtllib a b.mtl\no thing\nv 0 0 0\nv 1 0 0 1\nv 0 1 0\n\
                    vt 0 0\nvt 1 0 0\nvn 0 0 1\ng part\ns off\nusemtl red\n\
                    f 1/1/1 2/2/1 3/1/1\nf -3//-1 -2//-1 -1//-1\nf 1 2 3 1\nf 3/2 2/1 4/1\n\
                    v 1 1 0\nl 1 2\nl 2 3\ncurv 0 1 1 2\nhello\nf 1 2 3 # a comment\n";
        let facts = check_obj(&clean(text)).unwrap();
        assert_eq!(facts.mtllibs, ["a b.mtl"]);
        assert_eq!(facts.used_materials.get("red"), Some(&12));
        let warnings = facts.warnings.join("\n");
        for wanted in [
            "line 20: `curv` skipped: free-form",
            "line 21: `hello` skipped: not an OBJ statement",
            "line 18: `l` skipped: polylines have no area (and 1 more lines)",
        ] {
            assert!(warnings.contains(wanted), "{warnings}");
        }
        // Non-finite coordinates are the loader's to drop, with the mesh's name.
        assert!(check_obj("v nan 0 inf\n").is_ok());
    }

    #[test]
    fn clean_drops_comments_but_not_from_names() {
        assert_eq!(
            clean("  f 1 2 3 # tri\r\nusemtl a#b\n\tmap_Kd x#1.png\n# all\nKd 1 1 1#c"),
            "f 1 2 3\nusemtl a#b\nmap_Kd x#1.png\n\nKd 1 1 1\n"
        );
    }

    #[test]
    fn mtl_errors_name_the_line() {
        let cases = [
            ("newmtl\n", 1, "needs a material name"),
            ("Kd 1 1 1\n", 1, "before any `newmtl`"),
            ("newmtl a\nKd 0.5\n", 2, "`Kd` takes r g b, found 1"),
            ("newmtl a\nKs spectral x.rfl\n", 2, "not supported"),
            (
                "newmtl a\nKe 1 nan 1\n",
                2,
                "\"nan\" is not a finite number",
            ),
            ("newmtl a\nKa 1 -1 1\n", 2, "≥ 0"),
            (
                "newmtl a\nKs 1e39 1 1\n",
                2,
                "\"1e39\" is beyond the f32 range",
            ),
            ("newmtl a\nNs\n", 2, "one number"),
            ("newmtl a\nNi 0\n", 2, "index of refraction"),
            ("newmtl a\nd x\n", 2, "\"x\" is not a number"),
            ("newmtl a\nillum 4.5\n", 2, "`illum` takes one model number"),
            ("newmtl a\nmap_Kd\n", 2, "needs a file name"),
            ("newmtl a\nbump\n", 2, "`bump` needs a value"),
        ];
        for (text, line, wanted) in cases {
            let e = check_mtl(&clean(text)).expect_err(text);
            assert_eq!(e.line, line, "{text:?}: {e:?}");
            assert!(e.message.contains(wanted), "{text:?}: {e:?}");
        }
        let good = "newmtl a\nKa 0.6 0.06 0.05 # red\nKd 1 0.5 0\nTf 0.9\nNi 1.5\nillum 7\n\
                    map_Kd tex/a b.png\nbump -bm 0.5 n.png\nPr 0.5\nfoo 1\nfoo 2\n";
        let facts = check_mtl(&clean(good)).unwrap();
        assert_eq!(
            facts.warnings,
            ["line 10: `foo` is not an MTL statement; skipped (and 1 more lines)"]
        );
    }
}
